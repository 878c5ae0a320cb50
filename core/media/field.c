/* field.c — the density field: a constant (infinite extent) or a grid of voxels over a box, built from
 * memory, evaluated trilinearly, and queried. See density.h for the conventions (values at cell centres,
 * trilinear, clamp, 0 outside). The grid sources are in vol.c, nanovdb.c and cloud.c; the majorant grid
 * over a field in majorant.c, its DDA walk in dda.c. */
#include "media/field_impl.h"
#include "util/error.h"
#include "util/util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- Construction --------------------------------------------------------------------------- */

murk_field *murk_field_constant(float value)
{
    if (!isfinite(value) || value < 0.0f)
        return NULL;
    murk_field *f = calloc(1, sizeof *f);
    if (!f)
        return NULL;
    f->kind = FIELD_CONSTANT;
    f->value = f->vmin = f->vmax = value;
    f->res[0] = f->res[1] = f->res[2] = 1;
    f->lo = murk_v3(-INFINITY, -INFINITY, -INFINITY);
    f->hi = murk_v3(INFINITY, INFINITY, INFINITY);
    return f;
}

uint64_t murk_voxel_count(int64_t x, int64_t y, int64_t z)
{
    uint64_t max = MURK_FIELD_MAX_VOXELS;
    if (x < 1 || y < 1 || z < 1 || (uint64_t)x > max || (uint64_t)y > max || (uint64_t)z > max)
        return 0;
    if ((uint64_t)x > max / (uint64_t)y)
        return 0;
    uint64_t xy = (uint64_t)x * (uint64_t)y;
    if ((uint64_t)z > max / xy)
        return 0;
    return xy * (uint64_t)z;
}

murk_field *murk_field_wrap(const int res[3], murk_vec3 lo, murk_vec3 hi, float *data)
{
    murk_field *f = calloc(1, sizeof *f);
    if (!f) {
        free(data);
        return NULL;
    }
    f->kind = FIELD_GRID;
    f->lo = lo;
    f->hi = hi;
    f->data = data;
    for (int a = 0; a < 3; a++) {
        f->res[a] = res[a];
        f->scale[a] = (float)res[a] / (murk_v3_get(hi, a) - murk_v3_get(lo, a));
    }
    uint64_t n = (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2];
    f->vmin = INFINITY;
    f->vmax = -INFINITY;
    for (uint64_t i = 0; i < n; i++) {
        f->vmin = fminf(f->vmin, data[i]);
        f->vmax = fmaxf(f->vmax, data[i]);
    }
    return f;
}

int murk_box_ok(murk_vec3 lo, murk_vec3 hi)
{
    for (int a = 0; a < 3; a++) {
        float l = murk_v3_get(lo, a), h = murk_v3_get(hi, a);
        if (!isfinite(l) || !isfinite(h) || !(h - l >= MURK_MIN_EXTENT) || !isfinite(h - l))
            return 0;
    }
    return 1;
}

/* Checks every voxel is finite and >= 0; on failure writes "path: ..." and returns -1. */
static int check_values(const char *path, const float *data, const int res[3], const int origin[3], char *err,
                        size_t errlen)
{
    size_t i = 0;
    for (int z = 0; z < res[2]; z++)
        for (int y = 0; y < res[1]; y++)
            for (int x = 0; x < res[0]; x++, i++) {
                float v = data[i];
                if (isfinite(v) && v >= 0.0f)
                    continue;
                murk_err_file(err, errlen, path, "%s %g at voxel (%d, %d, %d); densities must be finite and >= 0", isnan(v) ? "invalid value" : (isinf(v) ? "infinite value" : "negative density"), (double)v, x + origin[0], y + origin[1], z + origin[2]);
                return -1;
            }
    return 0;
}

murk_field *murk_field_adopt(const char *path, const int res[3], const int origin[3], murk_vec3 lo, murk_vec3 hi,
                             float *data, char *err, size_t errlen)
{
    if (check_values(path, data, res, origin, err, errlen) != 0) {
        free(data);
        return NULL;
    }
    murk_field *f = murk_field_wrap(res, lo, hi, data);
    if (!f)
        murk_err_file(err, errlen, path, "out of memory");
    return f;
}

MURK_API murk_field *murk_field_from_voxels(const int res[3], murk_vec3 lo, murk_vec3 hi, const float *data)
{
    uint64_t n = murk_voxel_count(res[0], res[1], res[2]);
    if (n == 0 || !murk_box_ok(lo, hi))
        return NULL;
    for (uint64_t i = 0; i < n; i++)
        if (!(isfinite(data[i]) && data[i] >= 0.0f))
            return NULL;
    float *copy = malloc((size_t)n * sizeof *copy);
    if (!copy)
        return NULL;
    memcpy(copy, data, (size_t)n * sizeof *copy);
    return murk_field_wrap(res, lo, hi, copy);
}

/* ---- Queries -------------------------------------------------------------------------------- */

float murk_field_eval(const murk_field *f, murk_vec3 p)
{
    if (f->kind == FIELD_CONSTANT)
        return f->value;
    if (!(p.x >= f->lo.x && p.x <= f->hi.x && p.y >= f->lo.y && p.y <= f->hi.y && p.z >= f->lo.z && p.z <= f->hi.z))
        return 0.0f;
    int i0[3], i1[3];
    float w[3];
    for (int a = 0; a < 3; a++) {
        int n = f->res[a];
        float u = (murk_v3_get(p, a) - murk_v3_get(f->lo, a)) * f->scale[a] - 0.5f;
        if (!(u >= 0.0f)) /* NaN too: the cell index below must stay a number */
            u = 0.0f;
        if (u > (float)(n - 1))
            u = (float)(n - 1);
        int i = (int)u;
        if (i > n - 2)
            i = n >= 2 ? n - 2 : 0;
        i0[a] = i;
        i1[a] = n >= 2 ? i + 1 : i;
        w[a] = u - (float)i;
    }
    const float *d = f->data;
    size_t sx = 1, sy = (size_t)f->res[0], sz = (size_t)f->res[0] * (size_t)f->res[1];
    size_t z0 = (size_t)i0[2] * sz, z1 = (size_t)i1[2] * sz, y0 = (size_t)i0[1] * sy, y1 = (size_t)i1[1] * sy;
    size_t x0 = (size_t)i0[0] * sx, x1 = (size_t)i1[0] * sx;
    float c00 = d[z0 + y0 + x0] + w[0] * (d[z0 + y0 + x1] - d[z0 + y0 + x0]);
    float c10 = d[z0 + y1 + x0] + w[0] * (d[z0 + y1 + x1] - d[z0 + y1 + x0]);
    float c01 = d[z1 + y0 + x0] + w[0] * (d[z1 + y0 + x1] - d[z1 + y0 + x0]);
    float c11 = d[z1 + y1 + x0] + w[0] * (d[z1 + y1 + x1] - d[z1 + y1 + x0]);
    float c0 = c00 + w[1] * (c10 - c00), c1 = c01 + w[1] * (c11 - c01);
    float v = c0 + w[2] * (c1 - c0);
    return v > 0.0f ? v : 0.0f; /* rounding cannot make a density of non-negative voxels negative */
}

void murk_field_bounds(const murk_field *f, murk_vec3 *lo, murk_vec3 *hi, int *infinite)
{
    if (lo)
        *lo = f->lo;
    if (hi)
        *hi = f->hi;
    if (infinite)
        *infinite = f->kind == FIELD_CONSTANT;
}

MURK_API float murk_field_max(const murk_field *f) { return f->vmax; }
float murk_field_min(const murk_field *f) { return f->vmin; }

MURK_API void murk_field_grid(const murk_field *f, int res[3], const float **data)
{
    for (int a = 0; a < 3; a++)
        res[a] = f->res[a];
    if (data)
        *data = f->data;
}

MURK_API void murk_field_free(murk_field *f)
{
    if (!f)
        return;
    free(f->data);
    free(f);
}
