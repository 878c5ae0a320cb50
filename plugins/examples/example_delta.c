/* example_delta — delta (Woodcock) tracking: the smallest complete medium (tracker) plugin.
 * Woodcock, Murphy, Hemmings, Longworth 1965; the per-channel reweighting of coloured media is Kutz et
 * al. 2017's spectral tracking. It is murk's built-in `delta` (plugins/media/delta.c), step for step.
 *
 * Parameters: none of its own. The medium's common keys (density, sigma_a, sigma_s, scale, g, ...) are
 * read by the core and arrive in murk_medium_data.
 *
 * Free flights: tentative collisions come from murk/tracking.h's murk_collisions (a Poisson process
 * with the majorant rate of each grid cell, mu = cell max density x max channel of sigma_t). A tentative
 * collision at density `dens` has the real share a_k = dens sigma_t,k / mu in channel k. With grey
 * extinction it is real with probability a and scatters with weight albedo = sigma_s / sigma_t
 * (absorption folded into the weight): plain delta tracking. With coloured extinction there is no single
 * probability, so murk_collision_prob() picks one from the path's history and every channel is
 * reweighted by a_k / q (real) or (1 - a_k) / (1 - q) (null): unbiased, weights bounded. Should a
 * density exceed the majorant, the same reweighting keeps the estimate unbiased (said once), and
 * murk_collisions_raise() tracks the rest of the flight with a raised majorant (bounded variance).
 *
 * Albedo and emission fields (murk/medium.h, ABI 1.9): with a field (tr->fields != 0) every tentative
 * collision asks murk_local_sigma() for the local sigma_a and sigma_s (an albedo field changes the split of
 * extinction, not extinction) and, if the medium emits, adds its emission score with murk_emit(): the
 * collision estimator, sigma_a Le / mu times the running weight at every tentative collision, unbiased
 * on coloured media too. murk's own trackers compile their loop twice so that media without fields pay
 * nothing for this (murk/tracking.h); an example can afford the branch.
 *
 * The three things docs/plugins.md asks of every tracker, done here:
 *   - each collision's real/null choice is drawn with murk_collisions_choice(), not murk_rng_float(),
 *     so a stratified flight (the medium key stratify_flights) takes its first choice from its slot;
 *   - base.plugin names the tracker, so the watchdog's and the majorant's warnings name it;
 *   - at the watchdog's cap (c.stopped) the path ends (murk_event_kill), never goes on.
 *
 * Transmittance (shadow rays): residual ratio tracking, murk_tracker_transmittance() from murk/tracking.h.
 *
 * Thread-safety: sample() and transmittance() run on every render thread at once; the instance is
 * read-only after create() and all randomness comes from the caller's rng. */
#include "murk/medium.h"
#include "murk/tracking.h"

typedef struct example_delta {
    murk_tracker base; /* first: murk_tracker_new/murk_tracker_free manage it */
} example_delta;

static int ed_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                     char *err, size_t errlen)
{
    (void)params; /* none declared */
    example_delta *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->base.plugin = "example_delta"; /* the name warnings give (the watchdog's, the majorant's) */
    *self = m;
    return 0;
}

static void ed_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                      murk_medium_event *ev)
{
    const example_delta *m = self;
    const murk_tracker *tr = &m->base;
    murk_event_init(ev, ray); /* passes the segment with weight 1 unless a real collision happens */
    if (!(tr->smax > 0.0f))
        return;
    murk_collisions c;
    murk_collisions_init(&c, tr, ray, tr->smax);
    float t, dens, sa[3], ss[3];
    while (murk_collisions_next(&c, rng, &t, &dens)) {
        float a[3], amax = 0.0f;
        for (int k = 0; k < 3; k++) { /* real share of this tentative collision, per channel */
            a[k] = dens * tr->sigma_t.c[k] / c.mu;
            amax = murk_maxf(amax, a[k]);
        }
        murk_vec3 p = murk_madd(ray->o, ray->d, t);
        if (tr->fields) /* an albedo field or emission: the local coefficients at p */
            murk_local_sigma(tr, p, dens, sa, ss);
        else
            for (int k = 0; k < 3; k++) {
                sa[k] = dens * tr->d->sigma_a.c[k];
                ss[k] = dens * tr->d->sigma_s.c[k];
            }
        if (murk_emitting(tr)) /* before the collision's choice, with the weight so far */
            murk_emit(tr, ctx, ev, p, sa, c.mu, ev->weight, murk_rgb1(1.0f));
        if (amax > 1.0f)
            murk_warn_majorant(tr, "example_delta weights its collisions");
        float q = murk_collision_prob(tr, a, ctx, ev->weight); /* = a for grey extinction */
        if (murk_collisions_choice(&c, rng) < q) {
            for (int k = 0; k < 3; k++) /* sigma_s,k / (mu q): the albedo when q = a */
                ev->weight.c[k] *= ss[k] / (c.mu * q);
            ev->scattered = 1;
            ev->t = t;
            return;
        }
        for (int k = 0; k < 3; k++) /* 1 for grey extinction under a bounding majorant */
            ev->weight.c[k] *= (1.0f - a[k]) / (1.0f - q);
        murk_collisions_raise(&c, amax); /* after the choice: the rest of the flight under a bound */
    }
    if (c.stopped) /* the watchdog (MURK_WATCHDOG_ITERATIONS, murk/plugin.h) ended the walk: end the path */
        murk_event_kill(ev, c.t);
}

static const murk_medium_vt vt = {
    sizeof(murk_medium_vt), MURK_KIND_MEDIUM, ed_create, murk_tracker_free, ed_sample, murk_tracker_transmittance,
};

MURK_MEDIUM_PLUGIN("example_delta", "example: delta tracking, residual ratio-tracking transmittance (copy me)", NULL, 0,
                   &vt)
