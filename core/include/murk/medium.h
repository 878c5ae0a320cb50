/* murk/medium.h — the participating-medium (free-flight tracker) plugin interface.
 *
 * The core owns a medium's data — density field, sigma_a, sigma_s, phase function, majorant and
 * minorant grids — and hands a tracker plugin a murk_medium_data at create(); the plugin owns only its
 * method (delta, decomposition, spectral, ...) and its own parameters.
 *
 * sample() tracks a free flight along ray->d over (ray->tmin, ray->tmax) and reports either a real
 * scattering event at ev->t or that the flight left the segment. It returns its result as two RGB
 * factors that the integrator multiplies into the path: ev->weight (the contribution f, per channel)
 * and ev->pdf (per-channel path-pdf ratios used by spectral MIS; (1,1,1) for every other tracker). An
 * integrator computes a path's value as  prod(weight) * L / mean_c(prod(pdf)_c) , which reduces to the
 * usual throughput when pdf is 1. Trackers are unbiased for any bounding majorant: the expected value of
 * every estimate must not depend on the tracker, the majorant or the tracker's own parameters.
 * transmittance() returns an unbiased per-channel estimate of exp(-int sigma_t) along the segment
 * (ratio tracking or similar), used on shadow rays. */
#ifndef MURK_MEDIUM_H
#define MURK_MEDIUM_H

#include "murk/plugin.h"

typedef struct murk_density murk_density; /* opaque: a density field with its majorant/minorant grid */

/* What the core gives every tracker at create() (passed to create()). */
typedef struct murk_medium_data {
    uint32_t size;
    murk_rgb sigma_a, sigma_s;    /* per unit density, scene `scale` already applied */
    float g;                      /* Henyey-Greenstein asymmetry of the phase function */
    float majorant_factor;        /* multiplies the majorant grid (>= 1 keeps it bounding) */
    const murk_density *density;
    const char *name;             /* the medium's name in the scene, for messages */
} murk_medium_data;

/* A walk over the majorant grid along a ray: consecutive segments [ta, tb) with the maximum and
 * minimum density over each (already multiplied by majorant_factor for the maximum). Opaque storage. */
typedef struct murk_dda { uint64_t opaque[24]; } murk_dda;

typedef struct murk_medium_event {
    int scattered;   /* 1: a real scattering event at t; 0: the flight passed tmax */
    float t;
    murk_rgb weight; /* multiply into the path's contribution */
    murk_rgb pdf;    /* multiply into the path's per-channel pdf ratios (spectral MIS), else (1,1,1) */
} murk_medium_event;

/* Per-path state an integrator passes to trackers (spectral MIS's hero channel). */
typedef struct murk_path_ctx {
    int hero; /* channel 0..2 this path samples with (spectral_mis); others may ignore it */
} murk_path_ctx;

typedef struct murk_medium_vt {
    uint32_t size; /* sizeof(murk_medium_vt) of the plugin */
    /* create() gets its own parameters in `params`; the core's data for the medium in `data`. */
    int (*create)(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                  char *err, size_t errlen);
    void (*destroy)(void *self);
    int (*sample)(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                  murk_medium_event *ev);
    murk_rgb (*transmittance)(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng);
} murk_medium_vt;

/* A medium as the scene holds it. */
struct murk_medium {
    const murk_medium_vt *vt;
    void *self;
    const char *name;
    const murk_medium_data *data;
};

#endif
