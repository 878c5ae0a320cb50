/* accel.h — the Embree scene built over a loaded scene for rendering (accel.c), and the triangle helpers
 * it shares with host.c and lights.c (the light table: render/lights.h). Internal to libmurk. */
#ifndef MURK_ACCEL_H
#define MURK_ACCEL_H

#include <math.h>
#include <stddef.h>

#include "scene/scene.h"

/* Vertex i of a triangle shape. */
static inline murk_vec3 murk_shape_vertex(const murk_shape *sh, size_t i)
{
    const float *v = &sh->pos[3 * i]; /* size_t: one address, the three floats at constant offsets */
    return murk_v3(v[0], v[1], v[2]);
}

/* The bounds of shape sh: a sphere's box, or its vertices'. */
static inline void murk_shape_bounds(const murk_shape *sh, murk_vec3 *lo, murk_vec3 *hi)
{
    if (sh->type == MURK_SHAPE_SPHERE) {
        murk_vec3 r = murk_v3(sh->radius, sh->radius, sh->radius);
        *lo = murk_sub(sh->center, r);
        *hi = murk_add(sh->center, r);
        return;
    }
    *lo = murk_v3(INFINITY, INFINITY, INFINITY);
    *hi = murk_v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t v = 0; sh->pos && v < sh->nverts; v++) {
        *lo = murk_vmin(*lo, murk_shape_vertex(sh, v));
        *hi = murk_vmax(*hi, murk_shape_vertex(sh, v));
    }
}

/* The unit geometric normal of triangle (a, b, c): (b - a) x (c - a), normalised. accel.c stores it per
 * triangle (murk_shape.ng) and host.c uses the stored one, so both must compute it here. */
static inline murk_vec3 murk_triangle_normal(murk_vec3 a, murk_vec3 b, murk_vec3 c)
{
    return murk_normalize(murk_cross(murk_sub(b, a), murk_sub(c, a)));
}

/* A box or sphere shape holding a medium (interior set) and nothing else: no other shape's bounds meet
 * its bounds. A ray that starts inside it meets its surface before anything else, so host.c finds that
 * point by a slab test (a box) or the far root of a quadratic (a sphere) instead of asking Embree: the
 * free flights and shadow rays from the scattering events of a medium in a box or a sphere, the
 * commonest medium setups, cost no traversal. Nothing else lies within its bounds either, so a ray from
 * outside meets it where the same test (the near root of a sphere) says, unless Embree finds a surface
 * first: its geometry is left out of Embree's tree (disabled), and every ray that passes or crosses it
 * traverses a smaller tree. At most MURK_EMPTY_SHAPE_MAX per scene (each costs every
 * ray an inside test), found among the first 2 x MURK_EMPTY_SHAPE_MAX medium boxes and spheres (each is
 * checked against every primitive at load). */
enum { MURK_EMPTY_SHAPE_MAX = 8 };
typedef struct murk_box_tri {
    uint32_t prim;     /* the triangle's index in its shape */
    murk_vec3 a, g1, g2; /* its first corner and dual edge vectors: barycentrics (b1, b2) = ((p-a).g1, (p-a).g2) */
    murk_vec3 b, c, ng;  /* its other corners and its stored unit normal (murk_shape.ng), and */
    float uv[6];         /* its corners' (u, v): host.c fills a hit on it without the shape's arrays */
} murk_box_tri;
typedef struct murk_empty_shape {
    murk_vec3 lo, hi;       /* its bounds */
    uint32_t geom;          /* the shape's index (its Embree geometry id) */
    int sphere;             /* 1: a sphere (center, radius), else a box (tri) */
    murk_vec3 center;
    float radius;
    murk_box_tri tri[6][2]; /* a box: the two triangles of face 2a (the +a side, a = x, y, z) and 2a + 1 (-a) */
} murk_empty_shape;

/* Spheres that are not empty medium shapes, when a scene has at most MURK_FEW_SPHERES of them: host.c
 * intersects them itself and Embree's tree leaves them out. Embree keeps spheres in a tree of their own
 * beside the triangles' and traverses both for every ray; for a few spheres a test of each costs less. */
enum { MURK_FEW_SPHERES = 8 };

/* Returns 0, or -1 with err = "scene.yaml: what went wrong". Also finds the empty medium shapes. */
int murk_accel_build(murk_scene *s, char *err, size_t errlen);
/* The bounds of every shape's primitives: Embree's tree's and the empty medium shapes' (which it leaves
 * out). Empty (lo > hi) for a scene without shapes. */
void murk_accel_bounds(const murk_scene *s, murk_vec3 *lo, murk_vec3 *hi);

#endif
