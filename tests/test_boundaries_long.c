/* test_boundaries_long.c — test_boundaries.c's volpath_nee-against-volpath comparison on all twelve
 * configurations (box, sphere and mesh boundaries x grey and chromatic media x camera outside and
 * inside) at 64x64 with 8 seeds x 2048 spp and 8x8-pixel blocks: a block's standard error is about
 * 0.1 % of its value, so a 0.5 % local bias stands out by ~5 sigma (suite 'long', not in the default
 * run; ~20 minutes on two cores):
 *
 *   meson test -C build --setup long --suite long boundaries_long */
#define NEE_RES 64
#define NEE_BLOCK 8
#define NEE_SEEDS 8
#define NEE_SPP "2048"
#define BSDF_SPP "render.spp=8192"
#define NEE_ALL 1
#define BOUNDARIES_NO_MAIN 1
#include "test_boundaries.c"

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nee),
        cmocka_unit_test(test_shadow), /* as in the default run */
        cmocka_unit_test(test_path),   /* as in the default run */
        cmocka_unit_test(test_shadow_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
