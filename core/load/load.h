/* load.h — the scene loader's functions beyond the public murk_scene_load / murk_scene_free (murk.h):
 * the command's rules and the content hash (load.c), a shape's release (free.c). Internal to libmurk. */
#ifndef MURK_LOAD_H
#define MURK_LOAD_H

#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

/* murk_scene_check_unused (murk/murk.h): murk_scene_load itself refuses only the unused media and
 * materials a --set made (a misspelt name); embedders may load media and materials to call them directly. */

/* The content hash a checkpoint carries: the scene file and every file it loads (meshes, density
 * grids, image textures, as named after the --set overrides), each with its path; so a resume after
 * any of them changed is refused. 0 with err if one cannot be read. */
uint64_t murk_scene_hash(const murk_scene *s, char *err, size_t errlen);

/* The `lights:` list (light_block.c): each light checked and added (render/lights.h). 0, or -1 with a
 * located err. */
int murk_load_lights(murk_scene *s, const murk_ynode *n, char *err, size_t errlen);
/* Records that the lights added since s->nadded was `before` came from where (printf format), for murk info. */
void murk_load_note_lights(murk_scene *s, size_t before, const char *fmt, ...) MURK_PRINTF(3, 4);

/* Releases what a shape owns (its triangle arrays). */
void murk_shape_free(murk_shape *sh);

/* load.c's readers that asset.c shares: a `transform:` block (scale, rotate, translate) as a 3 x 4 matrix
 * M = T Rz Ry Rx S, and a material or medium named by a node. 0, or -1 with a located err. */
int murk_read_transform(const murk_ynode *n, float m[12], char *err, size_t errlen);
int murk_load_lookup_material(const murk_scene *s, const murk_ynode *n, const murk_material **out, char *err,
                              size_t errlen);
int murk_load_lookup_medium(const murk_scene *s, const murk_ynode *n, const murk_medium **out, char *err, size_t errlen);

/* A camera taken from an asset (camera: { from_asset: N }): found, and the camera's frame and vertical fov. */
typedef struct murk_asset_camera {
    int found;
    murk_vec3 from, at, up;
    float fov;
} murk_asset_camera;
/* The shape block n of `type: asset` (asset.c): appends a triangle shape per mesh of the file to s->shapes
 * (capacity *cap, grown as needed), makes the file's materials (material: from_file) and lights; with cam,
 * also takes the file's camera called camera (NULL: its first). 0, or -1 with a located err (shapes added
 * before it stay in s, to be freed with the scene). */
int murk_load_asset(murk_scene *s, const murk_host *host, const murk_ynode *n, size_t *cap, const char *camera,
                    murk_asset_camera *cam, char *err, size_t errlen);

/* What a loaded scene holds in memory, item by item (memory.c): each medium's density field with its bound
 * grid, each mesh (positions, uvs, normals, indices, triangle normals), each texture (texels as floats), and
 * Embree's scene (its BVH and its copies of the buffers, as its memory monitor counts them). Bytes as
 * allocated, without the allocator's own overhead. */
typedef struct murk_mem_item {
    const char *kind;   /* "grid", "mesh", "texture", "embree" */
    char name[160];     /* the medium, the file, or "scene" */
    char detail[160];   /* e.g. "sparse, 32221669 active voxels in 68051 bricks" */
    uint64_t bytes;
    uint64_t dense_bytes; /* a sparse grid: what its voxels would take held dense (4 bytes each); else 0 */
    uint64_t sparse_bytes; /* a sparse grid held dense (its dense form no larger): what its sparse form held */
} murk_mem_item;
/* Fills items[0..cap) and returns how many there are (it may exceed cap: call again with more room). */
size_t murk_scene_memory(const murk_scene *s, murk_mem_item *items, size_t cap);

#endif
