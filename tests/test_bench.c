/* test_bench.c — `murk bench` end to end on a tiny scene (rows, charts, report, a wrong --vary caught
 * before rendering, the cached reference reused and then invalidated), and the noise-corrected relMSE
 * of metrics.c (the code murk bench and murk compare share). */
#include "testutil.h"

#include "metrics.h"
#include "murk/murk.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static const char tiny[] =
    "murk: 1\n"
    "render: { resolution: [24, 24], spp: 4, seed: 0 }\n"
    "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
    "integrator: { type: volpath_nee, max_depth: 16 }\n"
    "background: %s\n"
    "materials: { white: { type: diffuse, albedo: 0.7 } }\n"
    "media:\n"
    "  smoke: { type: delta, density: { cloud: { min: [-1, -1, -1], max: [1, 1, 1], seed: 3, resolution: 16 } },"
    " sigma_s: 4, sigma_a: 0.2 }\n"
    "shapes:\n"
    "  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: smoke }\n"
    "  - { type: quad, center: [0, 2.5, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: 8 }\n";

static const char *write_tiny(const char *background)
{
    char text[2048];
    snprintf(text, sizeof text, tiny, background);
    return write_tmp("tiny.yaml", text);
}

static int exists(const char *dir, const char *name)
{
    char p[1024];
    struct stat st;
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return stat(p, &st) == 0 && st.st_size > 0;
}

static int csv_rows(const char *dir)
{
    char p[1024];
    snprintf(p, sizeof p, "%s/bench.csv", dir);
    FILE *f = fopen(p, "r");
    if (!f)
        return -1;
    int n = 0, c;
    while ((c = fgetc(f)) != EOF)
        n += c == '\n';
    fclose(f);
    return n - 1; /* the header */
}

static void bench_end_to_end(void **state)
{
    (void)state;
    char cache[512], out1[512], out2[512], out3[512];
    snprintf(cache, sizeof cache, "%s/cache", tmp_dir());
    setenv("MURK_CACHE_DIR", cache, 1);
    snprintf(out1, sizeof out1, "%s/b1", tmp_dir());
    snprintf(out2, sizeof out2, "%s/b2", tmp_dir());
    snprintf(out3, sizeof out3, "%s/b3", tmp_dir());
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char *out = NULL;
    /* 2 variants x 2 budgets x 2 seeds = 8 renders */
    int st = run_murk(&out, "bench", scene, "--vary", "media.smoke.type=delta,decomposition", "--spp", "1,4",
                      "--repeat", "2", "--ref-spp", "16", "--threads", "2", "-o", out1, NULL);
    if (st != 0)
        fail_msg("murk bench failed (%d):\n%s", st, out);
    assert_contains(out, "(rendered: 16 spp in 4 chunks");
    assert_contains(out, "8 renders (2 variants x 2 budgets x 2 seeds)");
    assert_int_equal(csv_rows(out1), 8);
    static const char *const files[] = {"bench.csv", "bench.json", "report.md", "error_vs_time.png",
                                        "error_vs_time.svg", "error_vs_lookups.png", "error_vs_lookups.svg",
                                        "efficiency.png", "efficiency.svg", "efficiency_map.png",
                                        "efficiency_map.svg", "maps/variant0.npy", "maps/variant1.npy"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        if (!exists(out1, files[i]))
            fail_msg("murk bench did not write %s/%s:\n%s", out1, files[i], out);
    free(out);

    /* the same scene, overrides and spp: the cached reference */
    st = run_murk(&out, "bench", scene, "--vary", "media.smoke.type=delta,decomposition", "--spp", "1",
                  "--repeat", "2", "--ref-spp", "16", "--threads", "2", "--no-charts", "-o", out2, NULL);
    assert_int_equal(st, 0);
    assert_contains(out, "reused from the cache");
    assert_int_equal(csv_rows(out2), 4);
    free(out);

    /* the scene changes: a new reference */
    scene = write_tiny("[0.3, 0.2, 0.2]");
    st = run_murk(&out, "bench", scene, "--vary", "media.smoke.type=delta,decomposition", "--spp", "1",
                  "--repeat", "2", "--ref-spp", "16", "--threads", "2", "--no-charts", "-o", out3, NULL);
    assert_int_equal(st, 0);
    assert_contains(out, "(rendered: 16 spp");
    assert_not_contains(out, "reused");
    free(out);
}

/* A --vary key the scene does not have, or a value its plugin refuses: a located message, exit 1, and
 * nothing rendered (not even the output folder). */
static void bench_bad_vary(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char dir[512], *out = NULL;
    snprintf(dir, sizeof dir, "%s/bad", tmp_dir());
    assert_int_equal(run_murk(&out, "bench", scene, "--vary", "media.smok.type=delta,spectral", "-o", dir, NULL), 1);
    assert_contains(out, "tiny.yaml:7:");
    assert_contains(out, "--vary media.smok.type: media has no 'smok' (it has: smoke)");
    assert_contains(out, "nothing was rendered");
    free(out);
    assert_int_equal(run_murk(&out, "bench", scene, "--vary", "media.smoke.majorant_factor=1,-2", "-o", dir, NULL), 1);
    assert_contains(out, "--set:1:29: medium 'smoke' (delta): parameter 'majorant_factor' must be in");
    assert_contains(out, "in --vary media.smoke.majorant_factor=1,-2 (value '-2')");
    free(out);
    struct stat sb;
    assert_int_not_equal(stat(dir, &sb), 0);
}

/* A render made of 4 chunks of different seeds: the mean and the variance of the per-pixel mean. */
static void chunked(const char *scene, int seed0, float **mean, float **var, int *w, int *h)
{
    enum { CHUNKS = 4, SPP = 4 };
    double *s1 = NULL, *s2 = NULL;
    size_t n = 0;
    for (int c = 0; c < CHUNKS; c++) {
        char set[64], err[2048];
        snprintf(set, sizeof set, "render.seed=%d", seed0 + c);
        const char *sets[] = {set};
        murk_scene *s = murk_scene_load(scene, sets, 1, err, sizeof err);
        if (!s)
            fail_msg("%s", err);
        murk_render_opts o = {.spp = SPP, .threads = 2};
        murk_render_result r;
        assert_int_equal(murk_render(s, &o, &r), 0);
        if (!s1) {
            *w = r.width, *h = r.height;
            n = 3 * (size_t)r.width * (size_t)r.height;
            s1 = calloc(n, sizeof *s1);
            s2 = calloc(n, sizeof *s2);
        }
        for (size_t i = 0; i < n; i++) {
            s1[i] += r.rgb[i];
            s2[i] += (double)r.rgb[i] * r.rgb[i];
        }
        free(r.rgb);
        murk_scene_free(s);
    }
    *mean = malloc(n * sizeof **mean);
    *var = malloc(n * sizeof **var);
    for (size_t i = 0; i < n; i++) {
        double m = s1[i] / CHUNKS;
        (*mean)[i] = (float)m;
        (*var)[i] = (float)(fmax(0.0, (s2[i] - s1[i] * m) / (CHUNKS - 1)) / CHUNKS);
    }
    free(s1);
    free(s2);
}

/* Two renders of the same scene with other seeds have the same expected image: their relMSE corrected
 * for both renders' noise (v = vA + vB, the chunk estimates) is 0 within 4 standard errors, while the
 * uncorrected figure is about twice one render's own noise term (E = Var A + Var B). Breaking the
 * correction (v ignored) fails the first check by far. */
static void corrected_relmse_of_two_seeds(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    float *a, *va, *b, *vb;
    int w, h;
    chunked(scene, 100, &a, &va, &w, &h);
    chunked(scene, 200, &b, &vb, &w, &h);
    size_t n = 3 * (size_t)w * (size_t)h;
    float *v = malloc(n * sizeof *v);
    for (size_t i = 0; i < n; i++)
        v[i] = va[i] + vb[i];
    murk_crop all = {0, 0, w, h};
    murk_metrics both, raw, single;
    murk_metrics_compute(a, b, v, w, all, &both, NULL);
    murk_metrics_compute(a, b, NULL, w, all, &raw, NULL);
    murk_metrics_compute(a, b, va, w, all, &single, NULL);
    printf("corrected relMSE %.4e ± %.2e; raw %.4e = %.3f x one render's noise term %.4e\n", both.relmse,
           both.relmse_se, raw.relmse_raw, raw.relmse_raw / single.ref_noise, single.ref_noise);
    assert_true(fabs(both.relmse) < 4.0 * both.relmse_se);
    assert_true(raw.relmse_raw > 4.0 * raw.relmse_se);
    assert_true(fabs(raw.relmse_raw / single.ref_noise - 2.0) < 0.4);
    free(a), free(va), free(b), free(vb), free(v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bench_bad_vary),
        cmocka_unit_test(corrected_relmse_of_two_seeds),
        cmocka_unit_test(bench_end_to_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
