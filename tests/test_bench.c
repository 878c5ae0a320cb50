/* test_bench.c — `murk bench` end to end on a tiny scene (rows, charts, report, a wrong --vary caught
 * before rendering, the cached reference reused and then invalidated), the noise-corrected relMSE
 * of metrics.c (the code murk bench and murk compare share), murk compare's bias test, --json, --crop
 * and maps, and a bench interrupted by SIGINT/SIGTERM (whole rows only, nothing half-written). */
#include "testutil.h"
#include "stat.h"

#include "murk/lab.h"
#include "murk/murk.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char tiny[] =
    "murk: 1\n"
    "render: { resolution: [24, 24], spp: 4, seed: 0 }\n"
    "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
    "integrator: { type: volpath_nee, max_depth: 16, rr_threshold: 1 }\n" /* corrected_relmse_of_two_seeds' tolerance */
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
    char out1[512], out2[512], out3[512];
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
                                        "efficiency_map.svg", "maps/variant0.npy", "maps/variant1.npy",
                                        "report.html"};
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
    assert_contains(out, "--set media.smoke.majorant_factor=-2: medium 'smoke' (delta): parameter 'majorant_factor' must be in");
    assert_contains(out, "in --vary media.smoke.majorant_factor=1,-2 (value '-2')");
    free(out);
    struct stat sb;
    assert_int_not_equal(stat(dir, &sb), 0);
}

/* --vary of a whole plugin block: a swap of the type carries the new plugin's own keys (set with the type
 * first, so the old plugin's keys are dropped and the new ones are checked against the new plugin); the
 * value 'control: 0.5' alone would be refused for delta. The label names each block; a block that is not
 * {key: value, ...} is refused before anything is rendered. */
static char *slurp_file(const char *path);

static void bench_vary_block(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char dir[512], *out = NULL, path[600];
    snprintf(dir, sizeof dir, "%s/block", tmp_dir());
    int st = run_murk(&out, "bench", scene, "--vary",
                      "media.smoke={type: decomposition, control: 0.5},{type: spectral, probabilities: max}",
                      "--spp", "1", "--repeat", "2", "--ref-spp", "8", "--threads", "2", "--no-charts", "-o", dir, NULL);
    if (st != 0)
        fail_msg("murk bench with block values failed (%d):\n%s", st, out);
    assert_contains(out, "4 renders (2 variants x 1 budgets x 2 seeds)");
    free(out);
    assert_int_equal(csv_rows(dir), 4);
    snprintf(path, sizeof path, "%s/bench.csv", dir);
    char *csv = slurp_file(path);
    assert_contains(csv, "\"smoke={type: decomposition, control: 0.5}\"");
    assert_contains(csv, "\"smoke={type: spectral, probabilities: max}\"");
    free(csv);
    /* a key the new type does not take: located at its --set, nothing rendered */
    snprintf(dir, sizeof dir, "%s/block_bad", tmp_dir());
    assert_int_equal(run_murk(&out, "bench", scene, "--vary", "media.smoke={type: delta, control: 0.5}", "-o", dir, NULL), 1);
    assert_contains(out, "--set media.smoke.control=0.5: unknown parameter 'control' for medium 'smoke' (delta)");
    free(out);
    assert_int_equal(run_murk(&out, "bench", scene, "--vary", "media.smoke={type delta}", "-o", dir, NULL), 2);
    assert_contains(out, "is not a block {key: value, ...}");
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
        const char *sets[] = {set, "render.resolution=[48, 48]"}; /* 4x the pixels of the scene: the raw
                                                                    * figure's bias is then ~14 of its se */
        murk_scene *s = murk_scene_load(scene, sets, 2, err, sizeof err);
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
 * for both renders' noise (v = vA + vB, the chunk estimates) is 0 within STAT_Z standard errors, while the
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
    assert_true(stat_z_ok(both.relmse, both.relmse_se, 0.0, 0.0));
    /* must-fail: the uncorrected figure, biased by both renders' noise, must not pass as 0 */
    assert_true(stat_must_fail("relMSE without the noise correction", raw.relmse_raw > STAT_Z * raw.relmse_se,
                               raw.relmse_raw / raw.relmse_se));
    assert_true(fabs(raw.relmse_raw / single.ref_noise - 2.0) < 0.4);
    free(a), free(va), free(b), free(vb), free(v);
}

/* murk compare on two renders of another seed: the bias test finds no difference (|z| <= STAT_Z), --json and
 * --crop give one JSON object over the crop, --diff writes the heat map and the signed map beside it,
 * and the efficiency comes from the EXR's render time and counters. */
static void compare_two_seeds(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char a[512], b[512], diff[512], sdiff[512], *out = NULL;
    snprintf(a, sizeof a, "%s/cmp_a.exr", tmp_dir());
    snprintf(b, sizeof b, "%s/cmp_b.exr", tmp_dir());
    snprintf(diff, sizeof diff, "%s/cmp_diff.png", tmp_dir());
    snprintf(sdiff, sizeof sdiff, "%s/cmp_diff_signed.png", tmp_dir());
    assert_int_equal(run_murk(&out, "render", scene, "-o", a, "--spp", "8", "--quiet", NULL), 0);
    free(out);
    assert_int_equal(run_murk(&out, "render", scene, "-o", b, "--spp", "8", "--quiet", "--set", "render.seed=9", NULL),
                     0);
    free(out);
    assert_int_equal(run_murk(&out, "compare", a, b, "--diff", diff, NULL), 0);
    /* (murk compare's own verdict "no sign of a different expected image" is at |z| < 3, a 0.3 %
     * false alarm: the test judges its printed z at STAT_Z instead) */
    assert_contains(out, "efficiency 1/(relMSE x seconds)");
    assert_contains(out, "efficiency 1/(relMSE x density lookups)");
    assert_contains(out, "blue -1 .. white 0 .. red +1");
    const char *z = strstr(out, "(z = ");
    assert_non_null(z);
    assert_true(stat_z_ok(atof(z + 5), 1.0, 0.0, 0.0));
    free(out);
    struct stat st;
    assert_int_equal(stat(diff, &st), 0);
    assert_int_equal(stat(sdiff, &st), 0);
    assert_int_equal(run_murk(&out, "compare", a, b, "--json", "--crop", "4,4,8,8", NULL), 0);
    assert_contains(out, "\"crop\": [4, 4, 8, 8], \"n\": 192,");
    assert_contains(out, "\"z\": ");
    free(out);
    assert_int_equal(run_murk(&out, "compare", a, b, "--crop", "20,20,8,8", NULL), 2);
    assert_contains(out, "reaches outside the 24x24 images");
    free(out);
}


/* ---- interrupted benches ---- */

/* tmp_dir()/NAME (the output folder), NAME_cache (MURK_CACHE_DIR) and NAME.log, each 512 bytes. */
static void bench_paths(const char *name, char *out, char *cache, char *log)
{
    snprintf(out, 512, "%s/%s", tmp_dir(), name);
    snprintf(cache, 512, "%s/%s_cache", tmp_dir(), name);
    snprintf(log, 512, "%s/%s.log", tmp_dir(), name);
}

/* Starts `murk bench ARGS` with its cache in cache (MURK_CACHE_DIR) and its stdout and stderr, progress
 * lines included (MURK_PROGRESS=1), into log. */
static pid_t start_bench(const char *log, const char *cache, const char *const *args)
{
    const char *argv[64];
    int n = 0;
    const char *exe = getenv("MURK_EXE");
    argv[n++] = exe && *exe ? exe : "build/core/murk";
    argv[n++] = "bench";
    for (; *args && n < 63; args++)
        argv[n++] = *args;
    argv[n] = NULL;
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0)
            _exit(127);
        dup2(fd, 1);
        dup2(fd, 2);
        setenv("MURK_CACHE_DIR", cache, 1);
        setenv("MURK_PROGRESS", "1", 1);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static char *slurp_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *buf = calloc(1, 1 << 20);
    if (f) {
        size_t n = fread(buf, 1, (1 << 20) - 1, f);
        buf[n] = 0;
        fclose(f);
    }
    return buf;
}

/* Waits (up to 5 minutes) until log contains what; fails if the bench ended first. */
static void wait_for(pid_t pid, const char *log, const char *what)
{
    struct timespec ts = {0, 10 * 1000 * 1000};
    for (int i = 0; i < 30000; i++) {
        char *text = slurp_file(log);
        int found = strstr(text, what) != NULL;
        if (!found && waitpid(pid, NULL, WNOHANG) == pid)
            fail_msg("murk bench ended before '%s':\n%s", what, text);
        free(text);
        if (found)
            return;
        nanosleep(&ts, NULL);
    }
    fail_msg("murk bench never printed '%s'", what);
}

/* The files of dir (none if it does not exist): fails on a temporary (NAME.tmp-PID or NAME.tmp); returns
 * how many there are. */
static int files_without_temporaries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    if (!d)
        return 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        if (strstr(e->d_name, ".tmp"))
            fail_msg("a temporary was left behind: %s/%s", dir, e->d_name);
        n++;
    }
    closedir(d);
    return n;
}

static int wait_exit(pid_t pid)
{
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    if (!WIFEXITED(st))
        fail_msg("murk bench was killed by signal %d instead of exiting", WIFSIGNALED(st) ? WTERMSIG(st) : 0);
    return WEXITSTATUS(st);
}

/* SIGINT after some renders of a long bench (2 variants x 1000 seeds): exit status 130, the message says how
 * many renders were whole and where their rows are; bench-interrupted.csv holds the header and exactly
 * those rows, each whole (every column); no bench.csv, bench.json, maps or charts; no temporary in the
 * output folder or the cache, where the reference finished before the signal stays (both files). */
static void bench_sigint_keeps_whole_rows(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char out[512], cache[512], log[512];
    bench_paths("int_rows", out, cache, log);
    const char *args[] = {scene, "--vary", "media.smoke.type=delta,decomposition", "--spp", "16", "--repeat", "1000",
                          "--ref-spp", "16", "--threads", "1", "-o", out, NULL};
    pid_t pid = start_bench(log, cache, args);
    wait_for(pid, log, "[3/2000]"); /* two renders are whole, the third is running */
    kill(pid, SIGINT);
    assert_int_equal(wait_exit(pid), 130);
    char *text = slurp_file(log);
    const char *msg = strstr(text, "murk bench: interrupted (SIGINT) after ");
    if (!msg)
        fail_msg("no interruption message:\n%s", text);
    int done = atoi(msg + strlen("murk bench: interrupted (SIGINT) after "));
    char expect[1024];
    snprintf(expect, sizeof expect, "after %d of 2000 renders; their rows are in %s/bench-interrupted.csv", done, out);
    assert_contains(text, expect);
    assert_true(done >= 2 && done < 2000);
    free(text);
    assert_int_equal(files_without_temporaries(out), 1); /* bench-interrupted.csv alone */
    assert_int_equal(files_without_temporaries(cache), 2); /* the reference and its variance */
    char path[1024];
    snprintf(path, sizeof path, "%s/bench-interrupted.csv", out);
    char *csv = slurp_file(path);
    int rows = -1, columns = 0;
    for (char *line = strtok(csv, "\n"); line; line = strtok(NULL, "\n"), rows++) {
        int c = 1;
        for (char *p = line; *p; p++)
            c += *p == ',';
        if (rows < 0)
            columns = c;
        else if (c != columns)
            fail_msg("row %d has %d columns, the header %d: %s", rows + 1, c, columns, line);
    }
    assert_int_equal(rows, done);
    assert_int_equal(columns, 20);
    free(csv);
}

/* SIGTERM while the reference renders: exit status 143, "nothing written", and nothing is: no output folder
 * (the bench made it, so it goes again), no cache file, no temporary. */
static void bench_sigterm_in_reference_writes_nothing(void **state)
{
    (void)state;
    const char *scene = write_tiny("[0.2, 0.2, 0.2]");
    char out[512], cache[512], log[512];
    bench_paths("int_ref", out, cache, log);
    const char *args[] = {scene, "--spp", "4", "--ref-spp", "400000", "--threads", "1", "-o", out, NULL};
    pid_t pid = start_bench(log, cache, args);
    wait_for(pid, log, "reference chunk 1 of 4");
    kill(pid, SIGTERM);
    assert_int_equal(wait_exit(pid), 143);
    char *text = slurp_file(log);
    assert_contains(text, "murk bench: interrupted (SIGTERM) while rendering the reference; nothing written");
    free(text);
    struct stat st;
    assert_int_not_equal(stat(out, &st), 0);
    assert_int_equal(files_without_temporaries(cache), 0);
}

int main(int argc, char **argv)
{
    char cache[512]; /* no test writes a reference into the user's cache */
    snprintf(cache, sizeof cache, "%s/cache", tmp_dir());
    setenv("MURK_CACHE_DIR", cache, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bench_bad_vary),
        cmocka_unit_test(bench_vary_block),
        cmocka_unit_test(corrected_relmse_of_two_seeds),
        cmocka_unit_test(compare_two_seeds),
        cmocka_unit_test(bench_end_to_end),
        cmocka_unit_test(bench_sigint_keeps_whole_rows),
        cmocka_unit_test(bench_sigterm_in_reference_writes_nothing),
    };
    return STAT_RUN(tests, argc, argv);
}
