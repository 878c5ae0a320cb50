/* test_equiangular.c — volpath_nee's equiangular distance sampling (`integrator.equiangular`,
 * plugins/integrators/pathtracer.c) renders the image of the tracker's free flights alone.
 *
 * Equiangular sampling adds a second estimator of the light scattered along every medium segment and
 * splits each scattering vertex's NEE between the two by MIS weights that must sum to one: a weight
 * that is off (double counting, a wrong pdf, a segment range the weights and the sampling disagree on)
 * brightens or darkens the medium. So each scene renders with equiangular on and off, several seeds
 * each (independent: seeds 10.. and 1000..), and the two must agree block by block (img_stack_agree: no
 * 4 x 4 block beyond STAT_Z sigma, the mean z over the blocks within STAT_Z / sqrt(blocks)); each
 * comparison's must-fail case is the same with one block brighter by 10 of its standard errors (the
 * comparison's resolution, printed in percent). The comparisons are image
 * level: they are the suite 'long' (long_* tests);
 *   box     test_boundaries' box scene: a constant chromatic medium box (delta tracker) right under a
 *           large ceiling lamp, the camera outside (segments that start at the box's faces);
 *   fog     a small spherical lamp inside a thin fog filling the room (decomposition), the lamp's own
 *           sphere ending segments close to the reference point;
 *   cloud   cornell_smoke's heterogeneous cloud with chromatic extinction (spectral_mis): the
 *           exponential stand-in for the free-flight pdf is only an approximation there, and the
 *           majorant grid bounds the equiangular range;
 * and the other switch of this kind, spectral_mis's `closed_form` flights, on the box scene and the lamp
 * in fog (constant media: closed form all the way), against the tracked flights. The default run keeps
 * the bitwise determinism with it on: 1 and 2 threads, one pass and --time's passes. */
#include "testutil.h"
#include "stat.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const ROOM = "camera: { from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40 }\n"
                                "materials:\n"
                                "  white: { type: diffuse, albedo: [0.73, 0.73, 0.73] }\n"
                                "  red: { type: diffuse, albedo: [0.63, 0.065, 0.05] }\n"
                                "  green: { type: diffuse, albedo: [0.14, 0.45, 0.091] }\n"
                                "shapes:\n"
                                "  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: white }\n"
                                "  - { type: quad, center: [0, 2, 0], u: [1, 0, 0], v: [0, 0, 1], material: white }\n"
                                "  - { type: quad, center: [0, 1, -1], u: [1, 0, 0], v: [0, 1, 0], material: white }\n"
                                "  - { type: quad, center: [-1, 1, 0], u: [0, 0, 1], v: [0, 1, 0], material: red }\n"
                                "  - { type: quad, center: [1, 1, 0], u: [0, 1, 0], v: [0, 0, 1], material: green }\n";

/* ROOM plus `rest` (more shapes, then media) under a header with the integrator. */
static const char *scene(const char *name, const char *header, const char *rest)
{
    size_t n = strlen(header) + strlen(ROOM) + strlen(rest) + 1;
    char *text = malloc(n);
    assert_non_null(text);
    snprintf(text, n, "%s%s%s", header, ROOM, rest);
    const char *path = write_tmp(name, text);
    free(text);
    return path;
}

static const char *const OFF[] = {"--set", "integrator.equiangular=false", NULL};
static const char *const ON[] = {"--set", "integrator.equiangular=true", NULL};

static void agree_with(const char *label, const char *path, int nseeds, const char *const *on,
                       const char *const *off)
{
    img_stack a, b;
    char out[64];
    snprintf(out, sizeof out, "%s_on.exr", label);
    img_stack_render(&a, path, out, nseeds, 10, on);
    snprintf(out, sizeof out, "%s_off.exr", label);
    img_stack_render(&b, path, out, nseeds, 1000, off);
    int ok = img_stack_agree(label, &a, &b, 4);
    ok &= img_stack_must_differ_block(label, &a, &b, 4, 0.0);
    img_stack_free(&a);
    img_stack_free(&b);
    assert_true(ok);
}

static void agree(const char *label, const char *path, int nseeds) { agree_with(label, path, nseeds, ON, OFF); }

static const char *box_scene(void)
{
    return scene("box.yaml",
                             "murk: 1\n"
                             "render: { resolution: [32, 32], spp: 256, seed: 0 }\n"
                             "integrator: { type: volpath_nee, max_depth: 1000 }\n",
                             "  - { type: quad, center: [0, 1.99, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, "
                             "emission: [3, 3, 3] }\n"
                             "  - { type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], interior: smoke }\n"
                             "media:\n"
                             "  smoke: { type: delta, density: { constant: 1 }, sigma_a: [0.05, 0.1, 0.2], "
                             "sigma_s: [0.5, 0.5, 0.5] }\n");
}

static void long_box(void **state)
{
    (void)state;
    agree("box", box_scene(), 8);
}

static const char *fog_scene(void)
{
    return scene("fog.yaml",
                             "murk: 1\n"
                             "render: { resolution: [32, 32], spp: 256, seed: 0 }\n"
                             "integrator: { type: volpath_nee, max_depth: 64 }\n",
                             "  - { type: box, min: [-0.99, 0.01, -0.99], max: [0.99, 1.99, 0.99], interior: fog }\n"
                             "  - { type: sphere, center: [0.2, 1.1, -0.2], radius: 0.1, material: white, "
                             "emission: [25, 20, 15], exterior: fog }\n"
                             "media:\n"
                             "  fog: { type: decomposition, density: { constant: 1 }, sigma_a: 0.02, "
                             "sigma_s: [0.3, 0.25, 0.2], g: 0.3 }\n");
}

static void long_fog(void **state)
{
    (void)state;
    agree("fog", fog_scene(), 8);
}

static void long_closed_form(void **state)
{
    (void)state;
    static const char *const box_on[] = {"--set", "media.smoke.type=spectral_mis", "--set",
                                         "media.smoke.closed_form=true", NULL};
    static const char *const box_off[] = {"--set", "media.smoke.type=spectral_mis", NULL};
    static const char *const fog_on[] = {"--set", "media.fog.type=spectral_mis", "--set",
                                         "media.fog.closed_form=true", NULL};
    static const char *const fog_off[] = {"--set", "media.fog.type=spectral_mis", NULL};
    agree_with("box closed_form", box_scene(), 8, box_on, box_off);
    agree_with("fog closed_form", fog_scene(), 8, fog_on, fog_off);
}

static void long_cloud(void **state)
{
    (void)state;
    const char *path = scene("cloud.yaml",
                             "murk: 1\n"
                             "render: { resolution: [32, 32], spp: 128, seed: 0 }\n"
                             "integrator: { type: volpath_nee, max_depth: 64 }\n",
                             "  - { type: quad, center: [0, 1.998, 0], u: [0.235, 0, 0], v: [0, 0, 0.19], "
                             "material: white, emission: [17, 12, 4] }\n"
                             "  - { type: box, min: [-0.6, 0.05, -0.6], max: [0.6, 1.45, 0.6], interior: smoke }\n"
                             "media:\n"
                             "  smoke: { type: spectral_mis, sigma_a: [0.2, 0.4, 0.8], sigma_s: [6, 4, 2], g: 0.2,\n"
                             "           density: { cloud: { min: [-0.6, 0.05, -0.6], max: [0.6, 1.45, 0.6], seed: 7, "
                             "frequency: 2.5, octaves: 5, coverage: 0.7, resolution: 32 } } }\n");
    agree("cloud", path, 6);
}

static void test_bitwise(void **state)
{
    (void)state;
    const char *path = scene("bits.yaml",
                             "murk: 1\n"
                             "render: { resolution: [24, 24], spp: 6, seed: 3 }\n"
                             "integrator: { type: volpath_nee, max_depth: 64, equiangular: true }\n",
                             "  - { type: quad, center: [0, 1.998, 0], u: [0.235, 0, 0], v: [0, 0, 0.19], "
                             "material: white, emission: [17, 12, 4] }\n"
                             "  - { type: box, min: [-0.6, 0.05, -0.6], max: [0.6, 1.45, 0.6], interior: smoke }\n"
                             "media:\n"
                             "  smoke: { type: delta, sigma_a: 0.5, sigma_s: [6, 4, 2], density: { cloud: { min: "
                             "[-0.6, 0.05, -0.6], max: [0.6, 1.45, 0.6], seed: 7, resolution: 16 } } }\n");
    const char *variants[][8] = {{"--threads", "1", NULL},
                                 {"--threads", "2", NULL},
                                 {"--threads", "2", "--time", "600", NULL}};
    char ref[256] = "";
    for (int v = 0; v < 3; v++) {
        char out[256];
        snprintf(out, sizeof out, "%s/bits%d.exr", tmp_dir(), v);
        const char *args[16] = {"render", path, "-o", out, "--quiet"};
        int n = 5;
        for (int k = 0; variants[v][k]; k++)
            args[n++] = variants[v][k];
        char *log = NULL;
        int rc = run_murk_argv(&log, args);
        if (rc != 0)
            fail_msg("murk render failed (%d): %s", rc, log ? log : "");
        free(log);
        if (v == 0)
            snprintf(ref, sizeof ref, "%s", out);
        else
            assert_same_pixels(ref, out);
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bitwise), cmocka_unit_test(long_box),         cmocka_unit_test(long_fog),
        cmocka_unit_test(long_cloud),   cmocka_unit_test(long_closed_form),
    };
    return STAT_RUN(tests, argc, argv);
}
