/* naive_spectral — per-channel delta tracking: each path delta-tracks one channel with that channel's own
 * majorant, and the other channels get weight 0. Unbiased per channel, but every path carries one
 * channel: the colour noise that spectral tracking (Kutz et al. 2017) and spectral MIS (Miller et al.
 * 2019) remove, and the baseline they are measured against. Two ways to choose the channel (the
 * `channel` key): a hero per path, drawn by the integrator, credited with 3x its estimate (one render); or
 * one fixed channel, credited 1x, for the reference report's three-pass baseline: three renders, red, green
 * and blue, whose channel c is taken from pass c (bench/three_pass.py). Shadow rays use residual ratio
 * tracking. Details: docs/trackers.md#naive_spectral. */
#include "murk/medium.h"
#include "murk/tracking.h"

enum { P_CHANNEL, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CHANNEL] = {"channel", MURK_PARAM_ENUM, MURK_PARAM_NO_SWEEP, {0, 0, 0}, "hero", "hero|red|green|blue", 0, 0,
                   "the channel a path tracks: hero, the path's hero channel (drawn uniformly per path by the "
                   "integrator; it alone is credited, with 3x its estimate); red, green or blue, that channel on "
                   "every path, credited 1x: one pass of the reference report's three-pass baseline, whose image "
                   "takes channel c from the render of pass c (bench/three_pass.py)"},
};

typedef struct naive {
    murk_tracker base;
    int channel; /* -1: the path's hero; else the fixed channel 0..2 */
} naive;

static int naive_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                        char *err, size_t errlen)
{
    naive *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->channel = p[P_CHANNEL].choice - 1;
    m->base.plugin = "naive_spectral";
    *self = m;
    return 0;
}

/* One free flight; `fields` (a constant at each call) adds the medium's albedo field and emission
 * (murk/tracking.h): the instance without them is per-channel delta tracking as it always was. */
static MURK_ALWAYS_INLINE void naive_flight(const naive *nm, const murk_ray *ray, const murk_path_ctx *ctx,
                                            murk_rng *rng, murk_medium_event *ev, int fields)
{
    const murk_tracker *m = &nm->base;
    int hero = nm->channel < 0 ? ctx->hero : nm->channel;
    float st = m->sigma_t.c[hero];
    murk_event_init(ev, ray);
    ev->weight = murk_rgb1(0.0f); /* only the tracked channel carries this path */
    ev->weight.c[hero] = 1.0f;
    /* a hero: pdf ratio 1 for it, 0 for the others (mean 1/3: the integrator's 3x); a fixed channel is the
     * only technique there is, ratio 1 everywhere (credited 1x) */
    ev->pdf_ratio = nm->channel < 0 ? ev->weight : murk_rgb1(1.0f);
    if (!(st > 0.0f))
        return;
    int emit = fields && murk_emitting(m);
    murk_collisions c;
    murk_collisions_init(&c, m, ray, st); /* the tracked channel's own majorant */
    float t, dens, sa[3], ss[3];
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a = dens * st / c.mu;
        if (fields) {
            murk_vec3 p = murk_madd(ray->o, ray->d, t);
            murk_local_sigma(m, p, dens, sa, ss);
            if (emit) /* the hero's score, x3 through the pdf ratios (murk_emit) */
                murk_emit(m, ctx, ev, p, sa, c.mu, ev->weight, ev->pdf_ratio);
        }
        if (a > 1.0f)
            murk_warn_majorant(m, "per-channel delta tracking weights");
        float q = murk_real_prob(a, 1.0f - a);
        if (murk_collisions_choice(&c, rng) < q) {
            ev->weight.c[hero] *= (fields ? ss[hero] : dens * m->d->sigma_s.c[hero]) / (c.mu * q);
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

static void naive_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                         murk_medium_event *ev)
{
    const naive *nm = self;
    if (nm->base.fields)
        naive_flight(nm, ray, ctx, rng, ev, 1);
    else
        naive_flight(nm, ray, ctx, rng, ev, 0);
}

/* every channel's transmittance is estimated; only the tracked channel carries weight in the path */
static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, naive_create, murk_tracker_free,
                                  naive_sample, murk_tracker_transmittance};

MURK_MEDIUM_PLUGIN("naive_spectral", "per-channel delta tracking (one channel per path): the baseline", params,
                   P_COUNT, &vt)
