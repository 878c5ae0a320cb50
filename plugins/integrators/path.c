/* path — unidirectional surface path tracing: at every surface one light sample (next-event estimation)
 * and one BSDF sample, combined by the power heuristic (Veach 1995, "Optimally combining sampling
 * techniques for Monte Carlo rendering"), and Russian roulette. Emission found by a delta BSDF sample or
 * by the camera ray counts with weight 1; the constant background is reached by BSDF sampling only (NEE
 * does not sample it). Media are ignored (volpath and volpath_nee track them): this is the shared tracer
 * of pathtracer.h (pathtracer.c) with media switched off. Parameters: `murk plugins path`. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 1, 0, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("path",
                       "surface path tracing: NEE + BSDF sampling with MIS (power heuristic), Russian roulette; "
                       "ignores media",
                       murk_pt_params, MURK_PT_NPARAMS, &vt)
