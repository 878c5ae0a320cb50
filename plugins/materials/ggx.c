/* ggx — a Lambertian base under a GGX microfacet specular coat (reflection only).
 *
 * Parameters
 *   albedo     RGB in [0,1], default 0.5, texturable. Reflectance of the diffuse base: with specular 0
 *              the material is exactly Lambertian with f = albedo / pi.
 *   specular   RGB in [0,1], default 0.04, texturable. F0, the normal-incidence reflectance of the coat
 *              in Schlick's Fresnel F(c) = F0 + (1 - F0)(1 - c)^5 (0.04 ~ plastics and glass, 1 = a
 *              perfect mirror coat: no light reaches the base).
 *   roughness  float in [0,1], default 0.5, texturable. Perceptual roughness; the GGX width is
 *              alpha = roughness^2.
 *   alpha      float in [0,1], optional, texturable. The GGX width itself; when the scene gives it, it
 *              overrides roughness (alpha = value, not squared). Giving both is allowed: alpha wins and
 *              create() logs a warning.
 *   The effective alpha is clamped to [0.001, 1]: roughness 0 (or alpha 0) is a very sharp but finite
 *   GGX lobe, never a delta lobe, so eval/pdf/sample stay one smooth, MIS-able distribution.
 *   multiscatter  bool, default true. Multiple-scattering compensation of the coat (below); false gives
 *              the single-scattering model exactly as before it existed (for A/B: it loses up to 69 % of
 *              the light at roughness 1).
 *
 * Model (local shading frame, n = +z, mu = cos theta):
 *   f = f_spec + f_diff
 *   f_spec(wo,wi) = F(wo.h) D(h) V(mu_o, mu_i),  h = normalize(wo + wi)
 *     D  GGX / Trowbridge-Reitz NDF (Walter et al. 2007): alpha^2 / (pi (alpha^2 h.z^2 + h.x^2 + h.y^2)^2)
 *     V  height-correlated Smith (Heitz 2014) G2 / (4 mu_o mu_i) = 0.5 / (mu_i R(mu_o) + mu_o R(mu_i)),
 *        R(mu) = sqrt(mu^2 (1 - alpha^2) + alpha^2)
 *   f_diff(wo,wi) = albedo (1 - F0) / pi * (1 - M(mu_o)) (1 - M(mu_i)) / (1 - Mavg)
 *
 * Energy conservation (the weighting of the diffuse lobe). Let
 *   E_F(wo) = integral over visible microfacet normals of F(wo.h) D_wo(h) dh = F0 + (1 - F0) M(mu_o),
 *   M(mu) = integral of (1 - wo.h)^5 D_wo(h) dh,   D_wo = G1(wo) max(0, wo.h) D(h) / mu_o (the VNDF),
 * the fraction of the light arriving from wo that the coat's microfacets reflect (Fresnel-weighted).
 * Because the height-correlated G2 <= G1(wo), the specular lobe's directional albedo
 * E_spec(wo) = integral of f_spec cos <= E_F(wo). The diffuse lobe above is a Kelemen & Szirmay-Kalos
 * (2001) style separable, symmetric (hence reciprocal) lobe whose normalisation
 * Mavg = integral of M(mu) 2 mu dmu makes its directional albedo exactly albedo (1 - E_F(wo)). So
 *   E(wo) = E_spec(wo) + albedo (1 - E_F(wo)) <= E_F(wo) + 1 - E_F(wo) = 1
 * for every albedo, specular and roughness; with albedo 1 the only loss is the coat's
 * single-scattering shortfall E_F - E_spec (no multiple-scattering compensation). f is symmetric in
 * (wo, wi) term by term, so reciprocal. M has no closed form: it is tabulated below over
 * (t = sqrt(mu), r = sqrt(alpha)) and read bilinearly; every table entry carries a local safety margin
 * so that the interpolated M is never below the true M (checked densely by the generator), which keeps
 * the bound E <= 1 rigorous. Mavg is integrated exactly from that same interpolant. The tables are
 * in ggx_tables.h, written by tools/ggx_tables.c (see there to regenerate them).
 *
 * Multiple-scattering compensation (multiscatter: true; Kulla & Conty 2017, chosen over Turquin 2019
 * because its extra lobe is symmetric in (wo, wi), so the BSDF stays reciprocal, and is sampled exactly by
 * the cosine lobe the base already uses; Turquin's 1 + F0 (1 - E(mu_o)) / E(mu_o) scale of f_spec is not
 * reciprocal). With E(mu) the coat's single-scattering albedo for F = 1 and Eavg its cosine average,
 *   f_ms(wo,wi) = Fms (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - Eavg)),
 *   Fms = Favg^2 Eavg / (1 - Favg (1 - Eavg)),  Favg = F0 + (1 - F0) / 21 (Schlick's average),
 * whose albedo is Fms (1 - E(mu_o)): with F0 = 1 the coat reflects E + 1 - E = 1 (the furnace). The base
 * then sits under the coat's energy bound X instead of E_F:
 *   X(mu) = F0 E(mu) + (1 - F0) M(mu) + Fms (1 - E(mu)),   f_diff = albedo (1 - X(mu_o)) (1 - X(mu_i)) / (pi (1 - Xavg)),
 * because the single-scattering albedo with Schlick's Fresnel is F0 E + (1 - F0) E5 (E5: F = (1 - c)^5)
 * and E5 <= M. So E(wo) <= X(wo) + albedo (1 - X(wo)) <= 1 again, and every term is symmetric. E is
 * tabulated (ggx_e, with safety margins so that the table is never below E: the bound stays rigorous,
 * and the compensated furnace is 1 minus at most that margin, 0.23 %) on the axis
 * w = mu (1 + alpha) / (mu + alpha), which resolves E's dip near mu ~ alpha at low alpha; Eavg
 * (ggx_eavg) is the exact average of that interpolant at 8 points per table row, interpolated between
 * (error 2.4e-6). P_spec weighs the coat's single scattering F0 E + (1 - F0) M against the compensation
 * lobe and the base together (both cosine-sampled).
 *
 * Sampling: with probability P_spec the coat (visible-normal sampling of GGX with the spherical-cap
 * method of Dupuy & Benyoub 2023, then mirror reflection), otherwise the base (cosine-weighted
 * hemisphere). P_spec = lum(E_F(wo)) / (lum(E_F(wo)) + lum(albedo (1 - E_F(wo)))), the lobes'
 * expected contributions, clamped to [0.05, 0.95] when both lobes are non-zero (exactly 1 when the base
 * is black, 0 when the coat is). pdf() is the exact mixture P_spec pdf_spec + (1 - P_spec) pdf_diff with
 * pdf_spec = D(h) G1(wo) / (4 mu_o); coat samples that reflect below the horizon are rejected (sample()
 * returns 0), so pdf() integrates to 1 minus that rejected mass.
 *
 * Robustness: wo.z or wi.z below 1e-9 (the horizon, below it, NaN) gives f = 0 and pdf = 0; sample()
 * returns 0 there and for rejected or zero-pdf samples. No formula divides by mu or tan theta alone, so
 * grazing directions (wo.z = 1e-7) stay finite, and with alpha >= 0.001 every output is bounded. */
#include "murk/material.h"
#include "murk/microfacet.h"

#include <string.h>

enum { P_ALBEDO, P_SPECULAR, P_ROUGHNESS, P_ALPHA, P_MULTISCATTER, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_ALBEDO] = {"albedo", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.5, 0.5, 0.5}, NULL, NULL, 0.0, 1.0,
                  "reflectance of the diffuse base (Lambertian under the coat)"},
    [P_SPECULAR] = {"specular", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.04, 0.04, 0.04}, NULL, NULL, 0.0, 1.0,
                    "normal-incidence reflectance F0 of the coat (Schlick Fresnel)"},
    [P_ROUGHNESS] = {"roughness", MURK_PARAM_FLOAT, MURK_PARAM_TEXTURABLE, {0.5, 0, 0}, NULL, NULL, 0.0, 1.0,
                     "perceptual roughness; GGX alpha = roughness^2 (clamped to >= 0.001)"},
    [P_ALPHA] = {"alpha", MURK_PARAM_FLOAT, MURK_PARAM_TEXTURABLE, {0.0, 0, 0}, NULL, NULL, 0.0, 1.0,
                 "GGX alpha directly; if given it overrides roughness (clamped to >= 0.001)"},
    [P_MULTISCATTER] = {"multiscatter", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                        "multiple-scattering compensation of the coat (Kulla & Conty 2017); false: single scattering"},
};

/* Cosines below this count as the horizon: it bounds f <= 0.5 D_max / (2 GGX_MU_MIN GGX_ALPHA_MIN) ~ 1e17
 * and pdf <= D_max / (2 GGX_ALPHA_MIN) ~ 2e8, so nothing overflows even for subnormal cosines. */
#define GGX_MU_MIN 1e-9f
#define GGX_PSPEC_MIN 0.05f
#define GGX_PSPEC_MAX 0.95f

/* ---- Tables: ggx_m (M(mu, alpha) with safety margins) and ggx_mavg, generated by
 * tools/ggx_tables.c (GGX_TAB_N, and GGX_ALPHA_MIN which the tables assume, come with them). */
#include "ggx_tables.h"

typedef struct ggx {
    const murk_host *host;
    murk_value p[P_COUNT];
    int use_alpha;
    int ms; /* multiple-scattering compensation */
} ggx;

/* Parameter values at one hit. */
typedef struct ggx_shade {
    murk_rgb albedo, f0;
    float alpha; /* clamped to [GGX_ALPHA_MIN, 1] */
    float r;     /* sqrt(alpha): the table's second axis */
    float mavg;  /* Mavg(alpha) */
    int ms;      /* compensated: the fields below are set */
    float eavg;  /* Eavg(alpha), average of the E table's interpolant */
    float fms[3];  /* Kulla-Conty's Fresnel factor of the compensation lobe, per channel */
    float xavg[3]; /* average of X (the coat's energy bound), per channel */
} ggx_shade;

static int above(float z) { return z >= GGX_MU_MIN; } /* NaN -> 0 */

static void ggx_shade_at(const ggx *g, const murk_hit *hit, ggx_shade *sh)
{
    float v[3];
    murk_value_eval(g->host, &g->p[P_ALBEDO], hit, v);
    sh->albedo = murk_rgb3(murk_clamp01(v[0]), murk_clamp01(v[1]), murk_clamp01(v[2]));
    murk_value_eval(g->host, &g->p[P_SPECULAR], hit, v);
    sh->f0 = murk_rgb3(murk_clamp01(v[0]), murk_clamp01(v[1]), murk_clamp01(v[2]));
    float a;
    if (g->use_alpha) {
        murk_value_eval(g->host, &g->p[P_ALPHA], hit, v);
        a = murk_clamp01(v[0]);
    } else {
        murk_value_eval(g->host, &g->p[P_ROUGHNESS], hit, v);
        float rough = murk_clamp01(v[0]);
        a = rough * rough;
    }
    sh->alpha = a > GGX_ALPHA_MIN ? a : GGX_ALPHA_MIN;
    sh->r = sqrtf(sh->alpha);
    float x = sh->r * (float)(GGX_TAB_N - 1);
    int j = (int)x;
    if (j > GGX_TAB_N - 2)
        j = GGX_TAB_N - 2;
    float fr = x - (float)j;
    sh->mavg = ggx_mavg[j] + (ggx_mavg[j + 1] - ggx_mavg[j]) * fr;
    sh->ms = g->ms;
    if (sh->ms) {
        enum { NA = (GGX_TAB_N - 1) * GGX_EAVG_SUB + 1 };
        float y = sh->r * (float)(NA - 1);
        int k = (int)y;
        if (k > NA - 2)
            k = NA - 2;
        sh->eavg = ggx_eavg[k] + (ggx_eavg[k + 1] - ggx_eavg[k]) * (y - (float)k);
        for (int c = 0; c < 3; c++) {
            float f0 = sh->f0.c[c], favg = f0 + (1.0f - f0) * (1.0f / 21.0f); /* Schlick's hemispherical average */
            sh->fms[c] = favg * favg * sh->eavg / fmaxf(1.0f - favg * (1.0f - sh->eavg), 1e-6f);
            sh->xavg[c] = f0 * sh->eavg + (1.0f - f0) * sh->mavg + sh->fms[c] * (1.0f - sh->eavg);
        }
    }
}

/* Bilinear lookup in a GGX_TAB_N x GGX_TAB_N table at column coordinate t in [0, 1] and row r (the
 * shading's sqrt(alpha)). */
static float tab_lookup(const float tab[GGX_TAB_N][GGX_TAB_N], float t01, float r)
{
    float t = t01 * (float)(GGX_TAB_N - 1);
    int i = (int)t;
    if (i > GGX_TAB_N - 2)
        i = GGX_TAB_N - 2;
    float ft = t - (float)i;
    float x = r * (float)(GGX_TAB_N - 1);
    int j = (int)x;
    if (j > GGX_TAB_N - 2)
        j = GGX_TAB_N - 2;
    float fr = x - (float)j;
    float v0 = tab[j][i] + (tab[j][i + 1] - tab[j][i]) * ft;
    float v1 = tab[j + 1][i] + (tab[j + 1][i + 1] - tab[j + 1][i]) * ft;
    return v0 + (v1 - v0) * fr;
}

/* M(mu, alpha), mu in [0, 1], on the table's axis t = sqrt(mu). */
static float ggx_m_lookup(const ggx_shade *sh, float mu) { return tab_lookup(ggx_m, sqrtf(murk_clamp01(mu)), sh->r); }

/* E(mu, alpha), mu in [0, 1], on the table's axis w = mu (1 + alpha) / (mu + alpha). */
static float ggx_e_lookup(const ggx_shade *sh, float mu)
{
    mu = murk_clamp01(mu);
    return tab_lookup(ggx_e, murk_clamp01(mu * (1.0f + sh->alpha) / (mu + sh->alpha)), sh->r);
}

/* Compensated model at one cosine: e = E(mu), and per channel the coat's energy bound
 * X = F0 E + (1 - F0) M + Fms (1 - E) (single scattering <= F0 E + (1 - F0) M, because E5 <= M) and
 * 1 - X clamped to >= 0 (it is >= 0 up to rounding: 1 - X is concave in F0 and >= 0 at F0 = 0 and 1). */
typedef struct ggx_msat { float e, m, ss[3], one_x[3]; } ggx_msat;
static void ggx_ms_at(const ggx_shade *sh, float mu, ggx_msat *a)
{
    a->e = ggx_e_lookup(sh, mu);
    a->m = ggx_m_lookup(sh, mu);
    for (int c = 0; c < 3; c++) {
        float f0 = sh->f0.c[c];
        a->ss[c] = f0 * a->e + (1.0f - f0) * a->m;
        a->one_x[c] = fmaxf(0.0f, 1.0f - a->ss[c] - sh->fms[c] * (1.0f - a->e));
    }
}

/* Probability of sampling the coat from the expected contributions of what it samples (es) and of what
 * the cosine lobe samples (ed): their luminance ratio, clamped to [GGX_PSPEC_MIN, GGX_PSPEC_MAX] when
 * both are non-zero, exactly 1 or 0 when one is. */
static float pspec_from(murk_rgb es, murk_rgb ed)
{
    float ws = murk_luminance(es), wd = murk_luminance(ed);
    if (!(wd > 0.0f))
        return 1.0f;
    if (!(ws > 0.0f))
        return 0.0f;
    float p = ws / (ws + wd);
    return p < GGX_PSPEC_MIN ? GGX_PSPEC_MIN : (p > GGX_PSPEC_MAX ? GGX_PSPEC_MAX : p);
}

/* Probability of sampling the coat, from the lobes' expected contributions at wo. mo = M(mu_o). */
static float ggx_pspec(const ggx_shade *sh, float mo)
{
    murk_rgb ef, ed;
    for (int c = 0; c < 3; c++) {
        float f0 = sh->f0.c[c];
        ef.c[c] = f0 + (1.0f - f0) * mo;
        ed.c[c] = sh->albedo.c[c] * (1.0f - f0) * (1.0f - mo);
    }
    return pspec_from(ef, ed);
}

/* The same for the compensated model: the coat's single scattering against everything sampled from the
 * cosine (compensation lobe and base). */
static float ggx_pspec_ms(const ggx_shade *sh, float mu_o)
{
    ggx_msat a;
    ggx_ms_at(sh, mu_o, &a);
    murk_rgb es, ed;
    for (int c = 0; c < 3; c++) {
        es.c[c] = a.ss[c];
        ed.c[c] = sh->fms[c] * (1.0f - a.e) + sh->albedo.c[c] * a.one_x[c];
    }
    return pspec_from(es, ed);
}

static float ggx_pspec_at(const ggx_shade *sh, float mu_o)
{
    return sh->ms ? ggx_pspec_ms(sh, mu_o) : ggx_pspec(sh, ggx_m_lookup(sh, mu_o));
}

/* Unit half vector of wo and wi (both above the horizon); 0 if they are (nearly) opposite. */
static int ggx_half(murk_vec3 wo, murk_vec3 wi, murk_vec3 *h)
{
    murk_vec3 s = murk_add(wo, wi);
    float l2 = murk_dot(s, s);
    if (!(l2 > 1e-12f))
        return 0;
    *h = murk_mul(s, 1.0f / sqrtf(l2));
    return 1;
}

static murk_rgb ggx_eval_sh(const ggx_shade *sh, murk_vec3 wo, murk_vec3 wi)
{
    murk_rgb f = murk_rgb1(0.0f);
    if (!above(wo.z) || !above(wi.z))
        return f;
    float mu_o = fminf(wo.z, 1.0f), mu_i = fminf(wi.z, 1.0f);
    if (sh->ms) { /* compensation lobe (Kulla & Conty 2017) and the base under the coat's bound X */
        ggx_msat ao, ai;
        ggx_ms_at(sh, mu_o, &ao);
        ggx_ms_at(sh, mu_i, &ai);
        float de = 1.0f - sh->eavg;
        float kms = de > 1e-6f ? (1.0f - ao.e) * (1.0f - ai.e) / de * MURK_INV_PI : 0.0f;
        for (int c = 0; c < 3; c++) {
            float dx = 1.0f - sh->xavg[c];
            f.c[c] = sh->fms[c] * kms;
            if (dx > 1e-6f)
                f.c[c] += sh->albedo.c[c] * ao.one_x[c] * ai.one_x[c] / dx * MURK_INV_PI;
        }
    } else { /* diffuse base */
        float kd = (1.0f - ggx_m_lookup(sh, mu_o)) * (1.0f - ggx_m_lookup(sh, mu_i)) /
                   fmaxf(1.0f - sh->mavg, 1e-6f) * MURK_INV_PI;
        for (int c = 0; c < 3; c++)
            f.c[c] = sh->albedo.c[c] * (1.0f - sh->f0.c[c]) * kd;
    }
    /* specular coat */
    murk_vec3 h;
    if (ggx_half(wo, wi, &h)) {
        float a2 = sh->alpha * sh->alpha;
        /* F D V, V = G2 / (4 mu_o mu_i) */
        float dv = murk_ggx_d(h, a2) * 0.5f / murk_ggx_g2_den(mu_o, mu_i, a2);
        float c = murk_clamp01(murk_dot(wo, h));
        for (int k = 0; k < 3; k++)
            f.c[k] += murk_fresnel_schlick(sh->f0.c[k], c) * dv;
    }
    return f;
}

static float ggx_pdf_sh(const ggx_shade *sh, murk_vec3 wo, murk_vec3 wi)
{
    if (!above(wo.z) || !above(wi.z))
        return 0.0f;
    float mu_o = fminf(wo.z, 1.0f), mu_i = fminf(wi.z, 1.0f);
    float ps = ggx_pspec_at(sh, mu_o);
    float pdf = (1.0f - ps) * mu_i * MURK_INV_PI;
    murk_vec3 h;
    if (ps > 0.0f && ggx_half(wo, wi, &h)) {
        float a2 = sh->alpha * sh->alpha;
        /* D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 mu_o), G1 = 2 mu_o / (mu_o + R(mu_o)) */
        pdf += ps * murk_ggx_d(h, a2) * 0.5f / (mu_o + murk_ggx_smith_r(mu_o, a2));
    }
    return pdf;
}

/* ---- Plugin interface ---------------------------------------------------------------------- */
static int ggx_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    ggx *g = host->alloc(sizeof *g);
    if (!g)
        return -1;
    g->host = host;
    memcpy(g->p, p, sizeof g->p);
    g->use_alpha = p[P_ALPHA].set != 0;
    g->ms = p[P_MULTISCATTER].f[0] != 0.0;
    if (g->use_alpha && p[P_ROUGHNESS].set && host->log)
        host->log(MURK_LOG_WARN, "ggx: both 'roughness' and 'alpha' given; 'alpha' overrides 'roughness'");
    *self = g;
    return 0;
}

static void ggx_destroy(void *self)
{
    ggx *g = self;
    if (g)
        g->host->free(g);
}

static void ggx_prepare(const void *self, const murk_hit *hit, murk_shading *sp)
{
    _Static_assert(sizeof(ggx_shade) <= MURK_SHADING_BYTES, "ggx_shade fits a murk_shading");
    ggx_shade_at(self, hit, (ggx_shade *)sp->data.bytes);
}

static murk_rgb ggx_eval_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    return ggx_eval_sh((const ggx_shade *)sp->data.bytes, wo, wi);
}

static float ggx_pdf_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    return ggx_pdf_sh((const ggx_shade *)sp->data.bytes, wo, wi);
}

static int ggx_sample_at(const void *self, const murk_shading *sp, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
    (void)self;
    const ggx_shade *sh = (const ggx_shade *)sp->data.bytes;
    memset(s, 0, sizeof *s);
    if (!above(wo.z))
        return 0;
    float ps = ggx_pspec_at(sh, fminf(wo.z, 1.0f));
    murk_vec3 wi;
    if (u[2] < ps) {
        murk_vec3 h = murk_ggx_sample_vndf(wo, sh->alpha, u[0], u[1]);
        if (!(murk_dot(wo, h) > 0.0f))
            return 0;
        wi = murk_reflect(wo, h);
    } else {
        float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1];
        wi = murk_v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[0])));
    }
    if (!above(wi.z))
        return 0;
    float pdf = ggx_pdf_sh(sh, wo, wi);
    murk_rgb f = ggx_eval_sh(sh, wo, wi);
    if (!(pdf > 0.0f) || !isfinite(pdf) || !murk_rgb_finite(f))
        return 0;
    s->wi = wi;
    s->f = f;
    s->pdf = pdf;
    s->delta = 0;
    return 1;
}

MURK_MATERIAL_HIT_METHODS(ggx)

static const murk_material_vt vt = {
    sizeof(murk_material_vt), MURK_KIND_MATERIAL, ggx_create, ggx_destroy, ggx_eval, ggx_pdf, ggx_sample,
    ggx_prepare, ggx_eval_at, ggx_pdf_at, ggx_sample_at,
};

MURK_MATERIAL_PLUGIN("ggx", "Lambertian base under a GGX specular coat (energy-conserving, reciprocal)", params,
                     P_COUNT, &vt)
