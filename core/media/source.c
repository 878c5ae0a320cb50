/* source.c — a scalar field from a scene block (source.h has the syntax): the medium's density, and any
 * other field a medium reads the same way. */
#include "media/source.h"
#include "yaml/yread.h"
#include "util/limit.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static murk_field *load_cloud(const murk_ynode *c, char *err, size_t errlen)
{
    static const char *const keys[] = {"min", "max", "seed", "frequency", "octaves", "coverage", "resolution"};
    if (c->kind != MURK_Y_MAP) {
        murk_yerr(err, errlen, c, "cloud must be a map { min, max, seed, frequency, octaves, coverage, resolution }");
        return NULL;
    }
    if (murk_ycheck_keys(c, "cloud", keys, 7, err, errlen))
        return NULL;
    murk_vec3 lo = murk_v3(-0.5f, -0.5f, -0.5f), hi = murk_v3(0.5f, 0.5f, 0.5f);
    double freq = 3, cov = 0.5;
    long long seed = 1, oct = 5, res = 64; /* whole numbers: 2.5 is an error, never silently 2 */
    const murk_ynode *k;
    if (((k = murk_ymap_get(c, "min")) && murk_yread_vec3(k, "cloud.min", &lo, err, errlen)) ||
        ((k = murk_ymap_get(c, "max")) && murk_yread_vec3(k, "cloud.max", &hi, err, errlen)) ||
        ((k = murk_ymap_get(c, "seed")) && murk_yread_int(k, "cloud.seed", 0, 4294967295.0, &seed, err, errlen)) ||
        ((k = murk_ymap_get(c, "frequency")) && murk_yread_range(k, "cloud.frequency", 0.01, 1000, &freq, err, errlen)) ||
        ((k = murk_ymap_get(c, "octaves")) && murk_yread_int(k, "cloud.octaves", 1, 16, &oct, err, errlen)) ||
        ((k = murk_ymap_get(c, "coverage")) && murk_yread_range(k, "cloud.coverage", 0, 1, &cov, err, errlen)) ||
        ((k = murk_ymap_get(c, "resolution")) && murk_yread_int(k, "cloud.resolution", 2, 1024, &res, err, errlen)))
        return NULL;
    if ((double)res * (double)res * (double)res > (double)MURK_FIELD_MAX_VOXELS) {
        murk_yerr(err, errlen, murk_ymap_get(c, "resolution"), "cloud.resolution %lld gives %.0f voxels, beyond the "
                  "limit of %llu (%s)", res, (double)res * (double)res * (double)res,
                  (unsigned long long)MURK_FIELD_MAX_VOXELS, murk_limit_name(MURK_LIMIT_GRID_VOXELS));
        return NULL;
    }
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
        murk_yerr(err, errlen, c, "cloud: max must exceed min on every axis");
        return NULL;
    }
    murk_field *f = murk_field_cloud(lo, hi, (int)res, (uint64_t)seed, (float)freq, (int)oct, (float)cov);
    if (!f)
        murk_yerr(err, errlen, c, "cloud: could not build the field (out of memory?)");
    return f;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t l = strlen(s), k = strlen(suffix);
    return l > k && strcmp(s + l - k, suffix) == 0;
}

/* { vdb: F, grid: NAME }: the error at the grid's name when the file has no such grid, else at the file. */
static murk_field *load_vdb(const char *scene_file, const murk_ynode *d, const char *what, char *err, size_t errlen)
{
    const murk_ynode *v = murk_ymap_get(d, "vdb"), *g = murk_ymap_get(d, "grid");
    if (v->kind != MURK_Y_SCALAR || !*v->str) {
        murk_yerr(err, errlen, v, "%s.vdb must be a file name", what);
        return NULL;
    }
    if (g && (g->kind != MURK_Y_SCALAR || !*g->str)) {
        murk_yerr(err, errlen, g, "%s.grid must be the name of a grid in %s", what, v->str);
        return NULL;
    }
    char *path = murk_path_relative_to(scene_file, v->str);
    char ferr[1536];
    int missing = 0;
    murk_field *f = murk_field_vdb_load(path, g ? g->str : NULL, &missing, ferr, sizeof ferr);
    free(path);
    if (!f)
        murk_yerr(err, errlen, missing && g ? g : v, "%s vdb: %s", what, ferr);
    return f;
}

murk_field *murk_field_from_node(const char *scene_file, const murk_ynode *d, const char *what, char *err,
                                 size_t errlen)
{
    static const char *const keys[] = {"constant", "grid", "vdb", "cloud"};
    const murk_ynode *k;
    if (d->kind == MURK_Y_MAP && murk_ymap_get(d, "vdb")) {
        static const char *const vdb_keys[] = {"vdb", "grid"};
        if (murk_ycheck_keys(d, what, vdb_keys, 2, err, errlen))
            return NULL;
        return load_vdb(scene_file, d, what, err, errlen);
    }
    if (d->kind != MURK_Y_MAP || d->n != 1) {
        murk_yerr(err, errlen, d, "%s must be one of { constant: V }, { grid: FILE.vol|FILE.nvdb }, "
                  "{ vdb: FILE.vdb, grid: NAME }, { cloud: {...} }", what);
        return NULL;
    }
    if (murk_ycheck_keys(d, what, keys, 4, err, errlen))
        return NULL;
    if ((k = murk_ymap_get(d, "constant"))) {
        char w[64];
        double v;
        snprintf(w, sizeof w, "%s.constant", what);
        if (murk_yread_range(k, w, 0, 1e30, &v, err, errlen))
            return NULL;
        return murk_field_constant((float)v);
    }
    if ((k = murk_ymap_get(d, "grid"))) {
        if (k->kind != MURK_Y_SCALAR || !*k->str) {
            murk_yerr(err, errlen, k, "%s.grid must be a file name", what);
            return NULL;
        }
        if (ends_with(k->str, ".vdb")) {
            murk_yerr(err, errlen, k, "%s: an OpenVDB file is named with { vdb: %s, grid: NAME }", what, k->str);
            return NULL;
        }
        char *path = murk_path_relative_to(scene_file, k->str);
        char ferr[768];
        murk_field *f = ends_with(path, ".nvdb") ? murk_field_nvdb_load(path, ferr, sizeof ferr)
                                                 : murk_field_vol_load(path, ferr, sizeof ferr);
        free(path);
        if (!f)
            murk_yerr(err, errlen, k, "%s grid: %s", what, ferr);
        return f;
    }
    return load_cloud(murk_ymap_get(d, "cloud"), err, errlen);
}

const murk_ynode *murk_field_node_file(const murk_ynode *n)
{
    const murk_ynode *f = murk_ymap_get(n, "vdb");
    if (!f)
        f = murk_ymap_get(n, "grid");
    return f && f->kind == MURK_Y_SCALAR ? f : NULL;
}
