/* delta — delta (Woodcock) tracking for free flights, ratio tracking for transmittance.
 *
 * Parameters: none of its own. The medium's common keys (density, sigma_a, sigma_s, scale, g,
 * majorant_factor, majorant_resolution) are read by the core.
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
 * the majorant fails to bound (majorant_factor < 1), the same weighted choice keeps the estimate
 * unbiased and murk says so once. Shadow rays use ratio tracking with Russian roulette on small
 * transmittance. */
#include "murk/medium.h"
#include "murk/tracking.h"

typedef struct delta {
    murk_tracker base;
    int grey;
} delta;

static int delta_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                        char *err, size_t errlen)
{
    (void)params;
    delta *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->grey = m->base.sigma_t.c[0] == m->base.sigma_t.c[1] && m->base.sigma_t.c[1] == m->base.sigma_t.c[2];
    if (!m->grey)
        host->log(MURK_LOG_INFO,
                  "medium '%s': delta tracking with chromatic extinction: collisions are chosen with history-aware "
                  "probabilities and weighted per channel (spectral tracking)", data->name);
    *self = m;
    return 0;
}

static int delta_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                        murk_medium_event *ev)
{
    const delta *m = self;
    const murk_medium_data *d = m->base.d;
    murk_event_init(ev, ray);
    if (!(m->base.smax > 0.0f))
        return 0;
    murk_collisions c;
    murk_collisions_init(&c, &m->base, ray, m->base.smax);
    float t, dens;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float q, amax = 0.0f;
        if (m->grey) {
            float a = dens * m->base.sigma_t.c[0] / c.mu; /* real share of the collision */
            amax = a;
            q = murk_real_prob(a, 1.0f - a);
        } else { /* history-aware choice over channels */
            float pr = 0.0f, pn = 0.0f;
            for (int k = 0; k < 3; k++) {
                float h = fabsf(ctx->beta.c[k] * ev->weight.c[k]), a = dens * m->base.sigma_t.c[k] / c.mu;
                amax = a > amax ? a : amax;
                pr += h * fabsf(a);
                pn += h * fabsf(1.0f - a);
            }
            q = pr + pn > 0.0f ? pr / (pr + pn) : 0.5f;
        }
        if (amax > 1.0f)
            m->base.host->warn_once("medium '%s': density exceeds the majorant (majorant_factor < 1?): delta "
                                    "tracking switches to weighted collisions (unbiased, noisier)", d->name);
        if (murk_rng_float(rng) < q) {
            for (int k = 0; k < 3; k++) /* sigma_s,k(x) / (mu q): the albedo for grey extinction */
                ev->weight.c[k] *= dens * d->sigma_s.c[k] / (c.mu * q);
            ev->scattered = 1;
            ev->t = t;
            return 1;
        }
        if (!m->grey || amax > 1.0f)
            for (int k = 0; k < 3; k++)
                ev->weight.c[k] *= (c.mu - dens * m->base.sigma_t.c[k]) / (c.mu * (1.0f - q));
    }
    return 0;
}

static murk_rgb delta_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const delta *m = self;
    return murk_ratio_tracking(m->base.host, m->base.d, ray, 0.0f, rng);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), delta_create, murk_tracker_free, delta_sample,
                                  delta_transmittance};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_MEDIUM, "delta",
    "delta tracking free flights, ratio tracking transmittance", NULL, 0, &vt,
};

MURK_PLUGIN(&desc)
