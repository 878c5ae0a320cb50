/* murk/plugin.h — the plugin ABI: version, descriptor, parameter schema, host services.
 *
 * A plugin is a shared object that exports exactly two symbols, both made by one of the typed macros
 * of the kinds' headers (MURK_MATERIAL_PLUGIN, MURK_MEDIUM_PLUGIN, MURK_INTEGRATOR_PLUGIN,
 * MURK_TRANSMITTANCE_PLUGIN):
 *
 *     MURK_EXPORT const murk_abi murk_plugin_abi = { MURK_ABI_MAJOR, MURK_ABI_MINOR };
 *     MURK_EXPORT const murk_plugin_desc *murk_plugin_entry(void);
 *
 * Loading. The host reads `murk_plugin_abi` (a data symbol) from the file before it runs any plugin
 * code: the major must equal the host's and the minor must not exceed it. Then it dlopen()s the file
 * (RTLD_NOW | RTLD_LOCAL), calls murk_plugin_entry() once and checks the descriptor: struct_size at
 * least the ABI 1.0 size, a known kind, name == the file's basename, a vtable whose kind field equals
 * the descriptor's kind and whose size is at least the kind's ABI 1.0 size, and a well-formed
 * parameter schema. Plugins never link libmurk: everything they need from the core arrives as the
 * murk_host table passed to create().
 *
 * Versioning (SQLite's iVersion pattern). Every struct that crosses the boundary starts with its size
 * and only ever grows at the end. A minor version may append fields to structs and methods to
 * vtables and the host table; it never moves, removes or changes the meaning of anything. So a plugin
 * built against ABI 1.m loads in every host 1.n with n >= m: the host reads a descriptor's or
 * vtable's size before touching a field appended after 1.0 (MURK_HAS), and a plugin reads
 * host->size before calling a host service appended after 1.0.
 * History: 1.0 the first stable ABI; 1.1 appends murk_plugin_desc.version; 1.2 adds the transmittance
 * kind and murk_medium's estimator fields; 1.3 appends murk_bsdf_sample.eta and lets materials transmit
 * (the hit a material gets has n on wo's side, murk/material.h); 1.4 appends murk_host.counters (the
 * cost counters, murk/counters.h), the sampler to murk_rng (murk_sample_1d/2d, murk/math.h) and the
 * host's sample_light_with / light_pdf_with; 1.5 appends murk_medium_data.stratify_flights (murk/medium.h);
 * 1.6 appends murk_host.boundaries; 1.7 appends the material's prepare() and prepared eval/pdf/sample
 * (textures read once per vertex, murk/material.h).
 * 1.8 (MURK_ABI_MINOR_LIGHTS) lets a light sample be at infinity
 * (dist = INFINITY) or of a delta light (murk_light_sample.flags, appended), and appends
 * murk_host.environment_pdf: escaped rays are MIS-weighted against the environment's light sampling.
 * 1.9 (MURK_ABI_MINOR_FIELDS) adds the phase-function kind (murk/phase.h),
 * murk_host's medium_phase_eval / medium_phase_sample / albedo / emission, murk_medium_data's fields and
 * integrator_minor, murk_medium_event's emitted and null_prob, murk_path_ctx's pdf_ratio and flags
 * (murk/medium.h: albedo and emission fields, volume emission).
 * Anything else — a changed signature,
 * a removed or reordered field — bumps the major, and the host refuses plugins of another major.
 *
 * Contracts common to every kind:
 *   create()  returns 0 and sets *self on success; on failure it returns non-zero, writes one line
 *             (no file or position: the core adds `scene.yaml:LINE:COL: medium 'smoke': ` before it)
 *             into err and leaves nothing allocated. It is called on the main thread.
 *   params    an array in schema order (murk_value); it, its strings and its texture pointers stay
 *             valid until destroy() returns, so an instance may keep pointers into it.
 *   host      the murk_host table is static: valid for the whole process.
 *   destroy() frees what create() made; called once, on the main thread, after all rendering.
 *   Methods other than create()/destroy() are called from every render thread at once with the same
 *   self: they must not modify the instance (keep per-call state on the stack).
 *   Rays: ray->d is unit length; ray->tmax may be INFINITY (an open ray that leaves the scene).
 *   Watchdog: one call of a per-sample method (a tracker's sample() or transmittance(), an estimator's
 *             transmittance(), an integrator's li()) runs at most MURK_WATCHDOG_ITERATIONS iterations
 *             of any loop (collisions, majorant cells, bounces, boundary crossings). A loop must also
 *             provably advance: a distance step that does not change a float t moves it to the next
 *             float. A call that reaches the cap ends its path (weight 0, or transmittance 0), and
 *             reports it with host->warn_once naming the plugin ("tracker 'delta' (medium 'smoke'):
 *             ..."), which counts every repeat and prints the total at the end of the run — a render
 *             that would hang finishes, biased where the cap was hit, and says so. */
#ifndef MURK_PLUGIN_H
#define MURK_PLUGIN_H

#include <stddef.h>
#include <stdint.h>
#include "murk/counters.h"
#include "murk/math.h"

#define MURK_ABI_MAJOR 1
#define MURK_ABI_MINOR 9
/* The minor that brought infinite and delta light samples: an integrator built before it never gets one
 * (the core keeps such lights out of its light sampling and refuses a scene with delta lights for it). */
#define MURK_ABI_MINOR_LIGHTS 8
/* The minor that appended phase-function plugins and medium fields (the history below): plugins and the
 * core compare another plugin's minor with it, never with a number. */
#define MURK_ABI_MINOR_FIELDS 9

/* The iteration cap of the watchdog contract above (2^24): far above what a valid scene needs — murk
 * refuses media whose optical depth exceeds 1e6 — and small enough that a stuck call ends in well
 * under a second. */
#define MURK_WATCHDOG_ITERATIONS 16777216L

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
    MURK_KIND_INTEGRATOR = 3,
    MURK_KIND_TRANSMITTANCE = 4, /* ABI 1.2: transmittance estimators (murk/transmittance.h) */
    MURK_KIND_PHASE = 5          /* ABI 1.9: phase functions (murk/phase.h) */
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
/* Another scale of the parameter just before it in the schema (ggx's alpha beside roughness, alpha =
 * roughness^2): a scene gives one or the other. The loader refuses both, located at the second key;
 * murk check gives each in turn. A host that predates the flag ignores it (create() should refuse both). */
#define MURK_PARAM_ALT_SCALE 4u
/* Values away from the default exist for study, not for use: where the method's assumption fails
 * (residual_ratio's control far above the density) or one pass of several (naive_spectral's fixed
 * channel). murk check's sweep keeps the parameter at its default; `murk check --set` still takes any
 * value. A host that predates the flag ignores it. */
#define MURK_PARAM_NO_SWEEP 8u

typedef struct murk_param {
    const char *name;
    uint32_t type;    /* murk_param_type */
    uint32_t flags;   /* MURK_PARAM_* */
    double def[3];    /* default for FLOAT/INT/BOOL (def[0]) and RGB */
    const char *def_str; /* default for STRING and ENUM */
    const char *choices; /* ENUM only: "max|average|history" */
    double min, max;  /* inclusive range for numbers and every RGB component */
    const char *doc;  /* the parameter's description, one paragraph without line breaks (any length:
                       * `murk plugins NAME` wraps it; `--markdown` puts it in a table cell) */
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
    murk_vec3 n;      /* unit shading normal, same side as ng (in the hit a material gets: on wo's side) */
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
    float dist;    /* distance to the light point; INFINITY (ABI 1.8) for a light at infinity (a distant
                    * light, the environment): the shadow ray runs to infinity along wi */
    murk_rgb le;   /* emitted radiance towards the shading point (a delta light: its irradiance there) */
    float pdf;     /* solid-angle pdf, light selection included; 0 = no sample (a delta light: the
                    * probability of choosing it) */
    /* ABI 1.8: MURK_LIGHT_SAMPLE_* bits. The host writes it only for integrators of ABI >= 1.8 (older
     * ones never get a delta or infinite sample): an integrator sets it to 0 before asking. */
    uint32_t flags;
} murk_light_sample;

/* murk_light_sample.flags (ABI 1.8). DELTA: a point, spot or delta distant light, which no BSDF or
 * phase sample can hit: f le T / pdf counts with MIS weight 1. */
#define MURK_LIGHT_SAMPLE_DELTA 1u
/* The size of murk_light_sample before ABI 1.8, of 1.0 to 1.7 (what an older integrator's stack holds; the
 * name is older than the minor's number, which became 1.8 when 1.7 went to prepared materials). */
#define MURK_LIGHT_SAMPLE_SIZE_1_6 (offsetof(murk_light_sample, pdf) + sizeof(float))

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
    /* Pick a light (by power: emissive shapes and, for integrators of ABI >= 1.8, the scene's `lights:`)
     * and a point on it as seen from p; u are three uniforms. */
    int (*sample_light)(const murk_scene *scene, murk_vec3 p, const float u[3], murk_light_sample *ls);
    /* The solid-angle pdf with which sample_light(p) would have produced the emissive hit. */
    float (*light_pdf)(const murk_scene *scene, murk_vec3 p, const murk_hit *hit);
    /* The radiance of the environment towards -dir (what a ray leaving the scene along dir sees). */
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
    /* ABI 1.4: the calling thread's cost counters for the medium whose density field is d
     * (murk/counters.h); never NULL. Call it once per flight, not per collision. */
    murk_counters *(*counters)(const murk_density *d);
    /* ABI 1.4: sample_light / light_pdf with a strategy (MURK_LIGHT_*). sample_light and light_pdf
     * are MURK_LIGHT_AREA. */
    int (*sample_light_with)(const murk_scene *scene, murk_vec3 p, const float u[3], int strategy,
                             murk_light_sample *ls);
    float (*light_pdf_with)(const murk_scene *scene, murk_vec3 p, const murk_hit *hit, int strategy);
    /* ABI 1.6: how many index-matched boundaries (shapes without a material) the scene has. With none,
     * every surface occluded() can find has a material: a shadow ray it reports blocked is blocked,
     * with no intersect() to tell a boundary from an occluder. */
    size_t (*boundaries)(const murk_scene *scene);
    /* ABI 1.8: the solid-angle pdf with which sample_light_with would have sampled direction dir of the
     * environment (background(), which holds the whole environment: the constant background, environment
     * maps, the sky, finite-cone distant lights). 0 where no part of it is sampled (a scene with only a
     * constant background: escaped rays count fully, as before). An escaped ray after a BSDF / phase
     * sample of pdf p adds background(dir) x power_heuristic(p, environment_pdf(dir)). */
    float (*environment_pdf)(const murk_scene *scene, murk_vec3 dir);
    /* ABI 1.9: medium m's phase function (its `phase:` block, else Henyey-Greenstein of its g;
     * murk/phase.h). medium_phase_eval is p(wo, wi) and the pdf of medium_phase_sample, which draws wi
     * from the uniforms u, sets *pdf and returns the value p(wo, wi) (0: no sample). */
    float (*medium_phase_eval)(const murk_medium *m, murk_vec3 wo, murk_vec3 wi);
    float (*medium_phase_sample)(const murk_medium *m, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf);
    /* ABI 1.9: a medium's fields beside its density at a world point (murk/medium.h: which a medium has is
     * murk_medium_data.fields): the single-scattering albedo per channel, and the radiance Le emitted per
     * unit absorption (the medium emits sigma_a(p) Le(p) per unit length). Each is one lookup, counted
     * like a density lookup. */
    murk_rgb (*albedo)(const murk_density *d, murk_vec3 p);
    murk_rgb (*emission)(const murk_density *d, murk_vec3 p);
} murk_host;

/* Light sampling strategies (ABI 1.4). AREA: a triangle uniformly by area (a rectangular quad or box
 * face, two triangles, as the whole rectangle: the same density), a sphere uniformly in its cone. SOLID_ANGLE: a rectangular quad or box face uniformly in the
 * solid angle it subtends (spherical rectangles, Urena et al. 2013) where that solid angle is at least
 * 1e-4 sr (smaller: by area), the rest as AREA. Both choose the light by power. */
enum { MURK_LIGHT_AREA = 0, MURK_LIGHT_SOLID_ANGLE = 1 };

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
    uint32_t struct_size; /* sizeof(murk_plugin_desc) of the plugin's headers */
    uint32_t kind;        /* murk_kind */
    const char *name;     /* the scene's `type:`; equals the file's basename */
    const char *description; /* one line, shown by `murk plugins` */
    const murk_param *params;
    uint32_t nparams;
    const void *vtable;   /* murk_material_vt / murk_medium_vt / murk_integrator_vt / murk_transmittance_vt */
    /* ABI 1.1 */
    const char *version;  /* the plugin's own version ("2.3.0"), NULL if none: shown by `murk plugins`
                           * and recorded in every image it renders */
} murk_plugin_desc;

/* Every vtable starts with these two fields. */
typedef struct murk_vt_head {
    uint32_t size; /* sizeof(the vtable) in the plugin's headers */
    uint32_t kind; /* murk_kind: must equal the descriptor's */
} murk_vt_head;

/* 1 if a struct of `size` bytes (its size field: desc->struct_size, vt->size, host->size) is large
 * enough to hold `member`, i.e. the other side was built with a version that has it. */
#define MURK_HAS(size, type, member) \
    ((size_t)(size) >= offsetof(type, member) + sizeof(((const type *)0)->member))
#define MURK_PLUGIN_DESC_SIZE_1_0 (offsetof(murk_plugin_desc, vtable) + sizeof(const void *))

#define MURK_PLUGIN_ENTRY_SYMBOL "murk_plugin_entry"
#define MURK_PLUGIN_ABI_SYMBOL "murk_plugin_abi"

/* The two exported symbols for a descriptor; the typed macros below use it. */
#define MURK_PLUGIN(desc_ptr)                                                            \
    MURK_EXPORT const murk_abi murk_plugin_abi = {MURK_ABI_MAJOR, MURK_ABI_MINOR};       \
    MURK_EXPORT const murk_plugin_desc *murk_plugin_entry(void);                         \
    const murk_plugin_desc *murk_plugin_entry(void) { return (desc_ptr); }

/* Declares a plugin of one kind, once per plugin file, e.g.
 *     static const murk_medium_vt vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, create, destroy, ...};
 *     MURK_MEDIUM_PLUGIN("mytracker", "one-line description", params, NPARAMS, &vt)
 * The vtable's type is checked at compile time (a material vtable under MURK_MEDIUM_PLUGIN does not
 * compile). params may be NULL with nparams 0. The kind's header (murk/material.h, murk/medium.h,
 * murk/integrator.h or murk/transmittance.h) defines the macro. */
#ifndef MURK_PLUGIN_VERSION
#define MURK_PLUGIN_VERSION NULL /* define it (e.g. -DMURK_PLUGIN_VERSION='"1.2.0"') to version a plugin */
#endif
#define MURK_DEFINE_PLUGIN_(KIND, NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                                      \
    static const murk_plugin_desc murk_plugin_desc_ = {sizeof(murk_plugin_desc), (KIND), (NAME), (DESCRIPTION), \
                                                       (PARAMS), (NPARAMS), (VT), MURK_PLUGIN_VERSION};         \
    MURK_PLUGIN(&murk_plugin_desc_)

#endif
