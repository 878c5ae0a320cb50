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
 * the eta^2 out of the path weight); 1 (or 0: not given) for a reflected one.
 *
 * Prepared shading points (ABI 1.7). A material whose parameters are textures reads them once per
 * vertex, not once per call: prepare() evaluates what the material needs at a hit (texture lookups,
 * table rows) into a murk_shading, and eval_at()/pdf_at()/sample_at() take that instead of the hit
 * (pbrt-v4's Material::GetBSDF makes the same split). The integrator prepares once per surface vertex
 * and hands the same shading point to every call there; murk_material_prepare() and
 * murk_material_eval/pdf/sample() below do that and fall back to the hit-based methods for a material
 * built before 1.7 (or one that leaves the four new methods NULL). A material that has them still
 * fills in eval/pdf/sample for integrators built before 1.7: MURK_MATERIAL_HIT_METHODS writes them. The
 * prepared methods must return exactly what the hit-based ones return for that hit. */
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

/* ABI 1.7: what a material's prepare() evaluated at one hit — a small POD of the material's own layout
 * in `data` (the material checks at compile time that it fits: MURK_SHADING_BYTES), plus the hit it was
 * prepared for. Lives on the integrator's stack for one vertex; valid as long as that hit. */
#define MURK_SHADING_BYTES 128
typedef struct murk_shading {
    const murk_hit *hit; /* set by the caller (murk_material_prepare) before prepare() */
    union {
        max_align_t align_;
        unsigned char bytes[MURK_SHADING_BYTES];
    } data;
} murk_shading;

typedef struct murk_material_vt {
    uint32_t size; /* sizeof(murk_material_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_MATERIAL */
    murk_create_fn create;
    void (*destroy)(void *self);
    murk_rgb (*eval)(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi);
    float (*pdf)(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi);
    int (*sample)(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3], murk_bsdf_sample *s);
    /* ABI 1.7 (all four or none; call them through murk_material_prepare/eval/pdf/sample) */
    void (*prepare)(const void *self, const murk_hit *hit, murk_shading *sp);
    murk_rgb (*eval_at)(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi);
    float (*pdf_at)(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi);
    int (*sample_at)(const void *self, const murk_shading *sp, murk_vec3 wo, const float u[3], murk_bsdf_sample *s);
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

/* 1 if the material has the prepared methods of ABI 1.7. */
static inline int murk_material_has_prepare(const murk_material_vt *vt)
{
    return MURK_HAS(vt->size, murk_material_vt, sample_at) && vt->prepare && vt->eval_at && vt->pdf_at &&
           vt->sample_at;
}

/* Prepares m's shading point at hit (its texture lookups happen here, once); for a material without
 * prepare() it only records the hit. */
static inline void murk_material_prepare(const murk_material *m, const murk_hit *hit, murk_shading *sp)
{
    sp->hit = hit;
    if (murk_material_has_prepare(m->vt))
        m->vt->prepare(m->self, hit, sp);
}
static inline murk_rgb murk_material_eval(const murk_material *m, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    return murk_material_has_prepare(m->vt) ? m->vt->eval_at(m->self, sp, wo, wi)
                                            : m->vt->eval(m->self, sp->hit, wo, wi);
}
static inline float murk_material_pdf(const murk_material *m, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    return murk_material_has_prepare(m->vt) ? m->vt->pdf_at(m->self, sp, wo, wi)
                                            : m->vt->pdf(m->self, sp->hit, wo, wi);
}
static inline int murk_material_sample(const murk_material *m, const murk_shading *sp, murk_vec3 wo, const float u[3],
                                       murk_bsdf_sample *s)
{
    return murk_material_has_prepare(m->vt) ? m->vt->sample_at(m->self, sp, wo, u, s)
                                            : m->vt->sample(m->self, sp->hit, wo, u, s);
}

/* The hit-based methods PREFIX_eval, PREFIX_pdf, PREFIX_sample of a material that defines PREFIX_prepare,
 * PREFIX_eval_at, PREFIX_pdf_at and PREFIX_sample_at: each prepares a shading point on its stack and
 * calls the prepared method (for integrators built before ABI 1.7). */
#define MURK_MATERIAL_HIT_METHODS(PREFIX)                                                                  \
    static murk_rgb PREFIX##_eval(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)       \
    {                                                                                                      \
        murk_shading sp;                                                                                   \
        sp.hit = hit;                                                                                      \
        PREFIX##_prepare(self, hit, &sp);                                                                  \
        return PREFIX##_eval_at(self, &sp, wo, wi);                                                        \
    }                                                                                                      \
    static float PREFIX##_pdf(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)           \
    {                                                                                                      \
        murk_shading sp;                                                                                   \
        sp.hit = hit;                                                                                      \
        PREFIX##_prepare(self, hit, &sp);                                                                  \
        return PREFIX##_pdf_at(self, &sp, wo, wi);                                                         \
    }                                                                                                      \
    static int PREFIX##_sample(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3],      \
                               murk_bsdf_sample *s)                                                        \
    {                                                                                                      \
        murk_shading sp;                                                                                   \
        sp.hit = hit;                                                                                      \
        PREFIX##_prepare(self, hit, &sp);                                                                  \
        return PREFIX##_sample_at(self, &sp, wo, u, s);                                                    \
    }

#endif
