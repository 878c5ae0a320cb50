/* murk/phase.h — the phase-function plugin interface (ABI 1.9).
 *
 * A medium scatters light with a phase function p(wo, wi): the probability density (per steradian) that
 * light arriving at a scattering point and leaving it towards wo came from direction wi. Both point away
 * from the scattering point (murk's convention for BSDFs too): forward scattering, the light going on
 * straight, is wi = -wo, and the scattering angle theta is the angle between -wo and wi, so
 * cos(theta) = -dot(wo, wi). A phase function integrates to 1 over wi and is reciprocal,
 * p(wo, wi) = p(wi, wo) (every phase function of a rotation-invariant medium depends on cos(theta) only).
 *
 * A medium names one in the scene:
 *     media: { cloud: { type: delta, phase: { type: hg_draine, diameter: 20 }, ... } }
 *     media: { fog: { type: delta, phase: isotropic, ... } }
 * Without `phase:` a medium scatters with Henyey-Greenstein of its `g` key (the built-in default, the same
 * function as the `hg` plugin); `g` beside a `phase:` block is an error. Trackers never see the phase
 * function (they only sample distances); integrators reach it through the host: murk_host's
 * medium_phase_eval / medium_phase_sample take the medium (murk/plugin.h), and the older phase_eval /
 * phase_sample (g, ...) remain Henyey-Greenstein for plugins built before 1.9.
 *
 * Contracts (besides those of murk/plugin.h):
 *   create()  gets the phase function's own parameters (schema-checked, with located errors).
 *   eval()    p(wo, wi) >= 0, finite; wo, wi unit. Also the pdf of sample(): murk's integrators use it as
 *             such in multiple importance sampling, so sample() must draw from exactly this density.
 *   sample()  draws wi from p(wo, .) with the two uniforms u (the integrator's sampler slot), writes
 *             wi (unit) and *pdf = p(wo, wi), and returns p(wo, wi) (the value: a sampler that is exact
 *             returns *pdf itself, so the path weight p / pdf is 1). Returns 0 (and *pdf = 0) when it
 *             cannot sample.
 *   mean_cosine()  the closed form of the mean cosine of the scattering angle, <cos theta> (HG: g), or
 *             NULL if there is none: `murk check` compares it with quadrature and with sampled
 *             directions.
 * eval() and sample() are called from every render thread at once: they must not modify self. */
#ifndef MURK_PHASE_H
#define MURK_PHASE_H

#include <math.h>

#include "murk/plugin.h"

typedef struct murk_phase_vt {
    uint32_t size; /* sizeof(murk_phase_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_PHASE */
    int (*create)(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen);
    void (*destroy)(void *self);
    float (*eval)(const void *self, murk_vec3 wo, murk_vec3 wi);
    float (*sample)(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf);
    double (*mean_cosine)(const void *self); /* may be NULL */
} murk_phase_vt;

#define MURK_PHASE_VT_SIZE_1_9 (offsetof(murk_phase_vt, mean_cosine) + sizeof(void (*)(void)))
#define MURK_PHASE_PLUGIN(NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                                  \
    MURK_DEFINE_PLUGIN_(MURK_KIND_PHASE, NAME, DESCRIPTION, PARAMS, NPARAMS,                       \
                        _Generic((VT), const murk_phase_vt *: (VT), murk_phase_vt *: (VT)))

/* A phase function as a medium holds it. */
typedef struct murk_phase {
    const murk_phase_vt *vt;
    void *self;
} murk_phase;

/* ---- Henyey-Greenstein (1941), shared by the host's built-in default and the `hg` plugin, so that both
 * give the same bits. p = (1 - g^2) / (4 pi (1 + g^2 + 2 g dot(wo, wi))^(3/2)); sampled by inverting its
 * CDF in cos(theta) (|g| < 1e-3: uniformly, as isotropic). */
static inline float murk_hg_eval(float g, murk_vec3 wo, murk_vec3 wi)
{
    float cost = murk_dot(wo, wi);
    float denom = 1.0f + g * g + 2.0f * g * cost;
    return (1.0f / (4.0f * MURK_PI)) * (1.0f - g * g) / (denom * sqrtf(murk_fmaxf(denom, 1e-12f)));
}

/* The direction with cos(angle to axis) = cost and azimuth 2 pi u1 about the unit axis. */
static inline murk_vec3 murk_phase_dir(murk_vec3 axis, float cost, float u1)
{
    cost = murk_fminf(1.0f, murk_fmaxf(-1.0f, cost));
    float sint = sqrtf(murk_fmaxf(0.0f, 1.0f - cost * cost)), phi = 2.0f * MURK_PI * u1;
    murk_vec3 t, b;
    murk_basis(axis, &t, &b);
    return murk_normalize(murk_from_local(murk_v3(sint * cosf(phi), sint * sinf(phi), cost), t, b, axis));
}

/* The direction at angle theta from the unit axis with 1 - cos(theta) = om (in [0, 2]), azimuth 2 pi u1:
 * om rather than cos(theta), so that directions within 1e-3 radians of the axis keep their precision. */
static inline murk_vec3 murk_phase_dir_om(murk_vec3 axis, float om, float u1)
{
    om = murk_fminf(2.0f, murk_fmaxf(0.0f, om));
    float sint = sqrtf(om * (2.0f - om)), phi = 2.0f * MURK_PI * u1;
    murk_vec3 t, b;
    murk_basis(axis, &t, &b);
    return murk_normalize(murk_from_local(murk_v3(sint * cosf(phi), sint * sinf(phi), 1.0f - om), t, b, axis));
}

static inline murk_vec3 murk_hg_sample(float g, murk_vec3 wo, const float u[2], float *pdf)
{
    float cost;
    if (fabsf(g) < 1e-3f) {
        cost = 1.0f - 2.0f * u[0];
    } else {
        float sq = (1.0f - g * g) / (1.0f + g - 2.0f * g * u[0]);
        cost = -(1.0f + g * g - sq * sq) / (2.0f * g);
    }
    murk_vec3 wi = murk_phase_dir(wo, cost, u[1]);
    *pdf = murk_hg_eval(g, wo, wi);
    return wi;
}

#endif
