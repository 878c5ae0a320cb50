/* residual_ratio — residual ratio tracking (Novák, Selle, Jarosz 2014, "Residual ratio tracking for
 * estimating attenuation in participating media") with the core's minorant grid as the control: the
 * control's optical depth in closed form, the residual ratio-tracked. The same computation as a tracker's
 * own transmittance() (murk_ratio_tracking with a control, murk/tracking.h). Parameters: `murk plugins
 * residual_ratio`; details: docs/trackers.md#residual_ratio. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_CONTROL, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CONTROL] = {"control", MURK_PARAM_FLOAT, MURK_PARAM_NO_SWEEP, {1, 0, 0}, NULL, NULL, 0, 10,
                   "the control density of a majorant cell as a multiple of the cell's minimum density (the "
                   "minorant grid); its optical depth is taken in closed form, exp(-c sigma_t L) per cell and "
                   "channel, and only the residual density - c is ratio-tracked, against the residual majorant "
                   "|max density - c|. In [0, 1] the control never exceeds the density; above 1 the residual goes "
                   "negative where the control does not bound, and the estimate stays unbiased but noisier (murk "
                   "says so at load). 0 is plain ratio tracking"},
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
                          "residual ratio tracking (Novak et al. 2014): minorant control in closed form + "
                          "ratio-tracked residual",
                          params, P_COUNT, &vt)
