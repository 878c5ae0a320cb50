/* test_lights.c — direct lighting from a rectangular lamp against its closed form (lights.c).
 *
 * A Lambertian point p with normal n under a rectangle of radiance Le receives the irradiance
 * E = Le / 2 * sum_i theta_i n . normalize(v_i x v_(i+1)) (the polygon-to-point form factor, the
 * rectangle clipped to p's upper hemisphere; v_i the corners relative to p). The tests estimate E / Le
 * for points all around the lamp of test_boundaries' box scene — far, near, under an edge, beside it
 * at grazing heights, close to its plane where the solid angle falls to the area fallback's threshold —
 * with light sampling alone (MURK_LIGHT_AREA and MURK_LIGHT_SOLID_ANGLE) and with the path tracer's
 * combination: the light sample and a cosine-sampled direction, each weighted by the power heuristic
 * against the other's pdf (light_pdf_with at the point the cosine ray hits). Every estimate must be
 * within STAT_Z of its standard errors of the closed form (fixed seeds, 100k samples each; stat.h); must-fail:
 * each estimator's estimates against an irradiance 0.2 % higher, which its best-measured point must see.
 * Then points on the lamp itself, which it must not light (the cause of issue 15's solid_angle bias), and
 * (suite 'long') the report's image test: test_boundaries' box scene with solid_angle against area,
 * block-wise z. */
#include "testutil.h"
#include "stat.h"
#include "render/host.h"
#include "scene/scene.h"

#include "murk/math.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* test_boundaries' lamp (y = 1.99, emitting down) over its floor; a second, small lamp far off so that
 * the light choice matters (its solid angle is below the fallback threshold from most points). */
static const char *const SCENE = "murk: 1\n"
                                 "render: { resolution: [8, 8] }\n"
                                 "camera: { from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40 }\n"
                                 "materials: { m: { type: diffuse, albedo: 0.5 } }\n"
                                 "shapes:\n"
                                 "  - { type: quad, center: [0, 1.99, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], "
                                 "material: m, emission: [3, 3, 3] }\n";

typedef struct dvec { double x, y, z; } dvec;

static dvec dv(murk_vec3 a) { return (dvec){a.x, a.y, a.z}; }
static dvec dsub(dvec a, dvec b) { return (dvec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dvec dlerp(dvec a, dvec b, double t) { return (dvec){a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)}; }
static double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec dcross(dvec a, dvec b) { return (dvec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double dlen(dvec a) { return sqrt(ddot(a, a)); }

/* E / Le at p (normal n) from the polygon c[0..3], clipped to n . (x - p) >= 0. */
static double irradiance(const dvec c[4], dvec p, dvec n)
{
    dvec v[8];
    int nv = 0;
    for (int i = 0; i < 4; i++) { /* Sutherland-Hodgman against the tangent plane */
        dvec a = dsub(c[i], p), b = dsub(c[(i + 1) % 4], p);
        double da = ddot(a, n), db = ddot(b, n);
        if (da >= 0.0)
            v[nv++] = a;
        if ((da >= 0.0) != (db >= 0.0))
            v[nv++] = dlerp(a, b, da / (da - db));
    }
    double sum = 0.0;
    for (int i = 0; i < nv; i++) {
        dvec a = v[i], b = v[(i + 1) % nv], g = dcross(a, b);
        double lg = dlen(g);
        if (!(lg > 0.0))
            continue;
        double th = atan2(lg, ddot(a, b));
        sum += th * ddot(n, g) / lg;
    }
    return 0.5 * fabs(sum);
}

/* The lamp's rectangle p0 + a ex + b ey, its emitting normal, and the lights (triangles 0 and 1). */
typedef struct lamp { murk_vec3 p0, ex, ey, n; } lamp;

/* Where the ray p + t w meets the lamp's front side: 1 and a hit as intersect() fills it for lights. */
static int hit_lamp(const lamp *L, murk_vec3 p, murk_vec3 w, murk_hit *hit)
{
    float dn = murk_dot(w, L->n);
    if (!(dn < 0.0f))
        return 0;
    float t = murk_dot(murk_sub(L->p0, p), L->n) / dn;
    if (!(t > 0.0f))
        return 0;
    murk_vec3 q = murk_madd(p, w, t), d = murk_sub(q, L->p0);
    float a = murk_dot(d, L->ex) / murk_dot(L->ex, L->ex), b = murk_dot(d, L->ey) / murk_dot(L->ey, L->ey);
    if (!(a >= 0.0f && a <= 1.0f && b >= 0.0f && b <= 1.0f))
        return 0;
    memset(hit, 0, sizeof *hit);
    hit->p = q;
    hit->t = t;
    hit->light = b <= a ? 0 : 1; /* load.c's put_quad: (p0 p1 p2) then (p0 p2 p3) */
    return 1;
}

static float power(float a, float b) { return a * a + b * b > 0.0f ? a * a / (a * a + b * b) : 0.0f; }

enum { NEE_AREA, NEE_SOLID, MIS_AREA, MIS_SOLID, NEST };
static const char *const EST_NAME[NEST] = {"area", "solid_angle", "MIS area", "MIS solid_angle"};

/* One estimate of E / Le at p by estimator k, from the numbers u[0..4]. */
static double estimate(const murk_host *h, const murk_scene *s, const lamp *L, murk_vec3 p, murk_vec3 n, int k,
                       const float u[5])
{
    int strategy = k == NEE_AREA || k == MIS_AREA ? MURK_LIGHT_AREA : MURK_LIGHT_SOLID_ANGLE;
    int mis = k >= MIS_AREA;
    double e = 0.0;
    murk_light_sample ls;
    if (h->sample_light_with(s, p, u, strategy, &ls)) {
        float c = murk_dot(n, ls.wi);
        if (c > 0.0f) {
            float w = mis ? power(ls.pdf, c / MURK_PI) : 1.0f;
            e += (double)c / ls.pdf * w;
        }
    }
    if (mis) { /* a cosine-sampled direction: c / pdf = pi */
        murk_vec3 t, b;
        murk_basis(n, &t, &b);
        float r = sqrtf(u[3]), phi = 2.0f * MURK_PI * u[4];
        float cz = sqrtf(murk_maxf(0.0f, 1.0f - u[3]));
        murk_vec3 w = murk_from_local(murk_v3(r * cosf(phi), r * sinf(phi), cz), t, b, n);
        murk_hit hit;
        if (cz > 0.0f && hit_lamp(L, p, w, &hit))
            e += MURK_PI * power(cz / MURK_PI, h->light_pdf_with(s, p, &hit, strategy));
    }
    return e;
}

/* Points around the lamp (offsets from its centre (0, 1.99, 0); the normal faces the lamp's side). */
typedef struct probe { const char *label; float p[3], n[3]; } probe;
static const probe PROBES[] = {
    {"floor centre", {0, 0, 0}, {0, 1, 0}},
    {"floor corner", {0.9f, 0, -0.9f}, {0, 1, 0}},
    {"box top centre", {0, 1.3f, 0}, {0, 1, 0}},
    {"box top corner", {0.6f, 1.3f, 0.6f}, {0, 1, 0}},
    {"under the lamp, near", {0.1f, 1.9f, -0.2f}, {0, 1, 0}},
    {"under an edge, near", {0.5f, 1.95f, 0.1f}, {0, 1, 0}},
    {"back wall, high", {0.2f, 1.8f, -1}, {0, 0, 1}},
    {"left wall, high", {-1, 1.9f, 0.3f}, {1, 0, 0}},
    {"left wall, 1e-2 below", {-1, 1.98f, 0.0f}, {1, 0, 0}},
    {"left wall, 1e-3 below", {-1, 1.989f, 0.2f}, {1, 0, 0}},
    {"beside the lamp, 3e-4 below", {-0.7f, 1.9897f, 0.0f}, {1, 0, 0}},
    {"beside the lamp, 1e-4 below, facing it", {-0.6f, 1.9899f, 0.1f}, {1, 0, 0}},
    {"in the medium, facing up", {-0.3f, 0.7f, 0.4f}, {0, 1, 0}},
    {"in the medium, tilted", {0.4f, 1.0f, -0.3f}, {0.6f, 0.8f, 0}},
};

static murk_scene *load_lamp(void)
{
    char err[512];
    murk_scene *s = murk_scene_load(write_tmp("lamp.yaml", SCENE), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    return s;
}

static void test_direct_closed_form(void **state)
{
    (void)state;
    murk_scene *s = load_lamp();
    const murk_host *h = murk_host_table();
    const murk_vec3 c = murk_v3(0.0f, 1.99f, 0.0f), u = murk_v3(0.5f, 0.0f, 0.0f), v = murk_v3(0.0f, 0.0f, 0.5f);
    lamp L;
    L.p0 = murk_sub(murk_sub(c, u), v);
    L.ex = murk_mul(u, 2.0f);
    L.ey = murk_mul(v, 2.0f);
    L.n = murk_normalize(murk_cross(L.ex, L.ey));
    const dvec corners[4] = {dv(L.p0), dv(murk_add(L.p0, L.ex)), dv(murk_add(L.p0, murk_add(L.ex, L.ey))),
                             dv(murk_add(L.p0, L.ey))};
    enum { N = 100000 };
    int nbad = 0;
    double zsum[NEST] = {0}, zbright[NEST] = {0};
    const size_t np = sizeof PROBES / sizeof PROBES[0];
    for (size_t i = 0; i < np; i++) {
        murk_vec3 p = murk_add(c, murk_v3(PROBES[i].p[0], PROBES[i].p[1] - 1.99f, PROBES[i].p[2]));
        murk_vec3 n = murk_normalize(murk_v3(PROBES[i].n[0], PROBES[i].n[1], PROBES[i].n[2]));
        double exact = irradiance(corners, dv(p), dv(n));
        printf("%-40s E/Le %.6g:", PROBES[i].label, exact);
        for (int k = 0; k < NEST; k++) {
            murk_rng rng;
            murk_rng_seed(&rng, 17, i, (uint64_t)k);
            double sum = 0.0, sum2 = 0.0;
            for (long j = 0; j < N; j++) {
                float uu[5];
                for (int q = 0; q < 5; q++)
                    uu[q] = murk_rng_float(&rng);
                double e = estimate(h, s, &L, p, n, k, uu);
                sum += e;
                sum2 += e * e;
            }
            double mean = sum / N, se = sqrt(fmax(0.0, sum2 / N - mean * mean) / N);
            double z = se > 0.0 ? (mean - exact) / se : (fabs(mean - exact) > 1e-7 * exact ? 1e9 : 0.0);
            zsum[k] += z;
            printf("  %s %+.2e (z %+.1f)", EST_NAME[k], mean / exact - 1.0, z);
            nbad += !stat_z_ok(mean, se, exact, 1e-7 * exact);
            zbright[k] = fmax(zbright[k], se > 0.0 ? fabs(mean - 1.002 * exact) / se : INFINITY);
        }
        printf("\n");
    }
    printf("mean z:");
    for (int k = 0; k < NEST; k++)
        printf("  %s %+.2f", EST_NAME[k], zsum[k] / (double)np);
    printf("\n");
    for (int k = 0; k < NEST; k++) {
        char label[96];
        snprintf(label, sizeof label, "%s against an irradiance 0.2%% higher (its best point)", EST_NAME[k]);
        nbad += !stat_must_fail(label, zbright[k] > STAT_Z, zbright[k]);
    }
    murk_scene_free(s);
    assert_int_equal(nbad, 0);
}

/* A point on the lamp itself — its back, hit from the gap under the ceiling, where the integrator's frame
 * faces away from the lamp's emitting side — lies on the lamp's plane up to rounding (either way).
 * Neither strategy may light it with the lamp: a point rounded to the emitting side saw the rectangle
 * fill its hemisphere (solid angle 2 pi, far above the area fallback's threshold) and received
 * E / Le = pi from solid-angle sampling, while area sampling (and the path tracer's BSDF rays, offset off
 * the surface) find nothing there; the lamp's back glowed, and the box scene of test_boundaries rendered
 * 0.1 % brighter with light_sampling: solid_angle. */
static void test_point_on_the_lamp(void **state)
{
    (void)state;
    murk_scene *s = load_lamp();
    const murk_host *h = murk_host_table();
    const murk_vec3 p0 = murk_v3(-0.5f, 1.99f, -0.5f), ex = murk_v3(1.0f, 0.0f, 0.0f), ey = murk_v3(0.0f, 0.0f, 1.0f);
    const murk_vec3 up = murk_v3(0.0f, 1.0f, 0.0f);
    int nlit = 0, npts = 0;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++)
            for (int k = -2; k <= 2; k++) { /* the plane's float, and two floats to either side */
                murk_vec3 p = murk_add(p0, murk_add(murk_mul(ex, 0.1f + 0.2f * (float)i), murk_mul(ey, 0.07f + 0.21f * (float)j)));
                for (int q = 0; q < (k < 0 ? -k : k); q++)
                    p.y = nextafterf(p.y, k < 0 ? 0.0f : 4.0f);
                for (int strategy = MURK_LIGHT_AREA; strategy <= MURK_LIGHT_SOLID_ANGLE; strategy++) {
                    murk_rng rng;
                    murk_rng_seed(&rng, 19, (uint64_t)(25 * i + 5 * j + k + 2), (uint64_t)strategy);
                    double e = 0.0;
                    enum { N = 4096 };
                    for (int m = 0; m < N; m++) {
                        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
                        murk_light_sample ls;
                        if (h->sample_light_with(s, p, u, strategy, &ls) && murk_dot(ls.wi, up) > 0.0f)
                            e += murk_dot(ls.wi, up) / ls.pdf / N;
                    }
                    npts++;
                    if (!(e < 1e-3)) {
                        nlit++;
                        printf("(%.2f, %.9g, %.2f) %s: E/Le %.4g from its own lamp\n", p.x, p.y, p.z,
                               strategy == MURK_LIGHT_AREA ? "area" : "solid_angle", e);
                    }
                }
            }
    printf("%d of %d points on the lamp lit by it\n", nlit, npts);
    murk_scene_free(s);
    assert_int_equal(nlit, 0);
}

/* The report's test (suite 'long'): test_boundaries' box scene (a medium box under the ceiling lamp,
 * volpath_nee) with light_sampling solid_angle against area, block-wise z-test (img_stack_agree: no 4x4
 * block beyond STAT_Z sigma, the mean z over the 64 blocks within STAT_Z / 8). At 8 seeds x 1024 spp a
 * block's standard error is about 0.1 % (printed), so the mean z of a 0.1 % bias over the image is
 * about 8; before the fix above it was. Must-fail: one block 1 % brighter. */
static void long_box_scene_area_vs_solid_angle(void **state)
{
    (void)state;
    static const char *const text =
        "murk: 1\n"
        "render: { resolution: [32, 32], spp: 1024, seed: 0 }\n"
        "camera: { from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40 }\n"
        "integrator: { type: volpath_nee, max_depth: 1000 }\n"
        "materials:\n"
        "  white: { type: diffuse, albedo: [0.73, 0.73, 0.73] }\n"
        "  red: { type: diffuse, albedo: [0.5, 0.5, 0.5] }\n"
        "  green: { type: diffuse, albedo: [0.3, 0.3, 0.3] }\n"
        "media:\n"
        "  smoke: { type: delta, density: { constant: 1 }, sigma_a: [0.05, 0.1, 0.2], sigma_s: [0.5, 0.5, 0.5] }\n"
        "shapes:\n"
        "  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: white }\n"
        "  - { type: quad, center: [0, 2, 0], u: [1, 0, 0], v: [0, 0, 1], material: white }\n"
        "  - { type: quad, center: [0, 1, -1], u: [1, 0, 0], v: [0, 1, 0], material: white }\n"
        "  - { type: quad, center: [-1, 1, 0], u: [0, 1, 0], v: [0, 0, 1], material: red }\n"
        "  - { type: quad, center: [1, 1, 0], u: [0, 0, 1], v: [0, 1, 0], material: green }\n"
        "  - { type: quad, center: [0, 1.99, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: [3, 3, 3] }\n"
        "  - { type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], interior: smoke }\n";
    static const char *const area[] = {"--set", "integrator.light_sampling=area", NULL};
    static const char *const solid[] = {"--set", "integrator.light_sampling=solid_angle", NULL};
    const char *scene = write_tmp("box.yaml", text);
    img_stack a, b;
    img_stack_render(&a, scene, "solid_angle.exr", 8, 10, solid);
    img_stack_render(&b, scene, "area.exr", 8, 1000, area);
    int ok = img_stack_agree("box scene, solid_angle against area", &a, &b, 4);
    ok &= img_stack_must_differ_block("box scene, solid_angle against area", &a, &b, 4, 0.01);
    img_stack_free(&a);
    img_stack_free(&b);
    assert_true(ok);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_direct_closed_form),
        cmocka_unit_test(test_point_on_the_lamp),
        cmocka_unit_test(long_box_scene_area_vs_solid_angle),
    };
    return STAT_RUN(tests, argc, argv);
}
