/* spectral — spectral tracking (Kutz, Habel, Li, Novák 2017, "Spectral and decomposition tracking for
 * rendering heterogeneous volumes", §5): one majorant over all channels, one free flight for all of them;
 * absorption, scattering and null collisions are chosen with probabilities built from the per-channel
 * coefficients, and each channel is weighted by its own. Shadow rays use residual ratio tracking
 * (murk_tracker_transmittance). Parameters: `murk plugins spectral`; the weights: docs/trackers.md#spectral. */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_PROBABILITIES, P_COUNT };
enum { PROB_MAX, PROB_AVERAGE, PROB_HISTORY };

static const murk_param params[P_COUNT] = {
    [P_PROBABILITIES] = {"probabilities", MURK_PARAM_ENUM, 0, {0, 0, 0}, "history", "max|average|history", 0, 0,
                         "how the absorption, scattering and null-collision probabilities P_a, P_s, P_n of a "
                         "tentative collision are chosen from the per-channel coefficients sigma_x,c (sigma_n,c = "
                         "majorant - sigma_t,c): max, P_x ~ max_c |sigma_x,c|; average, P_x ~ mean_c |sigma_x,c|; "
                         "history, P_x ~ mean_c |w_c sigma_x,c| with w the path's weight so far (Kutz et al. "
                         "2017's history-aware choice, which keeps the weights bounded in chromatic media)"},
};

typedef struct spectral {
    murk_tracker base;
    int scheme;
} spectral;

static int spectral_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                           char *err, size_t errlen)
{
    spectral *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->scheme = p[P_PROBABILITIES].choice;
    m->base.plugin = "spectral";
    *self = m;
    return 0;
}

static float pick(int scheme, const float x[3], const float w[3])
{
    if (scheme == PROB_MAX)
        return murk_fmaxf(fabsf(x[0]), murk_fmaxf(fabsf(x[1]), fabsf(x[2])));
    if (scheme == PROB_AVERAGE)
        return (fabsf(x[0]) + fabsf(x[1]) + fabsf(x[2])) / 3.0f;
    return (fabsf(w[0] * x[0]) + fabsf(w[1] * x[1]) + fabsf(w[2] * x[2])) / 3.0f;
}

/* One free flight; `fields` (a constant at each call) adds the medium's albedo field and emission
 * (murk/tracking.h): the instance without them is spectral tracking as it always was. */
static MURK_ALWAYS_INLINE void spectral_flight(const spectral *m, const murk_ray *ray, const murk_path_ctx *ctx,
                                               murk_rng *rng, murk_medium_event *ev, int fields)
{
    const murk_medium_data *d = m->base.d;
    murk_event_init(ev, ray);
    if (!(m->base.smax > 0.0f))
        return;
    int emit = fields && murk_emitting(&m->base);
    murk_collisions c;
    murk_collisions_init(&c, &m->base, ray, m->base.smax);
    float t, dens;
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float sa[3], ss[3], sn[3], hist[3];
        int neg = 0;
        if (fields) {
            murk_vec3 p = murk_madd(ray->o, ray->d, t);
            murk_local_sigma(&m->base, p, dens, sa, ss);
            if (emit)
                murk_emit(&m->base, ctx, ev, p, sa, c.mu, ev->weight, murk_rgb1(1.0f));
        }
        for (int k = 0; k < 3; k++) {
            if (!fields) {
                sa[k] = dens * d->sigma_a.c[k];
                ss[k] = dens * d->sigma_s.c[k];
            }
            sn[k] = c.mu - dens * m->base.sigma_t.c[k];
            neg |= sn[k] < 0.0f;
            hist[k] = ctx->beta.c[k] * ev->weight.c[k];
        }
        if (neg)
            murk_warn_majorant(&m->base, "spectral tracking gives negative null weights to");
        float pa = pick(m->scheme, sa, hist), ps = pick(m->scheme, ss, hist), pn = pick(m->scheme, sn, hist);
        float sum = pa + ps + pn, u = murk_collisions_choice(&c, rng) * sum;
        if (!(sum > 0.0f) || u < pa) { /* absorbed (or no weight left in any channel): the path ends */
            ev->weight = murk_rgb1(0.0f);
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        if (u < pa + ps) {
            for (int k = 0; k < 3; k++)
                ev->weight.c[k] *= ss[k] * sum / (c.mu * ps);
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        float amax = 0.0f;
        for (int k = 0; k < 3; k++) {
            ev->weight.c[k] *= sn[k] * sum / (c.mu * pn);
            amax = murk_maxf(amax, (sa[k] + ss[k]) / c.mu);
        }
        murk_collisions_raise(&c, amax);
    }
    if (c.stopped) /* the watchdog (murk/plugin.h) */
        murk_event_kill(ev, c.t);
}

static void spectral_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                            murk_medium_event *ev)
{
    const spectral *m = self;
    if (m->base.fields)
        spectral_flight(m, ray, ctx, rng, ev, 1);
    else
        spectral_flight(m, ray, ctx, rng, ev, 0);
}

static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, spectral_create, murk_tracker_free,
                                  spectral_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("spectral", "spectral tracking (Kutz et al. 2017): one majorant, per-channel weights", params,
                   P_COUNT, &vt)
