/* accel.h — the Embree scene built over a loaded scene for rendering (accel.c), and the triangle helpers
 * it shares with host.c and lights.c (the light table: render/lights.h). Internal to libmurk. */
#ifndef MURK_ACCEL_H
#define MURK_ACCEL_H

#include <stddef.h>

#include "scene/scene.h"

/* Vertex i of a triangle shape. */
static inline murk_vec3 murk_shape_vertex(const murk_shape *sh, size_t i)
{
    const float *v = &sh->pos[3 * i]; /* size_t: one address, the three floats at constant offsets */
    return murk_v3(v[0], v[1], v[2]);
}

/* The unit geometric normal of triangle (a, b, c): (b - a) x (c - a), normalised. accel.c stores it per
 * triangle (murk_shape.ng) and host.c uses the stored one, so both must compute it here. */
static inline murk_vec3 murk_triangle_normal(murk_vec3 a, murk_vec3 b, murk_vec3 c)
{
    return murk_normalize(murk_cross(murk_sub(b, a), murk_sub(c, a)));
}

/* Returns 0, or -1 with err = "scene.yaml: what went wrong". */
int murk_accel_build(murk_scene *s, char *err, size_t errlen);

#endif
