/* testutil.c — see testutil.h */
#include "testutil.h"

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
    const char *argv[64];
    int argc = 0;
    argv[argc++] = env_or("MURK_EXE", "build/core/murk");
    va_list ap;
    va_start(ap, arg0);
    for (const char *a = arg0; a && argc < 63; a = va_arg(ap, const char *))
        argv[argc++] = a;
    va_end(ap);
    argv[argc] = NULL;

    char logpath[512];
    snprintf(logpath, sizeof logpath, "%s/run-%d.log", tmp_dir(), (int)getpid());
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(logpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0)
            _exit(127);
        dup2(fd, 1);
        dup2(fd, 2);
        close(fd);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (out) {
        FILE *f = fopen(logpath, "rb");
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
        *out = buf;
    }
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
}

/* Regularised upper incomplete gamma Q(a, x) (Numerical Recipes: series / continued fraction). */
static double gamma_q(double a, double x)
{
    if (x <= 0.0)
        return 1.0;
    double gln = lgamma(a);
    if (x < a + 1.0) {
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < 10000; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * 1e-15)
                break;
        }
        return 1.0 - sum * exp(-x + a * log(x) - gln);
    }
    double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < 1e-300)
            d = 1e-300;
        c = b + an / c;
        if (fabs(c) < 1e-300)
            c = 1e-300;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1.0) < 1e-15)
            break;
    }
    return exp(-x + a * log(x) - gln) * h;
}

typedef struct { double obs, exp; } bin;
static int cmp_bin(const void *a, const void *b)
{
    double x = ((const bin *)a)->exp, y = ((const bin *)b)->exp;
    return (x > y) - (x < y);
}

double chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out)
{
    bin *b = malloc(sizeof *b * (size_t)nbins);
    for (int i = 0; i < nbins; i++) {
        b[i].obs = observed[i];
        b[i].exp = expected[i];
    }
    qsort(b, (size_t)nbins, sizeof *b, cmp_bin);
    double chsq = 0.0, pool_obs = 0.0, pool_exp = 0.0;
    int cells = 0;
    for (int i = 0; i < nbins; i++) {
        if (b[i].exp == 0.0) {
            if (b[i].obs > 0.0) { /* a sample where the pdf says none can fall */
                free(b);
                if (dof_out)
                    *dof_out = 0;
                return 0.0;
            }
            continue;
        }
        pool_obs += b[i].obs;
        pool_exp += b[i].exp;
        if (pool_exp >= min_expected) {
            double d = pool_obs - pool_exp;
            chsq += d * d / pool_exp;
            cells++;
            pool_obs = pool_exp = 0.0;
        }
    }
    if (pool_exp > 0.0) { /* leftover low-expectation mass joins the last cell */
        double d = pool_obs - pool_exp;
        chsq += d * d / (pool_exp > 0 ? pool_exp : 1.0);
        cells++;
    }
    free(b);
    int dof = cells - 1;
    if (dof_out)
        *dof_out = dof;
    if (dof < 1)
        return 1.0;
    return gamma_q(dof / 2.0, chsq / 2.0);
}
