/* plugins.c — `murk plugins [--markdown] [--all | NAME]`: the plugins on the search path and their
 * parameter schemas, as text for a terminal or as markdown for the docs. The schema's doc strings are
 * the only description of a parameter; tools/plugin_docs.py writes README.md's and docs/plugins.md's
 * generated blocks from this command's markdown, and the test `plugin_docs` fails when they differ. */
#include "cli/cli.h"
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "util/util.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { DOC_INDENT = 8, DOC_WIDTH = 100 }; /* text: a parameter's doc under its line, wrapped */

/* The medium keys the core reads apart from its schema (murk_medium_special_keys): a map and a name. */
typedef struct special_key {
    const char *name, *type, *doc;
} special_key;
static const special_key density_key = {
    .name = "density",
    .type = "map",
    .doc = "{ constant: V } | { grid: FILE.vol|FILE.nvdb } | { vdb: FILE.vdb, grid: NAME } | { cloud: { ... } }",
};
/* after the schema's keys */
static const special_key tail_keys[] = {
    {"transmittance", "name", "shadow-ray estimator: NAME or { type: NAME, ... } (default: the tracker's own)"},
    {"phase", "name", "phase function: NAME or { type: NAME, ... } (hg, isotropic, draine, hg_draine, rayleigh; "
                      "default: Henyey-Greenstein of g)"},
    {"albedo", "rgb|map", "single-scattering albedo in [0, 1]: [r, g, b] (sets the split of sigma_a and sigma_s, "
                          "their sum kept) or a field { grid: FILE.vol (1 or 3 channels)|FILE.nvdb } | { cloud: "
                          "{ ... } }: sigma_s(p) = albedo(p) sigma_t(p)"},
    {"emission", "rgb|map", "radiance emitted per unit absorption (the medium emits sigma_a(p) Le(p)): [r, g, b] or a "
                            "field { grid: ... } | { cloud: { ... } }; with a temperature it scales the blackbody "
                            "radiance (default 1)"},
    {"temperature", "map", "kelvin, (value - temperature_offset) x temperature_scale: { grid: ... } | { constant: "
                           "V } | { cloud: { ... } }; blackbody emission (Planck, CIE 1931, linear sRGB, normalised "
                           "to its peak as pbrt-v4)"},
};
#define NTAIL (sizeof tail_keys / sizeof tail_keys[0])

static const char *type_name(uint32_t t)
{
    static const char *const names[] = {"?", "float", "int", "bool", "rgb", "string", "enum"};
    return t <= MURK_PARAM_ENUM ? names[t] : "?";
}

/* A parameter's default and range as both formats show them (range empty for strings and bools). */
static void param_fields(const murk_param *q, char *def, size_t ndef, char *range, size_t nrange)
{
    switch (q->type) {
    case MURK_PARAM_RGB:
        snprintf(def, ndef, "[%g, %g, %g]", q->def[0], q->def[1], q->def[2]);
        break;
    case MURK_PARAM_BOOL:
        snprintf(def, ndef, "%s", q->def[0] != 0 ? "true" : "false");
        break;
    case MURK_PARAM_STRING:
    case MURK_PARAM_ENUM:
        snprintf(def, ndef, "%s", q->def_str ? q->def_str : "");
        break;
    default:
        snprintf(def, ndef, "%g", q->def[0]);
    }
    range[0] = '\0';
    if (q->type == MURK_PARAM_ENUM)
        snprintf(range, nrange, "one of %s", q->choices);
    else if (q->type != MURK_PARAM_STRING && q->type != MURK_PARAM_BOOL)
        snprintf(range, nrange, "[%g, %g]", q->min, q->max);
}

/* ---- text ---------------------------------------------------------------------------------- */

/* text at DOC_INDENT, broken at spaces before DOC_WIDTH columns (a longer word stays whole) */
static void print_wrapped(const char *text)
{
    const int room = DOC_WIDTH - DOC_INDENT;
    while (*text) {
        int n = (int)strlen(text), cut = n;
        if (n > room) {
            cut = room;
            while (cut > 0 && text[cut] != ' ')
                cut--;
            if (cut == 0)
                cut = (int)strcspn(text, " ");
        }
        printf("%*s%.*s\n", DOC_INDENT, "", cut, text);
        text += cut;
        while (*text == ' ')
            text++;
    }
}

static void print_params(const murk_param *ps, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        const murk_param *q = &ps[i];
        char def[128], range[256], line[512];
        param_fields(q, def, sizeof def, range, sizeof range);
        int n = snprintf(line, sizeof line, "    %-19s %-6s default %-18s %s%s%s", q->name, type_name(q->type), def,
                         range, (q->flags & MURK_PARAM_TEXTURABLE) ? " (texturable)" : "",
                         (q->flags & MURK_PARAM_REQUIRED) ? " (required)" : "");
        for (n = n < (int)sizeof line ? n : (int)sizeof line - 1; n > 0 && line[n - 1] == ' '; n--)
            line[n - 1] = '\0'; /* no trailing blanks where there is no range */
        puts(line);
        print_wrapped(q->doc);
    }
}

static void print_key(const special_key *key)
{
    printf("    %-19s %s\n", key->name, key->type);
    print_wrapped(key->doc);
}

static void medium_keys_text(void)
{
    printf("  medium keys (read by the core, for every tracker):\n");
    print_key(&density_key);
    print_params(murk_medium_core_params, MURK_MEDIUM_NCORE);
    for (size_t i = 0; i < NTAIL; i++)
        print_key(&tail_keys[i]);
}

/* keys: whether a medium's section lists the medium keys (--all lists them once, before the first) */
static void describe_text(const murk_plugin *p, int keys)
{
    const murk_plugin_desc *d = p->desc;
    printf("%s %s — %s\n  file: %s (version %s, ABI %u.%u)\n", murk_kind_name((int)d->kind), d->name, d->description,
           p->path, p->version ? p->version : "none", p->abi.major, p->abi.minor);
    if (d->kind == MURK_KIND_MEDIUM)
        keys ? medium_keys_text() : (void)printf("  medium keys: those above (read by the core, for every tracker)\n");
    if (d->kind == MURK_KIND_TRANSMITTANCE)
        printf("  a medium selects it with `transmittance: %s` (or { type: %s, ... }) beside its tracker\n", d->name,
               d->name);
    if (d->kind == MURK_KIND_PHASE)
        printf("  a medium selects it with `phase: %s` (or { type: %s, ... })\n", d->name, d->name);
    if (!d->nparams) {
        printf("  no parameters of its own\n");
        return;
    }
    printf("  parameters:\n");
    print_params(d->params, d->nparams);
}

/* ---- markdown ------------------------------------------------------------------------------ */

/* s in a table cell: '|' escaped, line breaks as spaces */
static void md_cell(const char *s)
{
    for (; *s; s++)
        if (*s == '|')
            fputs("\\|", stdout);
        else
            putchar(*s == '\n' || *s == '\r' ? ' ' : *s);
}

static void md_row(const char *name, const char *type, const char *def, const char *range, const char *doc)
{
    printf("| `%s` | ", name);
    md_cell(type);
    fputs(" | ", stdout);
    md_cell(*def ? def : "—");
    fputs(" | ", stdout);
    md_cell(*range ? range : "—");
    fputs(" | ", stdout);
    md_cell(doc);
    fputs(" |\n", stdout);
}

static void md_params(const murk_param *ps, uint32_t n, const special_key *first, const special_key *last, size_t nlast)
{
    printf("| parameter | type | default | range | what |\n|---|---|---|---|---|\n");
    if (first)
        md_row(first->name, first->type, "", "", first->doc);
    for (uint32_t i = 0; i < n; i++) {
        const murk_param *q = &ps[i];
        char def[128], range[256], type[64];
        param_fields(q, def, sizeof def, range, sizeof range);
        snprintf(type, sizeof type, "%s%s", type_name(q->type),
                 (q->flags & MURK_PARAM_TEXTURABLE) ? " or texture" : "");
        md_row(q->name, type, (q->flags & MURK_PARAM_REQUIRED) ? "required" : def, range, q->doc);
    }
    for (size_t i = 0; i < nlast; i++)
        md_row(last[i].name, last[i].type, "", "", last[i].doc);
}

static void medium_keys_md(void)
{
    md_params(murk_medium_core_params, MURK_MEDIUM_NCORE, &density_key, tail_keys, NTAIL);
}

static void describe_md(const murk_plugin *p, int keys)
{
    const murk_plugin_desc *d = p->desc;
    printf("### `%s` (%s)\n\n%s.\n\n", d->name, murk_kind_name((int)d->kind), d->description);
    if (d->kind == MURK_KIND_TRANSMITTANCE)
        printf("A medium selects it with `transmittance: %s` (or `{ type: %s, ... }`) beside its tracker.\n\n",
               d->name, d->name);
    if (d->kind == MURK_KIND_PHASE)
        printf("A medium selects it with `phase: %s` (or `{ type: %s, ... }`).\n\n", d->name, d->name);
    if (d->nparams) {
        md_params(d->params, d->nparams, NULL, NULL, 0);
        putchar('\n');
    } else {
        printf("No parameters of its own.\n\n");
    }
    if (d->kind == MURK_KIND_MEDIUM && keys) {
        printf("The medium keys every tracker takes (read by the core):\n\n");
        medium_keys_md();
        putchar('\n');
    } else if (d->kind == MURK_KIND_MEDIUM) {
        printf("And the [medium keys](#medium-keys) every tracker takes.\n\n");
    }
}

/* the table of every plugin: kind, name, description, its parameters' names */
static void list_md(murk_plugin *ps, size_t n)
{
    printf("| kind | plugin | what | parameters |\n|---|---|---|---|\n");
    for (size_t i = 0; i < n; i++) {
        const murk_plugin_desc *d = ps[i].desc;
        printf("| %s | `%s` | ", murk_kind_name((int)d->kind), d->name);
        md_cell(d->description);
        fputs(" | ", stdout);
        for (uint32_t k = 0; k < d->nparams; k++)
            printf("%s`%s`", k ? ", " : "", d->params[k].name);
        printf("%s |\n", d->nparams ? "" : "—");
    }
}

/* ---- finding the plugins ------------------------------------------------------------------- */

/* The .so files of a folder, sorted by name; NULL-free array of n names. */
static char **list_dir(const char *dir, size_t *n)
{
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    struct dirent *e;
    char **names = NULL;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l > 3 && strcmp(e->d_name + l - 3, ".so") == 0) {
            names = murk_xrealloc(names, (*n + 1) * sizeof *names);
            names[(*n)++] = murk_strdup(e->d_name);
        }
    }
    closedir(d);
    for (size_t a = 0; a < *n; a++)
        for (size_t b = a + 1; b < *n; b++)
            if (strcmp(names[b], names[a]) < 0) {
                char *t = names[a];
                names[a] = names[b];
                names[b] = t;
            }
    return names;
}

/* Opens every .so on the search path, folder by folder, each sorted by name, and hands it to visit: p
 * open (visit keeps or closes it), or NULL with err saying why it is broken. */
typedef void (*visit_fn)(void *ctx, const char *file, const char *path, murk_plugin *p, const char *err);
static void visit_all(const murk_registry *reg, visit_fn visit, void *ctx)
{
    char err[1024];
    for (size_t i = 0; i < reg->ndirs; i++) {
        size_t nn;
        char **names = list_dir(reg->dirs[i], &nn);
        for (size_t k = 0; k < nn; k++) {
            size_t len = strlen(reg->dirs[i]) + strlen(names[k]) + 2;
            char *path = murk_xmalloc(len);
            snprintf(path, len, "%s/%s", reg->dirs[i], names[k]);
            murk_plugin p;
            int ok = murk_plugin_open(path, 0, &p, err, sizeof err) == 0;
            visit(ctx, names[k], path, ok ? &p : NULL, err);
            free(path);
            free(names[k]);
        }
        free(names);
    }
}

/* `murk plugins`: every file on the search path, a broken one as one "(broken)" line */
static void list_text_one(void *ctx, const char *file, const char *path, murk_plugin *p, const char *err)
{
    (void)ctx;
    if (p) {
        printf("%-13s %-17s %-58s %s\n", murk_kind_name((int)p->desc->kind), p->desc->name, p->desc->description,
               path);
        murk_plugin_close(p);
    } else {
        printf("%-13s %-17s %s\n", "(broken)", file, err);
    }
}

/* the order of the docs: materials, media, transmittance estimators, phase functions, integrators; by name within */
static int kind_rank(uint32_t kind)
{
    return kind == MURK_KIND_MATERIAL ? 0 : kind == MURK_KIND_MEDIUM ? 1 : kind == MURK_KIND_TRANSMITTANCE ? 2
           : kind == MURK_KIND_PHASE ? 3 : 4;
}

static int by_kind_and_name(const void *a, const void *b)
{
    const murk_plugin *x = a, *y = b;
    int r = kind_rank(x->desc->kind) - kind_rank(y->desc->kind);
    return r ? r : strcmp(x->desc->name, y->desc->name);
}

typedef struct found {
    murk_plugin *ps;
    size_t n;
    int broken;
} found;

/* keeps a name's first plugin (as scenes load them); a broken file is reported on stderr */
static void collect_one(void *ctx, const char *file, const char *path, murk_plugin *p, const char *err)
{
    (void)file, (void)path;
    found *f = ctx;
    if (!p) {
        murk_cli_error(err);
        f->broken = 1;
        return;
    }
    for (size_t j = 0; j < f->n; j++)
        if (!strcmp(f->ps[j].desc->name, p->desc->name)) {
            murk_plugin_close(p);
            return;
        }
    f->ps = murk_xrealloc(f->ps, (f->n + 1) * sizeof *f->ps);
    f->ps[f->n++] = *p;
}

/* Every plugin on the search path, in the docs' order; *broken 1 if a file could not be opened. */
static murk_plugin *open_all(const murk_registry *reg, size_t *n, int *broken)
{
    found f = {NULL, 0, 0};
    visit_all(reg, collect_one, &f);
    if (f.n)
        qsort(f.ps, f.n, sizeof *f.ps, by_kind_and_name);
    *n = f.n;
    *broken = f.broken;
    return f.ps;
}

/* --all: every plugin described, the medium keys once before the first medium */
static int describe_all(const murk_registry *reg, int md)
{
    size_t n;
    int broken = 0, keys_done = 0;
    murk_plugin *ps = open_all(reg, &n, &broken);
    for (size_t i = 0; i < n; i++) {
        if (!md && i)
            putchar('\n');
        if (ps[i].desc->kind == MURK_KIND_MEDIUM && !keys_done) {
            keys_done = 1;
            if (md) {
                printf("### Medium keys\n\nEvery medium takes these keys, whatever its tracker; the core reads "
                       "them.\n\n");
                medium_keys_md();
                putchar('\n');
            } else {
                medium_keys_text();
                putchar('\n');
            }
        }
        md ? describe_md(&ps[i], 0) : describe_text(&ps[i], 0);
    }
    for (size_t i = 0; i < n; i++)
        murk_plugin_close(&ps[i]);
    free(ps);
    return broken;
}

static int list_all_md(const murk_registry *reg)
{
    size_t n;
    int broken = 0;
    murk_plugin *ps = open_all(reg, &n, &broken);
    list_md(ps, n);
    for (size_t i = 0; i < n; i++)
        murk_plugin_close(&ps[i]);
    free(ps);
    return broken;
}

int murk_cli_plugins(int argc, char **argv)
{
    int md = 0, all = 0;
    const char *name = NULL;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--markdown")) {
            md = 1;
        } else if (!strcmp(argv[i], "--all")) {
            all = 1;
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "murk: unknown plugins option '%s'\n", murk_cli_q(argv[i]));
            return murk_cli_usage(NULL);
        } else if (name) {
            return murk_cli_usage("plugins takes at most one name");
        } else {
            name = argv[i];
        }
    }
    if (all && name)
        return murk_cli_usage("plugins takes a name or --all, not both");
    murk_registry reg;
    murk_registry_init(&reg);
    int rc = 0;
    if (name) {
        char err[1024];
        const murk_plugin *p = murk_registry_load(&reg, 0, name, err, sizeof err);
        if (p)
            md ? describe_md(p, 1) : describe_text(p, 1);
        else
            murk_cli_error(err);
        rc = !p;
    } else if (all) {
        rc = describe_all(&reg, md);
    } else if (md) {
        rc = list_all_md(&reg);
    } else {
        visit_all(&reg, list_text_one, NULL);
    }
    murk_registry_free(&reg);
    return rc;
}
