/* test_cli.c — the murk command's own surface: `murk --help`, `murk help [COMMAND]` and `murk COMMAND
 * --help` print usage on stdout and exit 0 for every subcommand; unknown options and commands exit 2 with
 * the usage on stderr and nothing on stdout; `murk info` lists what a scene holds (camera, render
 * settings, media with tracker, estimator, grid and majorant, materials, shapes, plugins with paths),
 * with --set applied and checked as `murk render` checks it. Every file `murk render` will write is
 * checked before the first sample. */
#include "testutil.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const char *const commands[] = {"render", "info", "plugins", "compare", "check", "grid", "help"};
#define NCOMMANDS (sizeof commands / sizeof commands[0])

static void expect_help(const char *what, int st, const char *out, const char *err, const char *usage_of)
{
    if (st != 0 || err[0])
        fail_msg("[%s] exit %d (want 0), stderr:\n%s", what, st, err);
    char want[128];
    snprintf(want, sizeof want, "usage: murk %s", usage_of);
    assert_contains(out, want);
}

static void test_help_everywhere(void **state)
{
    (void)state;
    char *out, *err;
    /* the whole usage: every command named in it */
    static const char *const whole[][2] = {{"--help", NULL}, {"-h", NULL}, {"help", NULL}};
    for (size_t k = 0; k < 3; k++) {
        int st = run_murk_split(&out, &err, whole[k]);
        if (st != 0 || err[0])
            fail_msg("[murk %s] exit %d, stderr:\n%s", whole[k][0], st, err);
        for (size_t i = 0; i < NCOMMANDS; i++) {
            char want[64];
            snprintf(want, sizeof want, "murk %s", commands[i]);
            assert_contains(out, want);
        }
        free(out);
        free(err);
    }
    /* one command's: murk COMMAND --help, murk COMMAND -h, murk help COMMAND; also after other arguments */
    for (size_t i = 0; i < NCOMMANDS; i++) {
        const char *forms[][4] = {{commands[i], "--help", NULL}, {commands[i], "-h", NULL},
                                  {"help", commands[i], NULL}, {commands[i], "x.yaml", "--help", NULL}};
        for (size_t f = 0; f < 4; f++) {
            char what[96];
            snprintf(what, sizeof what, "murk %s %s%s", forms[f][0], forms[f][1], forms[f][2] ? " --help" : "");
            int st = run_murk_split(&out, &err, forms[f]);
            expect_help(what, st, out, err, commands[i]);
            free(out);
            free(err);
        }
    }
    /* what render's help says about the A/B rules */
    const char *const rh[] = {"render", "--help", NULL};
    run_murk_split(&out, &err, rh);
    assert_contains(out, "--set KEY.PATH=VALUE");
    assert_contains(out, "drops the file's keys");
    assert_contains(out, "nothing uses is an error");
    free(out);
    free(err);
    /* an option's value that happens to read -h is that option's, not a request for help */
    const char *const val[] = {"render", "x.yaml", "-o", "-h", NULL};
    assert_int_equal(run_murk_split(&out, &err, val), 2);
    assert_contains(err, "the output file must end in .exr, got '-h'");
    free(out);
    free(err);
}

/* Unknown options and commands: exit 2, the usage on stderr, nothing on stdout. */
static void test_unknown_options(void **state)
{
    (void)state;
    static const char *const cases[][4] = {
        {"render", "--bogus", NULL}, {"info", "x.yaml", "--bogus", NULL}, {"plugins", "--bogus", NULL},
        {"compare", "--bogus", "a.exr", NULL}, {"check", "--bogus", NULL}, {"grid", "--bogus", NULL},
        {"frobnicate", NULL}, {"help", "frobnicate", NULL}, {"--bogus", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *out, *err;
        int st = run_murk_split(&out, &err, cases[i]);
        if (st != 2 || out[0])
            fail_msg("[murk %s %s] exit %d (want 2), stdout:\n%s\nstderr:\n%s", cases[i][0],
                     cases[i][1] ? cases[i][1] : "", st, out, err);
        assert_contains(err, "usage");
        free(out);
        free(err);
    }
}

static void test_info(void **state)
{
    (void)state;
    char *out, *err;
    char smoke[1024];
    snprintf(smoke, sizeof smoke, "%s", src_path("scenes/cornell_smoke.yaml"));
    const char *const a[] = {"info", smoke, "--set", "media.smoke.type=decomposition", "--set",
                             "media.smoke.transmittance=ratio", "--set", "media.smoke.majorant_factor=2", NULL};
    int st = run_murk_split(&out, &err, a);
    if (st != 0)
        fail_msg("murk info failed (%d):\n%s", st, err);
    static const char *const want[] = {
        "overrides   --set media.smoke.type=decomposition",
        "render      512x512, 128 spp, seed 0",
        "camera      from [0, 1, 3.4] at [0, 1, 0] up [0, 1, 0], fov 40, starts in vacuum",
        "integrator  volpath_nee { max_depth: 64 }",
        "media (1)\n  smoke\n    tracker        decomposition\n    transmittance  ratio\n",
        "sigma_a [0.5, 0.5, 0.5], sigma_s [18, 18, 18]",
        "grid 64x64x64 voxels over [-0.6, 0.05, -0.6]-[0.6, 1.45, 0.6], max 1",
        "majorant       14x16x14 cells, majorant_factor 2; largest majorant 37",
        "materials (4)\n  white          diffuse { albedo: [0.73, 0.73, 0.73] }",
        "shapes (7)\n  0   quad   material white, interior vacuum, exterior vacuum\n",
        "  5   quad   material light, interior vacuum, exterior vacuum, emission [17, 12, 4]\n",
        "  6   box    material none (index-matched boundary), interior smoke, exterior vacuum\n",
        "plugins (4)\n",
        "/plugins/decomposition.so (version ",
        "/plugins/ratio.so (version ",
        "/plugins/volpath_nee.so (version ",
        "/plugins/diffuse.so (version ",
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        assert_contains(out, want[i]);
    assert_not_contains(out, "delta.so"); /* the file's tracker was swapped, never loaded */
    free(out);
    free(err);

    /* a mesh shape, a constant density, an exterior medium */
    const char *p = write_tmp("info.yaml", "murk: 1\n"
                                           "camera: { medium: air }\n"
                                           "materials: { m: { type: ggx, roughness: 0.25 } }\n"
                                           "media:\n"
                                           "  air: { type: delta, sigma_s: 0.1 }\n"
                                           "  ink: { type: spectral, density: { constant: 2 }, sigma_a: [1, 2, 3] }\n"
                                           "shapes:\n"
                                           "  - { type: sphere, center: [0, 0, 0], radius: 1, material: m, "
                                           "interior: ink, exterior: air }\n");
    const char *const b[] = {"info", p, NULL};
    st = run_murk_split(&out, &err, b);
    if (st != 0)
        fail_msg("murk info failed (%d):\n%s", st, err);
    assert_contains(out, "starts in air");
    assert_contains(out, "  m              ggx { roughness: 0.25 }");
    assert_contains(out, "  ink\n    tracker        spectral\n    transmittance  the tracker's own (spectral)");
    assert_contains(out, "density        { constant: 2 }: constant 2, everywhere");
    assert_contains(out, "  0   sphere material m, interior ink, exterior air\n");
    free(out);
    free(err);

    /* the same errors as murk render, nothing on stdout */
    const char *const c[] = {"info", smoke, "--set", "media.smok.type=spectral", NULL};
    assert_int_equal(run_murk_split(&out, &err, c), 1);
    assert_string_equal(out, "");
    assert_string_equal(err, "--set media.smok.type=spectral: media.smok is not used by any shape or by the camera; "
                             "did you mean media.smoke?\n");
    free(out);
    free(err);
}

/* `murk info IMAGE.png` prints the text keys of a preview murk wrote: murk:commit is the commit
 * `murk --version` names; the EXR beside it carries the same. */
static void test_info_image(void **state)
{
    (void)state;
    const char *scene = write_tmp("img.yaml", "murk: 1\n"
                                              "render: { resolution: [4, 4], spp: 1 }\n"
                                              "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }\n");
    char *out = NULL, *err = NULL, exr[1024], png[1024], want[256];
    snprintf(exr, sizeof exr, "%s", tmp_path("img.exr"));
    snprintf(png, sizeof png, "%s", tmp_path("img.png"));
    const char *const r[] = {"render", scene, "-o", exr, "--quiet", NULL};
    assert_int_equal(run_murk_split(&out, &err, r), 0);
    free(out);
    free(err);
    const char *const v[] = {"--version", NULL};
    assert_int_equal(run_murk_split(&out, &err, v), 0);
    const char *c = strstr(out, "(commit ");
    assert_non_null(c);
    snprintf(want, sizeof want, "murk:commit: %.*s\n", (int)strcspn(c + 8, ","), c + 8);
    free(out);
    free(err);
    for (int k = 0; k < 2; k++) {
        const char *const a[] = {"info", k ? exr : png, NULL};
        assert_int_equal(run_murk_split(&out, &err, a), 0);
        assert_contains(out, ": 4x4\n");
        assert_contains(out, want);
        assert_contains(out, "murk:version: ");
        free(out);
        free(err);
    }
    const char *const bad[] = {"info", png, "--set", "render.spp=2", NULL};
    assert_int_equal(run_murk_split(&out, &err, bad), 2);
    free(out);
    free(err);
}

/* A process confined to one CPU (as mpirun's default binding confines a rank) and asked for 2 threads
 * says so; without --threads it takes 1, the CPUs it may run on. taskset is util-linux's. */
static void test_affinity(void **state)
{
    (void)state;
    if (access("/usr/bin/taskset", X_OK) != 0)
        skip();
    const char *scene = write_tmp("aff.yaml", "murk: 1\n"
                                              "render: { resolution: [8, 8], spp: 1 }\n"
                                              "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }\n");
    const char *murk = getenv("MURK_EXE") ? getenv("MURK_EXE") : "build/core/murk";
    char *log = NULL;
    const char *const two[] = {"/usr/bin/taskset", "-c", "0", murk, "render", scene, "-o", tmp_path("aff.exr"),
                               "--threads", "2", NULL};
    assert_int_equal(run_argv(&log, two), 0);
    assert_contains(log, "2 render threads, but this process may run on 1 CPU only (its CPU affinity; under "
                         "mpirun: --bind-to none)");
    free(log);
    const char *const dflt[] = {"/usr/bin/taskset", "-c", "0", murk, "render", scene, "-o", tmp_path("aff.exr"), NULL};
    assert_int_equal(run_argv(&log, dflt), 0);
    assert_true(strstr(log, "render threads, but") == NULL);
    free(log);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The names in dir, sorted, space-separated. */
static void dir_names(const char *dir, char *buf, size_t n)
{
    struct dirent **e;
    int k = scandir(dir, &e, NULL, alphasort);
    assert_true(k >= 0);
    buf[0] = 0;
    for (int i = 0; i < k; i++) {
        if (e[i]->d_name[0] != '.')
            snprintf(buf + strlen(buf), n - strlen(buf), "%s%s", buf[0] ? " " : "", e[i]->d_name);
        free(e[i]);
    }
    free(e);
}

/* Renders the small Cornell box with `spp` samples and the extra arguments (NULL-terminated): the exit
 * status, the output in *out and the seconds it took in *secs. */
static int render_cornell(const char *exr, const char *spp, const char *const *extra, char **out, double *secs)
{
    const char *args[32] = {"render", src_path("scenes/cornell.yaml"), "-o", exr, "--spp", spp, "--threads", "2",
                            "--quiet", "--set", "render.resolution=[48,40]"};
    int n = 11;
    for (int i = 0; extra && extra[i]; i++)
        args[n++] = extra[i];
    args[n] = NULL;
    double t0 = now();
    int rc = run_murk_argv(out, args);
    *secs = now() - t0;
    return rc;
}

/* An output that cannot be written — the image in a folder that does not exist or is a file, its PNG
 * preview a directory, MURK_SAMPLE_DUMP's file in a missing folder, a folder without write permission —
 * is a one-line error, exit 1, in under half the time of a render of about 5 s: murk found it only
 * when writing, after the whole render. Nothing is written. */
static void test_outputs_checked_first(void **state)
{
    (void)state;
    char *out = NULL, names[1024], spp[32], dir[4096];
    double secs;
    snprintf(dir, sizeof dir, "%s", tmp_path("outputs")); /* tmp_path's buffers rotate */
    mkdir(dir, 0777);
    double t[2];
    for (int k = 0; k < 2; k++) { /* a render of about 5 s: seconds per spp from 4 and 36 spp */
        assert_int_equal(render_cornell(tmp_path("outputs/probe.exr"), k ? "36" : "4", NULL, &out, &t[k]), 0);
        free(out);
    }
    snprintf(spp, sizeof spp, "%d", (int)(5.0 / ((t[1] - t[0]) / 32 > 1e-4 ? (t[1] - t[0]) / 32 : 1e-4)));
    assert_int_equal(mkdir(tmp_path("outputs/o.png"), 0777), 0);
    fclose(fopen(tmp_path("outputs/file"), "w"));
    remove(tmp_path("outputs/probe.exr"));
    remove(tmp_path("outputs/probe.png"));
    struct {
        const char *exr, *dump, *says;
    } cases[] = {
        {"outputs/missing/o.exr", NULL, "missing/o.exr: cannot write the image: No such file or directory"},
        {"outputs/file/o.exr", NULL, "file/o.exr: cannot write the image: Not a directory"},
        {"outputs/o.exr", NULL, "o.png: is a directory; murk only replaces regular files"},
        {"outputs/d.exr", "outputs/missing/d.bin", "cannot write the sample dump (MURK_SAMPLE_DUMP): No such file"},
        {"outputs/ro/o.exr", NULL, "ro/o.exr: cannot write the image: Permission denied"},
    };
    mkdir(tmp_path("outputs/ro"), 0555); /* root may write there anyway: that case only when not root */
    for (size_t i = 0; i < sizeof cases / sizeof cases[0] - (geteuid() == 0); i++) {
        if (cases[i].dump)
            setenv("MURK_SAMPLE_DUMP", tmp_path(cases[i].dump), 1);
        int rc = render_cornell(tmp_path(cases[i].exr), spp, NULL, &out, &secs);
        unsetenv("MURK_SAMPLE_DUMP");
        if (secs >= 2.5) /* half the render's 5 s: start-up alone may take a second (sanitizers, load) */
            fail_msg("%s: refused after %.2f s, not before rendering:\n%s", cases[i].exr, secs, out);
        assert_int_equal(rc, 1);
        assert_contains(out, cases[i].says);
        assert_ptr_equal(strchr(out, '\n'), out + strlen(out) - 1);
        free(out);
    }
    dir_names(dir, names, sizeof names);
    assert_string_equal(names, "file o.png ro");
    dir_names(tmp_path("outputs/o.png"), names, sizeof names);
    assert_string_equal(names, "");
}

int main(void)
{
    unsetenv("MURK_PLUGIN_PATH");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_help_everywhere),
        cmocka_unit_test(test_unknown_options),
        cmocka_unit_test(test_info),
        cmocka_unit_test(test_info_image),
        cmocka_unit_test(test_affinity),
        cmocka_unit_test(test_outputs_checked_first),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
