/* metrics.h — how far an image is from a reference: the figures `murk compare` prints and `murk bench`
 * records for every render (one code for both). No dependency beyond libc: the tests compile it in. */
#ifndef MURK_METRICS_H
#define MURK_METRICS_H

#include <stddef.h>

/* A rectangle of pixels: x, y (top-left), w, h. */
typedef struct murk_crop { int x, y, w, h; } murk_crop;

typedef struct murk_metrics {
    size_t n;           /* pixel-channels compared (finite in both images) */
    size_t nonfinite;   /* pixel-channels skipped: NaN or infinite in either image */
    double mse;         /* mean (a - r)^2 */
    double relmse_raw;  /* mean (a - r)^2 / (r^2 + 0.01) */
    double ref_noise;   /* mean v / (r^2 + 0.01): the reference's own noise in relMSE (0 without v) */
    double relmse;      /* relmse_raw - ref_noise: the noise-corrected relMSE (unbiased for a's error) */
    double relmse_se;   /* its standard error, from the spread of the per-pixel terms */
    double mare;        /* mean |a - r| / (|r| + 0.01) */
    double diff[4], diff_se[4]; /* mean of a - r and its standard error per channel, [3]: all channels */
} murk_metrics;

/* Compares a with the reference r (both 3 floats per pixel, row stride w pixels) over the rectangle c.
 * v, if non-NULL, is the variance of r's per-pixel mean (same layout): subtracted from every squared
 * difference, so E[relmse] is a's own relMSE whatever the reference's noise. pix, if non-NULL, gets
 * c.w x c.h floats: each pixel's channel-mean of the corrected relative squared error. */
void murk_metrics_compute(const float *a, const float *r, const float *v, int w, murk_crop c, murk_metrics *m,
                          float *pix);

#endif
