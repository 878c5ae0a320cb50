/* scene.h — the scene as the core holds it after loading and validation (load.c loads it, scene.c frees
 * it). Internal to libmurk. */
#ifndef MURK_SCENE_H
#define MURK_SCENE_H

#include <embree3/rtcore.h>

#include "murk/integrator.h"
#include "murk/material.h"
#include "murk/medium.h"
#include "murk/murk.h"
#include "plugin_loader.h"
#include "yamldoc.h"

typedef enum { MURK_SHAPE_QUAD, MURK_SHAPE_SPHERE, MURK_SHAPE_BOX, MURK_SHAPE_MESH } murk_shape_type;

typedef struct murk_shape {
    murk_shape_type type;
    const murk_material *material;             /* NULL: medium boundary only */
    const murk_medium *interior, *exterior;
    murk_rgb emission;
    int32_t light_base;                        /* light index of primitive 0, or -1 */
    uint32_t nverts, ntris;
    float *pos;                                /* 3*nverts (triangle shapes) */
    float *uv;                                 /* 2*nverts or NULL */
    float *nrm;                                /* 3*nverts or NULL (mesh shading normals) */
    float *ng;                                 /* 3*ntris unit geometric normals (accel.c; fill_hit's) */
    uint32_t *idx;                             /* 3*ntris */
    murk_vec3 center;                          /* sphere */
    float radius;
    char *name;                                /* mesh: its file as the scene names it (owned), else NULL */
} murk_shape;

typedef struct murk_light {
    uint32_t geom, prim;
    int sphere;
    murk_vec3 p0, e1, e2, n; /* triangle: p0 + a e1 + b e2; unit normal (emitting side) */
    murk_vec3 center;        /* sphere */
    float radius, area;
    float pmf; /* probability of picking this light */
    murk_rgb le;
    /* a triangle of a rectangle (a quad or box face: two triangles): the rectangle p0 + a ex + b ey,
     * a, b in [0, 1], and the probability of picking either of its triangles (MURK_LIGHT_SOLID_ANGLE) */
    int rect;
    murk_vec3 rp0, rex, rey;
    float rect_pmf;
} murk_light;

typedef struct murk_named_material { char *name; murk_material m; const murk_plugin *plugin; } murk_named_material;

typedef struct murk_named_medium {
    char *name;
    murk_medium m;
    murk_medium_data data;
    const murk_plugin *plugin;
    const murk_plugin *tr_plugin; /* its transmittance estimator's, or NULL (m.tr_vt may be the counters' wrapper) */
    struct murk_density *density; /* owned */
} murk_named_medium;

struct murk_texture;

struct murk_scene {
    murk_ydoc doc;
    murk_registry reg;
    /* render block */
    int width, height, spp;
    uint64_t seed;
    float exposure;
    uint32_t sampler; /* MURK_SAMPLER_* (render.sampler) */
    /* camera */
    murk_vec3 cam_from, cam_at, cam_up;
    float fov;
    murk_vec3 cam_w, cam_u, cam_v; /* forward, right, up (unit) */
    float cam_tan;                 /* tan(fov/2) */
    const murk_medium *camera_medium;
    murk_rgb background;
    /* plugins and their instances */
    murk_named_material *materials;
    size_t nmaterials;
    murk_named_medium *media;
    size_t nmedia;
    const murk_plugin *integrator_plugin;
    void *integrator;
    const murk_integrator_vt *integrator_vt;
    murk_value **param_store; /* parameter arrays handed to create(), freed with the scene */
    size_t nparam_store;
    struct murk_texture **textures;
    size_t ntextures;
    /* geometry */
    murk_shape *shapes; /* index = Embree geometry id */
    size_t nshapes;
    size_t nboundaries; /* shapes without a material: index-matched boundaries (set by murk_accel_build) */
    murk_light *lights;
    size_t nlights;
    float *light_cdf; /* nlights + 1 */
    float light_power;
    RTCDevice device;
    RTCScene rtc;
    long long embree_bytes; /* what Embree holds for the scene (its memory monitor: BVH, buffers) */
};

/* The murk command's rule for a loaded scene: a medium or material that no shape (and, for a medium,
 * not the camera) references is an error, "FILE:LINE:COL: media.NAME is not used by any shape or by the
 * camera; did you mean media.OTHER?" (or "--set ...: ..." for one a --set made). murk_scene_load itself
 * refuses only those a --set made (a misspelt name): embedders may load media and materials to call
 * them directly. Returns 0, or -1 with err. */
int murk_scene_check_unused(const murk_scene *s, char *err, size_t errlen);

/* The content hash a checkpoint carries: the scene file and every file it loads (meshes, density
 * grids, image textures, as named after the --set overrides), each with its path; so a resume after
 * any of them changed is refused. 0 with err if one cannot be read. */
uint64_t murk_scene_hash(const murk_scene *s, char *err, size_t errlen);

/* Releases what a shape owns (its triangle arrays). */
void murk_shape_free(murk_shape *sh);

/* What a loaded scene holds in memory, item by item (memory.c): each medium's density field with its bound grid,
 * each mesh (positions, uvs, normals, indices, triangle normals), each texture (texels as floats), and Embree's
 * scene (its BVH and its copies of the buffers, as its memory monitor counts them). Bytes as allocated, without
 * the allocator's own overhead. */
typedef struct murk_mem_item {
    const char *kind;   /* "grid", "mesh", "texture", "embree" */
    char name[160];     /* the medium, the file, or "scene" */
    char detail[160];   /* e.g. "sparse, 32221669 active voxels in 68051 bricks" */
    uint64_t bytes;
} murk_mem_item;
/* Fills items[0..cap) and returns how many there are (it may exceed cap: call again with more room). */
size_t murk_scene_memory(const murk_scene *s, murk_mem_item *items, size_t cap);
/* The peak resident memory of this process in kB (VmHWM), -1 where /proc does not say. */
long murk_peak_rss_kb(void);

#endif
