/* raymarch — BIASED BY DESIGN: classic ray marching, T_c = exp(-sigma_t,c D^) with D^ a fixed-step
 * estimate of the density integral. A baseline for the unbiased estimators: its error does not vanish
 * with more samples, only with a smaller step, and is never zero on a heterogeneous medium. murk logs a
 * one-line notice when a scene uses it. Parameters: `murk plugins raymarch`; the bias:
 * docs/trackers.md#raymarch. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_STEP, P_JITTER, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_STEP] = {"step", MURK_PARAM_FLOAT, 0, {0.05, 0, 0}, NULL, NULL, 1e-4, 100,
                "the ray-marching step in world units: each majorant cell crossed is marched in ceil(length / "
                "step) equal steps (cells whose majorant is 0 are skipped: no lookups, and infinite rays end at "
                "the field's box). BIASED: the error shrinks with the step (tests/test_transmittance.c, "
                "docs/results.md), never to 0 on a heterogeneous medium"},
    [P_JITTER] = {"jitter", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                  "true: one uniform offset per march, so the density integral is unbiased but its exponential "
                  "is not (by Jensen's inequality it is biased upwards, by about sigma^2 Var / 2 x T); false: the "
                  "deterministic midpoint rule, biased by its quadrature error (and aliasing on grids)"},
};

typedef struct raymarch {
    murk_tracker base;
    float step;
    int jitter;
} raymarch;

static int rm_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                     char *err, size_t errlen)
{
    raymarch *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->step = (float)p[P_STEP].f[0];
    m->jitter = p[P_JITTER].f[0] != 0.0;
    host->log(MURK_LOG_WARN,
              "medium '%s': transmittance 'raymarch' (step %g%s) is BIASED by design: shadow rays are "
              "ray-marched, the image differs from every unbiased estimator's by an error that shrinks with the step",
              data->name, (double)m->step, m->jitter ? ", jittered" : ", midpoint");
    *self = m;
    return 0;
}

static murk_rgb rm_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const raymarch *m = self;
    if (!(m->base.smax > 0.0f))
        return murk_rgb1(1.0f);
    float u = m->jitter ? murk_rng_float(rng) : 0.5f;
    double D = murk_march_depth(m->base.host, m->base.d, ray, m->step, 0.0f, m->base.smax, u, NULL);
    if (isinf(D))
        return murk_rgb1(0.0f);
    murk_rgb T;
    for (int c = 0; c < 3; c++)
        T.c[c] = (float)exp(-(double)m->base.sigma_t.c[c] * D);
    return T;
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, rm_create,
                                         murk_tracker_free, rm_estimate};

MURK_TRANSMITTANCE_PLUGIN("raymarch", "BIASED ray marching with a fixed step (a baseline; not unbiased, by design)",
                          params, P_COUNT, &vt)
