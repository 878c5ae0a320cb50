/* field_impl.h — the representation of a density field, shared by the files of core/media that build or
 * read fields (field.c, sparse.c, vol.c, nanovdb.c, vdb.c, cloud.c, majorant.c). Internal to core/media:
 * everything else uses density.h. */
#ifndef MURK_FIELD_IMPL_H
#define MURK_FIELD_IMPL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "media/density.h"

enum { FIELD_CONSTANT, FIELD_GRID, FIELD_SPARSE };

/* A sparse grid (sparse.c) stores its voxels in bricks of 8^3 floats, one brick per 8^3 block of index
 * space (the blocks of OpenVDB's and NanoVDB's leaf nodes), found through a two-level table: a top table
 * of nodes over the grid's box, each node covering 16^3 bricks (128^3 voxels). A brick's 512 values are
 * laid out as a leaf node's, value (x, y, z) at (x & 7) << 6 | (y & 7) << 3 | (z & 7), followed by the
 * brick's maximum and minimum (MURK_BRICK_MAX, MURK_BRICK_MIN) for the bound grid. Blocks with no
 * active voxel point to one brick of zeros and regions with no brick to one node of such pointers, so a
 * lookup never branches on emptiness; blocks of one value (an active tile, a leaf of equal values) share
 * one brick per value. */
#define MURK_BRICK_VALUES 512
#define MURK_BRICK_MAX 512
#define MURK_BRICK_MIN 513
#define MURK_BRICK_FLOATS 514
#define MURK_NODE_BRICKS 4096 /* 16^3 */

typedef struct murk_sparse_node {
    const float *b[MURK_NODE_BRICKS]; /* brick (bx & 15, by & 15, bz & 15) at (bz & 15) << 8 | (by & 15) << 4 | (bx & 15) */
} murk_sparse_node;

typedef struct murk_sparse {
    int off[3];                   /* voxel x of the box is index x + off (0..7) of the brick table */
    int nt[3];                    /* top table size: nodes per axis */
    murk_sparse_node **top;       /* nt[0] * nt[1] * nt[2], x fastest */
    murk_sparse_node *empty;      /* the node every empty region points to */
    float *zero;                  /* the brick of zeros */
    float **owned;                /* every brick allocated (zero brick first); freed with the field */
    size_t nowned, capowned;
    murk_sparse_node **nodes;     /* every node allocated (empty node first) */
    size_t nnodes, capnodes;
    uint64_t active;              /* active voxels of the source grid */
} murk_sparse;

struct murk_field {
    int kind;
    float value;          /* FIELD_CONSTANT */
    int res[3];           /* FIELD_GRID, FIELD_SPARSE: voxels per axis */
    murk_vec3 lo, hi;     /* the box, in world space (in the grid's local space when `affine`) */
    float scale[3];       /* res / (hi - lo): box to cell units */
    float *data;          /* FIELD_GRID */
    murk_sparse *sparse;  /* FIELD_SPARSE */
    /* A FIELD_GRID built as a sparse grid (.vdb, .nvdb) and held dense by murk_sparse_end's rule: from_sparse
     * is 1, active the source's active voxels, sparse_bytes what its sparse form held (murk_sparse_bytes). */
    int from_sparse;
    uint64_t active;
    size_t sparse_bytes;
    float vmin, vmax;     /* voxel extremes */
    /* A grid whose index-to-world map rotates, shears or mirrors: lo/hi/scale are in its local space
     * (index space, shifted so that the box starts at -1/2), where the field is looked up and its bound
     * grid built; w2l maps world to local (row r: local_r = w2l[4r..4r+2] . p + w2l[4r+3]), and
     * wlo/whi is the world box around the local box's eight corners. Otherwise affine is 0 and
     * wlo/whi = lo/hi. */
    int affine;
    float w2l[12];
    murk_vec3 wlo, whi;
};

/* Multiplies three positive resolutions; 0 if one is < 1 or the product exceeds MURK_FIELD_MAX_VOXELS. */
uint64_t murk_voxel_count(int64_t x, int64_t y, int64_t z);
/* The smallest extent of a grid's box on any axis: cells per unit length (res / extent) must stay a finite
 * float for every resolution the voxel limit allows. */
#define MURK_MIN_EXTENT 1e-20f
/* 1 if the box is finite with hi - lo >= MURK_MIN_EXTENT (and a finite extent) on every axis. */
int murk_box_ok(murk_vec3 lo, murk_vec3 hi);
/* A grid field over the finite box [lo, hi] taking ownership of data (freed on failure); NULL when out of
 * memory. The values must already be finite and >= 0. */
murk_field *murk_field_wrap(const int res[3], murk_vec3 lo, murk_vec3 hi, float *data);
/* What the file readers do with the voxels they read: checks every voxel is finite and >= 0 (origin
 * offsets the voxel coordinates named in a message), then wraps data. NULL with err = "path: ..." on
 * failure (data is freed). */
murk_field *murk_field_adopt(const char *path, const int res[3], const int origin[3], murk_vec3 lo, murk_vec3 hi,
                             float *data, char *err, size_t errlen);

/* A sparse field's brick lookup (sparse.c): the brick holding box voxel (x, y, z) (>= 0, inside the table). */
static inline const float *murk_sparse_brick(const murk_sparse *s, int x, int y, int z)
{
    x += s->off[0], y += s->off[1], z += s->off[2];
    const murk_sparse_node *n = s->top[((size_t)(z >> 7) * (size_t)s->nt[1] + (size_t)(y >> 7)) * (size_t)s->nt[0] +
                                       (size_t)(x >> 7)];
    return n->b[((z >> 3) & 15) << 8 | ((y >> 3) & 15) << 4 | ((x >> 3) & 15)];
}
static inline int murk_sparse_slot(const murk_sparse *s, int x, int y, int z)
{
    return ((x + s->off[0]) & 7) << 6 | ((y + s->off[1]) & 7) << 3 | ((z + s->off[2]) & 7);
}
/* Frees a sparse grid's storage (sparse.c). */
void murk_sparse_free(murk_sparse *s);
/* Bytes a sparse grid holds: its tables, nodes and distinct bricks (sparse.c). */
size_t murk_sparse_bytes(const murk_sparse *s);
/* Max and min of a grid field's voxels over the box index range [a, b] (inclusive, inside the box). */
void murk_field_range(const murk_field *f, const int a[3], const int b[3], float *mx, float *mn);

/* Building a sparse grid from a VDB tree's leaves and tiles (sparse.c; vdb.c and nanovdb.c feed it).
 * Index coordinates are the file's; the grid's box is its active voxels' index box [amin, amax] grown by
 * one voxel (of zeros) on every side, so that the field is the trilinear interpolation of the file's
 * voxels, inactive ones 0, everywhere: the values fall to 0 across the last cell, as they do between an
 * active voxel and an inactive one inside the box.
 * Errors are "path: what is wrong"; after one, only murk_sparse_abort may be called. */
typedef struct murk_sparse_build murk_sparse_build;
/* NULL with err when the box is too large (an axis over 2^24 voxels, or more than MURK_MAX_GRID_BOX
 * voxels in all) or out of memory. */
murk_sparse_build *murk_sparse_begin(const char *path, const int amin[3], const int amax[3], char *err,
                                     size_t errlen);
/* A leaf node at origin (multiples of 8): 512 values in leaf layout; mask (8 words, bit i of word i >> 6
 * for value i; NULL: all active) says which are active, the others are taken as 0. -1 with err for an
 * active value that is negative or not finite, a leaf outside the box or met twice, or when the bricks
 * would hold more than MURK_MAX_GRID_VOXELS values. */
int murk_sparse_leaf(murk_sparse_build *b, const int origin[3], const float *values, const uint64_t *mask, char *err,
                     size_t errlen);
/* An active tile: value over the index cube [origin, origin + dim) (dim a multiple of 8), inside the active
 * box. Same errors. */
int murk_sparse_tile(murk_sparse_build *b, const int origin[3], long long dim, float value, char *err, size_t errlen);
/* The field, with the file's index-to-world map (row-major 3 x 4: world_r = m[4r..4r+2] . ijk + m[4r+3],
 * voxel ijk's value sitting at world(ijk)). An axis-aligned map with positive scales gives a world box;
 * any other invertible map a local box (field_impl.h, `affine`). NULL with err for a map that is not
 * finite or is singular, a box that float cannot hold, or out of memory. Frees b either way.
 * The form it is held in: sparse, unless its dense form (4 bytes for each voxel of its box) is at most
 * 1/MURK_DENSE_SLACK larger than its sparse form (murk_sparse_bytes: bricks, nodes, tables) and its box within
 * MURK_MAX_GRID_VOXELS, in which case it is held dense (FIELD_GRID, from_sparse): the same box, voxels and map,
 * so every lookup gives the same value bit for bit, and a lookup costs a dense one, without the brick table a
 * grid with few empty bricks pays for on every lookup held sparse (docs/results.md, "Sparse grids"). Why the
 * slack: a grid with every brick present costs about 4 bytes a voxel both ways (a brick 2056 bytes for 512
 * voxels, plus nodes; the dense box one voxel of zeros wider on each side), so "no larger" alone flips on a
 * few KiB either way (the bench's fully active 128^3 checker is one: docs/results.md). So a grid held dense holds
 * at most 17/16 of its sparse form's bytes and at most 4 x MURK_MAX_GRID_VOXELS bytes, as a sparse one; while
 * it is copied the two forms are held together. */
#define MURK_DENSE_SLACK 16
murk_field *murk_sparse_end(murk_sparse_build *b, const double map[12], char *err, size_t errlen);
/* murk_sparse_end with the form chosen: MURK_HOLD_SMALLER (murk_sparse_end's rule), or always sparse, or always
 * dense (for tests and the bench, which compare the two forms of one grid). */
enum { MURK_HOLD_SMALLER, MURK_HOLD_SPARSE, MURK_HOLD_DENSE };
murk_field *murk_sparse_finish(murk_sparse_build *b, const double map[12], int hold, char *err, size_t errlen);
void murk_sparse_abort(murk_sparse_build *b);

/* Little-endian scalars of the grid file formats. */
static inline uint32_t murk_rd_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t murk_rd_u64(const unsigned char *p)
{
    return (uint64_t)murk_rd_u32(p) | (uint64_t)murk_rd_u32(p + 4) << 32;
}

#endif
