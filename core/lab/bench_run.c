/* bench_run.c — `murk bench`'s run (bench.h): the reference, every render (budgets, seeds, variants
 * innermost), each measured into a row of bench.csv, then the files (bench.csv, or bench-interrupted.csv
 * after a signal; maps/variantN.npy; bench.json), the chart script and the comparison page. Part of
 * libmurklab. */
#define _GNU_SOURCE /* dladdr() */
#include "lab/bench.h"

#include "cmd/cmd.h"
#include "lab/report_html.h"
#include "render/counters.h"
#include "scene/scene.h"
#include "util/atomic.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"

#include <dlfcn.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *const counter_names[MURK_NCOUNTERS] = MURK_COUNTER_NAMES;

/* Renders (or, --assemble, reads) one render of the bench. 0; 1 when a signal abandoned it (no image:
 * only whole renders count); or -1 after a message. */
int murk_bench_render(const bench *b, int v, int bi, int k, const char *const *sets, size_t n,
                      const murk_render_opts *o, int w, int h, murk_render_result *res)
{
    char err[2048], path[4200];
    if (b->assemble) {
        murk_bench_job_out(b, v, bi, k, path, sizeof path);
        return murk_bench_read_job(path, w, h, res);
    }
    murk_scene *s = murk_bench_load(b, sets, n, err, sizeof err);
    if (!s) {
        fprintf(stderr, "\n%s\n", err);
        memset(res, 0, sizeof *res);
        return -1;
    }
    int rc = murk_render_err(s, o, res, err, sizeof err);
    if (rc != 0)
        fprintf(stderr, "\nmurk: %s\n", err);
    murk_scene_free(s);
    if (rc == 0 && res->interrupted) {
        free(res->rgb);
        res->rgb = NULL;
        return 1;
    }
    return rc ? -1 : 0;
}

static void json_str(FILE *f, const char *s) { murk_html_json_string(f, s, strlen(s)); }

static void csv_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* Every output file of the bench goes through murk_write_atomic (atomic.h): a temporary beside it,
 * renamed over it when whole. These fill the temporary. */

int murk_bench_text_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen)
{
    const text_job *t = user;
    (void)tmp, (void)err, (void)errlen;
    fwrite(t->p, 1, t->n, f); /* murk_write_atomic checks the stream */
    return 0;
}

typedef struct npy_job {
    const float *v;
    int w, h;
} npy_job;

/* A float32 .npy file of h x w values (numpy's format 1.0). */
static int npy_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen)
{
    const npy_job *j = user;
    const float *v = j->v;
    int w = j->w, h = j->h;
    (void)tmp, (void)err, (void)errlen;
    char head[128];
    int n = snprintf(head, sizeof head, "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, %d), }", h, w);
    int total = 10 + n + 1, pad = (64 - total % 64) % 64;
    unsigned short hl = (unsigned short)(n + pad + 1);
    fwrite("\x93NUMPY\x01\x00", 1, 8, f);
    fputc(hl & 0xff, f);
    fputc(hl >> 8, f);
    fwrite(head, 1, (size_t)n, f);
    for (int i = 0; i < pad; i++)
        fputc(' ', f);
    fputc('\n', f);
    fwrite(v, sizeof(float), (size_t)w * (size_t)h, f);
    return 0;
}

/* Where the chart script is: $MURK_BENCH_SCRIPT; beside the build tree's libmurklab (build/tools/); where
 * an install put it relative to the libmurklab in use (so a relocated or --destdir install finds it,
 * whatever program runs the lab); the install path. */
static void script_path(char *buf, size_t n)
{
    static const char anchor = 0; /* an address inside libmurklab */
    const char *env = getenv("MURK_BENCH_SCRIPT");
    if (env && *env) {
        snprintf(buf, n, "%s", env);
        return;
    }
    Dl_info info;
    char lib[4096];
    if (dladdr(&anchor, &info) && info.dli_fname && realpath(info.dli_fname, lib) && n > sizeof lib + 64) {
        char *slash = strrchr(lib, '/');
        if (slash) {
            *slash = 0;
            snprintf(buf, n, "%s/../tools/bench_report.py", lib);
            if (access(buf, R_OK) == 0)
                return;
            snprintf(buf, n, "%s/%s", lib, MURK_BENCH_SCRIPT_FROM_LIBDIR);
            if (access(buf, R_OK) == 0)
                return;
        }
    }
    snprintf(buf, n, "%s", MURK_BENCH_SCRIPT_INSTALLED);
}

static void fmt_eta(double s, char *buf, size_t n)
{
    if (s >= 3600)
        snprintf(buf, n, "%dh%02dm", (int)(s / 3600), (int)fmod(s / 60, 60));
    else if (s >= 60)
        snprintf(buf, n, "%dm%02ds", (int)(s / 60), (int)fmod(s, 60));
    else
        snprintf(buf, n, "%.0fs", s);
}

static void shell_quoted(FILE *f, int argc, char **argv)
{
    fputs("murk bench", f);
    for (int i = 0; i < argc; i++)
        murk_bench_shell_word(f, argv[i]);
}

typedef struct meta_job {
    const bench *b;
    const reference *r;
    int argc;
    char **argv;
    const double *load; /* the 1-, 5- and 15-minute load averages before the renders, then after; < 0: unknown */
} meta_job;

/* bench.json: what the chart script needs besides bench.csv. */
static int meta_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen)
{
    const meta_job *j = user;
    const bench *b = j->b;
    const reference *r = j->r;
    int argc = j->argc;
    char **argv = j->argv;
    (void)tmp, (void)err, (void)errlen;
    char cmd[65536];
    FILE *m = fmemopen(cmd, sizeof cmd, "w");
    if (m) {
        shell_quoted(m, argc, argv);
        fclose(m);
    } else {
        snprintf(cmd, sizeof cmd, "murk bench %s", b->scene);
    }
    fprintf(f, "{\n  \"command\": ");
    json_str(f, cmd);
    fprintf(f, ",\n  \"version\": \"%s\",\n  \"commit\": \"%s\",\n  \"scene\": ", MURK_VERSION, murk_build_commit());
    json_str(f, b->scene);
    fprintf(f, ",\n  \"budget\": \"%s\",\n  \"repeat\": %d,\n  \"threads\": %d,\n  \"cores\": %d,\n",
            b->time_mode ? "seconds" : "spp", b->repeat, b->threads, murk_cpus_usable());
    if (j->load) /* the machine's load: times measured while other work ran are noisy */
        fprintf(f, "  \"load\": {\"before\": [%.2f, %.2f, %.2f], \"after\": [%.2f, %.2f, %.2f]},\n", j->load[0],
                j->load[1], j->load[2], j->load[3], j->load[4], j->load[5]);
    fprintf(f, "  \"reference\": {\"path\": ");
    json_str(f, b->reference ? b->reference : r->path);
    fprintf(f, ", \"given\": %s, \"reused\": %s, \"spp\": %d, \"seconds\": %.3f, \"noise_estimated\": %s, \"sets\": [",
            b->reference ? "true" : "false", r->reused ? "true" : "false", b->reference ? 0 : r->spp, r->seconds,
            r->var ? "true" : "false");
    for (size_t i = 0; i < b->nref_sets; i++) {
        fputs(i ? ", " : "", f);
        json_str(f, b->ref_sets[i]);
    }
    fprintf(f, "]},\n  \"sets\": [");
    for (size_t i = 0; i < b->nsets; i++) {
        fputs(i ? ", " : "", f);
        json_str(f, b->sets[i]);
    }
    fprintf(f, "],\n  \"vary\": [");
    for (int j = 0; j < b->nvary; j++) {
        fputs(j ? ", " : "", f);
        json_str(f, b->vary[j].key);
    }
    fprintf(f, "],\n  \"variants\": [");
    for (int i = 0; i < b->nvariants; i++) {
        char label[1024];
        murk_bench_label(b, i, label, sizeof label);
        fputs(i ? ", " : "", f);
        json_str(f, label);
    }
    fprintf(f, "]\n}\n");
    return 0;
}

/* The chart script (tools/bench_report.py DIR) as a child process, without a shell, once every render is
 * done and bench.csv, bench.json and maps/ are written. It runs in its own process group, so a Ctrl-C
 * reaches murk alone, and murk passes a SIGINT, SIGTERM or SIGHUP on to it once: the script then removes the
 * chart it was writing (every chart is a temporary renamed when whole). A signal that came before it
 * started: no charts. 0, or the exit status after a message. */
static int run_charts(const bench *b)
{
    char script[8192];
    script_path(script, sizeof script);
    const char *py = getenv("MURK_PYTHON");
    if (!py || !*py)
        py = access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
    if (murk_bench_stopped(b)) {
        fprintf(stderr, "murk bench: interrupted (%s) after the last render; bench.csv, bench.json and maps/ are "
                "whole, no charts (%s %s %s makes them)\n", murk_cli_stop_name(), murk_cli_q(py), murk_cli_q(script),
                murk_cli_q(b->out));
        return murk_cli_stop_status();
    }
    if (!b->charts)
        return 0;
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid == 0) {
        setpgid(0, 0);
        execlp(py, py, script, b->out, (char *)NULL);
        fprintf(stderr, "murk: cannot run %s: %s\n", murk_cli_q(py), strerror(errno));
        _exit(127);
    }
    int st = -1, passed = 0;
    while (pid > 0) {
        if (murk_bench_stopped(b) && !passed) {
            kill(pid, murk_cli_stop_status() - 128);
            passed = 1;
        }
        if (waitpid(pid, &st, 0) == pid || errno != EINTR)
            break;
    }
    if (murk_bench_stopped(b)) {
        fprintf(stderr, "murk bench: interrupted (%s) while making the charts; bench.csv, bench.json and maps/ "
                "are whole, some charts may be missing (%s %s %s makes them)\n", murk_cli_stop_name(), murk_cli_q(py),
                murk_cli_q(script), murk_cli_q(b->out));
        return murk_cli_stop_status();
    }
    if (pid < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "murk: the chart script failed (%s %s: %s %d); bench.csv is complete. It needs python3 "
                "with matplotlib and numpy (Debian: python3-matplotlib python3-numpy)\n", murk_cli_q(py),
                murk_cli_q(script), pid < 0 ? "fork failed, errno" : WIFEXITED(st) ? "status" : "signal",
                pid < 0 ? errno : WIFEXITED(st) ? WEXITSTATUS(st) : WTERMSIG(st));
        return 1;
    }
    return 0;
}

/* DIR/report.html, once the bench's other files are written: rc (the chart script's status) or 1. */
static int write_page(murk_html_page *page, const bench *b, int rc)
{
    char path[4200], err[8400];
    snprintf(path, sizeof path, "%s/report.html", b->out);
    murk_html_attach_bench(page, b->out);
    if (murk_html_write(page, path, err, sizeof err) != 0) {
        fprintf(stderr, "murk: %s\n", err);
        return 1;
    }
    printf("comparison page: %s\n", murk_cli_q(path));
    return rc;
}

static void csv_row(FILE *csv, const murk_bench_row *w)
{
    const murk_metrics *m = &w->metrics;
    fprintf(csv, "%d,", w->variant);
    csv_str(csv, w->label);
    fprintf(csv, ",%g,%d,%d,%.6f,%llu", w->budget, w->seed, w->spp, w->seconds, (unsigned long long)w->rays);
    for (int c = 0; c < MURK_NCOUNTERS; c++)
        fprintf(csv, ",%llu", (unsigned long long)murk_counters_get(&w->counters, c));
    fprintf(csv, ",%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%llu,%.9g\n", m->mse, m->relmse, m->relmse_se, m->relmse_raw,
            m->ref_noise, m->mare, (unsigned long long)w->nonfinite, w->max_sample);
}

/* One bench run: the reference, then what the sweep fills render by render and the end writes out. */
typedef struct run {
    const bench *b;
    reference r;
    FILE *csv;            /* bench.csv's text in memory (rows), written whole at the end */
    char *rows;
    size_t rows_len;
    murk_html_page *page; /* report.html */
    float *pix;           /* one render's per-pixel relMSE (murk_metrics_compute) */
    double *maps;         /* per variant: the mean of pix over the seeds at the largest budget */
    size_t np;
    int big;              /* the largest budget's index */
    int done, total;      /* whole renders recorded, and asked for */
    double t0;
    double load[6];       /* load averages (1, 5, 15 min) before the renders and after (note_load) */
} run;

/* Records the load average in load[0..2] and warns when its 1-minute figure exceeds the cores murk may
 * run on: other processes then share the CPUs and every time measured is noisy (`when`: "before" or
 * "after" the renders). */
static void note_load(double load[3], const char *when)
{
    int cores = murk_cpus_usable();
    if (getloadavg(load, 3) != 3) {
        load[0] = load[1] = load[2] = -1.0;
        return;
    }
    if (load[0] > cores)
        fprintf(stderr, "murk bench: warning: load average %.2f %s the renders, above the %d cores murk may use: "
                        "other work shares the CPUs, so times (and equal-time ratios) are noisy; lookups are not\n",
                load[0], when, cores);
}

/* The reference: given (--reference), or rendered or taken from the cache (murk_bench_reference); said on
 * stdout. 0, 1 after a message, or the stop status when a signal came while rendering it. */
static int load_reference(const bench *b, reference *r)
{
    if (b->reference) {
        if (murk_bench_read_exr(b->reference, r->w, r->h, &r->rgb) != 0) {
            fprintf(stderr, "murk: --reference %s: not a readable %dx%d EXR (the scene's resolution)\n",
                    murk_cli_q(b->reference), r->w, r->h);
            return 1;
        }
        printf("reference: %s (given; its own noise is not known, so relMSE is not corrected for it)\n",
               murk_cli_q(b->reference));
        return 0;
    }
    if (murk_bench_reference(b, r) != 0) {
        if (!murk_bench_stopped(b))
            return 1;
        fprintf(stderr, "%smurk bench: interrupted (%s) while rendering the reference; nothing written\n",
                murk_cli_progress() ? "\r\033[K" : "", murk_cli_stop_name());
        return murk_cli_stop_status();
    }
    if (r->reused)
        printf("reference: %s (reused from the cache: same scene file, --set, spp, murk version and commit)\n",
               murk_cli_q(r->path));
    else
        printf("reference: %s (rendered: %d spp in %d chunks, %.1f s; cached)\n", murk_cli_q(r->path),
               REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS), REF_CHUNKS, r->seconds);
    return 0;
}

/* bench.csv's header, the buffers of the maps, and the comparison page with the reference on it. 0, or 1
 * after a message. */
static int run_open(run *u)
{
    const bench *b = u->b;
    char title[8192];
    u->csv = open_memstream(&u->rows, &u->rows_len);
    if (!u->csv) {
        fprintf(stderr, "murk: out of memory\n");
        return 1;
    }
    fprintf(u->csv, "variant,label,budget,seed,spp,seconds,rays");
    for (int k = 0; k < MURK_NCOUNTERS; k++)
        fprintf(u->csv, ",%s", counter_names[k]);
    fprintf(u->csv, ",mse,relmse,relmse_se,relmse_raw,ref_noise,mare,nonfinite,max_sample\n");
    u->t0 = murk_now();
    for (int i = 0; i < b->nbudgets; i++)
        if (b->budgets[i] > b->budgets[u->big])
            u->big = i;
    u->total = b->nbudgets * b->repeat * b->nvariants;
    u->np = (size_t)u->r.w * (size_t)u->r.h;
    snprintf(title, sizeof title, "murk bench: %s", b->scene);
    u->page = murk_html_new("bench", title, u->r.w, u->r.h, b->nvariants + 1, b->nvariants,
                            murk_limit(MURK_LIMIT_PAGE_BYTES));
    if (b->reference)
        snprintf(title, sizeof title, "given: %s", b->reference);
    else
        snprintf(title, sizeof title, "%d spp, the mean of %d chunks",
                 REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS), REF_CHUNKS);
    murk_html_image(u->page, b->nvariants, "reference", title, u->r.rgb, 1);
    u->pix = murk_xmalloc(u->np * sizeof(float));
    u->maps = calloc(u->np * (size_t)b->nvariants, sizeof(double));
    return u->maps ? 0 : 1;
}

/* A whole render's row, and at the largest budget its share of its variant's error map and of the page
 * (which shows the first seed's image). */
static void record(run *u, int v, int bi, int k, const char *label, const murk_render_result *res)
{
    const bench *b = u->b;
    const reference *r = &u->r;
    murk_bench_row w = {.variant = v, .label = label, .budget = b->budgets[bi], .seed = 1 + k, .spp = res->spp,
                   .seconds = res->seconds, .rays = res->rays, .counters = murk_counters_total(res),
                   .max_sample = res->max_sample};
    murk_metrics_compute(res->rgb, r->rgb, r->var, r->w, (murk_crop){0, 0, r->w, r->h}, &w.metrics, u->pix);
    w.nonfinite = res->nonfinite + w.metrics.nonfinite;
    csv_row(u->csv, &w);
    if (b->row)
        b->row(b->user, &w);
    if (bi == u->big) {
        for (size_t p = 0; p < u->np; p++)
            u->maps[(size_t)v * u->np + p] += isfinite(u->pix[p]) ? u->pix[p] / b->repeat : 0.0;
        murk_html_cost_add(u->page, v, res->seconds / b->repeat, (double)w.counters.lookups / b->repeat,
                           w.metrics.relmse / b->repeat);
        char note[96];
        snprintf(note, sizeof note, "seed 1 of %d, %g %s", b->repeat, b->budgets[bi], b->time_mode ? "s" : "spp");
        if (k == 0)
            murk_html_image(u->page, v, label, note, res->rgb, 0);
    }
    u->done++;
}

/* Renders (or, --assemble, reads back) variant v at budget bi with seed 1 + k and records it unless a
 * signal abandoned it. 0, or 1 after a message. */
static int render_one(run *u, int v, int bi, int k, const char *label, const char *const *sets, size_t n)
{
    const bench *b = u->b;
    murk_render_opts o = {.threads = b->threads, .stop = b->stop};
    if (b->time_mode) {
        o.time_limit = b->budgets[bi];
        o.spp = 1 << 24;
    } else {
        o.spp = (int)b->budgets[bi];
    }
    murk_render_result res;
    int failed = murk_bench_render(b, v, bi, k, sets, n, &o, u->r.w, u->r.h, &res);
    if (failed == 0)
        record(u, v, bi, k, label, &res);
    free(res.rgb);
    return failed < 0;
}

/* Every render: budgets outermost, then seeds, variants innermost (A B A B: a drift of the machine's speed
 * hits every variant alike), with a progress line on a terminal. 0, or 1 after a render failed; a signal
 * stops it after the running render. */
static int sweep(run *u)
{
    const bench *b = u->b;
    const char **sets = murk_xmalloc(murk_bench_max_sets(b) * sizeof *sets);
    char *store[BENCH_STORE];
    size_t nstore = 0;
    double total_w = 0, done_w = 0;
    for (int i = 0; i < b->nbudgets; i++)
        total_w += b->budgets[i] * b->repeat * b->nvariants;
    int rc = 0, count = 0, tty = murk_cli_progress();
    for (int bi = 0; bi < b->nbudgets && !rc && !murk_bench_stopped(b); bi++)
        for (int k = 0; k < b->repeat && !rc && !murk_bench_stopped(b); k++)
            for (int v = 0; v < b->nvariants && !rc && !murk_bench_stopped(b); v++) {
                char label[1024], eta[32] = "?";
                murk_bench_label(b, v, label, sizeof label);
                if (done_w > 0)
                    fmt_eta((murk_now() - u->t0) / done_w * (total_w - done_w), eta, sizeof eta);
                count++;
                if (tty) {
                    fprintf(stderr, "\r\033[K[%d/%d] %s  %s %g  seed %d  ETA %s", count, u->total, label,
                            b->time_mode ? "time" : "spp", b->budgets[bi], 1 + k, eta);
                    fflush(stderr);
                }
                size_t n = murk_bench_sets(b, v, 1 + k, sets, store, &nstore);
                rc = render_one(u, v, bi, k, label, sets, n);
                murk_bench_free_sets(store, &nstore);
                done_w += b->budgets[bi];
                murk_warn_summary();
            }
    if (tty)
        fprintf(stderr, "\r\033[K");
    free(sets);
    return rc;
}

/* The rows: bench.csv when every render was done; after a signal only the whole renders' rows, in
 * bench-interrupted.csv, never as bench.csv, and the stop status. rc: the sweep's. */
static int write_rows(run *u, int rc)
{
    const bench *b = u->b;
    char err[2048], path[8192];
    int bad = fclose(u->csv) != 0;
    text_job csv_text = {u->rows, u->rows_len};
    if (rc == 0 && (bad || !u->rows)) {
        fprintf(stderr, "murk: out of memory\n");
        rc = 1;
    }
    if (rc == 0 && u->done < u->total) {
        int cached = !b->reference && !u->r.reused && access(u->r.path, R_OK) == 0; /* rendered by this run */
        snprintf(path, sizeof path, "%s/bench-interrupted.csv", b->out);
        int kept = u->done > 0 && murk_write_atomic(path, murk_bench_text_fill, &csv_text, err, sizeof err) == 0;
        if (u->done > 0 && !kept)
            fprintf(stderr, "murk: %s\n", err);
        if (kept)
            fprintf(stderr, "murk bench: interrupted (%s) after %d of %d renders; their rows are in %s (the columns "
                    "of bench.csv); no bench.csv, bench.json, maps or charts were written\n", murk_cli_stop_name(),
                    u->done, u->total, murk_cli_q(path));
        else
            fprintf(stderr, "murk bench: interrupted (%s) after %d of %d renders; nothing written%s%s%s\n",
                    murk_cli_stop_name(), u->done, u->total, cached ? " but the reference, cached in " : "",
                    cached ? murk_cli_q(u->r.path) : "", cached ? " for the next bench" : "");
        rc = murk_cli_stop_status();
    }
    snprintf(path, sizeof path, "%s/bench.csv", b->out);
    if (rc == 0 && murk_write_atomic(path, murk_bench_text_fill, &csv_text, err, sizeof err) != 0) {
        fprintf(stderr, "murk: %s\n", err);
        rc = 1;
    }
    if (rc == 0) { /* a stale partial bench of an earlier run would sit beside the whole one */
        snprintf(path, sizeof path, "%s/bench-interrupted.csv", b->out);
        remove(path);
    }
    free(u->rows);
    return rc;
}

/* The per-pixel error maps of the largest budget (maps/variantN.npy, and on the page) and bench.json. 0,
 * or 1 after a message. */
static int write_maps(run *u, int argc, char **argv)
{
    const bench *b = u->b;
    char err[2048], path[8192];
    snprintf(path, sizeof path, "%s/maps", b->out);
    if (murk_bench_mkdirs(path) != 0) {
        fprintf(stderr, "murk: cannot create %s: %s\n", murk_cli_q(path), strerror(errno));
        return 1;
    }
    for (int v = 0; v < b->nvariants; v++) {
        for (size_t p = 0; p < u->np; p++)
            u->pix[p] = (float)u->maps[(size_t)v * u->np + p];
        murk_html_error_map(u->page, v, u->pix);
        snprintf(path, sizeof path, "%s/maps/variant%d.npy", b->out, v);
        npy_job nj = {u->pix, u->r.w, u->r.h};
        if (murk_write_atomic(path, npy_fill, &nj, err, sizeof err) != 0) {
            fprintf(stderr, "murk: %s\n", err);
            return 1;
        }
    }
    snprintf(path, sizeof path, "%s/bench.json", b->out);
    meta_job mj = {b, &u->r, argc, argv, u->load};
    if (murk_write_atomic(path, meta_fill, &mj, err, sizeof err) != 0) {
        fprintf(stderr, "murk: %s\n", err);
        return 1;
    }
    return 0;
}

/* The bench once its options are checked and its folder exists: the reference, every render, the files,
 * the charts and the page. The exit status. */
int murk_bench_run(const bench *b, int argc, char **argv)
{
    char err[2048];
    murk_scene *s0 = murk_bench_load(b, b->sets, b->nsets, err, sizeof err);
    if (!s0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    run u = {.b = b, .r = {.w = s0->width, .h = s0->height}};
    murk_scene_free(s0);
    int rc = load_reference(b, &u.r);
    if (rc != 0) {
        murk_bench_ref_free(&u.r);
        return rc;
    }
    fflush(stdout);
    rc = run_open(&u);
    if (u.csv) {
        note_load(u.load, "before");
        rc = rc ? rc : sweep(&u);
        note_load(u.load + 3, "after");
        rc = write_rows(&u, rc);
    }
    if (rc == 0)
        rc = write_maps(&u, argc, argv);
    free(u.pix);
    free(u.maps);
    murk_bench_ref_free(&u.r);
    if (rc == 0)
        printf("%d renders (%d variants x %d budgets x %d seeds) in %.1f s: %s/bench.csv\n", u.total, b->nvariants,
               b->nbudgets, b->repeat, murk_now() - u.t0, b->out);
    int whole = rc == 0;
    if (rc == 0)
        rc = run_charts(b); /* and a signal after the last render is said there */
    if (whole && rc <= 1 && !murk_bench_stopped(b))
        rc = write_page(u.page, b, rc);
    murk_html_free(u.page);
    return rc;
}
