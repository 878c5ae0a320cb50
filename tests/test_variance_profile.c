/* test_variance_profile.c — the path tracer's tap (MURK_PT_TAP in plugins/integrators/pathtracer.c),
 * which bench/variance_profile builds its variance profile on:
 *   sum       every contribution to a sample goes through the tap: on the Cornell box holding a constant
 *             chromatic medium (bench/equal_error.py's `medium`) with volpath_nee and equiangular
 *             sampling on, the terms the tap reports for each of a few hundred paths sum to the sample
 *             (to float rounding), each path reports at most one end, and surface, medium and
 *             equiangular NEE, phase-found emission and the camera-ray emission all occur;
 *   plugins   the plugins are built without it: no plugin file names the tap's functions (a plugin
 *             compiled with -DMURK_PT_TAP would import them), and the volpath_nee plugin's li() returns
 *             bitwise the samples this program's tapped copy returns for the same numbers (so the tap
 *             changes nothing, and the plugin is this same code).
 * This file compiles pathtracer.c itself, with the tap. */
#define MURK_PT_TAP
#include "pathtracer.c"

#include "testutil.h"

#include "render/camera.h"
#include "render/host.h"
#include "scene/scene.h"

#include <stdio.h>
#include <stdlib.h>

static double tap_sum[3], tap_abs;
static int tap_terms[MURK_PT_NTERMS], tap_ends;

void murk_pt_tap(int depth, int term, murk_rgb value)
{
    assert_true(term >= 0 && term < MURK_PT_NTERMS);
    assert_true(depth >= 0);
    for (int c = 0; c < 3; c++) {
        tap_sum[c] += value.c[c];
        tap_abs += fabs(value.c[c]);
    }
    tap_terms[term]++;
}

void murk_pt_tap_end(int depth, int why)
{
    assert_true(depth >= 0 && why >= 0 && why < MURK_PT_NENDS);
    tap_ends++;
}

/* The medium scene, 16 x 16, with equiangular sampling. */
static murk_scene *medium_scene(void)
{
    static const char *const sets[] = {"media.smoke.type=decomposition",     "media.smoke.density={constant: 1}",
                                       "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "media.smoke.sigma_s=[1.2, 0.8, 0.4]",
                                       "media.smoke.g=0.2",                  "integrator.equiangular=true",
                                       "render.resolution=[16, 16]"};
    char err[1024];
    murk_scene *s = murk_scene_load(src_path("scenes/cornell_smoke.yaml"), sets, sizeof sets / sizeof sets[0], err,
                                    sizeof err);
    if (!s)
        fail_msg("%s", err);
    assert_string_equal(s->integrator_plugin->desc->name, "volpath_nee");
    return s;
}

static void test_sum(void **state)
{
    (void)state;
    murk_scene *s = medium_scene();
    murk_pt pt = *(const murk_pt *)s->integrator;
    assert_true(pt.equiangular && pt.nee && pt.media);
    int total[MURK_PT_NTERMS] = {0}, paths = 0, ended = 0;
    double worst = 0.0;
    for (int y = 0; y < s->height; y++)
        for (int x = 0; x < s->width; x++)
            for (int k = 0; k < 2; k++) { /* 256 pixels x 2 samples = 512 paths */
                murk_rng rng;
                murk_ray r;
                murk_camera_sample(s, x, y, (uint32_t)k, &rng, &r);
                memset(tap_sum, 0, sizeof tap_sum);
                memset(tap_terms, 0, sizeof tap_terms);
                tap_abs = 0.0;
                tap_ends = 0;
                murk_rgb L = murk_pt_li(&pt, s, &r, &rng);
                assert_true(murk_rgb_finite(L));
                assert_true(tap_ends <= 1);
                ended += tap_ends;
                for (int c = 0; c < 3; c++) {
                    /* L is a float sum of the same terms in the same order: the difference is rounding,
                     * a few float ulps of the terms' magnitude per term */
                    double d = fabs(tap_sum[c] - (double)L.c[c]), tol = 1e-6 * tap_abs + 1e-30;
                    if (d > tol)
                        fail_msg("pixel (%d, %d) sample %d channel %d: the tap's terms sum to %.9g, the sample is "
                                 "%.9g",
                                 x, y, k, c, tap_sum[c], (double)L.c[c]);
                    worst = fmax(worst, d / (tap_abs + 1e-30));
                }
                for (int t = 0; t < MURK_PT_NTERMS; t++)
                    total[t] += tap_terms[t];
                paths++;
            }
    printf("  %d paths, %d ended by a tapped end, largest |sum - sample| / sum |terms| %.1e; terms:", paths, ended,
           worst);
    for (int t = 0; t < MURK_PT_NTERMS; t++)
        printf(" %d", total[t]);
    printf("\n");
    assert_true(total[MURK_PT_TERM_SURFACE_NEE] > 0);
    assert_true(total[MURK_PT_TERM_MEDIUM_NEE] > 0);
    assert_true(total[MURK_PT_TERM_EQUIANGULAR_NEE] > 0);
    assert_true(total[MURK_PT_TERM_PHASE_EMISSION] > 0);
    assert_true(total[MURK_PT_TERM_CAMERA_EMISSION] > 0);
    assert_true(ended > paths / 2);
    murk_scene_free(s);
}

/* 1 if the file contains the bytes `needle` (-1 if it cannot be read). */
static int file_contains(const char *path, const char *needle)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t n = strlen(needle), have = 0, cap = 1 << 16;
    char *buf = malloc(cap + n);
    int found = 0;
    for (;;) {
        size_t got = fread(buf + have, 1, cap, f);
        if (!got)
            break;
        have += got;
        for (size_t i = 0; i + n <= have && !found; i++)
            found = !memcmp(buf + i, needle, n);
        if (found)
            break;
        /* keep the last n - 1 bytes: a name split across two reads */
        size_t keep = have < n - 1 ? have : n - 1;
        memmove(buf, buf + have - keep, keep);
        have = keep;
    }
    free(buf);
    fclose(f);
    return found;
}

static void test_plugins(void **state)
{
    (void)state;
    static const char *const plugins[] = {"plugins/path.so", "plugins/volpath.so", "plugins/volpath_nee.so"};
    for (size_t i = 0; i < sizeof plugins / sizeof plugins[0]; i++) {
        int found = file_contains(build_path(plugins[i]), "murk_pt_tap");
        if (found < 0)
            fail_msg("cannot read %s", build_path(plugins[i]));
        if (found)
            fail_msg("%s names murk_pt_tap: a plugin was built with MURK_PT_TAP", build_path(plugins[i]));
    }
    murk_scene *s = medium_scene();
    murk_pt pt = *(const murk_pt *)s->integrator;
    int differ = 0, n = 0;
    for (int y = 0; y < s->height; y += 3)
        for (int x = 0; x < s->width; x += 3)
            for (int k = 0; k < 4; k++, n++) {
                murk_rng a, b;
                murk_ray ra, rb;
                murk_camera_sample(s, x, y, (uint32_t)k, &a, &ra);
                murk_camera_sample(s, x, y, (uint32_t)k, &b, &rb);
                murk_rgb La = s->integrator_vt->li(s->integrator, s, &ra, &a); /* the plugin */
                murk_rgb Lb = murk_pt_li(&pt, s, &rb, &b);                   /* this program's, tapped */
                differ += memcmp(La.c, Lb.c, sizeof La.c) != 0;
            }
    printf("  %d paths: the plugin and the tapped copy differ in %d\n", n, differ);
    assert_int_equal(differ, 0);
    murk_scene_free(s);
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sum),
        cmocka_unit_test(test_plugins),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
