/* test_media_long.c — the media convergence runs (suite 'long', not part of the default run):
 * test_media_render.c's furnaces and tracker-invariance comparison with ~16x (furnace) and ~10x
 * (invariance) the samples, more tracker variants (spectral's max / average probabilities, majorant x4
 * for every tracker), and a 1% instead of a 3% density change as the negative control the block
 * comparison must detect. About 15 minutes on two cores.
 *
 *   meson test -C build --suite long media_long */
#define MEDIA_LONG 1
#define MEDIA_RENDER_NO_MAIN 1
#define FURNACE_SPP 8192
#define INV_SEEDS 8
#define INV_SPP 4096
#define INV_DENSER "1.01"
#include "test_media_render.c"

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1) /* a pattern: run only the matching tests */
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_furnace_nee),
        cmocka_unit_test(test_invariance),
        cmocka_unit_test(test_slab),      /* as in the default run */
        cmocka_unit_test(test_stability), /* as in the default run */
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
