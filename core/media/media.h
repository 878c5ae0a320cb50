/* media.h — the core side of participating media: the scene's `media:` block, density fields with
 * their majorant grids, and the host services trackers use. Internal to libmurk. */
#ifndef MURK_MEDIA_H
#define MURK_MEDIA_H

#include "murk/medium.h"
#include "murk/murk.h"
#include "yaml/yamldoc.h"

/* The `media:` block n: each medium's data, density and tracker (and estimator) plugins, created with the
 * services table host. */
int murk_media_load(murk_scene *s, const murk_host *host, const murk_ynode *n, char *err, size_t errlen);
/* Refuses a medium whose optical depth (largest extinction x max density x majorant_factor x extent:
 * its density box, or the scene's box [scene_lo, scene_hi] for a constant density) exceeds
 * MURK_MAX_OPTICAL_DEPTH (limit.h): a located error at the medium's scale/sigma key. */
int murk_media_check_depth(const murk_scene *s, const murk_ynode *media_node, murk_vec3 scene_lo, murk_vec3 scene_hi,
                           char *err, size_t errlen);

/* The keys every medium has, read by the core whatever the tracker (sigma_a, sigma_s, scale, g,
 * majorant_factor, majorant_resolution, majorant_repair, stratify_flights, temperature_scale,
 * temperature_offset), as a parameter schema; and the keys read apart from it ("density", "transmittance",
 * "phase", "albedo", "emission", "temperature"). `murk plugins TRACKER` lists them. */
#define MURK_MEDIUM_NCORE 10
#define MURK_MEDIUM_NSPECIAL 6
extern const murk_param murk_medium_core_params[MURK_MEDIUM_NCORE];
extern const char *const murk_medium_special_keys[MURK_MEDIUM_NSPECIAL];
struct murk_field;
/* A scalar field from a scene node (media/source.h: constant, grid, vdb, cloud); what names it
 * in messages ("density", "temperature"). NULL with a located error. */
struct murk_field *murk_media_scalar_field(const murk_scene *s, const murk_ynode *d, const char *what, char *err,
                                           size_t errlen);
/* Tells every medium the ABI minor of the scene's integrator (murk_medium_data.integrator_minor) and refuses
 * an emitting medium with an integrator built before ABI 1.9 (a located error at its emission or
 * temperature key of media_node). */
int murk_media_bind_integrator(murk_scene *s, const murk_ynode *media_node, const char *integrator, uint32_t minor,
                               char *err, size_t errlen);
void murk_media_free(murk_scene *s);
/* Wraps a scene's medium (its tracker and, if any, its transmittance estimator) so that every free
 * flight that scatters and every transmittance estimate is counted in the medium's slot (counted.c).
 * The wrapped destroy() frees the wrapper too. */
void murk_media_count_medium(murk_medium *m, unsigned slot);
/* What a medium's density is made of, for `murk info`: its field, majorant grid and majorant_factor. */
struct murk_field;
struct murk_bound_grid;
void murk_density_parts(const murk_density *d, const struct murk_field **field, const struct murk_bound_grid **grid,
                        float *factor);

float murk_media_density(const murk_density *d, murk_vec3 p);
/* The density lookups and majorant walks a render makes, in order: bench/long_paths replays them with
 * nothing else around them. Each event is a density() call (kind MURK_LOOKUP_DENSITY at ray.o), a
 * walk_init() (MURK_LOOKUP_WALK_INIT with its ray, t0 and t1) or a walk_next() (MURK_LOOKUP_WALK_NEXT);
 * `walk` tells the walks apart (its address). n counts every event (it may pass cap: the first cap are
 * kept); sum adds every density() result. Record with one render thread. */
enum { MURK_LOOKUP_DENSITY, MURK_LOOKUP_WALK_INIT, MURK_LOOKUP_WALK_NEXT };
typedef struct murk_lookup_event {
    const murk_density *d;
    const void *walk;
    murk_ray ray;
    float t0, t1;
    int kind;
} murk_lookup_event;
typedef struct murk_lookup_record {
    murk_lookup_event *ev;
    size_t n, cap;
    double sum;
} murk_lookup_record;
/* Records every lookup and walk step from now on into rec (NULL: stop). Only while no render runs. */
void murk_media_record_lookups(murk_lookup_record *rec);
void murk_media_walk_init(const murk_density *d, const murk_ray *ray, float t0, float t1, murk_majorant_walk *w);
int murk_media_walk_next(murk_majorant_walk *w, float *ta, float *tb, float *dmax, float *dmin);
/* The calling thread's cost counters for d's medium (runtime.h): the host's counters() service. */
murk_counters *murk_media_counters(const murk_density *d);
float murk_phase_hg_eval(float g, murk_vec3 wo, murk_vec3 wi);
murk_vec3 murk_phase_hg_sample(float g, murk_vec3 wo, const float u[2], float *pdf);
/* The host's medium services of ABI 1.9 (murk/plugin.h): a medium's phase function, albedo and emission. */
float murk_media_phase_eval(const murk_medium *m, murk_vec3 wo, murk_vec3 wi);
float murk_media_phase_sample(const murk_medium *m, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf);
murk_rgb murk_media_albedo(const murk_density *d, murk_vec3 p);
/* The medium's phase-function plugin (vt NULL: the built-in Henyey-Greenstein of its g), for murk check. */
struct murk_phase;
const struct murk_phase *murk_media_phase(const murk_medium *m);
murk_rgb murk_media_emission(const murk_density *d, murk_vec3 p);

#endif
