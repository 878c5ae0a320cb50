/* test_flight.c — stratified free flights (the medium key stratify_flights, murk/tracking.h's
 * murk_flight_float and murk_collisions): a flight's first random number comes from the sampler slot
 * the integrator sought to, every later one from the PCG stream.
 *
 *   stratified   every tracker, a grey constant medium (the first tentative collision is the
 *                scattering event): over a pixel's first 2^k samples the first collisions' uniforms
 *                1 - exp(-mu t) fall one per interval [j/2^k, (j+1)/2^k); with the key off they do not
 *   helpers      murk_flight_float + murk_flight_choice: with sobol the slot's 2-D point (a (0, 6, 2)-net
 *                over 64 samples), later numbers from PCG; with independent numbers PCG's in call order
 *   one slot     a flight with many null collisions (checker grid, majorant x 4) takes exactly one slot
 *                (none with the key off): the collision loop never moves the integrator's slots
 *   same image   (suite 'long') every tracker with the key on renders the expected image of the key
 *                off, on cornell_smoke's cloud and on a constant chromatic medium (block-wise z-test, 8
 *                independent seeds each, img_stack_agree); must-fail: one block brighter by 10 of its
 *                standard errors (the resolution, printed)
 *   bitwise      with the key on: 1 and 2 threads and --time's passes give the same pixels; with
 *                render.sampler independent the key changes no pixel (it draws murk_rng_float in the
 *                same order); with sobol it does
 *   key          a value that is not a bool is a located error
 *
 * test_flight_choice.c checks what these do not see: the choice at a flight's first collision (a
 * deterministic count over 2^k samples) and the first flight's distance in heterogeneous media (the
 * cloud, a dense grid, a plateau) against the closed form, sharp enough for a first flight 5% short. */
#include "testutil.h"
#include "image/image.h"
#include "mediatest.h"
#include "stat.h"

#include "murk/math.h"
#include "murk/tracking.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const TRACKERS[] = {"delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"};
#define NTRACKERS 5

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The first collisions' uniforms of samples 0 .. 2^k - 1 of (seed, pixel) with the flight at `slot`:
 * 1 if they lie one per interval of 2^-k (to 1e-5: t is a float), sorted. */
static int flights_stratified(const murk_medium *m, uint64_t seed, uint64_t pixel, uint32_t slot, int k, float mu)
{
    int n = 1 << k, ok = 1;
    double *u = malloc((size_t)n * sizeof *u);
    assert_non_null(u);
    murk_ray ray = {{0.5f, 0.5f, 0}, {0, 0, 1}, 0.0f, INFINITY};
    murk_path_ctx ctx = {0, {{1, 1, 1}}};
    for (int i = 0; i < n; i++) {
        murk_rng r;
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, seed, pixel, (uint32_t)i);
        murk_sample_seek(&r, slot);
        murk_medium_event ev;
        m->vt->sample(m->self, &ray, &ctx, &r, &ev);
        assert_true(ev.scattered && isfinite(ev.t));
        u[i] = -expm1(-(double)mu * ev.t);
    }
    qsort(u, (size_t)n, sizeof *u, cmp_double);
    for (int j = 0; j < n && ok; j++)
        ok = u[j] >= (double)j / n - 1e-5 && u[j] < (double)(j + 1) / n + 1e-5;
    free(u);
    return ok;
}

static float one_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy, (void)cz;
    return 1.0f;
}

/* `common`: density 1 everywhere the flights go (the first tentative collision is real) for the ntr
 * trackers and a last medium, delta with the key off; mu is the extinction. */
static void check_stratified(const char *what, const char *common, const char *const *trackers, int ntr, float mu)
{
    mt_spec ms[NTRACKERS + 1];
    char keys[NTRACKERS + 1][64];
    for (int i = 0; i < ntr; i++) {
        snprintf(keys[i], sizeof keys[i], "type: %s", trackers[i]);
        ms[i] = (mt_spec){trackers[i], keys[i], 0};
    }
    ms[ntr] = (mt_spec){"delta_off", "type: delta, stratify_flights: false", 0};
    murk_scene *s = mt_load_media("strat.yaml", common, "", ms, ntr + 1);
    static const uint32_t slots[] = {0x20000000u, 0x20000000u + 3u * 1024u + 1u, 7u};
    for (int i = 0; i <= ntr; i++) {
        int all = 1;
        for (int k = 2; k <= 8; k += 2)
            for (uint64_t pixel = 0; pixel < 3; pixel++)
                for (size_t sl = 0; sl < sizeof slots / sizeof slots[0]; sl++)
                    all &= flights_stratified(&s->media[i].m, 5u + pixel, pixel * 977u, slots[sl], k, mu);
        printf("%s, %-15s first collisions one per interval of 2^-k, k = 2..8, 3 pixels x 3 slots: %s\n", what,
               ms[i].label, all ? "yes" : "no");
        if (i < ntr)
            assert_true(all);
        else
            assert_false(all); /* stratify_flights: false draws from PCG */
    }
    murk_scene_free(s);
}

static void test_stratified(void **state)
{
    (void)state;
    /* one majorant segment: density 1 x sigma_t is delta's majorant and decomposition's control rate */
    check_stratified("constant", "density: { constant: 1 }, " MT_GREY_KEYS, TRACKERS, NTRACKERS, 1.2f);
    /* a grid of 1s: the flight crosses majorant cells before its first collision (mean 1/24 of the box,
     * 16 cells across), and the stratified optical depth carries over them (murk_collisions; not
     * decomposition, whose stratified number is its first cell's) */
    const int res[3] = {4, 4, 4};
    char common[512];
    snprintf(common, sizeof common, "density: { grid: '%s' }, majorant_resolution: 16, scale: 20, %s",
             mt_save_grid("ones.vol", res, murk_v3(0, 0, 0), murk_v3(1, 1, 1), one_f), MT_GREY_KEYS);
    static const char *const grid_trackers[] = {"delta", "spectral", "spectral_mis", "naive_spectral"};
    check_stratified("16 cells", common, grid_trackers, 4, 24.0f);
}

/* The helpers' pair (murk_flight_float's first number, murk_flight_choice's): with sobol the slot's 2-D
 * point — over a pixel's first 2^k samples one in each elementary interval 2^-a x 2^-(k-a) — and the
 * choice after it from PCG; with independent numbers both from the PCG stream in call order. */
static void test_helpers(void **state)
{
    (void)state;
    enum { K = 6, N = 1 << K };
    float u[N][2];
    for (int i = 0; i < N; i++) {
        murk_rng r, pcg;
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, 9, 4242, (uint32_t)i);
        murk_sample_seek(&r, 0x20000000u);
        pcg = r;
        int first = 1;
        float uc = -1.0f;
        u[i][0] = murk_flight_float(&r, &first, &uc);
        u[i][1] = murk_flight_choice(&r, &uc);
        assert_int_equal(first, 0);
        assert_true(murk_flight_choice(&r, &uc) == murk_rng_float(&pcg)); /* later choices: PCG */
        assert_true(murk_flight_float(&r, &first, &uc) == murk_rng_float(&pcg));
        murk_sampler_start(&r, MURK_SAMPLER_INDEPENDENT, 9, 4242, (uint32_t)i);
        pcg = r;
        first = 1;
        uc = -1.0f;
        assert_true(murk_flight_float(&r, &first, &uc) == murk_rng_float(&pcg));
        assert_true(murk_flight_choice(&r, &uc) == murk_rng_float(&pcg));
    }
    for (int a = 0; a <= K; a++) {
        unsigned char seen[N] = {0};
        for (int i = 0; i < N; i++) {
            int cell = ((int)(u[i][0] * (float)(1 << a)) << (K - a)) | (int)(u[i][1] * (float)(1 << (K - a)));
            assert_int_equal(seen[cell]++, 0);
        }
    }
}

/* A flight with many null collisions (checker grid 0.2 / 1.4, majorant x 4) takes one slot if the key
 * is on, none if off; and with the key on its numbers after the first are PCG's: the rng's stream state
 * moves as it does with the key off, less the one number the slot replaced. */
static void test_one_slot(void **state)
{
    (void)state;
    mt_case cc = mt_checker_case();
    char common[512];
    snprintf(common, sizeof common, "density: { grid: '%s' }, majorant_factor: 4, %s", cc.grid, MT_GREY_KEYS);
    mt_spec ms[2 * NTRACKERS];
    char keys[2 * NTRACKERS][96];
    for (int i = 0; i < 2 * NTRACKERS; i++) {
        snprintf(keys[i], sizeof keys[i], "type: %s%s", TRACKERS[i % NTRACKERS], i < NTRACKERS ? "" : ", stratify_flights: false");
        ms[i] = (mt_spec){TRACKERS[i % NTRACKERS], keys[i], 0};
    }
    char names[2 * NTRACKERS][32];
    for (int i = 0; i < 2 * NTRACKERS; i++) {
        snprintf(names[i], sizeof names[i], "%s%s", TRACKERS[i % NTRACKERS], i < NTRACKERS ? "" : "_off");
        ms[i].label = names[i];
    }
    murk_scene *s = mt_load_media("slot.yaml", common, "", ms, 2 * NTRACKERS);
    murk_ray ray = cc.ray;
    murk_path_ctx ctx = {0, {{1, 1, 1}}};
    for (int i = 0; i < 2 * NTRACKERS; i++) {
        long used = 0, draws = 0, maxslots = 0;
        for (uint32_t n = 0; n < 4000; n++) {
            murk_rng r;
            murk_sampler_start(&r, MURK_SAMPLER_SOBOL, 3, 11, n);
            murk_sample_seek(&r, 1000u);
            murk_rng before = r;
            murk_medium_event ev;
            s->media[i].m.vt->sample(s->media[i].m.self, &ray, &ctx, &r, &ev);
            long slots = (long)(r.dim - 1000u);
            maxslots = slots > maxslots ? slots : maxslots;
            used += slots;
            draws += r.state != before.state || slots > 0;
        }
        printf("%-20s flights 4000, that drew: %ld, slots taken: %ld (at most %ld per flight)\n", names[i], draws,
               used, maxslots);
        assert_true(draws > 3000);
        assert_int_equal(used, i < NTRACKERS ? draws : 0);
    }
    murk_scene_free(s);
}

/* ---- renders ------------------------------------------------------------------------------- */

static const char *const CHROMATIC[] = {"--set", "media.smoke.density={constant: 1}", "--set",
                                        "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "--set",
                                        "media.smoke.sigma_s=[1.2, 0.8, 0.4]", NULL};

static void long_same_image(void **state)
{
    (void)state;
    int nfail = 0;
    for (int sc = 0; sc < 2; sc++)
        for (int i = 0; i < NTRACKERS; i++) {
            char type[64], label[128];
            snprintf(type, sizeof type, "media.smoke.type=%s", TRACKERS[i]);
            snprintf(label, sizeof label, "%s, %s: stratify_flights on vs off", sc ? "constant chromatic" : "cloud",
                     TRACKERS[i]);
            const char *on[24] = {"--set", "render.resolution=[32,32]", "--spp", "64", "--set", type}, *off[24];
            size_t n = 6;
            for (size_t k = 0; sc && CHROMATIC[k]; k++)
                on[n++] = CHROMATIC[k];
            memcpy(off, on, sizeof on);
            on[n] = "--set", on[n + 1] = "media.smoke.stratify_flights=true", on[n + 2] = NULL;
            off[n] = "--set", off[n + 1] = "media.smoke.stratify_flights=false", off[n + 2] = NULL;
            img_stack a, b;
            img_stack_render(&a, src_path("scenes/cornell_smoke.yaml"), "on.exr", 8, 10, on);
            img_stack_render(&b, src_path("scenes/cornell_smoke.yaml"), "off.exr", 8, 1000, off);
            nfail += !img_stack_agree(label, &a, &b, 4);
            nfail += !img_stack_must_differ_block(label, &a, &b, 4, 0.0);
            img_stack_free(&a);
            img_stack_free(&b);
        }
    assert_int_equal(nfail, 0);
}

/* cornell_smoke at 40x32, 8 spp, into tmp_path(name), with `extra` (NULL-terminated) after the common
 * arguments. */
static void render(const char *name, const char *tracker, const char *sampler, const char *stratify,
                          const char *const *extra)
{
    char type[64], smp[64], st[64];
    snprintf(type, sizeof type, "media.smoke.type=%s", tracker);
    snprintf(smp, sizeof smp, "render.sampler=%s", sampler);
    snprintf(st, sizeof st, "media.smoke.stratify_flights=%s", stratify);
    char out[512], scene[512];
    snprintf(out, sizeof out, "%s", tmp_path(name));
    snprintf(scene, sizeof scene, "%s", src_path("scenes/cornell_smoke.yaml"));
    const char *args[] = {"render", scene, "-o", out, "--quiet", "--spp", "8", "--set", "render.resolution=[40,32]",
                          "--set", type, "--set", smp, "--set", st, NULL};
    run_murk_ok(args, extra);
}

static void test_bitwise(void **state)
{
    (void)state;
    static const char *const one[] = {"--threads", "1", NULL}, *const two[] = {"--threads", "2", NULL},
                             *const timed[] = {"--threads", "2", "--time", "600", NULL};
    for (int i = 0; i < NTRACKERS; i++) {
        const char *tr = TRACKERS[i];
        render("a.exr", tr, "sobol", "true", one);
        render("b.exr", tr, "sobol", "true", two);
        render("c.exr", tr, "sobol", "true", timed);
        render("d.exr", tr, "sobol", "false", two);
        render("e.exr", tr, "independent", "true", two);
        render("f.exr", tr, "independent", "false", two);
        int threads = same_pixels(tmp_path("a.exr"), tmp_path("b.exr"));
        int passes = same_pixels(tmp_path("a.exr"), tmp_path("c.exr"));
        int differs = !same_pixels(tmp_path("a.exr"), tmp_path("d.exr"));
        int indep = same_pixels(tmp_path("e.exr"), tmp_path("f.exr"));
        printf("%-15s stratified sobol: 1 = 2 threads %s, = --time passes %s, differs from off %s; independent: "
               "on = off %s\n", tr, threads ? "yes" : "NO", passes ? "yes" : "NO", differs ? "yes" : "NO",
               indep ? "yes" : "NO");
        assert_true(threads && passes && differs && indep);
    }
}

static void test_key(void **state)
{
    (void)state;
    char *log = NULL;
    int rc = run_murk(&log, "render", src_path("scenes/cornell_smoke.yaml"), "-o", tmp_path("bad.exr"), "--quiet",
                      "--set", "media.smoke.stratify_flights=maybe", (char *)NULL);
    assert_int_equal(rc, 1);
    assert_contains(log, "--set media.smoke.stratify_flights=maybe: medium 'smoke' (delta): parameter 'stratify_flights'");
    free(log);
    rc = run_murk(&log, "plugins", "delta", (char *)NULL);
    assert_int_equal(rc, 0);
    assert_contains(log, "stratify_flights");
    free(log);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stratified), cmocka_unit_test(test_helpers), cmocka_unit_test(test_one_slot),
        cmocka_unit_test(test_key),        cmocka_unit_test(test_bitwise), cmocka_unit_test(long_same_image),
    };
    return STAT_RUN(tests, argc, argv);
}
