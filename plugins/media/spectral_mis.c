/* spectral_mis — unidirectional spectral MIS (Miller, Georgiev, Jarosz 2019).
 *
 * Parameters
 *   closed_form  bool, default false. A flight whose majorant cells all hold a constant density (max ==
 *              min: a `constant` field, or constant regions of a grid at majorant_factor 1) is sampled in
 *              closed form instead: the hero channel's own exponential, cell by cell, and each channel k
 *              weighted by its own exponential over the hero's (the balance heuristic over channels, as
 *              in Tungsten's homogeneous medium): no null collisions, no density lookups. Any other
 *              flight is tracked as below. Same expected image (tests/test_media.c); less noise per
 *              sample in homogeneous chromatic media (docs/results.md).
 *
 * Each path has a hero channel h, chosen uniformly by the integrator. Free flights are delta-tracked
 * with the hero channel's extinction against one majorant shared by all channels (mu = max density of
 * the grid cell x max channel of sigma_t): a tentative collision at x is real with probability
 * q_h = sigma_t,h(x) / mu. Because the majorant is common, the distance pdfs are equal for every channel
 * and only the event choices differ: channel k's own technique would have chosen the same event with
 * q_k (real) or 1 - q_k (null). The tracker returns
 *     weight_c = f_c / p_h   (real: sigma_s,c(x) / (mu q_h); null: (1 - sigma_t,c(x)/mu) / (1 - q_h))
 *     pdf_k    = p_k / p_h   (real: q_k / q_h;              null: (1 - q_k) / (1 - q_h))
 * and the integrator divides the path's product of weights by the mean over channels of the product
 * of pdf ratios: the balance heuristic over channels, applied to the whole path (not per segment),
 * together with NEE. A channel whose extinction differs wildly from the hero's no longer blows up the
 * weights as in per-channel delta tracking: some hero samples it well. Where the majorant fails to
 * bound, q_k = |a| / (|a| + |1 - a|) keeps every technique valid (weighted, unbiased), the rest of the
 * flight is tracked with the majorant raised (murk_collisions_raise: the same raise for every channel's
 * technique, so the distance pdfs stay equal) and murk says so once. Shadow rays use residual ratio tracking (murk_tracker_transmittance). */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_CLOSED_FORM, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CLOSED_FORM] = {"closed_form", MURK_PARAM_BOOL, 0, {0, 0, 0}, NULL, NULL, 0, 1,
                       "flights through constant-density cells: the hero channel's exponential in closed form"},
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
 * distance wherever it lies. *first says whether the flight's slot is still unused. */
static int smis_closed_form(const murk_tracker *m, const murk_ray *ray, int hero, murk_rng *rng, murk_medium_event *ev,
                            float *from, int *first)
{
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
            tau = -log1pf(-murk_flight_float(rng, first, &uc));
        float sh = dmax * m->sigma_t.c[hero], len = b - a;
        float x = sh > 0.0f ? tau / sh : INFINITY;
        tau -= sh * len;
        if (x < len) {
            float ph = sh * expf(-sh * x);
            for (int k = 0; k < 3; k++) {
                float sk = dmax * m->sigma_t.c[k], pk = sk * expf(-sk * x);
                ev->weight.c[k] *= dmax * m->d->sigma_s.c[k] * expf(-sk * x) / ph;
                ev->pdf_ratio.c[k] *= pk / ph;
            }
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

static void smis_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                        murk_medium_event *ev)
{
    const murk_tracker *m = self;
    int hero = ctx->hero;
    murk_event_init(ev, ray);
    if (!(m->smax > 0.0f))
        return;
    murk_ray rest = *ray;
    int first = murk_flight_stratified(m->d);
    if (((const smis *)self)->closed_form && smis_closed_form(m, ray, hero, rng, ev, &rest.tmin, &first))
        return;
    murk_collisions c;
    murk_collisions_init(&c, m, &rest, m->smax); /* one majorant for every channel */
    c.first = first; /* 0 if the closed-form part took the flight's slot */
    float t, dens;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a[3], q[3], amax = 0.0f;
        for (int k = 0; k < 3; k++) {
            a[k] = dens * m->sigma_t.c[k] / c.mu;
            q[k] = murk_real_prob(a[k], 1.0f - a[k]);
            amax = murk_maxf(amax, a[k]);
        }
        if (amax > 1.0f)
            murk_warn_majorant(m, "spectral MIS weights");
        if (murk_collisions_choice(&c, rng) < q[hero]) {
            for (int k = 0; k < 3; k++) {
                ev->weight.c[k] *= dens * m->d->sigma_s.c[k] / (c.mu * q[hero]);
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
        murk_collisions_raise(&c, amax);
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) */
        murk_event_kill(ev, c.t);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, smis_create, murk_tracker_free,
                                  smis_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("spectral_mis", "spectral MIS (Miller et al. 2019): hero-channel tracking, balance heuristic over channels",
                   params, P_COUNT, &vt)
