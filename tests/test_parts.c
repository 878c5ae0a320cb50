/* test_parts.c — `murk render --part I/N` and `murk merge` (issue 13, item 2). The parts 0/3, 1/3, 2/3 of
 * a scene with a medium, merged, are bitwise the single-process render (EXR pixels and PNG bytes) with
 * its rays and cost counters; a
 * missing part, a part of another scene, a part given twice, an interrupted-looking or whole image each
 * fail with a message naming the culprit, and leave no output. And the other way to spread work over
 * a batch scheduler (issue 13, item 3): `murk bench --emit-jobs`, its jobs run by a shell loop and
 * assembled, gives the in-process bench's rows. */
#include "image/image.h"
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define RES "render.resolution=[80,64]" /* 5 x 4 tiles: the parts of 3 hold 7, 7 and 6 */
#define SPP "12"

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Renders scene (relative to the source tree) into out, optionally one part ("I/N" or NULL). */
static void render(const char *scene, const char *out, const char *part)
{
    char *log = NULL;
    const char *args[] = {"render", src_path(scene), "-o", tmp_path(out), "--spp", SPP, "--set", RES,
                          "--threads", "2", "--quiet", part ? "--part" : NULL, part, NULL};
    int rc = run_murk_argv(&log, args);
    if (rc != 0)
        fail_msg("murk render %s %s failed (%d):\n%s", scene, part ? part : "", rc, log);
    free(log);
}

static void setup_parts(void)
{
    static int done;
    if (done++)
        return;
    render("scenes/cornell_smoke.yaml", "whole.exr", NULL);
    render("scenes/cornell_smoke.yaml", "p0.exr", "0/3");
    render("scenes/cornell_smoke.yaml", "p1.exr", "1/3");
    render("scenes/cornell_smoke.yaml", "p2.exr", "2/3");
    render("scenes/cornell.yaml", "other1.exr", "1/3"); /* same size, spp, seed: another scene */
}

/* murk merge OUT PARTS... (NULL-terminated); its exit status, and its output in *log. */
static int merge(char **log, const char *out, const char *const *parts)
{
    const char *args[16];
    int n = 0;
    args[n++] = "merge";
    args[n++] = tmp_path(out);
    for (; *parts; parts++)
        args[n++] = tmp_path(*parts);
    args[n] = NULL;
    return run_murk_argv(log, args);
}

static void merged_parts_are_the_whole_image(void **state)
{
    (void)state;
    setup_parts();
    char *log = NULL;
    const char *parts[] = {"p2.exr", "p0.exr", "p1.exr", NULL}; /* in any order */
    int rc = merge(&log, "merged.exr", parts);
    if (rc != 0)
        fail_msg("murk merge failed (%d):\n%s", rc, log);
    free(log);
    assert_same_pixels(tmp_path("merged.exr"), tmp_path("whole.exr"));
    assert_true(files_equal(tmp_path("merged.png"), tmp_path("whole.png")));
    /* a part holds its tiles only: not the whole image */
    murk_image img = {0};
    char err[1024];
    assert_int_equal(murk_exr_read(tmp_path("p1.exr"), &img, err, sizeof err), 0);
    assert_string_equal(murk_image_meta(&img, "murk:part"), "1/3");
    assert_string_equal(murk_image_meta(&img, "murk:part_tiles"), "7");
    assert_non_null(murk_image_meta(&img, "murk:scene_hash"));
    murk_image_free(&img);
    murk_image whole = {0};
    assert_int_equal(murk_exr_read(tmp_path("merged.exr"), &img, err, sizeof err), 0);
    assert_int_equal(murk_exr_read(tmp_path("whole.exr"), &whole, err, sizeof err), 0);
    assert_null(murk_image_meta(&img, "murk:part"));
    assert_string_equal(murk_image_meta(&img, "murk:merged_from"), "3 parts");
    /* rays and cost counters summed over the parts: the single process's */
    assert_string_equal(murk_image_meta(&img, "murk:counters"), murk_image_meta(&whole, "murk:counters"));
    assert_string_equal(murk_image_meta(&img, "murk:nonfinite_samples"), "0");
    murk_image_free(&img);
    murk_image_free(&whole);
}

/* merge fails naming `needle`, and writes neither the EXR nor the PNG. */
static void merge_fails(const char *const *parts, const char *needle, const char *needle2)
{
    char *log = NULL;
    int rc = merge(&log, "bad.exr", parts);
    if (rc != 1)
        fail_msg("murk merge exited %d, not 1:\n%s", rc, log);
    assert_contains(log, needle);
    if (needle2)
        assert_contains(log, needle2);
    free(log);
    assert_false(exists(tmp_path("bad.exr")));
    assert_false(exists(tmp_path("bad.png")));
}

static void missing_part_is_named(void **state)
{
    (void)state;
    setup_parts();
    const char *parts[] = {"p0.exr", "p2.exr", NULL};
    merge_fails(parts, "part 1/3 is missing", "--part 1/3");
}

static void part_of_another_scene_is_named(void **state)
{
    (void)state;
    setup_parts();
    const char *parts[] = {"p0.exr", "other1.exr", "p2.exr", NULL};
    merge_fails(parts, "other1.exr: is a part of another render", "murk:scene_hash");
}

static void duplicated_part_is_named(void **state)
{
    (void)state;
    setup_parts();
    const char *parts[] = {"p0.exr", "p1.exr", "p2.exr", "p1.exr", NULL};
    merge_fails(parts, "p1.exr: part 1/3 is given twice", NULL);
}

static void whole_image_is_not_a_part(void **state)
{
    (void)state;
    setup_parts();
    const char *parts[] = {"p0.exr", "whole.exr", NULL};
    merge_fails(parts, "whole.exr: not a part", NULL);
}

static void part_options_are_checked(void **state)
{
    (void)state;
    char *log = NULL;
    const char *bad[][2] = {{"3/3", "--part I"}, {"1/0", "--part N"}, {"1", "--part needs I/N"}, {"-1/2", "--part I"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *args[] = {"render", src_path("scenes/cornell.yaml"), "-o", tmp_path("x.exr"), "--part",
                              bad[i][0], NULL};
        assert_int_equal(run_murk_argv(&log, args), 2);
        assert_contains(log, bad[i][1]);
        free(log);
    }
    const char *args[] = {"render", src_path("scenes/cornell.yaml"), "-o", tmp_path("x.exr"), "--part", "0/2",
                          "--time", "1", NULL};
    assert_int_equal(run_murk_argv(&log, args), 2);
    assert_contains(log, "--part cannot be combined with --time");
    free(log);
    assert_false(exists(tmp_path("x.exr")));
}

/* The lines of a text file (malloc'd, NULL-terminated). */
static char **read_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("cannot read %s", path);
    char **v = calloc(1024, sizeof *v), buf[16384];
    int n = 0;
    while (n < 1023 && fgets(buf, sizeof buf, f)) {
        buf[strcspn(buf, "\n")] = 0;
        v[n++] = strdup(buf);
    }
    fclose(f);
    return v;
}

static void free_lines(char **v)
{
    for (int i = 0; v[i]; i++)
        free(v[i]);
    free(v);
}

/* A CSV row without its 6th column (seconds: the one that depends on the machine's speed). */
static void drop_seconds(const char *row, char *out, size_t n)
{
    int col = 1;
    size_t k = 0;
    for (const char *p = row; *p && k + 1 < n; p++) {
        if (*p == ',')
            col++;
        if (col != 6)
            out[k++] = *p;
    }
    out[k] = 0;
}

/* murk bench --emit-jobs: the commands of jobs.txt, run one by one by a shell loop, then assemble.sh,
 * give bench.csv rows equal to the in-process bench's but for the seconds; a missing render is named. */
static void sweep_as_jobs_assembles_the_same_rows(void **state)
{
    (void)state;
    const char *common[] = {"bench", src_path("scenes/cornell_smoke.yaml"), "--vary",
                            "media.smoke.type=delta,spectral_mis", "--set", "render.resolution=[40,32]", "--spp",
                            "2,4", "--repeat", "2", "--ref-spp", "8", "--threads", "2", "--no-charts", "-o", NULL,
                            NULL, NULL, NULL};
    char *log = NULL;
    common[16] = tmp_path("bench_in");
    int rc = run_murk_argv(&log, common);
    if (rc != 0)
        fail_msg("murk bench failed (%d):\n%s", rc, log);
    free(log);
    common[16] = tmp_path("bench_jobs");
    common[17] = "--emit-jobs";
    common[18] = tmp_path("jobs");
    rc = run_murk_argv(&log, common);
    if (rc != 0)
        fail_msg("murk bench --emit-jobs failed (%d):\n%s", rc, log);
    assert_contains(log, "12 renders as jobs");
    free(log);
    char **jobs = read_lines(tmp_path("jobs/jobs.txt")), **slurm = read_lines(tmp_path("jobs/slurm.sh"));
    int nslurm = 0;
    for (int i = 0; slurm[i]; i++)
        nslurm += !strcmp(slurm[i], "#SBATCH --array=0-11");
    assert_int_equal(nslurm, 1);
    free_lines(slurm);
    int n = 0;
    for (; jobs[n]; n++) { /* the plain shell loop: while read line; do sh -c "$line"; done < jobs.txt */
        const char *argv[] = {"/bin/sh", "-c", jobs[n], NULL};
        rc = run_argv(&log, argv);
        if (rc != 0)
            fail_msg("job %d failed (%d): %s\n%s", n + 1, rc, jobs[n], log);
        free(log);
    }
    assert_int_equal(n, 12); /* 4 reference chunks + 2 variants x 2 budgets x 2 seeds */
    free_lines(jobs);
    const char *assemble[] = {"/bin/sh", tmp_path("jobs/assemble.sh"), NULL};
    rc = run_argv(&log, assemble);
    if (rc != 0)
        fail_msg("assemble.sh failed (%d):\n%s", rc, log);
    free(log);
    char **a = read_lines(tmp_path("bench_in/bench.csv")), **b = read_lines(tmp_path("bench_jobs/bench.csv"));
    int rows = 0;
    for (; a[rows] || b[rows]; rows++) {
        char ra[4096], rb[4096];
        if (!a[rows] || !b[rows])
            fail_msg("bench.csv: %s has more rows", a[rows] ? "the in-process bench" : "the assembled one");
        drop_seconds(a[rows], ra, sizeof ra);
        drop_seconds(b[rows], rb, sizeof rb);
        assert_string_equal(rb, ra);
    }
    assert_int_equal(rows, 1 + 8);
    free_lines(a);
    free_lines(b);
    /* a render missing: the assembly names it and fails */
    assert_int_equal(remove(tmp_path("jobs/renders/v1-b0-s1.exr")), 0);
    rc = run_argv(&log, assemble);
    assert_int_not_equal(rc, 0);
    assert_contains(log, "v1-b0-s1.exr");
    free(log);
}

int main(void)
{
    setenv("MURK_CACHE_DIR", tmp_path("cache"), 1); /* murk bench's reference cache: not the user's */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(merged_parts_are_the_whole_image),
        cmocka_unit_test(missing_part_is_named),
        cmocka_unit_test(part_of_another_scene_is_named),
        cmocka_unit_test(duplicated_part_is_named),
        cmocka_unit_test(whole_image_is_not_a_part),
        cmocka_unit_test(part_options_are_checked),
        cmocka_unit_test(sweep_as_jobs_assembles_the_same_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
