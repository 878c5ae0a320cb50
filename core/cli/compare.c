/* compare.c — `murk compare TEST.exr REFERENCE.exr [--diff DIFF.png]`: error figures of one image
 * against a reference, and a heat map of the difference. Part of the murk executable. */
#include "cli.h"
#include "image.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define cli_error(m) murk_cli_error(m)
#define usage(m) murk_cli_usage(m)

/* ---- compare ------------------------------------------------------------------------------- */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int murk_cli_compare(int argc, char **argv)
{
    const char *a = NULL, *b = NULL, *diff = NULL;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--diff")) {
            if (i + 1 >= argc)
                return usage("--diff needs a .png file name");
            diff = argv[++i];
        } else if (!a) {
            a = argv[i];
        } else if (!b) {
            b = argv[i];
        } else {
            return usage("compare takes two images");
        }
    }
    if (!a || !b)
        return usage("compare needs two EXR files: TEST REFERENCE");
    murk_image A = {0}, B = {0};
    char err[1024];
    if (murk_exr_read(a, &A, err, sizeof err) || murk_exr_read(b, &B, err, sizeof err)) {
        cli_error(err);
        murk_image_free(&A);
        return 1;
    }
    int rc = 0;
    if (A.w != B.w || A.h != B.h) {
        fprintf(stderr, "murk: %s is %dx%d but %s is %dx%d\n", a, A.w, A.h, b, B.w, B.h);
        rc = 1;
    } else {
        size_t n = (size_t)A.w * (size_t)A.h;
        double mse = 0, rel = 0, mar = 0;
        size_t bad = 0;
        float *d = murk_xmalloc(n * sizeof(float));
        for (size_t i = 0; i < n; i++) {
            double dp = 0;
            for (int c = 0; c < 3; c++) {
                double x = A.rgb[3 * i + (size_t)c], r = B.rgb[3 * i + (size_t)c];
                if (!isfinite(x) || !isfinite(r)) {
                    bad++;
                    continue;
                }
                double e = x - r;
                mse += e * e;
                rel += e * e / (r * r + 1e-2);
                mar += fabs(e) / (fabs(r) + 1e-2);
                dp += fabs(e);
            }
            d[i] = (float)(dp / 3);
        }
        double m = 3.0 * (double)n;
        printf("MSE %.6e  relMSE %.6e  mean-abs-rel %.6e  (%s against reference %s; relMSE = mean (a-b)^2/(b^2+0.01))\n",
               mse / m, rel / m, mar / m, a, b);
        if (bad)
            printf("warning: %zu non-finite values skipped\n", bad);
        if (diff) {
            float *sorted = murk_xmalloc(n * sizeof(float));
            memcpy(sorted, d, n * sizeof(float));
            qsort(sorted, n, sizeof(float), cmp_float);
            float p99 = sorted[(size_t)(0.99 * (double)(n - 1))];
            float scale = p99 > 0 ? 1.0f / p99 : 1.0f;
            free(sorted);
            float *rgb = murk_xmalloc(3 * n * sizeof(float));
            for (size_t i = 0; i < n; i++) { /* black -> red -> yellow -> white heat map */
                float t = fminf(1.0f, d[i] * scale);
                rgb[3 * i] = fminf(1.0f, 3 * t);
                rgb[3 * i + 1] = fminf(1.0f, fmaxf(0.0f, 3 * t - 1));
                rgb[3 * i + 2] = fmaxf(0.0f, 3 * t - 2);
                for (int c = 0; c < 3; c++) /* the PNG writer applies the sRGB curve: undo it */
                    rgb[3 * i + (size_t)c] = powf(rgb[3 * i + (size_t)c], 2.2f);
            }
            if (murk_png_write(diff, rgb, A.w, A.h, 0.0f, err, sizeof err)) {
                cli_error(err);
                rc = 1;
            } else {
                printf("diff image %s: |a-b| averaged over channels, white = 99th percentile (%.3e)\n", diff, p99);
            }
            free(rgb);
        }
        free(d);
    }
    murk_image_free(&A);
    murk_image_free(&B);
    return rc;
}
