/* testutil.c — see testutil.h */
#include "testutil.h"
#include "stat.h"
#include "image/image.h"
#include "lab/check/sphere.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *env_or(const char *name, const char *fallback)
{
    const char *v = getenv(name);
    return v && *v ? v : fallback;
}

static const char *join(const char *root, const char *rel)
{
    static char bufs[8][4096];
    static int next;
    char *b = bufs[next++ & 7];
    snprintf(b, sizeof bufs[0], "%s/%s", root, rel);
    return b;
}

const char *src_path(const char *rel) { return join(env_or("MURK_SOURCE_ROOT", "."), rel); }
const char *build_path(const char *rel) { return join(env_or("MURK_BUILD_ROOT", "build"), rel); }
const char *tmp_path(const char *name) { return join(tmp_dir(), name); }

const char *tmp_dir(void)
{
    static char dir[256];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/murk-test-XXXXXX");
        if (!mkdtemp(dir)) {
            perror("mkdtemp");
            exit(1);
        }
    }
    return dir;
}

const char *write_tmp(const char *name, const char *text)
{
    const char *path = join(tmp_dir(), name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        exit(1);
    }
    fputs(text, f);
    fclose(f);
    return path;
}

int run_murk(char **out, const char *arg0, ...)
{
    const char *args[64];
    int n = 0;
    va_list ap;
    va_start(ap, arg0);
    for (const char *a = arg0; a && n < 63; a = va_arg(ap, const char *))
        args[n++] = a;
    va_end(ap);
    args[n] = NULL;
    return run_murk_argv(out, args);
}

/* A whole file as a malloc'd string ("" if it cannot be read). */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    size_t n = 0, cap = 4096;
    char *buf = malloc(cap);
    if (f) {
        size_t r;
        while ((r = fread(buf + n, 1, cap - n - 1, f)) > 0) {
            n += r;
            if (cap - n < 2)
                buf = realloc(buf, cap *= 2);
        }
        fclose(f);
    }
    buf[n] = 0;
    return buf;
}

static int run_argv_split(char **out, char **err, const char *const *argv);

/* Runs murk with stdout into *out and stderr into *err, or both into *out when err is NULL. */
static int run_captured(char **out, char **err, const char *const *args)
{
    const char *argv[96];
    int argc = 0;
    argv[argc++] = env_or("MURK_EXE", "build/core/murk");
    for (; *args && argc < 95; args++)
        argv[argc++] = *args;
    argv[argc] = NULL;
    return run_argv_split(out, err, argv);
}

int run_argv(char **out, const char *const *argv) { return run_argv_split(out, NULL, argv); }

/* Runs argv (argv[0] a path) with stdout into *out and stderr into *err, or both into *out if err is NULL. */
static int run_argv_split(char **out, char **err, const char *const *argv)
{
    char logpath[512], errpath[512];
    snprintf(logpath, sizeof logpath, "%s/run-%d.log", tmp_dir(), (int)getpid());
    snprintf(errpath, sizeof errpath, "%s/run-%d.err", tmp_dir(), (int)getpid());
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(logpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fe = err ? open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644) : fd;
        if (fd < 0 || fe < 0)
            _exit(127);
        dup2(fd, 1);
        dup2(fe, 2);
        close(fd);
        if (fe != fd)
            close(fe);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (out)
        *out = slurp(logpath);
    if (err)
        *err = slurp(errpath);
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
}

int run_murk_argv(char **out, const char *const *args) { return run_captured(out, NULL, args); }

int run_murk_split(char **out, char **err, const char *const *args) { return run_captured(out, err, args); }

void assert_refused(char *log, int rc, const char *where, const char *needle, const char *out)
{
    printf("  %s", log ? log : "(no output)\n");
    if (rc != 1)
        fail_msg("exit %d, expected 1", rc);
    assert_contains(log, where);
    assert_contains(log, needle);
    struct stat st;
    assert_true(stat(out, &st) != 0);
    free(log);
}

/* The same chi-square test as `murk check` (core/lab/check/sphere.c). */
double chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out)
{
    return murk_chi2_test(observed, expected, nbins, min_expected, dof_out);
}

/* ---- image stacks -------------------------------------------------------------------------- */

void img_stack_render(img_stack *st, const char *scene, const char *out, int nseeds, int seed0,
                      const char *const *extra)
{
    char path[512], seed[64];
    snprintf(path, sizeof path, "%s/%s", tmp_dir(), out);
    memset(st, 0, sizeof *st);
    st->n = nseeds;
    for (int k = 0; k < nseeds; k++) {
        snprintf(seed, sizeof seed, "render.seed=%d", seed0 + k);
        const char *args[64] = {"render", scene, "-o", path, "--threads", "2", "--quiet", "--set", seed};
        int na = 9;
        for (; extra && extra[na - 9] && na < 63; na++)
            args[na] = extra[na - 9];
        args[na] = NULL;
        char *log = NULL;
        int rc = run_murk_argv(&log, args);
        if (rc != 0)
            fail_msg("murk render %s failed (%d):\n%s", scene, rc, log);
        free(log);
        murk_image img;
        char err[512];
        if (murk_exr_read(path, &img, err, sizeof err) != 0)
            fail_msg("%s", err);
        const char *nf = murk_image_meta(&img, "murk:nonfinite_samples");
        if (!nf || strcmp(nf, "0") != 0)
            fail_msg("%s: %s NaN/inf samples", scene, nf ? nf : "(no count)");
        size_t np = (size_t)img.w * (size_t)img.h;
        if (k == 0) {
            st->w = img.w;
            st->h = img.h;
            st->mean = calloc(np, sizeof *st->mean);
            st->var = calloc(np, sizeof *st->var); /* sums of squares until the end */
            assert_non_null(st->mean);
            assert_non_null(st->var);
        }
        assert_int_equal(img.w, st->w);
        assert_int_equal(img.h, st->h);
        for (size_t p = 0; p < np; p++) {
            double v[4] = {img.rgb[3 * p], img.rgb[3 * p + 1], img.rgb[3 * p + 2], 0.0};
            v[3] = (v[0] + v[1] + v[2]) / 3.0;
            for (int c = 0; c < 4; c++) {
                st->mean[p][c] += v[c];
                st->var[p][c] += v[c] * v[c];
            }
        }
        murk_image_free(&img);
    }
    size_t np = (size_t)st->w * (size_t)st->h;
    for (size_t p = 0; p < np; p++)
        for (int c = 0; c < 4; c++) {
            double mu = st->mean[p][c] / nseeds;
            st->mean[p][c] = mu;
            st->var[p][c] = fmax(0.0, (st->var[p][c] - nseeds * mu * mu) / (nseeds - 1)) / nseeds;
        }
}

void img_stack_free(img_stack *st)
{
    free(st->mean);
    free(st->var);
    memset(st, 0, sizeof *st);
}

/* The comparison of img_stack_agree; *zworst: the largest of the blocks' |z| and the mean z over the blocks
 * in units of its own standard error (both judged against STAT_Z). Counts its decisions if count. */
static int stack_compare(const char *label, const img_stack *a, const img_stack *r, int block, int count, double *zworst)
{
    assert_int_equal(a->w, r->w);
    assert_int_equal(a->h, r->h);
    const int nbx = r->w / block, nby = r->h / block;
    int nblocks = 0, ntests = 0; /* blocks with signal (all-black blocks have no variance and carry no information) */
    double zmax = 0.0, zsum = 0.0, rel = 0.0, sum_ref = 0.0;
    int zmax_x = -1, zmax_y = -1, zmax_c = -1;
    for (int by = 0; by < nby; by++)
        for (int bx = 0; bx < nbx; bx++)
            for (int c = 0; c < 4; c++) {
                double ma = 0, mr = 0, va = 0, vr = 0;
                for (int y = 0; y < block; y++)
                    for (int x = 0; x < block; x++) {
                        size_t p = (size_t)(by * block + y) * (size_t)r->w + (size_t)(bx * block + x);
                        ma += a->mean[p][c];
                        mr += r->mean[p][c];
                        va += a->var[p][c];
                        vr += r->var[p][c];
                    }
                const double n = (double)block * block;
                if (!(va + vr > 0.0)) {
                    if (ma != mr && c < 3) { /* no noise but a difference: certainly not the same image */
                        zmax = INFINITY;
                        zmax_x = bx, zmax_y = by, zmax_c = c;
                    }
                    continue;
                }
                double z = (ma - mr) / sqrt(va + vr);
                if (c == 3) {
                    nblocks++;
                    zsum += z;
                    rel += sqrt(vr) / n; /* se of the reference's block mean */
                    sum_ref += mr / n;
                } else {
                    ntests++;
                    if (fabs(z) > zmax) {
                        zmax = fabs(z);
                        zmax_x = bx, zmax_y = by, zmax_c = c;
                    }
                }
            }
    if (nblocks < 16) {
        printf("  %-44s only %d blocks with signal  <-- FAIL\n", label, nblocks);
        *zworst = 0.0;
        return 0;
    }
    if (count)
        stat_count(ntests + 1, stat_tail2(STAT_Z));
    double zmean = zsum / nblocks, zm = zmean * sqrt((double)nblocks);
    *zworst = fmax(zmax, fabs(zm));
    int ok = zmax <= STAT_Z && fabs(zm) <= STAT_Z;
    printf("  %-44s max |z| %.2f (block %d,%d ch %d), mean z %+.3f over %d blocks (%+.2f se), block se %.2f%%: %s\n",
           label, zmax, zmax_x, zmax_y, zmax_c, zmean, nblocks, zm, 100.0 * rel / sum_ref, ok ? "agree" : "DIFFER");
    return ok;
}

int img_stack_agree(const char *label, const img_stack *a, const img_stack *r, int block)
{
    double z;
    return stack_compare(label, a, r, block, 1, &z);
}

int img_stack_must_differ(const char *label, const img_stack *a, const img_stack *r, int block)
{
    double z;
    int agree = stack_compare(label, a, r, block, 0, &z);
    return stat_must_fail(label, !agree, z);
}

int img_stack_must_differ_block(const char *label, const img_stack *a, const img_stack *r, int block, double bias)
{
    size_t np = (size_t)a->w * (size_t)a->h;
    img_stack b = *a;
    b.mean = malloc(np * sizeof *b.mean);
    assert_non_null(b.mean);
    memcpy(b.mean, a->mean, np * sizeof *b.mean);
    int bx = a->w / block / 2, by = a->h / block / 2; /* the block at the centre */
    if (!(bias > 0.0)) { /* 10 standard errors of the block's difference in its noisiest channel */
        for (int c = 0; c < 3; c++) {
            double m = 0.0, v = 0.0;
            for (int y = by * block; y < (by + 1) * block; y++)
                for (int x = bx * block; x < (bx + 1) * block; x++) {
                    size_t p = (size_t)y * (size_t)a->w + (size_t)x;
                    m += a->mean[p][c];
                    v += a->var[p][c] + r->var[p][c];
                }
            bias = fmax(bias, m > 0.0 ? 10.0 * sqrt(v) / m : 0.0);
        }
    }
    for (int y = by * block; y < (by + 1) * block; y++)
        for (int x = bx * block; x < (bx + 1) * block; x++)
            for (int c = 0; c < 4; c++)
                b.mean[(size_t)y * (size_t)a->w + (size_t)x][c] *= 1.0 + bias;
    char l[256];
    snprintf(l, sizeof l, "%s, block (%d,%d) %+.2g%%", label, bx, by, 100.0 * bias);
    int ok = img_stack_must_differ(l, &b, r, block);
    free(b.mean);
    return ok;
}

void run_murk_ok(const char *const *args, const char *const *extra)
{
    const char *all[65];
    size_t n = 0;
    for (size_t i = 0; args[i] && n < 64; i++)
        all[n++] = args[i];
    for (size_t i = 0; extra && extra[i] && n < 64; i++)
        all[n++] = extra[i];
    all[n] = NULL;
    char *log = NULL;
    int rc = run_murk_argv(&log, all);
    if (rc != 0)
        fail_msg("murk %s failed (%d):\n%s", args[0], rc, log ? log : "");
    free(log);
}

int same_pixels(const char *a, const char *b)
{
    murk_image A = {0}, B = {0};
    char err[1024];
    if (murk_exr_read(a, &A, err, sizeof err) != 0 || murk_exr_read(b, &B, err, sizeof err) != 0)
        fail_msg("%s", err);
    int same = A.w == B.w && A.h == B.h && memcmp(A.rgb, B.rgb, 3 * sizeof(float) * (size_t)A.w * (size_t)A.h) == 0;
    murk_image_free(&A);
    murk_image_free(&B);
    return same;
}

void assert_same_pixels(const char *a, const char *b)
{
    murk_image A = {0}, B = {0};
    char err[1024];
    if (murk_exr_read(a, &A, err, sizeof err) != 0 || murk_exr_read(b, &B, err, sizeof err) != 0)
        fail_msg("%s", err);
    if (A.w != B.w || A.h != B.h)
        fail_msg("%s is %dx%d, %s is %dx%d", a, A.w, A.h, b, B.w, B.h);
    size_t n = 3 * (size_t)A.w * (size_t)A.h;
    for (size_t i = 0; i < n; i++)
        if (memcmp(&A.rgb[i], &B.rgb[i], sizeof(float)) != 0)
            fail_msg("%s and %s differ first at pixel (%zu, %zu) channel %zu: %.9g vs %.9g", a, b,
                     i / 3 % (size_t)A.w, i / 3 / (size_t)A.w, i % 3, A.rgb[i], B.rgb[i]);
    murk_image_free(&A);
    murk_image_free(&B);
}

int files_equal(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        same = ca == cb;
        if (ca == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}
