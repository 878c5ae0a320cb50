/* lights.c — emissive shapes as lights: one light per emitting triangle or sphere, chosen in
 * proportion to its power (luminance x area), sampled uniformly by area (triangles) or uniformly in
 * the cone of directions the sphere subtends (spheres). Triangles and quads emit on the side of their
 * normal only; spheres emit outwards. */
#include "accel.h"
#include "util.h"

#include <stdlib.h>

static void add_light(murk_scene *s, size_t *cap, const murk_light *l)
{
    if (s->nlights == *cap) {
        *cap = *cap ? 2 * *cap : 16;
        s->lights = murk_xrealloc(s->lights, *cap * sizeof *s->lights);
    }
    s->lights[s->nlights++] = *l;
}

void murk_lights_build(murk_scene *s)
{
    size_t cap = 0;
    for (size_t i = 0; i < s->nshapes; i++) {
        murk_shape *sh = &s->shapes[i];
        if (murk_rgb_max(sh->emission) <= 0.0f)
            continue;
        sh->light_base = (int32_t)s->nlights;
        murk_light l = {0};
        l.geom = (uint32_t)i;
        l.le = sh->emission;
        if (sh->type == MURK_SHAPE_SPHERE) {
            l.sphere = 1;
            l.center = sh->center;
            l.radius = sh->radius;
            l.area = 4.0f * MURK_PI * sh->radius * sh->radius;
            add_light(s, &cap, &l);
            continue;
        }
        for (uint32_t t = 0; t < sh->ntris; t++) {
            const uint32_t *ix = &sh->idx[3 * t];
            murk_vec3 a = murk_v3(sh->pos[3 * ix[0]], sh->pos[3 * ix[0] + 1], sh->pos[3 * ix[0] + 2]);
            murk_vec3 b = murk_v3(sh->pos[3 * ix[1]], sh->pos[3 * ix[1] + 1], sh->pos[3 * ix[1] + 2]);
            murk_vec3 c = murk_v3(sh->pos[3 * ix[2]], sh->pos[3 * ix[2] + 1], sh->pos[3 * ix[2] + 2]);
            l.prim = t;
            l.p0 = a;
            l.e1 = murk_sub(b, a);
            l.e2 = murk_sub(c, a);
            murk_vec3 cr = murk_cross(l.e1, l.e2);
            l.area = 0.5f * murk_length(cr);
            l.n = murk_normalize(cr);
            add_light(s, &cap, &l); /* degenerate triangles get area 0 and are never picked */
        }
    }
    s->light_cdf = murk_xmalloc((s->nlights + 1) * sizeof(float));
    double total = 0.0, run = 0.0;
    for (size_t i = 0; i < s->nlights; i++)
        total += (double)murk_luminance(s->lights[i].le) * s->lights[i].area;
    for (size_t i = 0; i < s->nlights; i++) {
        double w = (double)murk_luminance(s->lights[i].le) * s->lights[i].area;
        s->light_cdf[i] = total > 0 ? (float)(run / total) : 0.0f;
        s->lights[i].pmf = total > 0 ? (float)(w / total) : 0.0f;
        run += w;
    }
    s->light_cdf[s->nlights] = 1.0f;
    s->light_power = (float)total;
}
