/* delta — delta (Woodcock) tracking for free flights, residual ratio tracking for transmittance.
 *
 * Parameters: none of its own. The medium's common keys (density, sigma_a, sigma_s, scale, g,
 * majorant_factor, majorant_resolution, majorant_repair, stratify_flights) are read by the core; with
 * stratify_flights the first tentative collision's optical depth and its real/null choice come from the
 * flight's sampler slot (murk_collisions, murk/tracking.h), as in spectral, spectral_mis and naive_spectral.
 *
 * Tentative collisions are drawn with the majorant mu = max density of the grid cell x max channel of
 * sigma_t, cell by cell along the ray. A tentative collision at x is real with probability
 * sigma_t(x) / mu; a real collision scatters with weight albedo = sigma_s / sigma_t per channel
 * (absorption is folded into that weight). This is classic delta tracking when the extinction is grey.
 * With chromatic extinction there is no single collision probability: the real branch is taken with
 * probability q = sum_c |h_c| sigma_t,c(x) / sum_c |h_c| (|sigma_t,c(x)| + |mu - sigma_t,c(x)|), with h the
 * path's weight so far (history-aware, after Kutz et al. 2017, which keeps the weights bounded where a
 * plain channel average lets them grow without limit), and every channel is reweighted (real:
 * sigma_s,c(x) / (mu q), null: (mu - sigma_t,c(x)) / (mu (1 - q))) — unbiased; murk says so once. Where
 * the majorant fails to bound (majorant_factor < 1 with majorant_repair: false), the same weighted choice
 * keeps the violating collision unbiased, the rest of the flight is tracked with the majorant raised
 * (murk_collisions_raise), and murk says so once. Shadow rays use residual ratio tracking (murk_tracker_transmittance: the
 * minorant grid as control) with Russian roulette on small
 * transmittance. */
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

MURK_MEDIUM_PLUGIN("delta", "delta tracking free flights, residual ratio tracking transmittance", NULL, 0, &vt)
