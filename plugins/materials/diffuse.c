/* diffuse — Lambertian reflection, f = albedo / pi, on whichever side wo lies (the integrator flips the
 * frame), sampled cosine-weighted (Malley's method), so f cos / pdf = albedo exactly. Emission is a
 * property of the shape (`emission:` in the scene), not of the material. */
#include "murk/material.h"

#include <string.h>

enum { P_ALBEDO, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_ALBEDO] = {"albedo", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.5, 0.5, 0.5}, NULL, NULL, 0.0, 1.0,
                  "fraction of light reflected (Lambertian)"},
};

typedef struct diffuse {
    const murk_host *host;
    murk_value albedo;
} diffuse;

static int diffuse_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    diffuse *d = host->alloc(sizeof *d);
    if (!d)
        return -1;
    d->host = host;
    d->albedo = p[P_ALBEDO];
    *self = d;
    return 0;
}

static void diffuse_destroy(void *self)
{
    diffuse *d = self;
    if (d)
        d->host->free(d);
}

/* The albedo at one hit. */
static void diffuse_prepare(const void *self, const murk_hit *hit, murk_shading *sp)
{
    const diffuse *d = self;
    float a[3];
    murk_value_eval(d->host, &d->albedo, hit, a);
    *(murk_rgb *)sp->data.bytes = murk_rgb3(a[0], a[1], a[2]);
}

static murk_rgb albedo_of(const murk_shading *sp) { return *(const murk_rgb *)sp->data.bytes; }

static murk_rgb diffuse_eval_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return murk_rgb1(0.0f);
    return murk_rgb_scale(albedo_of(sp), MURK_INV_PI);
}

static float diffuse_pdf_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    (void)sp;
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return 0.0f;
    return wi.z * MURK_INV_PI;
}

static int diffuse_sample_at(const void *self, const murk_shading *sp, murk_vec3 wo, const float u[3],
                             murk_bsdf_sample *s)
{
    (void)self;
    memset(s, 0, sizeof *s);
    if (wo.z <= 0.0f)
        return 0;
    /* Malley's method: uniform disk, lifted. */
    float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1];
    float x = r * cosf(phi), y = r * sinf(phi);
    float z = sqrtf(murk_maxf(0.0f, 1.0f - x * x - y * y));
    if (z <= 0.0f)
        return 0;
    s->wi = murk_v3(x, y, z);
    s->pdf = z * MURK_INV_PI;
    s->f = murk_rgb_scale(albedo_of(sp), MURK_INV_PI);
    return 1;
}

MURK_MATERIAL_HIT_METHODS(diffuse)

static const murk_material_vt vt = {
    sizeof(murk_material_vt), MURK_KIND_MATERIAL, diffuse_create, diffuse_destroy, diffuse_eval, diffuse_pdf,
    diffuse_sample, diffuse_prepare, diffuse_eval_at, diffuse_pdf_at, diffuse_sample_at,
};

MURK_MATERIAL_PLUGIN("diffuse", "Lambertian diffuse reflection", params, P_COUNT, &vt)
