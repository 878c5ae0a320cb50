/* spectral_mis — unidirectional spectral MIS (Miller, Georgiev, Jarosz 2019, "A null-scattering path
 * integral formulation of light transport"): a path delta-tracks its hero channel against one majorant
 * shared by all channels and returns per-channel weights and pdf ratios, with which the integrator
 * combines the channels' techniques by the balance heuristic over the whole path. Shadow rays use
 * residual ratio tracking (murk_tracker_transmittance). Parameters: `murk plugins spectral_mis`; the
 * weights and the closed-form flights: docs/trackers.md#spectral_mis. */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_CLOSED_FORM, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CLOSED_FORM] = {"closed_form", MURK_PARAM_BOOL, 0, {0, 0, 0}, NULL, NULL, 0, 1,
                       "a flight through majorant cells of constant density (max = min: a constant field, or "
                       "constant regions of a grid at majorant_factor 1) is sampled in closed form: the hero "
                       "channel's own exponential, cell by cell, each channel weighted by its own exponential over "
                       "the hero's (the balance heuristic over channels, as in Tungsten's homogeneous medium): no "
                       "null collisions, no density lookups. From the first cell that is not constant the flight "
                       "is tracked as usual. The same expected image (tests/test_media.c); less noise per sample "
                       "in homogeneous chromatic media (docs/results.md)"},
};

typedef struct smis {
    murk_tracker base;
    int closed_form;
} smis;

static int smis_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                       char *err, size_t errlen)
{
    smis *m = murk_tracker_new(host, data, sizeof(smis), err, errlen);
    if (m) {
        m->base.plugin = "spectral_mis";
        m->closed_form = params[P_CLOSED_FORM].f[0] != 0.0;
    }
    return (*self = m) ? 0 : -1;
}

/* closed_form: the flight cell by cell through the majorant cells of constant density (max == min) in
 * closed form, up to the first cell that is not constant; returns 1 if the flight ended (scattered or
 * passed the segment), else 0 with *from set to where the rest is to be tracked. Per cell of density d
 * and length L, with s_k = d sigma_t,k: the hero collides at x ~ s_h exp(-s_h x); if x < L it scatters
 * there with weight_k = d sigma_s,k e^(-s_k x) / (s_h e^(-s_h x)) and pdf ratio s_k e^(-s_k x) /
 * (s_h e^(-s_h x)), else it passes the cell with both e^(-s_k L) / e^(-s_h L). Channel k's technique is
 * the same thing with its own s_k, and the tracking that follows shares one majorant for every
 * channel, so the ratios of the whole flight stay those of one technique per channel. One optical depth
 * tau for the hero, drawn once (a stratified flight's first number: murk_flight_float) and used up cell
 * by cell (memoryless: the same as a fresh draw per cell), so the stratification reaches the scattering
 * distance wherever it lies. *first says whether the flight's slot is still unused. With an albedo field
 * sigma_s,k is the local one at the collision; with emission the collision scores, as every collision of
 * a tracked flight does (murk/tracking.h), e^(-s_k x) sigma_a,k Le_k / (s_h e^(-s_h x)) with the pdf ratios
 * up to and including the collision: the collision estimator with the hero's exponential as its
 * distance density. */
static int smis_closed_form(const murk_tracker *m, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                            murk_medium_event *ev, float *from, int *first)
{
    int hero = ctx->hero;
    const murk_host *h = m->host;
    murk_majorant_walk w;
    h->walk_init(m->d->density, ray, ray->tmin, ray->tmax, &w);
    float a, b, dmax, dmin, tau = -1.0f, uc = -1.0f;
    for (long i = 0; i < MURK_WATCHDOG_ITERATIONS && h->walk_next(&w, &a, &b, &dmax, &dmin); i++) {
        if (!(dmax > 0.0f))
            continue;
        if (dmax != dmin || !isfinite(b)) {
            *from = a;
            return 0;
        }
        if (tau < 0.0f)
            tau = murk_exp1(murk_flight_float(rng, first, &uc));
        float sh = dmax * m->sigma_t.c[hero], len = b - a;
        float x = sh > 0.0f ? tau / sh : INFINITY;
        tau -= sh * len;
        if (x < len) {
            float ph = sh * expf(-sh * x), sa[3], ss[3];
            murk_vec3 p = murk_madd(ray->o, ray->d, a + x);
            if (m->fields)
                murk_local_sigma(m, p, dmax, sa, ss);
            murk_rgb we; /* the flight's weight up to the collision, for its emission score */
            for (int k = 0; k < 3; k++) {
                float sk = dmax * m->sigma_t.c[k], pk = sk * expf(-sk * x);
                if (!m->fields)
                    ss[k] = dmax * m->d->sigma_s.c[k];
                we.c[k] = ev->weight.c[k] * (expf(-sk * x) / ph);
                ev->weight.c[k] *= ss[k] * expf(-sk * x) / ph;
                ev->pdf_ratio.c[k] *= pk / ph;
            }
            if (murk_emitting(m))
                murk_emit(m, ctx, ev, p, sa, 1.0f, we, ev->pdf_ratio);
            ev->scattered = 1;
            ev->t = a + x;
            return 1;
        }
        for (int k = 0; k < 3; k++) {
            float r = expf(-(dmax * m->sigma_t.c[k] - sh) * len);
            ev->weight.c[k] *= r;
            ev->pdf_ratio.c[k] *= r;
        }
    }
    return 1;
}

/* One free flight; `fields` (a constant at each call) adds the medium's albedo field, its emission and the
 * null probabilities an integrator may ask for (murk/medium.h, MURK_CTX_NULL_PROB): the instance without
 * them is spectral MIS as it always was. */
static MURK_ALWAYS_INLINE void smis_flight(const smis *sm, const murk_ray *ray, const murk_path_ctx *ctx,
                                           murk_rng *rng, murk_medium_event *ev, int fields)
{
    const murk_tracker *m = &sm->base;
    int hero = ctx->hero;
    murk_event_init(ev, ray);
    if (!(m->smax > 0.0f))
        return;
    int emit = fields && murk_emitting(m);
    int np = fields && m->d->integrator_minor >= MURK_ABI_MINOR_FIELDS && (ctx->flags & MURK_CTX_NULL_PROB) && !sm->closed_form;
    if (np)
        ev->null_prob = 1.0f; /* the product of the hero's null probabilities, for volpath_nee's nee_mis */
    murk_ray rest = *ray;
    int first = murk_flight_stratified(m->d);
    if (sm->closed_form && smis_closed_form(m, ray, ctx, rng, ev, &rest.tmin, &first))
        return;
    murk_collisions c;
    murk_collisions_init(&c, m, &rest, m->smax); /* one majorant for every channel */
    c.first = first; /* 0 if the closed-form part took the flight's slot */
    float t, dens, sa[3], ss[3];
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a[3], q[3], amax = 0.0f;
        for (int k = 0; k < 3; k++) {
            a[k] = dens * m->sigma_t.c[k] / c.mu;
            q[k] = murk_real_prob(a[k], 1.0f - a[k]);
            amax = murk_maxf(amax, a[k]);
        }
        if (fields && (emit || (m->fields & MURK_FIELD_ALBEDO))) {
            murk_vec3 p = murk_madd(rest.o, rest.d, t);
            murk_local_sigma(m, p, dens, sa, ss);
            if (emit)
                murk_emit(m, ctx, ev, p, sa, c.mu, ev->weight, ev->pdf_ratio);
        }
        if (amax > 1.0f)
            murk_warn_majorant(m, "spectral MIS weights");
        if (murk_collisions_choice(&c, rng) < q[hero]) {
            for (int k = 0; k < 3; k++) {
                ev->weight.c[k] *= (fields && (m->fields & MURK_FIELD_ALBEDO) ? ss[k] : dens * m->d->sigma_s.c[k]) /
                                   (c.mu * q[hero]);
                ev->pdf_ratio.c[k] *= q[k] / q[hero];
            }
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        for (int k = 0; k < 3; k++) {
            ev->weight.c[k] *= (1.0f - a[k]) / (1.0f - q[hero]);
            ev->pdf_ratio.c[k] *= (1.0f - q[k]) / (1.0f - q[hero]);
        }
        if (np)
            ev->null_prob *= 1.0f - q[hero];
        murk_collisions_raise(&c, amax);
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) */
        murk_event_kill(ev, c.t);
}

static void smis_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                        murk_medium_event *ev)
{
    const smis *m = self;
    if (m->base.fields || (m->base.d->integrator_minor >= MURK_ABI_MINOR_FIELDS && (ctx->flags & MURK_CTX_NULL_PROB)))
        smis_flight(m, ray, ctx, rng, ev, 1);
    else
        smis_flight(m, ray, ctx, rng, ev, 0);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, smis_create, murk_tracker_free,
                                  smis_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("spectral_mis",
                   "spectral MIS (Miller et al. 2019): hero-channel tracking, balance heuristic over channels",
                   params, P_COUNT, &vt)
