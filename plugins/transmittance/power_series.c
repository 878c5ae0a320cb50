/* power_series — a cumulative power-series transmittance estimator after Georgiev, Misso, Hachisuka,
 * Nowrouzezahrai, Krivanek, Jarosz 2019 ("Integral formulations of volumetric transmittance"): the
 * majorant as the control, the Poisson distribution of the majorant's optical depth as the order
 * distribution, and every term up to the sampled order evaluated (their cumulative "p-series" family;
 * the single top term alone would be ratio tracking).
 *
 * Parameters
 *   chunk_depth  float in [0.25, 32], default 4. The ray is cut into chunks of about this majorant
 *                optical depth (consecutive majorant cells, long cells split); each chunk gets its own
 *                series and the chunks' estimates multiply (independent, so still unbiased). Keeps the
 *                Poisson weights well-conditioned and lets Russian roulette stop opaque rays early.
 *
 * Estimator, per chunk with majorant rate mu(t) = dmax(t) x max_c sigma_t,c and optical depth
 * tau_bar = int mu. The points x_1..x_K of a Poisson process of rate mu (K ~ Poisson(tau_bar); given K the
 * points are i.i.d. with density mu / tau_bar) give y_i,c = 1 - sigma_t,c(x_i) / mu(x_i), each unbiased
 * for (tau_bar - tau_c) / tau_bar. With m_k,c the elementary symmetric mean of order k of the y_i,c
 * (unbiased for ((tau_bar - tau_c) / tau_bar)^k given K >= k, and symmetric: the points may come in
 * sorted order) and P(K >= k) the Poisson tail,
 *     T_c = sum_{k=0}^{K} Pois(k; tau_bar) m_k,c / P(K >= k)
 * has expectation sum_k e^-tau_bar (tau_bar - tau_c)^k / k! = exp(-tau_c): unbiased per channel, for any
 * majorant (where the density exceeds it y < 0 and the terms alternate; the core warns at load). With a
 * tight majorant on constant density (y = 0) T = e^-tau_bar exactly: zero variance. Cost: the same
 * lookups as ratio tracking (one per tentative collision) plus O(K^2) arithmetic per chunk. Russian
 * roulette between chunks (survival = the largest channel, once below 0.1), as ratio tracking. A chunk
 * whose tau_bar exceeds 64 (a float-limited split) falls back to the product of its y (ratio tracking,
 * unbiased); one with more than 1024 points stops with a warning (biased; never seen). */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_CHUNK_DEPTH, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CHUNK_DEPTH] = {"chunk_depth", MURK_PARAM_FLOAT, 0, {4, 0, 0}, NULL, NULL, 0.25, 32,
                       "majorant optical depth per independent power-series chunk"},
};

enum { MAX_PIECES = 64, MAX_POINTS = 1024 };

typedef struct ps {
    murk_tracker base;
    float chunk_depth;
} ps;

typedef struct piece { float ta, tb, mu; } piece;

static int ps_create(const murk_host *host, const murk_medium_data *data, const murk_value *p, void **self,
                     char *err, size_t errlen)
{
    ps *m = murk_tracker_new(host, data, sizeof *m, err, errlen);
    if (!m)
        return -1;
    m->chunk_depth = (float)p[P_CHUNK_DEPTH].f[0];
    *self = m;
    return 0;
}

/* Pois(k; tau) / P(K >= k) = 1 / sum_{j >= k} tau^(j-k) k! / j!, summed until the terms vanish. */
static double hazard(int k, double tau)
{
    double r = 1.0, s = 1.0;
    for (int j = k + 1; j < k + 100000; j++) {
        r *= tau / j;
        s += r;
        if (r < 1e-17 * s)
            break;
    }
    return 1.0 / s;
}

/* One chunk's estimate into T (multiplied in). Returns 0 if the point cap was hit. */
static int chunk(const ps *m, const murk_ray *ray, const piece *pc, int n, double tau, murk_rng *rng, double T[3])
{
    const murk_host *h = m->base.host;
    const murk_medium_data *d = m->base.d;
    double mk[MAX_POINTS + 1][3];
    int K = 0, ratio = tau > 64.0;
    double prod[3] = {1.0, 1.0, 1.0};
    mk[0][0] = mk[0][1] = mk[0][2] = 1.0;
    for (int i = 0; i < n; i++) {
        if (!(pc[i].mu > 0.0f))
            continue;
        for (float t = pc[i].ta;;) {
            t += murk_sample_exp(rng, pc[i].mu);
            if (!(t < pc[i].tb))
                break;
            if (K == MAX_POINTS) {
                h->warn_once("medium '%s': power_series chunk with over %d points: stopped (biased)", d->name,
                             MAX_POINTS);
                return 0;
            }
            float dens = h->density(d->density, murk_madd(ray->o, ray->d, t));
            K++;
            double y[3];
            for (int c = 0; c < 3; c++) {
                y[c] = 1.0 - (double)dens * m->base.sigma_t.c[c] / pc[i].mu;
                prod[c] *= y[c];
            }
            if (ratio)
                continue;
            /* elementary symmetric means of y_1..y_K from those of y_1..y_{K-1} */
            for (int c = 0; c < 3; c++)
                mk[K][c] = mk[K - 1][c] * y[c];
            for (int k = K - 1; k >= 1; k--)
                for (int c = 0; c < 3; c++)
                    mk[k][c] = (mk[k][c] * (K - k) + mk[k - 1][c] * y[c] * k) / K;
        }
    }
    if (ratio) {
        for (int c = 0; c < 3; c++)
            T[c] *= prod[c];
        return 1;
    }
    double s[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k <= K; k++) {
        double w = hazard(k, tau);
        for (int c = 0; c < 3; c++)
            s[c] += w * mk[k][c];
    }
    for (int c = 0; c < 3; c++)
        T[c] *= s[c];
    return 1;
}

/* Closes the current chunk: its estimate into T, then Russian roulette on small T. Returns 0 when
 * the estimate is 0 (rouletted or the point cap hit). */
static int flush(const ps *m, const murk_ray *ray, const piece *pc, int *n, double *tau, murk_rng *rng, double T[3])
{
    int ok = chunk(m, ray, pc, *n, *tau, rng, T);
    *n = 0;
    *tau = 0.0;
    if (!ok)
        return 0;
    double tm = fmax(fabs(T[0]), fmax(fabs(T[1]), fabs(T[2])));
    if (tm < 0.1) {
        if (tm <= 0.0 || murk_rng_float(rng) >= tm)
            return 0;
        for (int c = 0; c < 3; c++)
            T[c] /= tm;
    }
    return 1;
}

static murk_rgb ps_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    (void)ctx;
    const ps *m = self;
    const murk_host *h = m->base.host;
    const double smax = m->base.smax, full = m->chunk_depth * (1.0 - 1e-6);
    double T[3] = {1.0, 1.0, 1.0}, tau = 0.0;
    if (!(smax > 0.0))
        return murk_rgb1(1.0f);
    murk_majorant_walk w;
    h->walk_init(m->base.d->density, ray, ray->tmin, ray->tmax, &w);
    piece pc[MAX_PIECES];
    int n = 0;
    float ta, tb, dmax, dmin;
    while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
        if (!(dmax > 0.0f) || !(tb > ta))
            continue;
        if (!isfinite((double)tb - ta))
            return murk_rgb1(0.0f); /* an unbounded medium along an infinite ray */
        float mu = (float)(dmax * smax);
        while (ta < tb) { /* cut [ta, tb) into pieces that fill chunks of about chunk_depth */
            double room = m->chunk_depth - tau;
            float cut = tb;
            if ((double)mu * ((double)tb - ta) > room) {
                float tc = (float)(ta + room / mu);
                if (tc > ta && tc < tb) /* else the whole rest (float-limited): the chunk runs over */
                    cut = tc;
            }
            pc[n++] = (piece){ta, cut, mu};
            tau += (double)mu * ((double)cut - ta);
            ta = cut; /* cut > ta: the loop advances */
            if ((n == MAX_PIECES || tau >= full) && !flush(m, ray, pc, &n, &tau, rng, T))
                return murk_rgb1(0.0f);
        }
    }
    if (n > 0 && !flush(m, ray, pc, &n, &tau, rng, T))
        return murk_rgb1(0.0f);
    return murk_rgb3((float)T[0], (float)T[1], (float)T[2]);
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, ps_create,
                                         murk_tracker_free, ps_estimate};

MURK_TRANSMITTANCE_PLUGIN("power_series",
                          "cumulative power-series estimator (after Georgiev et al. 2019): majorant control, Poisson order",
                          params, P_COUNT, &vt)
