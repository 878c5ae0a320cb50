/* test_boundaries.c — light transport through index-matched medium boundaries.
 *
 *   shadow      murk_pt_shadow (the shadow rays of path, volpath and volpath_nee), in-process: from a
 *               point inside a homogeneous medium box, or on a floor below it, to a point outside —
 *               on a ceiling lamp parallel to the box's top face, or exactly past an edge or a corner
 *               of the box — through one or two boundaries. Every tracker's mean transmittance must
 *               be exp(-sigma_t,c d_inside) per channel within STAT_Z standard errors (d_inside: the
 *               segment's length inside the box, by slab clipping; stat.h); a segment that passes the
 *               box must give exactly 1; with media off (`path`) every segment must give exactly 1. (The
 *               tolerance adds the float geometry's share: boundary offsets of 1e-4 move d by < 1e-3.)
 *               Must-fail: each tracker's estimates against a path 10 % longer inside the box.
 *   shadow_once a blocked shadow ray from vacuum is traced once: without boundaries (host->boundaries()
 *               0) occluded() alone, with them the first leg's intersect() alone; the Cornell box renders
 *               bitwise what it renders with an index-matched box out of every ray's reach added, with as
 *               many rays.
 *   empty_box   a medium box or sphere with nothing else inside (render/accel.h) is found, and one that
 *               a sphere, a quad (inside, on a face or 1e-5 off it) or a nested shape meets is not; from
 *               inside it the host answers intersect() and occluded() by a slab test or a quadratic, with
 *               no Embree ray (the thread's ray count stays put), and agrees with Embree on 20000 random
 *               rays each: the same shape, t and p within 2e-5, the normal to 1e-5, the same media and
 *               answers for shortened rays; rays from outside go to Embree, whose tree leaves the shape
 *               out, and the host's entry test finds it (also among two boxes). Must-fail: the box
 *               declared empty in the scene with the sphere inside hides the sphere; without the entry
 *               test the box is missing for a ray from outside.
 * In the suite 'long' (long_* tests, 32x32, 8 seeds, 8x8-pixel blocks: 16 blocks, each with the
 * samples of test_boundaries_long's 64x64 blocks, at a quarter of its cost: a block's standard error is
 * about 0.1 % of its value):
 *   nee         volpath_nee (light sampling + MIS) against volpath (BSDF / phase sampling only) on a
 *               Cornell box holding a medium behind an index-matched boundary, the light outside it:
 *               box, sphere and mesh boundaries, grey and chromatic media, camera outside and inside
 *               (twelve configurations). Two independent estimators of the same image: block-wise z-test
 *               (img_stack_agree); must-fail: one block of the first configuration 1 % brighter.
 *   path        `path` (surfaces only) with an index-matched box in the room renders what it renders
 *               without the box: its paths pass boundaries, and so must its shadow rays. The two share
 *               no seeds (a shared seed makes the renders nearly equal, and their difference no normal
 *               variable the block test could judge); must-fail: one block 1 % brighter.
 *
 * Both failed before the fix of shadow rays that restarted off their line after a boundary and hit
 * the lamp itself (and of `path`'s shadow rays that stopped at boundaries). */
#include "testutil.h"
#include "stat.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/accel.h"
#include "render/host.h"
#include "pathtracer.h"
#include "scene/scene.h"

#define NEE_RES 32
#define NEE_BLOCK 8
#define NEE_SEEDS 8
#define NEE_SPP "2048"
#define BSDF_SPP "render.spp=8192" /* volpath finds the lamp by chance only: 4x the samples */

static int nfail;

/* ---- shadow rays in closed form ---------------------------------------------------------------- */

static const double BOX_LO[3] = {-0.6, 0.1, -0.6}, BOX_HI[3] = {0.6, 1.3, 0.6};
static const double SIGMA_T[3] = {0.5, 0.8, 1.4}; /* sigma_a [0.3, 0.6, 1.2] + sigma_s 0.2 */

/* Length of the segment a -> b inside the box. */
static double inside_length(const double a[3], const double b[3])
{
    double t0 = 0.0, t1 = 1.0;
    for (int k = 0; k < 3; k++) {
        double d = b[k] - a[k];
        if (d == 0.0) {
            if (a[k] < BOX_LO[k] || a[k] > BOX_HI[k])
                return 0.0;
            continue;
        }
        double ta = (BOX_LO[k] - a[k]) / d, tb = (BOX_HI[k] - a[k]) / d;
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }
    double len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    return t1 > t0 ? (t1 - t0) * len : 0.0;
}

typedef struct shadow_case {
    const char *label;
    double p[3], n[3], q[3]; /* n: the surface normal at p, zero for a point in a medium */
    int inside;              /* p lies in the box's medium */
} shadow_case;

/* q beyond the point e (on an edge or a corner) on the line from p: the segment leaves through e. */
static void through(shadow_case *c, const double e[3], double k)
{
    for (int i = 0; i < 3; i++)
        c->q[i] = e[i] + k * (e[i] - c->p[i]);
}

/* The bias the shadow test exists for: a segment's length inside the medium off by LONGER. */
#define LONGER 0.1

static void test_shadow(void **state)
{
    (void)state;
    nfail = 0;
    const char *scene_text =
        "murk: 1\n"
        "materials: { lamp: { type: diffuse, albedo: 0 }, floor: { type: diffuse, albedo: 0.5 } }\n"
        "media: { m: { type: %s, density: { constant: 1 }, sigma_a: [0.3, 0.6, 1.2], sigma_s: 0.2 } }\n"
        "shapes:\n"
        "  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: floor }\n"
        "  - { type: quad, center: [0, 1.99, 0], u: [0.25, 0, 0], v: [0, 0, 0.25], material: lamp, emission: 1 }\n"
        "  - { type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], interior: m }\n";
    shadow_case cases[] = {
        {"inside -> lamp", {0.3, 0.7, 0.2}, {0, 0, 0}, {-0.2, 1.99, -0.1}, 1},
        {"inside near top edge -> lamp", {-0.58, 1.27, 0.0}, {0, 0, 0}, {0.24, 1.99, 0.2}, 1},
        {"inside near corner -> lamp", {0.58, 1.28, 0.57}, {0, 0, 0}, {-0.24, 1.99, -0.24}, 1},
        {"inside, far and slanted -> lamp", {-0.5, 0.3, 0.5}, {0, 0, 0}, {0.25, 1.99, -0.25}, 1},
        {"inside -> exactly through top edge", {0.2, 0.9, 0.0}, {0, 0, 0}, {0}, 1},
        {"inside -> exactly through corner", {0.0, 0.7, 0.1}, {0, 0, 0}, {0}, 1},
        {"floor -> two boundaries -> lamp", {0.1, 0.0, 0.3}, {0, 1, 0}, {-0.1, 1.99, -0.2}, 0},
        {"floor -> side and top -> lamp", {0.9, 0.0, 0.05}, {0, 1, 0}, {0.2, 1.99, 0.0}, 0},
        {"floor -> past the box -> lamp", {0.95, 0.0, 0.9}, {0, 1, 0}, {0.24, 1.99, 0.24}, 0},
    };
    static const double edge[3] = {0.6, 1.3, 0.0}, corner[3] = {0.6, 1.3, 0.6};
    through(&cases[4], edge, 1.5);
    through(&cases[5], corner, 0.5);
    static const char *const trackers[] = {"delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"};
    const int N = 4000;
    for (size_t t = 0; t < sizeof trackers / sizeof trackers[0]; t++) {
        char text[2048], err[1024];
        snprintf(text, sizeof text, scene_text, trackers[t]);
        murk_scene *s = murk_scene_load(write_tmp("shadow.yaml", text), NULL, 0, err, sizeof err);
        if (!s)
            fail_msg("%s", err);
        const murk_medium *med = &s->media[0].m;
        for (int media = 1; media >= 0; media--) {
            murk_pt pt = {murk_host_table(), 64, 3, 1, media, MURK_LIGHT_AREA, 1.0f, 0, 0};
            for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
                const shadow_case *sc = &cases[c];
                double d = inside_length(sc->p, sc->q), s1[3] = {0}, s2[3] = {0};
                murk_vec3 p = murk_v3((float)sc->p[0], (float)sc->p[1], (float)sc->p[2]);
                murk_vec3 n = murk_v3((float)sc->n[0], (float)sc->n[1], (float)sc->n[2]);
                murk_vec3 q = murk_v3((float)sc->q[0], (float)sc->q[1], (float)sc->q[2]);
                for (int i = 0; i < N; i++) {
                    murk_rng rng;
                    murk_rng_seed(&rng, 77, c, (uint64_t)i);
                    murk_path_ctx ctx = {.hero = i % 3, .beta = murk_rgb1(1.0f)};
                    murk_rgb T = murk_pt_shadow(&pt, s, p, n, q, sc->inside ? med : NULL, &ctx, &rng);
                    for (int k = 0; k < 3; k++) {
                        s1[k] += T.c[k];
                        s2[k] += (double)T.c[k] * T.c[k];
                    }
                }
                int bad = 0;
                double zlong = 0.0;
                char line[512];
                size_t k0 = (size_t)snprintf(line, sizeof line, "  %-14s %-5s %-36s d %.4f:", trackers[t],
                                             media ? "media" : "path", sc->label, d);
                for (int k = 0; k < 3; k++) {
                    double expect = media ? exp(-SIGMA_T[k] * d) : 1.0, m = s1[k] / N;
                    double se = sqrt(fmax(0.0, s2[k] / N - m * m) / (N - 1));
                    /* + the float geometry: offsets of 1e-4 per boundary shift d by well under 1e-3 */
                    double slack = expect * SIGMA_T[k] * 1e-3 * media;
                    bad |= !(media && d > 0.0 ? stat_z_ok(m, se, expect, slack) : m == expect);
                    double longer = exp(-SIGMA_T[k] * d * (1.0 + LONGER));
                    zlong = fmax(zlong, se > 0.0 ? (fabs(m - longer) - slack) / se : INFINITY);
                    k0 += (size_t)snprintf(line + k0, sizeof line - k0, " %.4f+-%.4f (%.4f)", m, se, expect);
                }
                if (bad || c == 0)
                    printf("%s%s\n", line, bad ? "  <-- FAIL" : "");
                nfail += bad;
                if (media && d > 0.0 && c == 0) {
                    char label[96];
                    snprintf(label, sizeof label, "%s %s: against a path %g%% longer inside", trackers[t], sc->label,
                             100.0 * LONGER);
                    nfail += !stat_must_fail(label, zlong > STAT_Z, zlong);
                }
            }
        }
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* ---- volpath_nee against volpath --------------------------------------------------------------- */

/* A closed cube (outward winding) for the mesh boundary, written once. */
static const char *cube_obj(void)
{
    return write_tmp("cube.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                                 "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                                 "f 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n");
}

typedef struct nee_config {
    const char *label;
    const char *boundary; /* the shape bounding the medium */
    const char *camera;   /* extra camera keys (the camera medium) */
    const char *sigma_a;
    const char *tracker;
} nee_config;

#define GREY "0.1"
#define CHROMATIC "[0.05, 0.1, 0.2]"
#define OUTSIDE ""
#define INSIDE ", medium: smoke"

static const char *nee_scene(const nee_config *c)
{
    static char text[4096];
    char boundary[512];
    snprintf(boundary, sizeof boundary, c->boundary, cube_obj());
    snprintf(text, sizeof text,
             "murk: 1\n"
             "render: { resolution: [%d, %d], spp: %s, seed: 0 }\n"
             "camera: { from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40%s }\n"
             "integrator: { type: volpath_nee, max_depth: 1000 }\n"
             "materials:\n"
             "  white: { type: diffuse, albedo: [0.73, 0.73, 0.73] }\n"
             "  red: { type: diffuse, albedo: [0.5, 0.5, 0.5] }\n"
             "  green: { type: diffuse, albedo: [0.3, 0.3, 0.3] }\n"
             "media:\n"
             "  smoke: { type: %s, density: { constant: 1 }, sigma_a: %s, sigma_s: [0.5, 0.5, 0.5] }\n"
             "shapes:\n"
             "  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: white }\n"
             "  - { type: quad, center: [0, 2, 0], u: [1, 0, 0], v: [0, 0, 1], material: white }\n"
             "  - { type: quad, center: [0, 1, -1], u: [1, 0, 0], v: [0, 1, 0], material: white }\n"
             "  - { type: quad, center: [-1, 1, 0], u: [0, 1, 0], v: [0, 0, 1], material: red }\n"
             "  - { type: quad, center: [1, 1, 0], u: [0, 0, 1], v: [0, 1, 0], material: green }\n"
             "  - { type: quad, center: [0, 1.99, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, "
             "emission: [3, 3, 3] }\n"
             "  - %s\n",
             NEE_RES, NEE_RES, NEE_SPP, c->camera, c->tracker, c->sigma_a, boundary);
    return write_tmp("nee.yaml", text);
}

#define BOX_OUT "{ type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], interior: smoke }%.0s"
#define BOX_IN "{ type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 3.6], interior: smoke }%.0s"
#define SPHERE_OUT "{ type: sphere, center: [0.1, 0.8, 0], radius: 0.6, interior: smoke }%.0s"
#define SPHERE_IN "{ type: sphere, center: [0, 1, 3.4], radius: 1.2, interior: smoke }%.0s"
#define MESH_OUT \
    "{ type: mesh, file: %s, interior: smoke, transform: { scale: 0.5, rotate: [20, 35, 0], translate: [0, 0.8, 0] } }"
#define MESH_IN \
    "{ type: mesh, file: %s, interior: smoke, transform: { scale: 0.9, rotate: [0, 25, 0], translate: [0, 1, 3.2] } }"

static void long_nee(void **state)
{
    (void)state;
    nfail = 0;
    static const nee_config configs[] = {
        {"box, chromatic, camera outside", BOX_OUT, OUTSIDE, CHROMATIC, "delta"},
        {"sphere, grey, camera inside", SPHERE_IN, INSIDE, GREY, "spectral_mis"},
        {"mesh, chromatic, camera outside", MESH_OUT, OUTSIDE, CHROMATIC, "spectral_mis"},
        {"box, grey, camera outside", BOX_OUT, OUTSIDE, GREY, "delta"},
        {"box, chromatic, camera inside", BOX_IN, INSIDE, CHROMATIC, "spectral_mis"},
        {"box, grey, camera inside", BOX_IN, INSIDE, GREY, "delta"},
        {"sphere, chromatic, camera outside", SPHERE_OUT, OUTSIDE, CHROMATIC, "delta"},
        {"sphere, grey, camera outside", SPHERE_OUT, OUTSIDE, GREY, "delta"},
        {"sphere, chromatic, camera inside", SPHERE_IN, INSIDE, CHROMATIC, "spectral_mis"},
        {"mesh, grey, camera outside", MESH_OUT, OUTSIDE, GREY, "delta"},
        {"mesh, chromatic, camera inside", MESH_IN, INSIDE, CHROMATIC, "spectral_mis"},
        {"mesh, grey, camera inside", MESH_IN, INSIDE, GREY, "delta"},
    };
    static const char *const bsdf_only[] = {"--set", "integrator.type=volpath", "--set", BSDF_SPP, NULL};
    printf("volpath_nee against volpath (%dx%d, %d seeds x %s spp, blocks of %dx%d):\n", NEE_RES, NEE_RES, NEE_SEEDS,
           NEE_SPP, NEE_BLOCK, NEE_BLOCK);
    for (size_t i = 0; i < sizeof configs / sizeof configs[0]; i++) {
        img_stack a, b;
        const char *scene = nee_scene(&configs[i]);
        img_stack_render(&a, scene, "nee.exr", NEE_SEEDS, 10, NULL);
        img_stack_render(&b, scene, "bsdf.exr", NEE_SEEDS, 1000, bsdf_only);
        char label[128];
        snprintf(label, sizeof label, "%s (%s)", configs[i].label, configs[i].tracker);
        nfail += !img_stack_agree(label, &a, &b, NEE_BLOCK);
        if (i == 0)
            nfail += !img_stack_must_differ_block(label, &a, &b, NEE_BLOCK, 0.01);
        img_stack_free(&a);
        img_stack_free(&b);
    }
    assert_int_equal(nfail, 0);
}

/* ---- path through boundaries -------------------------------------------------------------------- */

/* `path` ignores media: a box boundary in the room must not change its image. */
static void long_path(void **state)
{
    (void)state;
    static const nee_config with = {"path", BOX_OUT, OUTSIDE, CHROMATIC, "delta"};
    static const char *const surf[] = {"--set", "integrator.type=path", NULL};
    img_stack a, b;
    const char *scene = nee_scene(&with);
    img_stack_render(&a, scene, "path_box.exr", NEE_SEEDS, 10, surf);
    /* the same room without the box: drop the last shape (and the medium it bounded) by rewriting the scene */
    char *text = NULL;
    {
        FILE *f = fopen(scene, "rb");
        assert_non_null(f);
        text = calloc(1, 8192);
        assert_non_null(text);
        size_t n = fread(text, 1, 8191, f);
        fclose(f);
        text[n] = 0;
        char *last = strstr(text, "  - { type: box");
        assert_non_null(last);
        *last = 0;
        char *media = strstr(text, "media:\n"), *shapes = strstr(text, "shapes:\n");
        assert_non_null(media);
        assert_non_null(shapes);
        memmove(media, shapes, strlen(shapes) + 1);
    }
    img_stack_render(&b, write_tmp("path_nobox.yaml", text), "path_nobox.exr", NEE_SEEDS, 1000, surf);
    free(text);
    int ok = img_stack_agree("path with and without a boundary box", &a, &b, NEE_BLOCK);
    ok &= img_stack_must_differ_block("path with and without a boundary box", &a, &b, NEE_BLOCK, 0.01);
    img_stack_free(&a);
    img_stack_free(&b);
    assert_true(ok);
}

/* The rays a render traced, from murk's "counters: N rays traced" line. */
static unsigned long long rays_traced(const char *scene, const char *out)
{
    char *log = NULL;
    const char *args[] = {"render", scene, "-o", out, "--spp", "2", "--threads", "2", "--set",
                          "render.resolution=[48,48]", NULL};
    int rc = run_murk_argv(&log, args);
    const char *at = log ? strstr(log, "counters: ") : NULL;
    unsigned long long n = 0;
    if (rc != 0 || !at || sscanf(at, "counters: %llu rays traced", &n) != 1)
        fail_msg("murk render %s (%d) printed no ray count:\n%s", scene, rc, log ? log : "");
    free(log);
    return n;
}

static void test_shadow_once(void **state)
{
    (void)state;
    FILE *f = fopen(src_path("scenes/cornell.yaml"), "rb");
    assert_non_null(f);
    char text[8192];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    char *shapes = strstr(text, "shapes:\n");
    assert_non_null(shapes);
    /* a medium and its index-matched box far below the room, outside the camera's view: no ray meets it */
    char with[9000];
    snprintf(with, sizeof with, "%.*smedia:\n  fog: { type: delta, density: { constant: 1 }, sigma_a: [0.1, 0.1, 0.1], "
             "sigma_s: [0.1, 0.1, 0.1] }\n%s  - { type: box, min: [-1, -60, -3], max: [1, -50, -2], interior: fog }\n",
             (int)(shapes - text), text, shapes);
    unsigned long long plain = rays_traced(src_path("scenes/cornell.yaml"), tmp_path("once_plain.exr"));
    unsigned long long bounded = rays_traced(write_tmp("once_boundary.yaml", with), tmp_path("once_boundary.exr"));
    printf("cornell, 48x48, 2 spp: %llu rays without a boundary, %llu with one out of reach (%.1f %% fewer)\n",
           plain, bounded, 100.0 * (1.0 - (double)plain / (double)bounded));
    assert_same_pixels(tmp_path("once_plain.exr"), tmp_path("once_boundary.exr"));
    /* with boundaries a shadow ray's first leg from vacuum is one intersect() (pathtracer.c's shadow()),
     * so a blocked one is traced once there too: the same count */
    assert_true(plain == bounded);
}

/* ---- empty medium boxes ------------------------------------------------------------------------- */

#define EBOX "  - { type: box, min: [-0.6, 0.1, -0.5], max: [0.7, 1.3, 0.4], interior: m }\n"
#define ESPHERE "  - { type: sphere, center: [0.05, 0.7, -0.05], radius: 0.55, interior: m }\n"

/* A floor, the medium shape (EBOX or ESPHERE: shape 1) and extra. */
static murk_scene *eshape_load(const char *shape, const char *extra)
{
    char text[2048], err[1024];
    snprintf(text, sizeof text,
             "murk: 1\n"
             "materials: { white: { type: diffuse, albedo: 0.5 } }\n"
             "media: { m: { type: delta, density: { constant: 1 }, sigma_a: 0.1, sigma_s: 0.5 } }\n"
             "shapes:\n"
             "  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: white }\n"
             "%s%s",
             shape, extra);
    murk_scene *s = murk_scene_load(write_tmp("ebox.yaml", text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    return s;
}

static murk_vec3 uniform_dir(murk_rng *rng)
{
    float z = 1.0f - 2.0f * murk_rng_float(rng), phi = 2.0f * MURK_PI * murk_rng_float(rng);
    float r = sqrtf(murk_maxf(0.0f, 1.0f - z * z));
    return murk_v3(r * cosf(phi), r * sinf(phi), z);
}

/* The same scene answered by Embree alone: its empty shapes' and few spheres' geometry put back into
 * Embree's tree (the loader leaves it out) and the host's shortcuts switched off. */
static murk_scene *eshape_embree(const char *shape, const char *extra)
{
    murk_scene *s = eshape_load(shape, extra);
    for (size_t i = 0; i < s->nempty_shapes; i++)
        rtcEnableGeometry(rtcGetGeometry(s->rtc, s->empty_shapes[i].geom));
    for (size_t i = 0; i < s->nfew_spheres; i++)
        rtcEnableGeometry(rtcGetGeometry(s->rtc, s->few_spheres[i]));
    rtcCommitScene(s->rtc);
    s->nempty_shapes = 0;
    s->nfew_spheres = 0;
    return s;
}

/* Whether two media or materials (of two loads of one scene) are the one of that name, or both none. */
#define same_name(x, y) ((x) == NULL ? (y) == NULL : (y) != NULL && strcmp((x)->name, (y)->name) == 0)

/* Whether the host's answers for r with scene s's empty shapes equal Embree's alone on ref (eshape_embree:
 * the same scene); *shortcut gets 1 if the first answer traced no Embree ray. Prints the disagreement. */
static int eshape_agrees(murk_scene *s, murk_scene *ref, const murk_ray *r, int *shortcut)
{
    const murk_host *h = murk_host_table();
    murk_hit a, b;
    uint64_t before = murk_host_thread_rays();
    int fa = h->intersect(s, r, &a), oa = h->occluded(s, r);
    *shortcut = murk_host_thread_rays() == before;
    int fb = h->intersect(ref, r, &b), ob = h->occluded(ref, r);
    int ok = fa == fb && oa == ob;
    if (ok && fa) {
        float tol = 2e-5f * murk_maxf(1.0f, b.t);
        ok = a.geom == b.geom && fabsf(a.t - b.t) <= tol && murk_length(murk_sub(a.p, b.p)) <= tol &&
             murk_dot(a.ng, b.ng) > 0.99999f && murk_dot(a.n, b.n) > 0.99999f && fabsf(a.u - b.u) <= 1e-4f &&
             fabsf(a.v - b.v) <= 1e-4f && same_name(a.interior, b.interior) && same_name(a.exterior, b.exterior) &&
             same_name(a.material, b.material) && a.light == b.light &&
             memcmp(a.emission.c, b.emission.c, sizeof a.emission.c) == 0;
    }
    if (!ok)
        printf("  ray (%g %g %g) -> (%g %g %g), tmax %g: host %d/%d geom %u t %.7g, Embree %d/%d geom %u t %.7g\n",
               (double)r->o.x, (double)r->o.y, (double)r->o.z, (double)r->d.x, (double)r->d.y, (double)r->d.z,
               (double)r->tmax, fa, oa, fa ? a.geom : 0u, fa ? (double)a.t : 0.0, fb, ob, fb ? b.geom : 0u,
               fb ? (double)b.t : 0.0);
    return ok;
}

/* Whether o lies inside empty shape e (strictly, for a sphere). */
static int in_eshape(const murk_empty_shape *e, murk_vec3 o)
{
    murk_vec3 oc = murk_sub(o, e->center);
    return e->sphere ? murk_dot(oc, oc) < e->radius * e->radius
                     : o.x >= e->lo.x && o.x <= e->hi.x && o.y >= e->lo.y && o.y <= e->hi.y && o.z >= e->lo.z &&
                           o.z <= e->hi.z;
}

/* Random rays with origins over a box around the medium shapes (most inside one: the shortcut; the rest
 * outside: Embree, and the entry test for the shapes Embree's tree leaves out), each also cut short before
 * and after its hit: the host's answers on s against Embree's alone on ref (eshape_embree). Returns the
 * disagreements; *shortcuts counts the rays that traced no Embree ray, *inside those that start inside a
 * shape, *entered those from outside whose first hit is an empty shape. */
static int eshape_rays(murk_scene *s, murk_scene *ref, murk_vec3 lo, murk_vec3 hi, int n, int *shortcuts,
                       int *inside, int *entered)
{
    murk_rng rng;
    murk_rng_seed(&rng, 7, 1, 2);
    int bad = 0;
    *shortcuts = *inside = *entered = 0;
    for (int i = 0; i < n; i++) {
        murk_vec3 o = murk_v3(lo.x + (hi.x - lo.x) * murk_rng_float(&rng), lo.y + (hi.y - lo.y) * murk_rng_float(&rng),
                              lo.z + (hi.z - lo.z) * murk_rng_float(&rng));
        murk_ray r = {o, uniform_dir(&rng), 0.0f, INFINITY};
        int sc, in = 0, empty_hit = 0;
        bad += !eshape_agrees(s, ref, &r, &sc);
        *shortcuts += sc;
        murk_hit hit;
        if (murk_host_table()->intersect(s, &r, &hit)) { /* shortened: ends before the hit, or just past it */
            for (size_t k = 0; k < s->nempty_shapes; k++)
                empty_hit |= hit.geom == s->empty_shapes[k].geom;
            r.tmax = 0.5f * hit.t;
            bad += !eshape_agrees(s, ref, &r, &sc);
            r.tmax = 1.5f * hit.t;
            bad += !eshape_agrees(s, ref, &r, &sc);
        }
        for (size_t k = 0; k < s->nempty_shapes; k++)
            in |= in_eshape(&s->empty_shapes[k], o);
        *inside += in;
        *entered += !in && empty_hit;
    }
    return bad;
}

static void test_empty_box(void **state)
{
    (void)state;
    /* the medium shape is shape 1; first: the first empty shape's index (-1: none) */
    static const struct { const char *label, *shape, *extra; size_t n; int first; } found[] = {
        {"box alone", EBOX, "", 1, 1},
        {"box, a sphere inside", EBOX, "  - { type: sphere, center: [0, 0.7, 0], radius: 0.1, material: white }\n", 0, -1},
        {"box, a quad touching its face", EBOX, "  - { type: quad, center: [0, 0.1, 0], u: [0, 0, 0.2], "
                                                "v: [0.2, 0, 0], material: white }\n", 0, -1},
        {"box, a quad 1e-5 below its face", EBOX, "  - { type: quad, center: [0, 0.09999, 0], u: [0, 0, 0.2], "
                                                  "v: [0.2, 0, 0], material: white }\n", 0, -1},
        {"box, a medium box nested in it (itself empty)", EBOX, "  - { type: box, min: [0, 0.5, 0], "
                                                                "max: [0.2, 0.7, 0.2], interior: m }\n", 1, 2},
        {"box, an opaque box beside it", EBOX, "  - { type: box, min: [0.8, 0, 0], max: [0.9, 0.2, 0.1], "
                                               "material: white }\n", 1, 1},
        {"box, a second medium box beside it", EBOX, "  - { type: box, min: [0.8, 0.05, 0], max: [0.9, 0.2, 0.1], "
                                                     "interior: m }\n", 2, 1},
        {"sphere alone", ESPHERE, "", 1, 1},
        {"sphere, a quad inside", ESPHERE, "  - { type: quad, center: [0, 0.7, 0], u: [0, 0, 0.1], v: [0.1, 0, 0], "
                                           "material: white }\n", 0, -1},
        {"sphere, a medium sphere nested in it (a sphere's bounds are its box: neither counts)", ESPHERE,
         "  - { type: sphere, center: [0, 0.7, 0], radius: 0.1, interior: m }\n", 0, -1},
    };
    for (size_t i = 0; i < sizeof found / sizeof found[0]; i++) {
        murk_scene *s = eshape_load(found[i].shape, found[i].extra);
        int first = s->nempty_shapes ? (int)s->empty_shapes[0].geom : -1;
        printf("%s: %zu empty medium shapes, the first shape %d (expected %zu, %d)\n", found[i].label,
               s->nempty_shapes, first, found[i].n, found[i].first);
        assert_int_equal(s->nempty_shapes, found[i].n);
        assert_int_equal(first, found[i].first);
        murk_scene_free(s);
    }
    /* origins over a box a little larger than the shapes' bounds */
    static const struct { const char *label, *shape, *extra; float lo[3], hi[3]; } rays[] = {
        {"box", EBOX, "", {-0.65f, 0.05f, -0.55f}, {0.75f, 1.35f, 0.45f}},
        {"sphere", ESPHERE, "", {-0.55f, 0.1f, -0.65f}, {0.65f, 1.3f, 0.55f}},
        {"two boxes", EBOX, "  - { type: box, min: [0.8, 0.05, 0], max: [0.9, 0.2, 0.1], interior: m }\n",
         {-0.65f, 0.0f, -0.55f}, {0.95f, 1.35f, 0.45f}},
    };
    murk_scene *s = NULL;
    for (size_t i = 0; i < sizeof rays / sizeof rays[0]; i++) {
        const int N = 20000;
        int shortcuts, inside, entered;
        murk_scene *e = eshape_load(rays[i].shape, rays[i].extra), *ref = eshape_embree(rays[i].shape, rays[i].extra);
        int bad = eshape_rays(e, ref, murk_v3(rays[i].lo[0], rays[i].lo[1], rays[i].lo[2]),
                              murk_v3(rays[i].hi[0], rays[i].hi[1], rays[i].hi[2]), N, &shortcuts, &inside, &entered);
        printf("empty %s: %d rays, %d from inside, %d answered without Embree, %d from outside entering one, "
               "%d disagreements\n", rays[i].label, N, inside, shortcuts, entered, bad);
        assert_int_equal(bad, 0);
        assert_int_equal(shortcuts, inside);
        assert_true(entered > N / 50); /* the entry test is exercised */
        murk_scene_free(ref);
        if (i == 0)
            s = e; /* the box, for the must-fail below */
        else
            murk_scene_free(e);
    }
    /* must fail: the same box declared empty where a sphere sits inside hides the sphere from a ray aimed
     * at it (the detection above is what prevents this) */
    murk_scene *t = eshape_load(EBOX, "  - { type: sphere, center: [0, 0.7, 0], radius: 0.1, material: white }\n");
    murk_scene *tref = eshape_embree(EBOX, "  - { type: sphere, center: [0, 0.7, 0], radius: 0.1, material: white }\n");
    assert_int_equal(t->nempty_shapes, 0);
    murk_empty_shape wrong = s->empty_shapes[0];
    t->empty_shapes = &wrong;
    t->nempty_shapes = 1;
    murk_ray at_sphere = {murk_v3(0.5f, 0.7f, 0.0f), murk_v3(-1.0f, 0.0f, 0.0f), 0.0f, INFINITY};
    int sc;
    int agrees = eshape_agrees(t, tref, &at_sphere, &sc);
    printf("must fail: a box wrongly declared empty around a sphere %s\n", agrees ? "went unnoticed" : "is seen");
    assert_false(agrees);
    t->empty_shapes = NULL;
    t->nempty_shapes = 0;
    /* must fail: without its entry test the box is missing for a ray from outside (Embree's tree leaves it
     * out), which the comparison sees */
    murk_scene *sref = eshape_embree(EBOX, "");
    murk_ray at_box = {murk_v3(0.0f, 0.7f, 2.0f), murk_v3(0.0f, 0.0f, -1.0f), 0.0f, INFINITY};
    assert_true(eshape_agrees(s, sref, &at_box, &sc));
    size_t n = s->nempty_shapes;
    s->nempty_shapes = 0;
    agrees = eshape_agrees(s, sref, &at_box, &sc);
    s->nempty_shapes = n;
    printf("must fail: the box without its entry test %s\n", agrees ? "went unnoticed" : "is seen");
    assert_false(agrees);
    /* must fail: the faces' copies of their corners' (u, v), from which the host fills a hit on the box
     * (accel.h), with u and v swapped: the hit's (u, v) differ from Embree's (0.46, 0.5 there) */
    murk_empty_shape keep = s->empty_shapes[0];
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 2; k++)
            for (int c = 0; c < 3; c++) {
                float *uv = &s->empty_shapes[0].tri[f][k].uv[2 * c], u0 = uv[0];
                uv[0] = uv[1];
                uv[1] = u0;
            }
    agrees = eshape_agrees(s, sref, &at_box, &sc);
    s->empty_shapes[0] = keep;
    printf("must fail: the box's (u, v) swapped in its faces' copies %s\n", agrees ? "went unnoticed" : "is seen");
    assert_false(agrees);
    murk_scene_free(sref);
    murk_scene_free(t);
    murk_scene_free(tref);
    murk_scene_free(s);
}

/* A scene's few spheres (render/accel.h) are intersected by the host, not Embree: its answers against
 * Embree's with the spheres put back, for random rays from inside and outside them. */
static void test_few_spheres(void **state)
{
    (void)state;
    /* shape 1 and the rest: a sphere, one overlapping it, a medium sphere with a quad inside (not empty) */
    static const char *first = "  - { type: sphere, center: [0, 0.5, 0], radius: 0.4, material: white }\n";
    static const char *rest =
        "  - { type: sphere, center: [0.3, 0.65, 0.1], radius: 0.2, material: white }\n"
        "  - { type: sphere, center: [-0.5, 1.0, -0.3], radius: 0.3, interior: m }\n"
        "  - { type: quad, center: [-0.5, 1.0, -0.3], u: [0.1, 0, 0], v: [0, 0, 0.1], material: white }\n";
    murk_scene *s = eshape_load(first, rest), *ref = eshape_embree(first, rest);
    printf("few spheres: %zu host-intersected spheres (expected 3), %zu empty shapes\n", s->nfew_spheres,
           s->nempty_shapes);
    assert_int_equal(s->nfew_spheres, 3);
    assert_int_equal(s->nempty_shapes, 0);
    const int N = 20000;
    int shortcuts, inside, entered;
    int bad = eshape_rays(s, ref, murk_v3(-0.9f, -0.1f, -0.7f), murk_v3(0.6f, 1.4f, 0.6f), N, &shortcuts, &inside,
                          &entered);
    /* how many of those rays the spheres answer (the same rays: eshape_rays' seed) */
    murk_rng rng;
    murk_rng_seed(&rng, 7, 1, 2);
    int on_sphere = 0;
    for (int i = 0; i < N; i++) {
        murk_vec3 o = murk_v3(-0.9f + 1.5f * murk_rng_float(&rng), -0.1f + 1.5f * murk_rng_float(&rng),
                              -0.7f + 1.3f * murk_rng_float(&rng));
        murk_ray r = {o, uniform_dir(&rng), 0.0f, INFINITY};
        murk_hit hit;
        on_sphere += murk_host_table()->intersect(s, &r, &hit) && s->shapes[hit.geom].type == MURK_SHAPE_SPHERE;
    }
    printf("few spheres: %d rays, %d hit a sphere, %d answered without Embree, %d disagreements\n", N, on_sphere,
           shortcuts, bad);
    assert_int_equal(bad, 0);
    assert_true(on_sphere > N / 10);
    /* must fail: the spheres left out of Embree's tree and not intersected by the host are missing */
    size_t n = s->nfew_spheres;
    s->nfew_spheres = 0;
    murk_ray at_sphere = {murk_v3(0.0f, 0.5f, 2.0f), murk_v3(0.0f, 0.0f, -1.0f), 0.0f, INFINITY};
    int sc, agrees = eshape_agrees(s, ref, &at_sphere, &sc);
    s->nfew_spheres = n;
    printf("must fail: the few spheres without the host's test %s\n", agrees ? "went unnoticed" : "are seen");
    assert_false(agrees);
    assert_true(eshape_agrees(s, ref, &at_sphere, &sc));
    murk_scene_free(ref);
    murk_scene_free(s);
    /* more spheres than MURK_FEW_SPHERES: all stay in Embree's tree */
    char many[1024] = "";
    for (int i = 0; i < MURK_FEW_SPHERES; i++)
        snprintf(many + strlen(many), sizeof many - strlen(many),
                 "  - { type: sphere, center: [%d, 2, 0], radius: 0.1, material: white }\n", i);
    s = eshape_load(first, many);
    printf("%d spheres: %zu host-intersected (expected 0)\n", MURK_FEW_SPHERES + 1, s->nfew_spheres);
    assert_int_equal(s->nfew_spheres, 0);
    murk_scene_free(s);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadow),
        cmocka_unit_test(test_shadow_once),
        cmocka_unit_test(test_empty_box),
        cmocka_unit_test(test_few_spheres),
        cmocka_unit_test(long_nee),
        cmocka_unit_test(long_path),
    };
    return STAT_RUN(tests, argc, argv);
}
