/* test_lab.c — libmurklab's programmatic API (murk/lab.h) as a program outside murk uses it: this test
 * includes the public headers only and links the shared libmurklab and libmurk, so every call goes through what
 * the library exports.
 *   metrics   two small images with known differences give the figures' closed forms;
 *   schema    a material's and a tracker's descriptors as data, the keys every medium takes, and a
 *             missing plugin refused with a message naming it. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "murk/lab.h"

/* |a - b| <= tol in double (cmocka's assert_float_equal works in float) */
#define assert_near(a, b, tol)                                                                         \
    do {                                                                                               \
        double a_ = (a), b_ = (b);                                                                     \
        if (!(fabs(a_ - b_) <= (tol)))                                                                 \
            fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);                                        \
    } while (0)

/* a = r + d with d = +1/8 in every channel of pixel 0 and -1/8 in pixel 1; r = 0.5 everywhere. */
static void metrics_closed_form(void **state)
{
    (void)state;
    const float r[6] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    float a[6];
    for (int i = 0; i < 6; i++)
        a[i] = r[i] + (i < 3 ? 0.125f : -0.125f); /* exact in float */
    murk_metrics m;
    float pix[2];
    murk_metrics_compute(a, r, NULL, 2, (murk_crop){0, 0, 2, 1}, &m, pix);
    double e = (double)a[0] - r[0], den = 0.25 + 0.01;
    assert_int_equal(m.n, 6);
    assert_int_equal(m.nonfinite, 0);
    assert_near(m.mse, e * e, 1e-12);
    assert_near(m.relmse, e * e / den, 1e-12);
    assert_near(m.relmse_raw, m.relmse, 1e-15);
    assert_near(m.ref_noise, 0.0, 1e-15);
    assert_near(m.mare, fabs(e) / 0.51, 1e-9);
    assert_near(m.diff[3], 0.0, 1e-9); /* +e and -e */
    assert_near(pix[0], e * e / den, 1e-6);
    /* a NaN is skipped and counted */
    a[4] = NAN;
    murk_metrics_compute(a, r, NULL, 2, (murk_crop){0, 0, 2, 1}, &m, NULL);
    assert_int_equal(m.n, 5);
    assert_int_equal(m.nonfinite, 1);
}

static const murk_param *find_param(const murk_param *ps, uint32_t n, const char *name)
{
    for (uint32_t i = 0; i < n; i++)
        if (!strcmp(ps[i].name, name))
            return &ps[i];
    return NULL;
}

static void schema_as_data(void **state)
{
    (void)state;
    char err[1024];
    murk_lab_plugin_info info;
    murk_lab_plugin *p = murk_lab_plugin_open("diffuse", &info, err, sizeof err);
    if (!p)
        fail_msg("%s", err);
    assert_string_equal(info.name, "diffuse");
    assert_int_equal(info.kind, MURK_KIND_MATERIAL);
    assert_int_equal(info.abi.major, MURK_ABI_MAJOR);
    const char *slash = strrchr(info.path, '/');
    assert_non_null(slash);
    assert_string_equal(slash, "/diffuse.so");
    assert_non_null(info.description);
    const murk_param *albedo = find_param(info.params, info.nparams, "albedo");
    assert_non_null(albedo);
    assert_int_equal(albedo->type, MURK_PARAM_RGB);
    assert_non_null(albedo->doc);
    murk_lab_plugin_close(p);

    p = murk_lab_plugin_open("delta", &info, err, sizeof err);
    if (!p)
        fail_msg("%s", err);
    assert_int_equal(info.kind, MURK_KIND_MEDIUM);
    murk_lab_plugin_close(p);
    uint32_t n = 0;
    const murk_param *keys = murk_lab_medium_params(&n);
    assert_true(n > 0);
    assert_non_null(find_param(keys, n, "sigma_a"));
    assert_non_null(find_param(keys, n, "majorant_factor"));

    err[0] = 0;
    assert_null(murk_lab_plugin_open("no_such_plugin", &info, err, sizeof err));
    if (!strstr(err, "no_such_plugin"))
        fail_msg("the message does not name the plugin: %s", err);
    murk_lab_plugin_close(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(metrics_closed_form),
        cmocka_unit_test(schema_as_data),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
