/* field_impl.h — the representation of a density field, shared by the files of core/media that build or
 * read fields (field.c, vol.c, nanovdb.c, cloud.c, majorant.c). Internal to core/media: everything
 * else uses density.h. */
#ifndef MURK_FIELD_IMPL_H
#define MURK_FIELD_IMPL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "media/density.h"

enum { FIELD_CONSTANT, FIELD_GRID };

struct murk_field {
    int kind;
    float value;          /* FIELD_CONSTANT */
    int res[3];           /* FIELD_GRID: voxels per axis */
    murk_vec3 lo, hi;     /* world box */
    float scale[3];       /* res / (hi - lo): world to cell units */
    float *data;
    float vmin, vmax;     /* voxel extremes */
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
