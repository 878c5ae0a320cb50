/* residual_ratio — residual ratio tracking (Novak, Selle, Jarosz 2014) with the core's minorant grid as
 * the control.
 *
 * Parameters
 *   control  float in [0, 10], default 1. The control density of a majorant-grid cell is control x the
 *            cell's minimum density (the minorant grid). Its optical depth is taken in closed form,
 *            exp(-c sigma_t,c L) per cell and channel; only the residual density(x) - c is ratio-tracked,
 *            against the residual majorant |max density - c|. In [0, 1] the control never exceeds the
 *            density; above 1 the residual goes negative where the control does not bound, the
 *            ratio-tracking factors 1 - residual sigma / mu exceed 1 and the estimate stays unbiased
 *            (noisier; murk says so at load). 0 is plain ratio tracking.
 *
 * The same computation as decomposition tracking's transmittance() (murk_ratio_tracking with a control,
 * murk/tracking.h), with Russian roulette on small transmittance. In cells of constant density with an
 * exact minorant the residual is 0: those cells cost no lookups and add no variance. Unbiased per
 * channel for any hero: the control and the collisions are shared, each channel weighted by its own
 * extinction. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_CONTROL, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CONTROL] = {"control", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 10,
                   "control density as a multiple of each majorant cell's minimum density (<= 1 stays below it)"},
};

typedef struct residual {
    murk_tracker base;
    float control;
} residual;

static int residual_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                           char *err, size_t errlen)
{
    residual *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->control = (float)p[P_CONTROL].f[0];
    if (m->control > 1.0f)
        host->log(MURK_LOG_WARN,
                  "medium '%s': residual_ratio control %g > 1 can exceed the local density (negative residual): "
                  "ratio-tracking weights above 1 (unbiased, noisier)", data->name, m->control);
    *self = m;
    return 0;
}

static murk_rgb residual_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const residual *m = self;
    return murk_ratio_tracking(m->base.host, m->base.d, ray, m->control, rng);
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, residual_create,
                                         murk_tracker_free, residual_estimate};

MURK_TRANSMITTANCE_PLUGIN("residual_ratio",
                          "residual ratio tracking (Novak et al. 2014): minorant control in closed form + ratio-tracked residual",
                          params, P_COUNT, &vt)
