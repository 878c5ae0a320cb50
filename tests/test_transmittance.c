/* test_transmittance.c — the transmittance-estimator plugins (murk/transmittance.h) in-process, against
 * closed forms, and the image they render.
 *
 * Scenes are written to tmp_dir() and loaded with murk_scene_load (plugins from the build tree); each
 * medium is `type: delta, transmittance: ESTIMATOR`, and the estimate is taken through
 * murk_medium_transmittance() exactly as the path tracer's shadow rays take it, with a uniform hero per
 * call and beta = (1, 1, 1).
 *
 *   closed forms   homogeneous slab (D = 0.75), the checker grid (8^3 voxels 0.2 / 1.4, a ray along x
 *                  through a row of voxel centres: D = the row's mean), a linear density ramp (D = 0.75 /
 *                  d.z), each grey and chromatic: for every unbiased estimator the mean of N estimates
 *                  lies within 4 standard errors (sample variance) of exp(-sigma_t,c D) in every channel,
 *                  and the figure can see a 3% error (>= 5 se in its best channel), as in test_media.c.
 *   bounds fail    the sinusoid grid with majorant_factor 0.6 (density above the majorant in places) and
 *                  residual_ratio's control 2 (control above the density in places): still unbiased
 *                  (reference: quadrature of the interpolated field); no resolution demanded.
 *   variance       on a constant density (majorant exact and 2x loose): unbiased_raymarch has zero
 *                  variance (asserted < 1e-12 T^2: float rounding), residual_ratio too (its control is
 *                  exact); track_length has the largest variance of all (ratio ties with it where the
 *                  majorant is exact; strictly below where it is loose); the same on the ramp and the
 *                  checker. The variances are printed.
 *   raymarch bias  on the sinusoid, sigma_t 4: jittered, the mean's bias on one ray (> 4 se at the coarse
 *                  step); midpoint, the RMS relative error over 64 rays. Measured non-zero at the coarse
 *                  step, never growing as the step halves, and at least 4x smaller at 1/16 of the step.
 *   image          cornell_smoke (32x32) with every unbiased estimator against ratio: block-wise z-test
 *                  (img_stack_agree); raymarch with a coarse step must DIFFER (the comparison sees its
 *                  bias). */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "density.h"
#include "host.h"
#include "media.h"
#include "scene.h"

static int nfail;

typedef struct espec {
    const char *label;
    const char *keys; /* the medium's estimator and extra keys */
    int weighted;     /* a bound fails on purpose: no resolution demanded */
} espec;

static const espec UNBIASED[] = {
    {"ratio", "transmittance: ratio", 0},
    {"residual_ratio", "transmittance: residual_ratio", 0},
    {"residual_ratio_c0.5", "transmittance: { type: residual_ratio, control: 0.5 }", 0},
    {"track_length", "transmittance: track_length", 0},
    {"unbiased_raymarch", "transmittance: unbiased_raymarch", 0},
    {"unbiased_raymarch_o3", "transmittance: { type: unbiased_raymarch, order: 3, depth_step: 4, roulette: 0.5 }", 0},
    {"power_series", "transmittance: power_series", 0},
    {"power_series_c0.5", "transmittance: { type: power_series, chunk_depth: 0.5 }", 0},
};
#define NUNBIASED ((int)(sizeof UNBIASED / sizeof UNBIASED[0]))

static murk_scene *load_media(const char *file, const char *common, const espec *es, int n)
{
    static char text[16384];
    size_t k = (size_t)snprintf(text, sizeof text, "murk: 1\nmedia:\n");
    for (int i = 0; i < n; i++)
        k += (size_t)snprintf(text + k, sizeof text - k, "  %s: { type: delta, %s, %s }\n", es[i].label, es[i].keys,
                              common);
    snprintf(text + k, sizeof text - k, "shapes: []\n");
    char err[2048];
    murk_scene *s = murk_scene_load(write_tmp(file, text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("scene load failed: %s\n%s", err, text);
    assert_int_equal((int)s->nmedia, n);
    for (int i = 0; i < n; i++)
        assert_non_null(s->media[i].m.tr_vt); /* the estimator, not the tracker's own transmittance() */
    return s;
}

static const char *save_grid(const char *name, const int res[3], murk_vec3 lo, murk_vec3 hi,
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

static float checker_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)cx, (void)cy, (void)cz;
    return ((x + y + z) & 1) ? 1.4f : 0.2f;
}
/* int_0^1 (0.2 + 1.1 z) dz = 0.75 exactly on the interpolated grid (see test_media.c) */
static float ramp_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy;
    return 0.2f + 1.1f * cz;
}
static float sinus_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z;
    return 0.18f + 0.13f * sinf(3.0f * cx + 1.0f) * sinf(2.5f * cy + 0.3f) * cosf(2.0f * cz);
}

/* optical depth (of the density) by the midpoint rule on the field as the core interpolates it */
static double quadrature(const murk_medium *m, const murk_ray *ray)
{
    const int steps = 200000;
    double h = ((double)ray->tmax - ray->tmin) / steps, acc = 0.0;
    for (int i = 0; i < steps; i++)
        acc += h * murk_media_density(m->data->density, murk_madd(ray->o, ray->d, (float)(ray->tmin + h * (i + 0.5))));
    return acc;
}

typedef struct est {
    long n;
    double k[3], s[3], s2[3]; /* sums of x - k, k the first estimate (no cancellation when all are equal) */
    double secs;
} est;

static double mean_of(const est *e, int c) { return e->k[c] + e->s[c] / (double)e->n; }
static double var_of(const est *e, int c)
{
    double m = e->s[c] / (double)e->n;
    return fmax(0.0, (e->s2[c] - (double)e->n * m * m) / (double)(e->n - 1));
}
static double se_of(const est *e, int c) { return sqrt(var_of(e, c) / (double)e->n); }

static void run(const murk_medium *m, const murk_ray *ray, long n, uint64_t seed, est *e)
{
    memset(e, 0, sizeof *e);
    e->n = n;
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x7472, 0);
    murk_path_ctx ctx;
    ctx.beta = murk_rgb1(1.0f);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    long bad = 0;
    for (long i = 0; i < n; i++) {
        ctx.hero = (int)(murk_rng_float(&rng) * 3.0f);
        murk_rgb T = murk_medium_transmittance(m, ray, &ctx, &rng);
        if (!murk_rgb_finite(T))
            bad++;
        for (int c = 0; c < 3; c++) {
            if (i == 0)
                e->k[c] = T.c[c];
            double x = (double)T.c[c] - e->k[c];
            e->s[c] += x;
            e->s2[c] += x * x;
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    e->secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (bad) {
        printf("  %-22s %ld non-finite estimates  <-- FAIL\n", m->name, bad);
        nfail++;
    }
}

/* |mean - T| <= 4 se (+ float rounding) per channel; with power, a 3% error must be >= 5 se in the
 * best-measured channel. */
static void check(const char *label, const est *e, const double T[3], int power)
{
    char line[512];
    size_t k = (size_t)snprintf(line, sizeof line, "  %-22s", label);
    int bad = 0;
    double res = 0.0;
    for (int c = 0; c < 3; c++) {
        double m = mean_of(e, c), se = se_of(e, c);
        if (!(fabs(m - T[c]) <= 4.0 * se + 2e-6 * T[c] + 1e-7))
            bad = 1;
        res = fmax(res, se > 0.0 ? 0.03 * T[c] / se : INFINITY);
        k += (size_t)snprintf(line + k, sizeof line - k, "  %.5f+-%.5f (%.5f, z %+.1f)", m, se, T[c],
                              se > 0 ? (m - T[c]) / se : 0.0);
    }
    int weak = power && res < 5.0;
    printf("%s  3%%=%.1f se  %.2f us%s%s\n", line, res, 1e6 * e->secs / (double)e->n, bad ? "  <-- FAIL" : "",
           weak ? "  <-- too noisy to see a 3% error" : "");
    nfail += bad + weak;
}

static const double GREY_ST[3] = {1.2, 1.2, 1.2}, CHROMA_ST[3] = {1.2, 1.5, 3.1};
#define GREY_KEYS "sigma_a: 0.3, sigma_s: 0.9"
#define CHROMA_KEYS "sigma_a: [0.2, 1, 3], sigma_s: [1, 0.5, 0.1]"
#define N_MAIN 100000L

typedef struct config {
    const char *name;
    const char *density; /* the density key's value */
    murk_ray ray;
    double D; /* closed-form optical depth of the density, < 0: quadrature */
} config;

/* Every estimator of es on cfg, grey and chromatic, against exp(-sigma_t scale D) (extra: more medium
 * keys, `scale` among them). Returns the estimates in
 * out[chroma][i] if out is non-NULL. */
static void check_config(const config *cfg, const char *extra, double scale, const espec *es, int n, est (*out)[16])
{
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: %s, %s%s", cfg->density, chroma ? CHROMA_KEYS : GREY_KEYS, extra);
        murk_scene *s = load_media("tr.yaml", common, es, n);
        double D = cfg->D >= 0 ? cfg->D : quadrature(&s->media[0].m, &cfg->ray), T[3];
        if (cfg->D >= 0) { /* the closed form against the field the core built */
            double q = quadrature(&s->media[0].m, &cfg->ray);
            if (!(fabs(q - cfg->D) < 1e-4 * cfg->D))
                fail_msg("%s: quadrature %.6f != closed form %.6f", cfg->name, q, cfg->D);
        }
        const double *st = chroma ? CHROMA_ST : GREY_ST;
        for (int c = 0; c < 3; c++)
            T[c] = exp(-st[c] * scale * D);
        printf("%s, %s (optical depth of the density %.5f)\n", cfg->name, chroma ? "chromatic" : "grey", D);
        for (int i = 0; i < n; i++) {
            est e;
            run(&s->media[i].m, &cfg->ray, N_MAIN, 500 + (uint64_t)i, &e);
            check(es[i].label, &e, T, !es[i].weighted);
            if (out)
                out[chroma][i] = e;
        }
        murk_scene_free(s);
    }
}

static config slab_cfg(void)
{
    return (config){"slab (constant 0.5)", "{ constant: 0.5 }",
                    {murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(0.3f, 0.4f, 1.0f)), 0.0f, 1.5f}, 0.75};
}
static config checker_cfg(void)
{
    const char *grid = save_grid("checker.vol", (int[]){8, 8, 8}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), checker_f);
    static char dens[600];
    snprintf(dens, sizeof dens, "{ grid: %s }", grid);
    double D = 0.0;
    for (int x = 0; x < 8; x++)
        D += checker_f(x, 3, 3, 0, 0, 0) / 8.0;
    float yc = 3.5f / 8.0f;
    return (config){"checker grid", dens, {murk_v3(-0.25f, yc, yc), murk_v3(1, 0, 0), 0.0f, 1.5f}, D};
}
static config ramp_cfg(void)
{
    const char *grid = save_grid("ramp.vol", (int[]){4, 4, 16}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), ramp_f);
    static char dens[600];
    snprintf(dens, sizeof dens, "{ grid: %s }", grid);
    murk_vec3 d = murk_normalize(murk_v3(0.2f, 0.1f, 1.0f));
    return (config){"linear ramp", dens, {murk_v3(0.3f, 0.4f, -0.5f), d, 0.0f, 2.5f}, 0.75 / d.z};
}
static config sinus_cfg(void)
{
    const char *grid = save_grid("sinus.vol", (int[]){16, 16, 16}, murk_v3(-1, -1, -1), murk_v3(1, 1, 1), sinus_f);
    static char dens[600];
    snprintf(dens, sizeof dens, "{ grid: %s }", grid);
    return (config){"sinusoid", dens,
                    {murk_v3(-1.5f, -1.2f, -1.4f), murk_normalize(murk_v3(1.0f, 0.8f, 0.9f)), 1.0f, 4.0f}, -1.0};
}

/* ---- closed forms ------------------------------------------------------------------------------ */

static void test_slab(void **state)
{
    (void)state;
    nfail = 0;
    config c = slab_cfg();
    check_config(&c, "", 1.0, UNBIASED, NUNBIASED, NULL);
    assert_int_equal(nfail, 0);
}

static void test_checker(void **state)
{
    (void)state;
    nfail = 0;
    config c = checker_cfg();
    check_config(&c, "", 1.0, UNBIASED, NUNBIASED, NULL);
    assert_int_equal(nfail, 0);
}

static void test_ramp(void **state)
{
    (void)state;
    nfail = 0;
    config c = ramp_cfg();
    check_config(&c, "", 1.0, UNBIASED, NUNBIASED, NULL);
    assert_int_equal(nfail, 0);
}

/* Density above the majorant (majorant_factor 0.6) and a control above the density (residual_ratio
 * control 2 / 3): weighted, still unbiased. Thinned to scale 0.5 (as test_media.c's majorant test: the
 * weights are heavy-tailed). */
static void test_bounds_fail(void **state)
{
    (void)state;
    nfail = 0;
    static const espec es[] = {
        {"ratio", "transmittance: ratio", 1},
        {"residual_ratio", "transmittance: residual_ratio", 1},
        {"residual_ratio_c2", "transmittance: { type: residual_ratio, control: 2 }", 1},
        {"residual_ratio_c3", "transmittance: { type: residual_ratio, control: 3 }", 1},
        {"track_length", "transmittance: track_length", 1},
        {"unbiased_raymarch", "transmittance: unbiased_raymarch", 1},
        {"power_series", "transmittance: power_series", 1},
    };
    config c = sinus_cfg();
    c.name = "sinusoid, majorant_factor 0.6, scale 0.5";
    check_config(&c, ", majorant_factor: 0.6, scale: 0.5", 0.5, es, (int)(sizeof es / sizeof es[0]), NULL);
    /* the control alone above the density, with a bounding majorant */
    static const espec es2[] = {
        {"residual_ratio_c2", "transmittance: { type: residual_ratio, control: 2 }", 1},
        {"residual_ratio_c4", "transmittance: { type: residual_ratio, control: 4 }", 1},
    };
    c.name = "sinusoid, residual control above the density";
    check_config(&c, "", 1.0, es2, 2, NULL);
    assert_int_equal(nfail, 0);
}

/* ---- variance ordering ------------------------------------------------------------------------- */

static void test_variance(void **state)
{
    (void)state;
    nfail = 0;
    static const espec es[] = {
        {"ratio", "transmittance: ratio", 0},
        {"residual_ratio", "transmittance: residual_ratio", 0},
        {"track_length", "transmittance: track_length", 0},
        {"unbiased_raymarch", "transmittance: unbiased_raymarch", 0},
        {"power_series", "transmittance: power_series", 0},
    };
    enum { RATIO, RESIDUAL, TL, URM, PS, NE };
    config cfgs[4] = {slab_cfg(), slab_cfg(), ramp_cfg(), checker_cfg()};
    const char *extra[4] = {"", ", majorant_factor: 2", "", ""};
    cfgs[1].name = "slab (constant 0.5), majorant x2";
    static est out[2][16];
    for (int k = 0; k < 4; k++) {
        check_config(&cfgs[k], extra[k], 1.0, es, NE, out);
        for (int chroma = 0; chroma < 2; chroma++) {
            printf("  variance per channel (%s):\n", chroma ? "chromatic" : "grey");
            for (int i = 0; i < NE; i++)
                printf("    %-20s %.3e %.3e %.3e\n", es[i].label, var_of(&out[chroma][i], 0), var_of(&out[chroma][i], 1),
                       var_of(&out[chroma][i], 2));
            for (int c = 0; c < 3; c++) {
                double vtl = var_of(&out[chroma][TL], c);
                /* ratio tracking is track length's expectation given the tentative collisions (Rao-
                 * Blackwell), so it can only be less variable, and equally so where every weight is 0 or
                 * 1 (an exact majorant: the slab, nearly on the ramp). Where the majorant is loose
                 * (slab x2, checker) every estimator must be clearly below (5%); elsewhere not above it
                 * beyond noise (a sample variance of n = 1e5 has relative se < 0.5% here: 2% margin). */
                double margin = (k == 1 || k == 3) ? 0.95 : 1.02;
                for (int i = 0; i < NE; i++) {
                    if (i != TL && !(var_of(&out[chroma][i], c) < margin * vtl)) {
                        printf("    %s variance %.3e not below track_length's %.3e (channel %d)  <-- FAIL\n",
                               es[i].label, var_of(&out[chroma][i], c), vtl, c);
                        nfail++;
                    }
                }
                if (k < 2) { /* constant density: the ray-marched control is exact */
                    double T = exp(-(chroma ? CHROMA_ST : GREY_ST)[c] * 0.75);
                    if (!(var_of(&out[chroma][URM], c) <= 1e-12 * T * T)) {
                        printf("    unbiased_raymarch variance %.3e on constant density (channel %d)  <-- FAIL\n",
                               var_of(&out[chroma][URM], c), c);
                        nfail++;
                    }
                    if (!(var_of(&out[chroma][RESIDUAL], c) <= 1e-10 * T * T)) {
                        printf("    residual_ratio variance %.3e on constant density (channel %d)  <-- FAIL\n",
                               var_of(&out[chroma][RESIDUAL], c), c);
                        nfail++;
                    }
                }
            }
        }
    }
    assert_int_equal(nfail, 0);
}

/* ---- raymarch's bias ---------------------------------------------------------------------------- */

static void test_raymarch_bias(void **state)
{
    (void)state;
    nfail = 0;
    static const double steps[] = {0.4, 0.2, 0.1, 0.05, 0.025};
    enum { NS = 5, NRAYS = 64 };
    for (int jitter = 1; jitter >= 0; jitter--) {
        espec es[NS];
        static char keys[NS][128], labels[NS][32];
        for (int i = 0; i < NS; i++) {
            snprintf(keys[i], sizeof keys[i], "transmittance: { type: raymarch, step: %g, jitter: %s }", steps[i],
                     jitter ? "true" : "false");
            snprintf(labels[i], sizeof labels[i], "raymarch_%g", steps[i]);
            es[i] = (espec){labels[i], keys[i], 1};
        }
        config c = sinus_cfg();
        char common[1024]; /* denser than the closed-form tests (sigma_t 4), so that the bias is large */
        snprintf(common, sizeof common, "density: %s, sigma_a: 1, sigma_s: 3", c.density);
        murk_scene *s = load_media("rm.yaml", common, es, NS);
        double bias[NS], se[NS];
        if (jitter) { /* one ray, many jittered marches: the mean's bias (Jensen) against its se */
            double D = quadrature(&s->media[0].m, &c.ray), T = exp(-4.0 * D);
            printf("raymarch bias, sinusoid, sigma_t 4, jittered, one ray (optical depth %.4f, T %.5f):\n", 4.0 * D, T);
            for (int i = 0; i < NS; i++) {
                est e;
                run(&s->media[i].m, &c.ray, 200000L, 900 + (uint64_t)i, &e);
                bias[i] = mean_of(&e, 0) - T;
                se[i] = se_of(&e, 0);
                printf("  step %-6g mean %.6f +- %.6f  bias %+.3e (%+.1f se, relative %+.2e)\n", steps[i],
                       mean_of(&e, 0), se[i], bias[i], bias[i] / se[i], bias[i] / T);
            }
        } else { /* deterministic: its error on one ray oscillates with the step (the field's edges meet
                  * the lattice at other phases), so the bias is the RMS relative error over 64 rays */
            printf("raymarch bias, sinusoid, sigma_t 4, midpoint, RMS relative error over %d rays:\n", NRAYS);
            murk_rng rng;
            murk_rng_seed(&rng, 31, 41, 59);
            double sq[NS] = {0};
            for (int r = 0; r < NRAYS; r++) {
                murk_vec3 o = murk_v3(2.0f * murk_rng_float(&rng) - 1.0f, 2.0f * murk_rng_float(&rng) - 1.0f, -1.6f);
                murk_vec3 d = murk_normalize(murk_v3(0.6f * (murk_rng_float(&rng) - 0.5f),
                                                     0.6f * (murk_rng_float(&rng) - 0.5f), 1.0f));
                murk_ray ray = {o, d, 0.0f, 3.5f};
                double T = exp(-4.0 * quadrature(&s->media[0].m, &ray));
                for (int i = 0; i < NS; i++) {
                    murk_path_ctx ctx = {0, murk_rgb1(1.0f)};
                    murk_rgb e = murk_medium_transmittance(&s->media[i].m, &ray, &ctx, &rng);
                    sq[i] += pow((e.c[0] - T) / T, 2);
                }
            }
            for (int i = 0; i < NS; i++) {
                bias[i] = sqrt(sq[i] / NRAYS);
                se[i] = 0.0;
                printf("  step %-6g RMS relative error %.3e\n", steps[i], bias[i]);
            }
        }
        if (!(fabs(bias[0]) > 4.0 * se[0] + 1e-6)) {
            printf("  the coarse step's bias is not measurable  <-- FAIL\n");
            nfail++;
        }
        /* shrinks: no halving of the step makes it grow beyond noise, and over the range (16x) it falls
         * by at least 4x */
        for (int i = 1; i < NS; i++)
            if (!(fabs(bias[i]) <= fabs(bias[i - 1]) + 4.0 * sqrt(se[i] * se[i] + se[i - 1] * se[i - 1]) + 1e-7)) {
                printf("  bias grew from step %g to %g  <-- FAIL\n", steps[i - 1], steps[i]);
                nfail++;
            }
        if (!(fabs(bias[NS - 1]) < 0.25 * fabs(bias[0]))) {
            printf("  bias did not shrink 4x from step %g to %g  <-- FAIL\n", steps[0], steps[NS - 1]);
            nfail++;
        }
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* ---- image invariance --------------------------------------------------------------------------- */

#define IMG_SEEDS 6

static void render_with(const char *estimator, img_stack *st)
{
    char set[256];
    snprintf(set, sizeof set, "media.smoke.transmittance=%s", estimator);
    const char *extra[] = {"--set", "render.resolution=[32, 32]", "--spp", "96", "--set", set, NULL};
    img_stack_free(st);
    img_stack_render(st, src_path("scenes/cornell_smoke.yaml"), "smoke.exr", IMG_SEEDS, 200, extra);
}

static void test_image(void **state)
{
    (void)state;
    nfail = 0;
    img_stack ref = {0}, m = {0};
    render_with("ratio", &ref);
    printf("cornell_smoke, 32x32, %d seeds x 96 spp, against ratio:\n", IMG_SEEDS);
    static const char *const est[] = {"residual_ratio", "track_length", "unbiased_raymarch", "power_series"};
    for (size_t i = 0; i < sizeof est / sizeof est[0]; i++) {
        render_with(est[i], &m);
        if (!img_stack_agree(est[i], &m, &ref, 4, 4.5))
            nfail++;
    }
    /* the negative control: the biased baseline with a coarse step must be told apart */
    render_with("{type: raymarch, step: 0.4, jitter: false}", &m);
    if (img_stack_agree("raymarch step 0.4 midpoint (must DIFFER)", &m, &ref, 4, 4.5)) {
        printf("  the comparison cannot see raymarch's bias  <-- FAIL\n");
        nfail++;
    }
    img_stack_free(&ref);
    img_stack_free(&m);
    assert_int_equal(nfail, 0);
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab),     cmocka_unit_test(test_checker),       cmocka_unit_test(test_ramp),
        cmocka_unit_test(test_bounds_fail), cmocka_unit_test(test_variance), cmocka_unit_test(test_raymarch_bias),
        cmocka_unit_test(test_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
