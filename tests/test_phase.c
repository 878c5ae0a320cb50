/* test_phase.c — phase functions as plugins (murk/phase.h):
 *   - murk check passes hg, isotropic, draine, hg_draine and rayleigh: chi-square of sampled directions
 *     against eval(), normalisation by quadrature, reciprocity, and the mean cosine against its closed
 *     form (HG: g; Draine: g (1 + a (3 + 2 g^2) / 5) / (1 + a (1 + 2 g^2) / 3)) by quadrature and by
 *     sampling, for three parameter sets each;
 *   - each check fails on the mutant made for it (tests/fixtures/phase_mutant.h): a sampler off by
 *     0.03 in g (chi2), 1 % too much (norm), an asymmetric eval (reciprocity), a wrong closed form (mean
 *     cos);
 *   - `phase: { type: hg, g: G }` renders the same bits as the medium's `g: G`;
 *   - scene errors: g beside a phase block, a phase parameter out of range, an unknown phase function,
 *     a tracker name given as a phase function: located, and no image written. */
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void test_builtin_phases_pass(void **state)
{
    (void)state;
    char *out;
    int rc = run_murk(&out, "check", "--quick", "hg", "isotropic", "draine", "hg_draine", "rayleigh", NULL);
    printf("%s", out);
    static const char *const names[] = {"hg", "isotropic", "draine", "hg_draine", "rayleigh"};
    for (int i = 0; i < 5; i++) {
        char want[64];
        snprintf(want, sizeof want, "%s: all checks passed", names[i]);
        assert_contains(out, want);
    }
    assert_contains(out, "PASS mean cos");
    assert_int_equal(rc, 0);
    free(out);
}

static void test_mutants_fail(void **state)
{
    (void)state;
    static const char *const cases[][2] = {{"bad_phase_sampling", "FAIL chi2"},
                                           {"bad_phase_norm", "FAIL norm"},
                                           {"bad_phase_reciprocity", "FAIL reciprocity"},
                                           {"bad_phase_mean", "FAIL mean cos"}};
    for (int i = 0; i < 4; i++) {
        char so[128], *out;
        snprintf(so, sizeof so, "tests/fixtures/%s.so", cases[i][0]);
        int rc = run_murk(&out, "check", "--quick", build_path(so), NULL);
        printf("%s: exit %d, %s\n", cases[i][0], rc, strstr(out, cases[i][1]) ? cases[i][1] : "(not seen)");
        assert_int_equal(rc, 1);
        assert_contains(out, cases[i][1]);
        free(out);
    }
    /* the flaw a mutant has is the one its check finds: the mean-cosine mutant passes chi2 and norm */
    char *out;
    run_murk(&out, "check", "--quick", build_path("tests/fixtures/bad_phase_mean.so"), NULL);
    assert_not_contains(out, "FAIL chi2");
    assert_not_contains(out, "FAIL norm");
    free(out);
}

static const char *scene_text(const char *phase_keys)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [24, 24], spp: 8, seed: 5 }\n"
             "camera: { from: [0, 0, 3], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
             "integrator: { type: volpath_nee }\nbackground: [0.2, 0.3, 0.4]\n"
             "materials: { black: { type: diffuse, albedo: 0 } }\n"
             "media: { fog: { type: delta, density: { constant: 1 }, sigma_a: 0.2, sigma_s: [1.5, 1, 0.5], %s } }\n"
             "shapes:\n"
             "  - { type: quad, center: [0, 1.2, 0], u: [0.3, 0, 0], v: [0, 0, -0.3], material: black, emission: [4, 4, 4] }\n"
             "  - { type: box, min: [-0.8, -0.8, -0.8], max: [0.8, 0.8, 0.8], interior: fog }\n",
             phase_keys);
    return text;
}

static void test_hg_plugin_is_g(void **state)
{
    (void)state;
    const char *a = write_tmp("g.yaml", scene_text("g: 0.55")), *b = write_tmp("hg.yaml", scene_text("phase: { type: hg, g: 0.55 }"));
    char oa[512], ob[512];
    snprintf(oa, sizeof oa, "%s", tmp_path("g.exr"));
    snprintf(ob, sizeof ob, "%s", tmp_path("hg.exr"));
    run_murk_ok((const char *const[]){"render", a, "-o", oa, "--quiet", "--threads", "2", NULL}, NULL);
    run_murk_ok((const char *const[]){"render", b, "-o", ob, "--quiet", "--threads", "2", NULL}, NULL);
    assert_same_pixels(oa, ob);
    /* and another phase function does change the image */
    const char *c = write_tmp("iso.yaml", scene_text("phase: isotropic"));
    char oc[512];
    snprintf(oc, sizeof oc, "%s", tmp_path("iso.exr"));
    run_murk_ok((const char *const[]){"render", c, "-o", oc, "--quiet", "--threads", "2", NULL}, NULL);
    assert_false(same_pixels(oa, oc));
}

static void expect_error(const char *name, const char *keys, const char *where, const char *what)
{
    const char *path = write_tmp(name, scene_text(keys));
    char out_exr[512], *out;
    snprintf(out_exr, sizeof out_exr, "%s.exr", path);
    unlink(out_exr);
    int rc = run_murk(&out, "render", path, "-o", out_exr, "--quiet", NULL);
    printf("%s -> %s", keys, out);
    assert_int_not_equal(rc, 0);
    char loc[640];
    snprintf(loc, sizeof loc, "%s:%s", path, where);
    assert_contains(out, loc);
    assert_contains(out, what);
    assert_int_not_equal(access(out_exr, F_OK), 0); /* nothing written */
    free(out);
}

static void test_phase_errors(void **state)
{
    (void)state;
    /* line 7 is the media line */
    expect_error("g_beside.yaml", "g: 0.3, phase: { type: draine, g: 0.5 }", "7:", "'g' beside a phase: block");
    expect_error("alpha.yaml", "phase: { type: draine, alpha: -2 }", "7:", "parameter 'alpha' must be in [0, 1000]");
    expect_error("gd.yaml", "phase: { type: draine, g: 1.5 }", "7:", "parameter 'g' must be in [-0.99, 0.99]");
    expect_error("diam.yaml", "phase: { type: hg_draine, diameter: 80 }", "7:", "parameter 'diameter' must be in");
    expect_error("unknown.yaml", "phase: { type: mie }", "7:", "no phase plugin 'mie'");
    expect_error("kind.yaml", "phase: delta", "7:", "'delta' is a medium plugin, not a phase");
    expect_error("typo.yaml", "phase: { type: hg, gg: 0.3 }", "7:", "did you mean 'g'?");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin_phases_pass),
        cmocka_unit_test(test_mutants_fail),
        cmocka_unit_test(test_hg_plugin_is_g),
        cmocka_unit_test(test_phase_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
