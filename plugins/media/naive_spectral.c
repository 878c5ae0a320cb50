/* naive_spectral — per-channel delta tracking: each path delta-tracks one channel, its hero, with that
 * channel's own majorant, and the other channels get weight 0 (the integrator credits the hero with 3x
 * its estimate). Unbiased per channel, but every path carries one channel: the colour noise that spectral
 * tracking (Kutz et al. 2017) and spectral MIS (Miller et al. 2019) remove, and the baseline they are
 * measured against. Shadow rays use residual ratio tracking. No parameters of its own; details:
 * docs/trackers.md#naive_spectral. */
#include "murk/medium.h"
#include "murk/tracking.h"

static int naive_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                        char *err, size_t errlen)
{
    (void)params;
    murk_tracker *m = murk_tracker_new(host, data, sizeof(murk_tracker), err, errlen);
    if (m)
        m->plugin = "naive_spectral";
    return (*self = m) ? 0 : -1;
}

static void naive_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                         murk_medium_event *ev)
{
    const murk_tracker *m = self;
    int hero = ctx->hero;
    float st = m->sigma_t.c[hero];
    murk_event_init(ev, ray);
    ev->weight = murk_rgb1(0.0f); /* only the hero channel carries this path */
    ev->weight.c[hero] = 1.0f;
    ev->pdf_ratio = ev->weight;
    if (!(st > 0.0f))
        return;
    murk_collisions c;
    murk_collisions_init(&c, m, ray, st); /* the hero channel's own majorant */
    float t, dens;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a = dens * st / c.mu;
        if (a > 1.0f)
            murk_warn_majorant(m, "per-channel delta tracking weights");
        float q = murk_real_prob(a, 1.0f - a);
        if (murk_collisions_choice(&c, rng) < q) {
            ev->weight.c[hero] *= dens * m->d->sigma_s.c[hero] / (c.mu * q);
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        if (a > 1.0f)
            ev->weight.c[hero] *= (1.0f - a) / (1.0f - q);
        murk_collisions_raise(&c, a);
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) */
        murk_event_kill(ev, c.t);
}

/* every channel's transmittance is estimated; only the hero's carries weight in the path */
static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, naive_create, murk_tracker_free,
                                  naive_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("naive_spectral", "per-channel delta tracking (one channel per path): the baseline", NULL, 0, &vt)
