/* volpath — volumetric path tracing with BSDF / phase-function sampling only (no next-event
 * estimation): emission counts only where a sampled direction reaches it. Slower to converge than
 * volpath_nee, and an independent estimator of the same image, which is what tests compare. Works with
 * every tracker: the shared tracer of pathtracer.h (pathtracer.c), which says how media, boundaries and
 * spectral MIS weights are handled. Parameters: `murk plugins volpath`. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 0, 1, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("volpath",
                       "volumetric path tracing, BSDF/phase sampling only (no NEE): an independent estimator",
                       murk_pt_params, MURK_PT_NPARAMS, &vt)
