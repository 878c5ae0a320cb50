/* yamldoc.c — libyaml events to a located tree; --set overrides. */
#include "yaml/yamldoc.h"
#include "util/error.h"
#include "util/file.h"
#include "util/util.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

murk_ynode *murk_ynode_new(murk_ykind kind, const char *file, int line, int col)
{
    murk_ynode *n = murk_xmalloc(sizeof *n);
    n->kind = kind;
    n->file = file;
    n->line = line;
    n->col = col;
    return n;
}

void murk_ynode_free(murk_ynode *n)
{
    if (!n)
        return;
    for (size_t i = 0; i < n->n; i++) {
        murk_ynode_free(n->items[i]);
        if (n->keys)
            free(n->keys[i]);
    }
    free(n->items);
    free(n->keys);
    free(n->key_line);
    free(n->key_col);
    free(n->key_file);
    free(n->str);
    free(n->swapped_type);
    free(n);
}

static void append(murk_ynode *parent, murk_ynode *child, char *key, const char *kf, int kl, int kc)
{
    size_t n = parent->n + 1;
    parent->items = murk_xrealloc(parent->items, n * sizeof *parent->items);
    parent->items[n - 1] = child;
    if (parent->kind == MURK_Y_MAP) {
        parent->keys = murk_xrealloc(parent->keys, n * sizeof *parent->keys);
        parent->key_line = murk_xrealloc(parent->key_line, n * sizeof(int));
        parent->key_col = murk_xrealloc(parent->key_col, n * sizeof(int));
        parent->key_file = murk_xrealloc(parent->key_file, n * sizeof *parent->key_file);
        parent->key_file[n - 1] = kf;
        parent->keys[n - 1] = key;
        parent->key_line[n - 1] = kl;
        parent->key_col[n - 1] = kc;
    }
    parent->n = n;
}

MURK_API murk_ynode *murk_ymap_get(const murk_ynode *map, const char *key)
{
    if (!map || map->kind != MURK_Y_MAP)
        return NULL;
    for (size_t i = 0; i < map->n; i++)
        if (strcmp(map->keys[i], key) == 0)
            return map->items[i];
    return NULL;
}

int murk_yerr(char *err, size_t errlen, const murk_ynode *n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    murk_verr_at(err, errlen, n->file, n->line, n->col, fmt, ap);
    va_end(ap);
    return -1;
}

int murk_yerr_key(char *err, size_t errlen, const murk_ynode *map, size_t i, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    murk_verr_at(err, errlen, map->key_file ? map->key_file[i] : map->file, map->key_line[i], map->key_col[i], fmt,
                 ap);
    va_end(ap);
    return -1;
}

/* Builds the tree from the parser's events. Depth is bounded so hostile input can't blow the stack. */
enum { MAX_DEPTH = 64 };

/* The tree being built: the open containers and, for each open map, the key waiting for its value. */
typedef struct builder {
    const char *file;
    murk_ynode *stack[MAX_DEPTH];
    char *pending_key[MAX_DEPTH];
    int pk_line[MAX_DEPTH], pk_col[MAX_DEPTH];
    int depth, docs;
    murk_ynode *root;
} builder;

/* The parser's error at its place in the file. */
static void parse_error(const yaml_parser_t *p, const unsigned char *text, size_t textlen, const char *file,
                        char *err, size_t errlen)
{
    int line = (int)p->problem_mark.line + 1, col = (int)p->problem_mark.column + 1;
    const char *prob = p->problem ? p->problem : "malformed YAML";
    int tab = 0;
    if (p->error == YAML_READER_ERROR) {
        /* encoding errors come as a byte offset, not a mark: count lines and characters */
        size_t off = p->problem_offset < textlen ? p->problem_offset : textlen;
        line = col = 1;
        for (size_t i = 0; i < off; i++) {
            if (text[i] == '\n')
                line++, col = 1;
            else if ((text[i] & 0xC0) != 0x80)
                col++;
        }
    } else if (p->problem_mark.index < textlen && text[p->problem_mark.index] == '\t') {
        /* libyaml says "cannot start any token" of a tab used for indentation: say so plainly */
        prob = "tab character: YAML indentation must use spaces";
        tab = 1;
    }
    if (p->context && !tab)
        murk_err_at(err, errlen, file, line, col, "%s %s", prob, p->context);
    else
        murk_err_at(err, errlen, file, line, col, "%s", prob);
}

/* A scalar where the open map waits for a key: it becomes that key (node is freed). 0, or -1 with err. */
static int take_key(builder *b, murk_ynode *node, char *err, size_t errlen)
{
    int d = b->depth - 1, rc = 0;
    if (node->kind != MURK_Y_SCALAR)
        rc = murk_err_at(err, errlen, b->file, node->line, node->col, "a map key must be a plain name");
    else if (murk_ymap_get(b->stack[d], node->str))
        rc = murk_err_at(err, errlen, b->file, node->line, node->col, "duplicate key '%s'", node->str);
    else {
        b->pending_key[d] = node->str;
        b->pk_line[d] = node->line;
        b->pk_col[d] = node->col;
        node->str = NULL;
    }
    murk_ynode_free(node);
    return rc;
}

/* A new node in its place: the root, a map's key, a value of the open container, or (a container) the
 * new open one. 0, or -1 with err set (node freed). */
static int place(builder *b, murk_ynode *node, char *err, size_t errlen)
{
    int container = node->kind != MURK_Y_SCALAR, d = b->depth - 1;
    if (b->depth == 0 && !container) {
        b->root = node;
        return 0;
    }
    if (b->depth > 0 && b->stack[d]->kind == MURK_Y_MAP && !b->pending_key[d])
        return take_key(b, node, err, errlen);
    if (container) {
        if (b->depth >= MAX_DEPTH) {
            murk_err_at(err, errlen, b->file, node->line, node->col, "nesting deeper than %d levels", MAX_DEPTH);
            murk_ynode_free(node);
            return -1;
        }
        b->stack[b->depth] = node;
        b->pending_key[b->depth] = NULL;
        b->depth++;
    } else if (b->stack[d]->kind == MURK_Y_MAP) {
        append(b->stack[d], node, b->pending_key[d], b->file, b->pk_line[d], b->pk_col[d]);
        b->pending_key[d] = NULL;
    } else {
        append(b->stack[d], node, NULL, NULL, 0, 0);
    }
    return 0;
}

/* The end of the open container: the root, or a value of the container around it. */
static void close_container(builder *b)
{
    murk_ynode *top = b->stack[--b->depth];
    int d = b->depth - 1;
    if (b->depth == 0) {
        b->root = top;
        return;
    }
    append(b->stack[d], top, b->pending_key[d], b->file, b->pk_line[d], b->pk_col[d]);
    b->pending_key[d] = NULL;
}

/* One event: 1 at the end of the stream, 0 to go on, -1 with err set. */
static int on_event(builder *b, const yaml_event_t *ev, char *err, size_t errlen)
{
    int line = (int)ev->start_mark.line + 1, col = (int)ev->start_mark.column + 1;
    murk_ynode *node;
    switch (ev->type) {
    case YAML_STREAM_END_EVENT:
        return 1;
    case YAML_DOCUMENT_START_EVENT:
        if (++b->docs > 1)
            return murk_err_at(err, errlen, b->file, line, col, "a scene file holds one YAML document");
        return 0;
    case YAML_ALIAS_EVENT:
        return murk_err_at(err, errlen, b->file, line, col, "YAML aliases are not supported in scenes");
    case YAML_SCALAR_EVENT:
        node = murk_ynode_new(MURK_Y_SCALAR, b->file, line, col);
        node->str = murk_strdup((const char *)ev->data.scalar.value);
        node->plain = ev->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
        return place(b, node, err, errlen);
    case YAML_SEQUENCE_START_EVENT:
    case YAML_MAPPING_START_EVENT:
        node = murk_ynode_new(ev->type == YAML_SEQUENCE_START_EVENT ? MURK_Y_SEQ : MURK_Y_MAP, b->file, line, col);
        return place(b, node, err, errlen);
    case YAML_SEQUENCE_END_EVENT:
    case YAML_MAPPING_END_EVENT:
        close_container(b);
        return 0;
    default:
        return 0;
    }
}

static int parse_events(yaml_parser_t *p, const unsigned char *text, size_t textlen, const char *file,
                        murk_ynode **root, char *err, size_t errlen)
{
    builder b = {.file = file};
    int rc = 0;
    while (rc == 0) {
        yaml_event_t ev;
        if (!yaml_parser_parse(p, &ev)) {
            parse_error(p, text, textlen, file, err, errlen);
            rc = -1;
            break;
        }
        rc = on_event(&b, &ev, err, errlen);
        yaml_event_delete(&ev);
    }
    if (rc < 0) {
        /* free whatever is still open: each open container is owned only by the stack */
        for (int i = b.depth - 1; i >= 0; i--) {
            free(b.pending_key[i]);
            murk_ynode_free(b.stack[i]);
        }
        if (b.depth == 0)
            murk_ynode_free(b.root);
        *root = NULL;
        return -1;
    }
    *root = b.root;
    return 0;
}

static int load(murk_ydoc *doc, const unsigned char *text, size_t len, const char *name, char *err, size_t errlen)
{
    memset(doc, 0, sizeof *doc);
    doc->file = murk_strdup(name);
    yaml_parser_t p;
    if (!yaml_parser_initialize(&p)) {
        murk_err_file(err, errlen, name, "cannot initialise the YAML parser");
        return -1;
    }
    yaml_parser_set_input_string(&p, text, len);
    int rc = parse_events(&p, text, len, doc->file, &doc->root, err, errlen);
    yaml_parser_delete(&p);
    if (rc != 0) {
        free(doc->file);
        doc->file = NULL;
    }
    return rc;
}

int murk_ydoc_load_string(murk_ydoc *doc, const char *text, const char *name, char *err, size_t errlen)
{
    return load(doc, (const unsigned char *)text, strlen(text), name, err, errlen);
}

int murk_ydoc_load_file(murk_ydoc *doc, const char *path, char *err, size_t errlen)
{
    memset(doc, 0, sizeof *doc);
    uint64_t fsize; /* a regular file: a directory, FIFO or device is named as such, never read */
    FILE *f = murk_file_open_regular(path, &fsize, err, errlen);
    if (!f)
        return -1;
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = murk_xmalloc(cap);
    for (;;) {
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (n < cap)
            break;
        if (cap >= ((size_t)64 << 20)) {
            fclose(f);
            free(buf);
            murk_err_file(err, errlen, path, "scene file larger than 64 MiB");
            return -1;
        }
        buf = murk_xrealloc(buf, cap *= 2);
    }
    int bad = ferror(f), saved = errno;
    fclose(f);
    if (bad) {
        free(buf);
        murk_err_file(err, errlen, path, "cannot read: %s", strerror(saved));
        return -1;
    }
    if (memchr(buf, 0, n)) {
        free(buf);
        murk_err_at(err, errlen, path, 1, 1, "not a text file (contains NUL bytes)");
        return -1;
    }
    int rc = load(doc, buf, n, path, err, errlen);
    free(buf);
    return rc;
}

void murk_ydoc_free(murk_ydoc *doc)
{
    murk_ynode_free(doc->root);
    for (size_t i = 0; i < doc->nsets; i++)
        free(doc->sets[i]);
    free(doc->sets);
    free(doc->file);
    memset(doc, 0, sizeof *doc);
}

/* Every node and key of a --set's value: the --set's label as file, line 0 ("LABEL: message"). */
static void retag(murk_ynode *n, const char *file)
{
    n->file = file;
    n->line = n->col = 0;
    for (size_t i = 0; i < n->n; i++) {
        retag(n->items[i], file);
        if (n->key_line)
            n->key_line[i] = n->key_col[i] = 0;
        if (n->key_file)
            n->key_file[i] = file;
    }
}

static int is_index(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (*s < '0' || *s > '9')
            return 0;
    return 1;
}

int murk_yfrom_set(const char *file) { return file && strncmp(file, "--set ", 6) == 0; }

int murk_ydoc_set(murk_ydoc *doc, const char *assignment, char *err, size_t errlen)
{
    size_t al = strlen(assignment);
    char *label = murk_xmalloc(al + 7);
    memcpy(label, "--set ", 6);
    memcpy(label + 6, assignment, al + 1);
    doc->sets = murk_xrealloc(doc->sets, (doc->nsets + 1) * sizeof *doc->sets);
    doc->sets[doc->nsets++] = label; /* owned by the document: its nodes name it */
    const char *eq = strchr(assignment, '=');
    if (!eq || eq == assignment)
        return murk_err_file(err, errlen, label, "expected KEY.PATH=VALUE");
    murk_ydoc vdoc;
    char verrbuf[512];
    if (murk_ydoc_load_string(&vdoc, eq + 1, "VALUE", verrbuf, sizeof verrbuf) != 0) {
        /* "VALUE:L:C: message": the message only (the value is short, and quoted in the label) */
        int l = 1, c = 1, used = 0;
        const char *msg = verrbuf;
        if (sscanf(verrbuf, "VALUE:%d:%d: %n", &l, &c, &used) == 2 && used > 0)
            msg = verrbuf + used;
        return murk_err_file(err, errlen, label, "the value after '=' is not valid YAML: %s", msg);
    }
    murk_ynode *value = vdoc.root;
    vdoc.root = NULL;
    free(vdoc.file);
    if (!value) {
        value = murk_ynode_new(MURK_Y_SCALAR, label, 0, 0);
        value->str = murk_strdup("");
        value->plain = 1;
    }
    retag(value, label);

    if (!doc->root)
        doc->root = murk_ynode_new(MURK_Y_MAP, label, 0, 0);
    murk_ynode *cur = doc->root;
    const char *seg = assignment;
    for (;;) {
        const char *dot = memchr(seg, '.', (size_t)(eq - seg));
        const char *end = dot ? dot : eq;
        size_t len = (size_t)(end - seg);
        if (len == 0) {
            murk_ynode_free(value);
            return murk_err_file(err, errlen, label, "empty key in '%.*s'", (int)(eq - assignment), assignment);
        }
        char *key = murk_xmalloc(len + 1);
        memcpy(key, seg, len);
        murk_ynode **slot = NULL;
        if (cur->kind == MURK_Y_SEQ) {
            if (!is_index(key) || strtoul(key, NULL, 10) >= cur->n) {
                murk_err_file(err, errlen, label, "'%s' is not an index of the list %.*s (it has %zu items)", key,
                              (int)(seg - assignment - (seg > assignment)), assignment, cur->n);
                free(key);
                murk_ynode_free(value);
                return -1;
            }
            slot = &cur->items[strtoul(key, NULL, 10)];
            free(key);
        } else if (cur->kind == MURK_Y_MAP) {
            for (size_t i = 0; i < cur->n; i++)
                if (strcmp(cur->keys[i], key) == 0)
                    slot = &cur->items[i];
            if (!slot) {
                murk_ynode *fresh = murk_ynode_new(dot ? MURK_Y_MAP : MURK_Y_SCALAR, label, 0, 0);
                append(cur, fresh, key, label, 0, 0);
                slot = &cur->items[cur->n - 1];
            } else {
                if (!dot && !strcmp(key, "type") && !cur->swapped_type && (*slot)->kind == MURK_Y_SCALAR &&
                    !murk_yfrom_set((*slot)->file))
                    cur->swapped_type = murk_strdup((*slot)->str); /* the file's plugin, whose keys may go */
                free(key);
            }
        } else {
            murk_err_file(err, errlen, label, "cannot descend into a scalar at '%s'", key);
            free(key);
            murk_ynode_free(value);
            return -1;
        }
        if (!dot) {
            murk_ynode_free(*slot);
            *slot = value;
            return 0;
        }
        cur = *slot;
        seg = dot + 1;
    }
}
