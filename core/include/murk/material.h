/* murk/material.h — the material (BSDF) plugin interface.
 *
 * Directions are in the local shading frame: the normal is +z. The integrator flips the frame to the
 * side wo lies on, so wo.z >= 0 on every call and two-sided materials need no special case; wi may lie
 * below (wi.z < 0) and a reflection-only material returns zero there. eval() returns the BSDF value f
 * without the cosine; pdf() is the solid-angle density that sample() draws wi from; sample() returns 0
 * (and pdf 0) when it produces no direction — never an infinite weight. The path weight of a sample is
 * always f * |wi.z| / pdf; a delta lobe sets f and pdf so that this ratio is its reflectance (e.g. pdf =
 * the lobe's selection probability, f = F / |wi.z|) and sets `delta` so the integrator skips MIS.
 * All three are called from every render thread at once (see murk/plugin.h); `hit` is valid for the
 * call only and carries the texture coordinates that murk_value_eval() reads. u[] are three uniforms
 * in [0, 1). Every returned number must be finite: murk names the material that returned NaN or
 * infinity.
 *
 * Transmission (ABI 1.3). The hit a material receives carries the side wo lies on: hit->ng is the
 * geometric normal as the shape defines it (sphere: outwards; +ng is the `exterior` side of a shape
 * bounding media) and hit->n is the shading normal flipped to wo's side, i.e. the local frame's +z in
 * world space. So dot(hit->n, hit->ng) < 0 means wo is inside (on the -ng side) — what a dielectric
 * needs to know which index of refraction lies on wo's side. A sample with wi.z < 0 is transmission
 * through the surface: the integrator then moves the path into the medium on the far side
 * (hit->interior / hit->exterior); reflection-only materials never return one (and return 0 from
 * eval()/pdf() for wi.z < 0, as always). The BSDF is the one for radiance (murk's integrators carry
 * radiance from the camera): a transmitted f includes the factor (eta_wo / eta_wi)^2 (Veach 1997,
 * 5.2), so eval(wo, wi) / eta_wo^2 = eval(wi, wo) / eta_wi^2 is the reciprocity that holds. sample()
 * sets `eta` = eta_wi / eta_wo for a transmitted sample (the integrator's Russian roulette divides
 * the eta^2 out of the path weight); 1 (or 0: not given) for a reflected one. */
#ifndef MURK_MATERIAL_H
#define MURK_MATERIAL_H

#include "murk/plugin.h"

typedef struct murk_bsdf_sample {
    murk_vec3 wi;   /* local frame, unit */
    murk_rgb f;     /* BSDF value for (wo, wi), without cosine */
    float pdf;      /* solid-angle pdf of wi (for a delta lobe: the discrete probability) */
    int delta;      /* 1 if wi came from a delta (perfectly specular) lobe: the integrator skips MIS */
    /* ABI 1.3 (the integrator sets it to 1 before calling sample(), so a plugin built before 1.3 leaves 1) */
    float eta;      /* transmitted sample: eta_wi / eta_wo (relative IOR across the surface); else 1 or 0 */
} murk_bsdf_sample;

typedef struct murk_material_vt {
    uint32_t size; /* sizeof(murk_material_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_MATERIAL */
    murk_create_fn create;
    void (*destroy)(void *self);
    murk_rgb (*eval)(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi);
    float (*pdf)(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi);
    int (*sample)(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3], murk_bsdf_sample *s);
} murk_material_vt;

#define MURK_MATERIAL_VT_SIZE_1_0 (offsetof(murk_material_vt, sample) + sizeof(void (*)(void)))
/* 1 if wo lies inside (on the -ng side of) the surface of the hit a material was given (ABI 1.3). */
static inline int murk_material_wo_inside(const murk_hit *hit) { return murk_dot(hit->n, hit->ng) < 0.0f; }
#define MURK_MATERIAL_PLUGIN(NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                               \
    MURK_DEFINE_PLUGIN_(MURK_KIND_MATERIAL, NAME, DESCRIPTION, PARAMS, NPARAMS,                    \
                        _Generic((VT), const murk_material_vt *: (VT), murk_material_vt *: (VT)))

/* A material as the scene holds it. */
struct murk_material {
    const murk_material_vt *vt;
    void *self;
    const char *name;
};

#endif
