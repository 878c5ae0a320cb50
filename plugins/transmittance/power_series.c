/* power_series — a cumulative power-series transmittance estimator after Georgiev, Misso, Hachisuka,
 * Nowrouzezahrai, Křivánek, Jarosz 2019 ("Integral formulations of volumetric transmittance"): the
 * majorant as the control, every term up to the order evaluated, the order at least the point where the
 * Poisson CMF of the majorant's optical depth reaches 1 - 1e-8 and beyond it the Poisson count (their
 * "p-series CMF"), on chunks of the ray whose estimates multiply. Unbiased per channel for any majorant;
 * zero variance on a constant density with a tight majorant. Parameters: `murk plugins power_series`; the
 * estimator, why the order is topped up, and its cost: docs/trackers.md#power_series. */
#include "murk/transmittance.h"
#include "murk/tracking.h"

enum { P_CHUNK_DEPTH, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_CHUNK_DEPTH] = {"chunk_depth", MURK_PARAM_FLOAT, 0, {4, 0, 0}, NULL, NULL, 0.25, 32,
                       "the majorant optical depth of a chunk: the ray is cut into chunks of about this depth "
                       "(consecutive majorant cells, long cells split), each gets its own series and the chunks' "
                       "estimates multiply (independent, so still unbiased). Keeps the Poisson weights "
                       "well-conditioned and lets Russian roulette stop opaque rays early"},
};

enum { MAX_PIECES = 64, MAX_POINTS = 1024 };
#define CMF_TAIL 1e-8

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

/* y_c = 1 - sigma_t,c(x) / mu at the point t of piece p: one density lookup, counted as one tentative
 * collision (murk/counters.h: every point of the series, Poisson or top-up, is one). */
static void point_y(const ps *m, const murk_ray *ray, const piece *p, float t, murk_counters *count, double y[3])
{
    count->collisions++;
    float dens = m->base.host->density(m->base.d->density, murk_madd(ray->o, ray->d, t));
    for (int c = 0; c < 3; c++)
        y[c] = 1.0 - (double)dens * m->base.sigma_t.c[c] / p->mu;
}

/* A K-th point's y into the elementary symmetric means mk[0..K] of the K - 1 before it:
 * e_k(K) = e_k(K-1) + y e_(k-1)(K-1), over C(K, k). */
static void add_mean(int K, const double y[3], double (*mk)[3])
{
    for (int c = 0; c < 3; c++)
        mk[K][c] = mk[K - 1][c] * y[c];
    for (int k = K - 1; k >= 1; k--)
        for (int c = 0; c < 3; c++)
            mk[k][c] = (mk[k][c] * (K - k) + mk[k - 1][c] * y[c] * k) / K;
}

/* One chunk's estimate into T (multiplied in). Returns 0 if rouletted or the point cap was hit. A chunk
 * deeper than 64 (Poisson weights out of double range) is ratio-tracked, with Russian roulette on its
 * product as murk_ratio_tracking. */
static int chunk(const ps *m, const murk_ray *ray, const piece *pc, int n, double tau, murk_counters *count,
                 murk_rng *rng, double T[3])
{
    double mk[MAX_POINTS + 1][3], prod[3] = {1.0, 1.0, 1.0}, y[3];
    int K = 0, k0 = 0, ratio = tau > 64.0;
    mk[0][0] = mk[0][1] = mk[0][2] = 1.0;
    /* k0: the order below which the Poisson mass left is under CMF_TAIL (tau <= 64: k0 <= 114) */
    double pk = exp(-tau), cmf = pk;
    while (!ratio && cmf < 1.0 - CMF_TAIL && k0 < MAX_POINTS) {
        k0++;
        pk *= tau / k0;
        cmf += pk;
    }
    for (int i = 0; i < n; i++) { /* the Poisson process of the majorant: K ~ Poisson(tau) points */
        if (!(pc[i].mu > 0.0f))
            continue;
        for (float t = pc[i].ta;;) {
            t += murk_sample_exp(rng, pc[i].mu);
            if (!(t < pc[i].tb))
                break;
            if (!ratio && K == MAX_POINTS) {
                m->base.host->warn_once("medium '%s': power_series chunk with over %d points: stopped (biased)",
                                        m->base.d->name, MAX_POINTS);
                return 0;
            }
            point_y(m, ray, &pc[i], t, count, y);
            if (!ratio) {
                add_mean(++K, y, mk);
                continue;
            }
            for (int c = 0; c < 3; c++)
                prod[c] *= y[c];
            double pm = fmax(fabs(prod[0]), fmax(fabs(prod[1]), fabs(prod[2])));
            if (pm < 0.1) {
                if (pm <= 0.0 || murk_rng_float(rng) >= pm)
                    return 0;
                for (int c = 0; c < 3; c++)
                    prod[c] /= pm;
            }
        }
    }
    if (ratio) {
        for (int c = 0; c < 3; c++)
            T[c] *= prod[c];
        return 1;
    }
    while (K < k0) { /* up to k0 points: more i.i.d. with density mu / tau (a piece by its depth) */
        double u = murk_rng_float(rng) * tau;
        int i = 0;
        for (; i < n - 1; i++) {
            double di = (double)pc[i].mu * ((double)pc[i].tb - pc[i].ta);
            if (u < di)
                break;
            u -= di;
        }
        float t = pc[i].ta + (float)(u / pc[i].mu);
        if (!(t < pc[i].tb))
            t = nextafterf(pc[i].tb, pc[i].ta);
        point_y(m, ray, &pc[i], t, count, y);
        add_mean(++K, y, mk);
    }
    /* N = max(K, k0) points: P(N >= k) = 1 up to k0, the Poisson tail above */
    double s[3] = {0.0, 0.0, 0.0};
    pk = exp(-tau);
    for (int k = 0; k <= K; k++) {
        if (k > 0)
            pk *= tau / k;
        double w = k <= k0 ? pk : hazard(k, tau);
        for (int c = 0; c < 3; c++)
            s[c] += w * mk[k][c];
    }
    for (int c = 0; c < 3; c++)
        T[c] *= s[c];
    return 1;
}

/* Closes the current chunk: its estimate into T, then Russian roulette on small T. Returns 0 when
 * the estimate is 0 (rouletted or the point cap hit). */
static int flush(const ps *m, const murk_ray *ray, const piece *pc, int *n, double *tau, murk_counters *count,
                 murk_rng *rng, double T[3])
{
    int ok = chunk(m, ray, pc, *n, *tau, count, rng, T);
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
    murk_counters scratch, *count = murk_tracker_counters(h, m->base.d, &scratch);
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
        if (!(mu > 0.0f))
            continue;
        while (ta < tb) { /* cut [ta, tb) into pieces that fill chunks of about chunk_depth */
            double room = m->chunk_depth - tau;
            float cut = tb;
            if ((double)mu * ((double)tb - ta) > room) {
                float tc = (float)(ta + room / mu);
                if (!(tc > ta)) { /* the room is below half a float step at ta */
                    if (n > 0) { /* the chunk is full (a cut rounded down by < mu ulp(ta) / 2) */
                        if (!flush(m, ray, pc, &n, &tau, count, rng, T))
                            return murk_rgb1(0.0f);
                        continue;
                    }
                    tc = nextafterf(ta, tb); /* one float step is deeper than a chunk: a chunk of one step */
                }
                if (tc < tb)
                    cut = tc;
            }
            pc[n++] = (piece){ta, cut, mu};
            tau += (double)mu * ((double)cut - ta);
            ta = cut; /* cut > ta: the loop advances */
            if ((n == MAX_PIECES || tau >= full) && !flush(m, ray, pc, &n, &tau, count, rng, T))
                return murk_rgb1(0.0f);
        }
    }
    if (n > 0 && !flush(m, ray, pc, &n, &tau, count, rng, T))
        return murk_rgb1(0.0f);
    return murk_rgb3((float)T[0], (float)T[1], (float)T[2]);
}

static const murk_transmittance_vt vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, ps_create,
                                         murk_tracker_free, ps_estimate};

MURK_TRANSMITTANCE_PLUGIN("power_series",
                          "cumulative power series (after Georgiev et al. 2019): majorant control, Poisson order "
                          "topped up to its 1 - 1e-8 CMF (bounded variance)",
                          params, P_COUNT, &vt)
