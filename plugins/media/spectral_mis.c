/* spectral_mis — unidirectional spectral MIS (Miller, Georgiev, Jarosz 2019).
 *
 * Parameters: none of its own.
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

static int smis_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                       char *err, size_t errlen)
{
    (void)params;
    murk_tracker *m = murk_tracker_new(host, data, sizeof(murk_tracker), err, errlen);
    if (m)
        m->plugin = "spectral_mis";
    return (*self = m) ? 0 : -1;
}

static void smis_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                        murk_medium_event *ev)
{
    const murk_tracker *m = self;
    int hero = ctx->hero;
    murk_event_init(ev, ray);
    if (!(m->smax > 0.0f))
        return;
    murk_collisions c;
    murk_collisions_init(&c, m, ray, m->smax); /* one majorant for every channel */
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
                   NULL, 0, &vt)
