/* accel.h — what is built over a loaded scene for rendering: the Embree scene (accel.c) and the light
 * list with its sampling CDF (lights.c). Internal to libmurk. */
#ifndef MURK_ACCEL_H
#define MURK_ACCEL_H

#include <stddef.h>

#include "scene.h"

/* Returns 0, or -1 with err = "scene.yaml: what went wrong". */
int murk_accel_build(murk_scene *s, char *err, size_t errlen);
void murk_lights_build(murk_scene *s);
/* The host's sample_light_with / light_pdf_with (murk/plugin.h); strategy: MURK_LIGHT_*. */
int murk_lights_sample(const murk_scene *s, murk_vec3 p, const float u[3], int strategy, murk_light_sample *ls);
float murk_lights_pdf(const murk_scene *s, murk_vec3 p, const murk_hit *h, int strategy);

#endif
