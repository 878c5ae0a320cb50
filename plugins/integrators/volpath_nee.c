/* volpath_nee — volumetric path tracing with next-event estimation at surface and medium vertices: a
 * light sample per vertex with each medium's transmittance estimate through media and boundaries,
 * combined with BSDF / phase sampling by the power heuristic (Veach 1995); optionally equiangular
 * distance sampling towards the lights (Kulla and Fajardo 2012, "Importance sampling techniques for path
 * tracing in participating media"). Works with every tracker: the shared tracer of pathtracer.h
 * (pathtracer.c), which says how media, boundaries and spectral MIS weights are handled. Parameters:
 * `murk plugins volpath_nee`. */
#include "pathtracer.h"

static int create(const murk_host *host, const murk_value *params, void **self, char *err, size_t errlen)
{
    return murk_pt_create(host, params, 1, 1, self, err, errlen);
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, create, murk_pt_destroy,
                                      murk_pt_li};

MURK_INTEGRATOR_PLUGIN("volpath_nee",
                       "volumetric path tracing: NEE through media + BSDF/phase sampling with MIS; optional "
                       "equiangular sampling",
                       murk_pt_nee_params, MURK_PT_NEE_NPARAMS, &vt)
