/* metrics.c — the image-against-reference figures of `murk compare` and `murk bench` (murk/lab.h).
 *
 * relMSE = mean over pixel-channels of (a - r)^2 / (r^2 + 0.01) (the 0.01 keeps black pixels from
 * dominating). With independent renders E[(a - r)^2] = bias^2 + Var a + Var r: the reference's noise
 * adds Var r, which the corrected figure subtracts with an unbiased estimate v of it. The standard
 * errors treat pixels as independent samples — they are: murk draws one random stream per pixel. */
#include "util/util.h"
#include "murk/lab.h"

#include <math.h>

MURK_API void murk_metrics_compute(const float *a, const float *r, const float *v, int w, murk_crop c,
                                   murk_metrics *m, float *pix)
{
    *m = (murk_metrics){0};
    double se = 0, sr = 0, sn = 0, sm = 0, t1 = 0, t2 = 0, d1[4] = {0}, d2[4] = {0};
    size_t nd[4] = {0}, npix = 0;
    for (int y = c.y; y < c.y + c.h; y++)
        for (int x = c.x; x < c.x + c.w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            double t = 0, ep = 0; /* the pixel's relative squared error and difference, channel means */
            int k = 0;
            for (int ch = 0; ch < 3; ch++) {
                double av = a[3 * i + (size_t)ch], rv = r[3 * i + (size_t)ch];
                double vv = v ? v[3 * i + (size_t)ch] : 0.0;
                if (!isfinite(av) || !isfinite(rv) || !isfinite(vv)) {
                    m->nonfinite++;
                    continue;
                }
                double e = av - rv, den = rv * rv + 1e-2;
                se += e * e;
                sr += e * e / den;
                sn += vv / den;
                sm += fabs(e) / (fabs(rv) + 1e-2);
                t += (e * e - vv) / den;
                k++;
                d1[ch] += e;
                d2[ch] += e * e;
                nd[ch]++;
                ep += e;
                m->n++;
            }
            if (k) { /* the all-channel figures per pixel: a pixel's channels are not independent */
                ep /= k;
                d1[3] += ep;
                d2[3] += ep * ep;
                nd[3]++;
                t /= k;
                t1 += t;
                t2 += t * t;
                npix++;
            }
            if (pix)
                pix[(size_t)(y - c.y) * (size_t)c.w + (size_t)(x - c.x)] = k ? (float)t : NAN;
        }
    if (!m->n)
        return;
    double n = (double)m->n;
    m->mse = se / n;
    m->relmse_raw = sr / n;
    m->ref_noise = sn / n;
    m->relmse = m->relmse_raw - m->ref_noise;
    m->mare = sm / n;
    if (npix > 1) {
        double mp = t1 / (double)npix, var = (t2 - t1 * mp) / (double)(npix - 1);
        m->relmse_se = sqrt(fmax(var, 0.0) / (double)npix);
    }
    for (int q = 0; q < 4; q++)
        if (nd[q] > 1) {
            double mu = d1[q] / (double)nd[q], var = (d2[q] - d1[q] * mu) / (double)(nd[q] - 1);
            m->diff[q] = mu;
            m->diff_se[q] = sqrt(fmax(var, 0.0) / (double)nd[q]);
        }
}
