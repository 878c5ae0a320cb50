/* sparse.c — sparse grids: voxels held in 8^3 bricks found through a two-level table, so that memory
 * follows a grid's active voxels rather than its box (field_impl.h has the layout; density.h the
 * conventions, which are the dense grid's: the same box, the same trilinear lookup, bit for bit).
 *
 * Built from the leaves and active tiles of an OpenVDB tree (vdb.c, through the C++ shim) or a NanoVDB
 * tree (nanovdb.c). Inactive voxels are 0 whatever the file stores for them: a density grid's background
 * is empty space. A leaf or tile of one value shares one brick per value, and a block with no active
 * voxel points to the brick of zeros, so neither costs a brick.
 *
 * Memory bound: everything a sparse grid allocates (top table, nodes, bricks) counts against a budget of
 * 4 x MURK_MAX_GRID_VOXELS bytes, the memory of the largest dense grid murk accepts; bricks are allocated
 * one by one at 514 floats, the size of an OpenVDB leaf buffer's allocation (2048 bytes, the same malloc
 * chunk), so that the shim can free each OpenVDB leaf as its brick is made and the allocator reuses it:
 * the peak while loading stays near one copy of the grid.
 *
 * The form a grid is held in (murk_sparse_end; field_impl.h states the rule): sparse, unless its dense form,
 * 4 bytes for each voxel of its box, is at most 1/16 larger than its sparse form's bytes (murk_sparse_bytes),
 * in which case it is copied into a dense grid with the same box and the bricks are freed: the same lookups bit
 * for bit, and a dense grid's lookup cost (a grid with few empty bricks pays the brick table on every lookup
 * and saves no memory for it, docs/results.md). */
#include "media/field_impl.h"
#include "util/error.h"
#include "util/limit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_AXIS (1 << 24) /* voxel indices stay exact in float */

struct murk_sparse_build {
    const char *path;
    murk_field *f;
    int bmin[3];        /* index of box voxel 0 */
    int org[3];         /* index of table voxel 0 (bmin rounded down to a multiple of 8) */
    int nbk[3];         /* bricks per axis of the table that hold box voxels */
    uint64_t bytes;     /* allocated so far, against budget */
    uint64_t budget;
    /* constant bricks by value: open addressing on the value's bits (cap a power of two) */
    uint32_t *ckey;
    float **cbrick;
    size_t ccap, ccount;
};

/* ---- storage ------------------------------------------------------------------------------- */

static int grow_list(void *list, size_t *n, size_t *cap, void *item)
{
    void ***l = list;
    if (*n == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        void **g = realloc(*l, nc * sizeof *g);
        if (!g)
            return -1;
        *l = g;
        *cap = nc;
    }
    (*l)[(*n)++] = item;
    return 0;
}

static int over_budget(murk_sparse_build *b, uint64_t more, char *err, size_t errlen)
{
    if (b->bytes + more <= b->budget) {
        b->bytes += more;
        return 0;
    }
    return murk_err_file(err, errlen, b->path, "the sparse grid needs more than %llu bytes, the memory of %llu voxels "
                         "(%s; %llu active voxels so far)", (unsigned long long)b->budget,
                         (unsigned long long)murk_limit(MURK_LIMIT_GRID_VOXELS), murk_limit_name(MURK_LIMIT_GRID_VOXELS),
                         (unsigned long long)b->f->sparse->active);
}

static float *new_brick(murk_sparse_build *b, char *err, size_t errlen)
{
    if (over_budget(b, MURK_BRICK_FLOATS * sizeof(float), err, errlen))
        return NULL;
    murk_sparse *s = b->f->sparse;
    float *br = malloc(MURK_BRICK_FLOATS * sizeof *br);
    if (!br || grow_list(&s->owned, &s->nowned, &s->capowned, br)) {
        free(br);
        murk_err_file(err, errlen, b->path, "out of memory");
        return NULL;
    }
    return br;
}

static void brick_stats(float *br)
{
    float mx = br[0], mn = br[0];
    for (int i = 1; i < MURK_BRICK_VALUES; i++) {
        mx = fmaxf(mx, br[i]);
        mn = fminf(mn, br[i]);
    }
    br[MURK_BRICK_MAX] = mx;
    br[MURK_BRICK_MIN] = mn;
}

/* The shared brick of value v (the zero brick for 0). */
static const float *constant_brick(murk_sparse_build *b, float v, char *err, size_t errlen)
{
    if (v == 0.0f)
        return b->f->sparse->zero;
    uint32_t key;
    memcpy(&key, &v, sizeof key);
    if (2 * (b->ccount + 1) > b->ccap) { /* keep the table at most half full */
        size_t nc = b->ccap ? 2 * b->ccap : 64;
        uint32_t *k = calloc(nc, sizeof *k);
        float **p = calloc(nc, sizeof *p);
        if (!k || !p) {
            free(k);
            free(p);
            murk_err_file(err, errlen, b->path, "out of memory");
            return NULL;
        }
        for (size_t i = 0; i < b->ccap; i++)
            if (b->cbrick[i]) {
                size_t h = (b->ckey[i] * 0x9e3779b1u) & (nc - 1);
                while (p[h])
                    h = (h + 1) & (nc - 1);
                k[h] = b->ckey[i];
                p[h] = b->cbrick[i];
            }
        free(b->ckey);
        free(b->cbrick);
        b->ckey = k;
        b->cbrick = p;
        b->ccap = nc;
    }
    size_t h = (key * 0x9e3779b1u) & (b->ccap - 1);
    while (b->cbrick[h] && b->ckey[h] != key)
        h = (h + 1) & (b->ccap - 1);
    if (b->cbrick[h])
        return b->cbrick[h];
    float *br = new_brick(b, err, errlen);
    if (!br)
        return NULL;
    for (int i = 0; i < MURK_BRICK_VALUES; i++)
        br[i] = v;
    brick_stats(br);
    b->ckey[h] = key;
    b->cbrick[h] = br;
    b->ccount++;
    return br;
}

/* Puts brick br at table brick (bx, by, bz); -1 if a brick is there already. */
static int put_brick(murk_sparse_build *b, int bx, int by, int bz, const float *br, char *err, size_t errlen)
{
    murk_sparse *s = b->f->sparse;
    size_t t = ((size_t)(bz >> 4) * (size_t)s->nt[1] + (size_t)(by >> 4)) * (size_t)s->nt[0] + (size_t)(bx >> 4);
    murk_sparse_node *n = s->top[t];
    if (n == s->empty) {
        if (over_budget(b, sizeof *n, err, errlen))
            return -1;
        n = malloc(sizeof *n);
        if (!n || grow_list(&s->nodes, &s->nnodes, &s->capnodes, n)) {
            free(n);
            return murk_err_file(err, errlen, b->path, "out of memory");
        }
        memcpy(n, s->empty, sizeof *n);
        s->top[t] = n;
    }
    const float **slot = &n->b[(bz & 15) << 8 | (by & 15) << 4 | (bx & 15)];
    if (*slot != s->zero)
        return murk_err_file(err, errlen, b->path, "corrupt tree: two nodes hold the voxels at index (%d, %d, %d)",
                             b->org[0] + 8 * bx, b->org[1] + 8 * by, b->org[2] + 8 * bz);
    *slot = br;
    return 0;
}

/* ---- building ------------------------------------------------------------------------------ */

static int floor8(int v) { return (int)((int64_t)v - (((int64_t)v % 8) + 8) % 8); }

murk_sparse_build *murk_sparse_begin(const char *path, const int amin[3], const int amax[3], char *err, size_t errlen)
{
    int64_t res[3], rounded = 1;
    int bmin[3], bmax[3]; /* the box: the active voxels' box and one voxel of zeros around it */
    for (int a = 0; a < 3; a++) {
        if ((int64_t)amax[a] < amin[a]) {
            murk_err_file(err, errlen, path, "the grid has no active voxels");
            return NULL;
        }
        if (amin[a] == INT32_MIN || amax[a] == INT32_MAX) {
            murk_err_file(err, errlen, path, "active voxels at index %d, the end of the index range", amin[a] == INT32_MIN ?
                          amin[a] : amax[a]);
            return NULL;
        }
        bmin[a] = amin[a] - 1;
        bmax[a] = amax[a] + 1;
        res[a] = (int64_t)bmax[a] - bmin[a] + 1;
        if (res[a] > MAX_AXIS) {
            murk_err_file(err, errlen, path, "the active voxels span %lld voxels along %c; murk takes at most %d",
                          (long long)res[a] - 2, "xyz"[a], MAX_AXIS - 2);
            return NULL;
        }
    }
    for (int a = 0; a < 3; a++) { /* the box the top table covers: each side rounded up to 128 */
        int64_t side = ((int64_t)bmin[a] - floor8(bmin[a]) + res[a] + 127) / 128 * 128;
        rounded = rounded > (int64_t)(murk_limit(MURK_LIMIT_GRID_BOX) / (uint64_t)side) + 1 ? INT64_MAX : rounded * side;
    }
    if (rounded < 0 || (uint64_t)rounded > murk_limit(MURK_LIMIT_GRID_BOX)) {
        murk_err_file(err, errlen, path, "the active voxels' box %lld x %lld x %lld (%lld..%lld, %lld..%lld, %lld..%lld) "
                      "exceeds the limit of %llu voxels (%s; each side counted rounded up to 128)", (long long)res[0] - 2,
                      (long long)res[1] - 2, (long long)res[2] - 2, (long long)amin[0], (long long)amax[0],
                      (long long)amin[1], (long long)amax[1], (long long)amin[2], (long long)amax[2],
                      (unsigned long long)murk_limit(MURK_LIMIT_GRID_BOX), murk_limit_name(MURK_LIMIT_GRID_BOX));
        return NULL;
    }
    murk_sparse_build *b = calloc(1, sizeof *b);
    murk_field *f = calloc(1, sizeof *f);
    murk_sparse *s = calloc(1, sizeof *s);
    if (!b || !f || !s) {
        free(b), free(f), free(s);
        murk_err_file(err, errlen, path, "out of memory");
        return NULL;
    }
    b->path = path;
    b->f = f;
    f->kind = FIELD_SPARSE;
    f->sparse = s;
    b->budget = 4 * murk_limit(MURK_LIMIT_GRID_VOXELS);
    size_t ntop = 1;
    for (int a = 0; a < 3; a++) {
        f->res[a] = (int)res[a];
        b->bmin[a] = bmin[a];
        b->org[a] = floor8(bmin[a]);
        s->off[a] = bmin[a] - b->org[a];
        b->nbk[a] = (s->off[a] + f->res[a] + 7) / 8;
        s->nt[a] = (s->off[a] + f->res[a] + 127) / 128;
        ntop *= (size_t)s->nt[a];
    }
    if (over_budget(b, ntop * sizeof *s->top + sizeof *s->empty + MURK_BRICK_FLOATS * sizeof(float), err, errlen)) {
        murk_sparse_abort(b);
        return NULL;
    }
    s->top = malloc(ntop * sizeof *s->top);
    s->empty = malloc(sizeof *s->empty);
    s->zero = calloc(MURK_BRICK_FLOATS, sizeof *s->zero);
    if (!s->top || !s->empty || !s->zero || grow_list(&s->owned, &s->nowned, &s->capowned, s->zero) ||
        grow_list(&s->nodes, &s->nnodes, &s->capnodes, s->empty)) {
        if (s->nowned == 0)
            free(s->zero);
        if (s->nnodes == 0)
            free(s->empty);
        s->zero = NULL;
        s->empty = NULL;
        murk_sparse_abort(b);
        murk_err_file(err, errlen, path, "out of memory");
        return NULL;
    }
    for (int i = 0; i < MURK_NODE_BRICKS; i++)
        s->empty->b[i] = s->zero;
    for (size_t i = 0; i < ntop; i++)
        s->top[i] = s->empty;
    return b;
}

/* The table brick of a node-aligned origin, or -1 with err if it holds no box voxel. */
static int table_brick(murk_sparse_build *b, const int origin[3], int bk[3], char *err, size_t errlen)
{
    for (int a = 0; a < 3; a++) {
        int64_t t = (int64_t)origin[a] - b->org[a];
        if (t < 0 || t % 8 != 0 || t / 8 >= b->nbk[a])
            return murk_err_file(err, errlen, b->path, "corrupt tree: a leaf at index (%d, %d, %d) holds active voxels "
                                 "outside the active box", origin[0], origin[1], origin[2]);
        bk[a] = (int)(t / 8);
    }
    return 0;
}

/* An active voxel of a leaf outside the active box (the box the file claims): -1 with err. */
static int outside_active(murk_sparse_build *b, const int origin[3], const uint64_t *mask, char *err, size_t errlen)
{
    int inside = 1;
    for (int a = 0; a < 3; a++)
        inside &= (int64_t)origin[a] > b->bmin[a] && (int64_t)origin[a] + 7 < (int64_t)b->bmin[a] + b->f->res[a] - 1;
    for (int i = 0; !inside && i < MURK_BRICK_VALUES; i++) {
        int c[3] = {origin[0] + (i >> 6), origin[1] + ((i >> 3) & 7), origin[2] + (i & 7)}, in = 1;
        for (int a = 0; a < 3; a++)
            in &= c[a] > b->bmin[a] && (int64_t)c[a] < (int64_t)b->bmin[a] + b->f->res[a] - 1;
        if (!in && (!mask || ((mask[i >> 6] >> (i & 63)) & 1u)))
            return murk_err_file(err, errlen, b->path, "corrupt tree: an active voxel at index (%d, %d, %d) lies "
                                 "outside the active box the file gives", c[0], c[1], c[2]);
    }
    return 0;
}

/* More active voxels than MURK_MAX_GRID_VOXELS: -1 with err. */
static int too_many(murk_sparse_build *b, uint64_t more, char *err, size_t errlen)
{
    uint64_t have = b->f->sparse->active, max = murk_limit(MURK_LIMIT_GRID_VOXELS);
    if (more <= max && have <= max - more)
        return 0;
    return murk_err_file(err, errlen, b->path, "more than %llu active voxels, the limit (%s)", (unsigned long long)max,
                         murk_limit_name(MURK_LIMIT_GRID_VOXELS));
}

static int bad_value(murk_sparse_build *b, float v, const int origin[3], int i, char *err, size_t errlen)
{
    return murk_err_file(err, errlen, b->path, "%s %g at voxel (%d, %d, %d); field values must be finite and >= 0",
                         isnan(v) ? "invalid value" : (isinf(v) ? "infinite value" : "negative value"), (double)v,
                         origin[0] + (i >> 6), origin[1] + ((i >> 3) & 7), origin[2] + (i & 7));
}

int murk_sparse_leaf(murk_sparse_build *b, const int origin[3], const float *values, const uint64_t *mask, char *err,
                     size_t errlen)
{
    float v[MURK_BRICK_FLOATS];
    unsigned active = 0;
    for (int i = 0; i < MURK_BRICK_VALUES; i++) {
        int on = !mask || ((mask[i >> 6] >> (i & 63)) & 1u);
        v[i] = on ? values[i] : 0.0f;
        if (on && !(isfinite(v[i]) && v[i] >= 0.0f))
            return bad_value(b, v[i], origin, i, err, errlen);
        active += (unsigned)on;
    }
    if (!active)
        return 0;
    if (too_many(b, active, err, errlen))
        return -1;
    int bk[3];
    if (table_brick(b, origin, bk, err, errlen) || outside_active(b, origin, mask, err, errlen))
        return -1;
    b->f->sparse->active += active;
    brick_stats(v);
    const float *br;
    if (v[MURK_BRICK_MAX] == v[MURK_BRICK_MIN]) {
        br = constant_brick(b, v[0], err, errlen);
    } else {
        float *nb = new_brick(b, err, errlen);
        if (nb)
            memcpy(nb, v, sizeof v);
        br = nb;
    }
    return br ? put_brick(b, bk[0], bk[1], bk[2], br, err, errlen) : -1;
}

int murk_sparse_tile(murk_sparse_build *b, const int origin[3], long long dim, float value, char *err, size_t errlen)
{
    if (!(isfinite(value) && value >= 0.0f)) {
        return murk_err_file(err, errlen, b->path, "%s %g in the tile at index (%d, %d, %d); field values must be finite "
                             "and >= 0", isnan(value) ? "invalid value" : (isinf(value) ? "infinite value" :
                             "negative value"), (double)value, origin[0], origin[1], origin[2]);
    }
    int lo[3], hi[3]; /* the table bricks the tile covers */
    uint64_t voxels = 1;
    for (int a = 0; a < 3; a++) {
        int64_t t0 = (int64_t)origin[a] - b->org[a], t1 = t0 + dim; /* [t0, t1) in table voxels */
        if (dim < 8 || dim % 8 != 0 || t0 % 8 != 0)
            return murk_err_file(err, errlen, b->path, "corrupt tree: a tile of %lld voxels at index (%d, %d, %d)",
                                 dim, origin[0], origin[1], origin[2]);
        int64_t a0 = (int64_t)b->bmin[a] + 1 - b->org[a], a1 = a0 + b->f->res[a] - 2; /* the active box */
        if (t0 < a0 || t1 > a1)
            return murk_err_file(err, errlen, b->path, "corrupt tree: the tile of %lld voxels at index (%d, %d, %d) "
                                 "reaches outside the active box the file gives", dim, origin[0], origin[1], origin[2]);
        voxels *= (uint64_t)dim;
        lo[a] = (int)(t0 / 8);
        hi[a] = (int)(t1 / 8);
    }
    if (too_many(b, voxels, err, errlen))
        return -1;
    b->f->sparse->active += voxels;
    if (value == 0.0f)
        return 0;
    const float *br = constant_brick(b, value, err, errlen);
    if (!br)
        return -1;
    for (int z = lo[2]; z < hi[2]; z++)
        for (int y = lo[1]; y < hi[1]; y++)
            for (int x = lo[0]; x < hi[0]; x++)
                if (put_brick(b, x, y, z, br, err, errlen))
                    return -1;
    return 0;
}

void murk_sparse_abort(murk_sparse_build *b)
{
    if (!b)
        return;
    if (b->f) {
        murk_sparse_free(b->f->sparse);
        free(b->f);
    }
    free(b->ckey);
    free(b->cbrick);
    free(b);
}

/* ---- the map from index space to the world ---------------------------------------------------- */

/* Sets the box (and, for a map that is not axis-aligned with positive scales, the local space). */
static int set_map(murk_sparse_build *b, const double m[12], char *err, size_t errlen)
{
    murk_field *f = b->f;
    double smax = 0.0;
    for (int i = 0; i < 12; i++) {
        if (!isfinite(m[i]))
            return murk_err_file(err, errlen, b->path, "the index-to-world transform is not finite");
        if (i % 4 != 3)
            smax = fmax(smax, fabs(m[i]));
    }
    int aligned = 1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            if (r == c ? !(m[4 * r + c] > 0.0) : !(fabs(m[4 * r + c]) <= 1e-9 * smax))
                aligned = 0;
    double lo[3], hi[3];
    if (aligned) { /* voxel ijk's centre at map(ijk): the box is the map of [bmin - 1/2, bmin + res - 1/2] */
        for (int a = 0; a < 3; a++) {
            lo[a] = m[4 * a + 3] + m[5 * a] * ((double)b->bmin[a] - 0.5);
            hi[a] = m[4 * a + 3] + m[5 * a] * ((double)b->bmin[a] + f->res[a] - 0.5);
        }
        f->lo = murk_v3((float)lo[0], (float)lo[1], (float)lo[2]);
        f->hi = murk_v3((float)hi[0], (float)hi[1], (float)hi[2]);
        f->wlo = f->lo;
        f->whi = f->hi;
        return murk_box_ok(f->lo, f->hi) ? 0 : murk_err_file(err, errlen, b->path, "the grid's world box is not "
                                                               "representable in float");
    }
    double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                 m[2] * (m[4] * m[9] - m[5] * m[8]);
    if (!(fabs(det) > 1e-12 * smax * smax * smax))
        return murk_err_file(err, errlen, b->path, "the index-to-world transform is singular (determinant %g)", det);
    double inv[9] = {(m[5] * m[10] - m[6] * m[9]) / det, (m[2] * m[9] - m[1] * m[10]) / det,
                     (m[1] * m[6] - m[2] * m[5]) / det, (m[6] * m[8] - m[4] * m[10]) / det,
                     (m[0] * m[10] - m[2] * m[8]) / det, (m[2] * m[4] - m[0] * m[6]) / det,
                     (m[4] * m[9] - m[5] * m[8]) / det, (m[1] * m[8] - m[0] * m[9]) / det,
                     (m[0] * m[5] - m[1] * m[4]) / det};
    /* local = inv (world - t) - bmin: index space with the box's first voxel centre at 0 */
    for (int r = 0; r < 3; r++) {
        double tr = -b->bmin[r];
        for (int c = 0; c < 3; c++) {
            f->w2l[4 * r + c] = (float)inv[3 * r + c];
            tr -= inv[3 * r + c] * m[4 * c + 3];
        }
        f->w2l[4 * r + 3] = (float)tr;
        if (!isfinite(tr) || !isfinite(f->w2l[4 * r]) || !isfinite(f->w2l[4 * r + 1]) || !isfinite(f->w2l[4 * r + 2]))
            return murk_err_file(err, errlen, b->path, "the inverse of the index-to-world transform is not "
                                 "representable in float");
    }
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (int k = 0; k < 8; k++) /* the world box around the local box's corners */
        for (int r = 0; r < 3; r++) {
            double w = m[4 * r + 3];
            for (int c = 0; c < 3; c++)
                w += m[4 * r + c] * ((double)b->bmin[c] - 0.5 + ((k >> c) & 1) * (double)f->res[c]);
            lo[r] = fmin(lo[r], w);
            hi[r] = fmax(hi[r], w);
        }
    f->affine = 1;
    f->lo = murk_v3(-0.5f, -0.5f, -0.5f);
    f->hi = murk_v3((float)f->res[0] - 0.5f, (float)f->res[1] - 0.5f, (float)f->res[2] - 0.5f);
    f->wlo = murk_v3(nextafterf((float)lo[0], -INFINITY), nextafterf((float)lo[1], -INFINITY),
                     nextafterf((float)lo[2], -INFINITY));
    f->whi = murk_v3(nextafterf((float)hi[0], INFINITY), nextafterf((float)hi[1], INFINITY),
                     nextafterf((float)hi[2], INFINITY));
    return murk_box_ok(f->wlo, f->whi) ? 0 : murk_err_file(err, errlen, b->path, "the grid's world box is not "
                                                             "representable in float");
}

/* The sparse field f held dense instead (FIELD_GRID, from_sparse): its box's voxels copied row by row, each
 * brick looked up once per run of up to 8 voxels along x; the box, map, scale and extremes stay, so every
 * lookup gives the same value bit for bit (field.c: one trilinear formula for both kinds). -1 with err
 * (f unchanged) when out of memory or, forced dense, when the box has more voxels than a dense grid may. */
static int hold_dense(murk_field *f, const char *path, char *err, size_t errlen)
{
    const murk_sparse *s = f->sparse;
    uint64_t n = murk_voxel_count(f->res[0], f->res[1], f->res[2]);
    if (n == 0)
        return murk_err_file(err, errlen, path, "the grid's box (%d x %d x %d voxels) is too large to hold dense",
                             f->res[0], f->res[1], f->res[2]);
    float *d = malloc((size_t)n * sizeof *d);
    if (!d)
        return murk_err_file(err, errlen, path, "out of memory");
    for (int z = 0; z < f->res[2]; z++)
        for (int y = 0; y < f->res[1]; y++) {
            float *row = d + ((size_t)z * (size_t)f->res[1] + (size_t)y) * (size_t)f->res[0];
            for (int x = 0; x < f->res[0];) { /* a brick's voxels along x are 64 apart (field_impl.h) */
                const float *br = murk_sparse_brick(s, x, y, z);
                int o = murk_sparse_slot(s, x, y, z), run = 8 - ((x + s->off[0]) & 7);
                for (int k = 0; k < run && x < f->res[0]; k++, x++)
                    row[x] = br[o + (k << 6)];
            }
        }
    f->active = s->active;
    f->sparse_bytes = murk_sparse_bytes(s);
    f->from_sparse = 1;
    murk_sparse_free(f->sparse);
    f->sparse = NULL;
    f->data = d;
    f->kind = FIELD_GRID;
    return 0;
}

murk_field *murk_sparse_finish(murk_sparse_build *b, const double map[12], int hold, char *err, size_t errlen)
{
    if (set_map(b, map, err, errlen)) {
        murk_sparse_abort(b);
        return NULL;
    }
    murk_field *f = b->f;
    for (int a = 0; a < 3; a++)
        f->scale[a] = (float)f->res[a] / (murk_v3_get(f->hi, a) - murk_v3_get(f->lo, a));
    int a0[3] = {0, 0, 0}, a1[3] = {f->res[0] - 1, f->res[1] - 1, f->res[2] - 1};
    murk_field_range(f, a0, a1, &f->vmax, &f->vmin);
    /* the rule (field_impl.h): dense when 4 bytes a box voxel are at most the sparse form's bytes and 1/16 of
     * them, i.e. res[0] res[1] <= (bytes + bytes / 16) / 4 / res[2] in integers (exactly that, without the
     * product's overflow), and the box within the voxels a dense grid may have */
    uint64_t sparse_bytes = murk_sparse_bytes(f->sparse);
    int dense = hold == MURK_HOLD_DENSE ||
                (hold == MURK_HOLD_SMALLER && (uint64_t)f->res[0] * (uint64_t)f->res[1] <=
                 (sparse_bytes + sparse_bytes / MURK_DENSE_SLACK) / sizeof(float) / (uint64_t)f->res[2] &&
                 murk_voxel_count(f->res[0], f->res[1], f->res[2]) != 0);
    if (dense && hold_dense(f, b->path, err, errlen)) {
        if (hold == MURK_HOLD_DENSE) {
            murk_sparse_abort(b);
            return NULL;
        }
        if (errlen) /* no memory for the dense copy: the grid stays sparse, as it is */
            err[0] = 0;
    }
    b->f = NULL;
    murk_sparse_abort(b);
    return f;
}

murk_field *murk_sparse_end(murk_sparse_build *b, const double map[12], char *err, size_t errlen)
{
    return murk_sparse_finish(b, map, MURK_HOLD_SMALLER, err, errlen);
}

/* ---- queries ------------------------------------------------------------------------------- */

void murk_sparse_free(murk_sparse *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < s->nowned; i++)
        free(s->owned[i]);
    for (size_t i = 0; i < s->nnodes; i++)
        free(s->nodes[i]);
    free(s->owned);
    free(s->nodes);
    free(s->top);
    free(s);
}

size_t murk_sparse_bytes(const murk_sparse *s)
{
    return sizeof *s + (size_t)s->nt[0] * (size_t)s->nt[1] * (size_t)s->nt[2] * sizeof *s->top +
           s->nnodes * sizeof(murk_sparse_node) + s->nowned * MURK_BRICK_FLOATS * sizeof(float) +
           s->capowned * sizeof *s->owned + s->capnodes * sizeof *s->nodes;
}

/* Max and min over the box voxels [a, b] of one brick, table brick (bx, by, bz): a brick wholly inside
 * takes its stored extremes, one cut by the range has its voxels in the range read. */
static void brick_range(const murk_sparse *s, int bx, int by, int bz, const int a[3], const int b[3], float *mx,
                        float *mn)
{
    int v0[3] = {8 * bx - s->off[0], 8 * by - s->off[1], 8 * bz - s->off[2]}, c0[3], c1[3], whole = 1;
    for (int k = 0; k < 3; k++) {
        c0[k] = v0[k] > a[k] ? v0[k] : a[k];
        c1[k] = v0[k] + 7 < b[k] ? v0[k] + 7 : b[k];
        whole &= c0[k] == v0[k] && c1[k] == v0[k] + 7;
    }
    const float *br = murk_sparse_brick(s, c0[0], c0[1], c0[2]);
    if (whole) {
        *mx = fmaxf(*mx, br[MURK_BRICK_MAX]);
        *mn = fminf(*mn, br[MURK_BRICK_MIN]);
        return;
    }
    for (int z = c0[2]; z <= c1[2]; z++)
        for (int y = c0[1]; y <= c1[1]; y++)
            for (int x = c0[0]; x <= c1[0]; x++) {
                float v = br[murk_sparse_slot(s, x, y, z)];
                *mx = fmaxf(*mx, v);
                *mn = fminf(*mn, v);
            }
}

/* Max and min over the box voxels [a, b] of a sparse field, node by node: a node of the empty region holds
 * zeros only, so a range over a mostly empty box costs its nodes, not its 2^9-voxel blocks. */
static void sparse_range(const murk_field *f, const int a[3], const int b[3], float *mx, float *mn)
{
    const murk_sparse *s = f->sparse;
    int lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = (a[k] + s->off[k]) >> 3;
        hi[k] = (b[k] + s->off[k]) >> 3;
    }
    for (int nz = lo[2] >> 4; nz <= hi[2] >> 4; nz++)
        for (int ny = lo[1] >> 4; ny <= hi[1] >> 4; ny++)
            for (int nx = lo[0] >> 4; nx <= hi[0] >> 4; nx++) {
                if (s->top[((size_t)nz * (size_t)s->nt[1] + (size_t)ny) * (size_t)s->nt[0] + (size_t)nx] == s->empty) {
                    *mx = fmaxf(*mx, 0.0f);
                    *mn = fminf(*mn, 0.0f);
                    continue;
                }
                int n0[3] = {nx << 4, ny << 4, nz << 4}, b0[3], b1[3];
                for (int k = 0; k < 3; k++) {
                    b0[k] = n0[k] > lo[k] ? n0[k] : lo[k];
                    b1[k] = n0[k] + 15 < hi[k] ? n0[k] + 15 : hi[k];
                }
                for (int bz = b0[2]; bz <= b1[2]; bz++)
                    for (int by = b0[1]; by <= b1[1]; by++)
                        for (int bx = b0[0]; bx <= b1[0]; bx++)
                            brick_range(s, bx, by, bz, a, b, mx, mn);
            }
}

void murk_field_range(const murk_field *f, const int a[3], const int b[3], float *mx, float *mn)
{
    *mx = 0.0f;
    *mn = INFINITY;
    if (f->kind == FIELD_SPARSE) {
        sparse_range(f, a, b, mx, mn);
        return;
    }
    size_t sy = (size_t)f->res[0], sz = (size_t)f->res[0] * (size_t)f->res[1];
    for (int z = a[2]; z <= b[2]; z++)
        for (int y = a[1]; y <= b[1]; y++) {
            const float *row = f->data + (size_t)z * sz + (size_t)y * sy;
            for (int x = a[0]; x <= b[0]; x++) {
                *mx = fmaxf(*mx, row[x]);
                *mn = fminf(*mn, row[x]);
            }
        }
}
