/* volpath_nee — volumetric path tracing with next-event estimation at surface and medium vertices:
 * a light sample per vertex with each medium's transmittance estimate through media and boundaries, combined
 * with BSDF / phase sampling by the power heuristic.
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
 *   equiangular  bool, default false: also sample each medium segment equiangularly (Kulla and
 *              Fajardo 2012) towards a reference point on a light, and combine that vertex's NEE with
 *              the free flight's by MIS (balance heuristic; a per-segment exponential stands in for the
 *              free flight's pdf, exact in a grey homogeneous medium, an approximation elsewhere: the
 *              image is the same either way, only the noise differs). Free flights are untouched. Pays
 *              off where single scattering of a light dominates and free flights rarely scatter near it
 *              (a lamp in or by a thin medium: 3.2x efficiency in docs/results.md); costs 1.5-1.7x per
 *              sample for ~0.63x the relMSE in an optically thin-to-moderate box (even), and does not
 *              pay in a dense cloud (0.64x): so it is off by default.
 *
 * Works with every tracker; see pathtracer.h (pathtracer.c) for how media, boundaries and spectral MIS weights
 * are handled. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 1, 1, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("volpath_nee", "volumetric path tracing, NEE through media + BSDF/phase sampling, MIS",
                       murk_pt_nee_params, MURK_PT_NEE_NPARAMS, &vt)
