/* murk/microfacet.h — GGX microfacet and Fresnel building blocks for material plugins.
 *
 * GGX (Trowbridge-Reitz) normal distribution (Walter et al. 2007, "Microfacet Models for Refraction
 * through Rough Surfaces"), Smith's Lambda and masking-shadowing, separable G1 and height-correlated G2
 * (Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs"), sampling of
 * the visible normals and its density (Heitz 2018, "Sampling the GGX Distribution of Visible Normals";
 * the spherical-cap method of Dupuy & Benyoub 2023), Schlick's Fresnel (Schlick 1994) and the exact
 * unpolarised Fresnel reflectance of a dielectric interface (Walter et al. 2007, eq. 22).
 *
 * Conventions: the local shading frame, normal +z; mu = cos theta = w.z; m a unit microfacet normal
 * with m.z > 0; a2 = alpha^2, alpha the GGX width. Each function is the exact formula the plugins
 * evaluate (operation for operation: the images are reproducible bit for bit). The table generator
 * tools/ggx_tables.c integrates in double, so what it shares is written once for both precisions
 * (the _d functions). Header-only (static inline), like murk/math.h. */
#ifndef MURK_MICROFACET_H
#define MURK_MICROFACET_H

#include "murk/math.h"

/* x clamped to [0, 1]; NaN -> 0. */
static inline float murk_clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

/* GGX D(m) = a2 / (pi (a2 m.z^2 + m.x^2 + m.y^2)^2) for a unit m: the denominator written without
 * tan theta, so it stays finite at m.z = 0. Bounded by 1 / (pi a2). */
static inline float murk_ggx_d(murk_vec3 m, float a2)
{
    float d = a2 * m.z * m.z + (m.x * m.x + m.y * m.y);
    return a2 / (MURK_PI * d * d);
}

/* Precision-generic definitions (float, and double with the suffix _d):
 *   R(mu) = sqrt(mu^2 (1 - a2) + a2) = mu sqrt(1 + a2 tan^2 theta) = mu (1 + 2 Lambda(mu)) for mu >= 0,
 *     Smith's Lambda for GGX (Heitz 2014, eq. 86) without a division by mu;
 *   F(ci, eta) the unpolarised Fresnel reflectance for the cosine ci in [0, 1] of the incident direction
 *     and eta = (index beyond the interface) / (index on the incident side); 1 under total internal
 *     reflection. */
#define MURK_MICROFACET_DEFINE_(T, SFX, SQRT)                                          \
    static inline T murk_ggx_smith_r##SFX(T mu, T a2) { return SQRT(mu * mu * (1 - a2) + a2); } \
    static inline T murk_fresnel_dielectric_cos##SFX(T ci, T eta)                      \
    {                                                                                  \
        T s2t = (1 - ci * ci) / (eta * eta);                                           \
        if (s2t >= 1)                                                                  \
            return 1;                                                                  \
        T ct = SQRT(1 - s2t);                                                          \
        T rpa = (eta * ci - ct) / (eta * ci + ct), rpe = (ci - eta * ct) / (ci + eta * ct); \
        return (T)0.5 * (rpa * rpa + rpe * rpe);                                       \
    }
MURK_MICROFACET_DEFINE_(float, , sqrtf)
MURK_MICROFACET_DEFINE_(double, _d, sqrt)
#undef MURK_MICROFACET_DEFINE_

/* Smith's Lambda(mu) = (sqrt(1 + a2 tan^2 theta) - 1) / 2 for mu > 0 (Heitz 2014, eq. 86). */
static inline float murk_ggx_lambda(float mu, float a2) { return 0.5f * (murk_ggx_smith_r(mu, a2) / mu - 1.0f); }

/* G1(mu) / |mu| = 2 / (|mu| + R(|mu|)), G1 = 1 / (1 + Lambda): finite at grazing mu. */
static inline float murk_ggx_g1_over_mu(float mu, float a2)
{
    mu = fabsf(mu);
    return 2.0f / (mu + murk_ggx_smith_r(mu, a2));
}

/* The height-correlated G2 = 1 / (1 + Lambda(mu_o) + Lambda(mu_i)) (Heitz 2014, eq. 99) is
 * 2 |mu_o mu_i| / murk_ggx_g2_den(mu_o, mu_i); murk_ggx_g2_over_mu2 is G2 / |mu_o mu_i|. */
static inline float murk_ggx_g2_den(float mu_o, float mu_i, float a2)
{
    mu_o = fabsf(mu_o);
    mu_i = fabsf(mu_i);
    return mu_i * murk_ggx_smith_r(mu_o, a2) + mu_o * murk_ggx_smith_r(mu_i, a2);
}
static inline float murk_ggx_g2_over_mu2(float mu_o, float mu_i, float a2)
{
    return 2.0f / murk_ggx_g2_den(mu_o, mu_i, a2);
}

/* A visible GGX normal of wo (wo.z > 0), alpha the width (not squared), u0, u1 in [0, 1): wo stretched
 * to the hemisphere configuration (alpha = 1), a uniform point on the unit sphere's cap z > -ws.z
 * whose half vector with ws is a visible normal there (Dupuy & Benyoub 2023), stretched back. Its
 * density is murk_ggx_vndf_pdf. */
static inline murk_vec3 murk_ggx_sample_vndf(murk_vec3 wo, float alpha, float u0, float u1)
{
    murk_vec3 ws = murk_normalize(murk_v3(alpha * wo.x, alpha * wo.y, wo.z));
    float phi = 2.0f * MURK_PI * u0;
    float z = (1.0f - u1) * (1.0f + ws.z) - ws.z;
    float st = sqrtf(murk_clamp01(1.0f - z * z));
    murk_vec3 hs = murk_v3(st * cosf(phi) + ws.x, st * sinf(phi) + ws.y, z + ws.z);
    return murk_normalize(murk_v3(alpha * hs.x, alpha * hs.y, murk_maxf(hs.z, 0.0f)));
}

/* The visible normal density D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z (Heitz 2018, eq. 3) of
 * murk_ggx_sample_vndf, per solid angle of m; for wo.z < 0 that of -wo (|wo.m|, |wo.z|). */
static inline float murk_ggx_vndf_pdf(murk_vec3 wo, murk_vec3 m, float a2)
{
    return murk_ggx_g1_over_mu(wo.z, a2) * murk_ggx_d(m, a2) * fabsf(murk_dot(wo, m));
}

/* w mirrored about the unit normal m: 2 (w.m) m - w, renormalised. */
static inline murk_vec3 murk_reflect(murk_vec3 w, murk_vec3 m)
{
    return murk_normalize(murk_sub(murk_mul(m, 2.0f * murk_dot(w, m)), w));
}

/* Schlick's approximation (Schlick 1994): F = F0 + (1 - F0) (1 - c)^5, c = cos of the incident
 * direction with the microfacet normal, in [0, 1]. */
static inline float murk_schlick_weight(float c)
{
    float x = 1.0f - c, x2 = x * x;
    return x2 * x2 * x;
}
static inline float murk_fresnel_schlick(float f0, float c) { return f0 + (1.0f - f0) * murk_schlick_weight(c); }

/* Exact unpolarised dielectric Fresnel for a signed cosine ci (negative: incident from inside) and eta
 * = index inside / index outside; 1 under total internal reflection. */
static inline float murk_fresnel_dielectric(float ci, float eta)
{
    ci = ci > 1.0f ? 1.0f : (ci < -1.0f ? -1.0f : ci);
    if (ci < 0.0f) {
        eta = 1.0f / eta;
        ci = -ci;
    }
    return murk_fresnel_dielectric_cos(ci, eta);
}

#endif
