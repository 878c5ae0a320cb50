/* yamldoc.h — a YAML document as a tree that remembers where every node came from.
 * libyaml parses; this keeps file:line:col (1-based) on every node and key so that each scene error
 * can name its place. Anchors/aliases are refused (scenes don't need them; cycles can't happen). */
#ifndef MURK_YAMLDOC_H
#define MURK_YAMLDOC_H

#include <stddef.h>

typedef enum { MURK_Y_SCALAR, MURK_Y_SEQ, MURK_Y_MAP } murk_ykind;

typedef struct murk_ynode murk_ynode;
struct murk_ynode {
    murk_ykind kind;
    const char *file; /* not owned: the document's file name */
    int line, col;
    char *str;        /* scalar text */
    int plain;        /* scalar was unquoted */
    size_t n;         /* items (SEQ) or entries (MAP) */
    murk_ynode **items;
    char **keys;      /* MAP only */
    int *key_line, *key_col;
    const char **key_file; /* where each key was written: the document's file, or a --set's label */
    char *swapped_type; /* MAP only: the file's `type` that a --set replaced (its keys may be dropped) */
};

typedef struct murk_ydoc {
    char *file;
    murk_ynode *root; /* NULL for an empty document */
    char **sets;      /* "--set KEY.PATH=VALUE": the file name of the nodes each --set made */
    size_t nsets;
} murk_ydoc;

/* Returns 0, or -1 with err = "file:line:col: message". */
int murk_ydoc_load_file(murk_ydoc *doc, const char *path, char *err, size_t errlen);
int murk_ydoc_load_string(murk_ydoc *doc, const char *text, const char *name, char *err, size_t errlen);
void murk_ydoc_free(murk_ydoc *doc);

murk_ynode *murk_ymap_get(const murk_ynode *map, const char *key); /* NULL if absent or not a map */
/* Applies "a.b.0.c=VALUE" (VALUE parsed as YAML; sequence indices are numbers). Missing map levels are
 * created. The nodes it makes (and the keys it adds) have the file "--set a.b.0.c=VALUE" and line 0, so
 * that every error about them quotes the --set: "--set a.b.0.c=VALUE: what is wrong"; its own errors
 * (a malformed assignment or value, a path that does not fit the document) read the same way. A --set
 * of `type` in a map whose `type` came from the file keeps the file's value in swapped_type. */
int murk_ydoc_set(murk_ydoc *doc, const char *assignment, char *err, size_t errlen);
/* 1 if the node (or key) was written by a --set: its file is a --set's label. */
int murk_yfrom_set(const char *file);
murk_ynode *murk_ynode_new(murk_ykind kind, const char *file, int line, int col);
void murk_ynode_free(murk_ynode *n);
/* "file:line:col: " prefix for a node, or for a map key when key_index >= 0. */
int murk_yerr(char *err, size_t errlen, const murk_ynode *n, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
int murk_yerr_key(char *err, size_t errlen, const murk_ynode *map, size_t key_index, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

#endif
