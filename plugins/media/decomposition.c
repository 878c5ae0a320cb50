/* decomposition — decomposition tracking (Kutz, Habel, Li, Novák 2017, "Spectral and decomposition
 * tracking for rendering heterogeneous volumes", §4): each majorant cell's extinction is split into a
 * homogeneous control part, sampled in closed form, and a residual delta-tracked against the residual
 * majorant; shadow rays take the control in closed form and ratio-track the residual. The expected image
 * does not depend on `control`, only noise and time do. Parameters: `murk plugins decomposition`; the
 * derivation and the stratified first draw: docs/trackers.md#decomposition. */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_CONTROL, P_REPAIR, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CONTROL] = {"control", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 10,
                   "the control density of a majorant cell as a multiple of the cell's minimum density (the core's "
                   "minorant grid). In [0, 1] the control never exceeds the local density, so every control "
                   "collision is real and the residual is >= 0. Above 1 it can exceed the density; with repair "
                   "it is clamped to 1 (said once at load). 0 is plain delta tracking. The image does not depend "
                   "on it, only the noise and the time do"},
    [P_REPAIR] = {"repair", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                  "true clamps a control above 1 to 1, the largest control that stays below the density "
                  "everywhere (no bias, no extra noise). false keeps it: where a residual collision finds the "
                  "control above the density (a negative residual) it is weighted (unbiased), the rest of the "
                  "flight is tracked with the control lowered below the density seen (murk/tracking.h's "
                  "per-flight repair; noisier than the clamp), and murk says so once"},
};

typedef struct decomposition {
    murk_tracker base;
    float smin, control;
} decomposition;

static int decomposition_create(const murk_host *host, const murk_medium_data *data, const murk_value *p,
                                void **self, char *err, size_t errlen)
{
    decomposition *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->smin = murk_minf(m->base.sigma_t.c[0], murk_minf(m->base.sigma_t.c[1], m->base.sigma_t.c[2]));
    m->control = (float)p[P_CONTROL].f[0];
    m->base.plugin = "decomposition";
    if (m->control > 1.0f && p[P_REPAIR].f[0] != 0.0) {
        host->log(MURK_LOG_WARN,
                  "medium '%s': decomposition control %g > 1 would exceed the local density (each cell's control is "
                  "control x its minimum density): murk clamps it to 1, the largest control that stays below the "
                  "density everywhere (no bias, no extra noise; repair: false keeps it)", data->name, m->control);
        m->control = 1.0f;
    } else if (m->control > 1.0f) {
        host->log(MURK_LOG_WARN,
                  "medium '%s': decomposition control %g > 1 with repair: false can exceed the local density "
                  "(negative residual): violating residual collisions are weighted and the flight's control "
                  "lowered below the density seen (unbiased; noisier than repair: true)", data->name, m->control);
    }
    *self = m;
    return 0;
}

/* A cell's two Poisson rates for this flight: control collisions rate_c = control x dmin x smin x cscale
 * (real in every channel) and residual tentative collisions mu_r (>= |max extinction - rate_c|, x boost).
 * cscale < 1 and boost > 1 are this flight's repairs where the control or the majorant failed. */
static void decomposition_rates(const decomposition *m, float dmax, float dmin, float cscale, float boost,
                                float *rate_c, float *mu_r)
{
    *rate_c = m->control * dmin * m->smin * cscale;
    float r = dmax * m->base.smax - *rate_c;
    *mu_r = murk_maxf(fabsf(r), 1e-3f * murk_maxf(dmax * m->base.smax, *rate_c)) * boost;
}

/* A process's next optical depth -ln(1 - u): what *carried holds (from an earlier cell; then -1), else a
 * new number (the slot's while *first). *keep gets the depth when it is one to carry on at the cell's end
 * (the slot's first number with sobol, or a carried one), else 0. Inlined: it runs at every tentative collision. */
static MURK_ALWAYS_INLINE float decomposition_depth(murk_rng *rng, int *first, float *uc, float *carried, float *keep)
{
    float tau;
    int carry = *carried >= 0.0f;
    if (carry) {
        tau = *carried;
        *carried = -1.0f;
    } else {
        carry = *first && rng->sampler == MURK_SAMPLER_SOBOL;
        tau = murk_exp1(murk_flight_float(rng, first, uc));
    }
    *keep = carry ? murk_maxf(tau, 1e-30f) : 0.0f;
    return tau;
}

/* Says once that a residual collision met a bound that failed: the control above the density (amin < 0)
 * or the density above the majorant (amax > 1). */
static void decomposition_warn(const decomposition *m, float amin, float amax)
{
    if (amin < 0.0f)
        m->base.host->warn_once("medium '%s': decomposition control exceeds the local density (repair: false): "
                                "decomposition tracking weights the violating residual collision and lowers the "
                                "rest of the flight's control below the density seen (unbiased; noisier than "
                                "repair: true)", m->base.d->name);
    if (amax > 1.0f)
        murk_warn_majorant(&m->base, "decomposition tracking weights");
}

/* The watchdog (murk/plugin.h) stopped the flight at t: said once, the path ends. */
static void decomposition_stop(const decomposition *m, murk_medium_event *ev, float t)
{
    murk_tracker_watchdog(&m->base, "a free flight");
    murk_event_kill(ev, t);
}

/* The medium's fields at a tentative collision at t (rate mu: control + residual): the local sigma_a and
 * sigma_s into sa, ss, and the emission score (murk/tracking.h). */
static void decomposition_fields(const decomposition *m, const murk_ray *ray, const murk_path_ctx *ctx,
                                 murk_medium_event *ev, float t, float dens, float mu, float sa[3], float ss[3])
{
    murk_vec3 p = murk_madd(ray->o, ray->d, t);
    murk_local_sigma(&m->base, p, dens, sa, ss);
    if (murk_emitting(&m->base))
        murk_emit(&m->base, ctx, ev, p, sa, mu, ev->weight, murk_rgb1(1.0f));
}

/* One free flight; `fields` (a constant at each call) adds the medium's albedo field and emission: the
 * instance without them is decomposition tracking as it always was. */
static MURK_ALWAYS_INLINE void decomposition_flight(const decomposition *m, const murk_ray *ray,
                                                    const murk_path_ctx *ctx, murk_rng *rng, murk_medium_event *ev,
                                                    int fields)
{
    const murk_host *h = m->base.host;
    const murk_medium_data *d = m->base.d;
    const murk_rgb st = m->base.sigma_t;
    murk_event_init(ev, ray);
    if (!(m->base.smax > 0.0f))
        return;
    murk_counters scratch, *count = murk_tracker_counters(h, d, &scratch);
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin, cscale = 1.0f, boost = 1.0f;
    int first = murk_flight_stratified(d); /* the flight's first numbers from the sampler (murk/tracking.h) */
    float uc = -1.0f;
    /* with sobol, the optical depth the first number has left for the process it started (control: tau_c,
     * residual: tau_r), carried to the next cell where that process has a rate; -1: none */
    float tau_c = -1.0f, tau_r = -1.0f;
    long steps = 0; /* the watchdog (murk/plugin.h): cells and collisions of this flight */
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        if (++steps > MURK_WATCHDOG_ITERATIONS) {
            decomposition_stop(m, ev, ta);
            return;
        }
        float rate_c, mu_r;
        decomposition_rates(m, dmax, dmin, cscale, boost, &rate_c, &mu_r);
        if (!(rate_c > 0.0f) && !(mu_r > 0.0f))
            continue;
        float tc = INFINITY, dc = 0.0f; /* dc: the optical depth tc was drawn with, if it is carried on */
        if (rate_c > 0.0f)
            tc = murk_advance(ta, decomposition_depth(rng, &first, &uc, &tau_c, &dc) / rate_c);
        for (float t = ta;;) {
            if (++steps > MURK_WATCHDOG_ITERATIONS) {
                decomposition_stop(m, ev, t);
                return;
            }
            float tr = INFINITY, dr = 0.0f;
            if (mu_r > 0.0f)
                tr = murk_advance(t, decomposition_depth(rng, &first, &uc, &tau_r, &dr) / mu_r);
            if (!(tc < tb) && !(tr < tb)) { /* the cell passed: what a carried number has left goes on */
                if (dc > 0.0f)
                    tau_c = murk_maxf(0.0f, dc - rate_c * (tb - ta));
                if (dr > 0.0f)
                    tau_r = murk_maxf(0.0f, dr - mu_r * (tb - t));
                break;
            }
            count->collisions++; /* a control or a residual collision */
            float sa[3] = {0}, ss[3] = {0}; /* with fields: the local coefficients (albedo field, emission) */
            if (fields && tc <= tr)
                decomposition_fields(m, ray, ctx, ev, tc, h->density(d->density, murk_madd(ray->o, ray->d, tc)),
                                     rate_c + mu_r, sa, ss);
            if (tc <= tr) { /* control collision */
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= st.c[k] > 0.0f ? (fields ? murk_ratio0(ss[k], sa[k] + ss[k])
                                                               : d->sigma_s.c[k] / st.c[k]) : 0.0f;
                ev->scattered = 1;
                ev->t = tc;
                return;
            }
            t = tr;
            float dens = h->density(d->density, murk_madd(ray->o, ray->d, t));
            if (fields)
                decomposition_fields(m, ray, ctx, ev, t, dens, rate_c + mu_r, sa, ss);
            float a[3], amin = INFINITY, amax = -INFINITY;
            for (int k = 0; k < 3; k++) { /* residual share of channel k */
                a[k] = (dens * st.c[k] - rate_c) / mu_r;
                amin = murk_minf(amin, a[k]);
                amax = murk_maxf(amax, a[k]);
            }
            if (amin < 0.0f || amax > 1.0f) /* a bound failed: said once */
                decomposition_warn(m, amin, amax);
            float q = murk_collision_prob(&m->base, a, ctx, ev->weight);
            if (murk_flight_choice(rng, &uc) < q) {
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= st.c[k] > 0.0f ? a[k] / q * (fields ? murk_ratio0(ss[k], dens * st.c[k])
                                                                          : d->sigma_s.c[k] / st.c[k]) : 0.0f;
                ev->scattered = 1;
                ev->t = t;
                return;
            }
            if (!m->base.grey || amin < 0.0f || amax > 1.0f)
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= (1.0f - a[k]) / (1.0f - q);
            if (amin < 0.0f || amax > 1.0f) {
                /* the flight's repair (unbiased, murk/tracking.h): the rest of it, from t on, with the
                 * control below the density seen here and the residual majorant above it; the pending
                 * control distance is redrawn at the new rate (both processes are memoryless) */
                if (amin < 0.0f)
                    cscale *= murk_maxf(0.0f, dens * m->smin / (rate_c * MURK_MAJORANT_RAISE));
                if (amax > 1.0f)
                    boost = murk_minf(boost * MURK_MAJORANT_RAISE * amax, 1e12f);
                decomposition_rates(m, dmax, dmin, cscale, boost, &rate_c, &mu_r);
                tc = rate_c > 0.0f ? murk_advance(t, murk_sample_exp(rng, rate_c)) : INFINITY;
                dc = 0.0f;
            }
        }
    }
}

static void decomposition_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                                 murk_medium_event *ev)
{
    const decomposition *m = self;
    if (m->base.fields)
        decomposition_flight(m, ray, ctx, rng, ev, 1);
    else
        decomposition_flight(m, ray, ctx, rng, ev, 0);
}

static murk_rgb decomposition_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx,
                                            murk_rng *rng)
{
    (void)ctx;
    const decomposition *m = self;
    /* shadow rays always with the control clamped to the cell's minimum density: a control above the density
     * makes the closed-form part overshoot by exp(-(c - density) sigma L), which ratio tracking must undo
     * with weights that grow like exp(+...) — unbiased but heavy-tailed (docs/stability.md) */
    return murk_ratio_tracking(m->base.host, m->base.d, ray, murk_minf(m->control, 1.0f), rng);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, decomposition_create,
                                  murk_tracker_free, decomposition_sample, decomposition_transmittance};

MURK_MEDIUM_PLUGIN("decomposition", "decomposition tracking (Kutz et al. 2017): closed-form control + tracked residual",
                   params, P_COUNT, &vt)
