/* envmap.c — a lat-long environment map and its importance sampling (see envmap.h for the mapping and
 * the density). */
#include "render/envmap.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Texel (i, j) with i wrapped around the longitude and j clamped to the rows. */
static const float *texel(const murk_envmap *e, int i, int j)
{
    i %= e->w;
    if (i < 0)
        i += e->w;
    j = j < 0 ? 0 : j >= e->h ? e->h - 1 : j;
    return &e->rgb[3 * ((size_t)j * (size_t)e->w + (size_t)i)];
}

/* The luminance of the bilinear radiance averaged over texel (i, j): per axis 1/8 of each neighbour and
 * 3/4 of the texel (the hat functions' integrals over it). */
static double texel_average(const murk_envmap *e, int i, int j)
{
    static const double k[3] = {0.125, 0.75, 0.125};
    double sum = 0.0;
    for (int b = -1; b <= 1; b++)
        for (int a = -1; a <= 1; a++) {
            const float *t = texel(e, i + a, j + b);
            sum += k[a + 1] * k[b + 1] * (double)murk_luminance(murk_rgb3(t[0], t[1], t[2]));
        }
    return sum;
}

/* Rejects what is not a lat-long radiance map (see murk_envmap_new). */
static int check_texels(const float *rgb, int w, int h, char *err, size_t errlen)
{
    if (w < 1 || h < 1) {
        snprintf(err, errlen, "the environment map is empty (%dx%d)", w, h);
        return -1;
    }
    if (w != 2 * h) {
        snprintf(err, errlen, "the environment map is %dx%d, not a lat-long map (its width must be twice its "
                 "height: 360 by 180 degrees); an equal-area or cube map must be converted first", w, h);
        return -1;
    }
    for (size_t k = 0; k < 3 * (size_t)w * (size_t)h; k++)
        if (!(rgb[k] >= 0.0f) || !isfinite(rgb[k])) {
            size_t px = k / 3;
            snprintf(err, errlen, "texel (%zu, %zu) of the environment map is %g: radiances must be finite and "
                     "not negative", px % (size_t)w, px / (size_t)w, (double)rgb[k]);
            return -1;
        }
    return 0;
}

/* The sampling weights, their marginal and conditional CDFs, and the luminance integral. */
static void build_distribution(murk_envmap *e)
{
    int w = e->w, h = e->h;
    e->f = murk_xmalloc((size_t)w * (size_t)h * sizeof *e->f);
    e->row_cdf = murk_xmalloc(((size_t)h + 1) * sizeof *e->row_cdf);
    e->col_cdf = murk_xmalloc((size_t)h * ((size_t)w + 1) * sizeof *e->col_cdf);
    double total = 0.0, integral = 0.0;
    e->row_cdf[0] = 0.0;
    for (int j = 0; j < h; j++) {
        double st = sin(M_PI * (j + 0.5) / h), row = 0.0;
        double *cdf = &e->col_cdf[(size_t)j * ((size_t)w + 1)];
        cdf[0] = 0.0;
        for (int i = 0; i < w; i++) {
            double a = texel_average(e, i, j);
            float f = (float)(a * st);
            e->f[(size_t)j * (size_t)w + (size_t)i] = f;
            row += f;
            cdf[i + 1] = row;
            integral += a * st;
        }
        for (int i = 1; i <= w; i++)
            cdf[i] = row > 0.0 ? cdf[i] / row : (double)i / w;
        total += row;
        e->row_cdf[j + 1] = total;
    }
    for (int j = 1; j <= h; j++)
        e->row_cdf[j] = total > 0.0 ? e->row_cdf[j] / total : (double)j / h;
    e->fsum = total;
    e->integral = integral * (2.0 * M_PI / w) * (M_PI / h);
}

murk_envmap *murk_envmap_new(const float *rgb, int w, int h, murk_rgb scale, double rotation_deg, char *err,
                             size_t errlen)
{
    if (check_texels(rgb, w, h, err, errlen))
        return NULL;
    murk_envmap *e = murk_xmalloc(sizeof *e);
    e->w = w;
    e->h = h;
    size_t n = (size_t)w * (size_t)h;
    e->rgb = murk_xmalloc(3 * n * sizeof *e->rgb);
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            e->rgb[3 * k + (size_t)c] = rgb[3 * k + (size_t)c] * scale.c[c];
    double a = rotation_deg * M_PI / 180.0;
    e->cos_rot = (float)cos(a);
    e->sin_rot = (float)sin(a);
    build_distribution(e);
    return e;
}

void murk_envmap_free(murk_envmap *e)
{
    if (!e)
        return;
    free(e->rgb);
    free(e->f);
    free(e->row_cdf);
    free(e->col_cdf);
    free(e);
}

/* World direction to the map's frame (R_y(-rotation)) and back (R_y(rotation)). */
static murk_vec3 to_map(const murk_envmap *e, murk_vec3 d)
{
    return murk_v3(e->cos_rot * d.x - e->sin_rot * d.z, d.y, e->sin_rot * d.x + e->cos_rot * d.z);
}

static murk_vec3 from_map(const murk_envmap *e, murk_vec3 d)
{
    return murk_v3(e->cos_rot * d.x + e->sin_rot * d.z, d.y, -e->sin_rot * d.x + e->cos_rot * d.z);
}

/* (u, v) in [0, 1]^2 of a unit direction in the map's frame. */
static void dir_uv(murk_vec3 d, float *u, float *v)
{
    *u = 0.5f + atan2f(d.x, -d.z) * (0.5f * MURK_INV_PI);
    *v = acosf(murk_minf(1.0f, murk_maxf(-1.0f, d.y))) * MURK_INV_PI;
}

murk_rgb murk_envmap_eval(const murk_envmap *e, murk_vec3 dir)
{
    float u, v;
    dir_uv(to_map(e, dir), &u, &v);
    float x = u * (float)e->w - 0.5f, y = v * (float)e->h - 0.5f;
    float x0 = floorf(x), y0 = floorf(y), fx = x - x0, fy = y - y0;
    int i = (int)x0, j = (int)y0;
    const float *t00 = texel(e, i, j), *t10 = texel(e, i + 1, j), *t01 = texel(e, i, j + 1),
                *t11 = texel(e, i + 1, j + 1);
    murk_rgb L;
    for (int c = 0; c < 3; c++)
        L.c[c] = (1.0f - fy) * ((1.0f - fx) * t00[c] + fx * t10[c]) + fy * ((1.0f - fx) * t01[c] + fx * t11[c]);
    return L;
}

/* The solid-angle pdf at texel (i, j) for a direction whose sin(theta) is st. */
static float texel_pdf(const murk_envmap *e, int i, int j, double st)
{
    if (!(e->fsum > 0.0) || !(st > 0.0))
        return 0.0f;
    double puv = (double)e->f[(size_t)j * (size_t)e->w + (size_t)i] * e->w * e->h / e->fsum;
    return (float)(puv / (2.0 * M_PI * M_PI * st));
}

float murk_envmap_pdf(const murk_envmap *e, murk_vec3 dir)
{
    murk_vec3 d = to_map(e, dir);
    float u, v;
    dir_uv(d, &u, &v);
    int i = (int)(u * (float)e->w), j = (int)(v * (float)e->h);
    i = i < 0 ? 0 : i >= e->w ? e->w - 1 : i;
    j = j < 0 ? 0 : j >= e->h ? e->h - 1 : j;
    return texel_pdf(e, i, j, sqrt((double)d.x * d.x + (double)d.z * d.z));
}

/* The k with cdf[k] <= u < cdf[k + 1] among n intervals, skipping empty ones. */
static int find_interval(const double *cdf, int n, double u)
{
    int lo = 0, hi = n; /* cdf[lo] <= u < cdf[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    while (lo + 1 < n && !(cdf[lo + 1] > cdf[lo]))
        lo++;
    return lo;
}

int murk_envmap_sample(const murk_envmap *e, const float u[2], murk_vec3 *dir, float *pdf)
{
    if (!(e->fsum > 0.0))
        return 0;
    int j = find_interval(e->row_cdf, e->h, u[0]);
    const double *cc = &e->col_cdf[(size_t)j * ((size_t)e->w + 1)];
    int i = find_interval(cc, e->w, u[1]);
    double dv = e->row_cdf[j + 1] - e->row_cdf[j], du = cc[i + 1] - cc[i];
    double fv = dv > 0.0 ? (u[0] - e->row_cdf[j]) / dv : 0.5, fu = du > 0.0 ? (u[1] - cc[i]) / du : 0.5;
    fv = fmin(fmax(fv, 0.0), 1.0);
    fu = fmin(fmax(fu, 0.0), 1.0);
    double theta = M_PI * (j + fv) / e->h, phi = 2.0 * M_PI * ((i + fu) / e->w - 0.5);
    double st = sin(theta);
    *pdf = texel_pdf(e, i, j, st);
    if (!(*pdf > 0.0f) || !isfinite(*pdf))
        return 0;
    *dir = from_map(e, murk_v3((float)(st * sin(phi)), (float)cos(theta), (float)(-st * cos(phi))));
    return 1;
}
