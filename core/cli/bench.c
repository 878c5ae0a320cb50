/* bench.c — `murk bench SCENE.yaml`: renders every variant (the cross product of the --vary lists) at
 * every budget (--spp or --time) with --repeat seeds, measures each render against a reference
 * (metrics.c: the noise-corrected relMSE and the rest) and its work (the cost counters), writes
 * DIR/bench.csv, DIR/bench.json and DIR/maps/, runs the chart script (tools/bench_report.py) for
 * the charts and report.md, and writes DIR/report.html, the comparison page (cli/report_html.h): each
 * variant's first-seed image at the largest budget, the reference, the error maps, charts and tables.
 * Part of the murk executable. */
#include "cli/cli.h"
#include "cli/metrics.h"
#include "cli/report_html.h"
#include "image/image.h"
#include "load/load.h"
#include "media/media.h"
#include "render/counters.h"
#include "scene/scene.h"
#include "util/atomic.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char *const counter_names[MURK_NCOUNTERS] = MURK_COUNTER_NAMES;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- murk bench ---------------------------------------------------------------------------- */

typedef struct vary {
    const char *arg; /* KEY=V1,V2,... as given */
    char *key;
    char **vals;
    int nvals;
} vary;

typedef struct bench {
    const char *scene, *out, *reference;
    const char **sets, **ref_sets;
    size_t nsets, nref_sets;
    vary *vary;
    int nvary, nvariants;
    double *budgets;
    int nbudgets, time_mode, repeat, threads, ref_spp, charts;
    const char *jobs; /* --emit-jobs DIR or --assemble DIR */
    int assemble;
    volatile sig_atomic_t *stop; /* set by SIGINT/SIGTERM/SIGHUP (murk_cli_catch_stop_signals) */
} bench;

enum { REF_CHUNKS = 4, MAX_VARY = 32 }; /* MAX_VARY: the --vary strings of one render fit in store[64] */

/* A signal asked the bench to stop. */
static int stopped(const bench *b) { return b->stop && *b->stop; }

static char **split_list(const char *s, int *n)
{
    char **v = NULL;
    *n = 0;
    for (const char *p = s;;) {
        const char *c = strchr(p, ',');
        size_t l = c ? (size_t)(c - p) : strlen(p);
        v = murk_xrealloc(v, (size_t)(*n + 1) * sizeof *v);
        v[*n] = murk_xmalloc(l + 1);
        memcpy(v[*n], p, l);
        v[*n][l] = 0;
        (*n)++;
        if (!c)
            break;
        p = c + 1;
    }
    return v;
}

static void free_list(char **v, int n)
{
    for (int i = 0; i < n; i++)
        free(v[i]);
    free(v);
}

/* Variant i's value index along --vary k (the last --vary varies fastest). */
static int variant_value(const bench *b, int i, int k)
{
    for (int j = b->nvary - 1; j > k; j--)
        i /= b->vary[j].nvals;
    return i % b->vary[k].nvals;
}

/* The short name of --vary key j: its last component ("type"), or its last two ("medium.type") when
 * another --vary key ends the same way. */
static const char *vary_name(const bench *b, int j)
{
    const char *key = b->vary[j].key, *leaf = strrchr(key, '.');
    leaf = leaf ? leaf + 1 : key;
    for (int o = 0; o < b->nvary; o++) {
        const char *ol = strrchr(b->vary[o].key, '.');
        if (o != j && !strcmp(ol ? ol + 1 : b->vary[o].key, leaf)) {
            if (leaf == key)
                return key;
            const char *p = leaf - 1; /* the '.' before the leaf; back to the start of the component before */
            while (p > key && p[-1] != '.')
                p--;
            return p;
        }
    }
    return leaf;
}

/* "type=delta majorant_factor=4": each --vary key's short name and the variant's value. */
static void variant_label(const bench *b, int i, char *buf, size_t n)
{
    size_t k = 0;
    buf[0] = 0;
    for (int j = 0; j < b->nvary && k < n; j++)
        k += (size_t)snprintf(buf + k, n - k, "%s%s=%s", j ? " " : "", vary_name(b, j),
                              b->vary[j].vals[variant_value(b, i, j)]);
    if (!b->nvary)
        snprintf(buf, n, "scene");
}

/* The --set list of a render: the common sets, variant i's values (i < 0: the reference's sets) and
 * the seed (seed < 0: the scene's). Strings are kept in store (freed by the caller). */
static size_t render_sets(const bench *b, int i, long seed, const char **out, char **store, size_t *nstore)
{
    size_t n = 0;
    for (size_t k = 0; k < b->nsets; k++)
        out[n++] = b->sets[k];
    if (i < 0 && b->nref_sets) {
        for (size_t k = 0; k < b->nref_sets; k++)
            out[n++] = b->ref_sets[k];
    } else {
        for (int j = 0; j < b->nvary; j++) {
            size_t l = strlen(b->vary[j].key) + strlen(b->vary[j].vals[variant_value(b, i < 0 ? 0 : i, j)]) + 2;
            char *s = murk_xmalloc(l);
            snprintf(s, l, "%s=%s", b->vary[j].key, b->vary[j].vals[variant_value(b, i < 0 ? 0 : i, j)]);
            out[n++] = store[(*nstore)++] = s;
        }
    }
    if (seed >= 0) {
        char *s = murk_xmalloc(40);
        snprintf(s, 40, "render.seed=%ld", seed);
        out[n++] = store[(*nstore)++] = s;
    }
    return n;
}

static void free_store(char **store, size_t *n)
{
    for (size_t i = 0; i < *n; i++)
        free(store[i]);
    *n = 0;
}

/* A --vary key must name a place the scene has, all but its last component (the last may be a key the
 * scene leaves at its default: media.smoke.majorant_factor). A located message otherwise. */
static int check_vary_key(const murk_scene *s, const vary *v, char *err, size_t errlen)
{
    const murk_ynode *n = s->doc.root;
    char *path = murk_strdup(v->key), *save = NULL;
    int rc = 0, line = 1, col = 1;
    const char *parent = "the scene";
    char *comp = strtok_r(path, ".", &save);
    while (comp) {
        char *next = strtok_r(NULL, ".", &save);
        if (!next)
            break;
        const murk_ynode *c = NULL;
        if (n && n->kind == MURK_Y_MAP) {
            for (size_t i = 0; i < n->n && !c; i++)
                if (!strcmp(n->keys[i], comp)) {
                    c = n->items[i];
                    line = n->key_line[i], col = n->key_col[i]; /* where the key is written */
                }
        } else if (n && n->kind == MURK_Y_SEQ) {
            char *end;
            long ix = strtol(comp, &end, 10);
            c = *comp && !*end && ix >= 0 && (size_t)ix < n->n ? n->items[ix] : NULL;
            if (c)
                line = c->line, col = c->col;
        }
        if (!c) {
            char have[512] = "";
            size_t k = 0;
            for (size_t i = 0; n && n->kind == MURK_Y_MAP && i < n->n && k < sizeof have; i++)
                k += (size_t)snprintf(have + k, sizeof have - k, "%s%s", i ? ", " : "", n->keys[i]);
            snprintf(err, errlen, "%s:%d:%d: --vary %s: %s has no '%s'%s%s%s", s->doc.file, line, col,
                     murk_cli_q(v->key), parent, murk_cli_q(comp), *have ? " (it has: " : "",
                     murk_cli_q(have), *have ? ")" : "");
            rc = -1;
            break;
        }
        n = c;
        parent = comp;
        comp = next;
    }
    free(path);
    return rc;
}

/* A variant's scene as `murk render` loads it: with the rule that every medium and material is used, so a
 * misspelt medium in a --vary or --set fails here instead of adding an unused block. */
static murk_scene *load_with(const bench *b, const char *const *sets, size_t nsets, char *err, size_t errlen)
{
    murk_scene *s = murk_scene_load(b->scene, sets, nsets, err, errlen);
    if (s && murk_scene_check_unused(s, err, errlen)) {
        murk_scene_free(s);
        s = NULL;
    }
    return s;
}

/* Every --vary value alone, then every variant, loads: the located loader message and the --vary that
 * caused it, before anything is rendered. */
static int validate(const bench *b)
{
    char err[2048];
    const char **sets = murk_xmalloc((b->nsets + (size_t)b->nvary + b->nref_sets + 2) * sizeof *sets);
    murk_scene *s = load_with(b, b->sets, b->nsets, err, sizeof err);
    int rc = 0;
    if (!s) {
        fprintf(stderr, "%s\n", err);
        free(sets);
        return -1;
    }
    for (int j = 0; j < b->nvary && !rc; j++) {
        if (check_vary_key(s, &b->vary[j], err, sizeof err)) {
            fprintf(stderr, "%s\nmurk: bench: nothing was rendered\n", err);
            rc = -1;
            break;
        }
        for (int k = 0; k < b->vary[j].nvals && !rc; k++) {
            char one[4096];
            snprintf(one, sizeof one, "%s=%s", b->vary[j].key, b->vary[j].vals[k]);
            size_t n = 0;
            for (size_t q = 0; q < b->nsets; q++)
                sets[n++] = b->sets[q];
            sets[n++] = one;
            murk_scene *t = load_with(b, sets, n, err, sizeof err);
            if (!t) {
                fprintf(stderr, "%s\nmurk: bench: in --vary %s (value '%s'); nothing was rendered\n", err,
                        murk_cli_q(b->vary[j].arg), murk_cli_q(b->vary[j].vals[k]));
                rc = -1;
            }
            murk_scene_free(t);
        }
    }
    char *store[64];
    size_t nstore = 0;
    for (int i = -1; i < b->nvariants && !rc; i++) {
        if (i < 0 && !b->nref_sets)
            continue;
        size_t n = render_sets(b, i, -1, sets, store, &nstore);
        murk_scene *t = load_with(b, sets, n, err, sizeof err);
        char label[1024];
        variant_label(b, i < 0 ? 0 : i, label, sizeof label);
        if (!t) {
            fprintf(stderr, "%s\nmurk: bench: in %s%s%s; nothing was rendered\n", err, i < 0 ? "the reference's --ref-set" : "variant '",
                    i < 0 ? "" : murk_cli_q(label), i < 0 ? "" : "'");
            rc = -1;
        } else if (t->width != s->width || t->height != s->height) {
            fprintf(stderr, "murk: bench: %s has another resolution than the scene; nothing was rendered\n",
                    i < 0 ? "the reference" : murk_cli_q(label));
            rc = -1;
        }
        murk_scene_free(t);
        free_store(store, &nstore);
    }
    murk_scene_free(s);
    free(sets);
    return rc;
}

/* ---- the reference ---- */

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

static int mkdirs(const char *path)
{
    char *p = murk_strdup(path);
    for (char *s = p + 1; *s; s++)
        if (*s == '/') {
            *s = 0;
            mkdir(p, 0777);
            *s = '/';
        }
    int rc = mkdir(p, 0777) == 0 || errno == EEXIST ? 0 : -1;
    free(p);
    return rc;
}

static void cache_dir(char *buf, size_t n)
{
    const char *d = getenv("MURK_CACHE_DIR"), *x = getenv("XDG_CACHE_HOME"), *h = getenv("HOME");
    if (d && *d)
        snprintf(buf, n, "%s", d);
    else if (x && *x)
        snprintf(buf, n, "%s/murk", x);
    else
        snprintf(buf, n, "%s/.cache/murk", h && *h ? h : "/tmp");
}

typedef struct reference {
    int w, h;
    float *rgb, *var; /* var: the variance of rgb's per-pixel mean; NULL if unknown */
    char path[4096];
    int reused, spp;
    double seconds;
} reference;

static void ref_free(reference *r)
{
    free(r->rgb);
    free(r->var);
}

static int read_exr(const char *path, int w, int h, float **out)
{
    murk_image im = {0};
    char err[1024];
    if (murk_exr_read(path, &im, err, sizeof err) || im.w != w || im.h != h) {
        murk_image_free(&im);
        return -1;
    }
    *out = im.rgb;
    im.rgb = NULL;
    murk_image_free(&im);
    return 0;
}

/* ---- sweeps as jobs (--emit-jobs DIR, --assemble DIR) ---- */

/* Where job (variant v, budget bi, seed k) writes its image; v < 0: reference chunk k. */
static void job_out(const bench *b, int v, int bi, int k, char *buf, size_t n)
{
    if (v < 0)
        snprintf(buf, n, "%s/renders/ref%d.exr", b->jobs, k);
    else
        snprintf(buf, n, "%s/renders/v%d-b%d-s%d.exr", b->jobs, v, bi, k);
}

/* The value of "NAME": N in a murk:counters JSON text (0 if absent). */
static uint64_t json_u64(const char *json, const char *name)
{
    char key[64];
    snprintf(key, sizeof key, "\"%s\": ", name);
    const char *p = json ? strstr(json, key) : NULL;
    return p ? strtoull(p + strlen(key), NULL, 10) : 0;
}

/* A job's image read back as murk_render_err would have returned it: pixels, spp, seconds, rays, the
 * counters' totals (as one medium), NaN count and largest sample. 0, or -1 after a message naming it. */
static int read_job(const char *path, int w, int h, murk_render_result *res)
{
    murk_image im = {0};
    char err[1024];
    memset(res, 0, sizeof *res);
    if (murk_exr_read(path, &im, err, sizeof err) != 0 || im.w != w || im.h != h ||
        !murk_image_meta(&im, "murk:counters") || strcmp(murk_image_meta(&im, "murk:interrupted"), "no") != 0) {
        fprintf(stderr, "murk: %s\nmurk: %s: not the finished %dx%d render of its job (run it again: the line "
                "of jobs.txt that writes it)\n", im.rgb ? "" : err, murk_cli_q(path), w, h);
        murk_image_free(&im);
        return -1;
    }
    const char *json = murk_image_meta(&im, "murk:counters"), *total = strstr(json, "\"total\": ");
    uint64_t t[MURK_NCOUNTERS];
    for (int k = 0; k < MURK_NCOUNTERS; k++)
        t[k] = json_u64(total, counter_names[k]);
    res->media[0] = (murk_counters){t[0], t[1], t[2], t[3], t[4]};
    res->nmedia = 1;
    res->rays = json_u64(json, "rays");
    res->spp = atoi(murk_image_meta(&im, "murk:spp"));
    res->seconds = strtod(murk_image_meta(&im, "murk:render_time"), NULL);
    res->nonfinite = strtoull(murk_image_meta(&im, "murk:nonfinite_samples"), NULL, 10);
    const char *mx = murk_image_meta(&im, "murk:max_sample");
    res->max_sample = mx ? strtod(mx, NULL) : 0.0;
    res->width = w, res->height = h;
    res->rgb = im.rgb;
    im.rgb = NULL;
    murk_image_free(&im);
    return 0;
}

/* Renders (or, --assemble, reads) one render of the bench. 0; 1 when a signal abandoned it (no image:
 * only whole renders count); or -1 after a message. */
static int bench_render(const bench *b, int v, int bi, int k, const char *const *sets, size_t n,
                        const murk_render_opts *o, int w, int h, murk_render_result *res)
{
    char err[2048], path[4200];
    if (b->assemble) {
        job_out(b, v, bi, k, path, sizeof path);
        return read_job(path, w, h, res);
    }
    murk_scene *s = load_with(b, sets, n, err, sizeof err);
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

/* Renders the reference in REF_CHUNKS independent chunks (seeds 900001..): the mean of the chunks is the
 * reference and the variance of its per-pixel mean is estimated without bias from the chunks' spread,
 * s^2 / REF_CHUNKS (s^2 the chunks' sample variance). Cached under the content hash of the scene file and
 * of every file it loads, the --set overrides, the spp and murk's version: the mean and the variance as
 * one group of atomic writes (both files or neither). A stop signal abandons it (-1, nothing cached). */
static int make_reference(const bench *b, reference *r)
{
    char err[2048], dir[3072];
    const char **sets = murk_xmalloc((b->nsets + (size_t)b->nvary + b->nref_sets + 2) * sizeof *sets);
    char *store[64];
    size_t nstore = 0, n = render_sets(b, -1, -1, sets, store, &nstore);
    /* the scene file and every file it loads (meshes, grids, textures), as a checkpoint hashes them */
    murk_scene *hs = load_with(b, sets, n, err, sizeof err);
    uint64_t sh = hs ? murk_scene_hash(hs, err, sizeof err) : 0;
    murk_scene_free(hs);
    if (!sh) {
        fprintf(stderr, "%s\n", err);
        free_store(store, &nstore);
        free(sets);
        return -1;
    }
    uint64_t h = fnv(1469598103934665603ull, "murk bench reference 1", 23);
    h = fnv(h, MURK_VERSION, sizeof MURK_VERSION);
    h = fnv(h, &sh, sizeof sh);
    h = fnv(h, &b->ref_spp, sizeof b->ref_spp);
    for (size_t i = 0; i < n; i++)
        h = fnv(h, sets[i], strlen(sets[i]) + 1);
    cache_dir(dir, sizeof dir);
    char var_path[4200];
    snprintf(r->path, sizeof r->path, "%s/bench-ref-%016llx.exr", dir, (unsigned long long)h);
    snprintf(var_path, sizeof var_path, "%s/bench-ref-%016llx-var.exr", dir, (unsigned long long)h);
    r->spp = b->ref_spp;
    if (!b->assemble && read_exr(r->path, r->w, r->h, &r->rgb) == 0 &&
        read_exr(var_path, r->w, r->h, &r->var) == 0) {
        r->reused = 1;
        free_store(store, &nstore);
        free(sets);
        return 0;
    }
    free(r->rgb);
    r->rgb = NULL;
    size_t np = (size_t)r->w * (size_t)r->h * 3;
    double *s1 = calloc(np, sizeof *s1), *s2 = calloc(np, sizeof *s2);
    int rc = s1 && s2 ? 0 : -1;
    for (int c = 0; c < REF_CHUNKS && rc == 0; c++) {
        char seed[40];
        snprintf(seed, sizeof seed, "render.seed=%d", 900001 + c);
        sets[n] = seed;
        murk_render_opts o = {.spp = (b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS, .threads = b->threads,
                              .stop = b->stop};
        if (stopped(b)) {
            rc = -1;
            break;
        }
        murk_render_result res;
        if (murk_cli_progress() && !b->assemble)
            fprintf(stderr, "\rmurk bench: reference chunk %d of %d (%d spp)...   ", c + 1, REF_CHUNKS, o.spp);
        if (bench_render(b, -1, 0, c, sets, n + 1, &o, r->w, r->h, &res) != 0) {
            rc = -1;
        } else {
            for (size_t i = 0; i < np; i++) {
                s1[i] += res.rgb[i];
                s2[i] += (double)res.rgb[i] * res.rgb[i];
            }
            r->seconds += res.seconds;
        }
        free(res.rgb);
    }
    if (murk_cli_progress() && !b->assemble)
        fputc('\n', stderr);
    if (rc == 0) {
        r->rgb = murk_xmalloc(np * sizeof(float));
        r->var = murk_xmalloc(np * sizeof(float));
        for (size_t i = 0; i < np; i++) {
            double m = s1[i] / REF_CHUNKS, v = (s2[i] - s1[i] * m) / (REF_CHUNKS - 1);
            r->rgb[i] = (float)m;
            r->var[i] = (float)(fmax(v, 0.0) / REF_CHUNKS);
        }
        char spp[32];
        snprintf(spp, sizeof spp, "%d", REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS));
        murk_kv meta[] = {{"murk:scene", b->scene}, {"murk:spp", spp}, {"murk:version", MURK_VERSION},
                          {"murk:bench", "reference: the mean of 4 chunks"}};
        murk_kv vmeta[] = {{"murk:scene", b->scene}, {"murk:bench", "variance of the reference's per-pixel mean"}};
        err[0] = 0;
        murk_output_begin();
        if (mkdirs(dir) != 0 || murk_exr_write(r->path, r->rgb, r->w, r->h, meta, 4, err, sizeof err) != 0 ||
            murk_exr_write(var_path, r->var, r->w, r->h, vmeta, 2, err, sizeof err) != 0 ||
            murk_output_commit(err, sizeof err) != 0) {
            murk_output_abort();
            fprintf(stderr, "murk: warning: could not cache the reference in %s (%s); it will be rendered again "
                    "next time\n", murk_cli_q(dir), err[0] ? err : strerror(errno));
        }
    }
    free(s1);
    free(s2);
    free_store(store, &nstore);
    free(sets);
    return rc;
}

/* ---- output ---- */

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

typedef struct text_job {
    const char *p;
    size_t n;
} text_job;

static int text_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen)
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

/* Where the chart script is: $MURK_BENCH_SCRIPT; beside the build tree's murk (build/tools/); where an
 * install put it relative to bin/murk (so a relocated or --destdir install finds it); the install path. */
static void script_path(char *buf, size_t n)
{
    const char *env = getenv("MURK_BENCH_SCRIPT");
    if (env && *env) {
        snprintf(buf, n, "%s", env);
        return;
    }
    char exe[4096];
    ssize_t l = n > sizeof exe + 64 ? readlink("/proc/self/exe", exe, sizeof exe - 1) : -1;
    if (l > 0) {
        exe[l] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = 0;
            snprintf(buf, n, "%s/../tools/bench_report.py", exe);
            if (access(buf, R_OK) == 0)
                return;
            snprintf(buf, n, "%s/%s", exe, MURK_BENCH_SCRIPT_FROM_BINDIR);
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

static int parse_budgets(const char *opt, const char *v, int time_mode, bench *b)
{
    int n;
    char **parts = split_list(v, &n);
    free(b->budgets);
    b->budgets = murk_xmalloc((size_t)n * sizeof *b->budgets);
    b->nbudgets = n;
    b->time_mode = time_mode;
    int rc = 0;
    for (int i = 0; i < n && !rc; i++) {
        char *end;
        double x = strtod(parts[i], &end);
        if (!*parts[i] || *end || !(x > 0) || x > (time_mode ? 1e6 : 1e7) || (!time_mode && x != floor(x))) {
            fprintf(stderr, "murk: %s needs a comma-separated list of %s, got '%s'\n", opt,
                    time_mode ? "positive seconds" : "whole spp counts above 0", murk_cli_q(v));
            rc = -1;
        }
        b->budgets[i] = x;
    }
    free_list(parts, n);
    return rc;
}

/* ---- the runs ---- */

/* " WORD" as a POSIX shell reads it back: plain, or in single quotes. */
static void shell_word(FILE *f, const char *w)
{
    int plain = *w != 0;
    for (const char *p = w; *p; p++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_=.,/:+@%", *p))
            plain = 0;
    if (plain) {
        fprintf(f, " %s", w);
        return;
    }
    fputs(" '", f);
    for (const char *p = w; *p; p++)
        fputs(*p == '\'' ? "'\\''" : (char[2]){*p, 0}, f);
    fputc('\'', f);
}

static void shell_quoted(FILE *f, int argc, char **argv)
{
    fputs("murk bench", f);
    for (int i = 0; i < argc; i++)
        shell_word(f, argv[i]);
}

typedef struct meta_job {
    const bench *b;
    const reference *r;
    int argc;
    char **argv;
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
    fprintf(f, ",\n  \"version\": \"%s\",\n  \"scene\": ", MURK_VERSION);
    json_str(f, b->scene);
    fprintf(f, ",\n  \"budget\": \"%s\",\n  \"repeat\": %d,\n  \"threads\": %d,\n  \"cores\": %d,\n", b->time_mode ? "seconds" : "spp",
            b->repeat, b->threads, murk_cpus_usable());
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
        variant_label(b, i, label, sizeof label);
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
    if (stopped(b)) {
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
        if (stopped(b) && !passed) {
            kill(pid, murk_cli_stop_status() - 128);
            passed = 1;
        }
        if (waitpid(pid, &st, 0) == pid || errno != EINTR)
            break;
    }
    if (stopped(b)) {
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

static int run_bench(const bench *b, int argc, char **argv)
{
    char err[2048], path[8192];
    murk_scene *s0 = load_with(b, b->sets, b->nsets, err, sizeof err);
    if (!s0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    reference r = {.w = s0->width, .h = s0->height};
    murk_scene_free(s0);
    if (b->reference) {
        if (read_exr(b->reference, r.w, r.h, &r.rgb) != 0) {
            fprintf(stderr, "murk: --reference %s: not a readable %dx%d EXR (the scene's resolution)\n",
                    murk_cli_q(b->reference), r.w, r.h);
            return 1;
        }
        printf("reference: %s (given; its own noise is not known, so relMSE is not corrected for it)\n",
               murk_cli_q(b->reference));
    } else {
        if (make_reference(b, &r) != 0) {
            ref_free(&r);
            if (!stopped(b))
                return 1;
            fprintf(stderr, "%smurk bench: interrupted (%s) while rendering the reference; nothing written\n",
                    murk_cli_progress() ? "\r\033[K" : "", murk_cli_stop_name());
            return murk_cli_stop_status();
        }
        if (r.reused)
            printf("reference: %s (reused from the cache: same scene file, --set, spp and murk version)\n",
                   murk_cli_q(r.path));
        else
            printf("reference: %s (rendered: %d spp in %d chunks, %.1f s; cached)\n", murk_cli_q(r.path),
                   REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS), REF_CHUNKS, r.seconds);
    }
    fflush(stdout);
    char *rows = NULL;
    size_t rows_len = 0;
    FILE *csv = open_memstream(&rows, &rows_len); /* bench.csv, written whole at the end */
    if (!csv) {
        fprintf(stderr, "murk: out of memory\n");
        ref_free(&r);
        return 1;
    }
    fprintf(csv, "variant,label,budget,seed,spp,seconds,rays");
    for (int k = 0; k < MURK_NCOUNTERS; k++)
        fprintf(csv, ",%s", counter_names[k]);
    fprintf(csv, ",mse,relmse,relmse_se,relmse_raw,ref_noise,mare,nonfinite,max_sample\n");
    int big = 0;
    double total_w = 0, done_w = 0, t0 = now();
    for (int i = 0; i < b->nbudgets; i++) {
        if (b->budgets[i] > b->budgets[big])
            big = i;
        total_w += b->budgets[i] * b->repeat * b->nvariants;
    }
    size_t np = (size_t)r.w * (size_t)r.h;
    snprintf(path, sizeof path, "murk bench: %s", b->scene);
    murk_html_page *page = murk_html_new("bench", path, r.w, r.h, b->nvariants + 1, b->nvariants,
                                         murk_limit(MURK_LIMIT_PAGE_BYTES));
    if (b->reference)
        snprintf(path, sizeof path, "given: %s", b->reference);
    else
        snprintf(path, sizeof path, "%d spp, the mean of %d chunks", REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS),
                 REF_CHUNKS);
    murk_html_image(page, b->nvariants, "reference", path, r.rgb, 1);
    float *pix = murk_xmalloc(np * sizeof(float));
    double *maps = calloc(np * (size_t)b->nvariants, sizeof(double));
    const char **sets = murk_xmalloc((b->nsets + (size_t)b->nvary + b->nref_sets + 2) * sizeof *sets);
    char *store[64];
    size_t nstore = 0;
    int rc = maps ? 0 : 1, count = 0, done = 0, total = b->nbudgets * b->repeat * b->nvariants;
    int tty = murk_cli_progress();
    for (int bi = 0; bi < b->nbudgets && !rc && !stopped(b); bi++)
        for (int k = 0; k < b->repeat && !rc && !stopped(b); k++)
            for (int v = 0; v < b->nvariants && !rc && !stopped(b); v++) { /* variants innermost: A B A B */
                char label[1024], eta[32] = "?";
                variant_label(b, v, label, sizeof label);
                if (done_w > 0)
                    fmt_eta((now() - t0) / done_w * (total_w - done_w), eta, sizeof eta);
                count++;
                if (tty) {
                    fprintf(stderr, "\r\033[K[%d/%d] %s  %s %g  seed %d  ETA %s", count, total, label,
                            b->time_mode ? "time" : "spp", b->budgets[bi], 1 + k, eta);
                    fflush(stderr);
                }
                size_t n = render_sets(b, v, 1 + k, sets, store, &nstore);
                murk_render_opts o = {.threads = b->threads, .stop = b->stop};
                if (b->time_mode) {
                    o.time_limit = b->budgets[bi];
                    o.spp = 1 << 24;
                } else {
                    o.spp = (int)b->budgets[bi];
                }
                murk_render_result res;
                int failed = bench_render(b, v, bi, k, sets, n, &o, r.w, r.h, &res);
                free_store(store, &nstore);
                if (failed < 0) {
                    rc = 1;
                } else if (failed == 0) {
                    murk_metrics m;
                    murk_metrics_compute(res.rgb, r.rgb, r.var, r.w, (murk_crop){0, 0, r.w, r.h}, &m, pix);
                    murk_counters t = murk_counters_total(&res);
                    fprintf(csv, "%d,", v);
                    csv_str(csv, label);
                    fprintf(csv, ",%g,%d,%d,%.6f,%llu", b->budgets[bi], 1 + k, res.spp, res.seconds,
                            (unsigned long long)res.rays);
                    for (int c = 0; c < MURK_NCOUNTERS; c++)
                        fprintf(csv, ",%llu", (unsigned long long)murk_counters_get(&t, c));
                    fprintf(csv, ",%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%llu,%.9g\n", m.mse, m.relmse, m.relmse_se,
                            m.relmse_raw, m.ref_noise, m.mare, (unsigned long long)(res.nonfinite + m.nonfinite),
                            res.max_sample);
                    if (bi == big) {
                        for (size_t p = 0; p < np; p++)
                            maps[(size_t)v * np + p] += isfinite(pix[p]) ? pix[p] / b->repeat : 0.0;
                        murk_html_cost_add(page, v, res.seconds / b->repeat, (double)t.lookups / b->repeat,
                                           m.relmse / b->repeat);
                        char note[96]; /* the page shows the first seed's image: one render at this budget */
                        snprintf(note, sizeof note, "seed 1 of %d, %g %s", b->repeat, b->budgets[bi],
                                 b->time_mode ? "s" : "spp");
                        if (k == 0)
                            murk_html_image(page, v, label, note, res.rgb, 0);
                    }
                    done++;
                }
                done_w += b->budgets[bi];
                free(res.rgb);
                murk_warn_summary();
            }
    if (tty)
        fprintf(stderr, "\r\033[K");
    int bad = fclose(csv) != 0;
    text_job csv_text = {rows, rows_len};
    if (rc == 0 && (bad || !rows)) {
        fprintf(stderr, "murk: out of memory\n");
        rc = 1;
    }
    if (rc == 0 && done < total) { /* a signal: only the whole renders' rows, never as bench.csv */
        int cached = !b->reference && !r.reused && access(r.path, R_OK) == 0; /* rendered by this run */
        snprintf(path, sizeof path, "%s/bench-interrupted.csv", b->out);
        int kept = done > 0 && murk_write_atomic(path, text_fill, &csv_text, err, sizeof err) == 0;
        if (done > 0 && !kept)
            fprintf(stderr, "murk: %s\n", err);
        if (kept)
            fprintf(stderr, "murk bench: interrupted (%s) after %d of %d renders; their rows are in %s (the columns "
                    "of bench.csv); no bench.csv, bench.json, maps or charts were written\n", murk_cli_stop_name(),
                    done, total, murk_cli_q(path));
        else
            fprintf(stderr, "murk bench: interrupted (%s) after %d of %d renders; nothing written%s%s%s\n",
                    murk_cli_stop_name(), done, total, cached ? " but the reference, cached in " : "",
                    cached ? murk_cli_q(r.path) : "", cached ? " for the next bench" : "");
        rc = murk_cli_stop_status();
    }
    snprintf(path, sizeof path, "%s/bench.csv", b->out);
    if (rc == 0 && murk_write_atomic(path, text_fill, &csv_text, err, sizeof err) != 0) {
        fprintf(stderr, "murk: %s\n", err);
        rc = 1;
    }
    if (rc == 0) { /* a stale partial bench of an earlier run would sit beside the whole one */
        snprintf(path, sizeof path, "%s/bench-interrupted.csv", b->out);
        remove(path);
    }
    free(rows);
    /* the per-pixel maps of the largest budget, and the meta data */
    snprintf(path, sizeof path, "%s/maps", b->out);
    if (rc == 0 && mkdirs(path) != 0) {
        fprintf(stderr, "murk: cannot create %s: %s\n", murk_cli_q(path), strerror(errno));
        rc = 1;
    }
    for (int v = 0; v < b->nvariants && rc == 0; v++) {
        for (size_t p = 0; p < np; p++)
            pix[p] = (float)maps[(size_t)v * np + p];
        murk_html_error_map(page, v, pix);
        snprintf(path, sizeof path, "%s/maps/variant%d.npy", b->out, v);
        npy_job nj = {pix, r.w, r.h};
        if (murk_write_atomic(path, npy_fill, &nj, err, sizeof err) != 0) {
            fprintf(stderr, "murk: %s\n", err);
            rc = 1;
        }
    }
    snprintf(path, sizeof path, "%s/bench.json", b->out);
    meta_job mj = {b, &r, argc, argv};
    if (rc == 0 && murk_write_atomic(path, meta_fill, &mj, err, sizeof err) != 0) {
        fprintf(stderr, "murk: %s\n", err);
        rc = 1;
    }
    free(pix);
    free(maps);
    free(sets);
    ref_free(&r);
    if (rc == 0)
        printf("%d renders (%d variants x %d budgets x %d seeds) in %.1f s: %s/bench.csv\n", total, b->nvariants,
               b->nbudgets, b->repeat, now() - t0, b->out);
    int whole = rc == 0;
    if (rc == 0)
        rc = run_charts(b); /* and a signal after the last render is said there */
    if (whole && rc <= 1 && !stopped(b))
        rc = write_page(page, b, rc);
    murk_html_free(page);
    return rc;
}

/* One render as a command line of jobs.txt. */
static void emit_job(const bench *b, FILE *jobs, const char *murk, const char *scene, const char *const *sets,
                     size_t n, double budget, const char *out)
{
    char num[64], *line = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&line, &len);
    if (!f) {
        fprintf(stderr, "murk: out of memory\n");
        exit(1);
    }
    shell_word(f, murk);
    fputs(" render", f);
    shell_word(f, scene);
    for (size_t i = 0; i < n; i++) {
        fputs(" --set", f);
        shell_word(f, sets[i]);
    }
    if (b->time_mode && budget > 0) {
        snprintf(num, sizeof num, "%g", budget);
        fprintf(f, " --time %s --spp %d", num, 1 << 24);
    } else {
        fprintf(f, " --spp %d", (int)budget);
    }
    if (b->threads)
        fprintf(f, " --threads %d", b->threads);
    fputs(" --quiet -o", f);
    shell_word(f, out);
    fclose(f);
    fprintf(jobs, "%s\n", line + 1); /* without shell_word's leading space */
    free(line);
}

/* --emit-jobs DIR: every render of the bench (the reference's chunks first) as one line of DIR/jobs.txt,
 * DIR/slurm.sh running line SLURM_ARRAY_TASK_ID + 1 as one task of a job array, and DIR/assemble.sh,
 * this bench's command line with --assemble DIR, which reads the images back into bench.csv, the
 * charts and the report as if the renders had run here. The jobs' paths are absolute. */
static int emit_jobs(const bench *b, int argc, char **argv)
{
    char murk[4096], scene[4096], dir[4096], path[8192], out[8192];
    ssize_t l = readlink("/proc/self/exe", murk, sizeof murk - 1);
    if (l <= 0 || !realpath(b->scene, scene)) {
        fprintf(stderr, "murk: cannot resolve the paths of murk and %s\n", murk_cli_q(b->scene));
        return 1;
    }
    murk[l] = 0;
    snprintf(path, sizeof path, "%s/renders", b->jobs);
    if (mkdirs(path) != 0 || !realpath(b->jobs, dir)) {
        fprintf(stderr, "murk: cannot create %s: %s\n", murk_cli_q(path), strerror(errno));
        return 1;
    }
    bench jb = *b;
    jb.jobs = dir;
    /* the three files as text in memory, then written as one group (atomic.h): all of them or none */
    enum { JOBS, SLURM, ASSEMBLE, NFILES };
    static const char *const names[NFILES] = {"jobs.txt", "slurm.sh", "assemble.sh"};
    char *text[NFILES] = {NULL, NULL, NULL};
    size_t len[NFILES] = {0, 0, 0};
    FILE *f = open_memstream(&text[JOBS], &len[JOBS]);
    if (!f) {
        fprintf(stderr, "murk: out of memory\n");
        return 1;
    }
    const char **sets = murk_xmalloc((b->nsets + (size_t)b->nvary + b->nref_sets + 2) * sizeof *sets);
    char *store[64];
    size_t nstore = 0;
    int njobs = 0;
    for (int c = 0; c < REF_CHUNKS && !b->reference; c++) {
        char seed[40];
        size_t n = render_sets(b, -1, -1, sets, store, &nstore);
        snprintf(seed, sizeof seed, "render.seed=%d", 900001 + c);
        sets[n++] = seed;
        job_out(&jb, -1, 0, c, out, sizeof out);
        emit_job(b, f, murk, scene, sets, n, (b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS, out);
        free_store(store, &nstore);
        njobs++;
    }
    for (int bi = 0; bi < b->nbudgets; bi++)
        for (int k = 0; k < b->repeat; k++)
            for (int v = 0; v < b->nvariants; v++) {
                size_t n = render_sets(b, v, 1 + k, sets, store, &nstore);
                job_out(&jb, v, bi, k, out, sizeof out);
                emit_job(b, f, murk, scene, sets, n, b->budgets[bi], out);
                free_store(store, &nstore);
                njobs++;
            }
    free(sets);
    int bad = fclose(f) != 0;
    if (!bad && (f = open_memstream(&text[SLURM], &len[SLURM])) != NULL) {
        fprintf(f, "#!/bin/sh\n# murk bench as a Slurm job array: one render per task (line TASK + 1 of jobs.txt).\n"
                   "#   jid=$(sbatch --parsable slurm.sh)\n"
                   "#   sbatch --dependency=afterok:$jid --wrap 'sh %s/assemble.sh'\n"
                   "#SBATCH --job-name=murk-bench\n#SBATCH --array=0-%d\n"
                   "exec sh -c \"$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" '%s/jobs.txt')\"\n", dir, njobs - 1, dir);
        bad = fclose(f) != 0;
    } else {
        bad = 1;
    }
    if (!bad && (f = open_memstream(&text[ASSEMBLE], &len[ASSEMBLE])) != NULL) {
        char cwd[4096];
        fprintf(f, "#!/bin/sh\n# Reads the renders of jobs.txt back into bench.csv, the charts and the report: the\n"
                   "# bench's own command line, in its folder, with --assemble for --emit-jobs.\ncd");
        shell_word(f, getcwd(cwd, sizeof cwd) ? cwd : ".");
        fputs(" || exit 1\nexec", f);
        shell_word(f, murk);
        fputs(" bench", f);
        for (int i = 0; i < argc; i++) {
            if (!strcmp(argv[i], "--emit-jobs")) {
                fputs(" --assemble", f);
                shell_word(f, dir);
                i++;
            } else {
                shell_word(f, argv[i]);
            }
        }
        fputc('\n', f);
        bad = fclose(f) != 0;
    } else {
        bad = 1;
    }
    char err[8400] = "out of memory";
    if (!bad) {
        murk_output_begin();
        for (int i = 0; i < NFILES && !bad; i++) {
            text_job tj = {text[i], len[i]};
            snprintf(path, sizeof path, "%s/%s", dir, names[i]);
            bad = murk_write_atomic(path, text_fill, &tj, err, sizeof err) != 0;
        }
        if (bad)
            murk_output_abort();
        else
            bad = murk_output_commit(err, sizeof err) != 0;
    }
    for (int i = 0; i < NFILES; i++)
        free(text[i]);
    if (bad) {
        fprintf(stderr, "murk: %s\n", err);
        return 1;
    }
    printf("%d renders as jobs: %s/jobs.txt (one command a line), %s/slurm.sh (sbatch: a job array); then "
           "sh %s/assemble.sh\n", njobs, dir, dir, dir);
    return 0;
}

static const char bench_usage[] =
    "usage: murk bench SCENE.yaml [--vary KEY=V1,V2,...]... [--set KEY=VALUE]... [--spp N1,N2,... | --time S1,S2,...]\n"
    "                  [--repeat K] [--reference REF.exr | --ref-spp N [--ref-set KEY=VALUE]...] [--threads N]\n"
    "                  [-o DIR] [--no-charts] [--emit-jobs JOBDIR | --assemble JOBDIR]\n"
    "SIGINT/SIGTERM/SIGHUP abandon the running render; the finished renders' rows go to DIR/bench-interrupted.csv\n"
    "(never bench.csv) and murk exits with 128 + the signal.\n";

int murk_cli_bench(int argc, char **argv)
{
    bench b = {0};
    b.repeat = 3;
    b.charts = 1;
    b.sets = murk_xmalloc((size_t)(argc + 1) * sizeof *b.sets);
    b.ref_sets = murk_xmalloc((size_t)(argc + 1) * sizeof *b.ref_sets);
    b.vary = murk_xmalloc((size_t)(argc + 1) * sizeof *b.vary);
    int rc = 0;
    long lv;
    for (int i = 0; i < argc && !rc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int needs = strcmp(a, "--no-charts") && strcmp(a, "--help") && strcmp(a, "-h") && a[0] == '-';
        if (needs && !v) {
            fprintf(stderr, "murk: %s needs a value\n%s", murk_cli_q(a), bench_usage);
            rc = 2;
            break;
        }
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(bench_usage, stdout);
            rc = -1;
        } else if (!strcmp(a, "--vary")) {
            const char *eq = strchr(v, '=');
            if (!eq || eq == v || !eq[1]) {
                fprintf(stderr, "murk: --vary needs KEY.PATH=V1,V2,..., got '%s'\n", murk_cli_q(v));
                rc = 2;
            } else if (b.nvary == MAX_VARY) {
                fprintf(stderr, "murk: at most %d --vary\n", MAX_VARY);
                rc = 2;
            } else {
                vary *x = &b.vary[b.nvary++];
                x->arg = v;
                x->key = murk_xmalloc((size_t)(eq - v) + 1);
                memcpy(x->key, v, (size_t)(eq - v));
                x->key[eq - v] = 0;
                x->vals = split_list(eq + 1, &x->nvals);
            }
            i++;
        } else if (!strcmp(a, "--set")) {
            b.sets[b.nsets++] = v, i++;
        } else if (!strcmp(a, "--ref-set")) {
            b.ref_sets[b.nref_sets++] = v, i++;
        } else if (!strcmp(a, "--spp") || !strcmp(a, "--time")) {
            rc = parse_budgets(a, v, !strcmp(a, "--time"), &b) ? 2 : 0, i++;
        } else if (!strcmp(a, "--repeat")) {
            char *end;
            lv = strtol(v, &end, 10);
            if (*end || lv < 2 || lv > 1000) {
                fprintf(stderr, "murk: --repeat needs a whole number in [2, 1000] (standard errors need 2 seeds)\n");
                rc = 2;
            }
            b.repeat = (int)lv, i++;
        } else if (!strcmp(a, "--ref-spp") || !strcmp(a, "--threads")) {
            char *end;
            lv = strtol(v, &end, 10);
            if (*end || lv < (a[2] == 'r' ? REF_CHUNKS : 0) || lv > 1L << 24) {
                fprintf(stderr, "murk: %s needs a whole number in [%d, %ld], got '%s'\n", a, a[2] == 'r' ? REF_CHUNKS : 0,
                        1L << 24, murk_cli_q(v));
                rc = 2;
            }
            *(a[2] == 'r' ? &b.ref_spp : &b.threads) = (int)lv, i++;
        } else if (!strcmp(a, "--reference")) {
            b.reference = v, i++;
        } else if (!strcmp(a, "-o")) {
            b.out = v, i++;
        } else if (!strcmp(a, "--emit-jobs") || !strcmp(a, "--assemble")) {
            if (b.jobs) {
                fprintf(stderr, "murk: --emit-jobs and --assemble are given once, not both\n%s", bench_usage);
                rc = 2;
            }
            b.jobs = v, b.assemble = a[2] == 'a', i++;
        } else if (!strcmp(a, "--no-charts")) {
            b.charts = 0;
        } else if (a[0] == '-') {
            fprintf(stderr, "murk: unknown bench option '%s'\n%s", murk_cli_q(a), bench_usage);
            rc = 2;
        } else if (!b.scene) {
            b.scene = a;
        } else {
            fprintf(stderr, "murk: bench takes one scene\n%s", bench_usage);
            rc = 2;
        }
    }
    if (rc == 0 && !b.scene) {
        fprintf(stderr, "murk: bench needs a scene\n%s", bench_usage);
        rc = 2;
    }
    if (rc == 0 && b.reference && (b.ref_spp || b.nref_sets)) {
        fprintf(stderr, "murk: --reference and --ref-spp/--ref-set exclude each other\n");
        rc = 2;
    }
    if (rc == 0 && !b.nbudgets)
        rc = parse_budgets("--spp", "4,16,64", 0, &b);
    b.nvariants = 1;
    for (int j = 0; j < b.nvary && rc == 0; j++) {
        if ((double)b.nvariants * b.vary[j].nvals > 1000) {
            fprintf(stderr, "murk: the --vary lists make more than 1000 variants\n");
            rc = 2;
        }
        b.nvariants *= b.vary[j].nvals;
        for (int k = 0; k < b.vary[j].nvals; k++)
            if (!*b.vary[j].vals[k]) {
                fprintf(stderr, "murk: --vary %s has an empty value\n", murk_cli_q(b.vary[j].arg));
                rc = 2;
            }
    }
    if (rc == 0 && !b.ref_spp) { /* default: 16 x the largest spp budget (equal time: 1024) */
        double mx = 0;
        for (int i = 0; i < b.nbudgets; i++)
            mx = fmax(mx, b.budgets[i]);
        b.ref_spp = b.time_mode ? 1024 : (int)fmin(fmax(16 * mx, 64), 1 << 24);
    }
    char outbuf[4096];
    if (rc == 0) {
        if (!b.out) {
            const char *base = strrchr(b.scene, '/');
            base = base ? base + 1 : b.scene;
            snprintf(outbuf, sizeof outbuf, "bench-%.*s", (int)strcspn(base, "."), base);
            b.out = outbuf;
        }
        murk_set_quiet(1);
        if (validate(&b) != 0)
            rc = 1;
    }
    if (rc == 0 && b.jobs && !b.assemble) {
        rc = emit_jobs(&b, argc, argv);
        rc = rc ? rc : -1;
    }
    struct stat st;
    int made_out = rc == 0 && stat(b.out, &st) != 0;
    if (rc == 0)
        b.stop = murk_cli_catch_stop_signals(); /* a signal stops after the running render (run_bench) */
    if (rc == 0 && mkdirs(b.out) != 0) {
        fprintf(stderr, "murk: cannot create the output folder '%s': %s\n", murk_cli_q(b.out), strerror(errno));
        rc = 1;
    }
    char page[4200], err[8400];
    snprintf(page, sizeof page, "%s/report.html", b.out);
    if (rc == 0 && murk_html_check_path(page, err, sizeof err) != 0) { /* before any render */
        fprintf(stderr, "murk: %s; nothing was rendered\n", err);
        rc = 1;
    }
    if (rc == 0) {
        rc = run_bench(&b, argc, argv);
        if (rc > 128 && made_out)
            rmdir(b.out); /* interrupted: the folder it made goes again if nothing was written into it */
    }
    for (int j = 0; j < b.nvary; j++) {
        free(b.vary[j].key);
        free_list(b.vary[j].vals, b.vary[j].nvals);
    }
    free(b.vary);
    free(b.sets);
    free(b.ref_sets);
    free(b.budgets);
    return rc < 0 ? 0 : rc;
}
