/* ratio — ratio tracking (Novak, Selle, Jarosz 2014) with the core's majorant grid.
 *
 * Parameters: none of its own.
 *
 * Tentative collisions are drawn cell by cell along the ray with rate mu = (the cell's maximum density)
 * x (the largest channel of sigma_t); each multiplies channel c's estimate by 1 - sigma_t,c(x) / mu.
 * Unbiased for any mu > 0: where the density exceeds the majorant (majorant_factor < 1) the factor goes
 * negative and the estimate stays unbiased (the core warns at load). Russian roulette on small
 * transmittance (survival probability = the largest channel, once below 0.1) keeps dense shadow rays
 * short without bias. Every channel shares the collisions and is weighted by its own extinction, so the
 * estimate is unbiased per channel for any hero (murk/transmittance.h). This is what every tracker's
 * own transmittance() does without a control (murk_ratio_tracking in murk/tracking.h). */
#include "murk/transmittance.h"
#include "murk/tracking.h"

static int ratio_create(const murk_host *host, const murk_medium_data *data, const murk_value *params, void **self,
                        char *err, size_t errlen)
{
    (void)params;
    return (*self = murk_tracker_new(host, data, sizeof(murk_tracker), err, errlen)) ? 0 : -1;
}

static murk_rgb ratio_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const murk_tracker *m = self;
    return murk_ratio_tracking(m->host, m->d, ray, 0.0f, rng);
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, ratio_create,
                                         murk_tracker_free, ratio_estimate};

MURK_TRANSMITTANCE_PLUGIN("ratio", "ratio tracking (Novak et al. 2014) against the majorant grid", NULL, 0, &vt)
