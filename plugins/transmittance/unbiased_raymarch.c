/* unbiased_raymarch — unbiased ray marching after Kettunen, d'Eon, Pantaleoni, Novák 2021 ("An unbiased
 * ray-marching transmittance estimator"): a jittered ray-marched control optical depth, corrected by a
 * power series whose terms are products of independent ray-marched estimates, with aggressive Russian
 * roulette. Unbiased per channel (an estimate may be negative, by design); zero variance where the
 * extinction is constant. Parameters: `murk plugins unbiased_raymarch`; the estimator and how it differs
 * from the paper's: docs/trackers.md#unbiased_raymarch. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_DEPTH_STEP, P_ORDER, P_ROULETTE, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_DEPTH_STEP] = {"depth_step", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0.05, 16,
                      "the majorant optical depth of a ray-march step: a majorant cell crossed over length L with "
                      "maximum density dmax gets ceil(dmax max_c sigma_t,c L / depth_step) equal steps (at least "
                      "one; cells with dmax 0 none). Smaller: more lookups per march, a better control and "
                      "smaller corrections"},
    [P_ORDER] = {"order", MURK_PARAM_INT, 0, {1, 0, 0}, NULL, NULL, 1, 16,
                 "the correction terms always evaluated; term k > order is evaluated with probability min(1, "
                 "max_c sigma_t,c |X_{k-1}| / k) (Russian roulette that follows the series' own decay) and "
                 "divided by it. Cost: about 1 + order ray marches per estimate"},
    [P_ROULETTE] = {"roulette", MURK_PARAM_FLOAT, 0, {0.1, 0, 0}, NULL, NULL, 0, 1,
                    "when the control's transmittance (its largest channel) is below this, the whole estimate "
                    "survives with probability exp(-control) / roulette and is divided by it (0: never): opaque "
                    "shadow rays skip the correction marches"},
};

typedef struct urm {
    murk_tracker base;
    float depth_step, roulette;
    int order;
} urm;

static int urm_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                      char *err, size_t errlen)
{
    urm *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->depth_step = (float)p[P_DEPTH_STEP].f[0];
    m->order = (int)p[P_ORDER].f[0];
    m->roulette = (float)p[P_ROULETTE].f[0];
    *self = m;
    return 0;
}

static murk_rgb urm_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const urm *m = self;
    const murk_host *h = m->base.host;
    const murk_medium_data *d = m->base.d;
    const murk_rgb st = m->base.sigma_t;
    const double smax = m->base.smax;
    if (!(smax > 0.0))
        return murk_rgb1(1.0f);
    long nl = 0;
    double Dc = murk_march_depth(h, d, ray, 0.0f, m->depth_step, m->base.smax, murk_rng_float(rng), &nl);
    if (nl == 0) /* no cell with a majorant: no density on the segment */
        return murk_rgb1(1.0f);
    if (isinf(Dc))
        return murk_rgb1(0.0f);
    double Tc[3], tmax = 0.0, scale = 1.0;
    for (int k = 0; k < 3; k++) {
        Tc[k] = exp(-(double)st.c[k] * Dc);
        tmax = fmax(tmax, Tc[k]);
    }
    if (tmax < m->roulette) {
        double p = tmax / m->roulette;
        if (!(p > 0.0) || murk_rng_float(rng) >= p)
            return murk_rgb1(0.0f);
        scale = 1.0 / p;
    }
    double term[3] = {1.0, 1.0, 1.0}, sum[3] = {1.0, 1.0, 1.0}, xprev = 0.0;
    for (int k = 1;; k++) {
        double p = 1.0;
        if (k > m->order) {
            p = fmin(1.0, smax * fabs(xprev) / k);
            if (!(p > 0.0) || murk_rng_float(rng) >= p)
                break;
        }
        if (k > 10000) {
            h->warn_once("medium '%s': unbiased_raymarch stopped its series after 10000 terms (biased): "
                         "lower depth_step", d->name);
            break;
        }
        double X = Dc - murk_march_depth(h, d, ray, 0.0f, m->depth_step, m->base.smax, murk_rng_float(rng), NULL);
        for (int c = 0; c < 3; c++) {
            term[c] *= (double)st.c[c] * X / ((double)k * p);
            sum[c] += term[c];
        }
        if (X == 0.0) /* every later term is 0 too */
            break;
        xprev = X;
    }
    return murk_rgb3((float)(scale * Tc[0] * sum[0]), (float)(scale * Tc[1] * sum[1]), (float)(scale * Tc[2] * sum[2]));
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, urm_create,
                                         murk_tracker_free, urm_estimate};

MURK_TRANSMITTANCE_PLUGIN("unbiased_raymarch",
                          "unbiased ray marching (Kettunen et al. 2021): ray-marched control + power-series "
                          "correction; zero variance where the density is constant",
                          params, P_COUNT, &vt)
