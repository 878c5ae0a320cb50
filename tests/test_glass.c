/* test_glass.c — light transport through refracting (dielectric) boundaries, in-process through the
 * path tracer of path, volpath and volpath_nee (plugins/integrators/pathtracer.c).
 *
 *   furnace        a dielectric sphere (ior 1.5, no absorption) in a constant background 1, seen from
 *                  outside: every pixel is 1 (radiance in = radiance out). Smooth: each path's weight is
 *                  exactly 1 (reflection 1, refraction 1 / eta^2 in and eta^2 out), also holding a
 *                  scattering, non-absorbing medium (volpath, volpath_nee: 1 within 4 standard errors).
 *                  Rough (0.3), with the multiple-scattering compensation (the default): 1 within 4
 *                  standard errors plus FURNACE_TABLE_TOL (the compensation's tables' error) and the same in
 *                  every integrator (4 sigma).
 *   furnace_rough  the same sphere at roughness 0.3, 0.6, 1 through `path`: compensated 1 within noise;
 *                  with multiscatter: false exactly the loss the single-scattering model had before the
 *                  compensation existed (0.9489, 0.6751, 0.3576).
 *   slab           a homogeneous absorbing medium (sigma_a 0.5 / 1 / 2, no scattering, thickness 0.5)
 *                  between two parallel smooth faces of ior 1.5 (a wide box), a downward-facing lamp of
 *                  radiance 1 above it, black background. Seen from below at angle theta:
 *                      L = (1 - R)^2 a / (1 - R^2 a^2),  a = exp(-sigma_a d / cos theta_t)
 *                  (Fresnel R at both faces, the geometric series of internal reflections). Seen from a
 *                  camera inside the medium, 0.25 below the top face, looking up at internal angle
 *                  theta_i: L = eta^2 (1 - R) a_0 / (1 - R^2 a^2), a_0 = exp(-sigma_a 0.25 / cos theta_i)
 *                  (radiance is eta^2 larger in the glass); past the critical angle, 0 (total internal
 *                  reflection). Every tracker (delta, decomposition, spectral, spectral_mis,
 *                  naive_spectral) with volpath and volpath_nee, per channel within 4 standard errors
 *                  (from the sample variance); `path` (media off) gives the same with a = 1. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/host.h"
#include "pathtracer.h"
#include "scene/scene.h"

#define PI 3.14159265358979323846

static murk_scene *load(const char *name, const char *text)
{
    char err[1024];
    murk_scene *s = murk_scene_load(write_tmp(name, text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    return s;
}

typedef struct stats { double s1[3], s2[3]; long n; } stats;

static void add(stats *st, murk_rgb L)
{
    for (int k = 0; k < 3; k++) {
        st->s1[k] += L.c[k];
        st->s2[k] += (double)L.c[k] * L.c[k];
    }
    st->n++;
}
static double mean(const stats *st, int k) { return st->s1[k] / st->n; }
static double se(const stats *st, int k)
{
    double m = mean(st, k);
    return sqrt(fmax(0.0, st->s2[k] / st->n - m * m) / (st->n - 1));
}

/* ---- furnace ------------------------------------------------------------------------------------ */

/* The largest shift of a rough furnace that the compensation's tables can cause (their interpolation
 * error, tools/ggx_tables.c: up to ~5e-3 at single directions inside, ~2e-3 outside, far smaller
 * averaged over the sphere's paths). */
#define FURNACE_TABLE_TOL 1.5e-3

static stats furnace(const murk_scene *s, int nee, int media, long n, uint64_t seed)
{
    murk_pt pt = {murk_host_table(), 100000, 3, nee, media, MURK_LIGHT_AREA, 1.0f, 0}; /* light trapped by TIR must not be cut off */
    stats st = {{0}, {0}, 0};
    for (long i = 0; i < n; i++) {
        murk_rng rng;
        murk_rng_seed(&rng, seed, 1, (uint64_t)i);
        /* from (0, 0, 4) towards a uniform point of the disc of radius 1.05 at z = 0: mostly the sphere */
        float r = 1.05f * sqrtf(murk_rng_float(&rng)), phi = 2.0f * (float)PI * murk_rng_float(&rng);
        murk_ray ray = {murk_v3(0, 0, 4), murk_normalize(murk_v3(r * cosf(phi), r * sinf(phi), -4.0f)), 0.0f, INFINITY};
        add(&st, murk_pt_li(&pt, s, &ray, &rng));
    }
    return st;
}

static void test_furnace(void **state)
{
    (void)state;
    const char *fmt = "murk: 1\nbackground: 1\n"
                      "materials: { glass: { type: dielectric, ior: 1.5, roughness: %s } }\n"
                      "media: { m: { type: delta, density: { constant: 1 }, sigma_a: 0, sigma_s: 2 } }\n"
                      "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: glass%s } ]\n";
    const char *names[3] = {"path", "volpath", "volpath_nee"};
    int bad = 0;
    double prev = 0.0, prev_e = 0.0;
    for (int rough = 0; rough < 2; rough++)
        for (int med = 0; med < 2; med++) {
            char text[1024];
            snprintf(text, sizeof text, fmt, rough ? "0.3" : "0", med ? ", interior: m" : "");
            murk_scene *s = load("furnace.yaml", text);
            for (int integ = 0; integ < 3; integ++) {
                if (med && integ == 0)
                    continue;
                stats st = furnace(s, integ == 2, integ > 0, rough ? 40000 : 20000, 100u + (uint64_t)integ);
                double m = mean(&st, 1), e = se(&st, 1);
                /* smooth: 1; rough (compensated): 1 within noise and the tables' error, and the three
                 * integrators agree */
                int ok = fabs(m - 1.0) <= 4.0 * e + (rough ? FURNACE_TABLE_TOL : 1e-5);
                if (rough && integ > med && fabs(m - prev) > 4.0 * hypot(e, prev_e))
                    ok = 0;
                prev = m;
                prev_e = e;
                printf("  furnace %-6s glass%-22s %-12s L = %.6f +- %.6f (%+.1f sigma from 1)%s\n",
                       rough ? "rough" : "smooth", med ? " holding a scattering medium" : "", names[integ], m, e,
                       e > 0.0 ? (m - 1.0) / e : 0.0, ok ? "" : "  <-- FAIL");
                bad += !ok;
            }
            murk_scene_free(s);
        }
    assert_int_equal(bad, 0);
}

/* The rough sphere's furnace across roughness, with the multiple-scattering compensation (the default)
 * and without (multiscatter: false), through `path` (media off: the sphere holds nothing). Compensated:
 * 1 within 4 standard errors plus FURNACE_TABLE_TOL. Uncompensated: the single-scattering
 * model's loss, exactly today's (the values the plugin gave before the compensation existed, same seeds:
 * with multiscatter false it draws the same random numbers in the same order), and clearly below 1. */
static const double furnace_roughs[3] = {0.3, 0.6, 1.0};
static const double furnace_today[3] = {0.948897, 0.675096, 0.357623}; /* before the compensation (printed to 1e-6) */

static void test_furnace_rough(void **state)
{
    (void)state;
    const char *fmt = "murk: 1\nbackground: 1\n"
                      "materials: { glass: { type: dielectric, ior: 1.5, roughness: %g%s } }\n"
                      "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: glass } ]\n";
    int bad = 0;
    for (int r = 0; r < 3; r++)
        for (int ms = 1; ms >= 0; ms--) {
            char text[1024];
            snprintf(text, sizeof text, fmt, furnace_roughs[r], ms ? "" : ", multiscatter: false");
            murk_scene *s = load("furnace_rough.yaml", text);
            stats st = furnace(s, 0, 0, 100000, 300u + (uint64_t)r);
            double m = mean(&st, 1), e = se(&st, 1);
            int ok = ms ? fabs(m - 1.0) <= 4.0 * e + FURNACE_TABLE_TOL
                        : m < 1.0 - 6.0 * e && fabs(m - furnace_today[r]) <= 1e-6;
            printf("  furnace rough %.1f %-14s L = %.6f +- %.6f (%+.1f sigma from 1)%s\n", furnace_roughs[r],
                   ms ? "compensated" : "single scatter", m, e, e > 0.0 ? (m - 1.0) / e : 0.0, ok ? "" : "  <-- FAIL");
            bad += !ok;
            murk_scene_free(s);
        }
    assert_int_equal(bad, 0);
}

/* ---- the slab --------------------------------------------------------------------------------- */

static const double SIGMA_A[3] = {0.5, 1.0, 2.0}, ETA = 1.5, THICK = 0.5;

static double fresnel(double c, double eta)
{
    double s2 = (1.0 - c * c) / (eta * eta);
    if (s2 >= 1.0)
        return 1.0;
    double ct = sqrt(1.0 - s2), a = (eta * c - ct) / (eta * c + ct), b = (c - eta * ct) / (c + eta * ct);
    return 0.5 * (a * a + b * b);
}

static void test_slab(void **state)
{
    (void)state;
    const char *fmt = "murk: 1\nbackground: 0\n%s"
                      "materials: { glass: { type: dielectric, ior: 1.5 }, lamp: { type: diffuse, albedo: 0 } }\n"
                      "media: { m: { type: %s, density: { constant: 1 }, sigma_a: [0.5, 1, 2], sigma_s: 0 } }\n"
                      "shapes:\n"
                      "  - { type: box, min: [-30, 0, -30], max: [30, 0.5, 30], material: glass, interior: m }\n"
                      "  - { type: quad, center: [0, 3, 0], u: [60, 0, 0], v: [0, 0, 60], material: lamp, emission: 1 }\n";
    static const char *const trackers[] = {"delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"};
    const double outside_deg[3] = {0.0, 40.0, 70.0}, inside_deg[3] = {0.0, 35.0, 50.0}; /* critical: 41.8 */
    int bad = 0;
    for (size_t t = 0; t < sizeof trackers / sizeof trackers[0]; t++)
        for (int inside = 0; inside < 2; inside++) {
            char text[2048];
            snprintf(text, sizeof text, fmt, inside ? "camera: { from: [0, 0.25, 0], at: [0, 1, 0], up: [1, 0, 0], medium: m }\n" : "",
                     trackers[t]);
            murk_scene *s = load("slab.yaml", text);
            for (int a = 0; a < 3; a++)
                for (int integ = 0; integ < 3; integ++) {
                    if (integ == 0 && (t > 0 || inside)) /* path ignores media: once is enough */
                        continue;
                    int media = integ > 0;
                    murk_pt pt = {murk_host_table(), 1000, 3, integ == 2, media, MURK_LIGHT_AREA, 1.0f, 0};
                    double th = (inside ? inside_deg[a] : outside_deg[a]) * PI / 180.0;
                    murk_ray ray = {murk_v3((float)sin(th), 0, 0), murk_v3((float)sin(th), (float)cos(th), 0), 0.0f, INFINITY};
                    ray.o = inside ? murk_v3(0, 0.25f, 0) : murk_v3(0, -1, 0);
                    stats st = {{0}, {0}, 0};
                    for (long i = 0; i < 50000; i++) {
                        murk_rng rng;
                        murk_rng_seed(&rng, 900u + t, (uint64_t)(a * 8 + integ * 2 + inside), (uint64_t)i);
                        add(&st, murk_pt_li(&pt, s, &ray, &rng));
                    }
                    char line[512];
                    size_t k0 = (size_t)snprintf(line, sizeof line, "  slab %-14s %-11s %s %2.0f deg:", trackers[t],
                                                 integ == 0 ? "path" : (integ == 1 ? "volpath" : "volpath_nee"),
                                                 inside ? "inside " : "outside", th * 180.0 / PI);
                    int lbad = 0;
                    for (int k = 0; k < 3; k++) {
                        double expect;
                        double c = cos(th);
                        if (!inside) {
                            double R = fresnel(c, ETA), ct = sqrt(1.0 - sin(th) * sin(th) / (ETA * ETA));
                            double aa = media ? exp(-SIGMA_A[k] * THICK / ct) : 1.0;
                            expect = (1.0 - R) * (1.0 - R) * aa / (1.0 - R * R * aa * aa);
                        } else {
                            double R = fresnel(c, 1.0 / ETA); /* from inside: relative index 1 / eta */
                            double aa = exp(-SIGMA_A[k] * THICK / c), a0 = exp(-SIGMA_A[k] * 0.25 / c);
                            expect = ETA * ETA * (1.0 - R) * a0 / (1.0 - R * R * aa * aa);
                        }
                        double m = mean(&st, k), e = se(&st, k);
                        /* + float geometry: offsets of 1e-4 per face move the path length by < 1e-3 */
                        if (!(fabs(m - expect) <= 4.0 * e + 2e-3 * expect * SIGMA_A[k] * media + 1e-6))
                            lbad = 1;
                        k0 += (size_t)snprintf(line + k0, sizeof line - k0, " %.5f+-%.5f (%.5f)", m, e, expect);
                    }
                    printf("%s%s\n", line, lbad ? "  <-- FAIL" : "");
                    bad += lbad;
                }
            murk_scene_free(s);
        }
    assert_int_equal(bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_furnace), cmocka_unit_test(test_furnace_rough),
                                       cmocka_unit_test(test_slab)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
