/* track_length — the track-length (delta-tracking) transmittance estimator: 1 if a free flight passes
 * the segment, 0 if it collides, one flight for every channel (common random numbers). The high-variance
 * baseline (Var = T (1 - T), the largest of murk's unbiased estimators; ratio tracking, Novák, Selle,
 * Jarosz 2014, is its conditional expectation). No parameters of its own; details:
 * docs/trackers.md#track_length. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

static int tl_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                     char *err, size_t errlen)
{
    (void)params;
    murk_tracker *m = murk_tracker_new(host, data, sizeof(murk_tracker), err, errlen);
    if (m)
        m->plugin = "track_length";
    return (*self = m) ? 0 : -1;
}

static murk_rgb tl_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const murk_tracker *m = self;
    murk_rgb T = murk_rgb1(1.0f);
    if (!(m->smax > 0.0f))
        return T;
    murk_collisions c;
    murk_collisions_init(&c, m, ray, m->smax);
    float t, dens;
    long steps = 0;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float u = murk_rng_float(rng);
        int alive = 0;
        for (int k = 0; k < 3; k++) {
            if (T.c[k] == 0.0f)
                continue;
            float a = dens * m->sigma_t.c[k] / c.mu;
            if (a <= 1.0f) {
                if (u < a)
                    T.c[k] = 0.0f;
            } else {
                murk_warn_majorant(m, "track_length switches to ratio-tracking weights");
                T.c[k] *= 1.0f - a;
            }
            alive |= T.c[k] != 0.0f;
        }
        if (!alive)
            return T;
        if (++steps > 100000000L) {
            m->host->warn_once("medium '%s': track_length gave up after 1e8 steps (transmittance set to 0: biased)",
                               m->d->name);
            return murk_rgb1(0.0f);
        }
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) ended the walk: reported, transmittance 0 */
        return murk_rgb1(0.0f);
    return T;
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, tl_create,
                                         murk_tracker_free, tl_estimate};

MURK_TRANSMITTANCE_PLUGIN("track_length", "track-length (binary delta-tracking) estimator: the high-variance baseline",
                          NULL, 0, &vt)
