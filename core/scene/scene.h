/* scene.h — the scene as the core holds it after loading and validation: data only (load/load.c builds
 * it, load/free.c frees it). Internal to libmurk. */
#ifndef MURK_SCENE_H
#define MURK_SCENE_H

#include <embree3/rtcore.h>

#include "murk/integrator.h"
#include "murk/material.h"
#include "murk/medium.h"
#include "murk/murk.h"
#include "plugin/plugin_loader.h"
#include "yaml/yamldoc.h"

struct murk_texture;

typedef enum { MURK_SHAPE_QUAD, MURK_SHAPE_SPHERE, MURK_SHAPE_BOX, MURK_SHAPE_MESH } murk_shape_type;

typedef struct murk_shape {
    murk_shape_type type;
    const murk_material *material;             /* NULL: medium boundary only */
    const murk_medium *interior, *exterior;
    murk_rgb emission;
    const struct murk_texture *emission_tex;   /* a mesh's emission is emission x this at (u, v); NULL: constant
                                                * (load/asset.c: a glTF emissiveTexture; the scene keeps it) */
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

/* What a light is: an emitting triangle or sphere of a shape (render/lights.c), or one of the scene's
 * `lights:` (load/light_block.c, or C: render/lights.h). */
typedef enum murk_light_kind {
    MURK_LK_TRIANGLE = 0,
    MURK_LK_SPHERE = 1,
    MURK_LK_POINT,   /* center, le = intensity (W/sr) */
    MURK_LK_SPOT,    /* center, n = axis (where it shines), le = intensity, cos_falloff, cos_cone */
    MURK_LK_DISTANT, /* n = unit direction towards it, le = irradiance E; omc > 0: a cone, radiance lc */
    MURK_LK_ENVMAP   /* env (NULL: a constant environment of radiance le); part of the environment */
} murk_light_kind;

typedef struct murk_envmap murk_envmap; /* a lat-long environment map (render/envmap.h) */

typedef struct murk_light {
    uint32_t geom, prim;
    int kind; /* murk_light_kind */
    murk_vec3 p0, e1, e2, n; /* triangle: p0 + a e1 + b e2; unit normal (emitting side) */
    murk_vec3 center;        /* sphere */
    float radius, area;
    float pmf; /* probability of picking this light */
    murk_rgb le;
    /* spot: the cosines of falloff_angle (full intensity) and cone_angle (none); distant: 1 - cos of
     * its cone's half-angle (0: a delta light) and the radiance inside the cone */
    float cos_falloff, cos_cone, omc;
    murk_rgb lc;
    const murk_envmap *env;
    /* a triangle of a rectangle (a quad or box face: two triangles): the rectangle p0 + a ex + b ey,
     * a, b in [0, 1], and the probability of picking either of its triangles (MURK_LIGHT_SOLID_ANGLE) */
    int rect;
    int textured; /* a triangle of a shape with an emission texture: le is its mean, ls.le its value */
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

/* render.traversal: Embree's default traversal, or its robust mode (RTC_SCENE_FLAG_ROBUST: conservative
 * box tests and exact triangle tests, so that fewer rays slip between triangles sharing an edge). */
enum { MURK_TRAVERSAL_FAST = 0, MURK_TRAVERSAL_ROBUST = 1 };

struct murk_scene {
    murk_ydoc doc;
    murk_registry reg;
    /* render block */
    int width, height, spp;
    uint64_t seed;
    float exposure;
    uint32_t sampler;   /* MURK_SAMPLER_* (render.sampler) */
    uint32_t traversal; /* MURK_TRAVERSAL_* (render.traversal) */
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
    /* materials made from an asset's own (shapes: - { type: asset, material: from_file }), each with the
     * YAML text of its parameters (load/asset.c) */
    murk_named_material **asset_materials;
    struct murk_ydoc **asset_docs;
    size_t nasset_materials;
    char **asset_inputs; /* the files an asset loaded beside itself (the files Assimp opened, e.g. a .gltf's .bin
                          * buffers or an OBJ's .mtl, and its PNG textures), for the content hash */
    size_t nasset_inputs;
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
    struct murk_empty_shape *empty_shapes; /* medium boxes and spheres with nothing else inside (render/accel.h) */
    size_t nempty_shapes;
    uint32_t *few_spheres; /* the other spheres' shape indices when there are few (render/accel.h) */
    size_t nfew_spheres;
    murk_light *lights;
    size_t nlights;
    float *light_cdf; /* nlights + 1 */
    float light_power;
    /* the `lights:` block's lights (and those added from C), until murk_lights_build appends them to
     * `lights`; the environment maps they own */
    murk_light *added;
    size_t nadded;
    /* where added lights came from, for murk info: added[first .. first + n) from `where` (owned) */
    struct murk_light_origin { size_t first, n; char *where; } *light_origins;
    size_t nlight_origins;
    murk_envmap **envmaps;
    size_t nenvmaps;
    /* the environment's parts (indices into lights: envmaps, finite-cone distant lights, and the constant
     * background as a constant envmap when there are others); none: background() is the constant */
    size_t *env;
    size_t nenv;
    int legacy_lights; /* the integrator predates MURK_ABI_MINOR_LIGHTS: the added lights get pmf 0 */
    RTCDevice device;
    RTCScene rtc;
    long long embree_bytes; /* what Embree holds for the scene (its memory monitor: BVH, buffers) */
};

#endif
