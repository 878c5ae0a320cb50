/* bench.c — `murk bench SCENE.yaml`: renders every variant (the cross product of the --vary lists) at
 * every budget (--spp or --time) with --repeat seeds, measures each render against a reference
 * (metrics.c: the noise-corrected relMSE and the rest) and its work (the cost counters), writes
 * DIR/bench.csv, DIR/bench.json and DIR/maps/, runs the chart script (tools/bench_report.py) for
 * the charts and report.md, and writes DIR/report.html, the comparison page (lab/report_html.h): each
 * variant's first-seed image at the largest budget, the reference, the error maps, charts and tables.
 * This file: the options, the variants and their --set lists, checking that every variant loads before
 * anything is rendered, and the entry points (murk/lab.h); the rest is in bench_run.c, bench_ref.c and
 * bench_jobs.c (bench.h). Part of libmurklab. */
#include "lab/bench.h"

#include "cmd/cmd.h"
#include "lab/report_html.h"
#include "load/load.h"
#include "scene/scene.h"
#include "util/runtime.h"
#include "util/util.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char **split_list(const char *s, int *n)
{
    char **v = NULL;
    *n = 0;
    for (const char *p = s;;) {
        const char *c = p;
        int depth = 0, quote = 0; /* a comma inside [], {} or quotes belongs to its value: {type: X, k: v} */
        for (; *c && (*c != ',' || depth > 0 || quote); c++) {
            if (quote)
                quote = *c == quote ? 0 : quote;
            else if (*c == '"' || *c == '\'')
                quote = *c;
            else
                depth += (*c == '[' || *c == '{') - (*c == ']' || *c == '}');
        }
        size_t l = (size_t)(c - p);
        v = murk_xrealloc(v, (size_t)(*n + 1) * sizeof *v);
        v[*n] = murk_xmalloc(l + 1);
        memcpy(v[*n], p, l);
        v[*n][l] = 0;
        (*n)++;
        if (!*c)
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

/* s without its leading and trailing blanks, into a new string. */
static char *trimmed(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t l = strlen(s);
    while (l && (s[l - 1] == ' ' || s[l - 1] == '\t'))
        l--;
    char *t = murk_xmalloc(l + 1);
    memcpy(t, s, l);
    t[l] = 0;
    return t;
}

/* The --set assignments of --vary KEY's value v, into out (max of them; freed by the caller): KEY=v; or,
 * when v is a whole plugin block {type: X, k: w, ...}, one per key with `type` first, KEY.type=X KEY.k=w,
 * so that the swap of the type drops the previous plugin's keys and the new plugin's keys are checked
 * against the new plugin (a block given whole would drop the scene's density, sigma_s, ...). The count,
 * or -1 when v is a block whose items are not `key: value`. */
static int vary_assignments(const char *key, const char *v, char **out, int max)
{
    char *t = trimmed(v);
    size_t tl = strlen(t);
    if (t[0] != '{' || tl < 2 || t[tl - 1] != '}') {
        free(t);
        out[0] = murk_xmalloc(strlen(key) + strlen(v) + 2);
        sprintf(out[0], "%s=%s", key, v);
        return 1;
    }
    t[tl - 1] = 0;
    int nitems, n = 0, bad = 0;
    char **items = split_list(t + 1, &nitems);
    for (int pass = 0; pass < 2 && !bad; pass++) /* type, then the rest in the order given */
        for (int i = 0; i < nitems && !bad; i++) {
            char *colon = strchr(items[i], ':');
            char *k = colon ? (*colon = 0, trimmed(items[i])) : NULL;
            if (colon)
                *colon = ':';
            char *w = colon ? trimmed(colon + 1) : NULL;
            bad = !k || !*k || strspn(k, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != strlen(k) ||
                  !*w || n == max;
            if (!bad && (pass == 0) == !strcmp(k, "type")) {
                out[n] = murk_xmalloc(strlen(key) + strlen(k) + strlen(w) + 3);
                sprintf(out[n++], "%s.%s=%s", key, k, w);
            }
            free(k);
            free(w);
        }
    free_list(items, nitems);
    free(t);
    if (bad) {
        while (n > 0)
            free(out[--n]);
        return -1;
    }
    return n;
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
void murk_bench_label(const bench *b, int i, char *buf, size_t n)
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
size_t murk_bench_sets(const bench *b, int i, long seed, const char **out, char **store, size_t *nstore)
{
    size_t n = 0;
    for (size_t k = 0; k < b->nsets; k++)
        out[n++] = b->sets[k];
    if (i < 0 && b->nref_sets) {
        for (size_t k = 0; k < b->nref_sets; k++)
            out[n++] = b->ref_sets[k];
    } else {
        for (int j = 0; j < b->nvary; j++) {
            int m = vary_assignments(b->vary[j].key, b->vary[j].vals[variant_value(b, i < 0 ? 0 : i, j)],
                                     store + *nstore, MAX_BLOCK_KEYS); /* parse_vary checked it */
            for (int q = 0; q < m; q++)
                out[n++] = store[(*nstore)++];
        }
    }
    if (seed >= 0) {
        char *s = murk_xmalloc(40);
        snprintf(s, 40, "render.seed=%ld", seed);
        out[n++] = store[(*nstore)++] = s;
    }
    return n;
}

void murk_bench_free_sets(char **store, size_t *n)
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
murk_scene *murk_bench_load(const bench *b, const char *const *sets, size_t nsets, char *err, size_t errlen)
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
    const char **sets = murk_xmalloc(murk_bench_max_sets(b) * sizeof *sets);
    murk_scene *s = murk_bench_load(b, b->sets, b->nsets, err, sizeof err);
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
            char *one[MAX_BLOCK_KEYS];
            size_t n = 0;
            for (size_t q = 0; q < b->nsets; q++)
                sets[n++] = b->sets[q];
            int m = vary_assignments(b->vary[j].key, b->vary[j].vals[k], one, MAX_BLOCK_KEYS);
            for (int q = 0; q < m; q++)
                sets[n++] = one[q];
            murk_scene *t = murk_bench_load(b, sets, n, err, sizeof err);
            for (int q = 0; q < m; q++)
                free(one[q]);
            if (!t) {
                fprintf(stderr, "%s\nmurk: bench: in --vary %s (value '%s'); nothing was rendered\n", err,
                        murk_cli_q(b->vary[j].arg), murk_cli_q(b->vary[j].vals[k]));
                rc = -1;
            }
            murk_scene_free(t);
        }
    }
    char *store[BENCH_STORE];
    size_t nstore = 0;
    for (int i = -1; i < b->nvariants && !rc; i++) {
        if (i < 0 && !b->nref_sets)
            continue;
        size_t n = murk_bench_sets(b, i, -1, sets, store, &nstore);
        murk_scene *t = murk_bench_load(b, sets, n, err, sizeof err);
        char label[1024];
        murk_bench_label(b, i < 0 ? 0 : i, label, sizeof label);
        if (!t) {
            fprintf(stderr, "%s\nmurk: bench: in %s%s%s; nothing was rendered\n", err,
                    i < 0 ? "the reference's --ref-set" : "variant '", i < 0 ? "" : murk_cli_q(label),
                    i < 0 ? "" : "'");
            rc = -1;
        } else if (t->width != s->width || t->height != s->height) {
            fprintf(stderr, "murk: bench: %s has another resolution than the scene; nothing was rendered\n",
                    i < 0 ? "the reference" : murk_cli_q(label));
            rc = -1;
        }
        murk_scene_free(t);
        murk_bench_free_sets(store, &nstore);
    }
    murk_scene_free(s);
    free(sets);
    return rc;
}

int murk_bench_mkdirs(const char *path)
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

static const char bench_usage[] =
    "usage: murk bench SCENE.yaml [--vary KEY=V1,V2,...]... [--set KEY=VALUE]... [--spp N1,N2,... | --time S1,S2,...]\n"
    "                  [--repeat K] [--reference REF.exr | --ref-spp N [--ref-set KEY=VALUE]...] [--threads N]\n"
    "                  [-o DIR] [--no-charts] [--emit-jobs JOBDIR | --assemble JOBDIR]\n"
    "A --vary value in braces is a whole plugin block, its keys set together with the type first, so that a swap\n"
    "carries its own keys: --vary 'media.smoke={type: decomposition, control: 0.5},{type: delta}'. Values are\n"
    "split at commas outside brackets, braces and quotes.\n"
    "SIGINT/SIGTERM/SIGHUP abandon the running render; the finished renders' rows go to DIR/bench-interrupted.csv\n"
    "(never bench.csv) and murk exits with 128 + the signal.\n";

/* --vary KEY=V1,V2,...: 0, or 2 after a message. */
static int parse_vary(bench *b, const char *v)
{
    const char *eq = strchr(v, '=');
    if (!eq || eq == v || !eq[1]) {
        fprintf(stderr, "murk: --vary needs KEY.PATH=V1,V2,..., got '%s'\n", murk_cli_q(v));
        return 2;
    }
    if (b->nvary == MAX_VARY) {
        fprintf(stderr, "murk: at most %d --vary\n", MAX_VARY);
        return 2;
    }
    vary *x = &b->vary[b->nvary++];
    x->arg = v;
    x->key = murk_xmalloc((size_t)(eq - v) + 1);
    memcpy(x->key, v, (size_t)(eq - v));
    x->key[eq - v] = 0;
    x->vals = split_list(eq + 1, &x->nvals);
    return 0;
}

/* --repeat, --ref-spp or --threads (a, its value v): 0, or 2 after a message. */
static int parse_count(bench *b, const char *a, const char *v)
{
    char *end;
    long lv = strtol(v, &end, 10);
    if (!strcmp(a, "--repeat")) {
        b->repeat = (int)lv;
        if (*end || lv < 2 || lv > 1000) {
            fprintf(stderr, "murk: --repeat needs a whole number in [2, 1000] (standard errors need 2 seeds)\n");
            return 2;
        }
        return 0;
    }
    *(a[2] == 'r' ? &b->ref_spp : &b->threads) = (int)lv;
    if (*end || lv < (a[2] == 'r' ? REF_CHUNKS : 0) || lv > 1L << 24) {
        fprintf(stderr, "murk: %s needs a whole number in [%d, %ld], got '%s'\n", a, a[2] == 'r' ? REF_CHUNKS : 0,
                1L << 24, murk_cli_q(v));
        return 2;
    }
    return 0;
}

/* The option argv[*i] (and its value, *i moved past it) into b: 0; 2 after a message; -1 for --help,
 * printed. */
static int bench_option(bench *b, int argc, char **argv, int *i)
{
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    int needs = strcmp(a, "--no-charts") && strcmp(a, "--help") && strcmp(a, "-h") && a[0] == '-';
    if (needs && !v) {
        fprintf(stderr, "murk: %s needs a value\n%s", murk_cli_q(a), bench_usage);
        return 2;
    }
    *i += needs;
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
        fputs(bench_usage, stdout);
        return -1;
    } else if (!strcmp(a, "--vary")) {
        return parse_vary(b, v);
    } else if (!strcmp(a, "--set")) {
        b->sets[b->nsets++] = v;
    } else if (!strcmp(a, "--ref-set")) {
        b->ref_sets[b->nref_sets++] = v;
    } else if (!strcmp(a, "--spp") || !strcmp(a, "--time")) {
        return parse_budgets(a, v, !strcmp(a, "--time"), b) ? 2 : 0;
    } else if (!strcmp(a, "--repeat") || !strcmp(a, "--ref-spp") || !strcmp(a, "--threads")) {
        return parse_count(b, a, v);
    } else if (!strcmp(a, "--reference")) {
        b->reference = v;
    } else if (!strcmp(a, "-o")) {
        b->out = v;
    } else if (!strcmp(a, "--emit-jobs") || !strcmp(a, "--assemble")) {
        int twice = b->jobs != NULL;
        b->jobs = v, b->assemble = a[2] == 'a';
        if (twice) {
            fprintf(stderr, "murk: --emit-jobs and --assemble are given once, not both\n%s", bench_usage);
            return 2;
        }
    } else if (!strcmp(a, "--no-charts")) {
        b->charts = 0;
    } else if (a[0] == '-') {
        fprintf(stderr, "murk: unknown bench option '%s'\n%s", murk_cli_q(a), bench_usage);
        return 2;
    } else if (!b->scene) {
        b->scene = a;
    } else {
        fprintf(stderr, "murk: bench takes one scene\n%s", bench_usage);
        return 2;
    }
    return 0;
}

/* What the options leave to check together, and the defaults: the budgets (4,16,64 spp), the variants'
 * count, the reference's spp (16 x the largest spp budget; equal time: 1024) and the folder
 * (bench-SCENE, in outbuf). 0, or 2 after a message. */
static int bench_defaults(bench *b, char *outbuf, size_t outlen)
{
    if (!b->scene) {
        fprintf(stderr, "murk: bench needs a scene\n%s", bench_usage);
        return 2;
    }
    if (b->reference && (b->ref_spp || b->nref_sets)) {
        fprintf(stderr, "murk: --reference and --ref-spp/--ref-set exclude each other\n");
        return 2;
    }
    if (!b->nbudgets && parse_budgets("--spp", "4,16,64", 0, b))
        return 2;
    b->nvariants = 1;
    for (int j = 0; j < b->nvary; j++) {
        int rc = 0;
        if ((double)b->nvariants * b->vary[j].nvals > 1000) {
            fprintf(stderr, "murk: the --vary lists make more than 1000 variants\n");
            rc = 2;
        }
        b->nvariants *= b->vary[j].nvals;
        for (int k = 0; k < b->vary[j].nvals && !rc; k++) {
            char *one[MAX_BLOCK_KEYS];
            int m = *b->vary[j].vals[k] ? vary_assignments(b->vary[j].key, b->vary[j].vals[k], one, MAX_BLOCK_KEYS) : 0;
            if (m <= 0) {
                if (m == 0)
                    fprintf(stderr, "murk: --vary %s has an empty value\n", murk_cli_q(b->vary[j].arg));
                else
                    fprintf(stderr, "murk: --vary %s: '%s' is not a block {key: value, ...} of at most %d keys\n",
                            murk_cli_q(b->vary[j].arg), murk_cli_q(b->vary[j].vals[k]), MAX_BLOCK_KEYS);
                rc = 2;
            }
            while (m > 0)
                free(one[--m]);
        }
        if (rc)
            return rc;
    }
    if (!b->ref_spp) {
        double mx = 0;
        for (int i = 0; i < b->nbudgets; i++)
            mx = fmax(mx, b->budgets[i]);
        b->ref_spp = b->time_mode ? 1024 : (int)fmin(fmax(16 * mx, 64), 1 << 24);
    }
    if (!b->out) {
        const char *base = strrchr(b->scene, '/');
        base = base ? base + 1 : b->scene;
        snprintf(outbuf, outlen, "bench-%.*s", (int)strcspn(base, "."), base);
        b->out = outbuf;
    }
    return 0;
}

static void bench_free(bench *b)
{
    for (int j = 0; j < b->nvary; j++) {
        free(b->vary[j].key);
        free_list(b->vary[j].vals, b->vary[j].nvals);
    }
    free(b->vary);
    free(b->sets);
    free(b->ref_sets);
    free(b->budgets);
}

/* The bench once its options hold: every variant loads, then --emit-jobs writes the jobs, or the folder
 * (and the page's path) is made ready and the bench runs with the stop signals caught. The exit status,
 * or -1 when the jobs were written. */
static int bench_main(bench *b, int argc, char **argv)
{
    murk_set_quiet(1);
    if (validate(b) != 0)
        return 1;
    if (b->jobs && !b->assemble) {
        int rc = murk_bench_emit_jobs(b, argc, argv);
        return rc ? rc : -1;
    }
    struct stat st;
    int made_out = stat(b->out, &st) != 0;
    if (b->command)
        b->stop = murk_cli_catch_stop_signals(); /* a signal stops after the running render (murk_bench_run) */
    if (murk_bench_mkdirs(b->out) != 0) {
        fprintf(stderr, "murk: cannot create the output folder '%s': %s\n", murk_cli_q(b->out), strerror(errno));
        return 1;
    }
    char page[4200], err[8400];
    snprintf(page, sizeof page, "%s/report.html", b->out);
    if (murk_html_check_path(page, err, sizeof err) != 0) { /* before any render */
        fprintf(stderr, "murk: %s; nothing was rendered\n", err);
        return 1;
    }
    int rc = murk_bench_run(b, argc, argv);
    if (rc > 128 && made_out)
        rmdir(b->out); /* interrupted: the folder it made goes again if nothing was written into it */
    return rc;
}

static int bench_entry(int argc, char **argv, volatile sig_atomic_t *stop, murk_bench_row_fn row, void *user,
                       int command)
{
    bench b = {.repeat = 3, .charts = 1, .stop = stop, .command = command, .row = row, .user = user};
    b.sets = murk_xmalloc((size_t)(argc + 1) * sizeof *b.sets);
    b.ref_sets = murk_xmalloc((size_t)(argc + 1) * sizeof *b.ref_sets);
    b.vary = murk_xmalloc((size_t)(argc + 1) * sizeof *b.vary);
    char outbuf[4096];
    int rc = 0;
    for (int i = 0; i < argc && !rc; i++)
        rc = bench_option(&b, argc, argv, &i);
    if (rc == 0)
        rc = bench_defaults(&b, outbuf, sizeof outbuf);
    if (rc == 0 && b.jobs && !b.assemble && !command) {
        fprintf(stderr, "murk: --emit-jobs writes jobs that run the murk command: give it to `murk bench`\n");
        rc = 2;
    }
    if (rc == 0)
        rc = bench_main(&b, argc, argv);
    bench_free(&b);
    return rc < 0 ? 0 : rc;
}

MURK_API int murk_lab_bench(int argc, char **argv) { return bench_entry(argc, argv, NULL, NULL, NULL, 1); }

MURK_API int murk_lab_bench_run(int argc, char **argv, volatile sig_atomic_t *stop, murk_bench_row_fn row, void *user)
{
    return bench_entry(argc, argv, stop, row, user, 0);
}
