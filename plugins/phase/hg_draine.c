/* hg_draine — the approximate Mie phase function of Jendersie and d'Eon (2023, "An approximate Mie
 * scattering function for fog and cloud rendering", ACM SIGGRAPH 2023 Talks, article 47,
 * doi:10.1145/3587421.3595409): a blend of Henyey-Greenstein and Draine (draine_math.h),
 *     p = (1 - w_D) HG(g_HG) + w_D Draine(g_D, alpha),
 * whose four parameters the talk fits to the diameter d of the water droplets, in micrometres, over four
 * ranges (its equations, as published; log is the natural logarithm):
 *   d <= 0.1:       g_HG = 13.8 d^2, g_D = 1.1456 d sin(9.29044 d), alpha = 250,
 *                   w_D = 0.252977 - 312.983 d^4.3
 *   0.1 < d < 1.5:  g_HG = 0.862 - 0.143 log^2 d,
 *                   g_D = 0.379685 cos(1.19692 cos((log d - 0.238604)(log d + 1.00667) /
 *                         (0.507522 - 0.15677 log d)) + 1.37932 log d + 0.0625835) + 0.344213,
 *                   alpha = 250, w_D = 0.146209 cos(3.38707 log d + 2.11193) + 0.316072 + 0.0778917 log d
 *   1.5 <= d < 5:   g_HG = 0.0604931 log log d + 0.940256,
 *                   g_D = 0.500411 - 0.081287 / (-2 log d + tan(log d) + 1.27551),
 *                   alpha = 7.30354 log d + 6.31675,
 *                   w_D = 0.026914 (log d - cos(5.68947 (log log d - 0.0292149))) + 0.376475
 *   5 <= d <= 50:   g_HG = exp(-0.0990567 / (d - 1.67154)), g_D = exp(-2.20679 / (d + 3.91029) - 0.428934),
 *                   alpha = exp(3.62489 - 8.29288 / (d + 5.52825)),
 *                   w_D = exp(-0.599085 / (d - 0.641583) - 0.665888)
 * Sampled exactly: the lobe by u[0] against w_D (u[0] rescaled for the lobe's own sampler), the value and
 * pdf the blend's. Fog is d of a few micrometres, cumulus clouds 10 to 30.
 *
 * The HG lobe is as narrow as 1 - g_HG = 0.002 (d = 50), where float arithmetic on cos(theta) loses the
 * peak: 1 + g^2 - 2 g cos(theta) there is about 1e-5 and cancels to a few percent. So this lobe works with
 * 1 - cos(theta) instead, |wo + wi|^2 / 2 in eval and, in sample, the inverse CDF rewritten without the
 * cancellation, 1 - cos(theta) = (1 - g) u (s + 1 - g) / (1 + g - 2 g u), s = (1 - g^2) / (1 + g - 2 g u)
 * (algebra on murk_hg_sample's s; murk's `hg` keeps murk_hg_eval, the bits of every earlier image). */
#include "murk/phase.h"

#include <stdio.h>

#include "draine_math.h"

enum { P_DIAMETER, P_COUNT };
static const murk_param params[P_COUNT] = {
    [P_DIAMETER] = {"diameter", MURK_PARAM_FLOAT, 0, {20, 0, 0}, NULL, NULL, 0.01, 50,
                    "the water droplets' diameter in micrometres, from which Jendersie and d'Eon's fits give the "
                    "blend's four parameters (murk prints them when it loads the scene): fog a few micrometres, cumulus clouds 10 to "
                    "30; the fits cover up to 50"},
};

typedef struct hgd {
    const murk_host *host;
    float g_hg, g_d, alpha, w_d;
} hgd;

/* The talk's fits of the blend's parameters to the diameter d in micrometres. */
static void hgd_fit(double d, hgd *p)
{
    double g_hg, g_d, alpha, w_d, l = log(d);
    if (d <= 0.1) {
        g_hg = 13.8 * d * d;
        g_d = 1.1456 * d * sin(9.29044 * d);
        alpha = 250.0;
        w_d = 0.252977 - 312.983 * pow(d, 4.3);
    } else if (d < 1.5) {
        g_hg = 0.862 - 0.143 * l * l;
        g_d = 0.379685 * cos(1.19692 * cos((l - 0.238604) * (l + 1.00667) / (0.507522 - 0.15677 * l)) +
                             1.37932 * l + 0.0625835) + 0.344213;
        alpha = 250.0;
        w_d = 0.146209 * cos(3.38707 * l + 2.11193) + 0.316072 + 0.0778917 * l;
    } else if (d < 5.0) {
        g_hg = 0.0604931 * log(l) + 0.940256;
        g_d = 0.500411 - 0.081287 / (-2.0 * l + tan(l) + 1.27551);
        alpha = 7.30354 * l + 6.31675;
        w_d = 0.026914 * (l - cos(5.68947 * (log(l) - 0.0292149))) + 0.376475;
    } else {
        g_hg = exp(-0.0990567 / (d - 1.67154));
        g_d = exp(-2.20679 / (d + 3.91029) - 0.428934);
        alpha = exp(3.62489 - 8.29288 / (d + 5.52825));
        w_d = exp(-0.599085 / (d - 0.641583) - 0.665888);
    }
    p->g_hg = (float)g_hg;
    p->g_d = (float)g_d;
    p->alpha = (float)alpha;
    p->w_d = (float)w_d;
}

static int hgd_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    hgd *h = host->alloc(sizeof *h);
    if (!h)
        return -1;
    h->host = host;
    hgd_fit(p[P_DIAMETER].f[0], h);
    if (!(fabsf(h->g_hg) < 1.0f && fabsf(h->g_d) < 1.0f && h->alpha >= 0.0f && h->w_d >= 0.0f && h->w_d <= 1.0f)) {
        snprintf(err, errlen, "diameter %g gives blend parameters outside their range (g_HG %g, g_D %g, alpha %g, w_D %g)",
                 p[P_DIAMETER].f[0], (double)h->g_hg, (double)h->g_d, (double)h->alpha, (double)h->w_d);
        host->free(h);
        return -1;
    }
    host->log(MURK_LOG_INFO, "hg_draine: diameter %g um: g_HG %.6f, g_D %.6f, alpha %.6f, w_D %.6f (Jendersie and "
              "d'Eon 2023)", p[P_DIAMETER].f[0], (double)h->g_hg, (double)h->g_d, (double)h->alpha, (double)h->w_d);
    *self = h;
    return 0;
}

static void hgd_destroy(void *self)
{
    hgd *h = self;
    if (h)
        h->host->free(h);
}

/* Henyey-Greenstein for g in [0, 1) from om = 1 - cos(theta): 1 + g^2 - 2 g cos = (1 - g)^2 + 2 g om. */
static float hg_om(float g, float om)
{
    float s = (1.0f - g) * (1.0f - g) + 2.0f * g * om;
    return (1.0f / (4.0f * MURK_PI)) * (1.0f - g * g) / (s * sqrtf(fmaxf(s, 1e-30f)));
}

static float hgd_eval(const void *self, murk_vec3 wo, murk_vec3 wi)
{
    const hgd *h = self;
    murk_vec3 s = murk_add(wo, wi);
    float om = 0.5f * murk_dot(s, s); /* 1 - cos(theta), cos(theta) = -dot(wo, wi) */
    return (1.0f - h->w_d) * hg_om(h->g_hg, om) + h->w_d * draine_eval_mu(h->g_d, h->alpha, 1.0f - om);
}

static float hgd_sample(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    const hgd *h = self;
    if (u[0] < h->w_d) {
        double mu = draine_sample_mu(h->g_d, h->alpha, fmin((double)u[0] / h->w_d, 1.0 - 1e-16));
        *wi = murk_phase_dir_om(murk_neg(wo), (float)(1.0 - mu), u[1]);
    } else {
        double g = h->g_hg, v = fmin((u[0] - h->w_d) / (1.0 - h->w_d), 1.0), d = 1.0 + g - 2.0 * g * v;
        double om = (1.0 - g) * v * ((1.0 - g * g) / d + 1.0 - g) / d; /* 1 - cos(theta) */
        *wi = murk_phase_dir_om(murk_neg(wo), (float)om, u[1]);
    }
    return *pdf = hgd_eval(self, wo, *wi);
}

static double hgd_mean(const void *self)
{
    const hgd *h = self;
    return (1.0 - h->w_d) * h->g_hg + h->w_d * draine_mean_cosine(h->g_d, h->alpha);
}

static const murk_phase_vt vt = {sizeof(murk_phase_vt), MURK_KIND_PHASE, hgd_create, hgd_destroy, hgd_eval, hgd_sample,
                                 hgd_mean};

MURK_PHASE_PLUGIN("hg_draine",
                  "approximate Mie scattering by water droplets (Jendersie and d'Eon 2023): HG + Draine fitted to "
                  "the droplet diameter", params, P_COUNT, &vt)
