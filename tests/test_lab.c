/* test_lab.c — libmurklab's programmatic API (murk/lab.h) as a program outside murk uses it: this test
 * includes the public headers only and links the shared libmurklab and libmurk, so every call goes through what
 * the library exports.
 *   metrics   two small images with known differences give the figures' closed forms;
 *   schema    a material's and a tracker's descriptors as data, the keys every medium takes, and a
 *             missing plugin refused with a message naming it;
 *   bench     murk_lab_bench_run hands over every row of bench.csv as it is written (each the same line
 *             formatted anew), its stop flag ends the bench as SIGINT does (status 130, the whole renders'
 *             rows in bench-interrupted.csv), and --emit-jobs is left to the command. */
#define _XOPEN_SOURCE 700 /* nftw() */
#include <ftw.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "murk/lab.h"

/* |a - b| <= tol in double (cmocka's assert_float_equal works in float) */
#define assert_near(a, b, tol)                                                                         \
    do {                                                                                               \
        double a_ = (a), b_ = (b);                                                                     \
        if (!(fabs(a_ - b_) <= (tol)))                                                                 \
            fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);                                        \
    } while (0)

/* a = r + d with d = +1/8 in every channel of pixel 0 and -1/8 in pixel 1; r = 0.5 everywhere. */
static void metrics_closed_form(void **state)
{
    (void)state;
    const float r[6] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    float a[6];
    for (int i = 0; i < 6; i++)
        a[i] = r[i] + (i < 3 ? 0.125f : -0.125f); /* exact in float */
    murk_metrics m;
    float pix[2];
    murk_metrics_compute(a, r, NULL, 2, (murk_crop){0, 0, 2, 1}, &m, pix);
    double e = (double)a[0] - r[0], den = 0.25 + 0.01;
    assert_int_equal(m.n, 6);
    assert_int_equal(m.nonfinite, 0);
    assert_near(m.mse, e * e, 1e-12);
    assert_near(m.relmse, e * e / den, 1e-12);
    assert_near(m.relmse_raw, m.relmse, 1e-15);
    assert_near(m.ref_noise, 0.0, 1e-15);
    assert_near(m.mare, fabs(e) / 0.51, 1e-9);
    assert_near(m.diff[3], 0.0, 1e-9); /* +e and -e */
    assert_near(pix[0], e * e / den, 1e-6);
    /* a NaN is skipped and counted */
    a[4] = NAN;
    murk_metrics_compute(a, r, NULL, 2, (murk_crop){0, 0, 2, 1}, &m, NULL);
    assert_int_equal(m.n, 5);
    assert_int_equal(m.nonfinite, 1);
}

static const murk_param *find_param(const murk_param *ps, uint32_t n, const char *name)
{
    for (uint32_t i = 0; i < n; i++)
        if (!strcmp(ps[i].name, name))
            return &ps[i];
    return NULL;
}

static void schema_as_data(void **state)
{
    (void)state;
    char err[1024];
    murk_lab_plugin_info info;
    murk_lab_plugin *p = murk_lab_plugin_open("diffuse", &info, err, sizeof err);
    if (!p)
        fail_msg("%s", err);
    assert_string_equal(info.name, "diffuse");
    assert_int_equal(info.kind, MURK_KIND_MATERIAL);
    assert_int_equal(info.abi.major, MURK_ABI_MAJOR);
    const char *slash = strrchr(info.path, '/');
    assert_non_null(slash);
    assert_string_equal(slash, "/diffuse.so");
    assert_non_null(info.description);
    const murk_param *albedo = find_param(info.params, info.nparams, "albedo");
    assert_non_null(albedo);
    assert_int_equal(albedo->type, MURK_PARAM_RGB);
    assert_non_null(albedo->doc);
    murk_lab_plugin_close(p);

    p = murk_lab_plugin_open("delta", &info, err, sizeof err);
    if (!p)
        fail_msg("%s", err);
    assert_int_equal(info.kind, MURK_KIND_MEDIUM);
    murk_lab_plugin_close(p);
    uint32_t n = 0;
    const murk_param *keys = murk_lab_medium_params(&n);
    assert_true(n > 0);
    assert_non_null(find_param(keys, n, "sigma_a"));
    assert_non_null(find_param(keys, n, "majorant_factor"));

    err[0] = 0;
    assert_null(murk_lab_plugin_open("no_such_plugin", &info, err, sizeof err));
    if (!strstr(err, "no_such_plugin"))
        fail_msg("the message does not name the plugin: %s", err);
    murk_lab_plugin_close(NULL);
}

static const char scene[] =
    "murk: 1\n"
    "render: { resolution: [8, 8], spp: 4, seed: 0 }\n"
    "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
    "integrator: { type: volpath_nee, max_depth: 16 }\n"
    "background: [0.2, 0.2, 0.2]\n"
    "materials: { white: { type: diffuse, albedo: 0.7 } }\n"
    "media:\n"
    "  smoke: { type: delta, density: { constant: 1 }, sigma_s: 2, sigma_a: 0.2 }\n"
    "shapes:\n"
    "  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: smoke }\n"
    "  - { type: quad, center: [0, 2.5, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: 8 }\n";

enum { MAX_ROWS = 16 };
typedef struct rows_seen {
    int n, stop_after;
    char line[MAX_ROWS][1024]; /* each row as a line of bench.csv */
    volatile sig_atomic_t *stop;
} rows_seen;

/* The row as bench.csv's line (its columns: README.md's "murk bench"). */
static void on_row(void *user, const murk_bench_row *w)
{
    rows_seen *seen = user;
    assert_true(seen->n < MAX_ROWS);
    const murk_metrics *m = &w->metrics;
    const murk_counters *c = &w->counters;
    snprintf(seen->line[seen->n], sizeof seen->line[0],
             "%d,\"%s\",%g,%d,%d,%.6f,%llu,%llu,%llu,%llu,%llu,%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%llu,%.9g",
             w->variant, w->label, w->budget, w->seed, w->spp, w->seconds, (unsigned long long)w->rays,
             (unsigned long long)c->lookups, (unsigned long long)c->cells, (unsigned long long)c->collisions,
             (unsigned long long)c->scatters, (unsigned long long)c->shadow, m->mse, m->relmse, m->relmse_se,
             m->relmse_raw, m->ref_noise, m->mare, (unsigned long long)w->nonfinite, w->max_sample);
    if (++seen->n == seen->stop_after)
        *seen->stop = 1;
}

/* The lines of DIR/NAME after its header, compared with the rows seen; their count. */
static int same_lines(const char *dir, const char *name, const rows_seen *seen)
{
    char path[1024], line[2048];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("no %s", path);
    int n = -1;
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = 0;
        if (n >= 0 && (n >= seen->n || strcmp(line, seen->line[n]) != 0))
            fail_msg("%s line %d:\n  %s\nthe row handed over:\n  %s", path, n + 2, line, n < seen->n ? seen->line[n] : "(none)");
        n++;
    }
    fclose(f);
    return n;
}

static int remove_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

static void bench_rows(void **state)
{
    (void)state;
    const char *tmp = getenv("TMPDIR");
    char dir[1024], path[1100], out[1100], out2[1100], cache[1100];
    snprintf(dir, sizeof dir, "%s/murk-test-lab-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    assert_non_null(mkdtemp(dir));
    snprintf(cache, sizeof cache, "%s/cache", dir);
    setenv("MURK_CACHE_DIR", cache, 1);
    snprintf(path, sizeof path, "%s/tiny.yaml", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(scene, f);
    fclose(f);
    snprintf(out, sizeof out, "%s/out", dir);
    char *args[] = {path, "--vary", "media.smoke.type=delta,decomposition", "--spp", "1,2", "--repeat", "2",
                    "--ref-spp", "8", "--no-charts", "-o", out, NULL};
    int argc = (int)(sizeof args / sizeof args[0]) - 1;
    volatile sig_atomic_t stop = 0;
    static rows_seen seen;
    seen = (rows_seen){.stop = &stop};
    assert_int_equal(murk_lab_bench_run(argc, args, &stop, on_row, &seen), 0);
    assert_int_equal(seen.n, 8); /* 2 variants x 2 budgets x 2 seeds */
    assert_int_equal(same_lines(out, "bench.csv", &seen), 8);

    /* the caller's stop flag, set after the third row: the third render is the last */
    snprintf(out2, sizeof out2, "%s/out2", dir);
    args[11] = out2;
    stop = 0;
    seen = (rows_seen){.stop = &stop, .stop_after = 3};
    assert_int_equal(murk_lab_bench_run(argc, args, &stop, on_row, &seen), 130);
    assert_int_equal(seen.n, 3);
    assert_int_equal(same_lines(out2, "bench-interrupted.csv", &seen), 3);

    char *jobs[] = {path, "--emit-jobs", out2, NULL};
    assert_int_equal(murk_lab_bench_run(3, jobs, NULL, NULL, NULL), 2);
    nftw(dir, remove_one, 16, FTW_DEPTH | FTW_PHYS);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(metrics_closed_form),
        cmocka_unit_test(schema_as_data),
        cmocka_unit_test(bench_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
