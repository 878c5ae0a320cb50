/* accel.h — what is built over a loaded scene for rendering: the Embree scene (accel.c) and the light
 * list with its sampling CDF (lights.c). Internal to libmurk. */
#ifndef MURK_ACCEL_H
#define MURK_ACCEL_H

#include <stddef.h>

#include "scene.h"

/* Returns 0, or -1 with err = "scene.yaml: what went wrong". */
int murk_accel_build(murk_scene *s, char *err, size_t errlen);
void murk_lights_build(murk_scene *s);

#endif
