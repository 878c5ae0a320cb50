/* murk/transmittance.h — the transmittance-estimator plugin interface (ABI 1.2).
 *
 * Every shadow ray through a medium asks for an estimate of T_c = exp(-int_tmin^tmax sigma_t,c(t) dt)
 * per channel c. A medium's tracker (murk/medium.h) has its own transmittance(); a transmittance
 * estimator is a plugin of its own kind that replaces it, chosen per medium in the scene beside the
 * tracker:
 *     media: { smoke: { type: delta, transmittance: residual_ratio, ... } }
 *     media: { smoke: { type: delta, transmittance: { type: unbiased_raymarch, order: 2 }, ... } }
 * and swapped with `--set media.smoke.transmittance=track_length`. Without the key the tracker's own
 * transmittance() is used. Integrators call murk_medium_transmittance() (murk/medium.h), which
 * dispatches to the estimator when the medium has one.
 *
 * The core owns the medium's data — density field, sigma_a, sigma_s, the majorant/minorant grid — and
 * hands the estimator the same murk_medium_data a tracker gets; the estimator reaches the density and
 * the majorant walk through murk_host (density, walk_init, walk_next, warn_once). murk/tracking.h has
 * the helpers murk's own estimators share (murk_tracker_new for the common state, murk_ratio_tracking,
 * murk_march_depth for a ray-marched density integral over the majorant walk).
 *
 * Contracts (besides those of murk/plugin.h):
 *   create()    gets the estimator's own parameters (validated against its schema, like a tracker's,
 *               with located errors) and the medium's data, valid and unchanged until destroy().
 *               Called on the main thread; it may log (a biased estimator must say so here).
 *   destroy()   frees what create() made; once, on the main thread, after all rendering.
 *   estimate()  the estimate over (ray->tmin, ray->tmax). Called from every render thread at once with
 *               the same self: it must not modify the instance (per-call state on the stack) and takes
 *               randomness only from rng, in a deterministic order. ray->d is unit length; ray->tmax may
 *               be INFINITY (outside the density field's box the density is 0 and the majorant walk
 *               ends there, so an estimator that walks the grid terminates; one that does not must stop
 *               at the box itself). Every loop must advance: where t is large, the float spacing of t,
 *               not only the step, decides progress — count steps in integers where you can.
 *   Result      finite channels. Unbiased: E[estimate_c] = T_c for every channel c, every ray and every
 *               ctx (hero and beta may steer the sampling, never the expectation). Non-negative is
 *               expected; a negative channel is allowed only from an estimator documented unbiased
 *               that produces it by design (power-series corrections, weighted collisions where a bound
 *               fails) — the path tracer multiplies it in like any other value; such an estimator says so
 *               in its one-line description (the word "negative"), or `murk check` holds it to
 *               non-negative estimates. An all-zero result means opaque: the shadow ray stops. An estimator that is biased by design (raymarch) must say
 *               so in its description, its header comment and a log line at create().
 *   Bounds      the majorant walk's dmax bounds the density only when majorant_factor >= 1, and dmin
 *               (the minorant) is a lower bound of the unscaled density. Where they fail, an unbiased
 *               estimator must stay unbiased (e.g. ratio-tracking weights 1 - sigma/mu that go negative)
 *               and finite, and say so once through host->warn_once.
 *
 * Spectral MIS. With chromatic extinction the integrator weights a path's contribution by beta_c over
 * mean_k(R_k), R the path's pdf ratios (murk/medium.h). A shadow ray's transmittance is not a sampling
 * decision of the path: it enters only as a factor of the light sample's contribution, and R is left
 * alone. So the pdf ratios stay right exactly when every channel's estimate is unbiased on its own for
 * any hero — an estimator must NOT return a hero-only estimate (channel h scaled by 3, the others 0, as
 * naive_spectral's free flights do), because that needs pdf ratios and estimate() has no way to return
 * them. Sampling decisions shared by all channels (one majorant for all, one set of positions) are fine
 * as long as each channel is reweighted by its own extinction. */
#include "murk/medium.h" /* outside the guard: medium.h includes this header after defining murk_medium */

#ifndef MURK_TRANSMITTANCE_H
#define MURK_TRANSMITTANCE_H

typedef struct murk_transmittance_vt {
    uint32_t size; /* sizeof(murk_transmittance_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_TRANSMITTANCE */
    /* create() gets its own parameters in `params` and the medium's data in `data` (valid for the
     * medium's whole life). */
    int (*create)(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                  char *err, size_t errlen);
    void (*destroy)(void *self);
    /* Per-channel unbiased estimate of exp(-int sigma_t) over (ray->tmin, ray->tmax); ctx is the path's
     * (hero channel, beta so far), as a tracker gets it. */
    murk_rgb (*estimate)(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng);
} murk_transmittance_vt;

#define MURK_TRANSMITTANCE_VT_SIZE_1_2 (offsetof(murk_transmittance_vt, estimate) + sizeof(void (*)(void)))
#define MURK_TRANSMITTANCE_PLUGIN(NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                          \
    MURK_DEFINE_PLUGIN_(MURK_KIND_TRANSMITTANCE, NAME, DESCRIPTION, PARAMS, NPARAMS,               \
                        _Generic((VT), const murk_transmittance_vt *: (VT), murk_transmittance_vt *: (VT)))

#endif
