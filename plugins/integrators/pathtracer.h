/* pathtracer.h — the path tracer behind the `path`, `volpath` and `volpath_nee` integrator plugins.
 * Compiled into each of the three modules (and into the tests); not a public header.
 *
 * A path carries an RGB weight beta and RGB pdf ratios R (both start at 1; see murk/medium.h) and
 * credits emitted radiance Le as beta * Le / mean(R). A hero channel is drawn uniformly per path for
 * the trackers that sample per channel.
 *
 * Media are tracked through index-matched boundaries (shapes with no material): crossing against the
 * normal enters `interior`, along it leaves to `exterior`; the camera starts in the scene's camera
 * medium. A material that transmits (MURK_MATERIAL_ORIENTED, murk/material.h: dielectric) moves a path
 * whose sampled direction crosses the surface into the medium on the far side, the same way; total
 * internal reflection is simply a reflected sample, so the path stays. Other materials only reflect.
 *
 * Shadow rays stop at every surface with a material, a refracting one included: light does not reach a
 * point in a glass by a straight line through the glass (it is bent there). NEE therefore finds no
 * light behind a dielectric, and that light arrives through BSDF / phase sampling alone: after a smooth
 * dielectric (a delta lobe) the emission found counts with MIS weight 1, since no light sample could
 * have produced that path; after a rough one it is weighted against the NEE done at the rough
 * surface vertex itself. So no light is counted twice and none is lost — the interface does not darken
 * direct light, it only makes it noisier (volpath_nee inside glass behaves like volpath for light
 * outside the glass).
 *
 * With nee = 1 every scattering vertex (surface or medium) also samples a light point and estimates
 * the transmittance to it (murk_pt_shadow); the light sample and the BSDF / phase sample are weighted
 * by the power heuristic on their solid-angle pdfs (unbiased: the weights depend on the direction
 * only and sum to 1). A light at infinity (a distant light, the environment: dist = INFINITY) is
 * reached by a shadow ray that runs to infinity along its direction (murk_pt_shadow_inf); a delta light
 * (point, spot, delta distant) counts with weight 1, since no BSDF or phase sample can hit it. A ray that
 * leaves the scene after a BSDF / phase sample adds background() weighted by the power heuristic
 * against environment_pdf(), the pdf with which light sampling picks its direction (1 where none can:
 * a constant background, which light sampling leaves out). With nee = 0 emission is found by BSDF / phase sampling alone — a slower,
 * independent estimator of the same image. With media = 0 (`path`) media are ignored and boundaries
 * passed straight through, by paths and shadow rays alike. Russian roulette after rr_depth events on
 * the path's largest channel weight over mean(R), relative to rr_threshold; survivors are divided by
 * the survival probability. */
#ifndef MURK_PATHTRACER_H
#define MURK_PATHTRACER_H

#include "murk/integrator.h"
#include "murk/medium.h"

/* The parameters all three integrators share (described in their schema entries, pathtracer.c). */
enum { MURK_PT_MAX_DEPTH, MURK_PT_RR_DEPTH, MURK_PT_LIGHT_SAMPLING, MURK_PT_RR_THRESHOLD, MURK_PT_NPARAMS };
extern const murk_param murk_pt_params[MURK_PT_NPARAMS];
/* volpath_nee's: the shared ones, then its own. */
enum { MURK_PT_EQUIANGULAR = MURK_PT_NPARAMS, MURK_PT_NEE_NPARAMS };
extern const murk_param murk_pt_nee_params[MURK_PT_NEE_NPARAMS];

typedef struct murk_pt {
    const murk_host *host;
    int max_depth, rr_depth;
    int nee;   /* sample lights at every scattering vertex */
    int media; /* track media (0: surfaces only, boundaries are invisible) */
    int light_strategy; /* MURK_LIGHT_* for NEE and the MIS weight of emission found (0: area, the default) */
    float rr_threshold; /* Russian roulette's survival probability is min(1, weight / rr_threshold) (0: 1) */
    int equiangular;    /* volpath_nee: equiangular distance sampling towards a light point per medium
                         * segment, MIS-combined with the tracker's free flights (pathtracer.c) */
} murk_pt;

/* create() for an integrator with the given strategy (params: murk_pt_nee_params when nee, else
 * murk_pt_params); destroy() for all of them. */
int murk_pt_create(const murk_host *host, const murk_value *params, int nee, int media, void **self, char *err,
                   size_t errlen);
void murk_pt_destroy(void *self);

/* Radiance along a camera ray (the integrator vtable's li()). */
murk_rgb murk_pt_li(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng);

/* Transmittance of a shadow ray from p to the point q (on a light): 0 if a surface with a material
 * (reflecting or refracting) blocks the way, else the product of the media's transmittance() estimates over the legs between
 * index-matched boundaries. m: the medium at p (ignored, like every medium, when pt->media = 0).
 * offset_n: the normal to offset a surface point along, or a zero vector for a point in a medium.
 * Every leg is aimed at q itself and stops 1e-4 max(1, |q|_inf) short of it. */
murk_rgb murk_pt_shadow(const murk_pt *pt, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 q,
                        const murk_medium *m, const murk_path_ctx *ctx, murk_rng *rng);

/* The same towards a light at infinity in direction wi: every leg keeps wi and runs to infinity. */
murk_rgb murk_pt_shadow_inf(const murk_pt *pt, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 wi,
                            const murk_medium *m, const murk_path_ctx *ctx, murk_rng *rng);

/* The techniques the path tracer tells apart, one for each contribution it makes to a sample (its
 * `term`): light sampling at a surface vertex, at a free-flight medium vertex and at the equiangular
 * vertex; emission found by BSDF sampling, by phase sampling, by the camera ray itself; the background.
 * And how a path ended. Only a build with the tap (-DMURK_PT_TAP, pathtracer_tap.h: bench/variance_profile,
 * never the plugins) reports them. */
enum { MURK_PT_TERM_SURFACE_NEE, MURK_PT_TERM_MEDIUM_NEE, MURK_PT_TERM_EQUIANGULAR_NEE, MURK_PT_TERM_BSDF_EMISSION,
       MURK_PT_TERM_PHASE_EMISSION, MURK_PT_TERM_CAMERA_EMISSION, MURK_PT_TERM_BACKGROUND, MURK_PT_NTERMS };
enum { MURK_PT_END_ROULETTE, MURK_PT_END_MAX_DEPTH, MURK_PT_END_ABSORBED, MURK_PT_END_ESCAPED, MURK_PT_NENDS };

#endif
