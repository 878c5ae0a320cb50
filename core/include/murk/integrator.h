/* murk/integrator.h — the integrator plugin interface.
 *
 * The core generates camera rays, one random stream per (seed, pixel, sample), and asks li() for the
 * radiance along each. li() must be reentrant: it is called from every render thread at once with the
 * same `self`. Everything it needs from the scene comes through the murk_host it got in create(). */
#ifndef MURK_INTEGRATOR_H
#define MURK_INTEGRATOR_H

#include "murk/plugin.h"

typedef struct murk_integrator_vt {
    uint32_t size; /* sizeof(murk_integrator_vt) of the plugin */
    murk_create_fn create;
    void (*destroy)(void *self);
    murk_rgb (*li)(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng);
} murk_integrator_vt;

#endif
