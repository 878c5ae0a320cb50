/* path — unidirectional surface path tracing with next-event estimation.
 *
 * Parameters
 *   max_depth  int in [1, 100000], default 64: the most bounces a path may take (1 = direct light only).
 *   rr_depth   int in [0, 100000], default 3: bounces before Russian roulette may end a path; the
 *              survival probability is min(1, max throughput channel), at least 0.05, and survivors are
 *              divided by it, so roulette adds noise but no bias.
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
 * At every surface it samples one light point (host->sample_light) and one BSDF direction, and weights
 * both with the power heuristic (Veach 1995); emission found by a delta BSDF sample or by the camera ray
 * is taken with weight 1. The constant background is reached by BSDF sampling only (it is not a light
 * that NEE samples). Shadow rays pass through index-matched medium boundaries but stop at any surface
 * with a material. This integrator ignores media (use volpath or volpath_nee for them): it is the
 * shared tracer of pathtracer.h (pathtracer.c) with media switched off. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 1, 0, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("path", "surface path tracing, NEE + BSDF sampling with MIS, Russian roulette",
                       murk_pt_params, MURK_PT_NPARAMS, &vt)
