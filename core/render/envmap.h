/* envmap.h — a lat-long environment map: radiance by direction, importance-sampled (envmap.c). Internal
 * to libmurk.
 *
 * Mapping (Mitsuba's): a direction (x, y, z) in the map's frame has theta = acos(y) from +y and
 * phi = atan2(x, -z); it reads the map at u = 1/2 + phi / (2 pi) (image x: u w), v = theta / pi (image y,
 * row 0 at the top, +y). So the image's centre column looks along -z and u grows towards +x: seen from
 * inside, the picture is not mirrored. `rotation` (degrees) turns the map about +y, right-handed: world =
 * R_y(rotation) map. Radiance is the bilinear interpolation of the texels (wrapping in u, clamped in v).
 *
 * Sampling (pbrt-v4's PiecewiseConstant2D; Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th
 * ed., 12.5): a piecewise-constant density over (u, v) whose weight in texel (i, j) is the luminance of
 * the bilinear radiance averaged over the texel (the texel with 1/8, 3/4, 1/8 of its neighbours along
 * each axis: positive wherever the radiance is) times sin(theta) at the row's centre; a row by the
 * marginal, a column by the row's conditional, a point uniformly in the texel. Its solid-angle pdf is
 * p(u, v) / (2 pi^2 sin theta). */
#ifndef MURK_ENVMAP_H
#define MURK_ENVMAP_H

#include <stddef.h>

#include "murk/math.h"

struct murk_envmap {
    int w, h;
    float *rgb;       /* 3 w h radiances, the scale applied */
    float *f;         /* w h sampling weights */
    double *row_cdf;  /* h + 1 */
    double *col_cdf;  /* h (w + 1) */
    double fsum;      /* the sum of f: 0 for a black map, which is never sampled */
    double integral;  /* the luminance integrated over the sphere of directions (sr) */
    float cos_rot, sin_rot;
};
typedef struct murk_envmap murk_envmap;

/* A map from w x h RGB texels (row 0 at the top) times scale, turned by rotation_deg about +y. NULL with
 * err ("what is wrong": not lat-long, a NaN, infinite or negative texel and where) on bad input. */
murk_envmap *murk_envmap_new(const float *rgb, int w, int h, murk_rgb scale, double rotation_deg, char *err,
                             size_t errlen);
void murk_envmap_free(murk_envmap *e);
/* The radiance arriving from world direction dir (unit), i.e. seen by a ray leaving along dir. */
murk_rgb murk_envmap_eval(const murk_envmap *e, murk_vec3 dir);
/* The solid-angle pdf of murk_envmap_sample at dir. */
float murk_envmap_pdf(const murk_envmap *e, murk_vec3 dir);
/* A direction by the pdf above from u in [0, 1)^2: 1, or 0 if none (a black map, a pole). */
int murk_envmap_sample(const murk_envmap *e, const float u[2], murk_vec3 *dir, float *pdf);

#endif
