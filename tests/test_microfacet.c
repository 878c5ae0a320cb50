/* test_microfacet.c — murk/microfacet.h against closed forms and quadrature: GGX's D is normalised
 * (integral of D(m) m.z over the hemisphere = 1, Walter et al. 2007), the visible-normal density
 * integrates to 1 (Heitz 2018: the weak white furnace of G1), sampled visible normals have the moments
 * that density gives them (with a biased mutant that must fail), Smith's Lambda, G1 and G2 agree with
 * Heitz 2014's closed forms, and the dielectric Fresnel equals ((n - 1) / (n + 1))^2 at normal
 * incidence, Fresnel's sine and tangent laws at oblique incidence, and 1 under total internal
 * reflection. */
#include "stat.h"

#include "murk/microfacet.h"

#include <math.h>
#include <stdio.h>

static const double PI = 3.14159265358979323846;

/* |a - b| <= tol in double (cmocka's assert_float_equal compares floats) */
#define assert_near(a, b, tol)                                                                         \
    do {                                                                                               \
        double a_ = (a), b_ = (b);                                                                     \
        if (!(fabs(a_ - b_) <= (tol)))                                                                 \
            fail_msg("%s = %.10g, expected %.10g (tolerance %g)", #a, a_, b_, (double)(tol));          \
    } while (0)

static murk_vec3 dir(double mu, double phi)
{
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    return murk_v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)mu);
}

/* integral of D(m) m.z dm over the hemisphere = 2 pi integral of D(mu) mu dmu, midpoint rule */
static void test_d_normalised(void **state)
{
    (void)state;
    const double alphas[] = {0.02, 0.1, 0.5, 1.0};
    enum { N = 2000000 };
    for (int k = 0; k < 4; k++) {
        float a2 = (float)(alphas[k] * alphas[k]);
        double sum = 0.0;
        for (int i = 0; i < N; i++) {
            double mu = (i + 0.5) / N;
            sum += murk_ggx_d(dir(mu, 0.0), a2) * mu;
        }
        double integral = 2.0 * PI * sum / N;
        if (fabs(integral - 1.0) > 1e-5)
            fail_msg("alpha %g: integral of D cos = %.7f, expected 1", alphas[k], integral);
    }
}

/* Moments of g(m) under the visible normal density of wo: out[0] = integral of D_wo, out[1..2] of
 * D_wo m.x and D_wo m.z, out[3..4] of D_wo m.x^2 and D_wo m.z^2 (midpoint rule over mu and phi). */
static void vndf_moments(murk_vec3 wo, float alpha, double out[5])
{
    enum { NMU = 3000, NPHI = 1500 };
    float a2 = alpha * alpha;
    for (int k = 0; k < 5; k++)
        out[k] = 0.0;
    for (int i = 0; i < NMU; i++)
        for (int j = 0; j < NPHI; j++) {
            murk_vec3 m = dir((i + 0.5) / NMU, 2.0 * PI * (j + 0.5) / NPHI);
            if (!(murk_dot(wo, m) > 0.0f))
                continue;
            double p = murk_ggx_vndf_pdf(wo, m, a2);
            out[0] += p;
            out[1] += p * m.x;
            out[2] += p * m.z;
            out[3] += p * m.x * m.x;
            out[4] += p * m.z * m.z;
        }
    for (int k = 0; k < 5; k++)
        out[k] *= 2.0 * PI / ((double)NMU * NPHI);
}

static void test_vndf_pdf_integrates_to_one(void **state)
{
    (void)state;
    const double alphas[] = {0.3, 0.6, 1.0}, thetas[] = {0.0, 45.0, 80.0};
    for (int a = 0; a < 3; a++)
        for (int t = 0; t < 3; t++) {
            double th = thetas[t] * PI / 180.0, mom[5];
            vndf_moments(dir(cos(th), 0.0), (float)alphas[a], mom);
            if (fabs(mom[0] - 1.0) > 5e-5)
                fail_msg("alpha %g, theta %g: integral of D_wo = %.6f, expected 1", alphas[a], thetas[t], mom[0]);
        }
}

/* Sample means of m.x and m.z over n visible normals drawn with width alpha_s, against the moments of
 * the density of width alpha: the deviations in units of their standard errors (z[0]: m.x, z[1]: m.z). */
static void vndf_sample_deviation(murk_vec3 wo, float alpha, float alpha_s, long n, double z[2])
{
    double mom[5];
    vndf_moments(wo, alpha, mom);
    murk_rng rng;
    murk_rng_seed(&rng, 7, 11, 13);
    double sx = 0.0, sz = 0.0;
    for (long i = 0; i < n; i++) {
        float u0 = murk_rng_float(&rng), u1 = murk_rng_float(&rng);
        murk_vec3 m = murk_ggx_sample_vndf(wo, alpha_s, u0, u1);
        sx += m.x;
        sz += m.z;
    }
    double ex = mom[1] / mom[0], ez = mom[2] / mom[0];
    double se_x = sqrt((mom[3] / mom[0] - ex * ex) / n), se_z = sqrt((mom[4] / mom[0] - ez * ez) / n);
    z[0] = (sx / n - ex) / se_x;
    z[1] = (sz / n - ez) / se_z;
}

/* murk_ggx_sample_vndf draws from murk_ggx_vndf_pdf: the moments agree within STAT_Z standard errors
 * (stat.h; the quadrature's own error is far below one standard error at this n); the must-fail case,
 * sampling with an alpha 15 % too large (a biased sampler), fails the same bound. */
static void test_vndf_sampling_matches_pdf(void **state)
{
    (void)state;
    const long n = stat_n(200000);
    const double alphas[] = {0.3, 0.8}, thetas[] = {30.0, 70.0};
    for (int a = 0; a < 2; a++)
        for (int t = 0; t < 2; t++) {
            double th = thetas[t] * PI / 180.0;
            murk_vec3 wo = dir(cos(th), 0.3);
            float al = (float)alphas[a];
            double z[2], zb[2];
            vndf_sample_deviation(wo, al, al, n, z);
            printf("alpha %g, theta %g: sample moments %+.2f, %+.2f standard errors off\n", alphas[a], thetas[t], z[0],
                   z[1]);
            for (int k = 0; k < 2; k++)
                assert_true(stat_z_ok(z[k], 1.0, 0.0, 0.0));
            vndf_sample_deviation(wo, al, 1.15f * al, n, zb);
            double worst = fabs(zb[0]) > fabs(zb[1]) ? zb[0] : zb[1];
            char label[96];
            snprintf(label, sizeof label, "vndf alpha %g theta %g, sampled with alpha x 1.15", alphas[a], thetas[t]);
            assert_true(stat_must_fail(label, fabs(worst) > STAT_Z, worst));
        }
}

/* Lambda(mu) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2; G1 = 1 / (1 + Lambda); the height-correlated
 * G2 = 1 / (1 + Lambda_o + Lambda_i) (Heitz 2014, eqs. 86 and 99). */
static void test_smith(void **state)
{
    (void)state;
    const double alphas[] = {0.05, 0.4, 1.0}, mus[] = {0.02, 0.3, 0.7, 1.0};
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < 4; i++) {
            double al = alphas[a], mu = mus[i], t2 = (1.0 - mu * mu) / (mu * mu);
            float a2 = (float)(al * al);
            double lambda = 0.5 * (sqrt(1.0 + al * al * t2) - 1.0);
            assert_near(murk_ggx_lambda((float)mu, a2), lambda, 2e-5 * (1.0 + lambda));
            assert_near(mu * murk_ggx_g1_over_mu((float)mu, a2), 1.0 / (1.0 + lambda), 2e-6);
            assert_near(mu * murk_ggx_g1_over_mu((float)-mu, a2), 1.0 / (1.0 + lambda), 2e-6);
            for (int j = 0; j < 4; j++) {
                double mi = mus[j], ti2 = (1.0 - mi * mi) / (mi * mi);
                double lambda_i = 0.5 * (sqrt(1.0 + al * al * ti2) - 1.0);
                assert_near(mu * mi * murk_ggx_g2_over_mu2((float)mu, (float)-mi, a2),
                                   1.0 / (1.0 + lambda + lambda_i), 2e-6);
            }
        }
}

/* Fresnel's laws for an interface of relative index eta, incidence angle ti from the side of index 1:
 * (R_s + R_p) / 2, R_s = sin^2(ti - tt) / sin^2(ti + tt), R_p = tan^2(ti - tt) / tan^2(ti + tt). */
static double fresnel_laws(double ti, double eta)
{
    double tt = asin(sin(ti) / eta);
    double rs = sin(ti - tt) / sin(ti + tt), rp = tan(ti - tt) / tan(ti + tt);
    return 0.5 * (rs * rs + rp * rp);
}

static void test_fresnel_dielectric(void **state)
{
    (void)state;
    const double etas[] = {1.33, 1.5, 2.4};
    for (int k = 0; k < 3; k++) {
        double n = etas[k], r0 = (n - 1.0) * (n - 1.0) / ((n + 1.0) * (n + 1.0));
        assert_near(murk_fresnel_dielectric(1.0f, (float)n), r0, 1e-6);
        assert_near(murk_fresnel_dielectric(-1.0f, (float)n), r0, 1e-6); /* from inside */
        assert_near(murk_fresnel_dielectric_cos_d(1.0, n), r0, 1e-15);
        for (int d = 10; d <= 80; d += 35) { /* oblique, from outside and (below the critical angle) inside */
            double ti = d * PI / 180.0;
            assert_near(murk_fresnel_dielectric((float)cos(ti), (float)n), fresnel_laws(ti, n), 2e-6);
            assert_near(murk_fresnel_dielectric_cos_d(cos(ti), n), fresnel_laws(ti, n), 1e-12);
            double tin = asin(sin(ti) / n); /* the same ray from inside: the same reflectance */
            assert_near(murk_fresnel_dielectric((float)-cos(tin), (float)n), fresnel_laws(ti, n), 2e-6);
        }
        /* total internal reflection past the critical angle from inside, and grazing incidence */
        double tc = asin(1.0 / n);
        for (double dt = 0.01; dt < PI / 2 - tc; dt += 0.2)
            assert_true(murk_fresnel_dielectric((float)-cos(tc + dt), (float)n) == 1.0f);
        assert_true(murk_fresnel_dielectric((float)-cos(tc - 0.01), (float)n) < 1.0f);
        assert_near(murk_fresnel_dielectric(0.0f, (float)n), 1.0, 1e-6);
    }
    assert_near(murk_fresnel_dielectric(0.6f, 1.0f), 0.0, 1e-10); /* index matched: invisible */
}

static void test_schlick_and_reflect(void **state)
{
    (void)state;
    assert_near(murk_fresnel_schlick(0.04f, 1.0f), 0.04f, 0.0);
    assert_near(murk_fresnel_schlick(0.04f, 0.0f), 1.0, 1e-7);
    assert_near(murk_fresnel_schlick(0.5f, 0.5f), 0.5 + 0.5 / 32.0, 1e-7);
    murk_vec3 w = murk_normalize(murk_v3(0.3f, -0.2f, 0.9f)), r = murk_reflect(w, murk_v3(0, 0, 1));
    assert_near(r.x, -w.x, 1e-7);
    assert_near(r.y, -w.y, 1e-7);
    assert_near(r.z, w.z, 1e-7);
    assert_near(murk_clamp01(NAN), 0.0, 0.0);
    assert_near(murk_clamp01(2.0f), 1.0, 0.0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_d_normalised),
        cmocka_unit_test(test_vndf_pdf_integrates_to_one),
        cmocka_unit_test(test_vndf_sampling_matches_pdf),
        cmocka_unit_test(test_smith),
        cmocka_unit_test(test_fresnel_dielectric),
        cmocka_unit_test(test_schlick_and_reflect),
    };
    return STAT_RUN(tests, argc, argv);
}
