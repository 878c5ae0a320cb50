/* diffuse — Lambertian reflection.
 *
 * Parameters
 *   albedo  RGB in [0,1], default 0.5, texturable. Fraction of light reflected; f = albedo / pi.
 *
 * Reflection only, on whichever side wo lies (the integrator flips the frame). Sampling is
 * cosine-weighted over the hemisphere, so f cos / pdf = albedo exactly. Emission is a property of the
 * shape (`emission:` in the scene), not of the material. */
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

static murk_rgb albedo_at(const diffuse *d, const murk_hit *hit)
{
    float a[3];
    murk_value_eval(d->host, &d->albedo, hit, a);
    return murk_rgb3(a[0], a[1], a[2]);
}

static murk_rgb diffuse_eval(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return murk_rgb1(0.0f);
    return murk_rgb_scale(albedo_at(self, hit), MURK_INV_PI);
}

static float diffuse_pdf(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    (void)hit;
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return 0.0f;
    return wi.z * MURK_INV_PI;
}

static int diffuse_sample(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
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
    s->f = murk_rgb_scale(albedo_at(self, hit), MURK_INV_PI);
    return 1;
}

static const murk_material_vt vt = {
    sizeof(murk_material_vt), MURK_KIND_MATERIAL, diffuse_create, diffuse_destroy, diffuse_eval, diffuse_pdf,
    diffuse_sample,
};

MURK_MATERIAL_PLUGIN("diffuse", "Lambertian diffuse reflection", params, P_COUNT, &vt)
