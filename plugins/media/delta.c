/* delta — delta (Woodcock) tracking for free flights (Woodcock, Murphy, Hemmings, Longworth 1965), cell by
 * cell against the core's majorant grid; with chromatic extinction the real/null choice is history-aware
 * and every channel reweighted (after Kutz, Habel, Li, Novák 2017: unbiased, bounded weights). Shadow
 * rays use residual ratio tracking (Novák, Selle, Jarosz 2014; murk_tracker_transmittance). No
 * parameters of its own (`murk plugins delta` lists the medium keys); the weights: docs/trackers.md#delta. */
#include "murk/medium.h"
#include "murk/tracking.h"

static int delta_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                        char *err, size_t errlen)
{
    (void)params;
    murk_tracker *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->plugin = "delta";
    if (!m->grey)
        host->log(MURK_LOG_INFO,
                  "medium '%s': delta tracking with chromatic extinction: collisions are chosen with history-aware "
                  "probabilities and weighted per channel (spectral tracking)", data->name);
    *self = m;
    return 0;
}

static void delta_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                         murk_medium_event *ev)
{
    const murk_tracker *m = self;
    murk_event_init(ev, ray);
    if (!(m->smax > 0.0f))
        return;
    murk_collisions c;
    murk_collisions_init(&c, m, ray, m->smax);
    float t, dens;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a[3], amax = 0.0f; /* real share of the collision per channel */
        for (int k = 0; k < 3; k++) {
            a[k] = dens * m->sigma_t.c[k] / c.mu;
            amax = murk_maxf(amax, a[k]);
        }
        if (amax > 1.0f)
            murk_warn_majorant(m, "delta tracking weights");
        float q = murk_collision_prob(m, a, ctx, ev->weight);
        if (murk_collisions_choice(&c, rng) < q) {
            for (int k = 0; k < 3; k++) /* sigma_s,k(x) / (mu q): the albedo for grey extinction */
                ev->weight.c[k] *= dens * m->d->sigma_s.c[k] / (c.mu * q);
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        if (!m->grey || amax > 1.0f)
            for (int k = 0; k < 3; k++)
                ev->weight.c[k] *= (1.0f - a[k]) / (1.0f - q);
        murk_collisions_raise(&c, amax);
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) */
        murk_event_kill(ev, c.t);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, delta_create, murk_tracker_free,
                                  delta_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("delta",
                   "delta (Woodcock) tracking; residual ratio tracking for shadow rays (as every tracker by default)",
                   NULL, 0, &vt)
