/* murk/medium.h — the participating-medium (free-flight tracker) plugin interface.
 *
 * The core owns a medium's data — density field, sigma_a, sigma_s, phase function, majorant and
 * minorant grids — and hands a tracker plugin a murk_medium_data at create(); the plugin owns only its
 * method (delta, decomposition, spectral, ...) and its own parameters. Trackers reach the density and
 * the majorant grid through murk_host's density services (density, walk_init, walk_next, warn_once).
 *
 * Path weights. An integrator keeps, per path, an RGB weight beta and RGB pdf ratios R (both start at
 * 1) and credits a path's emitted radiance L as  beta_c * L_c / mean_k(R_k) . A tracker returns, for
 * each free flight it samples, the factors to multiply in:
 *   ev->weight = f / p_hero   per channel: the flight's contribution over the pdf it was sampled with
 *                             (for plain delta tracking: 1 through to the surface, the albedo at a
 *                             scattering event; 0 means the path was absorbed)
 *   ev->pdf_ratio = p_k / p_hero per channel: the pdf channel k's own technique would have given this
 *                             flight, relative to the one used. (1,1,1) for every tracker except the
 *                             per-channel ones (spectral_mis: the balance heuristic over channels;
 *                             naive_spectral: 1 for the path's hero channel, 0 for others, so the
 *                             hero channel alone gets 3x its estimate).
 * The hero channel is chosen once per path by the integrator (uniformly) and passed in ctx.
 * Every tracker is unbiased for any bounding majorant: the expected image must not depend on the
 * tracker, the majorant or the tracker's parameters. Where a bound fails (majorant below the density,
 * control above it) a tracker must stay unbiased (e.g. by weighted collisions), stay finite, and say so
 * once through host->warn_once.
 *
 * transmittance() returns an unbiased per-channel estimate of exp(-int sigma_t) over the segment
 * (ratio tracking or better), used on shadow rays unless the scene gives the medium a transmittance
 * estimator plugin (`transmittance: NAME`, murk/transmittance.h); integrators call
 * murk_medium_transmittance(), which dispatches to whichever applies.
 *
 * Unbiased on coloured media. With chromatic extinction there is no single probability of a real
 * collision: taking one channel's (or the average) sigma_t / majorant and giving the other channels
 * weight 1 is biased. Reweight every channel by its own real / null share over the probability used
 * (murk/tracking.h: murk_collision_choice does this with history-aware probabilities that keep the
 * weights bounded).
 *
 * Contracts (besides those of murk/plugin.h):
 *   create()        gets the core's data for the medium in `data`: valid, unchanged, until destroy().
 *   sample()        samples a free flight over (ray->tmin, ray->tmax); ray->tmax may be INFINITY (the
 *                   ray leaves the scene: outside the density field's box the density is 0, and the
 *                   majorant walk ends there, so a tracker that walks the grid terminates; one that
 *                   uses a single global majorant must stop at the field's box itself). It fills *ev
 *                   completely. Called from every render thread at once: it must not modify self.
 *   transmittance() same rules; returns finite, non-negative channels (0 = opaque: the shadow ray
 *                   stops). Every loop must advance: the float spacing of t, not only the sampled
 *                   step, decides progress once t is large.
 * murk names the medium whose call returned a NaN or infinite weight. */
#ifndef MURK_MEDIUM_H
#define MURK_MEDIUM_H

#include "murk/plugin.h"

typedef struct murk_density murk_density; /* opaque: a density field with its majorant/minorant grid */

/* What the core gives every tracker at create(). Coefficients are per unit density, with the scene's
 * `scale` applied: sigma_t(x) = density(x) * (sigma_a + sigma_s). */
typedef struct murk_medium_data {
    uint32_t size;                /* sizeof(murk_medium_data) of the core */
    murk_rgb sigma_a, sigma_s;
    float g;                      /* Henyey-Greenstein asymmetry of the phase function */
    const murk_density *density;  /* the field with its majorant/minorant grid (majorant_factor applied) */
    const char *name;             /* the medium's name in the scene, for messages */
    /* ABI 1.5 (read it only if MURK_HAS(size, murk_medium_data, stratify_flights)):
     * the medium's `stratify_flights` key. 1: the integrator has sought (murk_sample_seek) to this flight's
     * own sampler slot before sample(), and the tracker takes the flight's FIRST random numbers from it
     * (with render.sampler sobol a 2-D point stratified over a pixel's samples: the first distance and
     * the first collision's choice), every later one with murk_rng_float(rng). 0: every number from
     * murk_rng_float, as trackers built before it do. murk/tracking.h's murk_flight_* helpers and
     * murk_collisions do this. */
    int stratify_flights;
    /* ABI 1.9 (read them only if MURK_HAS(size, murk_medium_data, integrator_minor)): */
    uint32_t fields;           /* MURK_FIELD_*: the medium's fields beside density (below) */
    uint32_t integrator_minor; /* the ABI minor of the scene's integrator: >= MURK_ABI_MINOR_FIELDS means it passes a
                                * murk_medium_event with `emitted` and `null_prob` and a murk_path_ctx with
                                * `pdf_ratio` and `flags`; a tracker writes or reads those only then */
} murk_medium_data;

/* Fields beside density (ABI 1.9), the scene's `albedo`, `emission` and `temperature` keys. Where a
 * medium has none of them (fields == 0), sigma_a and sigma_s are the constants above, everywhere.
 *   MURK_FIELD_ALBEDO    the single-scattering albedo varies in space: host->albedo(density, p) = a(p)
 *                        per channel, and at p  sigma_s(p) = a(p) sigma_t(p),
 *                        sigma_a(p) = (1 - a(p)) sigma_t(p),  with sigma_t(p) = density(p) (sigma_a +
 *                        sigma_s) unchanged: the constants then give the extinction only.
 *   MURK_FIELD_EMISSION  the medium emits: host->emission(density, p) = Le(p), radiance per unit
 *                        absorption, so the source term is sigma_a(p) Le(p) per unit length (temperature
 *                        fields arrive here as blackbody radiance). A tracker collects it along its free
 *                        flights into ev->emitted (murk/tracking.h: murk_emit).
 * murk refuses a medium with fields whose tracker was built before ABI 1.9 (it would ignore them), and
 * emission with an integrator built before 1.9 (it would not collect it). */
enum { MURK_FIELD_ALBEDO = 1u, MURK_FIELD_EMISSION = 2u };

/* A walk over the majorant grid along a ray: consecutive segments [ta, tb) that tile the range given
 * to walk_init exactly, each with the maximum density over it (already multiplied by
 * majorant_factor) and the minimum density. Parts outside the field's box come out with max = min = 0.
 * Opaque storage on the caller's stack. */
typedef struct murk_majorant_walk { uint64_t opaque[32]; } murk_majorant_walk;

typedef struct murk_medium_event {
    int scattered;      /* 1: a real scattering event at t; 0: the flight passed the segment's end */
    float t;            /* where it scattered (ray->tmax when it passed) */
    murk_rgb weight;    /* multiply into the path's beta (all 0: absorbed, the path ends) */
    murk_rgb pdf_ratio; /* multiply into the path's pdf ratios R: (1,1,1) except for per-channel trackers */
    /* ABI 1.9 (only if the medium data's integrator_minor >= MURK_ABI_MINOR_FIELDS; the integrator sets emitted to 0 and
     * null_prob to -1 before sample()): */
    murk_rgb emitted;   /* the radiance the flight collected from an emitting medium, which the integrator
                         * credits as beta * emitted / mean(R) with the path's beta and R before this flight
                         * (murk_emit in murk/tracking.h computes it); stays 0 in media without emission */
    float null_prob;    /* with MURK_CTX_NULL_PROB asked for: the product over the flight's tentative
                         * collisions of the probability the hero channel's technique took the null branch
                         * with (for a flight that passed the segment); -1: this tracker does not report it */
} murk_medium_event;

/* Per-path state an integrator passes to trackers. */
typedef struct murk_path_ctx {
    int hero;        /* channel 0..2 chosen uniformly per path */
    murk_rgb beta;   /* the path's weight so far (history-aware probabilities use it) */
    /* ABI 1.9 (only if the medium data's integrator_minor >= MURK_ABI_MINOR_FIELDS): */
    murk_rgb pdf_ratio; /* the path's pdf ratios R so far (murk_emit needs them for spectral MIS) */
    uint32_t flags;     /* MURK_CTX_*: what the integrator asks of this flight */
} murk_path_ctx;

/* MURK_CTX_NULL_PROB: report ev->null_prob, the null-collision probabilities of the flight, for path-level
 * MIS of next-event estimation with free flights (Miller, Georgiev, Jarosz 2019, §5; volpath_nee's
 * nee_mis). Only meaningful for a tracker whose tentative collisions are those of the majorant
 * density max x max_k sigma_t,k and whose channel k technique takes a collision as null with
 * probability 1 - sigma_t,k / majorant (spectral_mis). */
enum { MURK_CTX_NULL_PROB = 1u };

typedef struct murk_medium_vt {
    uint32_t size; /* sizeof(murk_medium_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_MEDIUM */
    /* create() gets its own parameters in `params` and the core's data for the medium in `data`
     * (valid for the medium's whole life). */
    int (*create)(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                  char *err, size_t errlen);
    void (*destroy)(void *self);
    /* Samples a free flight along ray->d from ray->o over (ray->tmin, ray->tmax) into *ev.
     * Watchdog (murk/plugin.h): at most MURK_WATCHDOG_ITERATIONS collisions or majorant cells per
     * call, every step advancing t by at least one float; at the cap the flight ends the path
     * (ev->scattered = 1, ev->weight = 0) and the tracker says so with host->warn_once, naming itself
     * and the medium. transmittance() likewise returns 0 at the cap. murk/tracking.h does all this. */
    void (*sample)(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                   murk_medium_event *ev);
    /* Unbiased per-channel transmittance estimate over (ray->tmin, ray->tmax). */
    murk_rgb (*transmittance)(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng);
} murk_medium_vt;

#define MURK_MEDIUM_VT_SIZE_1_0 (offsetof(murk_medium_vt, transmittance) + sizeof(void (*)(void)))
#define MURK_MEDIUM_PLUGIN(NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                                 \
    MURK_DEFINE_PLUGIN_(MURK_KIND_MEDIUM, NAME, DESCRIPTION, PARAMS, NPARAMS,                      \
                        _Generic((VT), const murk_medium_vt *: (VT), murk_medium_vt *: (VT)))

typedef struct murk_transmittance_vt murk_transmittance_vt; /* murk/transmittance.h */

/* A medium as the scene holds it. */
struct murk_medium {
    const murk_medium_vt *vt;
    void *self;
    const char *name;
    const murk_medium_data *data;
    /* ABI 1.2: the medium's transmittance estimator (the scene's `transmittance:` key); NULL: the
     * tracker's own transmittance(). Call murk_medium_transmittance(), which picks the right one. */
    const murk_transmittance_vt *tr_vt;
    void *tr_self;
};

#include "murk/transmittance.h"

/* The transmittance estimate of a shadow-ray segment through medium m: its estimator plugin if the
 * scene chose one, else the tracker's own transmittance(). What integrators call on shadow rays. */
static inline murk_rgb murk_medium_transmittance(const murk_medium *m, const murk_ray *ray, const murk_path_ctx *ctx,
                                                 murk_rng *rng)
{
    if (m->tr_vt)
        return m->tr_vt->estimate(m->tr_self, ray, ctx, rng);
    return m->vt->transmittance(m->self, ray, ctx, rng);
}

#endif
