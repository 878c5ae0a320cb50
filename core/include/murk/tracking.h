/* murk/tracking.h — small helpers for tracker (medium plugin) authors: free-flight distances,
 * weighted collision choices that stay unbiased when a majorant fails to bound, and ratio-tracking
 * transmittance over the core's majorant grid. Header-only; include after murk/medium.h. */
#ifndef MURK_TRACKING_H
#define MURK_TRACKING_H

#include "murk/medium.h"

/* Extinction per unit density. */
static inline murk_rgb murk_sigma_t(const murk_medium_data *d) { return murk_rgb_add(d->sigma_a, d->sigma_s); }

/* Distance to the next event of a Poisson process of rate mu > 0. */
static inline float murk_sample_exp(murk_rng *rng, float mu) { return -log1pf(-murk_rng_float(rng)) / mu; }

/* Probability of taking the "real" branch of a collision whose real and null weights (each relative to
 * the majorant, real + null = 1) are a and b. For a bounding majorant (a, b >= 0) this is a itself:
 * plain delta tracking. When the majorant fails (b < 0, or a control above the density makes a < 0)
 * the branches are chosen in proportion to |a| and |b| and weighted by a/q and b/(1-q): still
 * unbiased, with weights that may exceed 1 or go negative. */
static inline float murk_real_prob(float a, float b)
{
    float s = fabsf(a) + fabsf(b);
    return s > 0.0f ? fabsf(a) / s : 0.0f;
}

/* Ratio tracking (Novak et al. 2014) over (ray->tmin, ray->tmax) with majorant segments from the
 * walk; extra: a second density-proportional extinction that is handled in closed form instead
 * (decomposition's control, per unit density-of-control), NULL for none. Russian roulette on small
 * transmittance (survival probability = the largest channel, once below 0.1) keeps long, dense shadow
 * rays cheap without bias. */
static inline murk_rgb murk_ratio_tracking(const murk_host *h, const murk_medium_data *d, const murk_ray *ray,
                                           float control, murk_rng *rng)
{
    murk_rgb st = murk_sigma_t(d), T = murk_rgb1(1.0f);
    float smax = murk_rgb_max(st);
    if (!(smax > 0.0f))
        return T;
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin;
    long steps = 0;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        float c = control * dmin; /* control density, handled in closed form */
        if (c > 0.0f) {
            float len = tb - ta;
            if (!isfinite(len))
                return murk_rgb1(0.0f);
            for (int k = 0; k < 3; k++)
                T.c[k] *= expf(-c * st.c[k] * len);
        }
        /* residual majorant; any positive value keeps ratio tracking unbiased, so a control above the
         * majorant only costs variance */
        float mu = fmaxf(fabsf(dmax - c), 1e-3f * fmaxf(dmax, c)) * smax;
        if (!(mu > 0.0f))
            continue;
        for (float t = ta;;) {
            t += murk_sample_exp(rng, mu);
            if (!(t < tb))
                break;
            murk_vec3 p = murk_madd(ray->o, ray->d, t);
            float dens = h->density(d->density, p) - c;
            for (int k = 0; k < 3; k++)
                T.c[k] *= 1.0f - dens * st.c[k] / mu;
            float tm = fmaxf(fabsf(T.c[0]), fmaxf(fabsf(T.c[1]), fabsf(T.c[2])));
            if (tm < 0.1f) {
                if (tm <= 0.0f || murk_rng_float(rng) >= tm)
                    return murk_rgb1(0.0f);
                T = murk_rgb_scale(T, 1.0f / tm);
            }
            if (++steps > 100000000L) {
                h->warn_once("medium '%s': ratio tracking gave up after 1e8 steps (transmittance set to 0: biased)",
                             d->name);
                return murk_rgb1(0.0f);
            }
        }
    }
    return T;
}

#endif
