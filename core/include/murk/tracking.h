/* murk/tracking.h — helpers for tracker (medium plugin) authors: the common tracker state, free-flight
 * distances, collision choices that stay unbiased (and bounded) on coloured media and where a
 * majorant fails to bound, the warning for that, ratio-tracking transmittance over the core's
 * majorant grid and a ray-marched density integral over it (murk_march_depth, for transmittance
 * estimators, murk/transmittance.h). Header-only; include after murk/medium.h.
 *
 * A tracker that walks the majorant grid itself (host->walk_init / walk_next) and reads the density
 * with host->density() needs nothing else from here; these helpers are what murk's own trackers share.
 *
 * Cost counters (murk/counters.h). The core counts density lookups and majorant cells inside
 * host->density() and host->walk_next(), so a tracker that walks the grid itself has its lookups and
 * cells counted with nothing to do; the helpers below count their tentative collisions. A tracker that
 * draws its own collisions takes murk_tracker_counters() once per flight and adds one to ->collisions
 * per tentative (null or real) collision (decomposition.c and power_series.c do; see murk/counters.h for
 * what counts as one). */
#ifndef MURK_TRACKING_H
#define MURK_TRACKING_H

#include <stdio.h>

#include "murk/medium.h"

/* Inlined wherever it is called, whatever the compiler's size heuristics: the collision loop's helpers, so
 * that a tracker that writes its loop twice (see "Fields beside density" below) gets each instance with
 * no call per collision. */
#if defined(__GNUC__)
#define MURK_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define MURK_ALWAYS_INLINE inline
#endif

/* What every tracker keeps; put it first in a tracker's own struct. */
typedef struct murk_tracker {
    const murk_host *host;
    const murk_medium_data *d;
    murk_rgb sigma_t; /* extinction per unit density */
    float smax;       /* its largest channel */
    int grey;         /* 1 if sigma_t is the same in every channel */
    const char *plugin; /* the tracker's name for the watchdog's reports; set it after murk_tracker_new */
    uint32_t fields;  /* the medium's fields beside density (MURK_FIELD_*, murk/medium.h; 0 before ABI 1.9) */
} murk_tracker;

/* Allocates a zeroed tracker struct of `size` bytes with the common part filled in. NULL (with err)
 * when the host lacks the media services or memory runs out. */
static inline void *murk_tracker_new(const murk_host *host, const murk_medium_data *d, size_t size, char *err,
                                     size_t errlen)
{
    if (host->size < sizeof(murk_host) || size < sizeof(murk_tracker)) {
        snprintf(err, errlen, "this murk's host table lacks the media services");
        return NULL;
    }
    murk_tracker *t = host->alloc(size);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    t->host = host;
    t->d = d;
    t->sigma_t = murk_rgb_add(d->sigma_a, d->sigma_s);
    t->smax = murk_rgb_max(t->sigma_t);
    t->grey = t->sigma_t.c[0] == t->sigma_t.c[1] && t->sigma_t.c[1] == t->sigma_t.c[2];
    t->fields = MURK_HAS(d->size, murk_medium_data, integrator_minor) ? d->fields : 0;
    return t;
}

static inline void murk_tracker_free(void *self)
{
    murk_tracker *t = self;
    if (t)
        t->host->free(t);
}

/* The calling thread's counters for medium d (host->counters, once per flight), or *scratch when the
 * host predates ABI 1.4 or fills no counters (a test's host table): never NULL. */
static inline murk_counters *murk_tracker_counters(const murk_host *h, const murk_medium_data *d,
                                                   murk_counters *scratch)
{
    return MURK_HAS(h->size, murk_host, counters) && h->counters ? h->counters(d->density) : scratch;
}

/* An event that passes the whole segment with weight 1 and pdf ratios 1. */
static inline void murk_event_init(murk_medium_event *ev, const murk_ray *ray)
{
    ev->scattered = 0;
    ev->t = ray->tmax;
    ev->weight = murk_rgb1(1.0f);
    ev->pdf_ratio = murk_rgb1(1.0f);
}

/* Extinction per unit density. */
static inline murk_rgb murk_sigma_t(const murk_medium_data *d) { return murk_rgb_add(d->sigma_a, d->sigma_s); }

/* The Exp(1) variate -ln(1 - u) of a uniform u in [0, 1): an optical depth. murk's uniforms
 * (murk_rng_float, murk_sample_1d/2d) are multiples of 2^-24, so 1 - u is exact in float and logf(1 - u)
 * is as accurate as log1pf(-u), at a fraction of glibc's log1pf's cost (docs/results.md, "Free-flight
 * logarithm"); for any other u in [0, 1) the rounding of 1 - u moves the result by at most 2^-24. Every
 * free flight and tentative collision draws one. */
static MURK_ALWAYS_INLINE float murk_exp1(float u) { return -logf(1.0f - u); }

/* Distance to the next event of a Poisson process of rate mu > 0. */
static inline float murk_sample_exp(murk_rng *rng, float mu) { return murk_exp1(murk_rng_float(rng)) / mu; }

/* Stratified free flights (the medium's `stratify_flights` key, murk_medium_data.stratify_flights). The
 * integrator seeks (murk_sample_seek) to a slot of the flight's own before sample(); a stratified flight
 * takes its FIRST random numbers from that slot and every later one from the PCG stream, so the
 * collision loop's unbounded use never moves the integrator's slots. With render.sampler sobol the slot
 * is a 2-D point, stratified over the pixel's samples: its first coordinate gives the flight's first
 * distance, its second the choice (real or null, absorbed or scattered) at the flight's first
 * collision, jointly stratified (docs/results.md, "Stratified free flights", compares it with the
 * distance alone). It changes which numbers a flight uses, never its method or its distribution.
 * With render.sampler independent murk_sample_1d is murk_rng_float in call order and the choice's
 * number is drawn where it always was: the numbers are those of an unstratified flight. A tracker keeps
 * `int first = murk_flight_stratified(d); float uc = -1;` per flight and draws with murk_flight_float /
 * murk_flight_exp and murk_flight_choice (murk_collisions does this itself: murk_collisions_choice). */
static inline int murk_flight_stratified(const murk_medium_data *d)
{
    return MURK_HAS(d->size, murk_medium_data, stratify_flights) && d->stratify_flights;
}

/* A uniform number in [0, 1): if *first (which it clears) the slot's — with sobol its first coordinate,
 * the second kept in *uc for murk_flight_choice — else the PCG stream's. */
static MURK_ALWAYS_INLINE float murk_flight_float(murk_rng *rng, int *first, float *uc)
{
    if (!*first)
        return murk_rng_float(rng);
    *first = 0;
    if (rng->sampler != MURK_SAMPLER_SOBOL)
        return murk_sample_1d(rng);
    float u[2];
    murk_sample_2d(rng, u);
    *uc = u[1];
    return u[0];
}

/* murk_sample_exp with murk_flight_float's number. */
static inline float murk_flight_exp(murk_rng *rng, int *first, float *uc, float mu)
{
    return murk_exp1(murk_flight_float(rng, first, uc)) / mu;
}

/* The number for a collision's choice: the slot's second coordinate if murk_flight_float left one in
 * *uc (which it clears), else the PCG stream's. */
static MURK_ALWAYS_INLINE float murk_flight_choice(murk_rng *rng, float *uc)
{
    float u = *uc;
    *uc = -1.0f;
    return u >= 0.0f ? u : murk_rng_float(rng);
}

/* t + step, but at least the next float above t: a loop that steps t always advances (the watchdog
 * contract, murk/plugin.h), even where a step is below the float spacing of t. */
static inline float murk_advance(float t, float step)
{
    float n = t + step;
    return n > t ? n : nextafterf(t, INFINITY);
}

/* The watchdog's report for a tracker (murk/plugin.h): once per run and message, counted. */
static inline void murk_tracker_watchdog(const murk_tracker *t, const char *what)
{
    t->host->warn_once("tracker '%s' (medium '%s'): %s exceeded %ld iterations (MURK_WATCHDOG_ITERATIONS); "
                       "the path was ended (biased)", t->plugin ? t->plugin : "?", t->d->name, what,
                       MURK_WATCHDOG_ITERATIONS);
}

/* Ends a path at a flight the watchdog stopped: weight 0, "scattered" at t. */
static inline void murk_event_kill(murk_medium_event *ev, float t)
{
    ev->weight = murk_rgb1(0.0f);
    ev->scattered = 1;
    ev->t = t;
}

/* Probability of taking the "real" branch of a collision whose real and null weights (each relative to
 * the majorant, real + null = 1) are a and b, for ONE channel (grey extinction, or a tracker that
 * follows one channel per path). For a bounding majorant (a, b >= 0) this is a itself: plain delta
 * tracking. When the majorant fails (b < 0, or a control above the density makes a < 0) the branches
 * are chosen in proportion to |a| and |b| and weighted by a/q and b/(1-q): still unbiased, with
 * weights that may exceed 1 or go negative. For coloured extinction use murk_collision_prob. */
static inline float murk_real_prob(float a, float b)
{
    float s = fabsf(a) + fabsf(b);
    return s > 0.0f ? fabsf(a) / s : 0.0f;
}

/* Probability of the real branch of a collision whose real share in channel k is a[k] (the local
 * sigma_t,k over the majorant; the null share is 1 - a[k]). Grey extinction: murk_real_prob(a[0]).
 * Coloured: history-aware (Kutz et al. 2017), q = sum_k |h_k| |a_k| / sum_k |h_k| (|a_k| + |1 - a_k|)
 * with h_k = beta_k x weight_k the path's weight so far in channel k — a plain channel average lets
 * the weights grow without bound along a path. The caller then multiplies channel k's weight by
 * a[k] / q (real) or (1 - a[k]) / (1 - q) (null), which keeps every channel unbiased. */
static inline float murk_collision_prob(const murk_tracker *t, const float a[3], const murk_path_ctx *ctx,
                                        murk_rgb weight)
{
    if (t->grey)
        return murk_real_prob(a[0], 1.0f - a[0]);
    float pr = 0.0f, pn = 0.0f;
    for (int k = 0; k < 3; k++) {
        float h = fabsf(ctx->beta.c[k] * weight.c[k]);
        pr += h * fabsf(a[k]);
        pn += h * fabsf(1.0f - a[k]);
    }
    return pr + pn > 0.0f ? pr / (pr + pn) : 0.5f;
}

/* Where a majorant or control is wrong (docs/stability.md).
 *
 * The core repairs a majorant_factor < 1 before rendering (majorant_repair, the default: every cell gets
 * its exact bound back) and decomposition clamps its control to each cell's minimum density (its `repair`
 * parameter), so by default no tracker sees a violation. With the repairs off (or for a tracker of
 * its own whose bounds are estimated) a tracker may meet a tentative collision whose real share a > 1
 * (density above the majorant) or < 0 (control above the density). It weights that collision as
 * murk_real_prob says — a factor up to |a| + |1 - a| on the path's weight — and then raises the majorant
 * of the rest of the FLIGHT by MURK_MAJORANT_RAISE x a (murk_collisions_raise), in this cell and the
 * following ones. That is unbiased: the null-collision identity holds for any majorant along the
 * remaining segment, and the remaining segment is estimated afresh after each collision, so the
 * majorant after a collision may depend on everything sampled before it. It is per path, from the
 * path's own random numbers: the image stays a pure function of (scene, seed, spp) for any thread
 * count and tiling, which a majorant shared and raised between threads at run time would break. Without
 * the raise a weight of 2a - 1 multiplies at EVERY violating collision (docs/stability.md has what that
 * did to cornell_smoke); with it about one collision per flight is weighted. Each flight starts again
 * from the grid's majorant (a path has no state of its own), which is why the core's repair, not this
 * one, is the default. */
#define MURK_MAJORANT_RAISE 2.0f

/* The warning for a density above the majorant (a real share above 1), once per run and medium;
 * `what` names the tracker's way to weight the collision, e.g. "delta tracking weights". */
static inline void murk_warn_majorant(const murk_tracker *t, const char *what)
{
    t->host->warn_once("medium '%s': density above the majorant (majorant_repair: false?): %s the violating "
                       "collision and raises the rest of the flight's majorant %gx the excess (unbiased; more "
                       "tentative collisions, noisier than the repaired majorant)", t->d->name, what,
                       (double)MURK_MAJORANT_RAISE);
}

/* Tentative collisions along a ray: a Poisson process whose rate in each majorant cell is
 * mu = (the cell's maximum density) x sigma x boost, walked cell by cell (delta tracking's proposal);
 * boost starts at 1 and only murk_collisions_raise changes it. A stratified flight (murk_flight_stratified)
 * with render.sampler sobol draws its first tentative collision's majorant optical depth tau = -ln(1 - u)
 * once, from the slot, and carries what is left of it over the cells it passes (tau - mu x the cell's
 * length; exponential distances are memoryless, so this is the same process as a fresh draw per cell),
 * so the slot's stratification reaches the first collision wherever it lies; later collisions draw
 * afresh from the PCG stream in each cell. With independent numbers each cell draws afresh, as before
 * the key existed (the same numbers in the same order). */
typedef struct murk_collisions {
    const murk_tracker *tr;
    const murk_ray *ray;
    murk_majorant_walk walk;
    float sigma, t, tb, mu, dmin;
    float boost; /* this flight's majorant multiplier, raised where the majorant failed */
    long steps;  /* collisions and cells so far */
    int stopped; /* 1 if the watchdog ended the walk (MURK_WATCHDOG_ITERATIONS): kill the path */
    int first;   /* 1 until the flight's first number is drawn, if the flight is stratified */
    float tau;   /* the stratified first draw's optical depth still to go (carried over cells), < 0: none */
    float uc;    /* the first collision's choice number (the slot's second coordinate), < 0: none */
    murk_counters *count, scratch; /* the medium's cost counters (murk_tracker_counters) */
} murk_collisions;

static inline void murk_collisions_init(murk_collisions *c, const murk_tracker *tr, const murk_ray *ray, float sigma)
{
    c->tr = tr;
    c->ray = ray;
    c->sigma = sigma;
    c->t = c->tb = ray->tmin;
    c->mu = 0.0f;
    c->dmin = 0.0f;
    c->boost = 1.0f;
    c->steps = 0;
    c->stopped = 0;
    c->first = murk_flight_stratified(tr->d);
    c->tau = c->uc = -1.0f;
    c->count = murk_tracker_counters(tr->host, tr->d, &c->scratch);
    tr->host->walk_init(tr->d->density, ray, ray->tmin, ray->tmax, &c->walk);
}

/* After a tentative collision whose largest real share was amax > 1: the rest of this flight is drawn
 * with the majorant raised by MURK_MAJORANT_RAISE x amax (unbiased, see above). Call it after the
 * collision's real/null choice and weights, never before. */
static inline void murk_collisions_raise(murk_collisions *c, float amax)
{
    if (!(amax > 1.0f))
        return;
    float f = murk_fminf(MURK_MAJORANT_RAISE * amax, 1e6f);
    c->boost = murk_fminf(c->boost * f, 1e12f);
    c->mu *= f;
}

/* The next tentative collision: its distance *t and the density *dens there; c->mu is the majorant rate
 * it was drawn with. Returns 0 when the ray's segment is used up — or when the watchdog stopped it
 * (c->stopped, reported once; the caller ends the path with murk_event_kill). Every iteration advances
 * t by at least one float or moves to the next cell, so the loop ends. */
static MURK_ALWAYS_INLINE int murk_collisions_next(murk_collisions *c, murk_rng *rng, float *t, float *dens)
{
    for (;;) {
        if (++c->steps > MURK_WATCHDOG_ITERATIONS) {
            c->stopped = 1;
            murk_tracker_watchdog(c->tr, "a free flight");
            return 0;
        }
        if (c->mu > 0.0f) {
            float t0 = c->t, tau;
            int carry = c->tau >= 0.0f;
            if (carry) {
                tau = c->tau;
            } else {
                carry = c->first && rng->sampler == MURK_SAMPLER_SOBOL;
                tau = murk_exp1(murk_flight_float(rng, &c->first, &c->uc));
            }
            c->t = murk_advance(c->t, tau / c->mu);
            c->tau = carry && !(c->t < c->tb) ? murk_fmaxf(0.0f, tau - c->mu * (c->tb - t0)) : -1.0f;
            if (c->t < c->tb) {
                c->count->collisions++;
                *t = c->t;
                *dens = c->tr->host->density(c->tr->d->density, murk_madd(c->ray->o, c->ray->d, c->t));
                return 1;
            }
        }
        float ta, dmax;
        if (!c->tr->host->walk_next(&c->walk, &ta, &c->tb, &dmax, &c->dmin))
            return 0;
        c->t = ta;
        c->mu = dmax * c->sigma * c->boost;
    }
}

/* The number for the choice at the collision murk_collisions_next() just returned (real or null,
 * absorbed or scattered): at the first collision of a stratified flight with sobol the slot's second
 * coordinate, else the PCG stream's. Draw it with this, not murk_rng_float. */
static MURK_ALWAYS_INLINE float murk_collisions_choice(murk_collisions *c, murk_rng *rng) { return murk_flight_choice(rng, &c->uc); }

/* ---- Fields beside density (ABI 1.9; murk/medium.h) ---------------------------------------------------
 * A medium with an albedo field or emission (t->fields != 0) needs more per collision than one without, so
 * murk's trackers write their collision loop once as a MURK_ALWAYS_INLINE function with a constant flag
 * and call it twice: the instance without fields is the loop as it always was (no lookups, no branches
 * added per collision), chosen once per flight.
 *
 * Albedo: at a collision at p with density dens, murk_local_sigma gives the local sigma_a,k(p) and
 * sigma_s,k(p) (with an albedo field a(p): a sigma_t,k dens and (1 - a) sigma_t,k dens); use them
 * wherever the constants d->sigma_a, d->sigma_s times dens would be (scattering weights, spectral
 * tracking's probabilities). Extinction, and so the majorants and null collisions, do not change.
 *
 * Emission: the collision estimator of pbrt-v4 (VolPathIntegrator): at EVERY tentative collision of the
 * flight at p — null or real, before its choice — add  w_k sigma_a,k(p) Le_k(p) / mu  to the flight's
 * emitted radiance, w the flight's running weight per channel and mu the rate the collision was drawn
 * with. Tentative collisions are a Poisson process of rate mu, and a collision at t is reached with
 * probability density mu(t) times the null-collision weights so far, whose expectation per channel is
 * the transmittance T_k(t) (the running weights reweight every channel to its own); so the sum has
 * expectation int T_k(t) sigma_a,k Le_k dt per channel, chromatic extinction included: unbiased, and it
 * needs no probability of its own. (Scoring at real collisions only, weighted by sigma_a / sigma_t, is
 * unbiased too, but in a thin flame real collisions are rare, while every null collision scores here.)
 * Decomposition tracking's two processes together are one of rate control + residual; spectral MIS
 * credits each score with the pdf ratios the path has at that collision (murk_emit's r). */
/* 1 if the flight must collect emission: the medium emits and the integrator passes events that hold it. */
static inline int murk_emitting(const murk_tracker *t)
{
    return (t->fields & MURK_FIELD_EMISSION) && t->d->integrator_minor >= MURK_ABI_MINOR_FIELDS;
}

/* a / b, 0 where b is 0 (a local albedo where the density vanishes). */
static inline float murk_ratio0(float a, float b) { return b > 0.0f ? a / b : 0.0f; }

/* The local absorption and scattering coefficients at p, density dens (see above). */
static inline void murk_local_sigma(const murk_tracker *t, murk_vec3 p, float dens, float sa[3], float ss[3])
{
    if (t->fields & MURK_FIELD_ALBEDO) {
        murk_rgb a = t->host->albedo(t->d->density, p);
        for (int k = 0; k < 3; k++) {
            float st = dens * t->sigma_t.c[k];
            ss[k] = a.c[k] * st;
            sa[k] = (1.0f - a.c[k]) * st;
        }
    } else {
        for (int k = 0; k < 3; k++) {
            sa[k] = dens * t->d->sigma_a.c[k];
            ss[k] = dens * t->d->sigma_s.c[k];
        }
    }
}

/* The emission score of a tentative collision at p (see above): ev->emitted += w sa Le / mu, times
 * mean(R) / mean(R r) with R the path's pdf ratios before the flight (ctx) and r the flight's pdf ratios up
 * to this collision (ev->pdf_ratio for a tracker that keeps them there; 1 for trackers without per-channel
 * techniques), so that the integrator's crediting (beta emitted / mean(R)) weights each score as spectral
 * MIS weights a path ending there. */
static inline void murk_emit(const murk_tracker *t, const murk_path_ctx *ctx, murk_medium_event *ev, murk_vec3 p,
                             const float sa[3], float mu, murk_rgb w, murk_rgb r)
{
    murk_rgb le = t->host->emission(t->d->density, p);
    float f = 1.0f / mu;
    if (r.c[0] != 1.0f || r.c[1] != 1.0f || r.c[2] != 1.0f) {
        murk_rgb R = ctx->pdf_ratio;
        float m = R.c[0] + R.c[1] + R.c[2], mr = R.c[0] * r.c[0] + R.c[1] * r.c[1] + R.c[2] * r.c[2];
        f = mr > 0.0f ? f * m / mr : 0.0f;
    }
    for (int k = 0; k < 3; k++)
        ev->emitted.c[k] += w.c[k] * sa[k] * le.c[k] * f;
}

/* Ratio tracking (Novak et al. 2014) over (ray->tmin, ray->tmax) with majorant segments from the
 * walk; extra: a second density-proportional extinction that is handled in closed form instead
 * (decomposition's control, per unit density-of-control), NULL for none. Russian roulette on small
 * transmittance (survival probability = the largest channel, once below 0.1) keeps long, dense shadow
 * rays cheap without bias. */
static inline murk_rgb murk_ratio_tracking(const murk_host *h, const murk_medium_data *d, const murk_ray *ray,
                                           float control, murk_rng *rng)
{
    murk_rgb st = murk_sigma_t(d), T = murk_rgb1(1.0f);
    float smax = murk_rgb_max(st);
    if (!(smax > 0.0f))
        return T;
    murk_counters scratch, *count = murk_tracker_counters(h, d, &scratch);
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin, boost = 1.0f; /* boost: the ray's majorant raise where it failed */
    long steps = 0;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        float c = control * dmin; /* control density, handled in closed form */
        if (c > 0.0f) {
            float len = tb - ta;
            if (!isfinite(len))
                return murk_rgb1(0.0f);
            for (int k = 0; k < 3; k++)
                T.c[k] *= expf(-c * st.c[k] * len);
        }
        /* residual majorant; any positive value keeps ratio tracking unbiased, so a control above the
         * majorant only costs variance; where |density - control| x sigma exceeds it the rest of the ray
         * is tracked with it raised (unbiased for the reason given above murk_collisions_raise) */
        float mu = murk_fmaxf(fabsf(dmax - c), 1e-3f * murk_fmaxf(dmax, c)) * smax * boost;
        if (!(mu > 0.0f))
            continue;
        for (float t = ta;;) {
            t = murk_advance(t, murk_sample_exp(rng, mu));
            if (!(t < tb))
                break;
            count->collisions++;
            murk_vec3 p = murk_madd(ray->o, ray->d, t);
            float dens = h->density(d->density, p) - c, r = fabsf(dens) * smax / mu;
            for (int k = 0; k < 3; k++)
                T.c[k] *= 1.0f - dens * st.c[k] / mu;
            if (r > 1.0f) { /* the majorant failed (|factor| may exceed 1): raise it for the rest of the ray */
                float f = murk_fminf(MURK_MAJORANT_RAISE * r, 1e6f);
                boost = murk_fminf(boost * f, 1e12f);
                mu *= f;
            }
            float tm = murk_fmaxf(fabsf(T.c[0]), murk_fmaxf(fabsf(T.c[1]), fabsf(T.c[2])));
            if (tm < 0.1f) {
                if (tm <= 0.0f || murk_rng_float(rng) >= tm)
                    return murk_rgb1(0.0f);
                T = murk_rgb_scale(T, 1.0f / tm);
            }
            if (++steps > MURK_WATCHDOG_ITERATIONS) {
                h->warn_once("medium '%s': ratio tracking exceeded %ld iterations (MURK_WATCHDOG_ITERATIONS); "
                             "transmittance set to 0 (biased)", d->name, MURK_WATCHDOG_ITERATIONS);
                return murk_rgb1(0.0f);
            }
        }
    }
    return T;
}

/* Plain ratio tracking for path-level MIS of next-event estimation with free flights (Miller, Georgiev,
 * Jarosz 2019, §5; volpath_nee's nee_mis: null_scattering): tentative collisions at the free flights' own
 * majorant, max density x max_c sigma_t,c per cell (no control), each multiplying channel c's estimate
 * by 1 - sigma_t,c(x) / mu and *pnull (per channel) by the probability with which channel c's delta
 * tracking would have taken that collision as null, 1 - murk_real_prob(a_c, 1 - a_c) — the same as the
 * estimate's factor while the majorant bounds. Russian roulette (below 0.1, as murk_ratio_tracking)
 * scales the estimate, never *pnull, which is a pdf of the path's null vertices, not an estimate. */
static inline murk_rgb murk_ratio_tracking_null(const murk_host *h, const murk_medium_data *d, const murk_ray *ray,
                                                murk_rng *rng, murk_rgb *pnull)
{
    murk_rgb st = murk_sigma_t(d), T = murk_rgb1(1.0f), P = murk_rgb1(1.0f);
    float smax = murk_rgb_max(st);
    if (!(smax > 0.0f)) {
        *pnull = P;
        return T;
    }
    murk_counters scratch, *count = murk_tracker_counters(h, d, &scratch);
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin;
    long steps = 0;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin) && steps <= MURK_WATCHDOG_ITERATIONS) {
        float mu = dmax * smax;
        for (float t = ta; mu > 0.0f && ++steps <= MURK_WATCHDOG_ITERATIONS;) {
            t = murk_advance(t, murk_sample_exp(rng, mu));
            if (!(t < tb))
                break;
            count->collisions++;
            float dens = h->density(d->density, murk_madd(ray->o, ray->d, t));
            for (int k = 0; k < 3; k++) {
                float a = dens * st.c[k] / mu;
                T.c[k] *= 1.0f - a;
                P.c[k] *= 1.0f - murk_real_prob(a, 1.0f - a);
            }
            float tm = murk_fmaxf(fabsf(T.c[0]), murk_fmaxf(fabsf(T.c[1]), fabsf(T.c[2])));
            if (tm < 0.1f) { /* Russian roulette on the estimate only */
                if (tm <= 0.0f || murk_rng_float(rng) >= tm) {
                    *pnull = P;
                    return murk_rgb1(0.0f);
                }
                T = murk_rgb_scale(T, 1.0f / tm);
            }
        }
    }
    if (steps > MURK_WATCHDOG_ITERATIONS) {
        h->warn_once("medium '%s': ratio tracking exceeded %ld iterations (MURK_WATCHDOG_ITERATIONS); "
                     "transmittance set to 0 (biased)", d->name, MURK_WATCHDOG_ITERATIONS);
        T = murk_rgb1(0.0f);
    }
    *pnull = P;
    return T;
}

/* Ray-marched integral of the density (not of sigma_t) over (ray->tmin, ray->tmax), walked over the
 * majorant grid: segments whose majorant is 0 are skipped (no lookups; the walk ends at the field's box,
 * so infinite rays terminate). Two ways to place the lookups, each with an offset u in [0, 1):
 *   step > 0        a fixed lattice along the whole ray, t_i = tmin + (i + u) step, each lookup
 *                   weighted by step (the classic ray march; cell boundaries do not matter);
 *   depth_step > 0  per majorant segment [ta, tb) of length L and majorant density dmax,
 *                   n = max(1, ceil(dmax sigma L / depth_step)) equal steps at ta + (i + u) L / n
 *                   (steps follow the majorant optical depth).
 * With u uniform (one offset per march, drawn by the caller) either sum is an unbiased estimate of the
 * integral (jittered ray marching); u = 0.5 is the deterministic midpoint rule (biased by its
 * quadrature error). At most 2^24 lookups per segment (a larger count is clamped: biased, and absurd).
 * The loops count integer steps, so they advance however large t is. Returns INFINITY if a segment with
 * dmax > 0 is infinitely long (an unbounded constant field: infinite optical depth). *lookups (if
 * non-NULL) is increased by the density lookups made. What unbiased_raymarch and raymarch share. */
static inline double murk_march_depth(const murk_host *h, const murk_medium_data *d, const murk_ray *ray, float step,
                                      float depth_step, float sigma, float u, long *lookups)
{
    murk_majorant_walk w;
    h->walk_init(d->density, ray, ray->tmin, ray->tmax, &w);
    float ta, tb, dmax, dmin;
    double D = 0.0;
    long nl = 0;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        if (!(dmax > 0.0f) || !(tb > ta))
            continue;
        double L = (double)tb - (double)ta, t0, hstep, acc = 0.0;
        if (!isfinite(L))
            return INFINITY;
        long i0, i1;
        if (step > 0.0f) { /* lattice points tmin + (i + u) step inside [ta, tb) */
            hstep = step;
            t0 = ray->tmin;
            i0 = (long)fmin(ceil(((double)ta - t0) / hstep - u), 9e18);
            i1 = (long)fmin(ceil(((double)tb - t0) / hstep - u), 9e18);
        } else {
            double n = depth_step > 0.0f ? fmax(1.0, ceil((double)dmax * sigma * L / depth_step)) : 1.0;
            hstep = L / fmin(n, 16777216.0);
            t0 = ta;
            i0 = 0;
            i1 = (long)fmin(n, 16777216.0);
        }
        if (i1 - i0 > 16777216L)
            i1 = i0 + 16777216L;
        for (long i = i0; i < i1; i++)
            acc += h->density(d->density, murk_madd(ray->o, ray->d, (float)(t0 + ((double)i + u) * hstep)));
        D += acc * hstep;
        nl += i1 > i0 ? i1 - i0 : 0;
    }
    if (lookups)
        *lookups += nl;
    return D;
}

/* The transmittance() of a tracker whose struct starts with a murk_tracker — what a medium's shadow
 * rays use when the scene names no estimator: residual ratio tracking with each majorant cell's
 * minimum density as the control (the `residual_ratio` estimator's default), exact (zero variance)
 * where the density is constant over a cell, and never negative while the majorant bounds: which is
 * why it, and not `unbiased_raymarch` (whose estimates may be negative), is the default. docs/results.md
 * ("The default") compares their efficiency with plain ratio tracking's. */
static inline murk_rgb murk_tracker_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx,
                                                  murk_rng *rng)
{
    (void)ctx;
    const murk_tracker *t = self;
    return murk_ratio_tracking(t->host, t->d, ray, 1.0f, rng);
}

#endif
