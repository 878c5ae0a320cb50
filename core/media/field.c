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
    f->wlo = f->lo;
    f->whi = f->hi;
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
    f->lo = f->wlo = lo;
    f->hi = f->whi = hi;
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
                murk_err_file(err, errlen, path, "%s %g at voxel (%d, %d, %d); field values must be finite and >= 0", isnan(v) ? "invalid value" : (isinf(v) ? "infinite value" : "negative value"), (double)v, x + origin[0], y + origin[1], z + origin[2]);
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

/* Trilinear interpolation of the 8 values around a point, v[(z * 2 + y) * 2 + x] for the corner
 * (x, y, z) in {0, 1}^3, with weights w: the one formula of every grid kind, so that a sparse grid gives
 * the dense grid's values bit for bit. */
static inline float trilinear(const float v[8], const float w[3])
{
    float c00 = v[0] + w[0] * (v[1] - v[0]);
    float c10 = v[2] + w[0] * (v[3] - v[2]);
    float c01 = v[4] + w[0] * (v[5] - v[4]);
    float c11 = v[6] + w[0] * (v[7] - v[6]);
    float c0 = c00 + w[1] * (c10 - c00), c1 = c01 + w[1] * (c11 - c01);
    float r = c0 + w[2] * (c1 - c0);
    return r > 0.0f ? r : 0.0f; /* rounding cannot make a density of non-negative voxels negative */
}

/* The 8 values around box voxel i0 of a sparse grid (d: 0 or 1 per axis, the step to the far corner).
 * When the 2 x 2 x 2 block lies in one brick (7 times in 8 per axis) one brick lookup serves all; otherwise
 * only the distinct bricks it touches (2, 4 or 8) are looked up. */
static inline void sparse_corners(const murk_sparse *s, const int i0[3], const int d[3], float v[8])
{
    int x = i0[0] + s->off[0], y = i0[1] + s->off[1], z = i0[2] + s->off[2];
    int cx = (x & 7) + d[0] > 7, cy = (y & 7) + d[1] > 7, cz = (z & 7) + d[2] > 7;
    const float *b0 = murk_sparse_brick(s, i0[0], i0[1], i0[2]);
    int o = murk_sparse_slot(s, i0[0], i0[1], i0[2]);
    if (!(cx | cy | cz)) {
        int sx = d[0] << 6, sy = d[1] << 3, sz = d[2];
        v[0] = b0[o];
        v[1] = b0[o + sx];
        v[2] = b0[o + sy];
        v[3] = b0[o + sx + sy];
        v[4] = b0[o + sz];
        v[5] = b0[o + sx + sz];
        v[6] = b0[o + sy + sz];
        v[7] = b0[o + sx + sy + sz];
        return;
    }
    const float *b[8];
    b[0] = b0;
    b[1] = cx ? murk_sparse_brick(s, i0[0] + 1, i0[1], i0[2]) : b0;
    b[2] = cy ? murk_sparse_brick(s, i0[0], i0[1] + 1, i0[2]) : b0;
    b[3] = cy ? (cx ? murk_sparse_brick(s, i0[0] + 1, i0[1] + 1, i0[2]) : b[2]) : b[1];
    for (int k = 4; k < 8; k++) /* the far z layer: the same bricks, or the next brick along z */
        b[k] = cz ? murk_sparse_brick(s, i0[0] + (k & 1) * d[0], i0[1] + ((k >> 1) & 1) * d[1], i0[2] + 1) : b[k - 4];
    for (int k = 0; k < 8; k++) {
        int px = (x + (k & 1) * d[0]) & 7, py = (y + ((k >> 1) & 1) * d[1]) & 7, pz = (z + (k >> 2) * d[2]) & 7;
        v[k] = b[k][px << 6 | py << 3 | pz];
    }
}

float murk_field_eval(const murk_field *f, murk_vec3 p)
{
    if (f->kind == FIELD_CONSTANT)
        return f->value;
    if (f->affine) { /* to the grid's local space (field_impl.h) */
        const float *m = f->w2l;
        p = murk_v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                    m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
    }
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
    float v[8];
    if (f->kind == FIELD_SPARSE) {
        int d[3] = {i1[0] - i0[0], i1[1] - i0[1], i1[2] - i0[2]};
        sparse_corners(f->sparse, i0, d, v);
        return trilinear(v, w);
    }
    const float *d = f->data;
    size_t sx = 1, sy = (size_t)f->res[0], sz = (size_t)f->res[0] * (size_t)f->res[1];
    size_t z0 = (size_t)i0[2] * sz, z1 = (size_t)i1[2] * sz, y0 = (size_t)i0[1] * sy, y1 = (size_t)i1[1] * sy;
    size_t x0 = (size_t)i0[0] * sx, x1 = (size_t)i1[0] * sx;
    v[0] = d[z0 + y0 + x0];
    v[1] = d[z0 + y0 + x1];
    v[2] = d[z0 + y1 + x0];
    v[3] = d[z0 + y1 + x1];
    v[4] = d[z1 + y0 + x0];
    v[5] = d[z1 + y0 + x1];
    v[6] = d[z1 + y1 + x0];
    v[7] = d[z1 + y1 + x1];
    return trilinear(v, w);
}

MURK_API float murk_field_voxel(const murk_field *f, int x, int y, int z)
{
    if (f->kind == FIELD_SPARSE)
        return murk_sparse_brick(f->sparse, x, y, z)[murk_sparse_slot(f->sparse, x, y, z)];
    if (f->kind == FIELD_CONSTANT)
        return f->value;
    return f->data[((size_t)z * (size_t)f->res[1] + (size_t)y) * (size_t)f->res[0] + (size_t)x];
}

MURK_API void murk_field_bounds(const murk_field *f, murk_vec3 *lo, murk_vec3 *hi, int *infinite)
{
    if (lo)
        *lo = f->wlo;
    if (hi)
        *hi = f->whi;
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

MURK_API void murk_field_describe(const murk_field *f, murk_field_info *info)
{
    memset(info, 0, sizeof *info);
    info->grid = f->kind != FIELD_CONSTANT;
    info->sparse = f->kind == FIELD_SPARSE;
    info->held_dense = f->from_sparse;
    info->transformed = f->affine;
    info->bytes = sizeof *f;
    if (f->kind == FIELD_GRID)
        info->bytes += (size_t)f->res[0] * (size_t)f->res[1] * (size_t)f->res[2] * sizeof *f->data;
    if (f->from_sparse) {
        info->active = f->active;
        info->sparse_bytes = f->sparse_bytes;
    }
    if (f->kind == FIELD_SPARSE) {
        info->active = f->sparse->active;
        info->bricks = f->sparse->nowned - 1; /* not the brick of zeros */
        info->sparse_bytes = murk_sparse_bytes(f->sparse);
        info->bytes += info->sparse_bytes;
    }
}

murk_ray murk_field_local_ray(const murk_field *f, const murk_ray *r)
{
    if (!f->affine)
        return *r;
    const float *m = f->w2l;
    murk_ray l = *r;
    double o[3] = {r->o.x, r->o.y, r->o.z}, d[3] = {r->d.x, r->d.y, r->d.z}, lo[3], ld[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (double)m[4 * a] * o[0] + (double)m[4 * a + 1] * o[1] + (double)m[4 * a + 2] * o[2] + m[4 * a + 3];
        ld[a] = (double)m[4 * a] * d[0] + (double)m[4 * a + 1] * d[1] + (double)m[4 * a + 2] * d[2];
    }
    l.o = murk_v3((float)lo[0], (float)lo[1], (float)lo[2]);
    l.d = murk_v3((float)ld[0], (float)ld[1], (float)ld[2]);
    return l;
}

MURK_API void murk_field_free(murk_field *f)
{
    if (!f)
        return;
    free(f->data);
    murk_sparse_free(f->sparse);
    free(f);
}
