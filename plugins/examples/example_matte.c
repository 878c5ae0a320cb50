/* example_matte — a Lambertian (matte) material with a tint: the smallest complete material plugin.
 * Copy it, rename the file and the name in MURK_MATERIAL_PLUGIN (they must match), change the lobe.
 *
 * Parameters
 *   color     RGB in [0,1], default 0.8, texturable. The reflectance before the tint.
 *   tint      RGB in [0,1], default 1. Multiplies color (a plain constant: shows a non-texturable RGB).
 *
 * BSDF: f(wo, wi) = color * tint / pi for wo, wi both above the surface, 0 otherwise. sample() draws
 * wi cosine-weighted (pdf = cos(wi) / pi), so the path weight f cos / pdf is color * tint exactly.
 *
 * Contract (murk/material.h): directions are in the local shading frame (normal +z) and the host flips
 * the frame so that wo.z >= 0; eval() is f without the cosine; pdf() is the solid-angle density of
 * sample(); sample() fills s->f and s->pdf with what eval() and pdf() give for s->wi, or returns 0.
 * Every method may run on many threads at once: the instance is read-only after create(). */
#include "murk/material.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

enum { P_COLOR, P_TINT, P_COUNT };

/* name, type, flags, default, default string, choices, min, max, one-line doc */
static const murk_param params[P_COUNT] = {
    [P_COLOR] = {"color", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.8, 0.8, 0.8}, NULL, NULL, 0.0, 1.0,
                 "reflectance before the tint (Lambertian)"},
    [P_TINT] = {"tint", MURK_PARAM_RGB, 0, {1.0, 1.0, 1.0}, NULL, NULL, 0.0, 1.0, "multiplies color"},
};

typedef struct matte {
    const murk_host *host; /* keep it: textures are evaluated through it, memory is freed through it */
    murk_value color;      /* copied: the params array belongs to the host */
    murk_rgb tint;
} matte;

static int matte_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    matte *m = host->alloc(sizeof *m);
    if (!m) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    m->host = host;
    m->color = p[P_COLOR];
    m->tint = murk_rgb3((float)p[P_TINT].f[0], (float)p[P_TINT].f[1], (float)p[P_TINT].f[2]);
    *self = m;
    return 0;
}

static void matte_destroy(void *self)
{
    matte *m = self;
    if (m)
        m->host->free(m);
}

/* The reflectance at a hit: the texture if the scene gave one, else the constant. */
static murk_rgb reflectance(const matte *m, const murk_hit *hit)
{
    float c[3];
    murk_value_eval(m->host, &m->color, hit, c);
    return murk_rgb3(c[0] * m->tint.c[0], c[1] * m->tint.c[1], c[2] * m->tint.c[2]);
}

static murk_rgb matte_eval(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return murk_rgb1(0.0f);
    return murk_rgb_scale(reflectance(self, hit), MURK_INV_PI);
}

static float matte_pdf(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    (void)hit;
    return wo.z > 0.0f && wi.z > 0.0f ? wi.z * MURK_INV_PI : 0.0f;
}

static int matte_sample(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
    memset(s, 0, sizeof *s);
    if (wo.z <= 0.0f)
        return 0;
    /* Malley's method: a uniform point on the unit disk, lifted to the hemisphere. */
    float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1];
    float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(murk_maxf(0.0f, 1.0f - x * x - y * y));
    if (z <= 0.0f)
        return 0; /* never an infinite weight: no sample instead */
    s->wi = murk_v3(x, y, z);
    s->pdf = z * MURK_INV_PI;
    s->f = murk_rgb_scale(reflectance(self, hit), MURK_INV_PI);
    s->delta = 0;
    return 1;
}

/* Designated initialisers: methods a later ABI minor appends start NULL (murk/material.h's prepared
 * methods of ABI 1.7 are optional), and the vtable compiles without warnings against newer headers. */
static const murk_material_vt vt = {
    .size = sizeof(murk_material_vt),
    .kind = MURK_KIND_MATERIAL,
    .create = matte_create,
    .destroy = matte_destroy,
    .eval = matte_eval,
    .pdf = matte_pdf,
    .sample = matte_sample,
};

MURK_MATERIAL_PLUGIN("example_matte", "example: tinted Lambertian (copy me)", params, P_COUNT, &vt)
