/* vdb_shim.h — the C interface of the C++ shim over libopenvdb (vdb_shim.cpp), called by vdb.c only.
 * Plain C types on both sides: the shim includes no murk header and murk's C includes no OpenVDB one. */
#ifndef MURK_VDB_SHIM_H
#define MURK_VDB_SHIM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Where the shim puts a grid's content, in index space. Each callback returns 0, or -1 having written its
 * own message into the err given to murk_vdb_read (the shim then stops and returns -1). */
typedef struct murk_vdb_sink {
    void *user;
    /* the active voxels' index box, inclusive; called once, before any tile or leaf */
    int (*begin)(void *user, const int bmin[3], const int bmax[3], char *err, size_t errlen);
    /* an active tile of value over the cube [origin, origin + dim) */
    int (*tile)(void *user, const int origin[3], long long dim, float value, char *err, size_t errlen);
    /* a leaf node: 512 values, value (x, y, z) at (x & 7) << 6 | (y & 7) << 3 | (z & 7), and its active
     * mask (8 words of 64 bits, bit i for value i) */
    int (*leaf)(void *user, const int origin[3], const float *values, const uint64_t *mask, char *err,
                size_t errlen);
} murk_vdb_sink;

/* What murk_vdb_read found besides the voxels. */
typedef struct murk_vdb_meta {
    double map[12];       /* index to world, row-major 3 x 4: world_r = map[4r..4r+2] . ijk + map[4r+3] */
    double background;    /* the grid's background value (what its inactive voxels hold) */
    int no_such_grid;     /* 1 when the error is that the file has no grid of the name asked for */
} murk_vdb_meta;

/* Reads the scalar grid `grid` of the OpenVDB file at path (NULL: the file's only grid) into sink: a float
 * grid (stored as float or half) or a double grid (its values rounded to float, each checked to stay
 * finite). Refused, with the reason in err as "path: what is wrong": a file OpenVDB cannot read (the
 * library's own message and anything it logged), a missing grid (naming those the file has), a grid of
 * another value type, a level set, a non-linear (frustum) transform, a grid whose file metadata claims
 * more than max_active active voxels (before its voxels are read). Any C++ exception becomes such an
 * error; nothing is printed. Returns 0 or -1. */
int murk_vdb_read(const char *path, const char *grid, uint64_t max_active, const murk_vdb_sink *sink,
                  murk_vdb_meta *meta, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
