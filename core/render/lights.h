/* lights.h — the scene's light table (lights.c: emissive shapes, selection by power, the environment)
 * and the lights of the `lights:` block (scene_lights.c), which C code may add too (a glTF loader's
 * KHR_lights_punctual, a test): point, spot, distant, environment map, sky. Internal to libmurk.
 *
 * Why a core table and not a plugin kind: choosing a light by power needs every light in one
 * distribution; escaped rays need the environment evaluated by the host (background()); MIS needs each
 * light's pdf for a direction (environment_pdf()); the environment map and the sky need the core's EXR
 * reader and its limits.
 *
 * Add lights after the shapes are loaded and before murk_lights_build (murk_scene_load calls it after
 * building the Embree scene: an environment's power needs the scene's bounding sphere). Every adder
 * checks its input and returns 0, or -1 with err = "what is wrong" (no location: the YAML loader,
 * load/light_block.c, puts one before it). Angles are in degrees; directions need not be unit but must
 * not be zero. */
#ifndef MURK_LIGHTS_H
#define MURK_LIGHTS_H

#include <stddef.h>

#include "scene/scene.h"

/* Builds the light table from the emissive shapes and the added lights: every light's probability of
 * being chosen in proportion to its power (over pi): luminance x area for an emitting triangle or
 * sphere, 4 I for a point light, 2 I (1 - (cos falloff + cos cone) / 2) for a spot (its smoothstep profile
 * integrated exactly), E R^2 for a distant light and R^2 times the luminance integrated over directions
 * for an environment (R: the radius of the scene's bounding sphere, pbrt-v4's choice). With a legacy
 * integrator (scene.legacy_lights) the added lights get probability 0, and delta lights are an error.
 * Returns 0, or -1 with err = "scene.yaml: what is wrong". */
int murk_lights_build(murk_scene *s, char *err, size_t errlen);
/* The host's sample_light_with / light_pdf_with (murk/plugin.h); strategy: MURK_LIGHT_*. */
int murk_lights_sample(const murk_scene *s, murk_vec3 p, const float u[3], int strategy, murk_light_sample *ls);
float murk_lights_pdf(const murk_scene *s, murk_vec3 p, const murk_hit *h, int strategy);
/* The host's background() and environment_pdf(): the environment's radiance towards -dir (the constant
 * background, or the sum of its parts), and the pdf with which murk_lights_sample picks dir. */
murk_rgb murk_lights_background(const murk_scene *s, murk_vec3 dir);
float murk_lights_environment_pdf(const murk_scene *s, murk_vec3 dir);

/* ---- the lights of the `lights:` block (scene_lights.c) ------------------------------------------- */

/* A point light of intensity I (W/sr, RGB). */
int murk_lights_add_point(murk_scene *s, murk_vec3 position, murk_rgb intensity, char *err, size_t errlen);
/* A spot at position shining along direction: intensity I within falloff_deg of its axis (half-angle),
 * falling to 0 at cone_deg by pbrt-v4's smoothstep in cos theta; cone_deg >= falloff_deg, cone_deg in
 * (0, 180]. */
int murk_lights_add_spot(murk_scene *s, murk_vec3 position, murk_vec3 direction, murk_rgb intensity, double cone_deg,
                         double falloff_deg, char *err, size_t errlen);
/* A distant light in direction `towards` (from the scene to the light) giving irradiance E (W/m^2) on
 * a surface facing it: a delta light when angular_diameter_deg < MURK_DISTANT_DELTA_DEG, else uniform
 * radiance E / (pi sin^2 alpha) in the cone of half-angle alpha = diameter / 2 (< 90 degrees), which
 * gives exactly E on a facing surface (and E cos theta on one tilted by theta while the cone stays above
 * its horizon). */
int murk_lights_add_distant(murk_scene *s, murk_vec3 towards, murk_rgb irradiance, double angular_diameter_deg,
                            char *err, size_t errlen);
#define MURK_DISTANT_DELTA_DEG 1e-3
/* An environment map from a lat-long RGB EXR file (envmap.h), its radiance times scale, turned by
 * rotation_deg about +y. err names the file. */
int murk_lights_add_envmap(murk_scene *s, const char *path, murk_rgb scale, double rotation_deg, char *err,
                           size_t errlen);
/* The same from w x h RGB texels in memory (row 0 at the top), copied. */
int murk_lights_add_envmap_rgb(murk_scene *s, const float *rgb, int w, int h, murk_rgb scale, double rotation_deg,
                               char *err, size_t errlen);
/* Preetham's daylight sky (sky.c) for the sun in direction sun_dir and turbidity T in [1.7, 10],
 * tabulated into an environment map of MURK_SKY_W x MURK_SKY_H texels; with sun, also the sun as a
 * distant light of angular diameter MURK_SUN_DIAMETER_DEG. A sun below the horizon adds nothing (the
 * model is for daylight) and says so. */
int murk_lights_add_sky(murk_scene *s, murk_vec3 sun_dir, double turbidity, int sun, char *err, size_t errlen);
#define MURK_SKY_W 512
#define MURK_SKY_H 256
#define MURK_SUN_DIAMETER_DEG 0.53

/* sky.c: the sky's radiance table (3 w h floats, malloc'd; envmap.h's layout) and the sun's irradiance
 * for a sun at cos(theta_s) from the zenith. */
float *murk_sky_table(murk_vec3 sun_dir, double turbidity, int w, int h);
murk_rgb murk_sky_sun_irradiance(double cos_theta_s, double turbidity);

/* scene_lights.c: the light sample, radiance and pdf of a light of the `lights:` block (kind >= POINT);
 * what murk_lights_sample dispatches to. */
int murk_lights_sample_added(const murk_scene *s, const murk_light *l, murk_vec3 p, const float u[3],
                             murk_light_sample *ls);
/* An environment part's radiance towards -dir and its own solid-angle pdf for dir. */
murk_rgb murk_light_env_radiance(const murk_light *l, murk_vec3 dir);
float murk_light_env_pdf(const murk_light *l, murk_vec3 dir);
/* The light's power over pi (see murk_lights_build) for a scene of bounding radius R. */
double murk_light_added_weight(const murk_light *l, double R);
/* 1 if the light is part of the environment (an envmap, a distant light with a cone). */
int murk_light_is_env(const murk_light *l);

#endif
