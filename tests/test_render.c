/* test_render.c — end-to-end renders through the murk command: white furnace, a closed emitting box
 * against its closed form, 1-vs-2-thread bitwise determinism, and the Cornell box (finite pixels, EXR
 * metadata read back through OpenEXRCore). */
#include "testutil.h"
#include "stat.h"
#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Renders scene to out with up to six extra arguments (NULL-terminated early). */
static void render_ok(const char *scene, const char *out, const char *x1, const char *x2, const char *x3,
                      const char *x4, const char *x5, const char *x6)
{
    char *log = NULL;
    int rc = run_murk(&log, "render", scene, "-o", out, "--quiet", x1, x2, x3, x4, x5, x6, (char *)NULL);
    if (rc != 0)
        fprintf(stderr, "murk render %s failed (%d):\n%s\n", scene, rc, log);
    assert_int_equal(rc, 0);
    free(log);
}

static void read_exr(const char *path, murk_image *img)
{
    char err[512];
    int rc = murk_exr_read(path, img, err, sizeof err);
    if (rc)
        fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
}

/* Mean over every pixel and channel, with the standard error from the spread of pixel values (all
 * pixels estimate the same value in these scenes, so the spread is the per-pixel estimator's). */
static void image_stats(const murk_image *img, double *mean, double *stderr_mean, double *maxdev, double expect)
{
    size_t n = 3 * (size_t)img->w * (size_t)img->h;
    double s = 0, s2 = 0, md = 0;
    for (size_t i = 0; i < n; i++) {
        double v = img->rgb[i];
        assert_true(isfinite(v));
        s += v;
        s2 += v * v;
        if (fabs(v - expect) > md)
            md = fabs(v - expect);
    }
    *mean = s / (double)n;
    double var = s2 / (double)n - *mean * *mean;
    *stderr_mean = sqrt(fmax(var, 0.0) / (double)n);
    *maxdev = md;
}

static const char *furnace_scene(const char *name, const char *integrator)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\n"
             "render: { resolution: [32, 32], spp: 16, seed: 7 }\n"
             "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }\n"
             "integrator: { type: %s, max_depth: 64 }\n"
             "background: [1, 1, 1]\n"
             "materials: { white: { type: diffuse, albedo: 1 } }\n"
             "shapes:\n"
             "  - { type: sphere, center: [0, 0, 0], radius: 1, material: white }\n",
             integrator);
    return write_tmp(name, text);
}

/* A convex albedo-1 object under a uniform unit sky reflects exactly 1 along every path, so the
 * estimator has zero variance: any deviation beyond float rounding is an error. */
static void test_white_furnace(void **state)
{
    (void)state;
    const char *scene = furnace_scene("furnace.yaml", "path");
    char out[512];
    snprintf(out, sizeof out, "%s/furnace.exr", tmp_dir());
    render_ok(scene, out, NULL, NULL, NULL, NULL, NULL, NULL);
    murk_image img = {0};
    read_exr(out, &img);
    double mean, se, maxdev;
    image_stats(&img, &mean, &se, &maxdev, 1.0);
    printf("furnace: mean %.7f, max |L-1| %.3g\n", mean, maxdev);
    assert_true(maxdev < 1e-4);
    murk_image_free(&img);
}

/* Inside a closed box whose walls all have albedo rho and emit Le inwards, the radiance is
 * Le (1 - rho^(D+1)) / (1 - rho) for paths of at most D bounces. rho = 0.5, Le = 1, D = 64: 2. */
static void test_closed_box(void **state)
{
    (void)state;
    const char *text =
        "murk: 1\n"
        "render: { resolution: [24, 24], spp: 64, seed: 3 }\n"
        "camera: { from: [0.2, 0.1, 0.3], at: [0, 0, -1], up: [0, 1, 0], fov: 90 }\n"
        "integrator: { type: path, max_depth: 64 }\n"
        "materials: { grey: { type: diffuse, albedo: 0.5 } }\n"
        "shapes:   # six inward-facing emitting walls of a 2x2x2 box\n"
        "  - { type: quad, center: [0, -1, 0], u: [1, 0, 0], v: [0, 0, -1], material: grey, emission: 1 }\n"
        "  - { type: quad, center: [0, 1, 0], u: [1, 0, 0], v: [0, 0, 1], material: grey, emission: 1 }\n"
        "  - { type: quad, center: [-1, 0, 0], u: [0, 1, 0], v: [0, 0, 1], material: grey, emission: 1 }\n"
        "  - { type: quad, center: [1, 0, 0], u: [0, 1, 0], v: [0, 0, -1], material: grey, emission: 1 }\n"
        "  - { type: quad, center: [0, 0, -1], u: [1, 0, 0], v: [0, 1, 0], material: grey, emission: 1 }\n"
        "  - { type: quad, center: [0, 0, 1], u: [0, 1, 0], v: [1, 0, 0], material: grey, emission: 1 }\n";
    const char *scene = write_tmp("closed.yaml", text);
    char out[512];
    snprintf(out, sizeof out, "%s/closed.exr", tmp_dir());
    render_ok(scene, out, NULL, NULL, NULL, NULL, NULL, NULL);
    murk_image img = {0};
    read_exr(out, &img);
    double mean, se, maxdev, expect = 2.0 * (1.0 - pow(0.5, 65));
    image_stats(&img, &mean, &se, &maxdev, expect);
    printf("closed box: mean %.5f +- %.5f (expected %.5f)\n", mean, se, expect);
    assert_true(se > 0.0 && se < 0.01);
    assert_true(stat_z_ok(mean, se, expect, 0.0));
    double zd = fabs(mean - 0.98 * expect) / se; /* must-fail: a box 2 % darker */
    assert_true(stat_must_fail("closed box against 2% darker", zd > STAT_Z, zd));
    murk_image_free(&img);
}

static void test_threads_bitwise(void **state)
{
    (void)state;
    char a[512], b[512];
    snprintf(a, sizeof a, "%s/t1.exr", tmp_dir());
    snprintf(b, sizeof b, "%s/t2.exr", tmp_dir());
    const char *scene = src_path("scenes/cornell.yaml");
    render_ok(scene, a, "--threads", "1", "--set", "render.resolution=[64,48]", "--spp", "4");
    render_ok(scene, b, "--threads", "2", "--set", "render.resolution=[64,48]", "--spp", "4");
    murk_image A = {0}, B = {0};
    read_exr(a, &A);
    read_exr(b, &B);
    assert_int_equal(A.w, B.w);
    assert_int_equal(A.h, B.h);
    assert_memory_equal(A.rgb, B.rgb, 3 * sizeof(float) * (size_t)A.w * (size_t)A.h);
    murk_image_free(&A);
    murk_image_free(&B);
}

static void test_cornell(void **state)
{
    (void)state;
    char out[512], png[512];
    snprintf(out, sizeof out, "%s/cornell.exr", tmp_dir());
    snprintf(png, sizeof png, "%s/cornell.png", tmp_dir());
    render_ok(src_path("scenes/cornell.yaml"), out, "--set", "render.resolution=[96,96]", "--spp", "8", NULL, NULL);
    murk_image img = {0};
    read_exr(out, &img);
    assert_int_equal(img.w, 96);
    assert_int_equal(img.h, 96);
    double mean, se, maxdev;
    image_stats(&img, &mean, &se, &maxdev, 0.0);
    assert_true(mean > 0.05 && mean < 5.0);
    assert_non_null(murk_image_meta(&img, "murk:scene"));
    assert_string_equal(murk_image_meta(&img, "murk:spp"), "8");
    assert_string_equal(murk_image_meta(&img, "murk:seed"), "0");
    assert_non_null(murk_image_meta(&img, "murk:render_time"));
    assert_non_null(murk_image_meta(&img, "murk:version"));
    murk_image_free(&img);
    murk_image p = {0};
    char err[512];
    assert_int_equal(murk_png_read(png, 1, &p, err, sizeof err), 0);
    assert_int_equal(p.w, 96);
    murk_image_free(&p);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_white_furnace),
        cmocka_unit_test(test_closed_box),
        cmocka_unit_test(test_threads_bitwise),
        cmocka_unit_test(test_cornell),
    };
    return STAT_RUN(tests, argc, argv);
}
