/* murk/plugin.h — the plugin ABI: version, descriptor, parameter schema, host services.
 *
 * A plugin is a shared object that exports exactly two symbols:
 *
 *     MURK_EXPORT const murk_abi murk_plugin_abi = { MURK_ABI_MAJOR, MURK_ABI_MINOR };
 *     MURK_EXPORT const murk_plugin_desc *murk_plugin_entry(void);
 *
 * The host reads `murk_plugin_abi` (a data symbol) before it runs any plugin code: the major must equal
 * the host's and the minor must not exceed it. Then it calls murk_plugin_entry() once and checks the
 * descriptor (struct_size, kind, name == file basename, vtable size). Plugins never link against
 * libmurk: everything they need from the core arrives as the murk_host table passed to create().
 * Structs that cross the boundary start with a size field; fields and methods are only appended. */
#ifndef MURK_PLUGIN_H
#define MURK_PLUGIN_H

#include <stddef.h>
#include <stdint.h>
#include "murk/math.h"

#define MURK_ABI_MAJOR 1
#define MURK_ABI_MINOR 0

#if defined(__GNUC__)
#define MURK_EXPORT __attribute__((visibility("default")))
#define MURK_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define MURK_EXPORT
#define MURK_PRINTF(a, b)
#endif

typedef struct murk_abi { uint32_t major, minor; } murk_abi;

typedef enum murk_kind {
    MURK_KIND_MATERIAL = 1,
    MURK_KIND_MEDIUM = 2,
    MURK_KIND_INTEGRATOR = 3
} murk_kind;

/* ---- Parameter schema ---------------------------------------------------------------------- */
typedef enum murk_param_type {
    MURK_PARAM_FLOAT = 1, /* a number; with MURK_PARAM_TEXTURABLE also a texture */
    MURK_PARAM_INT = 2,
    MURK_PARAM_BOOL = 3,
    MURK_PARAM_RGB = 4,   /* [r, g, b] or one number for grey; with MURK_PARAM_TEXTURABLE also a texture */
    MURK_PARAM_STRING = 5,
    MURK_PARAM_ENUM = 6   /* one of `choices`, a '|'-separated list */
} murk_param_type;

#define MURK_PARAM_TEXTURABLE 1u /* the value may be a texture ({ checker: ... } / { image: ... }) */
#define MURK_PARAM_REQUIRED 2u   /* the scene must give it */

typedef struct murk_param {
    const char *name;
    uint32_t type;    /* murk_param_type */
    uint32_t flags;   /* MURK_PARAM_* */
    double def[3];    /* default for FLOAT/INT/BOOL (def[0]) and RGB */
    const char *def_str; /* default for STRING and ENUM */
    const char *choices; /* ENUM only: "max|average|history" */
    double min, max;  /* inclusive range for numbers and every RGB component */
    const char *doc;  /* one line, shown by `murk plugins NAME` */
} murk_param;

typedef struct murk_texture murk_texture; /* opaque; evaluated through murk_host.tex_eval */

/* The value of one parameter as create() receives it: an array in schema order. */
typedef struct murk_value {
    int set;                 /* 1 if the scene gave it, 0 if this is the default */
    double f[3];             /* FLOAT/INT/BOOL in f[0]; RGB in f[0..2] */
    const char *s;           /* STRING and ENUM: the text */
    int choice;              /* ENUM: index into choices */
    const murk_texture *tex; /* non-NULL when a texture was given (f holds its average) */
} murk_value;

/* ---- Surface interactions ------------------------------------------------------------------ */
typedef struct murk_material murk_material; /* a material instance (see murk/material.h) */
typedef struct murk_medium murk_medium;     /* a medium instance (see murk/medium.h) */
typedef struct murk_scene murk_scene;       /* opaque scene handle given to integrators */
typedef struct murk_density murk_density;   /* a medium's density field (see murk/medium.h) */
typedef struct murk_majorant_walk murk_majorant_walk;

typedef struct murk_hit {
    float t;
    murk_vec3 p;      /* world position */
    murk_vec3 ng;     /* unit geometric normal, as the shape defines it (quad: u x v; sphere: outwards) */
    murk_vec3 n;      /* unit shading normal, same side as ng */
    float u, v;       /* surface parameterisation / texture coordinates */
    const murk_material *material; /* NULL: an index-matched medium boundary, not a surface */
    const murk_medium *interior;   /* medium on the -ng side (NULL: vacuum) */
    const murk_medium *exterior;   /* medium on the +ng side (NULL: vacuum) */
    murk_rgb emission; /* radiance emitted towards +ng (zero for non-emitters) */
    int32_t light;     /* index of the light this hit belongs to, or -1 */
    uint32_t geom, prim;
} murk_hit;

typedef struct murk_light_sample {
    murk_vec3 wi;  /* unit direction from the shading point to the light point */
    float dist;    /* distance to the light point */
    murk_rgb le;   /* emitted radiance towards the shading point */
    float pdf;     /* solid-angle pdf, light selection included; 0 = no sample */
} murk_light_sample;

/* ---- Host services (the only way a plugin reaches the core) -------------------------------- */
enum { MURK_LOG_INFO = 0, MURK_LOG_WARN = 1 };

typedef struct murk_host {
    uint32_t size; /* sizeof(murk_host) of the core that filled it; check before using appended fields */
    uint32_t abi_major, abi_minor;
    void *(*alloc)(size_t n); /* zero-filled; NULL when out of memory */
    void (*free)(void *p);
    void (*log)(int level, const char *fmt, ...) MURK_PRINTF(2, 3);
    /* A texture's value at a hit, RGB (a float parameter reads out[0]). */
    void (*tex_eval)(const murk_texture *tex, const murk_hit *hit, float out[3]);
    /* Scene queries for integrators. intersect() returns 1 and fills *hit for the closest surface in
     * (ray.tmin, ray.tmax); occluded() returns 1 if any surface lies there (boundaries included). */
    int (*intersect)(const murk_scene *scene, const murk_ray *ray, murk_hit *hit);
    int (*occluded)(const murk_scene *scene, const murk_ray *ray);
    /* Pick an emissive shape (by power) and a point on it as seen from p; u are three uniforms. */
    int (*sample_light)(const murk_scene *scene, murk_vec3 p, const float u[3], murk_light_sample *ls);
    /* The solid-angle pdf with which sample_light(p) would have produced the emissive hit. */
    float (*light_pdf)(const murk_scene *scene, murk_vec3 p, const murk_hit *hit);
    murk_rgb (*background)(const murk_scene *scene, murk_vec3 dir);
    const murk_medium *(*camera_medium)(const murk_scene *scene);
    /* Media (murk/medium.h). density() is the field at a world point; walk_init/walk_next step
     * through the majorant grid along ray->o + t ray->d for t in [t0, t1] (see murk_majorant_walk). */
    float (*density)(const murk_density *d, murk_vec3 p);
    void (*walk_init)(const murk_density *d, const murk_ray *ray, float t0, float t1, murk_majorant_walk *w);
    int (*walk_next)(murk_majorant_walk *w, float *ta, float *tb, float *dmax, float *dmin);
    /* Logs a warning the first time this exact message is given in a run; later repeats are counted
     * and summarised at the end. Thread-safe. */
    void (*warn_once)(const char *fmt, ...) MURK_PRINTF(1, 2);
    /* Henyey-Greenstein phase function, wo and wi pointing away from the scattering point (forward
     * scattering, g > 0, favours wi = -wo). phase_eval is also the pdf of phase_sample. */
    float (*phase_eval)(float g, murk_vec3 wo, murk_vec3 wi);
    murk_vec3 (*phase_sample)(float g, murk_vec3 wo, const float u[2], float *pdf);
} murk_host;

/* A parameter's value at a hit: the texture if one was given, else the constant. */
static inline void murk_value_eval(const murk_host *host, const murk_value *v, const murk_hit *hit, float out[3])
{
    if (v->tex && hit) {
        host->tex_eval(v->tex, hit, out);
    } else {
        out[0] = (float)v->f[0];
        out[1] = (float)v->f[1];
        out[2] = (float)v->f[2];
    }
}

/* Radiance a hit emits towards direction wo (unit, pointing away from the surface): emitters are
 * one-sided, emitting on the +ng side only. */
static inline murk_rgb murk_hit_le(const murk_hit *hit, murk_vec3 wo)
{
    return murk_dot(hit->ng, wo) > 0.0f ? hit->emission : murk_rgb1(0.0f);
}

/* ---- Descriptor ---------------------------------------------------------------------------- */
typedef int (*murk_create_fn)(const murk_host *host, const murk_value *params, void **self,
                              char *err, size_t errlen);

typedef struct murk_plugin_desc {
    uint32_t struct_size; /* sizeof(murk_plugin_desc) */
    uint32_t kind;        /* murk_kind */
    const char *name;     /* the scene's `type:`; equals the file's basename */
    const char *description;
    const murk_param *params;
    uint32_t nparams;
    const void *vtable;   /* murk_material_vt / murk_medium_vt / murk_integrator_vt */
} murk_plugin_desc;

#define MURK_PLUGIN_ENTRY_SYMBOL "murk_plugin_entry"
#define MURK_PLUGIN_ABI_SYMBOL "murk_plugin_abi"

/* Declares the two exported symbols; use once per plugin: MURK_PLUGIN(&my_descriptor); */
#define MURK_PLUGIN(desc_ptr)                                                            \
    MURK_EXPORT const murk_abi murk_plugin_abi = {MURK_ABI_MAJOR, MURK_ABI_MINOR};       \
    MURK_EXPORT const murk_plugin_desc *murk_plugin_entry(void);                         \
    const murk_plugin_desc *murk_plugin_entry(void) { return (desc_ptr); }

#endif
