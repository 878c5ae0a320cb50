/* spectral — spectral tracking (Kutz, Habel, Li, Novak 2017, §5): one majorant over all channels,
 * one free flight for all of them, per-channel weights.
 *
 * Parameters
 *   probabilities  enum max | average | history, default history. How the absorption, scattering and
 *                  null-collision probabilities at a tentative collision are chosen from the
 *                  per-channel coefficients sigma_x,c(x) (x = a, s, n; sigma_n,c = mu - sigma_t,c(x)):
 *                    max      P_x ~ max_c |sigma_x,c|
 *                    average  P_x ~ mean_c |sigma_x,c|
 *                    history  P_x ~ mean_c |w_c sigma_x,c| with w the path's weight so far (Kutz et al.'s
 *                             history-aware choice: keeps the weights bounded for chromatic media)
 *
 * The majorant is mu = max density of the grid cell x max channel of sigma_t. An absorption event ends
 * the path (weight 0), a scattering event weights channel c by sigma_s,c / (mu P_s), a null event by
 * sigma_n,c / (mu P_n). Unbiased for any choice of probabilities that is non-zero wherever the
 * coefficient is; where the majorant fails to bound (sigma_n < 0) the absolute values keep it so, with
 * negative weights, and murk says so once. Shadow rays use ratio tracking. */
#include "murk/medium.h"
#include "murk/tracking.h"

#include <stdio.h>

enum { P_PROBABILITIES, P_COUNT };
enum { PROB_MAX, PROB_AVERAGE, PROB_HISTORY };

static const murk_param params[P_COUNT] = {
    [P_PROBABILITIES] = {"probabilities", MURK_PARAM_ENUM, 0, {0, 0, 0}, "history", "max|average|history", 0, 0,
                         "collision-type probabilities: max, average or history-aware (Kutz et al. 2017)"},
};

typedef struct spectral {
    const murk_host *host;
    const murk_medium_data *d;
    murk_rgb sigma_t;
    float smax;
    int scheme;
} spectral;

static int spectral_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                           char *err, size_t errlen)
{
    if (host->size < sizeof(murk_host)) {
        snprintf(err, errlen, "this murk's host table lacks the media services");
        return -1;
    }
    spectral *m = host->alloc(sizeof *m);
    if (!m)
        return -1;
    m->host = host;
    m->d = data;
    m->sigma_t = murk_sigma_t(data);
    m->smax = murk_rgb_max(m->sigma_t);
    m->scheme = p[P_PROBABILITIES].choice;
    *self = m;
    return 0;
}

static void spectral_destroy(void *self)
{
    spectral *m = self;
    if (m)
        m->host->free(m);
}

static float pick(int scheme, const float x[3], const float w[3])
{
    if (scheme == PROB_MAX)
        return fmaxf(fabsf(x[0]), fmaxf(fabsf(x[1]), fabsf(x[2])));
    if (scheme == PROB_AVERAGE)
        return (fabsf(x[0]) + fabsf(x[1]) + fabsf(x[2])) / 3.0f;
    return (fabsf(w[0] * x[0]) + fabsf(w[1] * x[1]) + fabsf(w[2] * x[2])) / 3.0f;
}

static int spectral_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                           murk_medium_event *ev)
{
    const spectral *m = self;
    const murk_host *h = m->host;
    ev->scattered = 0;
    ev->t = ray->tmax;
    ev->weight = murk_rgb1(1.0f);
    ev->pdf = murk_rgb1(1.0f);
    if (!(m->smax > 0.0f))
        return 0;
    murk_majorant_walk w;
    h->walk_init(m->d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        float mu = dmax * m->smax;
        if (!(mu > 0.0f))
            continue;
        for (float t = ta;;) {
            t += murk_sample_exp(rng, mu);
            if (!(t < tb))
                break;
            float dens = h->density(m->d->density, murk_madd(ray->o, ray->d, t));
            float sa[3], ss[3], sn[3], hist[3];
            int neg = 0;
            for (int k = 0; k < 3; k++) {
                sa[k] = dens * m->d->sigma_a.c[k];
                ss[k] = dens * m->d->sigma_s.c[k];
                sn[k] = mu - dens * m->sigma_t.c[k];
                neg |= sn[k] < 0.0f;
                hist[k] = ctx->beta.c[k] * ev->weight.c[k];
            }
            if (neg)
                h->warn_once("medium '%s': density exceeds the majorant (majorant_factor < 1?): spectral tracking "
                             "uses negative null weights (unbiased, noisier)", m->d->name);
            float pa = pick(m->scheme, sa, hist), ps = pick(m->scheme, ss, hist), pn = pick(m->scheme, sn, hist);
            float sum = pa + ps + pn;
            if (!(sum > 0.0f)) { /* the path carries no weight in any channel */
                ev->weight = murk_rgb1(0.0f);
                ev->scattered = 1;
                ev->t = t;
                return 1;
            }
            float u = murk_rng_float(rng) * sum;
            if (u < pa) { /* absorbed: no emission in murk's media, the path ends */
                ev->weight = murk_rgb1(0.0f);
                ev->scattered = 1;
                ev->t = t;
                return 1;
            }
            if (u < pa + ps) {
                float P = ps / sum;
                for (int k = 0; k < 3; k++)
                    ev->weight.c[k] *= ss[k] / (mu * P);
                ev->scattered = 1;
                ev->t = t;
                return 1;
            }
            float P = pn / sum;
            for (int k = 0; k < 3; k++)
                ev->weight.c[k] *= sn[k] / (mu * P);
        }
    }
    return 0;
}

static murk_rgb spectral_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx,
                                       murk_rng *rng)
{
    (void)ctx;
    const spectral *m = self;
    return murk_ratio_tracking(m->host, m->d, ray, 0.0f, rng);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), spectral_create, spectral_destroy, spectral_sample,
                                  spectral_transmittance};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_MEDIUM, "spectral",
    "spectral tracking (Kutz et al. 2017): one majorant, per-channel weights", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
