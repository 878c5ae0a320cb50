/* scene_lights.c — the lights of the `lights:` block: point and spot lights (pbrt-v4's, with its
 * smoothstep falloff), distant lights (delta, or a uniform cone of directions: the sun's disk), lat-long
 * environment maps (envmap.c) and Preetham's sky (sky.c). Their adders check the input; their samples
 * are what murk_lights_sample (lights.c) returns when it picks one of them. See lights.h. */
#include "render/lights.h"
#include "image/image.h"
#include "render/envmap.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void add(murk_scene *s, const murk_light *l)
{
    s->added = murk_xrealloc(s->added, (s->nadded + 1) * sizeof *s->added);
    s->added[s->nadded++] = *l;
}

/* Intensities and irradiances: finite, not negative. */
static int check_rgb(murk_rgb c, const char *what, char *err, size_t errlen)
{
    for (int k = 0; k < 3; k++)
        if (!(c.c[k] >= 0.0f) || !isfinite(c.c[k])) {
            snprintf(err, errlen, "%s must be finite and not negative, got [%g, %g, %g]", what, (double)c.c[0],
                     (double)c.c[1], (double)c.c[2]);
            return -1;
        }
    return 0;
}

static int check_position(murk_vec3 p, char *err, size_t errlen)
{
    if (!(fabs(p.x) <= MURK_MAX_COORD && fabs(p.y) <= MURK_MAX_COORD && fabs(p.z) <= MURK_MAX_COORD)) {
        snprintf(err, errlen, "position [%g, %g, %g] lies beyond %g, the largest coordinate murk accepts", (double)p.x,
                 (double)p.y, (double)p.z, MURK_MAX_COORD);
        return -1;
    }
    return 0;
}

/* A unit direction from d, or -1 with err when d has no length (or is not finite). */
static int unit_dir(murk_vec3 d, const char *what, murk_vec3 *out, char *err, size_t errlen)
{
    double len = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
    if (!(len > 0.0) || !isfinite(len)) {
        snprintf(err, errlen, "%s [%g, %g, %g] has no length: give the direction it points in", what, (double)d.x,
                 (double)d.y, (double)d.z);
        return -1;
    }
    *out = murk_v3((float)(d.x / len), (float)(d.y / len), (float)(d.z / len));
    return 0;
}

int murk_lights_add_point(murk_scene *s, murk_vec3 position, murk_rgb intensity, char *err, size_t errlen)
{
    if (check_position(position, err, errlen) || check_rgb(intensity, "intensity", err, errlen))
        return -1;
    murk_light l = {0};
    l.kind = MURK_LK_POINT;
    l.center = position;
    l.le = intensity;
    add(s, &l);
    return 0;
}

int murk_lights_add_spot(murk_scene *s, murk_vec3 position, murk_vec3 direction, murk_rgb intensity, double cone_deg,
                         double falloff_deg, char *err, size_t errlen)
{
    murk_light l = {0};
    if (check_position(position, err, errlen) || unit_dir(direction, "direction", &l.n, err, errlen) ||
        check_rgb(intensity, "intensity", err, errlen))
        return -1;
    if (!(cone_deg > 0.0 && cone_deg <= 180.0) || !(falloff_deg >= 0.0 && falloff_deg <= 180.0)) {
        snprintf(err, errlen, "cone_angle must be in (0, 180] and falloff_angle in [0, 180] degrees, got %g and %g",
                 cone_deg, falloff_deg);
        return -1;
    }
    if (cone_deg < falloff_deg) {
        snprintf(err, errlen, "cone_angle (%g, where the spot reaches 0) is smaller than falloff_angle (%g, where "
                 "it is still at full intensity): cone_angle must be at least falloff_angle", cone_deg, falloff_deg);
        return -1;
    }
    l.kind = MURK_LK_SPOT;
    l.center = position;
    l.le = intensity;
    l.cos_cone = (float)cos(cone_deg * M_PI / 180.0);
    l.cos_falloff = (float)cos(falloff_deg * M_PI / 180.0);
    add(s, &l);
    return 0;
}

int murk_lights_add_distant(murk_scene *s, murk_vec3 towards, murk_rgb irradiance, double angular_diameter_deg,
                            char *err, size_t errlen)
{
    murk_light l = {0};
    if (unit_dir(towards, "direction", &l.n, err, errlen) || check_rgb(irradiance, "irradiance", err, errlen))
        return -1;
    if (!(angular_diameter_deg >= 0.0 && angular_diameter_deg < 180.0)) {
        snprintf(err, errlen, "angular_diameter must be in [0, 180) degrees, got %g (a cone of half-angle 90 or more "
                 "is no distant light)", angular_diameter_deg);
        return -1;
    }
    l.kind = MURK_LK_DISTANT;
    l.le = irradiance;
    if (angular_diameter_deg >= MURK_DISTANT_DELTA_DEG) {
        double a = 0.5 * angular_diameter_deg * M_PI / 180.0, sh = sin(0.5 * a), sa = sin(a);
        l.omc = (float)(2.0 * sh * sh);                           /* 1 - cos(a), accurate when tiny */
        l.lc = murk_rgb_scale(irradiance, (float)(1.0 / (M_PI * sa * sa))); /* E / (pi sin^2 a) */
    }
    add(s, &l);
    return 0;
}

int murk_lights_add_envmap_rgb(murk_scene *s, const float *rgb, int w, int h, murk_rgb scale, double rotation_deg,
                               char *err, size_t errlen)
{
    if (check_rgb(scale, "scale", err, errlen))
        return -1;
    if (!(fabs(rotation_deg) <= 1e6)) {
        snprintf(err, errlen, "rotation must be within [-1e6, 1e6] degrees, got %g", rotation_deg);
        return -1;
    }
    murk_envmap *e = murk_envmap_new(rgb, w, h, scale, rotation_deg, err, errlen);
    if (!e)
        return -1;
    s->envmaps = murk_xrealloc(s->envmaps, (s->nenvmaps + 1) * sizeof *s->envmaps);
    s->envmaps[s->nenvmaps++] = e;
    murk_light l = {0};
    l.kind = MURK_LK_ENVMAP;
    l.env = e;
    l.le = murk_rgb1(1.0f);
    add(s, &l);
    return 0;
}

int murk_lights_add_envmap(murk_scene *s, const char *path, murk_rgb scale, double rotation_deg, char *err,
                           size_t errlen)
{
    murk_image img;
    if (murk_exr_read(path, &img, err, errlen))
        return -1;
    char why[512];
    int rc = murk_lights_add_envmap_rgb(s, img.rgb, img.w, img.h, scale, rotation_deg, why, sizeof why);
    if (rc)
        snprintf(err, errlen, "%s: %s", path, why);
    murk_image_free(&img);
    return rc;
}

int murk_lights_add_sky(murk_scene *s, murk_vec3 sun_dir, double turbidity, int sun, char *err, size_t errlen)
{
    murk_vec3 d;
    if (unit_dir(sun_dir, "sun_direction", &d, err, errlen))
        return -1;
    if (!(turbidity >= 1.7 && turbidity <= 10.0)) {
        snprintf(err, errlen, "turbidity must be in [1.7, 10] (the range Preetham's model was fitted to), got %g",
                 turbidity);
        return -1;
    }
    if (!(d.y > 0.0f)) {
        murk_log(MURK_LOG_WARN, "sky: the sun is below the horizon (sun_direction [%g, %g, %g]): Preetham's model is "
                 "for daylight only, so the sky is black and there is no sun", (double)sun_dir.x, (double)sun_dir.y,
                 (double)sun_dir.z);
        return 0;
    }
    float *rgb = murk_sky_table(d, turbidity, MURK_SKY_W, MURK_SKY_H);
    int rc = murk_lights_add_envmap_rgb(s, rgb, MURK_SKY_W, MURK_SKY_H, murk_rgb1(1.0f), 0.0, err, errlen);
    free(rgb);
    if (rc == 0 && sun)
        rc = murk_lights_add_distant(s, d, murk_sky_sun_irradiance(d.y, turbidity), MURK_SUN_DIAMETER_DEG, err,
                                     errlen);
    return rc;
}

/* ---- sampling ------------------------------------------------------------------------------------- */

int murk_light_is_env(const murk_light *l)
{
    return l->kind == MURK_LK_ENVMAP || (l->kind == MURK_LK_DISTANT && l->omc > 0.0f);
}

/* 1 - cos of the angle between unit vectors a and b, accurate when tiny: |a - b|^2 / 2. */
static float one_minus_cos(murk_vec3 a, murk_vec3 b)
{
    murk_vec3 d = murk_sub(a, b);
    return 0.5f * murk_dot(d, d);
}

murk_rgb murk_light_env_radiance(const murk_light *l, murk_vec3 dir)
{
    if (l->kind == MURK_LK_ENVMAP)
        return l->env ? murk_envmap_eval(l->env, dir) : l->le;
    return one_minus_cos(dir, l->n) <= l->omc ? l->lc : murk_rgb1(0.0f);
}

float murk_light_env_pdf(const murk_light *l, murk_vec3 dir)
{
    if (l->kind == MURK_LK_ENVMAP)
        return l->env ? murk_envmap_pdf(l->env, dir) : 0.25f * MURK_INV_PI;
    return one_minus_cos(dir, l->n) <= l->omc ? 1.0f / (2.0f * MURK_PI * l->omc) : 0.0f;
}

/* A direction of environment part l from u[1], u[2]. */
static int sample_env_dir(const murk_light *l, const float u[3], murk_vec3 *dir)
{
    float pdf;
    if (l->kind == MURK_LK_ENVMAP && l->env)
        return murk_envmap_sample(l->env, u + 1, dir, &pdf);
    float omc = l->kind == MURK_LK_ENVMAP ? 2.0f : l->omc; /* the whole sphere, or the cone */
    murk_vec3 axis = l->kind == MURK_LK_ENVMAP ? murk_v3(0, 1, 0) : l->n, t, b;
    murk_basis(axis, &t, &b);
    float x = u[1] * omc, cost = 1.0f - x, sint = sqrtf(murk_maxf(0.0f, x * (2.0f - x))), phi = 2.0f * MURK_PI * u[2];
    *dir = murk_normalize(murk_from_local(murk_v3(sint * cosf(phi), sint * sinf(phi), cost), t, b, axis));
    return 1;
}

/* pbrt-v4's SmoothStep(cos theta, cos cone, cos falloff). */
static float spot_falloff(const murk_light *l, float cost)
{
    if (cost >= l->cos_falloff)
        return 1.0f;
    if (cost <= l->cos_cone)
        return 0.0f;
    float t = (cost - l->cos_cone) / (l->cos_falloff - l->cos_cone);
    return t * t * (3.0f - 2.0f * t);
}

int murk_lights_sample_added(const murk_scene *s, const murk_light *l, murk_vec3 p, const float u[3],
                             murk_light_sample *ls)
{
    if (l->kind == MURK_LK_POINT || l->kind == MURK_LK_SPOT) {
        murk_vec3 d = murk_sub(l->center, p);
        float dist2 = murk_dot(d, d), dist = sqrtf(dist2);
        if (!(dist > 0.0f))
            return 0;
        ls->wi = murk_mul(d, 1.0f / dist);
        float k = l->kind == MURK_LK_SPOT ? spot_falloff(l, -murk_dot(ls->wi, l->n)) : 1.0f;
        if (!(k > 0.0f))
            return 0;
        ls->dist = dist;
        ls->le = murk_rgb_scale(l->le, k / dist2);
        ls->pdf = l->pmf;
        ls->flags = MURK_LIGHT_SAMPLE_DELTA;
        return isfinite(ls->le.c[0] + ls->le.c[1] + ls->le.c[2]);
    }
    if (l->kind == MURK_LK_DISTANT && !(l->omc > 0.0f)) {
        ls->wi = l->n;
        ls->dist = INFINITY;
        ls->le = l->le;
        ls->pdf = l->pmf;
        ls->flags = MURK_LIGHT_SAMPLE_DELTA;
        return 1;
    }
    /* the environment: a direction by this part, then, as one light that is the mixture of all parts, its
     * whole radiance over the mixture's pdf (so that escaped rays weigh background() by the same pdf) */
    murk_vec3 dir;
    if (!sample_env_dir(l, u, &dir))
        return 0;
    ls->wi = dir;
    ls->dist = INFINITY;
    ls->pdf = murk_lights_environment_pdf(s, dir);
    ls->le = murk_lights_background(s, dir);
    return ls->pdf > 0.0f && isfinite(ls->pdf) && !murk_rgb_is_black(ls->le);
}

double murk_light_added_weight(const murk_light *l, double R)
{
    double lum = murk_luminance(l->le);
    switch (l->kind) {
    case MURK_LK_POINT:
        return 4.0 * lum;
    case MURK_LK_SPOT:
        return 2.0 * lum * (1.0 - 0.5 * ((double)l->cos_falloff + (double)l->cos_cone));
    case MURK_LK_DISTANT:
        return lum * R * R;
    case MURK_LK_ENVMAP:
        return R * R * (l->env ? l->env->integral : 4.0 * M_PI * lum);
    default:
        return 0.0;
    }
}
