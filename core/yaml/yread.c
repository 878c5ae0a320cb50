/* yread.c — typed, range-checked readers of YAML nodes with located errors, shared by the scene,
 * media and texture loaders. */
#include "yaml/yread.h"
#include "util/limit.h"
#include "util/util.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERR(node, ...) murk_yerr(err, errlen, (node), __VA_ARGS__)

/* ---- Typed value readers ------------------------------------------------------------------- */

int murk_yread_number(const murk_ynode *n, const char *what, double *out, char *err, size_t errlen)
{
    if (n->kind != MURK_Y_SCALAR)
        return ERR(n, "%s must be a number, got a %s", what, n->kind == MURK_Y_MAP ? "map" : "list");
    char *end = NULL;
    errno = 0;
    double v = strtod(n->str, &end);
    if (!*n->str || *end || isnan(v) || (n->str[0] == '0' && (n->str[1] == 'x' || n->str[1] == 'X')))
        return ERR(n, "%s must be a number, got '%s'", what, n->str);
    if (isinf(v) || (errno == ERANGE && fabs(v) > 1.0))
        return ERR(n, "%s is too large, got '%s'", what, n->str);
    if (errno == ERANGE) /* underflow: as good as 0 */
        v = 0.0;
    *out = v;
    return 0;
}

int murk_yread_range(const murk_ynode *n, const char *what, double lo, double hi, double *out, char *err,
                      size_t errlen)
{
    if (murk_yread_number(n, what, out, err, errlen))
        return -1;
    if (*out < lo || *out > hi)
        return ERR(n, "%s must be in [%g, %g], got %g", what, lo, hi, *out);
    return 0;
}

int murk_yread_int(const murk_ynode *n, const char *what, double lo, double hi, long long *out, char *err,
                    size_t errlen)
{
    double v = 0;
    if (murk_yread_number(n, what, &v, err, errlen))
        return -1;
    if (v != floor(v))
        return ERR(n, "%s must be a whole number, got '%s'", what, n->str);
    if (v < lo || v > hi)
        return ERR(n, "%s must be in [%.0f, %.0f], got %s", what, lo, hi, n->str);
    *out = (long long)v;
    return 0;
}

int murk_yread_bool(const murk_ynode *n, const char *what, int *out, char *err, size_t errlen)
{
    if (n->kind == MURK_Y_SCALAR) {
        if (!strcmp(n->str, "true") || !strcmp(n->str, "yes") || !strcmp(n->str, "on")) {
            *out = 1;
            return 0;
        }
        if (!strcmp(n->str, "false") || !strcmp(n->str, "no") || !strcmp(n->str, "off")) {
            *out = 0;
            return 0;
        }
    }
    return ERR(n, "%s must be true or false", what);
}

/* A fixed-length list of numbers in [lo, hi]. */
int murk_yread_list(const murk_ynode *n, const char *what, int len, double lo, double hi, double *out, char *err,
                     size_t errlen)
{
    if (n->kind != MURK_Y_SEQ || n->n != (size_t)len)
        return ERR(n, "%s must be a list of %d numbers", what, len);
    for (int i = 0; i < len; i++)
        if (murk_yread_range(n->items[i], what, lo, hi, &out[i], err, errlen))
            return -1;
    return 0;
}

int murk_yread_vec3(const murk_ynode *n, const char *what, murk_vec3 *v, char *err, size_t errlen)
{
    double d[3];
    if (n->kind != MURK_Y_SEQ || n->n != 3)
        return ERR(n, "%s must be a list of 3 numbers", what);
    for (int i = 0; i < 3; i++) {
        if (murk_yread_number(n->items[i], what, &d[i], err, errlen))
            return -1;
        if (fabs(d[i]) > MURK_MAX_COORD) /* positions and vectors alike: the scene must fit Embree and float */
            return ERR(n->items[i], "%s: %g is beyond %g, the largest coordinate murk accepts (Embree cannot trace "
                       "rays from beyond 1.8e18 and float arithmetic loses all precision long before)", what, d[i],
                       MURK_MAX_COORD);
    }
    *v = murk_v3((float)d[0], (float)d[1], (float)d[2]);
    return 0;
}

/* RGB: [r, g, b] or one number for grey. */
int murk_yread_rgb(const murk_ynode *n, const char *what, double lo, double hi, double out[3], char *err,
                    size_t errlen)
{
    if (n->kind == MURK_Y_SCALAR) {
        if (murk_yread_range(n, what, lo, hi, &out[0], err, errlen))
            return -1;
        out[1] = out[2] = out[0];
        return 0;
    }
    if (n->kind != MURK_Y_SEQ || n->n != 3)
        return ERR(n, "%s must be [r, g, b] or one number", what);
    return murk_yread_list(n, what, 3, lo, hi, out, err, errlen);
}

int murk_yread_string(const murk_ynode *n, const char *what, const char **out, char *err, size_t errlen)
{
    if (n->kind != MURK_Y_SCALAR || !*n->str)
        return ERR(n, "%s must be a name or a path", what);
    *out = n->str;
    return 0;
}

int murk_yexpect_map(const murk_ynode *n, const char *what, char *err, size_t errlen)
{
    if (!n || n->kind != MURK_Y_MAP)
        return ERR(n, "%s must be a map of keys", what);
    return 0;
}

/* Refuses any key of map that is not in allowed[], suggesting the closest. */
int murk_ycheck_keys(const murk_ynode *map, const char *what, const char *const *allowed, size_t nallowed,
                      char *err, size_t errlen)
{
    for (size_t i = 0; i < map->n; i++) {
        int ok = 0;
        for (size_t j = 0; j < nallowed && !ok; j++)
            ok = strcmp(map->keys[i], allowed[j]) == 0;
        if (ok)
            continue;
        const char *s = murk_did_you_mean(map->keys[i], allowed, nallowed);
        if (s)
            return murk_yerr_key(err, errlen, map, i, "unknown key '%s' in %s (did you mean '%s'?)", map->keys[i], what, s);
        int k = murk_yerr_key(err, errlen, map, i, "unknown key '%s' in %s; expected one of:", map->keys[i], what);
        size_t len = strlen(err);
        for (size_t j = 0; j < nallowed && len < errlen; j++)
            len += (size_t)snprintf(err + len, errlen - len, "%s %s", j ? "," : "", allowed[j]);
        return k;
    }
    return 0;
}

const murk_ynode *murk_yrequire(const murk_ynode *map, const char *key, const char *what, char *err, size_t errlen)
{
    const murk_ynode *n = murk_ymap_get(map, key);
    if (!n)
        murk_yerr(err, errlen, map, "%s is missing the required key '%s'", what, key);
    return n;
}

