/* volpath_nee — volumetric path tracing with next-event estimation at surface and medium vertices:
 * a light sample per vertex with ratio-tracking transmittance through media and boundaries, combined
 * with BSDF / phase sampling by the power heuristic.
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
    return volpath_li_impl(self, scene, ray, rng, 1, 1);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), volpath_create, volpath_destroy, li};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_INTEGRATOR, "volpath_nee",
    "volumetric path tracing, NEE with ratio-tracking transmittance + BSDF/phase sampling, MIS", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
