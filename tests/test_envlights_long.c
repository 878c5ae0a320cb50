/* test_envlights_long.c — image-level agreement under an environment (suite long): a diffuse and a GGX
 * sphere on a diffuse plane under a lat-long map (a gradient with one bright texel) and a 20-degree sun
 * (wide enough that BSDF sampling alone finds it often: with a 5-degree one the BSDF-only images have a
 * heavy tail at the GGX sphere's grazing edge, whose variance 8 seeds underestimate), rendered with volpath_nee (light sampling and BSDF sampling by MIS) and with volpath (BSDF sampling
 * alone), independent seeds, block-wise z (img_stack_agree: no 4x4 block beyond STAT_Z sigma, the mean z
 * within STAT_Z / sqrt(blocks)). Must fail: the same against the map scaled by 1.01 (a 1 % brighter
 * environment). */
#include "stat.h"
#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const char *write_map(void)
{
    enum { W = 64, H = 32 };
    static float rgb[3 * W * H];
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float *t = &rgb[3 * (j * W + i)];
            t[0] = 0.2f + 1.5f * (float)i / W;
            t[1] = 0.2f + (float)j / H;
            t[2] = 0.5f;
            if (i == 40 && j == 9)
                t[0] = t[1] = t[2] = 30.0f;
        }
    char err[256];
    const char *path = tmp_path("long_map.exr");
    if (murk_exr_write(path, rgb, W, H, NULL, 0, err, sizeof err))
        fail_msg("%s", err);
    return path;
}

static const char *scene_text(const char *map)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [32, 32], spp: 256 }\n"
             "camera: { from: [0, 1.2, 4], at: [0, 0.5, 0], up: [0, 1, 0], fov: 35 }\n"
             "integrator: { type: volpath_nee, max_depth: 8 }\n"
             "materials:\n  d: { type: diffuse, albedo: 0.7 }\n"
             "  g: { type: ggx, albedo: 0, specular: 0.9, roughness: 0.3 }\n"
             "lights:\n  - { type: envmap, file: %s, rotation: 20 }\n"
             "  - { type: distant, direction: [0.5, 1, 0.3], irradiance: 2, angular_diameter: 20 }\n"
             "shapes:\n  - { type: sphere, center: [-0.6, 0.5, 0], radius: 0.5, material: d }\n"
             "  - { type: sphere, center: [0.6, 0.5, 0], radius: 0.5, material: g }\n"
             "  - { type: quad, center: [0, 0, 0], u: [3, 0, 0], v: [0, 0, -3], material: d }\n",
             map);
    return text;
}

static void test_mis_vs_bsdf_only(void **state)
{
    (void)state;
    const char *scene = write_tmp("long_env.yaml", scene_text(write_map()));
    img_stack mis, bsdf, brighter;
    const char *bsdf_only[] = {"--set", "integrator.type=volpath", "--spp", "1024", NULL};
    const char *scaled[] = {"--set", "lights.0.scale=1.01", NULL};
    img_stack_render(&mis, scene, "mis.exr", 8, 100, NULL);
    img_stack_render(&bsdf, scene, "bsdf.exr", 8, 200, bsdf_only);
    img_stack_render(&brighter, scene, "brighter.exr", 8, 300, scaled);
    int agree = img_stack_agree("MIS against BSDF sampling alone", &mis, &bsdf, 4);
    int biased = img_stack_must_differ("MIS with the map 1.01 x against BSDF alone", &brighter, &bsdf, 4);
    img_stack_free(&mis);
    img_stack_free(&bsdf);
    img_stack_free(&brighter);
    assert_true(agree);
    assert_true(biased);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mis_vs_bsdf_only),
    };
    return STAT_RUN(tests, argc, argv);
}
