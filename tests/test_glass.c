/* test_glass.c — light transport through refracting (dielectric) boundaries, in-process through the
 * path tracer of path, volpath and volpath_nee (plugins/integrators/pathtracer.c).
 *
 *   furnace        a dielectric sphere (ior 1.5, no absorption) in a constant background 1, seen from
 *                  outside: every pixel is 1 (radiance in = radiance out). Smooth: each path's weight is
 *                  exactly 1 (reflection 1, refraction 1 / eta^2 in and eta^2 out), also holding a
 *                  scattering, non-absorbing medium (volpath, volpath_nee: 1 within STAT_Z standard
 *                  errors, stat.h). Rough (0.3), with the multiple-scattering compensation (the default): 1
 *                  within STAT_Z standard errors plus FURNACE_TABLE_TOL (the compensation's tables' error)
 *                  and the same in every integrator (STAT_Z); must-fail: against 0.98 - FURNACE_TABLE_TOL.
 *   furnace_rough  the same sphere at roughness 0.3, 0.6, 1 through `path`, against a random walk written
 *                  here (the sphere intersected analytically, the plugin's sample() at every hit; no path
 *                  tracer, no Embree): the two agree within STAT_Z standard errors of their difference
 *                  (independent seeds), compensated and with multiscatter: false (which loses light:
 *                  below 1 by STAT_Z standard errors); compensated, 1 within noise plus the tables' error.
 *                  Must-fail: the path tracer against the walk of the other model (compensated against
 *                  single scattering: a 5 to 64 % difference) and against the walk's mean 4 % lower.
 *   slab           a homogeneous absorbing medium (sigma_a 0.5 / 1 / 2, no scattering, thickness 0.5)
 *                  between two parallel smooth faces of ior 1.5 (a wide box), a downward-facing lamp of
 *                  radiance 1 above it, black background. Seen from below at angle theta:
 *                      L = (1 - R)^2 a / (1 - R^2 a^2),  a = exp(-sigma_a d / cos theta_t)
 *                  (Fresnel R at both faces, the geometric series of internal reflections). Seen from a
 *                  camera inside the medium, 0.25 below the top face, looking up at internal angle
 *                  theta_i: L = eta^2 (1 - R) a_0 / (1 - R^2 a^2), a_0 = exp(-sigma_a 0.25 / cos theta_i)
 *                  (radiance is eta^2 larger in the glass); past the critical angle, 0 (total internal
 *                  reflection). Every tracker (delta, decomposition, spectral, spectral_mis,
 *                  naive_spectral) with volpath and volpath_nee, per channel within STAT_Z standard errors
 *                  (from the sample variance); `path` (media off) gives the same with a = 1. Must-fail:
 *                  each against the slab of a medium absorbing 25 % more. */
#include "testutil.h"
#include "stat.h"

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
                stats st = furnace(s, integ == 2, integ > 0, stat_n(rough ? 40000 : 20000), 100u + (uint64_t)integ);
                double m = mean(&st, 1), e = se(&st, 1);
                /* smooth: 1; rough (compensated): 1 within noise and the tables' error, and the three
                 * integrators agree */
                int ok = rough ? stat_z_ok(m, e, 1.0, FURNACE_TABLE_TOL) : fabs(m - 1.0) <= 4.0 * e + 1e-5;
                if (rough && integ > med && !stat_z_ok(m - prev, hypot(e, prev_e), 0.0, 0.0))
                    ok = 0;
                if (rough) {
                    double z = (fabs(m - (0.98 - FURNACE_TABLE_TOL)) - FURNACE_TABLE_TOL) / e;
                    char label[96];
                    snprintf(label, sizeof label, "furnace rough%s %s against 0.98 - the tables' error",
                             med ? " holding a medium" : "", names[integ]);
                    bad += !stat_must_fail(label, z > STAT_Z, z);
                }
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

/* The furnace of `furnace` computed without the path tracer: from (0, 0, 4) towards a uniform point of
 * the disc of radius 1.05 at z = 0, the unit sphere met analytically, at every hit the material's
 * sample() in the frame the integrators give it (n on wo's side, ng outwards: murk/material.h), the path's
 * weight times f |cos| / pdf, until the ray leaves towards the background 1. Channel 1. */
static stats walk(const murk_material *mat, long n, uint64_t seed)
{
    stats st = {{0}, {0}, 0};
    for (long i = 0; i < n; i++) {
        murk_rng rng;
        murk_rng_seed(&rng, seed, 2, (uint64_t)i);
        float r = 1.05f * sqrtf(murk_rng_float(&rng)), phi = 2.0f * (float)PI * murk_rng_float(&rng);
        murk_vec3 o = murk_v3(0, 0, 4), d = murk_normalize(murk_v3(r * cosf(phi), r * sinf(phi), -4.0f));
        double w = 1.0;
        for (int depth = 0; depth < 100000 && w > 0.0; depth++) {
            double b = murk_dot(o, d), c = murk_dot(o, o) - 1.0, disc = b * b - c, t = -1.0;
            if (disc > 0.0) {
                double t0 = -b - sqrt(disc), t1 = -b + sqrt(disc);
                t = t0 > 1e-4 ? t0 : (t1 > 1e-4 ? t1 : -1.0);
            }
            if (t < 0.0)
                break; /* the background: radiance 1 */
            murk_hit hit;
            memset(&hit, 0, sizeof hit);
            hit.p = murk_madd(o, d, (float)t);
            hit.ng = murk_normalize(hit.p);
            hit.n = murk_dot(hit.ng, d) > 0.0f ? murk_neg(hit.ng) : hit.ng; /* on wo's side */
            hit.t = (float)t;
            hit.u = hit.v = 0.5f;
            hit.material = mat;
            hit.light = -1;
            murk_vec3 tb, bb;
            murk_basis(hit.n, &tb, &bb);
            murk_vec3 wo = murk_to_local(murk_neg(d), tb, bb, hit.n);
            float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
            murk_bsdf_sample bs;
            bs.eta = 1.0f;
            if (!mat->vt->sample(mat->self, &hit, wo, u, &bs) || !(bs.pdf > 0.0f)) {
                w = 0.0;
                break;
            }
            w *= bs.f.c[1] * fabs(bs.wi.z) / bs.pdf;
            d = murk_normalize(murk_from_local(bs.wi, tb, bb, hit.n));
            o = murk_madd(hit.p, bs.wi.z > 0.0f ? hit.n : murk_neg(hit.n), 1e-4f);
        }
        add(&st, murk_rgb1((float)w));
    }
    return st;
}

/* The rough sphere's furnace across roughness, with the multiple-scattering compensation (the default)
 * and without (multiscatter: false), through `path` (media off: the sphere holds nothing), against the
 * walk above with independent seeds. */
static const double furnace_roughs[3] = {0.3, 0.6, 1.0};

static void test_furnace_rough(void **state)
{
    (void)state;
    const char *fmt = "murk: 1\nbackground: 1\n"
                      "materials: { glass: { type: dielectric, ior: 1.5, roughness: %g%s } }\n"
                      "shapes: [ { type: sphere, center: [0, 0, 0], radius: 1, material: glass } ]\n";
    int bad = 0;
    for (int r = 0; r < 3; r++) {
        stats pt[2], wk[2];
        for (int ms = 1; ms >= 0; ms--) {
            char text[1024];
            snprintf(text, sizeof text, fmt, furnace_roughs[r], ms ? "" : ", multiscatter: false");
            murk_scene *s = load("furnace_rough.yaml", text);
            pt[ms] = furnace(s, 0, 0, stat_n(200000), 300u + (uint64_t)r);
            wk[ms] = walk(&s->materials[0].m, stat_n(200000), 700u + (uint64_t)r);
            double m = mean(&pt[ms], 1), e = se(&pt[ms], 1), mw = mean(&wk[ms], 1), ew = se(&wk[ms], 1);
            int ok = stat_z_ok(m - mw, hypot(e, ew), 0.0, 0.0);
            if (ms)
                ok &= stat_z_ok(m, e, 1.0, FURNACE_TABLE_TOL);
            else /* one-sided: it loses light */
                ok &= (stat_count(1, stat_tail2(STAT_Z) / 2.0), m < 1.0 - STAT_Z * e);
            printf("  furnace rough %.1f %-14s L = %.6f +- %.6f (%+.1f sigma from 1), walk %.6f +- %.6f (%+.1f sigma)%s\n",
                   furnace_roughs[r], ms ? "compensated" : "single scatter", m, e, e > 0.0 ? (m - 1.0) / e : 0.0, mw, ew,
                   stat_z2(m, e, mw, ew), ok ? "" : "  <-- FAIL");
            bad += !ok;
            murk_scene_free(s);
        }
        char label[96];
        double z = stat_z2(mean(&pt[1], 1), se(&pt[1], 1), mean(&wk[0], 1), se(&wk[0], 1));
        snprintf(label, sizeof label, "rough %.1f compensated against the single-scattering walk", furnace_roughs[r]);
        bad += !stat_must_fail(label, fabs(z) > STAT_Z, z);
        z = stat_z2(mean(&pt[0], 1), se(&pt[0], 1), 0.96 * mean(&wk[0], 1), 0.96 * se(&wk[0], 1));
        snprintf(label, sizeof label, "rough %.1f single scattering against the walk 4%% lower", furnace_roughs[r]);
        bad += !stat_must_fail(label, fabs(z) > STAT_Z, z);
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

/* The slab's radiance at angle th (outside: below it; inside: from the camera 0.25 below the top face)
 * for the absorption coefficient sa (0: media off). */
static double expect_slab(double th, int inside, double sa)
{
    double c = cos(th);
    if (!inside) {
        double R = fresnel(c, ETA), ct = sqrt(1.0 - sin(th) * sin(th) / (ETA * ETA));
        double aa = exp(-sa * THICK / ct);
        return (1.0 - R) * (1.0 - R) * aa / (1.0 - R * R * aa * aa);
    }
    double R = fresnel(c, 1.0 / ETA); /* from inside: relative index 1 / eta */
    double aa = exp(-sa * THICK / c), a0 = exp(-sa * 0.25 / c);
    return ETA * ETA * (1.0 - R) * a0 / (1.0 - R * R * aa * aa);
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
                    for (long i = 0, n = stat_n(50000); i < n; i++) {
                        murk_rng rng;
                        murk_rng_seed(&rng, 900u + t, (uint64_t)(a * 8 + integ * 2 + inside), (uint64_t)i);
                        add(&st, murk_pt_li(&pt, s, &ray, &rng));
                    }
                    char line[512];
                    size_t k0 = (size_t)snprintf(line, sizeof line, "  slab %-14s %-11s %s %2.0f deg:", trackers[t],
                                                 integ == 0 ? "path" : (integ == 1 ? "volpath" : "volpath_nee"),
                                                 inside ? "inside " : "outside", th * 180.0 / PI);
                    int lbad = 0;
                    double zmore = 0.0;
                    for (int k = 0; k < 3; k++) {
                        double expect = media ? expect_slab(th, inside, SIGMA_A[k]) : expect_slab(th, inside, 0.0);
                        double m = mean(&st, k), e = se(&st, k);
                        /* + float geometry: offsets of 1e-4 per face move the path length by < 1e-3 */
                        double slack = 2e-3 * expect * SIGMA_A[k] * media + 1e-6;
                        lbad |= !stat_z_ok(m, e, expect, slack);
                        if (media) { /* the must-fail case: 25 % more absorption */
                            double more = expect_slab(th, inside, 1.25 * SIGMA_A[k]);
                            zmore = fmax(zmore, e > 0.0 ? (fabs(m - more) - slack) / e : INFINITY);
                        }
                        k0 += (size_t)snprintf(line + k0, sizeof line - k0, " %.5f+-%.5f (%.5f)", m, e, expect);
                    }
                    printf("%s%s\n", line, lbad ? "  <-- FAIL" : "");
                    bad += lbad;
                    if (media) {
                        char label[96];
                        snprintf(label, sizeof label, "slab %s %s %s %2.0f deg: 25%% more absorption", trackers[t],
                                 integ == 1 ? "volpath" : "volpath_nee", inside ? "inside" : "outside", th * 180.0 / PI);
                        bad += !stat_must_fail(label, zmore > STAT_Z, zmore);
                    }
                }
            murk_scene_free(s);
        }
    assert_int_equal(bad, 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_furnace), cmocka_unit_test(test_furnace_rough),
                                       cmocka_unit_test(test_slab)};
    return STAT_RUN(tests, argc, argv);
}
