/* test_resume.c — interrupt and resume (issue 10, item 7). Renders are killed with SIGINT, SIGTERM or SIGHUP at
 * random points (during a pass, during a checkpoint or image write, before rendering starts), resumed
 * from their checkpoint, killed again, ... until they finish; the finished image must be bitwise
 * identical to an uninterrupted render of the same spp. An interrupted render must exit with 128 + the
 * signal, write the image of the spp it reached (murk:spp, murk:interrupted) or nothing, and leave no
 * temporary file behind. A checkpoint of another scene / other overrides is refused. A SIGHUP that was
 * ignored when murk started (nohup) stays ignored. A --checkpoint that cannot be written is refused
 * before the first sample. */
#include "image/image.h"
#include "testutil.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define SPP "96"

static const char *scene_path(void) { return src_path("scenes/cornell.yaml"); }

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Starts `murk render` on the small Cornell box into dir/out with extra arguments (NULL-terminated). */
static int ignore_hup; /* start_render's child starts murk with SIGHUP ignored, as nohup does */

static pid_t start_render(const char *dir, const char *out, const char *const *extra)
{
    const char *exe = getenv("MURK_EXE");
    assert_non_null(exe);
    const char *argv[32];
    int n = 0;
    argv[n++] = exe;
    argv[n++] = "render";
    argv[n++] = scene_path();
    argv[n++] = "-o";
    argv[n++] = out;
    argv[n++] = "--spp";
    argv[n++] = SPP;
    argv[n++] = "--threads";
    argv[n++] = "2";
    argv[n++] = "--set";
    argv[n++] = "render.resolution=[48,40]";
    argv[n++] = "--quiet";
    for (int i = 0; extra && extra[i]; i++)
        argv[n++] = extra[i];
    argv[n] = NULL;
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (chdir(dir) != 0)
            _exit(126);
        signal(SIGHUP, ignore_hup ? SIG_IGN : SIG_DFL);
        int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
        }
        execv(exe, (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static const char *sig_name(int sig) { return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGHUP"; }

static int wait_status(pid_t pid)
{
    int st;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    return st;
}

static int exists(const char *dir, const char *name)
{
    char p[4096];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    struct stat st;
    return stat(p, &st) == 0;
}

static void no_temporaries(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strstr(e->d_name, ".tmp-")) {
            fprintf(stderr, "temporary left behind: %s/%s\n", dir, e->d_name);
            fail();
        }
    }
    closedir(d);
}

static void read_exr(const char *dir, const char *name, murk_image *img)
{
    char p[4096], err[1024];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    if (murk_exr_read(p, img, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        fail();
    }
}

static const char *make_dir(const char *name)
{
    static char buf[4][4096];
    static int k;
    char *p = buf[k++ % 4];
    snprintf(p, 4096, "%s/%s", tmp_dir(), name);
    mkdir(p, 0777);
    return p;
}

static double t_ref; /* seconds an uninterrupted render takes */
static murk_image ref;

static void render_reference(void)
{
    if (ref.rgb)
        return;
    const char *dir = make_dir("ref");
    double t0 = now();
    assert_int_equal(wait_status(start_render(dir, "ref.exr", NULL)), 0);
    t_ref = now() - t0;
    read_exr(dir, "ref.exr", &ref);
    assert_string_equal(murk_image_meta(&ref, "murk:spp"), SPP);
    assert_string_equal(murk_image_meta(&ref, "murk:interrupted"), "no");
    fprintf(stderr, "reference render: %.2f s\n", t_ref);
}

/* Kills renders at random points and resumes them until one finishes; returns the number of kills that
 * interrupted a render. */
static int kill_and_resume(unsigned seed, int round, int *interrupted_images)
{
    char name[64];
    snprintf(name, sizeof name, "round%d", round);
    const char *dir = make_dir(name);
    srand(seed);
    int kills = 0;
    for (int attempt = 0; attempt < 40; attempt++) {
        int resume = exists(dir, "ck");
        const char *extra[] = {"--checkpoint", "ck", "--every", "0", resume ? "--resume" : NULL, "ck", NULL};
        char out[64];
        snprintf(out, sizeof out, "out%d.exr", attempt);
        int last = attempt >= 6; /* after six kills, let it finish */
        pid_t pid = start_render(dir, out, extra);
        int sig = 0;
        if (!last) {
            double frac = (double)rand() / RAND_MAX;
            struct timespec ts = {0, 0};
            double d = frac * 0.6 * t_ref + 0.002;
            ts.tv_sec = (time_t)d;
            ts.tv_nsec = (long)((d - (double)ts.tv_sec) * 1e9);
            nanosleep(&ts, NULL);
            static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
            sig = sigs[rand() % 3];
            kill(pid, sig);
        }
        int st = wait_status(pid);
        no_temporaries(dir);
        if (WIFSIGNALED(st)) { /* killed before murk caught the signals: nothing written */
            assert_int_equal(WTERMSIG(st), sig);
            assert_false(exists(dir, out));
            continue;
        }
        assert_true(WIFEXITED(st));
        int rc = WEXITSTATUS(st);
        if (rc == 0) {
            murk_image img = {0};
            read_exr(dir, out, &img);
            assert_string_equal(murk_image_meta(&img, "murk:spp"), SPP);
            assert_string_equal(murk_image_meta(&img, "murk:interrupted"), "no");
            assert_int_equal(img.w, ref.w);
            assert_int_equal(img.h, ref.h);
            if (memcmp(img.rgb, ref.rgb, 3 * sizeof(float) * (size_t)img.w * (size_t)img.h) != 0) {
                fprintf(stderr, "round %d: resumed render differs from the uninterrupted one\n", round);
                fail();
            }
            murk_image_free(&img);
            return kills;
        }
        assert_int_equal(rc, 128 + sig);
        kills++;
        if (exists(dir, out)) { /* the signal may also cut the image write short: then nothing is written */
            murk_image img = {0};
            read_exr(dir, out, &img);
            const char *spp = murk_image_meta(&img, "murk:spp"), *why = murk_image_meta(&img, "murk:interrupted");
            assert_non_null(spp);
            assert_non_null(why);
            char expect[96];
            snprintf(expect, sizeof expect, "%s after %s of " SPP " spp", sig_name(sig), spp);
            if (strcmp(spp, SPP) == 0) { /* the signal came after the last pass: the image is whole */
                assert_string_equal(why, "no");
                assert_memory_equal(img.rgb, ref.rgb, 3 * sizeof(float) * (size_t)img.w * (size_t)img.h);
            } else {
                assert_string_equal(why, expect);
                assert_true(atoi(spp) < atoi(SPP));
                (*interrupted_images)++;
            }
            murk_image_free(&img);
        }
    }
    fail_msg("the render never finished");
    return kills;
}

static void test_kill_resume_bitwise(void **state)
{
    (void)state;
    render_reference();
    int kills = 0, images = 0;
    const char *seed_env = getenv("MURK_RESUME_SEED");
    unsigned seed = seed_env ? (unsigned)strtoul(seed_env, NULL, 10) : (unsigned)time(NULL);
    fprintf(stderr, "MURK_RESUME_SEED=%u\n", seed);
    for (int round = 0; round < 4; round++)
        kills += kill_and_resume(seed + (unsigned)round, round, &images);
    fprintf(stderr, "%d renders interrupted (%d wrote their partial image), every resumed render bitwise identical\n",
            kills, images);
    assert_true(kills > 0);
}

/* A render interrupted mid-way by SIGINT (a terminal's Ctrl-C) or SIGHUP (its terminal closed): status
 * 128 + the signal, the image of the spp reached, metadata saying so. */
static void test_interrupted_image(void **state)
{
    (void)state;
    render_reference();
    static const int sigs[] = {SIGINT, SIGHUP};
    for (int i = 0; i < 2; i++) {
        const char *dir = make_dir(i ? "interrupt_hup" : "interrupt");
        const char *extra[] = {"--spp", "100000", "--checkpoint", "ck", "--every", "0", NULL};
        pid_t pid = start_render(dir, "int.exr", extra);
        struct timespec ts = {0, 20 * 1000 * 1000};
        for (int k = 0; k < 3000 && !exists(dir, "ck"); k++) /* the first whole pass is done */
            nanosleep(&ts, NULL);
        kill(pid, sigs[i]);
        int st = wait_status(pid);
        assert_true(WIFEXITED(st));
        assert_int_equal(WEXITSTATUS(st), 128 + sigs[i]);
        no_temporaries(dir);
        murk_image img = {0};
        read_exr(dir, "int.exr", &img);
        int spp = atoi(murk_image_meta(&img, "murk:spp"));
        assert_true(spp >= 1 && spp < 100000);
        char expect[96];
        snprintf(expect, sizeof expect, "%s after %d of 100000 spp", sig_name(sigs[i]), spp);
        assert_string_equal(murk_image_meta(&img, "murk:interrupted"), expect);
        assert_string_equal(murk_image_meta(&img, "murk:spp_requested"), "100000");
        murk_image_free(&img);
        assert_true(exists(dir, "int.png"));
    }
}

/* Started with SIGHUP ignored (`nohup murk render ...`), murk keeps ignoring it: a SIGHUP after the first
 * pass changes nothing, and the SIGINT that then stops the render is the one the image names. */
static void test_nohup_keeps_rendering(void **state)
{
    (void)state;
    const char *dir = make_dir("nohup");
    const char *extra[] = {"--spp", "100000", "--checkpoint", "ck", "--every", "0", NULL};
    ignore_hup = 1;
    pid_t pid = start_render(dir, "int.exr", extra);
    ignore_hup = 0;
    struct timespec ts = {0, 20 * 1000 * 1000};
    for (int k = 0; k < 3000 && !exists(dir, "ck"); k++)
        nanosleep(&ts, NULL);
    kill(pid, SIGHUP);
    nanosleep(&ts, NULL);
    nanosleep(&ts, NULL);
    assert_int_equal(waitpid(pid, NULL, WNOHANG), 0); /* still rendering */
    kill(pid, SIGINT);
    int st = wait_status(pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 130);
    murk_image img = {0};
    read_exr(dir, "int.exr", &img);
    const char *why = murk_image_meta(&img, "murk:interrupted");
    assert_non_null(why);
    assert_true(strncmp(why, "SIGINT after ", 13) == 0);
    murk_image_free(&img);
}

/* --resume refuses a checkpoint of another scene, of other overrides, or with more spp than asked. */
static void test_resume_refuses(void **state)
{
    (void)state;
    const char *dir = make_dir("refuse");
    char ck[4096];
    snprintf(ck, sizeof ck, "%s/ck", dir);
    const char *extra[] = {"--checkpoint", "ck", NULL};
    assert_int_equal(wait_status(start_render(dir, "a.exr", extra)), 0);
    assert_true(exists(dir, "ck"));
    char *out = NULL;
    int rc = run_murk(&out, "render", src_path("scenes/cornell_smoke.yaml"), "-o", build_path("x_resume.exr"),
                      "--resume", ck, "--quiet", NULL);
    assert_int_equal(rc, 1);
    assert_contains(out, "checkpoint of another scene");
    free(out);
    rc = run_murk(&out, "render", scene_path(), "-o", build_path("x_resume.exr"), "--resume", ck, "--quiet", "--set",
                  "render.resolution=[48,41]", NULL);
    assert_int_equal(rc, 1);
    assert_contains(out, "other --set overrides");
    free(out);
    rc = run_murk(&out, "render", scene_path(), "-o", build_path("x_resume.exr"), "--resume", ck, "--quiet", "--set",
                  "render.resolution=[48,40]", "--spp", "8", NULL);
    assert_int_equal(rc, 1);
    assert_contains(out, "more than the 8 asked for");
    free(out);
    /* a damaged checkpoint */
    FILE *f = fopen(ck, "r+b");
    assert_non_null(f);
    fseek(f, 100, SEEK_SET);
    fputc(0x5a, f);
    fclose(f);
    rc = run_murk(&out, "render", scene_path(), "-o", build_path("x_resume.exr"), "--resume", ck, "--quiet", "--set",
                  "render.resolution=[48,40]", NULL);
    assert_int_equal(rc, 1);
    assert_contains(out, "damaged checkpoint");
    free(out);
}

/* The checkpoint's content hash covers the files the scene loads: after the scene's mesh, density grid
 * or texture changed, --resume is refused; unchanged, it resumes. */
static void test_resume_refuses_changed_inputs(void **state)
{
    (void)state;
    const char *dir = make_dir("inputs");
    char path[4096], ck[4096], exr[4096], grid[4096];
    snprintf(grid, sizeof grid, "%s/g.vol", dir);
    char *out = NULL;
    assert_int_equal(run_murk(&out, "grid", grid, "--res", "8", NULL), 0);
    free(out);
    char tex[4096]; /* a texture: the PNG preview of a tiny render */
    snprintf(tex, sizeof tex, "%s/tex.exr", dir);
    assert_int_equal(run_murk(&out, "render", scene_path(), "-o", tex, "--spp", "1", "--quiet", "--set",
                              "render.resolution=[4,4]", NULL), 0);
    free(out);
    snprintf(path, sizeof path, "%s/m.obj", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n", f);
    fclose(f);
    snprintf(path, sizeof path, "%s/s.yaml", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("murk: 1\nrender: { resolution: [8, 8], spp: 4 }\nintegrator: { type: volpath_nee }\n"
          "materials: { w: { type: diffuse, albedo: { texture: image, file: tex.png } } }\n"
          "media: { g: { type: delta, density: { grid: g.vol } } }\n"
          "shapes:\n"
          "  - { type: mesh, file: m.obj, material: w, emission: 1 }\n"
          "  - { type: box, min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5], interior: g }\n", f);
    fclose(f);
    snprintf(ck, sizeof ck, "%s/ck", dir);
    snprintf(exr, sizeof exr, "%s/a.exr", dir);
    /* each step: a fresh 2-spp checkpoint, one input changed (the mesh by a comment: the content is what
     * counts; the grid baked with another seed; the texture rendered with another seed), --resume */
    char obj[4096];
    snprintf(obj, sizeof obj, "%s/m.obj", dir);
    for (int step = 0; step < 4; step++) {
        assert_int_equal(run_murk(&out, "render", path, "-o", exr, "--spp", "2", "--checkpoint", ck, "--quiet", NULL), 0);
        free(out);
        if (step == 1) {
            f = fopen(obj, "a");
            assert_non_null(f);
            fputs("# edited\n", f);
            fclose(f);
        } else if (step == 2) {
            assert_int_equal(run_murk(&out, "grid", grid, "--res", "8", "--seed", "2", NULL), 0);
            free(out);
        } else if (step == 3) {
            assert_int_equal(run_murk(&out, "render", scene_path(), "-o", tex, "--spp", "1", "--quiet", "--set",
                                      "render.resolution=[4,4]", "--set", "render.seed=9", NULL), 0);
            free(out);
        }
        int rc = run_murk(&out, "render", path, "-o", exr, "--resume", ck, "--quiet", NULL);
        if (step == 0) /* unchanged: resumes */
            assert_int_equal(rc, 0);
        else {
            assert_int_equal(rc, 1);
            assert_contains(out, "a file it loads (mesh, grid, texture) changed since");
        }
        free(out);
    }
}

/* A --checkpoint in a folder that does not exist, or is a file, or (when not root) has no write
 * permission: one line, exit 1, in under half the time of a render of 5 s or more, and no image —
 * murk found it only after the whole render, which it wrote, unprotected all along. */
static void test_unwritable_checkpoint(void **state)
{
    (void)state;
    render_reference();
    const char *dir = make_dir("unwritable");
    char spp[32], file[4096], ro[4096];
    snprintf(spp, sizeof spp, "%d", (int)(atoi(SPP) * 5.0 / t_ref) + 1); /* at least 5 s of rendering */
    snprintf(file, sizeof file, "%s/file", dir);
    fclose(fopen(file, "w"));
    snprintf(ro, sizeof ro, "%s/ro", dir);
    mkdir(ro, 0555);
    static const char *const cks[][2] = {{"missing/ck", "No such file or directory"},
                                         {"file/ck", "Not a directory"},
                                         {"ro/ck", "Permission denied"}};
    for (size_t i = 0; i < 3 - (geteuid() == 0); i++) { /* root may write into ro/ */
        char ck[4096], exr[4096], want[4200], *out = NULL;
        snprintf(ck, sizeof ck, "%s/%s", dir, cks[i][0]);
        snprintf(exr, sizeof exr, "%s/o.exr", dir);
        double t0 = now();
        int rc = run_murk(&out, "render", scene_path(), "-o", exr, "--spp", spp, "--threads", "2", "--quiet",
                          "--set", "render.resolution=[48,40]", "--checkpoint", ck, NULL);
        double secs = now() - t0;
        if (secs >= 2.5) /* half the render's 5 s: start-up alone may take a second (sanitizers, load) */
            fail_msg("--checkpoint %s: refused after %.2f s (a render of %s spp), not before it:\n%s", cks[i][0],
                     secs, spp, out);
        assert_int_equal(rc, 1);
        snprintf(want, sizeof want, "murk: %s: cannot write the checkpoint: %s\n", ck, cks[i][1]);
        assert_string_equal(out, want);
        free(out);
        assert_false(exists(dir, "o.exr"));
        assert_false(exists(dir, "o.png"));
        no_temporaries(dir);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_resume_refuses),
        cmocka_unit_test(test_resume_refuses_changed_inputs),
        cmocka_unit_test(test_unwritable_checkpoint),
        cmocka_unit_test(test_interrupted_image),
        cmocka_unit_test(test_nohup_keeps_rendering),
        cmocka_unit_test(test_kill_resume_bitwise),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    murk_image_free(&ref);
    return rc;
}
