/* mediatest.c — see mediatest.h */
#include "mediatest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

murk_scene *mt_load_media(const char *file, const char *common, const char *prefix, const mt_spec *ms, int n)
{
    static char text[16384];
    size_t k = (size_t)snprintf(text, sizeof text, "murk: 1\nmedia:\n");
    for (int i = 0; i < n; i++)
        k += (size_t)snprintf(text + k, sizeof text - k, "  %s: { %s%s, %s }\n", ms[i].label, prefix, ms[i].keys,
                              common);
    snprintf(text + k, sizeof text - k, "shapes: []\n");
    char err[2048];
    murk_scene *s = murk_scene_load(write_tmp(file, text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("scene load failed: %s\n%s", err, text);
    assert_int_equal((int)s->nmedia, n);
    return s;
}

const double mt_sigma_a[2][3] = {{0.3, 0.3, 0.3}, {0.2, 1.0, 3.0}};
const double mt_sigma_s[2][3] = {{0.9, 0.9, 0.9}, {1.0, 0.5, 0.1}};
const double mt_sigma_t[2][3] = {{1.2, 1.2, 1.2}, {1.2, 1.5, 3.1}};

const char *mt_sigma_keys(int chroma) { return chroma ? MT_CHROMA_KEYS : MT_GREY_KEYS; }

const char *mt_save_grid(const char *name, const int res[3], murk_vec3 lo, murk_vec3 hi,
                         float (*f)(int, int, int, float, float, float))
{
    size_t n = (size_t)res[0] * res[1] * res[2];
    float *v = malloc(n * sizeof *v);
    assert_non_null(v);
    for (int z = 0; z < res[2]; z++)
        for (int y = 0; y < res[1]; y++)
            for (int x = 0; x < res[0]; x++) {
                float cx = lo.x + (hi.x - lo.x) * ((float)x + 0.5f) / (float)res[0];
                float cy = lo.y + (hi.y - lo.y) * ((float)y + 0.5f) / (float)res[1];
                float cz = lo.z + (hi.z - lo.z) * ((float)z + 0.5f) / (float)res[2];
                v[((size_t)z * res[1] + y) * res[0] + x] = f(x, y, z, cx, cy, cz);
            }
    murk_field *fld = murk_field_from_voxels(res, lo, hi, v);
    assert_non_null(fld);
    free(v);
    static char path[4][512];
    static int next;
    char *p = path[next++ & 3];
    snprintf(p, sizeof path[0], "%s/%s", tmp_dir(), name);
    char err[512];
    if (murk_field_vol_save(p, fld, err, sizeof err) != 0)
        fail_msg("%s", err);
    murk_field_free(fld);
    return p;
}

float mt_checker_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)cx, (void)cy, (void)cz;
    return ((x + y + z) & 1) ? 1.4f : 0.2f;
}

float mt_ramp_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy;
    return 0.2f + 1.1f * cz;
}

float mt_sinus_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z;
    return 0.18f + 0.13f * sinf(3.0f * cx + 1.0f) * sinf(2.5f * cy + 0.3f) * cosf(2.0f * cz);
}

mt_case mt_checker_case(void)
{
    const char *grid = mt_save_grid("checker.vol", (int[]){8, 8, 8}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), mt_checker_f);
    double D = 0.0;
    for (int x = 0; x < 8; x++)
        D += mt_checker_f(x, 3, 3, 0, 0, 0) / 8.0;
    float yc = 3.5f / 8.0f;
    return (mt_case){grid, {murk_v3(-0.25f, yc, yc), murk_v3(1, 0, 0), 0.0f, 1.5f}, D};
}

mt_case mt_ramp_case(void)
{
    const char *grid = mt_save_grid("ramp.vol", (int[]){4, 4, 16}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), mt_ramp_f);
    murk_vec3 d = murk_normalize(murk_v3(0.2f, 0.1f, 1.0f));
    return (mt_case){grid, {murk_v3(0.3f, 0.4f, -0.5f), d, 0.0f, 2.5f}, 0.75 / d.z};
}

mt_case mt_sinus_case(void)
{
    const char *grid = mt_save_grid("sinus.vol", (int[]){16, 16, 16}, murk_v3(-1, -1, -1), murk_v3(1, 1, 1), mt_sinus_f);
    return (mt_case){grid, {murk_v3(-1.5f, -1.2f, -1.4f), murk_normalize(murk_v3(1.0f, 0.8f, 0.9f)), 1.0f, 4.0f}, -1.0};
}

void mt_depths(const murk_medium *m, const char *grid, const murk_ray *ray, int nbins, int sub, double *D)
{
    murk_field *f = NULL;
    if (grid) {
        char err[512];
        f = murk_field_vol_load(grid, err, sizeof err);
        if (!f)
            fail_msg("%s", err);
    }
    double h = ((double)ray->tmax - ray->tmin) / ((double)nbins * sub), acc = 0.0;
    D[0] = 0.0;
    for (int b = 0; b < nbins; b++) {
        for (int i = 0; i < sub; i++) {
            double t = ray->tmin + h * ((double)(b * sub + i) + 0.5);
            murk_vec3 p = murk_madd(ray->o, ray->d, (float)t);
            acc += h * (f ? murk_field_eval(f, p) : murk_media_density(m->data->density, p));
        }
        D[b + 1] = acc;
    }
    murk_field_free(f);
}

double mt_quadrature(const murk_medium *m, const murk_ray *ray)
{
    double D[2];
    mt_depths(m, NULL, ray, 1, 200000, D);
    return D[1];
}

void mt_acc_add(mt_acc *a, const double x[3])
{
    for (int c = 0; c < 3; c++) {
        if (a->n == 0)
            a->k[c] = x[c];
        double d = x[c] - a->k[c];
        a->s[c] += d;
        a->s2[c] += d * d;
        a->s3[c] += d * d * d;
        a->s4[c] += d * d * d * d;
        a->amax[c] = fmax(a->amax[c], fabs(x[c]));
    }
    a->n++;
}

double mt_mean(const mt_acc *a, int c) { return a->k[c] + a->s[c] / (double)a->n; }

double mt_var(const mt_acc *a, int c)
{
    double m = a->s[c] / (double)a->n;
    return fmax(0.0, (a->s2[c] - (double)a->n * m * m) / (double)(a->n - 1));
}

double mt_se(const mt_acc *a, int c) { return sqrt(mt_var(a, c) / (double)a->n); }

int mt_hero(murk_rng *rng) { return (int)(murk_rng_float(rng) * 3.0f); }

int mt_call(const murk_medium *m, const murk_ray *ray, murk_rng *rng, murk_rgb *T, murk_medium_event *ev, double x[3])
{
    murk_path_ctx ctx;
    ctx.beta = murk_rgb1(1.0f);
    ctx.hero = mt_hero(rng);
    *T = m->vt->transmittance(m->self, ray, &ctx, rng);
    ctx.hero = mt_hero(rng);
    m->vt->sample(m->self, ray, &ctx, rng, ev);
    double mp = ((double)ev->pdf_ratio.c[0] + ev->pdf_ratio.c[1] + ev->pdf_ratio.c[2]) / 3.0;
    for (int c = 0; c < 3; c++)
        x[c] = mp > 0.0 ? ev->weight.c[c] / mp : 0.0;
    return murk_rgb_finite(*T) && murk_rgb_finite(ev->weight) && murk_rgb_finite(ev->pdf_ratio) && isfinite(ev->t);
}

double mt_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

double mt_zmax(const mt_acc *a, const double expect[3], double rel)
{
    double z = 0.0;
    for (int c = 0; c < 3; c++) {
        double d = fabs(mt_mean(a, c) - expect[c]) - rel * fabs(expect[c]) - 1e-7, se = mt_se(a, c);
        double zc = d <= 0.0 ? 0.0 : (se > 0.0 ? d / se : INFINITY);
        z = isnan(d) ? INFINITY : fmax(z, zc);
    }
    return z;
}

int mt_check(const char *head, const mt_acc *a, const double expect[3], double rel, const char *tail)
{
    char line[512];
    size_t k = (size_t)snprintf(line, sizeof line, "%s", head);
    int bad = 0;
    for (int c = 0; c < 3; c++) {
        double m = mt_mean(a, c), se = mt_se(a, c), e = expect[c];
        bad |= !stat_z_ok(m, se, e, rel * fabs(e) + 1e-7);
        k += (size_t)snprintf(line + k, sizeof line - k, "  %.5f+-%.5f (%.5f, z %+.1f)", m, se, e,
                              se > 0 ? (m - e) / se : 0.0);
    }
    double wmax = fmax(a->amax[0], fmax(a->amax[1], a->amax[2]));
    if (wmax > 1.0) /* weighted: the largest |sample| tells how heavy the tail is */
        snprintf(line + k, sizeof line - k, "  max |x| %.3g", wmax);
    printf("%s%s%s\n", line, tail, bad ? "  <-- FAIL" : "");
    return bad;
}

/* The empirical Bernstein bound of mt_check_bounded for channel c. */
static double eb_bound(const mt_acc *a, int c, double wmax)
{
    return stat_eb_bound(mt_var(a, c), a->n, 2.0 * fmax(wmax, a->amax[c]));
}

double mt_zmax_bounded(const mt_acc *a, const double expect[3], double wmax)
{
    double z = 0.0;
    for (int c = 0; c < 3; c++) {
        double d = fabs(mt_mean(a, c) - expect[c]);
        z = isnan(d) ? INFINITY : fmax(z, STAT_Z * d / eb_bound(a, c, wmax));
    }
    return z;
}

int mt_check_bounded(const char *head, const mt_acc *a, const double expect[3], double wmax, const char *tail)
{
    char line[512];
    size_t k = (size_t)snprintf(line, sizeof line, "%s", head);
    int bad = 0;
    for (int c = 0; c < 3; c++) {
        double m = mt_mean(a, c), e = expect[c], b = eb_bound(a, c, wmax);
        stat_count(1, stat_tail2(STAT_Z));
        bad |= !(fabs(m - e) <= b);
        k += (size_t)snprintf(line + k, sizeof line - k, "  %.5f+-%.5f (%.5f, max %.3g)", m, b, e, a->amax[c]);
    }
    printf("%s  (W %g)%s%s\n", line, wmax, tail, bad ? "  <-- FAIL" : "");
    return bad;
}
