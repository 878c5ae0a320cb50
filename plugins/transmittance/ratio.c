/* ratio — ratio tracking (Novák, Selle, Jarosz 2014, "Residual ratio tracking for estimating attenuation
 * in participating media") against the core's majorant grid: every tentative collision multiplies each
 * channel's estimate by its null-collision fraction, with Russian roulette on small transmittance. What
 * every tracker's own transmittance() does without a control (murk_ratio_tracking, murk/tracking.h). No
 * parameters of its own; details: docs/trackers.md#ratio. */
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
