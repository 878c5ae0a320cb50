/* test_texture.c — textures end to end: a diffuse quad under a uniform unit sky with one bounce has
 * radiance equal to its albedo with zero variance (cosine sampling weights are exactly the albedo),
 * so the rendered pixels show the texels themselves: checker parity and PNG texels at known (u,v).
 * Also: in-process parsing errors, and a rendered GGX furnace that must not exceed 1 beyond noise. */
#include "testutil.h"
#include "stat.h"
#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 64, H = 64 };

/* The quad [-1,1]^2 at z = 0 fills the view exactly: pixel (x, y) sees u = (x+.5)/W, v = 1-(y+.5)/H. */
static const char *quad_scene(const char *name, const char *albedo)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\n"
             "render: { resolution: [%d, %d], spp: 4, seed: 1 }\n"
             "camera: { from: [0, 0, 2], at: [0, 0, 0], up: [0, 1, 0], fov: 53.13010235415598 }\n"
             "integrator: { type: path, max_depth: 1 }\n"
             "background: 1\n"
             "materials: { tex: { type: diffuse, albedo: %s } }\n"
             "shapes: [ { type: quad, center: [0, 0, 0], u: [1, 0, 0], v: [0, 1, 0], material: tex } ]\n",
             W, H, albedo);
    return write_tmp(name, text);
}

static void render_to(const char *scene, const char *exr, murk_image *img)
{
    char *log = NULL;
    int rc = run_murk(&log, "render", scene, "-o", exr, "--quiet", (char *)NULL);
    if (rc)
        fprintf(stderr, "%s\n", log);
    assert_int_equal(rc, 0);
    free(log);
    char err[512];
    assert_int_equal(murk_exr_read(exr, img, err, sizeof err), 0);
    assert_int_equal(img->w, W);
}

static void test_checker_parity(void **state)
{
    (void)state;
    /* scale 4: squares of 1/4 in uv = 16 pixels; sample at square centres */
    const char *scene = quad_scene("checker.yaml", "{ texture: checker, even: [0.9, 0.5, 0.1], odd: [0.1, 0.2, 0.3], scale: 4 }");
    char exr[512];
    snprintf(exr, sizeof exr, "%s/checker.exr", tmp_dir());
    murk_image img = {0};
    render_to(scene, exr, &img);
    int checked = 0;
    for (int y = 8; y < H; y += 16)
        for (int x = 8; x < W; x += 16) {
            double u = (x + 0.5) / W, v = 1.0 - (y + 0.5) / H;
            int parity = ((int)floor(u * 4) + (int)floor(v * 4)) & 1;
            const float *px = &img.rgb[3 * (y * W + x)];
            float e[3] = {0.9f, 0.5f, 0.1f}, o[3] = {0.1f, 0.2f, 0.3f};
            for (int c = 0; c < 3; c++)
                assert_float_equal(px[c], parity ? o[c] : e[c], 1e-5);
            checked++;
        }
    assert_int_equal(checked, 16);
    murk_image_free(&img);
}

static void test_png_texels(void **state)
{
    (void)state;
    /* an 8x8 PNG made of 4x4 blocks of 2x2 equal texels: bilinear filtering is exact at block centres */
    float lin[8 * 8 * 3];
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++)
            for (int c = 0; c < 3; c++)
                lin[3 * (y * 8 + x) + c] = (float)(((x / 2) * 5 + (y / 2) * 3 + c * 7) % 11) / 10.0f;
    char png[512], err[512];
    snprintf(png, sizeof png, "%s/tex.png", tmp_dir());
    assert_int_equal(murk_png_write(png, lin, 8, 8, 0.0f, err, sizeof err), 0);
    murk_image tex = {0};
    assert_int_equal(murk_png_read(png, 1, &tex, err, sizeof err), 0); /* the texels as murk decodes them */
    char albedo[600];
    snprintf(albedo, sizeof albedo, "{ texture: image, file: %s }", png);
    const char *scene = quad_scene("png.yaml", albedo);
    char exr[512];
    snprintf(exr, sizeof exr, "%s/png.exr", tmp_dir());
    murk_image img = {0};
    render_to(scene, exr, &img);
    /* block (bx, by) covers texels 2bx..2bx+1, rows 2by..2by+1 = pixels 16bx..16bx+15 (row 0 at the top) */
    for (int by = 0; by < 4; by++)
        for (int bx = 0; bx < 4; bx++) {
            const float *px = &img.rgb[3 * ((16 * by + 8) * W + 16 * bx + 8)];
            const float *tx = &tex.rgb[3 * ((2 * by) * 8 + 2 * bx)];
            for (int c = 0; c < 3; c++)
                assert_float_equal(px[c], tx[c], 1e-5);
        }
    murk_image_free(&img);
    murk_image_free(&tex);
}

static void test_texture_errors(void **state)
{
    (void)state;
    struct { const char *albedo, *expect; } cases[] = {
        {"{ texture: checkr }", "unknown texture 'checkr'"},
        {"{ texture: checker, even: 2 }", "must be in [0, 1]"},
        {"{ texture: checker, sclae: 2 }", "did you mean 'scale'"},
        {"{ texture: image, file: nope.png }", "nope.png"},
        {"{ even: 1 }", "texture: checker"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *scene = quad_scene("bad_texture.yaml", cases[i].albedo);
        char *log = NULL, exr[512];
        snprintf(exr, sizeof exr, "%s/bad.exr", tmp_dir());
        int rc = run_murk(&log, "render", scene, "-o", exr, "--quiet", (char *)NULL);
        if (rc != 1 || !strstr(log, cases[i].expect) || !strstr(log, "bad_texture.yaml:6:"))
            fprintf(stderr, "case %zu: rc %d, log: %s\n", i, rc, log);
        assert_int_equal(rc, 1);
        assert_non_null(strstr(log, cases[i].expect));
        assert_non_null(strstr(log, "bad_texture.yaml:6:"));
        free(log);
    }
}

/* A GGX sphere under a uniform unit sky reflects at most 1 (energy conservation): the image mean must
 * not exceed 1 by more than 4 standard errors, for the materials most likely to gain energy. */
static void test_ggx_render_furnace(void **state)
{
    (void)state;
    const char *params[] = {"albedo: 1, specular: 1, roughness: 0.05", "albedo: 1, specular: 1, roughness: 0.5",
                            "albedo: 1, specular: 1, roughness: 1", "albedo: 1, specular: 0.04, roughness: 0.3",
                            "albedo: 0, specular: 1, roughness: 0"};
    for (size_t i = 0; i < sizeof params / sizeof params[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "murk: 1\n"
                 "render: { resolution: [24, 24], spp: 64, seed: 5 }\n"
                 "camera: { from: [0, 0, 3.2], at: [0, 0, 0], up: [0, 1, 0], fov: 36 }\n"
                 "integrator: { type: path, max_depth: 64 }\n"
                 "background: 1\n"
                 "materials: { m: { type: ggx, %s } }\n"
                 "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: m } ]\n",
                 params[i]);
        const char *scene = write_tmp("ggx_furnace.yaml", text);
        char exr[512];
        snprintf(exr, sizeof exr, "%s/ggx_furnace.exr", tmp_dir());
        murk_image img = {0};
        char *log = NULL, err[512];
        assert_int_equal(run_murk(&log, "render", scene, "-o", exr, "--quiet", (char *)NULL), 0);
        free(log);
        assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
        /* only pixels that see the sphere: |ndc| small enough (the sphere fills the centre) */
        double s = 0, s2 = 0;
        int n = 0;
        for (int y = 0; y < img.h; y++)
            for (int x = 0; x < img.w; x++) {
                double dx = (x + 0.5) / img.w - 0.5, dy = (y + 0.5) / img.h - 0.5;
                if (dx * dx + dy * dy > 0.3 * 0.3)
                    continue;
                for (int c = 0; c < 3; c++) {
                    double v = img.rgb[3 * (y * img.w + x) + c];
                    assert_true(isfinite(v));
                    s += v;
                    s2 += v * v;
                    n++;
                }
            }
        double mean = s / n, se = sqrt(fmax(0.0, s2 / n - mean * mean) / n);
        printf("ggx furnace (%s): mean %.5f +- %.5f\n", params[i], mean, se);
        stat_count(1, stat_tail2(STAT_Z) / 2.0); /* one-sided */
        assert_true(mean <= 1.0 + STAT_Z * se + 1e-6);
        assert_true(mean > 0.25);
        murk_image_free(&img);
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checker_parity),
        cmocka_unit_test(test_png_texels),
        cmocka_unit_test(test_texture_errors),
        cmocka_unit_test(test_ggx_render_furnace),
    };
    return STAT_RUN(tests, argc, argv);
}
