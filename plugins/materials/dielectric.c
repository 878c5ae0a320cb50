/* dielectric — a smooth or rough dielectric interface (glass, water, a liquid's surface) that reflects
 * and transmits (murk/material.h, "Transmission"): exact Fresnel, smooth delta lobes or GGX microfacet
 * reflection and transmission (Walter et al. 2007; pbrt-v4's DielectricBxDF) with height-correlated
 * Smith masking-shadowing (Heitz 2014) and visible-normal sampling (Heitz 2018; Dupuy & Benyoub 2023),
 * multiple-scattering compensation (Kulla & Conty 2017) and RGB dispersion. It works in its own
 * oriented frame, +z = outside, where wo.z < 0 means wo inside. The model is derived in
 * docs/materials.md; the tables come from tools/ggx_tables.c. */
#include "murk/material.h"
#include "murk/microfacet.h"

#include <string.h>

enum { P_IOR, P_ROUGHNESS, P_TINT, P_MULTISCATTER, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_IOR] = {"ior", MURK_PARAM_RGB, 0, {1.5, 1.5, 1.5}, NULL, NULL, 1.0, 4.0,
               "index of refraction inside relative to outside; three values: RGB dispersion"},
    [P_ROUGHNESS] = {"roughness", MURK_PARAM_FLOAT, MURK_PARAM_TEXTURABLE, {0.0, 0, 0}, NULL, NULL, 0.0, 1.0,
                     "0: smooth (delta lobes); > 0: GGX with alpha = roughness^2 (>= 0.001)"},
    [P_TINT] = {"tint", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {1.0, 1.0, 1.0}, NULL, NULL, 0.0, 1.0,
                "multiplies transmitted light at each crossing"},
    [P_MULTISCATTER] = {"multiscatter", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                        "rough: multiple-scattering compensation (Kulla & Conty 2017); false: single scattering"},
};

#define DI_MU_MIN 1e-9f

/* di_e: E(mu, alpha, eta) of the single-scattering model, outside and inside, with DI_TAB_NMU, DI_TAB_NR,
 * DI_TAB_NETA and DI_ALPHA_MIN (the alpha clamp the tables assume); tools/ggx_tables.c writes it. */
#include "dielectric_tables.h"

/* The compensation's tables for one index eta, built at create(): E per side (0: wo outside, 1: inside)
 * and roughness row on the row's own mu axis (tools/ggx_tables.c, di_u_of_mu), the rows of the two
 * nearest eta nodes blended; each row's exact average; Favg, the outside's hemispherical Fresnel average. */
typedef struct di_ms {
    float e[2][DI_TAB_NR][DI_TAB_NMU];
    float avg[2][DI_TAB_NR];
    float mc;   /* cosine of the critical angle inside */
    float favg; /* integral of F(mu, eta) 2 mu dmu from outside */
} di_ms;

typedef struct dielectric {
    const murk_host *host;
    murk_value p[P_COUNT];
    float eta[3];
    int dispersive; /* the channels' indices differ */
    int ms;         /* multiple-scattering compensation */
    di_ms tab[3];   /* per channel (only [0] when not dispersive) */
} dielectric;

/* Parameter values at one hit. */
typedef struct di_shade {
    float alpha; /* 0: smooth */
    murk_rgb tint;
    int inside;  /* wo is inside (murk_material_wo_inside): the oriented frame flips z */
} di_shade;

static void shade_at(const dielectric *d, const murk_hit *hit, di_shade *sh)
{
    float v[3];
    sh->inside = murk_material_wo_inside(hit);
    murk_value_eval(d->host, &d->p[P_ROUGHNESS], hit, v);
    float r = murk_clamp01(v[0]);
    sh->alpha = r > 0.0f ? murk_maxf(r * r, DI_ALPHA_MIN) : 0.0f;
    murk_value_eval(d->host, &d->p[P_TINT], hit, v);
    sh->tint = murk_rgb3(murk_clamp01(v[0]), murk_clamp01(v[1]), murk_clamp01(v[2]));
}

/* Refraction of w (pointing away from the surface) through normal n with relative index eta (the side
 * n points to is outside). Returns 0 under total internal reflection; *etap = eta_wt / eta_w. */
static int refract(murk_vec3 w, murk_vec3 n, float eta, float *etap, murk_vec3 *wt)
{
    float ci = murk_dot(n, w);
    if (ci < 0.0f) {
        eta = 1.0f / eta;
        ci = -ci;
        n = murk_neg(n);
    }
    float s2t = murk_maxf(0.0f, 1.0f - ci * ci) / (eta * eta);
    if (s2t >= 1.0f)
        return 0;
    float ct = sqrtf(1.0f - s2t);
    *wt = murk_normalize(murk_add(murk_mul(w, -1.0f / eta), murk_mul(n, ci / eta - ct)));
    *etap = eta;
    return 1;
}

static int usable(float z) { return fabsf(z) >= DI_MU_MIN; } /* NaN -> 0 */

/* ---- Multiple-scattering compensation ---------------------------------------------------------- */
#include "dielectric_tables_axis.h"

static float ms_alpha(int j)
{
    float r = (float)j / (float)(DI_TAB_NR - 1);
    return murk_maxf(r * r, DI_ALPHA_MIN);
}

/* E(mu) of row j on side `side` */
static float ms_row(const di_ms *t, int side, int j, float mu)
{
    float u = (float)di_u_of_mu(side, mu, ms_alpha(j), t->mc) * (float)(DI_TAB_NMU - 1);
    int i = (int)u;
    i = i > DI_TAB_NMU - 2 ? DI_TAB_NMU - 2 : (i < 0 ? 0 : i);
    const float *row = t->e[side][j];
    return row[i] + (row[i + 1] - row[i]) * (u - (float)i);
}

/* The compensation at one wo for one index: its probability of being sampled (1 - E(mu_o)), the share of
 * it that reflects (r) and the constants of its two lobes. */
typedef struct ms_at {
    int j;           /* roughness row, blended with j + 1 by fr */
    float fr;
    float one_eo;    /* 1 - E(mu_o) */
    float r;         /* reflected share of the compensation's energy, on wo's side */
    float kr, kt;    /* f = kr (1 - E_o)(1 - E_i) (reflection), kt (1 - E_o)(1 - E_i) [/ eta^2 from outside] */
} ms_at;

/* 1 - E(mu) on side `side` at m's roughness */
static float ms_one_e(const di_ms *t, const ms_at *m, int side, float mu)
{
    float e0 = ms_row(t, side, m->j, mu), e1 = ms_row(t, side, m->j + 1, mu);
    return murk_clamp01(1.0f - (e0 + (e1 - e0) * m->fr));
}

/* The lobe (Kulla & Conty 2017's dielectric extension; derived in docs/materials.md). Sides: o outside,
 * i inside (index eta); A_s = 1 - Eavg_s, Favg the outside's Fresnel average. For wo on side s, wi on s':
 *   transmitted share  t_o = (1 - Favg) A_i / (A_o + A_i),  t_i = (1 - Favg) A_o / (eta^2 (A_o + A_i)),
 *                      r_s = 1 - t_s (both sides conserve energy; transmission stays reciprocal)
 *   reflection    f = kr (1 - E_s(mu_o)) (1 - E_s(mu_i)),  kr = r_s / (pi A_s)
 *   transmission  f = kt (1 - E_s(mu_o)) (1 - E_s'(mu_i)) [/ eta^2 from outside],  kt = (1 - Favg) / (pi (A_o + A_i))
 * It is sampled with probability 1 - E_s(mu_o) (the energy it carries), then reflection with
 * probability r_s, else transmission, the direction cosine-weighted on that side. */
static void ms_prepare(const di_ms *t, float alpha, float eta, int side, float mu_o, ms_at *m)
{
    float r = sqrtf(alpha) * (float)(DI_TAB_NR - 1);
    int j = (int)r;
    m->j = j > DI_TAB_NR - 2 ? DI_TAB_NR - 2 : j;
    m->fr = r - (float)m->j;
    m->one_eo = ms_one_e(t, m, side, mu_o);
    float ao = 1.0f - (t->avg[0][m->j] + (t->avg[0][m->j + 1] - t->avg[0][m->j]) * m->fr);
    float ai = 1.0f - (t->avg[1][m->j] + (t->avg[1][m->j + 1] - t->avg[1][m->j]) * m->fr);
    float as = side ? ai : ao, sum = ao + ai, tf = 1.0f - t->favg;
    if (!(sum > 1e-7f)) { /* (numerically) no loss to compensate on either side */
        m->one_eo = m->r = m->kr = m->kt = 0.0f;
        return;
    }
    float ts = side ? tf * ao / (eta * eta * sum) : tf * ai / sum;
    m->r = murk_clamp01(1.0f - ts);
    m->kr = as > 1e-7f ? m->r / (MURK_PI * as) : 0.0f; /* kt alone keeps transmission reciprocal */
    m->kt = tf / (MURK_PI * sum);
}

/* Rough lobes for one index eta: f (without tint) into *f, pdf into *pdf; ms (may be NULL): the
 * compensation's tables for eta. Returns 0 when both are 0. */
static int rough_one(const di_ms *ms, float eta, float alpha, murk_vec3 wo, murk_vec3 wi, float *f, float *pdf, int *trans)
{
    *f = *pdf = 0.0f;
    float co = wo.z, ci = wi.z;
    int reflect = co * ci > 0.0f;
    float etap = reflect ? 1.0f : (co > 0.0f ? eta : 1.0f / eta);
    *trans = !reflect;
    float a2 = alpha * alpha;
    murk_vec3 wm = murk_add(murk_mul(wi, etap), wo);
    float l2 = murk_dot(wm, wm);
    if (l2 > 1e-12f) { /* single scattering */
        wm = murk_mul(wm, 1.0f / sqrtf(l2));
        if (wm.z < 0.0f)
            wm = murk_neg(wm);
        float dwi = murk_dot(wm, wi), dwo = murk_dot(wm, wo);
        if (dwi * ci > 0.0f && dwo * co > 0.0f) {
            float D = murk_ggx_d(wm, a2);
            /* a transmitted pair's Fresnel from the outside direction's cosine, whichever of wo and wi it
             * is: the same number as from inside, but without the cancellation in 1 - sin^2 near the
             * critical angle, so f stays reciprocal to float precision */
            float F = murk_fresnel_dielectric(reflect || co > 0.0f ? dwo : dwi, eta);
            float dwo_pdf = murk_ggx_vndf_pdf(wo, wm, a2); /* D_wo(wm) */
            if (reflect) {
                *f = D * F * 0.25f * murk_ggx_g2_over_mu2(co, ci, a2);
                *pdf = dwo_pdf * F / (4.0f * fabsf(dwo));
            } else {
                float s = dwi + dwo / etap, den = s * s;
                if (den > 0.0f) {
                    float T = 1.0f - F;
                    *f = D * T * murk_ggx_g2_over_mu2(co, ci, a2) * fabsf(dwi * dwo) / den / (etap * etap);
                    *pdf = dwo_pdf * T * fabsf(dwi) / den;
                }
            }
        }
    }
    if (ms) { /* the compensation lobe, mixed into the pdf with its sampling probability */
        ms_at m;
        int so = co < 0.0f, si = ci < 0.0f;
        ms_prepare(ms, alpha, eta, so, fabsf(co), &m);
        float k = m.one_eo * ms_one_e(ms, &m, si, fabsf(ci));
        float cos_pdf = fabsf(ci) * MURK_INV_PI;
        *pdf *= 1.0f - m.one_eo;
        if (reflect) {
            *f += m.kr * k;
            *pdf += m.one_eo * m.r * cos_pdf;
        } else {
            *f += so ? m.kt * k : m.kt * k / (eta * eta);
            *pdf += m.one_eo * (1.0f - m.r) * cos_pdf;
        }
    }
    if (!isfinite(*f) || !isfinite(*pdf)) {
        *f = *pdf = 0.0f;
        return 0;
    }
    return *f > 0.0f || *pdf > 0.0f;
}

/* eval and pdf together: f per channel, pdf averaged over the channels when dispersive. */
static float rough_eval(const dielectric *d, const di_shade *sh, murk_vec3 wo, murk_vec3 wi, murk_rgb *f)
{
    *f = murk_rgb1(0.0f);
    if (!usable(wo.z) || !usable(wi.z) || !(sh->alpha > 0.0f))
        return 0.0f;
    float pdf = 0.0f;
    int trans = 0;
    for (int c = 0; c < 3; c++) {
        if (c > 0 && !d->dispersive) {
            f->c[c] = f->c[0];
            continue;
        }
        float fc, pc;
        rough_one(d->ms ? &d->tab[c] : NULL, d->eta[c], sh->alpha, wo, wi, &fc, &pc, &trans);
        f->c[c] = fc;
        pdf += pc;
    }
    if (!d->dispersive)
        pdf *= 3.0f;
    if (trans)
        *f = murk_rgb_mul(*f, sh->tint);
    return pdf * (1.0f / 3.0f);
}

/* The compensation's tables for index eta (in [1, 4]): the rows of the two nearest eta nodes blended on
 * the aligned axis (dielectric_tables_axis.h), their exact averages, and Favg by a midpoint rule in mu^2
 * with 4096 points (F is smooth from outside; its error: docs/results.md). */
static void ms_build(di_ms *t, double eta)
{
    double x = sqrt(fmax(0.0, (eta - 1.0) / 3.0)) * (DI_TAB_NETA - 1);
    int k = (int)x;
    k = k > DI_TAB_NETA - 2 ? DI_TAB_NETA - 2 : k;
    double fx = x - k, mc = di_mucrit(eta);
    t->mc = (float)mc;
    for (int side = 0; side < 2; side++)
        for (int j = 0; j < DI_TAB_NR; j++) {
            double row[DI_TAB_NMU];
            const float *r0 = &di_e[((side * DI_TAB_NETA + k) * DI_TAB_NR + j) * DI_TAB_NMU];
            const float *r1 = r0 + DI_TAB_NR * DI_TAB_NMU;
            for (int i = 0; i < DI_TAB_NMU; i++) {
                row[i] = r0[i] + ((double)r1[i] - r0[i]) * fx;
                t->e[side][j][i] = (float)row[i];
            }
            t->avg[side][j] = (float)di_row_avg(row, DI_TAB_NMU, side, ms_alpha(j), mc);
        }
    double sum = 0.0;
    enum { NF = 4096 };
    for (int i = 0; i < NF; i++) /* integral of F d(mu^2) */
        sum += murk_fresnel_dielectric(sqrtf((float)((i + 0.5) / NF)), (float)eta);
    t->favg = (float)(sum / NF);
}

/* ---- Plugin interface ---------------------------------------------------------------------- */
static int di_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    dielectric *d = host->alloc(sizeof *d);
    if (!d)
        return -1;
    d->host = host;
    memcpy(d->p, p, sizeof d->p);
    for (int c = 0; c < 3; c++)
        d->eta[c] = (float)p[P_IOR].f[c];
    d->dispersive = d->eta[0] != d->eta[1] || d->eta[1] != d->eta[2];
    d->ms = p[P_MULTISCATTER].f[0] != 0.0;
    for (int c = 0; d->ms && c < (d->dispersive ? 3 : 1); c++)
        ms_build(&d->tab[c], p[P_IOR].f[c]);
    *self = d;
    return 0;
}

static void di_destroy(void *self)
{
    dielectric *d = self;
    if (d)
        d->host->free(d);
}

/* murk's frame (+z on wo's side) to the oriented one (+z outside) and back: the model is isotropic, so
 * flipping z is all it takes. */
static int orient(const di_shade *sh, murk_vec3 *wo, murk_vec3 *wi)
{
    if (!sh->inside)
        return 0;
    wo->z = -wo->z;
    if (wi)
        wi->z = -wi->z;
    return 1;
}

static void di_prepare(const void *self, const murk_hit *hit, murk_shading *sp)
{
    _Static_assert(sizeof(di_shade) <= MURK_SHADING_BYTES, "di_shade fits a murk_shading");
    shade_at(self, hit, (di_shade *)sp->data.bytes);
}

static murk_rgb di_eval_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    const di_shade *sh = (const di_shade *)sp->data.bytes;
    orient(sh, &wo, &wi);
    murk_rgb f;
    rough_eval(self, sh, wo, wi, &f);
    return f;
}

static float di_pdf_at(const void *self, const murk_shading *sp, murk_vec3 wo, murk_vec3 wi)
{
    const di_shade *sh = (const di_shade *)sp->data.bytes;
    orient(sh, &wo, &wi);
    murk_rgb f;
    return rough_eval(self, sh, wo, wi, &f);
}

static int di_sample_oriented(const dielectric *d, const di_shade *sh, murk_vec3 wo, const float u[3],
                              murk_bsdf_sample *s);

static int di_sample_at(const void *self, const murk_shading *sp, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
    const di_shade *sh = (const di_shade *)sp->data.bytes;
    int in = orient(sh, &wo, NULL);
    int ok = di_sample_oriented(self, sh, wo, u, s);
    if (in)
        s->wi.z = -s->wi.z;
    return ok;
}

MURK_MATERIAL_HIT_METHODS(di)

static int di_sample_oriented(const dielectric *d, const di_shade *sh, murk_vec3 wo, const float u[3],
                              murk_bsdf_sample *s)
{
    memset(s, 0, sizeof *s);
    s->eta = 1.0f;
    if (!usable(wo.z))
        return 0;
    float uc = u[2];
    int ch = 0;
    if (d->dispersive) { /* one channel's lobes, chosen uniformly; uc reused for the lobe choice */
        ch = (int)(uc * 3.0f);
        ch = ch > 2 ? 2 : ch;
        uc = uc * 3.0f - (float)ch;
    }
    float eta = d->eta[ch];
    if (!(sh->alpha > 0.0f)) { /* smooth: two delta lobes */
        float R = murk_fresnel_dielectric(wo.z, eta), T = 1.0f - R;
        float w;
        if (uc < R) {
            s->wi = murk_v3(-wo.x, -wo.y, wo.z);
            s->pdf = R;
            w = R;
            s->f = murk_rgb1(R / fabsf(s->wi.z));
        } else {
            float etap;
            if (!refract(wo, murk_v3(0, 0, 1), eta, &etap, &s->wi) || !usable(s->wi.z) || s->wi.z * wo.z >= 0.0f)
                return 0;
            s->pdf = T;
            w = T;
            s->f = murk_rgb_scale(sh->tint, T / (etap * etap * fabsf(s->wi.z)));
            s->eta = etap;
        }
        if (!(w > 0.0f))
            return 0;
        if (d->dispersive) { /* channel ch only, weight x3 (chosen with probability 1/3) */
            for (int c = 0; c < 3; c++)
                s->f.c[c] = c == ch ? 3.0f * s->f.c[c] : 0.0f;
        }
        s->delta = 1;
        return murk_rgb_finite(s->f) && isfinite(s->pdf);
    }
    murk_vec3 wi;
    int lobe_ms = 0;
    if (d->ms) { /* the compensation lobe with probability 1 - E(mu_o) (see ms_prepare) */
        ms_at m;
        ms_prepare(&d->tab[ch], sh->alpha, eta, wo.z < 0.0f, fabsf(wo.z), &m);
        if (uc < m.one_eo) {
            lobe_ms = 1;
            float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1], z = sqrtf(murk_maxf(0.0f, 1.0f - u[0]));
            int same = uc / m.one_eo < m.r; /* reflection: wo's side */
            wi = murk_v3(r * cosf(phi), r * sinf(phi), (wo.z > 0.0f) == same ? z : -z);
            if (!same)
                s->eta = wo.z > 0.0f ? eta : 1.0f / eta;
        } else {
            uc = (uc - m.one_eo) / (1.0f - m.one_eo);
        }
    }
    if (!lobe_ms) { /* a visible normal of wo (of -wo when wo is inside), then Fresnel's choice */
        murk_vec3 wv = wo.z > 0.0f ? wo : murk_neg(wo);
        murk_vec3 wm = murk_ggx_sample_vndf(wv, sh->alpha, u[0], u[1]);
        float R = murk_fresnel_dielectric(murk_dot(wo, wm), eta);
        if (uc < R) {
            wi = murk_reflect(wo, wm);
            if (wi.z * wo.z <= 0.0f)
                return 0;
        } else {
            float etap;
            if (!refract(wo, wm, eta, &etap, &wi) || wi.z * wo.z >= 0.0f)
                return 0;
            s->eta = etap;
        }
    }
    if (!usable(wi.z))
        return 0;
    murk_rgb f;
    float pdf = rough_eval(d, sh, wo, wi, &f);
    if (!(pdf > 0.0f) || !isfinite(pdf) || !murk_rgb_finite(f))
        return 0;
    s->wi = wi;
    s->f = f;
    s->pdf = pdf;
    return 1;
}

static const murk_material_vt vt = {
    sizeof(murk_material_vt), MURK_KIND_MATERIAL, di_create, di_destroy, di_eval, di_pdf, di_sample,
    di_prepare, di_eval_at, di_pdf_at, di_sample_at,
};

MURK_MATERIAL_PLUGIN("dielectric",
                     "smooth or rough (GGX, energy-compensated) dielectric: reflection, refraction, TIR; RGB dispersion",
                     params, P_COUNT, &vt)
