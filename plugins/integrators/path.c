/* path — unidirectional surface path tracing with next-event estimation.
 *
 * Parameters
 *   max_depth  int in [1, 100000], default 64: the most bounces a path may take (1 = direct light only).
 *   rr_depth   int in [0, 100000], default 3: bounces before Russian roulette may end a path; the
 *              survival probability is min(1, max throughput channel), at least 0.05, and survivors are
 *              divided by it, so roulette adds noise but no bias.
 *
 * At every surface it samples one light point (host->sample_light) and one BSDF direction, and weights
 * both with the power heuristic (Veach 1995); emission found by a delta BSDF sample or by the camera ray
 * is taken with weight 1. The constant background is reached by BSDF sampling only (it is not a light
 * that NEE samples). Shadow rays pass through index-matched medium boundaries but stop at any surface
 * with a material. This integrator ignores media (use volpath or volpath_nee for them): it is the
 * shared tracer of volpath_common.h with media switched off. */
#include <stdio.h>

#include "volpath_common.h"

static murk_rgb li(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng)
{
    return volpath_li_impl(self, scene, ray, rng, 1, 0);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), volpath_create, volpath_destroy, li};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_INTEGRATOR, "path",
    "surface path tracing, NEE + BSDF sampling with MIS, Russian roulette", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
