/* obj.c — Wavefront OBJ triangle mesh loader.
 *
 * Reads the file line by line. v, vt and vn lines append to raw attribute arrays; each f line
 * resolves its vertex references immediately (1-based, negative ones relative to the attributes
 * defined so far), unifies every distinct (v, vt, vn) triple to one output vertex through an
 * open-addressing hash table, and fan-triangulates the polygon. Every other statement is ignored.
 * At the end the unified vertices are expanded into the mesh arrays.
 *
 * The parser is strict: a malformed number, an index of 0 or out of range, or a face with fewer
 * than three vertices stops the load with "path:LINE:COL: message", where LINE and COL (1-based,
 * a tab counts as one column) locate the offending token. '#' starts a comment anywhere; CRLF line
 * ends and tabs are accepted. Counts are checked against 32-bit limits and every allocation is
 * checked; on failure everything is freed and the mesh is left zeroed.
 *
 * Numbers: when the digits form an integer of at most 2^24 and the decimal exponent is within
 * +-10 (nearly every OBJ coordinate), the value is computed exactly and locale-independently with
 * one float multiplication or division (Clinger's fast path); anything else goes to strtof in the
 * "C" locale (switched for this thread only), which is correctly rounded too: both give the same
 * bits whatever locale the application has set. */
#include "scene/obj.h"
#include "util/error.h"
#include "util/file.h"
#include "util/limit.h"

#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#define NO_INDEX UINT32_MAX
/* Largest count of any element: indices must fit in uint32_t with NO_INDEX to spare. */
#define MAX_COUNT ((size_t)UINT32_MAX - 1)

typedef struct vkey { uint32_t v, t, n; } vkey;

typedef struct objparse {
    const char *path;
    char *err;
    size_t errlen;
    size_t lineno;
    const char *line;           /* start of the current line, for columns */
    float *v, *vt, *vn;         /* raw attributes: 3, 2 and 3 floats each */
    size_t nv, nvt, nvn, capv, capvt, capvn;
    vkey *keys;                 /* unified vertices, in output order */
    size_t nkeys, capkeys;
    uint32_t *table;            /* hash table of key index + 1; 0 = empty; size is a power of two */
    size_t tabsize;
    uint32_t *idx;              /* 3 per triangle */
    size_t nidx, capidx;
    uint32_t *face;             /* the current face's unified vertices */
    size_t capface;
    locale_t c_locale;          /* for strtof, created on first use; (locale_t)0 if none */
} objparse;

/* "path:LINE:COL: message" with COL the column of at. */
MURK_PRINTF(3, 4)
static int fail_at(objparse *o, const char *at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    murk_verr_at(o->err, o->errlen, o->path, (long)o->lineno, (long)(at - o->line) + 1, fmt, ap);
    va_end(ap);
    return -1;
}

static int oom(objparse *o)
{
    return murk_err_file(o->err, o->errlen, o->path, "out of memory");
}

/* Makes room for need elements of size elem in p (capacity *cap); returns the (possibly moved)
 * array, or NULL on overflow or when out of memory (p is then still valid). */
static void *grow(void *p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return p;
    size_t n = *cap ? *cap : 256;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return NULL;
        n *= 2;
    }
    if (n > SIZE_MAX / elem)
        return NULL;
    void *q = realloc(p, n * elem);
    if (q)
        *cap = n;
    return q;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static const char *skip_space(const char *p, const char *e)
{
    while (p < e && is_space(*p))
        p++;
    return p;
}

static const char *token_end(const char *p, const char *e)
{
    while (p < e && !is_space(*p))
        p++;
    return p;
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* strtof of the NUL-terminated s in the "C" locale, whatever the application's locale. */
static float strtof_c(objparse *o, const char *s, char **end)
{
    if (o->c_locale == (locale_t)0)
        o->c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (o->c_locale == (locale_t)0) /* out of memory: the current locale is most likely "C" anyway */
        return strtof(s, end);
    locale_t old = uselocale(o->c_locale);
    float f = strtof(s, end);
    uselocale(old);
    return f;
}

/* Parses the decimal number [s, e) into *out. Returns 0, -1 if malformed, -2 if out of range for a
 * float. The grammar is [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?. */
static int parse_float(objparse *o, const char *s, const char *e, float *out)
{
    static const float pow10f[11] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f, 1e8f, 1e9f, 1e10f};
    const char *p = s;
    int neg = 0, any = 0, ndig = 0, exact = 1;
    long exp10 = 0;
    uint64_t mant = 0;

    if (p < e && (*p == '+' || *p == '-'))
        neg = *p++ == '-';
    for (; p < e && is_digit(*p); p++) {
        any = 1;
        if (ndig < 19) {
            mant = mant * 10 + (uint64_t)(*p - '0');
            ndig += mant != 0;
        } else {
            exp10++;
            exact &= *p == '0';
        }
    }
    if (p < e && *p == '.') {
        for (p++; p < e && is_digit(*p); p++) {
            any = 1;
            if (ndig < 19) {
                mant = mant * 10 + (uint64_t)(*p - '0');
                ndig += mant != 0;
                exp10--;
            } else {
                exact &= *p == '0';
            }
        }
    }
    if (!any)
        return -1;
    if (p < e && (*p == 'e' || *p == 'E')) {
        int eneg = 0;
        long ev = 0;
        p++;
        if (p < e && (*p == '+' || *p == '-'))
            eneg = *p++ == '-';
        if (p == e || !is_digit(*p))
            return -1;
        for (; p < e && is_digit(*p); p++)
            if (ev < 100000)
                ev = ev * 10 + (*p - '0');
        exp10 += eneg ? -ev : ev;
    }
    if (p != e)
        return -1;

    float f;
    if (mant == 0) {
        f = neg ? -0.0f : 0.0f;
    } else if (exact && mant <= (1u << 24) && exp10 >= -10 && exp10 <= 10) {
        /* Both operands are exact floats, so one correctly rounded operation gives the exact result. */
        f = (float)mant;
        f = exp10 < 0 ? f / pow10f[-exp10] : f * pow10f[exp10];
        f = neg ? -f : f;
    } else {
        char buf[128];
        size_t n = (size_t)(e - s);
        char *tmp = n < sizeof buf ? buf : malloc(n + 1);
        char *end;
        if (!tmp)
            return -1;
        memcpy(tmp, s, n);
        tmp[n] = 0;
        f = strtof_c(o, tmp, &end);
        int whole = end == tmp + n;
        if (tmp != buf)
            free(tmp);
        if (!whole) /* cannot happen for text matching the grammar */
            return -1;
    }
    if (isinf(f))
        return -2;
    *out = f;
    return 0;
}

/* Parses the numbers after the keyword kw (named name) into vals: at least minn, at most maxn.
 * Returns the count, or -1 with the error set. */
static int parse_floats(objparse *o, const char *kw, const char *name, const char *p, const char *e, float *vals,
                        int minn, int maxn)
{
    int n = 0;
    for (p = skip_space(p, e); p < e; p = skip_space(p, e)) {
        const char *te = token_end(p, e);
        float f = 0.0f;
        int r = parse_float(o, p, te, &f);
        if (r == -1)
            return fail_at(o, p, "bad number '%.*s'", (int)(te - p > 40 ? 40 : te - p), p);
        if (r == -2)
            return fail_at(o, p, "number out of range '%.*s'", (int)(te - p > 40 ? 40 : te - p), p);
        if (n == maxn)
            return fail_at(o, p, "too many values for '%s' (at most %d)", name, maxn);
        vals[n++] = f;
        p = te;
    }
    if (n < minn)
        return fail_at(o, kw, "'%s' needs at least %d values, got %d", name, minn, n);
    return n;
}

/* Appends count floats to a raw attribute array. */
static int push_floats(objparse *o, float **arr, size_t *n, size_t *cap, const float *vals, size_t count)
{
    if (*n >= MAX_COUNT)
        return murk_err_at(o->err, o->errlen, o->path, (long)o->lineno, 1, "too many vertex attributes");
    float *a = grow(*arr, cap, (*n + 1) * count, sizeof(float));
    if (!a)
        return oom(o);
    *arr = a;
    memcpy(a + *n * count, vals, count * sizeof(float));
    (*n)++;
    return 0;
}

static uint64_t hash_key(vkey k)
{
    uint64_t h = (uint64_t)k.v * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t)k.t * 0xC2B2AE3D27D4EB4Full + (h >> 31);
    h ^= (uint64_t)k.n * 0x165667B19E3779F9ull + (h >> 29);
    h ^= h >> 32;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return h;
}

static int rehash(objparse *o, size_t size)
{
    if (size > SIZE_MAX / sizeof(uint32_t))
        return -1;
    uint32_t *t = calloc(size, sizeof(uint32_t));
    if (!t)
        return -1;
    for (size_t i = 0; i < o->nkeys; i++) {
        size_t slot = (size_t)hash_key(o->keys[i]) & (size - 1);
        while (t[slot])
            slot = (slot + 1) & (size - 1);
        t[slot] = (uint32_t)(i + 1);
    }
    free(o->table);
    o->table = t;
    o->tabsize = size;
    return 0;
}

/* The output vertex of (v, t, n), created if new. */
static int unify(objparse *o, vkey k, uint32_t *out)
{
    if ((o->nkeys + 1) * 2 > o->tabsize) {
        if (o->tabsize > SIZE_MAX / 2 || rehash(o, o->tabsize ? o->tabsize * 2 : 1024) != 0)
            return oom(o);
    }
    size_t mask = o->tabsize - 1, slot = (size_t)hash_key(k) & mask;
    for (; o->table[slot]; slot = (slot + 1) & mask) {
        const vkey *c = &o->keys[o->table[slot] - 1];
        if (c->v == k.v && c->t == k.t && c->n == k.n) {
            *out = o->table[slot] - 1;
            return 0;
        }
    }
    if (o->nkeys >= MAX_COUNT)
        return murk_err_at(o->err, o->errlen, o->path, (long)o->lineno, 1, "too many distinct vertices");
    vkey *keys = grow(o->keys, &o->capkeys, o->nkeys + 1, sizeof *keys);
    if (!keys)
        return oom(o);
    o->keys = keys;
    keys[o->nkeys] = k;
    o->table[slot] = (uint32_t)(o->nkeys + 1);
    *out = (uint32_t)o->nkeys++;
    return 0;
}

/* Resolves the index [s, e) of a face token starting at tok against count defined elements. */
static int resolve(objparse *o, const char *tok, const char *te, const char *s, const char *e, size_t count,
                   const char *what, uint32_t *out)
{
    const char *p = s;
    int neg = 0;
    uint64_t v = 0;
    if (p < e && (*p == '+' || *p == '-'))
        neg = *p++ == '-';
    if (p == e)
        return fail_at(o, tok, "bad index '%.*s'", (int)(te - tok > 40 ? 40 : te - tok), tok);
    for (; p < e; p++) {
        if (!is_digit(*p))
            return fail_at(o, tok, "bad index '%.*s'", (int)(te - tok > 40 ? 40 : te - tok), tok);
        if (v <= UINT32_MAX)
            v = v * 10 + (uint64_t)(*p - '0'); /* saturates above any possible count */
    }
    if (v == 0)
        return fail_at(o, tok, "index 0 is invalid in '%.*s' (OBJ indices start at 1)",
                       (int)(te - tok > 40 ? 40 : te - tok), tok);
    if (v > count)
        return fail_at(o, tok, "%s index %.*s out of range (%zu defined)", what, (int)(e - s > 40 ? 40 : e - s),
                       s, count);
    *out = (uint32_t)(neg ? count - v : v - 1);
    return 0;
}

/* One face vertex: v, v/vt, v//vn or v/vt/vn. */
static int parse_face_vertex(objparse *o, const char *tok, const char *te, uint32_t *out)
{
    const char *s1 = memchr(tok, '/', (size_t)(te - tok));
    const char *s2 = s1 ? memchr(s1 + 1, '/', (size_t)(te - s1 - 1)) : NULL;
    vkey k = {0, NO_INDEX, NO_INDEX};
    if (s2 && memchr(s2 + 1, '/', (size_t)(te - s2 - 1)))
        return fail_at(o, tok, "bad index '%.*s'", (int)(te - tok > 40 ? 40 : te - tok), tok);
    if (resolve(o, tok, te, tok, s1 ? s1 : te, o->nv, "vertex", &k.v) != 0)
        return -1;
    /* v/vt or v/vt/vn; "v//vn" has no vt */
    if (s1 && (!s2 || s2 > s1 + 1) &&
        resolve(o, tok, te, s1 + 1, s2 ? s2 : te, o->nvt, "texture coordinate", &k.t) != 0)
        return -1;
    if (s2 && resolve(o, tok, te, s2 + 1, te, o->nvn, "normal", &k.n) != 0)
        return -1;
    return unify(o, k, out);
}

static int parse_face(objparse *o, const char *kw, const char *p, const char *e)
{
    size_t n = 0;
    for (p = skip_space(p, e); p < e; p = skip_space(p, e)) {
        const char *te = token_end(p, e);
        uint32_t *f = grow(o->face, &o->capface, n + 1, sizeof *f);
        if (!f)
            return oom(o);
        o->face = f;
        if (parse_face_vertex(o, p, te, &f[n]) != 0)
            return -1;
        n++;
        p = te;
    }
    if (n < 3)
        return fail_at(o, kw, "face has fewer than 3 vertices (%zu)", n);
    size_t ntris = o->nidx / 3 + (n - 2);
    if (ntris > MAX_COUNT || ntris > murk_limit(MURK_LIMIT_MESH_TRIANGLES))
        return fail_at(o, kw, "more than %llu triangles (the limit, %s)",
                       (unsigned long long)murk_limit(MURK_LIMIT_MESH_TRIANGLES), murk_limit_name(MURK_LIMIT_MESH_TRIANGLES));
    if (ntris > SIZE_MAX / 3)
        return oom(o);
    uint32_t *idx = grow(o->idx, &o->capidx, ntris * 3, sizeof *idx);
    if (!idx)
        return oom(o);
    o->idx = idx;
    for (size_t i = 1; i + 1 < n; i++) {
        idx[o->nidx++] = o->face[0];
        idx[o->nidx++] = o->face[i];
        idx[o->nidx++] = o->face[i + 1];
    }
    return 0;
}

static int keyword_is(const char *k, const char *ke, const char *word)
{
    size_t n = strlen(word);
    return (size_t)(ke - k) == n && memcmp(k, word, n) == 0;
}

/* One line without its newline; line[len] may be anything. */
static int parse_line(objparse *o, const char *line, size_t len)
{
    const char *e = line + len, *hash = memchr(line, '#', len);
    float vals[7];
    o->line = line; /* a NUL byte is just a character that fits no token */
    if (hash)
        e = hash;
    const char *k = skip_space(line, e);
    const char *ke = token_end(k, e);
    if (keyword_is(k, ke, "v")) {
        if (parse_floats(o, k, "v", ke, e, vals, 3, 7) < 0)
            return -1;
        return push_floats(o, &o->v, &o->nv, &o->capv, vals, 3);
    }
    if (keyword_is(k, ke, "vt")) {
        vals[1] = 0.0f;
        if (parse_floats(o, k, "vt", ke, e, vals, 1, 3) < 0)
            return -1;
        return push_floats(o, &o->vt, &o->nvt, &o->capvt, vals, 2);
    }
    if (keyword_is(k, ke, "vn")) {
        if (parse_floats(o, k, "vn", ke, e, vals, 3, 3) < 0)
            return -1;
        return push_floats(o, &o->vn, &o->nvn, &o->capvn, vals, 3);
    }
    if (keyword_is(k, ke, "f"))
        return parse_face(o, k, ke, e);
    return 0; /* blank, comment, or a statement murk does not use */
}

/* Expands the unified vertices into the mesh; the parse state keeps ownership on failure. */
static int build_mesh(objparse *o, murk_mesh *mesh)
{
    size_t n = o->nkeys;
    if (n > SIZE_MAX / (3 * sizeof(float)))
        return oom(o);
    mesh->pos = malloc(n * 3 * sizeof(float));
    mesh->uv = o->nvt ? malloc(n * 2 * sizeof(float)) : NULL;
    mesh->nrm = o->nvn ? malloc(n * 3 * sizeof(float)) : NULL;
    if (!mesh->pos || (o->nvt && !mesh->uv) || (o->nvn && !mesh->nrm))
        return oom(o);
    for (size_t i = 0; i < n; i++) {
        vkey k = o->keys[i];
        memcpy(mesh->pos + 3 * i, o->v + 3 * (size_t)k.v, 3 * sizeof(float));
        if (mesh->uv) {
            mesh->uv[2 * i] = k.t == NO_INDEX ? 0.0f : o->vt[2 * (size_t)k.t];
            mesh->uv[2 * i + 1] = k.t == NO_INDEX ? 0.0f : o->vt[2 * (size_t)k.t + 1];
        }
        if (mesh->nrm) {
            for (int c = 0; c < 3; c++)
                mesh->nrm[3 * i + c] = k.n == NO_INDEX ? 0.0f : o->vn[3 * (size_t)k.n + c];
        }
    }
    mesh->nverts = (uint32_t)n;
    mesh->ntris = (uint32_t)(o->nidx / 3);
    mesh->idx = realloc(o->idx, o->nidx * sizeof *o->idx); /* drop the spare capacity */
    if (!mesh->idx)
        mesh->idx = o->idx;
    o->idx = NULL;
    return 0;
}

static void parse_free(objparse *o)
{
    free(o->v);
    free(o->vt);
    free(o->vn);
    free(o->keys);
    free(o->table);
    free(o->idx);
    free(o->face);
    if (o->c_locale != (locale_t)0)
        freelocale(o->c_locale);
}

int murk_obj_load(const char *path, murk_mesh *mesh, char *err, size_t errlen)
{
    if (!mesh)
        return murk_err_file(err, errlen, path ? path : "(null)", "no mesh to load into");
    memset(mesh, 0, sizeof *mesh);
    if (!path)
        return murk_err_file(err, errlen, "(null)", "no path");
    uint64_t fsize; /* a regular file within MURK_MAX_FILE_BYTES: never /dev/zero or a FIFO */
    FILE *f = murk_file_open_regular(path, &fsize, err, errlen);
    if (!f)
        return -1;

    objparse o;
    memset(&o, 0, sizeof o);
    o.path = path;
    o.err = err;
    o.errlen = errlen;
    char *line = NULL;
    size_t cap = 0;
    int rc = 0;
    for (;;) {
        errno = 0;
        ssize_t n = getline(&line, &cap, f);
        if (n < 0) {
            if (ferror(f) || !feof(f)) {
                int e = errno ? errno : EIO;
                rc = e == ENOMEM ? oom(&o) : murk_err_file(err, errlen, path, "read error: %s", strerror(e));
            }
            break;
        }
        o.lineno++;
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            n--;
        if ((rc = parse_line(&o, line, (size_t)n)) != 0)
            break;
    }
    free(line);
    fclose(f);
    if (rc == 0 && o.nidx == 0)
        rc = murk_err_file(err, errlen, path, "no faces");
    if (rc == 0 && build_mesh(&o, mesh) != 0)
        rc = -1;
    parse_free(&o);
    if (rc != 0)
        murk_mesh_free(mesh);
    return rc;
}

void murk_mesh_free(murk_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->pos);
    free(mesh->uv);
    free(mesh->nrm);
    free(mesh->idx);
    memset(mesh, 0, sizeof *mesh);
}
