/* test_roulette_long.c — Russian roulette's rule leaves the expected image alone (suite long): the path
 * tracer's default integrator.rr_threshold (0.3: play only with paths whose weight fell below 0.3) against
 * 1 (every path below 1, murk's rule before) and against 0.1 (Tungsten's rule), on the Cornell box (path),
 * cornell_smoke's cloud (volpath_nee, delta tracking) and a constant chromatic medium in the same box,
 * independent seeds, block-wise z (img_stack_agree: 4x4 blocks, its bounds from stat.h). Roulette divides a survivor by its survival probability, so every rule estimates the
 * same image whatever the threshold; a rule that forgot the division, or divided by the wrong probability,
 * would not. Must fail, on each scene: the default with the lamp 1 % brighter against threshold 1.
 * The same scenes and stacks check the default render.traversal (Embree's fast traversal) against
 * `robust` (RTC_SCENE_FLAG_ROBUST): the two differ only where a ray meets an edge to within rounding, so
 * they must estimate the same image; the must-fail is the brighter lamp against robust. */
#include "testutil.h"

#include <stdio.h>

enum { SEEDS = 6, BLOCK = 4 };

typedef struct scene_case {
    const char *label, *file;
    const char *extra[16]; /* --set overrides of the scene, NULL-terminated */
} scene_case;

static const scene_case cases[] = {
    {"cornell", "cornell.yaml", {NULL}},
    {"cornell_smoke", "cornell_smoke.yaml", {NULL}},
    {"constant chromatic medium", "cornell_smoke.yaml",
     {"--set", "media.smoke.type=delta", "--set", "media.smoke.density={constant: 1}", "--set",
      "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "--set", "media.smoke.sigma_s=[1.2, 0.8, 0.4]", "--set",
      "media.smoke.g=0.2", NULL}},
};

/* scene's overrides, a small image, then the case's own --set items */
static void args_for(const scene_case *c, const char *rr, int brighter, const char **out)
{
    int n = 0;
    for (int i = 0; c->extra[i]; i++)
        out[n++] = c->extra[i];
    static const char *const common[] = {"--set", "render.resolution=[40, 40]", "--spp", "128"};
    for (int i = 0; i < 4; i++)
        out[n++] = common[i];
    if (rr) { /* NULL: the default */
        out[n++] = "--set";
        out[n++] = rr;
    }
    if (brighter) {
        out[n++] = "--set";
        out[n++] = "shapes.5.emission=[17.17, 12.12, 4.04]"; /* the lamp of both scenes, 1.01 x */
    }
    out[n] = NULL;
}

static void test_threshold_keeps_image(void **state)
{
    (void)state;
    int nfail = 0, nmissed = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const scene_case *c = &cases[i];
        char scene[512], label[160];
        snprintf(scene, sizeof scene, "scenes/%s", c->file);
        const char *deflt[32], *rule1[32], *rule01[32], *bright[32], *robust[32]; /* bright: the lamp 1.01 x */
        args_for(c, NULL, 0, deflt);
        args_for(c, "render.traversal=robust", 0, robust);
        args_for(c, "integrator.rr_threshold=1", 0, rule1);
        args_for(c, "integrator.rr_threshold=0.1", 0, rule01);
        args_for(c, NULL, 1, bright);
        img_stack a, b, t, m, r;
        img_stack_render(&a, src_path(scene), "rr_default.exr", SEEDS, 100, deflt);
        img_stack_render(&b, src_path(scene), "rr1.exr", SEEDS, 200, rule1);
        img_stack_render(&t, src_path(scene), "rr01.exr", SEEDS, 400, rule01);
        img_stack_render(&m, src_path(scene), "rr_bright.exr", SEEDS, 300, bright);
        img_stack_render(&r, src_path(scene), "robust.exr", SEEDS, 500, robust);
        snprintf(label, sizeof label, "%s: rr_threshold default (0.3) against 1", c->label);
        nfail += !img_stack_agree(label, &a, &b, BLOCK);
        snprintf(label, sizeof label, "%s: rr_threshold 0.1 against 1", c->label);
        nfail += !img_stack_agree(label, &t, &b, BLOCK);
        snprintf(label, sizeof label, "%s: rr_threshold default with the lamp 1.01 x against 1 (must fail)", c->label);
        nmissed += img_stack_agree(label, &m, &b, BLOCK);
        snprintf(label, sizeof label, "%s: render.traversal default (fast) against robust", c->label);
        nfail += !img_stack_agree(label, &a, &r, BLOCK);
        snprintf(label, sizeof label, "%s: the lamp 1.01 x against robust (must fail)", c->label);
        nmissed += img_stack_agree(label, &m, &r, BLOCK);
        img_stack_free(&r);
        img_stack_free(&t);
        img_stack_free(&a);
        img_stack_free(&b);
        img_stack_free(&m);
    }
    assert_int_equal(nfail, 0);
    assert_int_equal(nmissed, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threshold_keeps_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
