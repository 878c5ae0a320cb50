/* test_diffuse.c — statistical tests of the diffuse (Lambertian) material plugin (plugins/diffuse.so).
 * Angles are polar angles of wo measured from the normal. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bsdftest.h"
#include "stat.h"

#define PLUGIN "plugins/diffuse.so"
#define DEG (3.14159265358979323846 / 180.0)
#define INV_PI 0.31830988618379067154

static void test_schema(void **state)
{
    (void)state;
    bt_mat *m = bt_create(PLUGIN, NULL, 0);
    assert_int_equal(m->desc->nparams, 1);
    assert_string_equal(m->desc->params[0].name, "albedo");
    assert_int_equal(m->desc->params[0].type, MURK_PARAM_RGB);
    bt_destroy(m);
}

/* sample() against pdf() over the whole sphere (cells uniform in cos theta around +z): p >= STAT_P */
static void test_chi2(void **state)
{
    (void)state;
    const double ds[3] = {0.0, 45.0, 80.0};
    bt_set set[1] = {BT_RGB("albedo", 0.9, 0.5, 0.1)};
    bt_mat *m = bt_create(PLUGIN, set, 1);
    bt_grid g = {20, 40, {0, 0, 1}, 1.0};
    for (int i = 0; i < 3; i++) {
        char label[48];
        snprintf(label, sizeof label, "diffuse theta=%.0f", ds[i]);
        bt_chi2_result r;
        bt_chi2(label, m, NULL, NULL, bt_dir(ds[i] * DEG, 1.0), stat_n(500000), 31u + (uint64_t)i, &g, &r);
        assert_true(stat_chi2_ok(r.p));
        assert_int_equal(r.mismatch, 0);
        assert_true(fabs(r.pdf_integral - 1.0) <= 3.0 * r.pdf_err + 1e-6);
    }
    bt_destroy(m);
}

/* The must-fail case: the harness rejects a slightly wrong pdf, (n + 1) / (2 pi) cos^n with n = 1.05
 * instead of 1. */
static double cos_pow_pdf(void *ctx, murk_vec3 wo, murk_vec3 wi)
{
    (void)ctx;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
        return 0.0;
    return 2.05 / (2.0 * 3.14159265358979323846) * pow(wi.z, 1.05);
}

static void test_chi2_teeth(void **state)
{
    (void)state;
    bt_mat *m = bt_create(PLUGIN, NULL, 0);
    bt_grid g = {20, 40, {0, 0, 1}, 1.0};
    double p = bt_chi2("diffuse vs cos^1.05", m, cos_pow_pdf, NULL, bt_dir(30.0 * DEG, 0.0), stat_n(1000000), 5u, &g, NULL);
    assert_true(stat_must_fail_chi2("diffuse's samples against cos^1.05", p));
    bt_destroy(m);
}

/* eval = albedo / pi above the horizon, 0 below; pdf = cos / pi */
static void test_eval(void **state)
{
    (void)state;
    bt_set set[1] = {BT_RGB("albedo", 0.25, 0.5, 1.0)};
    bt_mat *m = bt_create(PLUGIN, set, 1);
    murk_rng rng;
    murk_rng_seed(&rng, 17, 0, 0);
    for (int n = 0; n < 10000; n++) {
        murk_vec3 wo = bt_dir(acos(murk_rng_float(&rng)), 6.283185307 * murk_rng_float(&rng));
        murk_vec3 wi = bt_dir(acos(2.0 * murk_rng_float(&rng) - 1.0), 6.283185307 * murk_rng_float(&rng));
        if (!(wo.z > 0.0f))
            continue;
        murk_rgb f = bt_eval(m, wo, wi);
        float p = bt_pdf(m, wo, wi);
        if (wi.z > 0.0f) {
            assert_true(fabs(f.c[0] - 0.25 * INV_PI) <= 1e-6 * 0.25 * INV_PI);
            assert_true(fabs(f.c[1] - 0.5 * INV_PI) <= 1e-6 * 0.5 * INV_PI);
            assert_true(fabs(f.c[2] - 1.0 * INV_PI) <= 1e-6 * INV_PI);
            assert_true(fabs(p - wi.z * INV_PI) <= 1e-6 * wi.z * INV_PI + 1e-12);
        } else {
            assert_true(murk_rgb_is_black(f));
            assert_true(p == 0.0f);
        }
    }
    /* wo at or below the horizon: nothing */
    murk_bsdf_sample s;
    const float u[3] = {0.3f, 0.6f, 0.5f};
    assert_int_equal(bt_sample(m, murk_v3(1, 0, 0), u, &s), 0);
    assert_true(murk_rgb_is_black(bt_eval(m, murk_v3(1, 0, 0), murk_v3(0, 0, 1))));
    assert_true(bt_pdf(m, murk_v3(1, 0, 0), murk_v3(0, 0, 1)) == 0.0f);
    bt_destroy(m);
}

/* White furnace: albedo 1 reflects everything, and cosine sampling makes f cos / pdf exactly 1. */
static void test_furnace(void **state)
{
    (void)state;
    bt_set set[1] = {BT_F("albedo", 1.0)};
    bt_mat *m = bt_create(PLUGIN, set, 1);
    const double ds[3] = {0.0, 45.0, 89.0};
    for (int i = 0; i < 3; i++) {
        double mean[3], sig[3];
        const long n = 200000;
        bt_albedo_is(m, bt_dir(ds[i] * DEG, 0.0), n, 70u + (uint64_t)i, mean, sig);
        double sd = sig[0] * sqrt((double)n); /* per-sample standard deviation */
        fprintf(stderr, "  diffuse furnace theta=%2.0f: E = %.8f, per-sample sd %.2e\n", ds[i], mean[0], sd);
        for (int c = 0; c < 3; c++) {
            assert_true(fabs(mean[c] - 1.0) < 1e-5);
            assert_true(sig[c] * sqrt((double)n) < 1e-5);
        }
    }
    bt_destroy(m);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_schema),
        cmocka_unit_test(test_chi2),
        cmocka_unit_test(test_chi2_teeth),
        cmocka_unit_test(test_eval),
        cmocka_unit_test(test_furnace),
    };
    if (getenv("BT_FILTER"))
        cmocka_set_test_filter(getenv("BT_FILTER"));
    return STAT_RUN(tests, argc, argv);
}
