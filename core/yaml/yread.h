/* yread.h — typed readers of YAML nodes for the scene, media and texture loaders. Internal to libmurk.
 * Each returns 0, or -1 with err = "file:line:col: WHAT must be ..." naming the node. */
#ifndef MURK_YREAD_H
#define MURK_YREAD_H

#include <stddef.h>

#include "murk/math.h"
#include "yaml/yamldoc.h"

int murk_yread_number(const murk_ynode *n, const char *what, double *out, char *err, size_t errlen);
int murk_yread_range(const murk_ynode *n, const char *what, double lo, double hi, double *out, char *err,
                     size_t errlen);
int murk_yread_int(const murk_ynode *n, const char *what, double lo, double hi, long long *out, char *err,
                   size_t errlen);
int murk_yread_bool(const murk_ynode *n, const char *what, int *out, char *err, size_t errlen);
/* A list of exactly len numbers in [lo, hi]. */
int murk_yread_list(const murk_ynode *n, const char *what, int len, double lo, double hi, double *out, char *err,
                    size_t errlen);
int murk_yread_vec3(const murk_ynode *n, const char *what, murk_vec3 *v, char *err, size_t errlen);
/* [r, g, b] or one number for grey, each in [lo, hi]. */
int murk_yread_rgb(const murk_ynode *n, const char *what, double lo, double hi, double out[3], char *err,
                   size_t errlen);
int murk_yread_string(const murk_ynode *n, const char *what, const char **out, char *err, size_t errlen);
int murk_yexpect_map(const murk_ynode *n, const char *what, char *err, size_t errlen);
/* Refuses any key of map not in allowed[], suggesting the closest. */
int murk_ycheck_keys(const murk_ynode *map, const char *what, const char *const *allowed, size_t nallowed,
                     char *err, size_t errlen);
/* The value of a required key, or NULL with an error naming the map. */
const murk_ynode *murk_yrequire(const murk_ynode *map, const char *key, const char *what, char *err, size_t errlen);

#endif
