/* test_envlights.c — the lights of the `lights:` block (render/lights.h) against closed forms, each
 * check with a must-fail twin that shows it sees a 1 % error:
 *
 *   envmap_chi2        directions sampled by light sampling from a scene holding one environment map
 *                      (constant, one bright texel, a gradient; rotated 30 degrees), binned by texel
 *                      groups of the map, against N x the pdf environment_pdf() gives, integrated over
 *                      each bin (exact: the pdf times sin theta is constant over a texel); chi-square
 *                      p >= 1e-6 (stat.h); a sampler that moves 1 % of the samples from the map's right
 *                      half to its left is rejected (must-fail).
 *   envmap_pdf         environment_pdf integrates to 1 over the sphere (midpoint rule on a grid aligned
 *                      with the texels: exact up to rounding) within 1e-3, 1.01 x it does not; the texel
 *                      a direction reads is the one envmap.h's mapping names.
 *   env_mis            the irradiance a point receives from an envmap plus a sun of 10 degrees, by light
 *                      sampling alone, by cosine sampling alone and by their power-heuristic MIS: the
 *                      three agree within 5 sigma (independent streams); light sampling with its pdf 1 %
 *                      too high does not (must-fail; MIS and the mutant with 4 x 10^6 samples, where 1 %
 *                      is 12 to 19 of their standard errors).
 *   point_spot         a point light's and a spot's irradiance at points of a plane by light sampling
 *                      (delta: exact) against I cos / r^2 times pbrt-v4's smoothstep, to 1e-5; 1.01 x the
 *                      closed form fails.
 *   selection_by_power a point, a spot, a delta sun and an envmap in one scene are chosen in the ratios of
 *                      their powers (the bounding radius cancelled), exactly (1e-5); 1.01 x fails.
 *   furnace            a white diffuse sphere under a constant envmap renders the map's radiance (mean
 *                      over the image within 5 sigma of 1); an albedo-0.99 sphere is rejected (must-fail);
 *                      so does a map of half that radiance beside a constant `background` of the other
 *                      half (the background then sampled as a part of the environment); 1.01 x fails.
 *   sun_plane          a diffuse plane under a distant light renders albedo / pi E cos theta: exactly for
 *                      a delta sun, within 5 sigma for a 40-degree cone above the horizon and for one that
 *                      the horizon cuts (the closed form integrated numerically); 1.01 x fails (must-fail).
 *   slab               the same plane under a delta sun through an absorbing chromatic slab: times
 *                      exp(-sigma_t d / cos theta), for every tracker's own transmittance and every
 *                      transmittance estimator (the shadow ray runs to infinity through the slab's box);
 *                      1.01 x fails.
 *   equiangular_punctual volpath_nee's single scattering (max_depth 1) of a point and of a spot light
 *                      along one ray through a grey homogeneous medium, equiangular sampling towards the
 *                      light on and off, against the integral along the ray (midpoint rule); 1.01 x fails.
 *   legacy             an integrator of ABI 1.6 gets only the emissive shapes to sample, never more than
 *                      its struct, and is refused a scene with a delta light; background() still
 *                      holds the environment.
 *   bad_input          each bad light is a located error and writes nothing (an envmap that is not
 *                      lat-long, not an EXR, empty, has a NaN, infinite or negative texel, or is over the
 *                      image limit; a direction of length 0; a diameter of 180; a spot cone narrower than
 *                      its falloff); a sun below the horizon renders black with a warning.
 * Fixed seeds throughout; every statistical decision goes through stat.h (5 sigma, chi-square p >= 1e-6,
 * counted for the suite's family-wise rate in tests/README.md). */
#include "stat.h"
#include "image/image.h"
#include "render/envmap.h"
#include "render/host.h"
#include "render/lights.h"
#include "scene/scene.h"

#include "murk/math.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---- helpers --------------------------------------------------------------------------------------- */

static murk_scene *load_text(const char *name, const char *text)
{
    char err[1024];
    murk_scene *s = murk_scene_load(write_tmp(name, text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    return s;
}

enum { MAP_CONSTANT, MAP_TEXEL, MAP_GRADIENT, NMAPS };
static const char *const MAP_NAME[NMAPS] = {"constant", "bright texel", "gradient"};
enum { MW = 32, MH = 16 };

/* Writes map k (MW x MH) as tmp_dir()/map_K.exr and returns its texels in rgb. */
static const char *write_map(int k, float *rgb)
{
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW; i++) {
            float *t = &rgb[3 * (j * MW + i)];
            if (k == MAP_CONSTANT)
                t[0] = t[1] = t[2] = 1.0f;
            else if (k == MAP_TEXEL)
                t[0] = t[1] = t[2] = (i == 21 && j == 5) ? 1000.0f : 0.01f;
            else {
                t[0] = 0.1f + 2.0f * (float)i / MW;
                t[1] = 0.1f + (float)j / MH;
                t[2] = 0.3f;
            }
        }
    char name[64], err[256];
    snprintf(name, sizeof name, "map_%d.exr", k);
    const char *path = tmp_path(name);
    if (murk_exr_write(path, rgb, MW, MH, NULL, 0, err, sizeof err))
        fail_msg("%s", err);
    return path;
}

/* A scene of one diffuse quad far below and lights given as YAML list items. */
static murk_scene *lights_scene(const char *name, const char *lights)
{
    char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [8, 8] }\nintegrator: { type: volpath_nee }\n"
             "materials: { m: { type: diffuse, albedo: 0.5 } }\nlights:\n%s"
             "shapes:\n  - { type: quad, center: [0, -50, 0], u: [1, 0, 0], v: [0, 0, -1], material: m }\n",
             lights);
    return load_text(name, text);
}

static void map_uv(murk_vec3 d, double rot_deg, double *u, double *v)
{
    double a = rot_deg * M_PI / 180.0, c = cos(a), s = sin(a);
    double x = c * d.x - s * d.z, z = s * d.x + c * d.z; /* R_y(-rotation) */
    *u = 0.5 + atan2(x, -z) / (2.0 * M_PI);
    *v = acos(fmin(1.0, fmax(-1.0, (double)d.y))) / M_PI;
}

/* The world direction of map coordinates (u, v) (envmap.h's mapping, then R_y(rotation)). */
static murk_vec3 uv_dir(double u, double v, double rot_deg)
{
    double th = M_PI * v, ph = 2.0 * M_PI * (u - 0.5), a = rot_deg * M_PI / 180.0;
    double x = sin(th) * sin(ph), y = cos(th), z = -sin(th) * cos(ph);
    return murk_v3((float)(cos(a) * x + sin(a) * z), (float)y, (float)(-sin(a) * x + cos(a) * z));
}

/* ---- envmap sampling ----------------------------------------------------------------------------- */

enum { BU = 8, BV = 4 }; /* bins of 4 x 4 texels */

static double envmap_chi2_p(const murk_scene *s, double rot, int mutant, long n, uint64_t seed)
{
    const murk_host *h = murk_host_table();
    double obs[BU * BV] = {0}, exp_[BU * BV] = {0};
    /* expected: the pdf at each texel's centre x 2 pi^2 sin(theta) x its (u, v) area, summed per bin */
    for (int j = 0; j < MH; j++)
        for (int i = 0; i < MW; i++) {
            double u = (i + 0.5) / MW, v = (j + 0.5) / MH;
            double pdf = h->environment_pdf(s, uv_dir(u, v, rot));
            exp_[(j / (MH / BV)) * BU + i / (MW / BU)] += n * pdf * 2.0 * M_PI * M_PI * sin(M_PI * v) / (MW * MH);
        }
    murk_rng rng;
    murk_rng_seed(&rng, seed, 1, 2);
    for (long k = 0; k < n; k++) {
        float uu[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_light_sample ls;
        ls.flags = 0;
        if (!h->sample_light_with(s, murk_v3(0, 0, 0), uu, MURK_LIGHT_AREA, &ls))
            continue;
        double u, v;
        map_uv(ls.wi, rot, &u, &v);
        if (mutant && u >= 0.5 && murk_rng_float(&rng) < 0.02f)
            u -= 0.5; /* 1 % of all samples moved from the right half to the left */
        int bi = (int)fmin(BU - 1, u * BU), bj = (int)fmin(BV - 1, v * BV);
        obs[bj * BU + bi] += 1.0;
    }
    int dof;
    return chi2_test(obs, exp_, BU * BV, 5.0, &dof);
}

static void test_envmap_chi2(void **state)
{
    (void)state;
    float rgb[3 * MW * MH];
    for (int k = 0; k < NMAPS; k++) {
        char lights[512];
        snprintf(lights, sizeof lights, "  - { type: envmap, file: %s, rotation: 30 }\n", write_map(k, rgb));
        murk_scene *s = lights_scene("chi2.yaml", lights);
        double p = envmap_chi2_p(s, 30.0, 0, stat_n(400000), 11 + (uint64_t)k);
        double pm = envmap_chi2_p(s, 30.0, 1, stat_n(400000), 11 + (uint64_t)k);
        printf("%-13s chi-square p = %.3g; with 1 %% of the samples moved: p = %.3g\n", MAP_NAME[k], p, pm);
        murk_scene_free(s);
        char label[96];
        snprintf(label, sizeof label, "envmap chi2 %s, 1 %% of the samples moved", MAP_NAME[k]);
        assert_true(stat_chi2_ok(p));
        assert_true(stat_must_fail_chi2(label, pm));
    }
}

/* The integral of environment_pdf over the sphere by the midpoint rule on a grid of 4 x 4 cells per
 * texel (the pdf x sin theta is constant on a texel: the rule is exact but for rounding). */
static double pdf_integral(const murk_scene *s, double rot)
{
    const murk_host *h = murk_host_table();
    int nu = 4 * MW, nv = 4 * MH;
    double sum = 0.0;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            double u = (i + 0.5) / nu, v = (j + 0.5) / nv;
            sum += h->environment_pdf(s, uv_dir(u, v, rot)) * sin(M_PI * v) * (2.0 * M_PI / nu) * (M_PI / nv);
        }
    return sum;
}

static void test_envmap_pdf(void **state)
{
    (void)state;
    float rgb[3 * MW * MH];
    const murk_host *h = murk_host_table();
    for (int k = 0; k < NMAPS; k++) {
        char lights[512];
        snprintf(lights, sizeof lights, "  - { type: envmap, file: %s, rotation: 30 }\n", write_map(k, rgb));
        murk_scene *s = lights_scene("pdf.yaml", lights);
        double I = pdf_integral(s, 30.0);
        printf("%-13s integral of the pdf %.6f (1.01 x it: %.6f)\n", MAP_NAME[k], I, 1.01 * I);
        assert_true(fabs(I - 1.0) < 1e-3);
        assert_false(fabs(1.01 * I - 1.0) < 1e-3);
        /* the bright texel's centre reads its radiance (bilinear weights 1 there) */
        if (k == MAP_TEXEL) {
            murk_rgb L = h->background(s, uv_dir((21 + 0.5) / MW, (5 + 0.5) / MH, 30.0));
            printf("radiance at the bright texel's centre: %g\n", (double)L.c[0]);
            assert_true(fabs(L.c[0] - 1000.0f) < 0.5f);
        }
        murk_scene_free(s);
    }
}

/* ---- MIS against light-only and BSDF-only --------------------------------------------------------- */

/* Irradiance at the origin (normal n) from the scene's environment: technique 0 light sampling alone
 * (pdf x pdf_scale), 1 cosine sampling alone, 2 both by the power heuristic. mean and its standard error. */
static void irradiance(const murk_scene *s, murk_vec3 n, int tech, double pdf_scale, long N, uint64_t seed, double *mean,
                       double *se)
{
    const murk_host *h = murk_host_table();
    murk_rng rng;
    murk_rng_seed(&rng, seed, 3, (uint64_t)tech);
    murk_vec3 t, b;
    murk_basis(n, &t, &b);
    double sum = 0.0, sum2 = 0.0;
    for (long k = 0; k < N; k++) {
        float u[5];
        for (int q = 0; q < 5; q++)
            u[q] = murk_rng_float(&rng);
        double e = 0.0;
        murk_light_sample ls;
        ls.flags = 0;
        if (tech != 1 && h->sample_light_with(s, murk_v3(0, 0, 0), u, MURK_LIGHT_AREA, &ls)) {
            float c = murk_dot(ls.wi, n);
            if (c > 0.0f) {
                float pl = ls.pdf * (float)pdf_scale, pb = c * MURK_INV_PI;
                float w = tech == 2 ? pl * pl / (pl * pl + pb * pb) : 1.0f;
                e += (double)murk_luminance(ls.le) * c / pl * w;
            }
        }
        if (tech != 0) {
            float r = sqrtf(u[3]), phi = 2.0f * MURK_PI * u[4], cz = sqrtf(murk_maxf(0.0f, 1.0f - u[3]));
            murk_vec3 w = murk_from_local(murk_v3(r * cosf(phi), r * sinf(phi), cz), t, b, n);
            float pb = cz * MURK_INV_PI, pl = h->environment_pdf(s, w);
            float wt = tech == 2 ? pb * pb / (pl * pl + pb * pb) : 1.0f;
            if (cz > 0.0f)
                e += (double)murk_luminance(h->background(s, w)) * MURK_PI * wt;
        }
        sum += e;
        sum2 += e * e;
    }
    *mean = sum / N;
    *se = sqrt(fmax(0.0, sum2 / N - *mean * *mean) / N);
}

static void test_env_mis(void **state)
{
    (void)state;
    float rgb[3 * MW * MH];
    const char *map = write_map(MAP_GRADIENT, rgb);
    char lights[512];
    snprintf(lights, sizeof lights,
             "  - { type: envmap, file: %s, rotation: 30 }\n"
             "  - { type: distant, direction: [0.3, 1, 0.2], irradiance: 3, angular_diameter: 10 }\n", map);
    murk_scene *s = lights_scene("mis.yaml", lights);
    const murk_vec3 normals[2] = {murk_normalize(murk_v3(0.1f, 1, 0.3f)), murk_normalize(murk_v3(1, 0.2f, -0.4f))};
    for (int q = 0; q < 2; q++) {
        double m[3], e[3], mb, eb;
        /* MIS and the mutant with 4x the samples, so that a 1 % error is ~13 of their standard errors */
        for (int tech = 0; tech < 3; tech++)
            irradiance(s, normals[q], tech, 1.0, stat_n(tech == 2 ? 4000000 : 1000000), 5 + (uint64_t)q, &m[tech],
                       &e[tech]);
        irradiance(s, normals[q], 0, 1.01, stat_n(4000000), 7 + (uint64_t)q, &mb, &eb);
        double z01 = (m[0] - m[1]) / hypot(e[0], e[1]), z21 = (m[2] - m[1]) / hypot(e[2], e[1]),
               z20 = (m[2] - m[0]) / hypot(e[2], e[0]), zb = (mb - m[2]) / hypot(eb, e[2]);
        printf("normal %d: light %.5f +- %.5f, cosine %.5f +- %.5f, MIS %.5f +- %.5f; z light-cosine %+.2f, "
               "MIS-cosine %+.2f, MIS-light %+.2f; light with its pdf 1.01 x: z %+.1f\n", q, m[0], e[0], m[1], e[1],
               m[2], e[2], z01, z21, z20, zb);
        assert_true(stat_z_ok(m[0] - m[1], hypot(e[0], e[1]), 0.0, 0.0));
        assert_true(stat_z_ok(m[2] - m[1], hypot(e[2], e[1]), 0.0, 0.0));
        assert_true(stat_z_ok(m[2] - m[0], hypot(e[2], e[0]), 0.0, 0.0));
        char label[96];
        snprintf(label, sizeof label, "env MIS, normal %d: light sampling's pdf 1.01 x", q);
        assert_true(stat_must_fail(label, fabs(zb) > STAT_Z, zb));
    }
    murk_scene_free(s);
}

/* ---- point and spot ------------------------------------------------------------------------------- */

static void test_point_spot(void **state)
{
    (void)state;
    murk_scene *s = lights_scene("punctual.yaml",
                                 "  - { type: point, position: [0, 2, 0], intensity: [3, 2, 1] }\n"
                                 "  - { type: spot, position: [0, 2, 0], direction: [0, -1, 0], intensity: [5, 5, 5], "
                                 "cone_angle: 40, falloff_angle: 20 }\n");
    const murk_host *h = murk_host_table();
    const murk_vec3 n = murk_v3(0, 1, 0);
    double cc = cos(40 * M_PI / 180), cf = cos(20 * M_PI / 180);
    int bad = 0, bad_mutant = 0, nonzero = 0;
    for (int i = 0; i <= 30; i++) {
        murk_vec3 p = murk_v3(0.1f * (float)i, 0.0f, 0.03f * (float)i);
        double r2 = (double)p.x * p.x + 4.0 + (double)p.z * p.z, c = 2.0 / sqrt(r2);
        double ct = c, tt = (ct - cc) / (cf - cc), fall = ct >= cf ? 1.0 : ct <= cc ? 0.0 : tt * tt * (3 - 2 * tt);
        double want[2] = {3.0 * c / r2, 5.0 * fall * c / r2}; /* red channel: point, spot */
        double got[2] = {0, 0};
        for (int l = 0; l < 2; l++) { /* u[0] picks the light: below and above the cdf step */
            murk_light_sample ls;
            ls.flags = 0;
            float u[3] = {l == 0 ? 0.0f : 0.999999f, 0.5f, 0.5f};
            if (h->sample_light_with(s, p, u, MURK_LIGHT_AREA, &ls)) {
                assert_true(ls.flags & MURK_LIGHT_SAMPLE_DELTA);
                got[l] = ls.le.c[0] * murk_dot(ls.wi, n) / ls.pdf * s->lights[l].pmf;
            }
            bad += fabs(got[l] - want[l]) > 1e-5 * fmax(want[l], 1e-3);
            bad_mutant += fabs(got[l] - 1.01 * want[l]) > 1e-5 * fmax(want[l], 1e-3);
            nonzero += want[l] > 0.0;
        }
        if (i % 6 == 0)
            printf("x %.1f: point E %.6f (closed form %.6f), spot E %.6f (%.6f)\n", (double)p.x, got[0], want[0],
                   got[1], want[1]);
    }
    murk_scene_free(s);
    printf("%d of 62 values off the closed form; against 1.01 x it: %d of the %d lit ones off\n", bad, bad_mutant,
           nonzero);
    assert_int_equal(bad, 0);
    assert_int_equal(bad_mutant, nonzero);
}

/* ---- selection by power ------------------------------------------------------------------------------ */

/* A point (I 1), a spot (I 2, cone 40, falloff 20), a delta sun (E 3) and a constant envmap (L 1) in one
 * scene: their probabilities of being chosen are in the ratios of their powers (lights.h): 4 I, 2 I (1 -
 * (cos falloff + cos cone) / 2), E R^2 and R^2 x the map's integral over directions (its midpoint sum over
 * the rows, ~4 pi), R the scene's bounding radius (cancelled in the ratios checked), and sum to 1. To 1e-5;
 * a 1 % error in any ratio is seen. */
static void test_selection_by_power(void **state)
{
    (void)state;
    float rgb[3 * MW * MH];
    char lights[1024];
    snprintf(lights, sizeof lights,
             "  - { type: point, position: [0, 2, 0], intensity: 1 }\n"
             "  - { type: spot, position: [0, 2, 0], direction: [0, -1, 0], intensity: 2, cone_angle: 40, "
             "falloff_angle: 20 }\n"
             "  - { type: distant, direction: [0, 1, 0], irradiance: 3 }\n"
             "  - { type: envmap, file: %s }\n", write_map(MAP_CONSTANT, rgb));
    murk_scene *s = lights_scene("power.yaml", lights);
    assert_int_equal(s->nlights, 4);
    double rows = 0.0;
    for (int j = 0; j < MH; j++)
        rows += sin(M_PI * (j + 0.5) / MH);
    double integral = rows * MW * (2.0 * M_PI / MW) * (M_PI / MH);
    double spot = 2.0 * 2.0 * (1.0 - 0.5 * (cos(20 * M_PI / 180) + cos(40 * M_PI / 180)));
    double got[3] = {s->lights[1].pmf / s->lights[0].pmf, s->lights[3].pmf / s->lights[2].pmf,
                     (double)s->lights[0].pmf + s->lights[1].pmf + s->lights[2].pmf + s->lights[3].pmf};
    double want[3] = {spot / 4.0, integral / 3.0, 1.0};
    const char *what[3] = {"spot / point", "envmap / sun", "sum"};
    for (int k = 0; k < 3; k++) {
        printf("%-12s %.7f (power ratio %.7f)\n", what[k], got[k], want[k]);
        assert_true(fabs(got[k] / want[k] - 1.0) < 1e-5);
        assert_false(fabs(got[k] / (1.01 * want[k]) - 1.0) < 1e-5);
    }
    printf("the scene's radius from the point and the sun: R = %.4f\n",
           sqrt((double)s->lights[2].pmf / s->lights[0].pmf * 4.0 / 3.0));
    murk_scene_free(s);
}

/* ---- images ---------------------------------------------------------------------------------------- */

/* Renders scene text (with extra --set arguments, NULL-terminated) and returns the red channel's mean
 * over the image and its standard error (the pixels are independent samples of one expected value). */
static void render_mean(const char *name, const char *text, const char *const *extra, double *mean, double *se)
{
    const char *scene = write_tmp(name, text);
    char exr[1024];
    snprintf(exr, sizeof exr, "%s/%s.exr", tmp_dir(), name);
    const char *args[] = {"render", scene, "-o", exr, "--threads", "2", "--quiet", NULL};
    run_murk_ok(args, extra);
    murk_image img;
    char err[512];
    if (murk_exr_read(exr, &img, err, sizeof err))
        fail_msg("%s", err);
    double sum = 0.0, sum2 = 0.0;
    size_t n = (size_t)img.w * (size_t)img.h;
    for (size_t i = 0; i < n; i++) {
        sum += img.rgb[3 * i];
        sum2 += (double)img.rgb[3 * i] * img.rgb[3 * i];
    }
    *mean = sum / (double)n;
    *se = sqrt(fmax(0.0, sum2 / (double)n - *mean * *mean) / (double)n);
    murk_image_free(&img);
}

/* The mean agrees with want when it is within STAT_Z standard errors plus `slack` x want (slack: a known
 * deterministic error, e.g. the ray offsets' 1e-4 at each boundary crossing); asserts it does, and that
 * 1.01 x want does not (the must-fail case: a 1 % error). */
static void check_closed_form(const char *label, double mean, double se, double want, double slack)
{
    double z = (fabs(mean - want) - slack * want) / fmax(se, 1e-300);
    double zb = (fabs(mean - 1.01 * want) - slack * want) / fmax(se, 1e-300);
    printf("%-34s %.6f +- %.6f, closed form %.6f (%+.1e): z %+.2f; against 1.01 x it: z %+.1f (z beyond the "
           "slack %g)\n", label, mean, se, want, mean / want - 1.0, fmax(z, 0.0), fmin(zb, 999.0), slack);
    assert_true(stat_z_ok(mean, se, want, slack * want));
    char mf[160];
    snprintf(mf, sizeof mf, "%s against 1.01 x the closed form", label);
    assert_true(stat_must_fail(mf, zb > STAT_Z, zb));
}

static void test_furnace(void **state)
{
    (void)state;
    float rgb[3 * MW * MH];
    char text[1024];
    const char *map = write_map(MAP_CONSTANT, rgb);
    for (int k = 0; k < 3; k++) { /* 2: half the radiance from the map, half from a constant background */
        snprintf(text, sizeof text,
                 "murk: 1\nrender: { resolution: [32, 32], spp: 64, seed: 1 }\n%s"
                 "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 25 }\n"
                 "integrator: { type: volpath_nee }\nmaterials: { w: { type: diffuse, albedo: %s } }\n"
                 "lights: [ { type: envmap, file: %s, scale: %s } ]\n"
                 "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: w } ]\n",
                 k == 2 ? "background: 0.5\n" : "", k == 1 ? "0.99" : "1", map, k == 2 ? "0.5" : "1");
        double m, se;
        render_mean("furnace.yaml", text, NULL, &m, &se);
        double z = (m - 1.0) / se;
        printf("white furnace, albedo %s%s: %.6f +- %.6f (z %+.2f against 1)\n", k == 1 ? "0.99" : "1",
               k == 2 ? ", map 0.5 + background 0.5" : "", m, se, z);
        if (k == 0)
            assert_true(stat_z_ok(m, se, 1.0, 0.0));
        else if (k == 1) /* the 1 %-darker sphere is seen */
            assert_true(stat_must_fail("white furnace with albedo 0.99", fabs(z) > STAT_Z, z));
        else /* the constant background sampled as one more part of the environment */
            check_closed_form("furnace, map 0.5 + background 0.5", m, se, 1.0, 0.0);
    }
}

/* The plane's irradiance / E from a uniform cone of half-angle a around a direction at theta from its
 * normal, clipped by its horizon: (1 / (pi sin^2 a)) x the integral of max(0, cos) over the cone. */
static double cone_irradiance(double theta, double a)
{
    enum { NT = 2000, NP = 2000 };
    double sum = 0.0, st = sin(theta), ct = cos(theta);
    for (int i = 0; i < NT; i++) {
        double al = a * (i + 0.5) / NT;
        for (int j = 0; j < NP; j++) {
            double ph = 2.0 * M_PI * (j + 0.5) / NP;
            double c = cos(al) * ct + sin(al) * cos(ph) * st; /* the cone's direction . the normal */
            sum += c > 0.0 ? c * sin(al) : 0.0;
        }
    }
    sum *= (a / NT) * (2.0 * M_PI / NP);
    return sum / (M_PI * sin(a) * sin(a));
}

static const char *sun_scene(char *text, size_t len, double theta_deg, double diam, const char *extra_shapes,
                             const char *media)
{
    double th = theta_deg * M_PI / 180.0;
    snprintf(text, len,
             "murk: 1\nrender: { resolution: [16, 16], spp: 256, seed: 2 }\n"
             "camera: { from: [0, 0.5, 0.001], at: [0, 0, 0], up: [0, 0, -1], fov: 20 }\n"
             "integrator: { type: volpath_nee }\nmaterials: { w: { type: diffuse, albedo: 0.5 } }\n%s"
             "lights: [ { type: distant, direction: [%.9f, %.9f, 0], irradiance: 2, angular_diameter: %g } ]\n"
             "shapes:\n  - { type: quad, center: [0, 0, 0], u: [100, 0, 0], v: [0, 0, -100], material: w }\n%s",
             media, sin(th), cos(th), diam, extra_shapes);
    return text;
}

static void test_sun_plane(void **state)
{
    (void)state;
    char text[2048];
    double m, se;
    render_mean("sun_delta.yaml", sun_scene(text, sizeof text, 35, 0, "", ""), NULL, &m, &se);
    check_closed_form("delta sun at 35 degrees", m, se, 0.5 / M_PI * 2.0 * cos(35 * M_PI / 180), 1e-5);
    render_mean("sun_cone.yaml", sun_scene(text, sizeof text, 50, 40, "", ""), NULL, &m, &se);
    check_closed_form("40-degree sun at 50 degrees", m, se, 0.5 / M_PI * 2.0 * cos(50 * M_PI / 180), 0.0);
    render_mean("sun_cut.yaml", sun_scene(text, sizeof text, 80, 40, "", ""), NULL, &m, &se);
    check_closed_form("40-degree sun at 80 degrees (cut)", m, se,
                      0.5 / M_PI * 2.0 * cone_irradiance(80 * M_PI / 180, 20 * M_PI / 180), 0.0);
}

/* The delta sun at 40 degrees through a slab y in [0.6, 0.9] (index-matched box) of an absorbing
 * chromatic medium, seen from below it (the camera at 0.5): red's sigma_t is 0.8 per unit length. */
static void test_slab(void **state)
{
    (void)state;
    static const char *const variants[][2] = {
        {"delta", NULL}, {"decomposition", NULL}, {"spectral", NULL}, {"spectral_mis", NULL}, {"naive_spectral", NULL},
        {"delta", "ratio"}, {"delta", "residual_ratio"}, {"delta", "track_length"}, {"delta", "power_series"},
        {"delta", "unbiased_raymarch"}, {"delta", "raymarch"},
    };
    char text[2048];
    sun_scene(text, sizeof text, 40, 0,
              "  - { type: box, min: [-100, 0.6, -100], max: [100, 0.9, 100], interior: slab }\n",
              "media: { slab: { type: delta, density: { constant: 1 }, sigma_a: [0.8, 1.6, 3.2], sigma_s: 0 } }\n");
    double c = cos(40 * M_PI / 180), want = 0.5 / M_PI * 2.0 * c * exp(-0.8 * 0.3 / c);
    for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
        char type[128], tr[128], label[128];
        snprintf(type, sizeof type, "media.slab.type=%s", variants[v][0]);
        snprintf(tr, sizeof tr, "media.slab.transmittance.type=%s", variants[v][1] ? variants[v][1] : "");
        /* the noisy estimators (ratio, track_length) with 4x the samples, so a 1 % error stands out */
        int noisy = variants[v][1] && (!strcmp(variants[v][1], "ratio") || !strcmp(variants[v][1], "track_length"));
        const char *extra[] = {"--spp", noisy ? "1024" : "256", "--set", type, variants[v][1] ? "--set" : NULL, tr, NULL};
        double m, se;
        render_mean("slab.yaml", text, extra, &m, &se);
        snprintf(label, sizeof label, "slab: %s%s%s", variants[v][0], variants[v][1] ? " + " : "",
                 variants[v][1] ? variants[v][1] : "");
        check_closed_form(label, m, se, want, 3e-4); /* two crossings' offsets: 1.3e-4 of the optical depth */
    }
}

/* ---- equiangular sampling towards point and spot lights ---------------------------------------------- */

/* Single scattering of a point (spot = 0) or spot light at (0, 1, -2) along the ray from the origin down
 * -z through a grey homogeneous medium (sigma_s 0.5, sigma_t 0.6, isotropic) that ends at z = -10: the
 * integral over t of sigma_s exp(-sigma_t t) I f(t) exp(-sigma_t r) / (4 pi r^2), r the distance from
 * the ray's point to the light, f the spot's smoothstep in the cosine of its angle from the axis
 * (straight down; cone 40, falloff 20 degrees), by the midpoint rule (1e6 steps: exact to ~1e-9). */
static double single_scatter(int spot)
{
    const double ss = 0.5, st = 0.6, cc = cos(40 * M_PI / 180), cf = cos(20 * M_PI / 180);
    const int n = 1000000;
    double sum = 0.0, dt = 10.0 / n;
    for (int i = 0; i < n; i++) {
        double t = (i + 0.5) * dt, r2 = 1.0 + (t - 2.0) * (t - 2.0), r = sqrt(r2), f = 1.0;
        if (spot) {
            double c = 1.0 / r, x = (c - cc) / (cf - cc);
            f = c >= cf ? 1.0 : c <= cc ? 0.0 : x * x * (3 - 2 * x);
        }
        sum += ss * exp(-st * (t + r)) * f / (4.0 * M_PI * r2);
    }
    return sum * dt;
}

/* volpath_nee at max_depth 1 (single scattering) renders that integral with equiangular sampling on
 * (towards the light's position) and off (free flights alone), for a point and a spot light: the camera
 * sits in the medium with a 0.01-degree field of view, so every pixel is an independent sample of the
 * one ray. Must fail: 1.01 x the closed form. */
static void test_equiangular_punctual(void **state)
{
    (void)state;
    static const char *const lights[2] = {
        "{ type: point, position: [0, 1, -2], intensity: 1 }",
        "{ type: spot, position: [0, 1, -2], direction: [0, -1, 0], intensity: 1, cone_angle: 40, falloff_angle: 20 }"};
    for (int spot = 0; spot < 2; spot++) {
        double want = single_scatter(spot);
        for (int eq = 1; eq >= 0; eq--) {
            char text[2048], label[64];
            snprintf(text, sizeof text,
                     "murk: 1\nrender: { resolution: [32, 32], spp: 128, seed: %d }\n"
                     "camera: { from: [0, 0, 0], at: [0, 0, -1], up: [0, 1, 0], fov: 0.01, medium: fog }\n"
                     "integrator: { type: volpath_nee, max_depth: 1, equiangular: %s }\n"
                     "media: { fog: { type: delta, density: { constant: 1 }, sigma_a: [0.1, 0.1, 0.1], "
                     "sigma_s: [0.5, 0.5, 0.5], g: 0 } }\n"
                     "lights: [ %s ]\n"
                     "shapes: [ { type: box, min: [-10, -10, -10], max: [10, 10, 10], interior: fog } ]\n",
                     3 + 2 * spot + eq, eq ? "true" : "false", lights[spot]);
            const char *extra[] = {"--spp", eq ? "128" : "1024", NULL};
            double m, se;
            render_mean("eq_punctual.yaml", text, extra, &m, &se);
            snprintf(label, sizeof label, "%s light, equiangular %s", spot ? "spot" : "point", eq ? "on" : "off");
            check_closed_form(label, m, se, want, 3e-4); /* the rays' offsets, as in test_slab */
        }
    }
}

/* ---- older integrators ------------------------------------------------------------------------------ */

static void test_legacy(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", build_path("tests/fixtures"), 1);
    float rgb[3 * MW * MH];
    char text[1024];
    snprintf(text, sizeof text,
             "murk: 1\nintegrator: { type: old_integrator }\nmaterials: { m: { type: diffuse } }\n"
             "lights: [ { type: envmap, file: %s }, { type: distant, direction: [0, 1, 0], irradiance: 1, "
             "angular_diameter: 5 } ]\n"
             "shapes: [ { type: quad, center: [0, 2, 0], u: [1, 0, 0], v: [0, 0, 1], material: m, emission: 1 } ]\n",
             write_map(MAP_GRADIENT, rgb));
    murk_scene *s = load_text("legacy.yaml", text);
    const murk_host *h = murk_host_table();
    murk_rng rng;
    murk_rng_seed(&rng, 9, 9, 9);
    int nsamples = 0, ninf = 0, canary_hit = 0;
    for (int k = 0; k < 10000; k++) {
        struct { unsigned char ls[MURK_LIGHT_SAMPLE_SIZE_1_6]; uint32_t canary; } old;
        old.canary = 0xC0FFEEu;
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        if (h->sample_light_with(s, murk_v3(0, 0, 0), u, MURK_LIGHT_AREA, (murk_light_sample *)(void *)old.ls)) {
            murk_light_sample ls;
            memcpy(&ls, old.ls, MURK_LIGHT_SAMPLE_SIZE_1_6);
            nsamples++;
            ninf += !isfinite(ls.dist);
        }
        canary_hit += old.canary != 0xC0FFEEu;
    }
    murk_rgb up = h->background(s, murk_v3(0, 1, 0));
    printf("ABI 1.6 integrator: %d samples, %d at infinity, %d writes past its struct; environment_pdf %g, "
           "background towards the sun %g\n", nsamples, ninf, canary_hit, (double)h->environment_pdf(s, murk_v3(0, 1, 0)),
           (double)up.c[0]);
    assert_true(nsamples > 1000);
    assert_int_equal(ninf, 0);
    assert_int_equal(canary_hit, 0);
    assert_true(h->environment_pdf(s, murk_v3(0, 1, 0)) == 0.0f);
    assert_true(up.c[0] > 10.0f); /* the sun's cone is in the environment */
    murk_scene_free(s);
    /* a delta light is refused, located at its type */
    char err[1024];
    const char *bad = write_tmp("legacy_delta.yaml", "murk: 1\nintegrator: { type: old_integrator }\n"
                                                     "lights: [ { type: point, position: [0, 1, 0], intensity: 1 } ]\n");
    assert_null(murk_scene_load(bad, NULL, 0, err, sizeof err));
    printf("%s\n", err);
    assert_contains(err, "legacy_delta.yaml:3:19: lights[0] (point): the integrator predates plugin ABI 1.");
    unsetenv("MURK_PLUGIN_PATH");
}

/* ---- bad input -------------------------------------------------------------------------------------- */

static void check_refused(const char *name, const char *lights, const char *want)
{
    char text[1024], exr[1024];
    snprintf(text, sizeof text, "murk: 1\nmaterials: { m: { type: diffuse } }\nlights:\n%s"
             "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: m } ]\n", lights);
    const char *scene = write_tmp(name, text);
    snprintf(exr, sizeof exr, "%s/%s.exr", tmp_dir(), name);
    char *out = NULL;
    int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
    printf("%s: %s", name, out);
    struct stat sb;
    int written = stat(exr, &sb) == 0;
    if (st != 1 || !strstr(out, want) || written)
        fail_msg("%s: status %d, output written %d, want \"%s\" in:\n%s", name, st, written, want, out);
    free(out);
}

static void test_bad_input(void **state)
{
    (void)state;
    float rgb[3 * 8 * 8];
    char err[256], lights[512];
    for (int i = 0; i < 3 * 64; i++)
        rgb[i] = 1.0f;
    assert_int_equal(murk_exr_write(tmp_path("square.exr"), rgb, 8, 8, NULL, 0, err, sizeof err), 0);
    check_refused("square.yaml", "  - { type: envmap, file: square.exr }\n",
                  "square.yaml:4:27: lights[0] (envmap): ");
    check_refused("square2.yaml", "  - { type: envmap, file: square.exr }\n", "is 8x8, not a lat-long map");
    const float bad[3] = {NAN, INFINITY, -1.0f};
    for (int k = 0; k < 3; k++) {
        rgb[3 * 5 + 1] = bad[k];
        char f[64], y[64];
        snprintf(f, sizeof f, "bad%d.exr", k);
        snprintf(y, sizeof y, "bad%d.yaml", k);
        assert_int_equal(murk_exr_write(tmp_path(f), rgb, 8, 4, NULL, 0, err, sizeof err), 0);
        snprintf(lights, sizeof lights, "  - { type: envmap, file: %s }\n", f);
        check_refused(y, lights, "texel (5, 0) of the environment map is");
    }
    rgb[3 * 5 + 1] = 1.0f;
    assert_int_equal(murk_exr_write(tmp_path("big.exr"), rgb, 8, 4, NULL, 0, err, sizeof err), 0);
    setenv("MURK_MAX_IMAGE_PIXELS", "16", 1);
    check_refused("big.yaml", "  - { type: envmap, file: big.exr }\n", "MURK_MAX_IMAGE_PIXELS");
    unsetenv("MURK_MAX_IMAGE_PIXELS");
    check_refused("missing.yaml", "  - { type: envmap, file: none.exr }\n", "missing.yaml:4:27: lights[0] (envmap): ");
    /* not an EXR at all: a text file and an empty one under the name */
    write_tmp("text.exr", "this is not an OpenEXR file\n");
    check_refused("text.yaml", "  - { type: envmap, file: text.exr }\n", "text.yaml:4:27: lights[0] (envmap): ");
    write_tmp("empty.exr", "");
    check_refused("empty.yaml", "  - { type: envmap, file: empty.exr }\n", "empty.yaml:4:27: lights[0] (envmap): ");
    /* a 0 x 0 map (OpenEXR cannot hold one: the C adder a loader of another format would call) */
    murk_scene *s = lights_scene("zero.yaml", "  - { type: point, position: [0, 2, 0], intensity: 1 }\n");
    size_t before = s->nadded;
    assert_int_equal(murk_lights_add_envmap_rgb(s, rgb, 0, 0, murk_rgb1(1.0f), 0.0, err, sizeof err), -1);
    printf("0 x 0 map: %s\n", err);
    assert_contains(err, "the environment map is empty (0x0)");
    assert_int_equal(s->nadded, before);
    murk_scene_free(s);
    check_refused("zero_dir.yaml", "  - { type: distant, direction: [0, 0, 0], irradiance: 1 }\n",
                  "zero_dir.yaml:4:33: lights[0] (distant): direction has no length");
    check_refused("diam.yaml", "  - { type: distant, direction: [0, 1, 0], irradiance: 1, angular_diameter: 180 }\n",
                  "diam.yaml:4:77: lights[0] (distant): angular_diameter must be below 180 degrees");
    check_refused("spot.yaml", "  - { type: spot, position: [0, 2, 0], direction: [0, -1, 0], intensity: 1, "
                  "cone_angle: 20, falloff_angle: 30 }\n", "spot.yaml:4:89: lights[0] (spot): cone_angle (20, where");
    check_refused("spot_dir.yaml", "  - { type: spot, position: [0, 2, 0], direction: [0, 0, 0], intensity: 1 }\n",
                  "spot_dir.yaml:4:51: lights[0] (spot): direction has no length");
    check_refused("type.yaml", "  - { type: spto, position: [0, 2, 0] }\n",
                  "type.yaml:4:13: lights[0]: unknown light type 'spto' (did you mean 'spot'?)");
    check_refused("key.yaml", "  - { type: point, position: [0, 2, 0], intensty: 1 }\n", "(did you mean 'intensity'?)");
    check_refused("sun_dir.yaml", "  - { type: sky, sun_direction: [0, 0, 0] }\n",
                  "sun_dir.yaml:4:33: lights[0] (sky): sun_direction has no length");
    check_refused("sun_bool.yaml", "  - { type: sky, sun_direction: [0, 1, 0], sun: maybe }\n",
                  "sun_bool.yaml:4:49: lights[0] (sky): sun must be true or false");
    check_refused("turbidity.yaml", "  - { type: sky, sun_direction: [0, 1, 0], turbidity: 20 }\n",
                  "turbidity.yaml:4:55: lights[0] (sky): turbidity must be in [1.7, 10]");
    /* a sun below the horizon is allowed: a warning, a black sky, no sun */
    char *out = NULL, exr[1024];
    const char *scene = write_tmp("night.yaml", "murk: 1\nrender: { resolution: [8, 8], spp: 4 }\n"
                                                "lights: [ { type: sky, sun_direction: [0, -1, 1] } ]\n");
    snprintf(exr, sizeof exr, "%s/night.exr", tmp_dir());
    assert_int_equal(run_murk(&out, "render", scene, "-o", exr, NULL), 0);
    assert_contains(out, "the sun is below the horizon");
    murk_image img;
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    double sum = 0.0;
    for (int i = 0; i < 3 * img.w * img.h; i++)
        sum += img.rgb[i];
    assert_true(sum == 0.0);
    murk_image_free(&img);
    free(out);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_envmap_chi2),        cmocka_unit_test(test_envmap_pdf), cmocka_unit_test(test_env_mis),
        cmocka_unit_test(test_point_spot),         cmocka_unit_test(test_selection_by_power),
        cmocka_unit_test(test_furnace),            cmocka_unit_test(test_sun_plane),
        cmocka_unit_test(test_slab),               cmocka_unit_test(test_equiangular_punctual),
        cmocka_unit_test(test_legacy),             cmocka_unit_test(test_bad_input),
    };
    return STAT_RUN(tests, argc, argv);
}
