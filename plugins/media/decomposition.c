/* decomposition — decomposition tracking (Kutz, Habel, Li, Novak 2017, §4): the extinction of each
 * majorant-grid cell is split into a homogeneous control part, sampled in closed form, and a residual
 * tracked with delta tracking against the residual majorant.
 *
 * Parameters
 *   control  float in [0, 10], default 1. The control density of a cell is control x the cell's
 *            minimum density (from the core's minorant grid). In [0, 1] the control never exceeds the
 *            local density, so every control collision is real and the residual is >= 0. Above 1 the
 *            control can exceed the density: the residual goes negative and murk switches to weighted
 *            residual collisions (unbiased, noisier) and says so once. 0 is plain delta tracking.
 *
 * Per cell: control rate sigma_c = c sigma_t (c = control x minorant), residual majorant
 * mu_r = (max density - c) max_c sigma_t. The first of a control event (always real) and a residual
 * tentative event (real with probability (d(x) - c) sigma_t / mu_r) decides the flight; both processes
 * are memoryless, so a pending control distance survives a null residual event. A real collision
 * scatters with weight albedo. The total real-collision rate is c sigma_t + (d(x) - c) sigma_t =
 * d(x) sigma_t: the expected image does not depend on `control` — only noise and time do.
 * With chromatic extinction the channel-average rates are sampled and every channel reweighted (the
 * control part by exp(-(sigma_c,k - mean sigma_c) s) and sigma_c,k / mean sigma_c), which stays unbiased.
 * Transmittance: the control part in closed form times ratio tracking of the residual. */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_CONTROL, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CONTROL] = {"control", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 10,
                   "control density as a multiple of each majorant cell's minimum density (<= 1 stays below it)"},
};

typedef struct decomposition {
    murk_tracker base;
    float savg, control;
    int grey;
} decomposition;

static int decomposition_create(const murk_host *host, const murk_medium_data *data, const murk_value *p,
                                void **self, char *err, size_t errlen)
{
    decomposition *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->savg = murk_rgb_avg(m->base.sigma_t);
    m->grey = m->base.sigma_t.c[0] == m->base.sigma_t.c[1] && m->base.sigma_t.c[1] == m->base.sigma_t.c[2];
    m->control = (float)p[P_CONTROL].f[0];
    if (m->control > 1.0f)
        host->log(MURK_LOG_WARN,
                  "medium '%s': decomposition control %g > 1 can exceed the local density (negative residual): "
                  "residual collisions become weighted (unbiased, noisier)", data->name, m->control);
    *self = m;
    return 0;
}

/* Weights channel k by the control process having been sampled at the average rate over length s. */
static void control_tilt(const decomposition *m, float c, float s, murk_rgb *w)
{
    if (c <= 0.0f || s <= 0.0f)
        return;
    for (int k = 0; k < 3; k++)
        w->c[k] *= expf(-c * (m->base.sigma_t.c[k] - m->savg) * s);
}

static int decomposition_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                                murk_medium_event *ev)
{
    (void)ctx;
    const decomposition *m = self;
    const murk_host *h = m->base.host;
    const murk_medium_data *d = m->base.d;
    murk_event_init(ev, ray);
    if (!(m->base.smax > 0.0f))
        return 0;
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        float c = m->control * dmin;
        float rate_c = c * m->savg; /* control events, sampled at the channel-average rate */
        float mu_r = fmaxf(fabsf(dmax - c), 1e-3f * fmaxf(dmax, c)) * m->base.smax;
        if (!(rate_c > 0.0f) && !(mu_r > 0.0f))
            continue;
        float tc = rate_c > 0.0f ? ta + murk_sample_exp(rng, rate_c) : INFINITY;
        float t = ta;
        for (;;) {
            float tr = mu_r > 0.0f ? t + murk_sample_exp(rng, mu_r) : INFINITY;
            if (!(tc < tb) && !(tr < tb)) {
                if (isfinite(tb))
                    control_tilt(m, c, tb - ta, &ev->weight);
                break;
            }
            if (tc <= tr) { /* control collision: always real */
                control_tilt(m, c, tc - ta, &ev->weight);
                for (int k = 0; k < 3; k++) /* (sigma_c,k / mean sigma_c) * albedo_k */
                    ev->weight.c[k] *= d->sigma_s.c[k] / m->savg;
                ev->scattered = 1;
                ev->t = tc;
                return 1;
            }
            t = tr;
            float dens = h->density(d->density, murk_madd(ray->o, ray->d, t)) - c; /* residual density */
            if (dens < 0.0f)
                h->warn_once("medium '%s': decomposition control exceeds the local density (negative residual): "
                             "weighted residual collisions (unbiased, noisier)", d->name);
            float a = dens * m->savg / mu_r;
            float q = murk_real_prob(a, 1.0f - a);
            if (murk_rng_float(rng) < q) {
                control_tilt(m, c, t - ta, &ev->weight);
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= dens * d->sigma_s.c[k] / (mu_r * q);
                ev->scattered = 1;
                ev->t = t;
                return 1;
            }
            if (dens < 0.0f || a > 1.0f || !m->grey)
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= (1.0f - dens * m->base.sigma_t.c[k] / mu_r) / (1.0f - q);
        }
    }
    return 0;
}

static murk_rgb decomposition_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx,
                                            murk_rng *rng)
{
    (void)ctx;
    const decomposition *m = self;
    return murk_ratio_tracking(m->base.host, m->base.d, ray, m->control, rng);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), decomposition_create, murk_tracker_free,
                                  decomposition_sample, decomposition_transmittance};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_MEDIUM, "decomposition",
    "decomposition tracking (Kutz et al. 2017): closed-form control + tracked residual", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
