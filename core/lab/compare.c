/* compare.c — `murk compare TEST.exr REFERENCE.exr [--crop X,Y,W,H] [--json] [--diff DIFF.png] [--scale S]
 * [--html PAGE.html]`:
 * the error figures of one image against a reference (metrics.c, the same code `murk bench` uses), a
 * bias test (mean difference, its standard error and z-score), the efficiency from the render time and
 * cost counters the EXR records, and two pictures of the difference: a heat map of |a - r| scaled to its
 * 99th percentile, and beside it a signed map on a fixed scale; --html, the interactive comparison page
 * (lab/report_html.h). Part of libmurklab (murk/lab.h). */
#include "cmd/cmd.h"
#include "image/image.h"
#include "lab/report_html.h"
#include "util/atomic.h"
#include "util/util.h"
#include "murk/lab.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define cli_error(m) murk_cli_error(m)
#define usage(m) murk_cli_usage(m)

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static const char *meta(const murk_image *im, const char *key)
{
    for (int i = 0; i < im->nmeta; i++)
        if (im->meta[i].key && !strcmp(im->meta[i].key, key))
            return im->meta[i].value;
    return NULL;
}

/* The render's seconds (murk:render_time) and total density lookups (murk:counters), -1 if absent. */
static double render_seconds(const murk_image *im)
{
    const char *s = meta(im, "murk:render_time");
    char *end;
    double t = s ? strtod(s, &end) : -1;
    return s && end != s && t > 0 ? t : -1;
}

static double render_lookups(const murk_image *im)
{
    const char *s = meta(im, "murk:counters"), *p = s ? strstr(s, "\"total\": {\"lookups\": ") : NULL;
    return p ? strtod(p + strlen("\"total\": {\"lookups\": "), NULL) : -1;
}

static int parse_crop(const char *v, murk_crop *c)
{
    long x[4];
    const char *p = v;
    for (int k = 0; k < 4; k++) {
        char *end;
        errno = 0;
        x[k] = p && *p >= '0' && *p <= '9' ? strtol(p, &end, 10) : -1;
        if (x[k] < 0 || errno || x[k] > 1L << 30 || *end != (k < 3 ? ',' : '\0'))
            return -1;
        p = end + 1;
    }
    *c = (murk_crop){(int)x[0], (int)x[1], (int)x[2], (int)x[3]};
    return c->w > 0 && c->h > 0 ? 0 : -1;
}

/* "D.png" -> "D_signed.png": the signed map's file, beside the heat map. */
static char *signed_path(const char *diff)
{
    size_t n = strlen(diff), b = n > 4 && !strcmp(diff + n - 4, ".png") ? n - 4 : n;
    char *p = murk_xmalloc(b + 12);
    memcpy(p, diff, b);
    memcpy(p + b, "_signed.png", 12);
    return p;
}

/* The heat map (black-red-yellow-white, white = the 99th percentile of |a - r|) and the signed map
 * (blue = -scale, white = 0, red = +scale, of the relative difference (a - r) / (|r| + 0.01), channel
 * mean) of the crop. The PNG writer applies the sRGB curve, so both are written linear. */
static int write_maps(const char *diff, const float *A, const float *B, int w, murk_crop c, double scale, int json)
{
    size_t n = (size_t)c.w * (size_t)c.h;
    float *d = murk_xmalloc(n * sizeof(float)), *sg = murk_xmalloc(n * sizeof(float));
    for (int y = 0; y < c.h; y++)
        for (int x = 0; x < c.w; x++) {
            size_t i = (size_t)(y + c.y) * (size_t)w + (size_t)(x + c.x), o = (size_t)y * (size_t)c.w + (size_t)x;
            double da = 0, dr = 0;
            for (int k = 0; k < 3; k++) {
                double e = (double)A[3 * i + (size_t)k] - B[3 * i + (size_t)k];
                da += isfinite(e) ? fabs(e) : 0;
                dr += isfinite(e) ? e / (fabs(B[3 * i + (size_t)k]) + 1e-2) : 0;
            }
            d[o] = (float)(da / 3);
            sg[o] = (float)(dr / 3);
        }
    float *sorted = murk_xmalloc(n * sizeof(float));
    memcpy(sorted, d, n * sizeof(float));
    qsort(sorted, n, sizeof(float), cmp_float);
    float p99 = sorted[(size_t)(0.99 * (double)(n - 1))], hs = p99 > 0 ? 1.0f / p99 : 1.0f;
    free(sorted);
    float *rgb = murk_xmalloc(3 * n * sizeof(float)), *rgb2 = murk_xmalloc(3 * n * sizeof(float));
    for (size_t i = 0; i < n; i++) {
        float t = fminf(1.0f, d[i] * hs);
        float h[3] = {fminf(1.0f, 3 * t), fminf(1.0f, fmaxf(0.0f, 3 * t - 1)), fmaxf(0.0f, 3 * t - 2)};
        float s = (float)fmax(-1.0, fmin(1.0, sg[i] / scale)), a = fabsf(s);
        float g[3] = {s > 0 ? 1.0f : 1.0f - a, 1.0f - a, s < 0 ? 1.0f : 1.0f - a};
        for (int k = 0; k < 3; k++) {
            rgb[3 * i + (size_t)k] = powf(h[k], 2.2f);
            rgb2[3 * i + (size_t)k] = powf(g[k], 2.2f);
        }
    }
    char err[1024], *sp = signed_path(diff);
    int rc = 0;
    murk_output_begin(); /* both maps or neither */
    if (murk_png_write(diff, rgb, c.w, c.h, 0.0f, err, sizeof err) ||
        murk_png_write(sp, rgb2, c.w, c.h, 0.0f, err, sizeof err) || murk_output_commit(err, sizeof err)) {
        murk_output_abort();
        cli_error(err);
        rc = 1;
    } else if (!json) {
        printf("diff images: %s = |a-r| averaged over channels, white = 99th percentile (%.3e); %s = signed "
               "(a-r)/(|r|+0.01), blue -%g .. white 0 .. red +%g (fixed scale, --scale)\n",
               diff, p99, sp, scale, scale);
    }
    free(sp);
    free(rgb);
    free(rgb2);
    free(d);
    free(sg);
    return rc;
}

typedef struct compare_opts {
    const char *a, *b, *diff, *html; /* TEST, REFERENCE, --diff, --html */
    int json, cropped;
    double scale;
    murk_crop crop;
} compare_opts;

/* The arguments into o: 0, or the usage status after a message. */
static int compare_options(compare_opts *o, int argc, char **argv)
{
    *o = (compare_opts){.scale = 1.0};
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--diff")) {
            if (i + 1 >= argc)
                return usage("--diff needs a .png file name");
            o->diff = argv[++i];
        } else if (!strcmp(argv[i], "--html")) {
            if (i + 1 >= argc)
                return usage("--html needs an .html file name");
            o->html = argv[++i];
        } else if (!strcmp(argv[i], "--crop")) {
            if (i + 1 >= argc || parse_crop(argv[i + 1], &o->crop))
                return usage("--crop needs X,Y,W,H (whole numbers, W and H above 0)");
            o->cropped = 1;
            i++;
        } else if (!strcmp(argv[i], "--scale")) {
            char *end = NULL;
            o->scale = i + 1 < argc ? strtod(argv[i + 1], &end) : 0;
            if (!end || *end || !(o->scale > 0) || !isfinite(o->scale))
                return usage("--scale needs a positive number (the signed map's full scale)");
            i++;
        } else if (!strcmp(argv[i], "--json")) {
            o->json = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "murk: unknown compare option '%s'\n", murk_cli_q(argv[i]));
            return usage(NULL);
        } else if (!o->a) {
            o->a = argv[i];
        } else if (!o->b) {
            o->b = argv[i];
        } else {
            return usage("compare takes two images");
        }
    }
    return !o->a || !o->b ? usage("compare needs two EXR files: TEST REFERENCE") : 0;
}

/* The figures of TEST against REFERENCE: the metrics, the bias test's z, and the efficiency from TEST's
 * render time (t) and density lookups (look), each -1 when unknown. */
typedef struct figures {
    murk_metrics m;
    double z, t, look, eff_t, eff_l;
} figures;

/* The --json object (also the page's figures), malloc'd; NULL when out of memory. */
static char *figures_json(const compare_opts *o, const figures *f)
{
    const murk_metrics *m = &f->m;
    const murk_crop *c = &o->crop;
    char *js = NULL;
    size_t jl = 0;
    FILE *jf = open_memstream(&js, &jl);
    if (!jf)
        return NULL;
    fprintf(jf, "{\"test\": \"%s\", \"reference\": \"%s\", \"crop\": [%d, %d, %d, %d], \"n\": %zu, "
           "\"nonfinite\": %zu, \"mse\": %.9g, \"relmse\": %.9g, \"relmse_se\": %.9g, \"mare\": %.9g, "
           "\"diff\": [%.9g, %.9g, %.9g, %.9g], \"diff_se\": [%.9g, %.9g, %.9g, %.9g], \"z\": %.6g",
           murk_cli_q(o->a), murk_cli_q(o->b), c->x, c->y, c->w, c->h, m->n, m->nonfinite, m->mse, m->relmse,
           m->relmse_se, m->mare, m->diff[0], m->diff[1], m->diff[2], m->diff[3], m->diff_se[0], m->diff_se[1],
           m->diff_se[2], m->diff_se[3], f->z);
    if (f->t > 0)
        fprintf(jf, ", \"seconds\": %.6g, \"efficiency_time\": %.9g", f->t, f->eff_t);
    if (f->look > 0)
        fprintf(jf, ", \"lookups\": %.0f, \"efficiency_lookups\": %.9g", f->look, f->eff_l);
    fprintf(jf, "}\n");
    fclose(jf);
    return js;
}

static void print_figures(const compare_opts *o, const figures *f)
{
    const murk_metrics *m = &f->m;
    printf("MSE %.6e  relMSE %.6e  mean-abs-rel %.6e  (%s against reference %s; relMSE = mean (a-b)^2/(b^2+0.01))\n",
           m->mse, m->relmse, m->mare, murk_cli_q(o->a), murk_cli_q(o->b));
    if (o->cropped)
        printf("crop: %dx%d pixels at (%d, %d)\n", o->crop.w, o->crop.h, o->crop.x, o->crop.y);
    printf("relMSE standard error %.2e; difference a-b: mean %.4e ± %.2e (z = %.2f; r %.3e, g %.3e, b %.3e): "
           "%s\n", m->relmse_se, m->diff[3], m->diff_se[3], f->z, m->diff[0], m->diff[1], m->diff[2],
           fabs(f->z) < 3 ? "no sign of a different expected image (|z| < 3)"
                          : "the expected images differ (|z| >= 3: bias, or a reference of another scene)");
    if (f->t > 0)
        printf("efficiency 1/(relMSE x seconds) = %.4g (render time %.3g s, murk:render_time)\n", f->eff_t, f->t);
    if (f->look > 0)
        printf("efficiency 1/(relMSE x density lookups) = %.4g (%.0f lookups, murk:counters)\n", f->eff_l, f->look);
}

/* Two images of one size, the crop inside them: the figures (text or --json), then the --diff maps and
 * the --html page. The exit status. */
static int compare_images(const compare_opts *o, const murk_image *A, const murk_image *B)
{
    figures f;
    murk_metrics_compute(A->rgb, B->rgb, NULL, A->w, o->crop, &f.m, NULL);
    f.z = f.m.diff_se[3] > 0 ? f.m.diff[3] / f.m.diff_se[3] : 0.0;
    f.t = render_seconds(A), f.look = render_lookups(A);
    f.eff_t = f.t > 0 && f.m.relmse > 0 ? 1.0 / (f.m.relmse * f.t) : -1;
    f.eff_l = f.look > 0 && f.m.relmse > 0 ? 1.0 / (f.m.relmse * f.look) : -1;
    char *js = o->json || o->html ? figures_json(o, &f) : NULL, err[1024];
    int rc = 0;
    if (o->json)
        fputs(js ? js : "", stdout);
    else
        print_figures(o, &f);
    if (f.m.nonfinite)
        fprintf(stderr, "murk: warning: %zu non-finite values skipped\n", f.m.nonfinite);
    if (o->diff)
        rc = write_maps(o->diff, A->rgb, B->rgb, A->w, o->crop, o->scale, o->json);
    if (o->html && rc == 0) {
        if (!js || murk_html_compare(o->html, o->a, o->b, A->rgb, B->rgb, A->w, &o->crop, js, f.t, f.look, err,
                                     sizeof err) != 0) {
            cli_error(js ? err : "out of memory");
            rc = 1;
        } else if (!o->json) {
            printf("comparison page: %s\n", murk_cli_q(o->html));
        }
    }
    free(js);
    return rc;
}

MURK_API int murk_lab_compare(int argc, char **argv)
{
    compare_opts o;
    int rc = compare_options(&o, argc, argv);
    if (rc)
        return rc;
    murk_image A = {0}, B = {0};
    char err[1024];
    if (o.html && murk_html_check_path(o.html, err, sizeof err) != 0) { /* before any work */
        cli_error(err);
        return 1;
    }
    if (murk_exr_read(o.a, &A, err, sizeof err) || murk_exr_read(o.b, &B, err, sizeof err)) {
        cli_error(err);
        murk_image_free(&A);
        return 1;
    }
    if (!o.cropped)
        o.crop = (murk_crop){0, 0, A.w, A.h};
    if (A.w != B.w || A.h != B.h) {
        fprintf(stderr, "murk: %s is %dx%d but %s is %dx%d\n", murk_cli_q(o.a), A.w, A.h, murk_cli_q(o.b), B.w, B.h);
        rc = 1;
    } else if ((long)o.crop.x + o.crop.w > A.w || (long)o.crop.y + o.crop.h > A.h) {
        fprintf(stderr, "murk: --crop %d,%d,%d,%d reaches outside the %dx%d images\n", o.crop.x, o.crop.y, o.crop.w,
                o.crop.h, A.w, A.h);
        rc = 2;
    } else {
        rc = compare_images(&o, &A, &B);
    }
    murk_image_free(&A);
    murk_image_free(&B);
    return rc;
}
