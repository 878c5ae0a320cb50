/* volpath — volumetric path tracing with BSDF / phase-function sampling only (no next-event
 * estimation): emission is found only when a sampled direction reaches it. Slower to converge than
 * volpath_nee, and an independent estimator of the same image, which is what tests compare.
 *
 * Parameters
 *   max_depth  int in [1, 100000], default 64: most scattering events (surface or medium) per path.
 *   rr_depth   int in [0, 100000], default 3: events before Russian roulette may end a path.
 *   light_sampling  area | solid_angle, default area: how next-event estimation picks a point on a
 *              light: every emitting triangle (a rectangular quad or box face: its rectangle) uniformly
 *              by area, or a rectangular quad or box face uniformly in the solid angle it subtends
 *              (Urena et al. 2013; tiny ones and other shapes by area). solid_angle is far less noisy for points close to a light, but costs more per
 *              sample: at equal time it is at best even with area (docs/results.md), so area is
 *              the default; both render the same image (tests/test_lights.c).
 *   rr_threshold  float in [0.001, 1], default 1: Russian roulette keeps a path with probability
 *              min(1, weight / rr_threshold) (at least 0.05): 1 plays with every path whose weight fell
 *              below 1, 0.1 only with the paths below a tenth (longer paths, less noise per sample, no
 *              better per second: docs/results.md).
 *
 * Works with every tracker; see pathtracer.h (pathtracer.c) for how media, boundaries and spectral MIS weights
 * are handled. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 0, 1, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("volpath", "volumetric path tracing, BSDF/phase sampling only (no NEE)",
                       murk_pt_params, MURK_PT_NPARAMS, &vt)
