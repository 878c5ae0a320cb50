/* draine_math.h — Draine's phase function (Draine 2003, "Scattering by interstellar dust grains. I.
 * Optical and ultraviolet", ApJ 598, eq. 4), which the `draine` and `hg_draine` plugins share:
 *
 *   p(mu) = 1/(4 pi) (1 - g^2) / (1 + g^2 - 2 g mu)^(3/2) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3)
 *
 * mu = cos(theta) the cosine of the scattering angle; alpha = 0 is Henyey-Greenstein, alpha = 1 (g = 0)
 * Rayleigh's (1 + mu^2). Its mean cosine is <mu> = g (1 + alpha (3 + 2 g^2) / 5) / (1 + alpha (1 + 2 g^2)
 * / 3) (Draine 2003, eq. 5: HG's Legendre moments <P_l> = g^l give <mu^2> = (1 + 2 g^2) / 3 and <mu^3> =
 * (3 g + 2 g^3) / 5).
 *
 * Sampling: exactly, by inverting its CDF in mu with safeguarded Newton steps (in double). The CDF is
 *   F(mu) = (H(mu) + alpha M2(mu)) / (1 + alpha (1 + 2 g^2) / 3),
 * H the CDF of HG and M2(mu) = int_{-1}^{mu} x^2 HG(x) dx; with t = sqrt(1 + g^2 - 2 g mu), T = 1 + g
 * (t at mu = -1), c = 1 + g^2 and q = t T, both without the 1/g^3 cancellation of the textbook forms
 * (derived for murk; finite at g = 0, where they are (1 + mu) / 2 and (1 + mu^3) / 6):
 *   H(mu)  = (1 - g) (1 + mu) / (t (1 + g + t))
 *   M2(mu) = (1 - g^2) (1 + mu) K / (3 (T + t) q (q + c)),
 *   K      = (1 - mu) (q + 3 c) (c (1 - mu) - 2 g mu) / (q + c) - mu (q - 3 c).
 * Jendersie and d'Eon (2023) give a closed-form inverse; Newton on these forms is as exact and keeps
 * the code checkable line by line. */
#ifndef MURK_DRAINE_MATH_H
#define MURK_DRAINE_MATH_H

#include <math.h>

/* The density of mu (per unit mu, integrating to 1 over [-1, 1]). */
static inline double draine_pdf_mu(double g, double alpha, double mu)
{
    double s = 1.0 + g * g - 2.0 * g * mu;
    return 0.5 * (1.0 - g * g) / (s * sqrt(s)) * (1.0 + alpha * mu * mu) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0);
}

/* The phase function per steradian at mu. */
static inline float draine_eval_mu(float g, float alpha, float mu)
{
    float s = 1.0f + g * g - 2.0f * g * mu;
    return (1.0f / (4.0f * MURK_PI)) * (1.0f - g * g) / (s * sqrtf(fmaxf(s, 1e-12f))) * (1.0f + alpha * mu * mu) /
           (1.0f + alpha * (1.0f + 2.0f * g * g) / 3.0f);
}

static inline double draine_cdf(double g, double alpha, double mu)
{
    double t = sqrt(fmax(0.0, 1.0 + g * g - 2.0 * g * mu)), T = 1.0 + g, c = 1.0 + g * g, q = t * T;
    double H = (1.0 - g) * (1.0 + mu) / (t * (1.0 + g + t));
    double K = (1.0 - mu) * (q + 3.0 * c) * (c * (1.0 - mu) - 2.0 * g * mu) / (q + c) - mu * (q - 3.0 * c);
    double M2 = (1.0 - g * g) * (1.0 + mu) * K / (3.0 * (T + t) * q * (q + c));
    return (H + alpha * M2) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0);
}

static inline double draine_mean_cosine(double g, double alpha)
{
    return g * (1.0 + alpha * (3.0 + 2.0 * g * g) / 5.0) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0);
}

/* mu with F(mu) = u: Newton steps from HG's own inverse, kept inside a bracket that bisection shrinks
 * whenever a step leaves it; at most 100 steps (about 6 suffice), to |F - u| <= 1e-12. */
static inline double draine_sample_mu(double g, double alpha, double u)
{
    double lo = -1.0, hi = 1.0, mu;
    if (fabs(g) < 1e-3) {
        mu = 2.0 * u - 1.0;
    } else {
        double sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        mu = (1.0 + g * g - sq * sq) / (2.0 * g);
    }
    mu = fmin(1.0, fmax(-1.0, mu));
    for (int i = 0; i < 100; i++) {
        double e = draine_cdf(g, alpha, mu) - u;
        if (fabs(e) <= 1e-12)
            break;
        if (e > 0.0)
            hi = mu;
        else
            lo = mu;
        double f = draine_pdf_mu(g, alpha, mu), next = f > 0.0 ? mu - e / f : 0.5 * (lo + hi);
        mu = next > lo && next < hi ? next : 0.5 * (lo + hi);
    }
    return mu;
}

#endif
