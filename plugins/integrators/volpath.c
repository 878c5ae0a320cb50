/* volpath — volumetric path tracing with BSDF / phase-function sampling only (no next-event
 * estimation): emission is found only when a sampled direction reaches it. Slower to converge than
 * volpath_nee, and an independent estimator of the same image, which is what tests compare.
 *
 * Parameters
 *   max_depth  int in [1, 100000], default 64: most scattering events (surface or medium) per path.
 *   rr_depth   int in [0, 100000], default 3: events before Russian roulette may end a path.
 *
 * Works with every tracker; see volpath_common.h for how media, boundaries and spectral MIS weights
 * are handled. */
#include <stdio.h>

#include "volpath_common.h"

static murk_rgb li(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng)
{
    return volpath_li_impl(self, scene, ray, rng, 0, 1);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), volpath_create, volpath_destroy, li};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_INTEGRATOR, "volpath",
    "volumetric path tracing, BSDF/phase sampling only (no NEE)", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
