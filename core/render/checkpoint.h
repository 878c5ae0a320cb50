/* checkpoint.h — a render's accumulated state on disk, so an interrupted render can be resumed. Internal
 * to libmurk.
 *
 * The file holds what the render loop keeps after whole passes — per pixel the sums of its finite samples
 * (double, in sample order) and their count — with the spp reached and what the state belongs to: the
 * scene's content hash, its --set overrides, seed and resolution. Resuming continues with sample spp, so a
 * render interrupted and resumed to N spp is bitwise identical to an uninterrupted N-spp render. Layout
 * (native byte order, a byte-order mark guards it): "MURKCKPT" u32 version u32 0x01020304, u64 scene_hash,
 * u64 seed, i32 width, i32 height, i32 spp, u32 overrides length, u64 nonfinite, u64 rays, overrides
 * bytes, 3*w*h double sums, w*h u32 counts, u64 FNV-1a of everything before. Written with
 * murk_write_atomic (a temporary renamed over the file), so a checkpoint is whole or absent. */
#ifndef MURK_CHECKPOINT_H
#define MURK_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

typedef struct murk_ckpt {
    uint64_t scene_hash, seed;
    int width, height, spp;
    const char *overrides; /* "" when none; owned by the caller on save, malloc'd by load */
    uint64_t nonfinite, rays;
    double *sum;           /* 3*width*height */
    uint32_t *count;       /* width*height */
} murk_ckpt;

uint64_t murk_fnv1a(uint64_t h, const void *data, size_t n); /* start with h = 0 */
int murk_ckpt_save(const char *path, const murk_ckpt *c, char *err, size_t errlen);
/* Reads path and checks it belongs to `want` (scene_hash, seed, size, overrides): fills c (sum, count and
 * overrides malloc'd; murk_ckpt_free) or returns -1 with "path: why" in err. */
int murk_ckpt_load(const char *path, const murk_ckpt *want, murk_ckpt *c, char *err, size_t errlen);
void murk_ckpt_free(murk_ckpt *c);

#endif
