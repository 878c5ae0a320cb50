/* murk/integrator.h — the integrator plugin interface.
 *
 * The core generates camera rays, one random stream per (seed, pixel, sample), and asks li() for the
 * radiance along each. li() must be reentrant: it is called from every render thread at once with the
 * same `self`. Everything it needs from the scene comes through the murk_host it got in create().
 * li() returns the radiance estimate of one sample (finite; a NaN or infinite sample is dropped from
 * its pixel, counted and reported with the integrator's name). The rng is the sample's own stream:
 * draw as many numbers from it as needed, in a deterministic order, so that an image depends only on
 * (scene, seed, spp). Materials and media are called through their vtables (murk/material.h,
 * murk/medium.h); a medium's sample() and transmittance() take rays whose tmax may be INFINITY.
 * Watchdog (murk/plugin.h): one li() call runs at most MURK_WATCHDOG_ITERATIONS iterations of any of
 * its loops (bounces, boundary crossings, shadow-ray segments); at the cap it returns what it has
 * gathered so far (or 0) and reports it with host->warn_once naming the integrator. */
#ifndef MURK_INTEGRATOR_H
#define MURK_INTEGRATOR_H

#include "murk/plugin.h"

typedef struct murk_integrator_vt {
    uint32_t size; /* sizeof(murk_integrator_vt) of the plugin */
    uint32_t kind; /* MURK_KIND_INTEGRATOR */
    murk_create_fn create;
    void (*destroy)(void *self);
    murk_rgb (*li)(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng);
} murk_integrator_vt;

#define MURK_INTEGRATOR_VT_SIZE_1_0 (offsetof(murk_integrator_vt, li) + sizeof(void (*)(void)))
#define MURK_INTEGRATOR_PLUGIN(NAME, DESCRIPTION, PARAMS, NPARAMS, VT)                             \
    MURK_DEFINE_PLUGIN_(MURK_KIND_INTEGRATOR, NAME, DESCRIPTION, PARAMS, NPARAMS,                  \
                        _Generic((VT), const murk_integrator_vt *: (VT), murk_integrator_vt *: (VT)))

#endif
