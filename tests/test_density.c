/* test_density.c — density fields (core/density.c): trilinear interpolation over cell centres, clamp
 * and 0 outside, .vol round trip and errors, NanoVDB loading (files written here by a minimal
 * writer of an uncompressed single-segment NanoVDB 32.4 float grid), majorant/minorant bounds,
 * DDA tiling, the procedural cloud. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "media/density.h"

static char err[1024];

static float frand(murk_rng *r, float a, float b) { return a + (b - a) * murk_rng_float(r); }
static float v3(murk_vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

static const char *tmp_file(const char *name)
{
    static char bufs[4][512];
    static int next;
    char *b = bufs[next++ & 3];
    snprintf(b, sizeof bufs[0], "%s/%s", tmp_dir(), name);
    return b;
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static unsigned char *read_bytes(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*n + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, *n, f), *n);
    fclose(f);
    return b;
}

static void expect_err(const char *path, const char *needle)
{
    if (!strstr(err, path) || !strstr(err, needle))
        fail_msg("error \"%s\" should name %s and mention \"%s\"", err, path, needle);
}

/* ---- Little-endian writers ------------------------------------------------------------------ */

static void put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static void put64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static void putf(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put32(p, u);
}
static void putd(unsigned char *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    put64(p, u);
}

/* A .vol image: 48-byte header + data; the caller frees. */
static unsigned char *make_vol(int rx, int ry, int rz, int ch, const float box[6], const float *data, size_t *n)
{
    size_t nd = (size_t)rx * ry * rz * ch;
    *n = 48 + 4 * nd;
    unsigned char *b = calloc(1, *n);
    memcpy(b, "VOL", 3);
    b[3] = 3;
    put32(b + 4, 1);
    put32(b + 8, (uint32_t)rx);
    put32(b + 12, (uint32_t)ry);
    put32(b + 16, (uint32_t)rz);
    put32(b + 20, (uint32_t)ch);
    for (int i = 0; i < 6; i++)
        putf(b + 24 + 4 * i, box[i]);
    for (size_t i = 0; i < nd; i++)
        putf(b + 48 + 4 * i, data ? data[i] : 0.5f);
    return b;
}

/* ---- Constant fields ------------------------------------------------------------------------ */

static void test_constant(void **state)
{
    (void)state;
    murk_field *f = murk_field_constant(2.5f);
    assert_non_null(f);
    assert_true(murk_field_eval(f, murk_v3(1e30f, -3, 0)) == 2.5f);
    murk_vec3 lo, hi;
    int inf = 0;
    murk_field_bounds(f, &lo, &hi, &inf);
    assert_true(inf && isinf(lo.x) && lo.x < 0 && isinf(hi.z) && hi.z > 0);
    assert_true(murk_field_max(f) == 2.5f && murk_field_min(f) == 2.5f);
    murk_bound_grid g;
    assert_int_equal(murk_bound_grid_build(f, 16, &g), 0);
    assert_int_equal(g.res[0] * g.res[1] * g.res[2], 1);
    assert_true(g.maj[0] == 2.5f && g.min[0] == 2.5f);
    murk_ray r = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0, INFINITY};
    murk_dda it;
    float ta, tb, mj, mn;
    murk_dda_init(&it, &g, &r, 0.5f, 7.0f);
    assert_int_equal(murk_dda_next(&it, &ta, &tb, &mj, &mn), 1);
    assert_true(ta == 0.5f && tb == 7.0f && mj == 2.5f && mn == 2.5f);
    assert_int_equal(murk_dda_next(&it, &ta, &tb, &mj, &mn), 0);
    murk_dda_init(&it, &g, &r, 0.0f, INFINITY);
    assert_int_equal(murk_dda_next(&it, &ta, &tb, &mj, &mn), 1);
    assert_true(ta == 0.0f && isinf(tb));
    murk_bound_grid_free(&g);
    char path[600];
    snprintf(path, sizeof path, "%s/const.vol", tmp_dir());
    assert_int_equal(murk_field_vol_save(path, f, err, sizeof err), -1);
    expect_err(path, "constant");
    murk_field_free(f);
    assert_null(murk_field_constant(-1.0f));
    assert_null(murk_field_constant(NAN));
    murk_field_free(NULL);
}

/* ---- Trilinear interpolation ---------------------------------------------------------------- */

/* A res grid over [lo,hi] sampled from lin(p) = c0 + c . p at cell centres. */
static murk_field *linear_grid(const int res[3], murk_vec3 lo, murk_vec3 hi, const float c[4])
{
    size_t n = (size_t)res[0] * res[1] * res[2];
    float *d = malloc(n * sizeof *d);
    size_t i = 0;
    for (int z = 0; z < res[2]; z++)
        for (int y = 0; y < res[1]; y++)
            for (int x = 0; x < res[0]; x++, i++) {
                int ix[3] = {x, y, z};
                double v = c[3];
                for (int a = 0; a < 3; a++)
                    v += c[a] * (v3(lo, a) + (ix[a] + 0.5) * (v3(hi, a) - v3(lo, a)) / res[a]);
                d[i] = (float)v;
            }
    murk_field *f = murk_field_from_voxels(res, lo, hi, d);
    free(d);
    return f;
}

static void test_trilinear_linear_exact(void **state)
{
    (void)state;
    int res[3] = {5, 7, 4};
    murk_vec3 lo = murk_v3(-1.0f, 0.5f, 2.0f), hi = murk_v3(3.0f, 2.0f, 5.0f);
    float c[4] = {0.7f, -1.3f, 0.45f, 5.0f}; /* positive over the box */
    murk_field *f = linear_grid(res, lo, hi, c);
    assert_non_null(f);
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    for (int k = 0; k < 100000; k++) {
        float p[3];
        for (int a = 0; a < 3; a++) { /* inside the hull of the cell centres */
            float h = 0.5f * (v3(hi, a) - v3(lo, a)) / res[a];
            p[a] = frand(&rng, v3(lo, a) + h, v3(hi, a) - h);
        }
        double want = c[3] + (double)c[0] * p[0] + (double)c[1] * p[1] + (double)c[2] * p[2];
        float got = murk_field_eval(f, murk_v3(p[0], p[1], p[2]));
        if (fabs(got - want) > 2e-5 * 8.0)
            fail_msg("eval(%g %g %g) = %.9g, linear %.9g", p[0], p[1], p[2], (double)got, want);
    }
    /* min/max over the box are the voxel extremes */
    const float *data;
    int r2[3];
    murk_field_grid(f, r2, &data);
    float mn = INFINITY, mx = -INFINITY;
    for (int i = 0; i < res[0] * res[1] * res[2]; i++) {
        mn = fminf(mn, data[i]);
        mx = fmaxf(mx, data[i]);
    }
    assert_true(murk_field_min(f) == mn && murk_field_max(f) == mx);
    murk_field_free(f);
}

static void test_clamp_and_outside(void **state)
{
    (void)state;
    int res[3] = {4, 3, 1}; /* a single-voxel axis too */
    murk_vec3 lo = murk_v3(0, 0, 0), hi = murk_v3(4, 3, 1);
    float d[12];
    for (int i = 0; i < 12; i++)
        d[i] = (float)(1 + i * i % 7);
    murk_field *f = murk_field_from_voxels(res, lo, hi, d);
    assert_non_null(f);
    /* voxel centres reproduce the voxels exactly; z is constant (one voxel) */
    for (int y = 0; y < 3; y++)
        for (int x = 0; x < 4; x++)
            for (float z = 0.0f; z <= 1.0f; z += 0.125f)
                assert_true(murk_field_eval(f, murk_v3(x + 0.5f, y + 0.5f, z)) == d[y * 4 + x]);
    /* border half-cells clamp: the value is that of the nearest centre along the clamped axis */
    murk_rng rng;
    murk_rng_seed(&rng, 7, 0, 0);
    for (int k = 0; k < 10000; k++) {
        float y = frand(&rng, 0.5f, 2.5f), z = frand(&rng, 0, 1);
        float xl = frand(&rng, 0.0f, 0.5f), xh = frand(&rng, 3.5f, 4.0f);
        assert_true(murk_field_eval(f, murk_v3(xl, y, z)) == murk_field_eval(f, murk_v3(0.5f, y, z)));
        assert_true(murk_field_eval(f, murk_v3(xh, y, z)) == murk_field_eval(f, murk_v3(3.5f, y, z)));
    }
    /* corners of the box (closed) hold the corner voxels */
    assert_true(murk_field_eval(f, murk_v3(0, 0, 0)) == d[0]);
    assert_true(murk_field_eval(f, murk_v3(4, 3, 1)) == d[11]);
    /* outside: 0; NaN: 0 */
    assert_true(murk_field_eval(f, murk_v3(-1e-6f, 1, 0.5f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(4.0001f, 1, 0.5f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(2, 3.0001f, 0.5f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(2, 1, -0.001f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(NAN, 1, 0.5f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(INFINITY, 1, 0.5f)) == 0.0f);
    murk_vec3 blo, bhi;
    int inf = 1;
    murk_field_bounds(f, &blo, &bhi, &inf);
    assert_int_equal(inf, 0);
    assert_true(blo.x == 0 && bhi.x == 4 && bhi.y == 3 && bhi.z == 1);
    murk_field_free(f);
    /* invalid voxel arrays */
    d[5] = -1.0f;
    assert_null(murk_field_from_voxels(res, lo, hi, d));
    d[5] = NAN;
    assert_null(murk_field_from_voxels(res, lo, hi, d));
    d[5] = 1.0f;
    assert_null(murk_field_from_voxels(res, hi, lo, d));
    int bad[3] = {0, 3, 1};
    assert_null(murk_field_from_voxels(bad, lo, hi, d));
}

/* ---- .vol ----------------------------------------------------------------------------------- */

static void test_vol_round_trip(void **state)
{
    (void)state;
    murk_field *c = murk_field_cloud(murk_v3(-1, -2, 0), murk_v3(1, 2, 3), 24, 99, 3.0f, 4, 0.6f);
    assert_non_null(c);
    const char *p1 = tmp_file("cloud1.vol"), *p2 = tmp_file("cloud2.vol");
    assert_int_equal(murk_field_vol_save(p1, c, err, sizeof err), 0);
    murk_field *l = murk_field_vol_load(p1, err, sizeof err);
    if (!l)
        fail_msg("%s", err);
    int ra[3], rb[3];
    const float *da, *db;
    murk_field_grid(c, ra, &da);
    murk_field_grid(l, rb, &db);
    assert_memory_equal(ra, rb, sizeof ra);
    assert_memory_equal(da, db, sizeof(float) * (size_t)ra[0] * ra[1] * ra[2]);
    murk_vec3 lo1, hi1, lo2, hi2;
    murk_field_bounds(c, &lo1, &hi1, NULL);
    murk_field_bounds(l, &lo2, &hi2, NULL);
    assert_memory_equal(&lo1, &lo2, sizeof lo1);
    assert_memory_equal(&hi1, &hi2, sizeof hi1);
    assert_true(murk_field_max(l) == murk_field_max(c));
    assert_int_equal(murk_field_vol_save(p2, l, err, sizeof err), 0);
    size_t n1, n2;
    unsigned char *b1 = read_bytes(p1, &n1), *b2 = read_bytes(p2, &n2);
    assert_int_equal(n1, n2);
    assert_int_equal(n1, 48 + 4 * 24 * 24 * 24);
    assert_memory_equal(b1, b2, n1);
    assert_memory_equal(b1, "VOL\3", 4);
    free(b1);
    free(b2);
    /* overwriting an existing file works (rename over it) */
    assert_int_equal(murk_field_vol_save(p1, l, err, sizeof err), 0);
    /* saving into a missing directory fails with a message */
    const char *bad = tmp_file("no/such/dir/x.vol");
    assert_int_equal(murk_field_vol_save(bad, l, err, sizeof err), -1);
    expect_err(bad, "temporary");
    murk_field_free(c);
    murk_field_free(l);
}

static void vol_expect(const char *name, const unsigned char *b, size_t n, const char *needle)
{
    const char *p = tmp_file(name);
    write_bytes(p, b, n);
    err[0] = 0;
    murk_field *f = murk_field_vol_load(p, err, sizeof err);
    if (f)
        fail_msg("%s loaded but should fail with \"%s\"", name, needle);
    expect_err(p, needle);
}

static void test_vol_errors(void **state)
{
    (void)state;
    const float box[6] = {0, 0, 0, 1, 2, 3};
    float data[24];
    for (int i = 0; i < 24; i++)
        data[i] = 0.1f * i;
    size_t n;
    unsigned char *b = make_vol(2, 3, 4, 1, box, data, &n);
    {
        const char *p = tmp_file("good.vol");
        write_bytes(p, b, n);
        murk_field *f = murk_field_vol_load(p, err, sizeof err);
        if (!f)
            fail_msg("%s", err);
        /* x fastest: voxel (1,2,3) is data[(3*3 + 2)*2 + 1] */
        assert_true(fabsf(murk_field_eval(f, murk_v3(0.75f, 5.0f / 3.0f, 2.625f)) - data[23]) < 1e-5f);
        assert_true(fabsf(murk_field_eval(f, murk_v3(0.25f, 1.0f / 3.0f, 0.375f)) - data[0]) < 1e-6f);
        murk_field_free(f);
    }
    unsigned char *c = malloc(n + 8);
    memcpy(c, b, n);
    c[0] = 'X';
    vol_expect("magic.vol", c, n, "bad magic");
    memcpy(c, b, n);
    c[3] = 2;
    vol_expect("version.vol", c, n, "version 2");
    memcpy(c, b, n);
    put32(c + 4, 2);
    vol_expect("encoding.vol", c, n, "encoding 2");
    memcpy(c, b, n);
    vol_expect("trunc_header.vol", c, 20, "truncated header");
    vol_expect("trunc_data.vol", c, n - 5, "truncated data");
    memcpy(c + n, "\0\0\0\0", 4);
    vol_expect("trailing.vol", c, n + 4, "after the data");
    memcpy(c, b, n);
    putf(c + 48 + 4 * 7, -0.25f);
    vol_expect("negative.vol", c, n, "negative value");
    memcpy(c, b, n);
    putf(c + 48 + 4 * 7, NAN);
    vol_expect("nan.vol", c, n, "invalid value");
    memcpy(c, b, n);
    putf(c + 48 + 4 * 7, INFINITY);
    vol_expect("inf.vol", c, n, "infinite value");
    memcpy(c, b, n);
    put32(c + 8, 0);
    vol_expect("zero_res.vol", c, n, "bad resolution");
    memcpy(c, b, n);
    put32(c + 8, (uint32_t)-5);
    vol_expect("neg_res.vol", c, n, "bad resolution");
    memcpy(c, b, n);
    put32(c + 8, 65536);
    put32(c + 12, 65536);
    put32(c + 16, 65536);
    vol_expect("huge.vol", c, n, "exceeds the limit");
    memcpy(c, b, n);
    put32(c + 8, 0x7fffffff);
    put32(c + 12, 0x7fffffff);
    put32(c + 16, 0x7fffffff);
    vol_expect("overflow.vol", c, n, "exceeds the limit");
    memcpy(c, b, n);
    putf(c + 24, 5.0f); /* xmin > xmax */
    vol_expect("box.vol", c, n, "bad bounding box");
    memcpy(c, b, n);
    putf(c + 28, NAN);
    vol_expect("box_nan.vol", c, n, "bad bounding box");
    free(b);
    free(c);
    b = make_vol(2, 2, 2, 3, box, NULL, &n);
    vol_expect("rgb.vol", b, n, "3 channels");
    free(b);
    const char *missing = tmp_file("missing.vol");
    assert_null(murk_field_vol_load(missing, err, sizeof err));
    expect_err(missing, "No such file");
}

/* ---- Bounds --------------------------------------------------------------------------------- */

static void check_bounds(const murk_field *f, int target, int samples_per_cell, uint64_t seed)
{
    murk_bound_grid g;
    assert_int_equal(murk_bound_grid_build(f, target, &g), 0);
    murk_vec3 lo, hi;
    murk_field_bounds(f, &lo, &hi, NULL);
    assert_memory_equal(&g.lo, &lo, sizeof lo);
    assert_memory_equal(&g.hi, &hi, sizeof hi);
    int longest = 0;
    for (int a = 0; a < 3; a++)
        longest = g.res[a] > longest ? g.res[a] : longest;
    assert_int_equal(longest, target);
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0, 0);
    float allmax = 0.0f;
    size_t k = 0;
    for (int cz = 0; cz < g.res[2]; cz++)
        for (int cy = 0; cy < g.res[1]; cy++)
            for (int cx = 0; cx < g.res[0]; cx++, k++) {
                int c[3] = {cx, cy, cz};
                float a[3], b[3];
                for (int ax = 0; ax < 3; ax++) {
                    float w = (v3(hi, ax) - v3(lo, ax)) / g.res[ax];
                    a[ax] = v3(lo, ax) + c[ax] * w;
                    b[ax] = c[ax] == g.res[ax] - 1 ? v3(hi, ax) : v3(lo, ax) + (c[ax] + 1) * w;
                }
                assert_true(g.min[k] <= g.maj[k]);
                allmax = fmaxf(allmax, g.maj[k]);
                for (int s = 0; s < samples_per_cell; s++) {
                    murk_vec3 p;
                    if (s < 8) /* the cell's corners, then random interior points */
                        p = murk_v3(s & 1 ? b[0] : a[0], s & 2 ? b[1] : a[1], s & 4 ? b[2] : a[2]);
                    else
                        p = murk_v3(frand(&rng, a[0], b[0]), frand(&rng, a[1], b[1]), frand(&rng, a[2], b[2]));
                    float v = murk_field_eval(f, p);
                    if (!(g.min[k] <= v && v <= g.maj[k]))
                        fail_msg("cell (%d %d %d): eval %.9g outside [%.9g, %.9g]", cx, cy, cz, (double)v,
                                 (double)g.min[k], (double)g.maj[k]);
                }
            }
    assert_true(allmax == murk_field_max(f));
    murk_bound_grid_free(&g);
}

static void test_majorant_bounds(void **state)
{
    (void)state;
    /* a rough random grid with zeros and spikes, non-cubic, not aligned with the bound cells */
    int res[3] = {13, 9, 21};
    size_t n = (size_t)res[0] * res[1] * res[2];
    float *d = malloc(n * sizeof *d);
    murk_rng rng;
    murk_rng_seed(&rng, 11, 0, 0);
    for (size_t i = 0; i < n; i++) {
        float u = murk_rng_float(&rng);
        d[i] = u < 0.3f ? 0.0f : (u > 0.97f ? 50.0f * u : u);
    }
    murk_field *f = murk_field_from_voxels(res, murk_v3(-2, 0.25f, 1), murk_v3(1.5f, 2, 7), d);
    free(d);
    assert_non_null(f);
    check_bounds(f, 16, 1000, 1);
    check_bounds(f, 7, 1000, 2);
    check_bounds(f, 1, 20000, 3);
    check_bounds(f, 40, 60, 4); /* finer than the voxels */
    murk_field_free(f);

    murk_field *c = murk_field_cloud(murk_v3(0, 0, 0), murk_v3(2, 1, 1), 32, 5, 4.0f, 5, 0.7f);
    assert_non_null(c);
    check_bounds(c, 16, 1000, 5);
    murk_field_free(c);

    murk_bound_grid g;
    murk_field *k = murk_field_constant(1.0f);
    assert_int_equal(murk_bound_grid_build(k, 0, &g), -1);
    assert_null(g.maj);
    murk_field_free(k);
}

/* ---- DDA ------------------------------------------------------------------------------------ */

/* Walks [t0, t1] and checks the tiling; returns the number of segments. */
static int check_dda(const murk_bound_grid *g, const murk_ray *r, float t0, float t1)
{
    murk_dda it;
    murk_dda_init(&it, g, r, t0, t1);
    float ta, tb, mj, mn, prev = t0;
    double sum = 0.0;
    int count = 0;
    while (murk_dda_next(&it, &ta, &tb, &mj, &mn)) {
        if (ta != prev || !(tb > ta))
            fail_msg("segment %d [%.9g, %.9g) after %.9g (t0 %.9g t1 %.9g)", count, (double)ta, (double)tb,
                     (double)prev, (double)t0, (double)t1);
        prev = tb;
        sum += (double)tb - ta;
        count++;
        if (count > 10000)
            fail_msg("runaway DDA");
        /* the cell its midpoint lies in (or outside the box -> -1 and zero bounds) */
        if (isinf(tb))
            continue;
        double tm = 0.5 * ((double)ta + tb);
        int in = 1, near = 0, cell[3];
        for (int a = 0; a < 3; a++) {
            double lo = v3(g->lo, a), hi = v3(g->hi, a);
            double p = v3(r->o, a) + (double)v3(r->d, a) * tm;
            double u = (p - lo) / (hi - lo) * g->res[a];
            double eps = 1e-4 * (1.0 + fabs(u)) + 1e-5 * fabs(v3(r->d, a) * tm) / (hi - lo) * g->res[a];
            if (u < -eps || u > g->res[a] + eps)
                in = 0;
            if (fabs(u - floor(u + 0.5)) <= eps)
                near = 1; /* on a cell boundary up to rounding: either neighbour is fine */
            cell[a] = u < 0 ? 0 : (u >= g->res[a] ? g->res[a] - 1 : (int)floor(u));
        }
        if (!in) {
            if (it.cell[0] != -1 || mj != 0.0f || mn != 0.0f)
                fail_msg("segment [%.9g %.9g) outside the box has cell %d and maj %g", (double)ta, (double)tb,
                         it.cell[0], (double)mj);
            continue;
        }
        if (it.cell[0] < 0) {
            if (!near)
                fail_msg("segment [%.9g %.9g) inside the box reported as outside", (double)ta, (double)tb);
            continue;
        }
        size_t k = ((size_t)it.cell[2] * g->res[1] + it.cell[1]) * g->res[0] + it.cell[0];
        assert_true(mj == g->maj[k] && mn == g->min[k]);
        for (int a = 0; a < 3; a++)
            if (it.cell[a] != cell[a] && !(near && abs(it.cell[a] - cell[a]) == 1))
                fail_msg("segment [%.9g %.9g) reports cell (%d %d %d); its midpoint is in (%d %d %d)", (double)ta,
                         (double)tb, it.cell[0], it.cell[1], it.cell[2], cell[0], cell[1], cell[2]);
    }
    if (t0 < t1) {
        if (prev != t1)
            fail_msg("segments end at %.9g, not t1 %.9g", (double)prev, (double)t1);
        if (isfinite(t1) && fabs(sum - ((double)t1 - t0)) > 1e-5 * fabs((double)t1 - t0))
            fail_msg("segment lengths sum to %.9g, not %.9g", sum, (double)t1 - t0);
    } else {
        assert_int_equal(count, 0);
    }
    return count;
}

static float pick_dir(murk_rng *rng)
{
    float u = murk_rng_float(rng);
    if (u < 0.12f)
        return 0.0f;
    if (u < 0.2f)
        return -0.0f;
    return frand(rng, -1, 1);
}

static void test_dda_tiling(void **state)
{
    (void)state;
    int res[3] = {10, 6, 8};
    size_t n = (size_t)res[0] * res[1] * res[2];
    float *d = malloc(n * sizeof *d);
    murk_rng rng;
    murk_rng_seed(&rng, 21, 0, 0);
    for (size_t i = 0; i < n; i++)
        d[i] = murk_rng_float(&rng);
    murk_field *f = murk_field_from_voxels(res, murk_v3(-1, -0.5f, 2), murk_v3(2, 1, 4), d);
    free(d);
    assert_non_null(f);
    murk_bound_grid g;
    assert_int_equal(murk_bound_grid_build(f, 12, &g), 0);
    int total = 0;
    for (int k = 0; k < 20000; k++) {
        murk_ray r;
        /* origins inside, near, or far outside the box; on grid planes sometimes */
        float spread = k % 3 == 0 ? 1.0f : (k % 3 == 1 ? 5.0f : 1000.0f);
        r.o = murk_v3(frand(&rng, -1, 2) * spread, frand(&rng, -0.5f, 1) * spread, 3 + frand(&rng, -1, 1) * spread);
        if (k % 7 == 0)
            r.o.x = -1.0f + 0.25f * (float)(k % 13); /* exactly on a bound-cell plane (cell width 0.25) */
        r.d = murk_v3(pick_dir(&rng), pick_dir(&rng), pick_dir(&rng));
        if (r.d.x == 0 && r.d.y == 0 && r.d.z == 0)
            r.d.z = 1.0f;
        r.d = murk_normalize(r.d);
        if (k % 5 == 0)
            r.d = murk_mul(r.d, frand(&rng, 0.01f, 100.0f)); /* not unit length */
        r.tmin = 0;
        r.tmax = INFINITY;
        float t0, t1;
        switch (k % 6) {
        case 0: t0 = 0.0f; t1 = INFINITY; break;
        case 1: t0 = frand(&rng, -10, 10); t1 = t0; break;                 /* empty */
        case 2: t0 = -1e30f; t1 = 1e30f; break;                            /* huge */
        case 3: t0 = frand(&rng, 0, 3); t1 = t0 + frand(&rng, 0, 0.5f); break;
        default: t0 = frand(&rng, -2000, 100); t1 = t0 + frand(&rng, 0, 3000); break;
        }
        if (t1 == INFINITY || fabsf(t1) >= 1e30f) { /* sum check needs a finite range: only check tiling */
            murk_dda it;
            murk_dda_init(&it, &g, &r, t0, t1);
            float ta, tb, prev = t0;
            int cnt = 0;
            while (murk_dda_next(&it, &ta, &tb, NULL, NULL)) {
                assert_true(ta == prev && tb > ta);
                prev = tb;
                cnt++;
                assert_true(cnt < 1000);
            }
            assert_true(prev == t1);
            total += cnt;
        } else {
            total += check_dda(&g, &r, t0, t1);
        }
    }
    assert_true(total > 20000);
    /* axis-parallel rays along cell planes and box faces, both directions, through the whole box */
    for (int s = 0; s < 2; s++)
        for (int a = 0; a < 3; a++)
            for (int j = 0; j <= 4; j++) {
                murk_ray r;
                float o[3] = {0.5f, 0.25f, 3.0f};
                int b = (a + 1) % 3;
                float w = (v3(g.hi, b) - v3(g.lo, b)) / g.res[b];
                o[b] = v3(g.lo, b) + j * w;
                o[a] = s ? 10.0f : -10.0f;
                float dd[3] = {0, 0, 0};
                dd[a] = s ? -1.0f : 1.0f;
                r.o = murk_v3(o[0], o[1], o[2]);
                r.d = murk_v3(dd[0], dd[1], dd[2]);
                int cnt = check_dda(&g, &r, 0.0f, 20.0f);
                assert_true(cnt >= g.res[a] + 2 || j == 4 || j == 0);
            }
    /* starting inside, a single tiny segment; t0 > t1 yields nothing; NaN yields nothing */
    murk_ray r = {murk_v3(0.1f, 0.2f, 3.3f), murk_normalize(murk_v3(1, 2, 3)), 0, INFINITY};
    assert_int_equal(check_dda(&g, &r, 0.0f, 1e-6f), 1);
    assert_int_equal(check_dda(&g, &r, 1.0f, 0.5f), 0);
    murk_dda it;
    murk_dda_init(&it, &g, &r, NAN, 1.0f);
    assert_int_equal(murk_dda_next(&it, NULL, NULL, NULL, NULL), 0);
    /* a ray missing the box: one zero segment over the whole range */
    murk_ray miss = {murk_v3(0, 5, 3), murk_v3(1, 0, 0), 0, INFINITY};
    float ta, tb, mj, mn;
    murk_dda_init(&it, &g, &miss, -3.0f, 8.0f);
    assert_int_equal(murk_dda_next(&it, &ta, &tb, &mj, &mn), 1);
    assert_true(ta == -3.0f && tb == 8.0f && mj == 0.0f && mn == 0.0f && it.cell[0] == -1);
    assert_int_equal(murk_dda_next(&it, &ta, &tb, &mj, &mn), 0);
    /* a ray from far away: the inside segments carry their cells' majorants, whose max is > 0 */
    murk_ray far = {murk_v3(-1e6f, 0.3f, 3.1f), murk_v3(1, 0, 0), 0, INFINITY};
    murk_dda_init(&it, &g, &far, 0.0f, 2e6f);
    float mxj = 0.0f;
    int cnt = 0;
    while (murk_dda_next(&it, &ta, &tb, &mj, &mn)) {
        mxj = fmaxf(mxj, mj);
        cnt++;
    }
    assert_int_equal(cnt, g.res[0] + 2);
    assert_true(mxj > 0.0f);
    murk_bound_grid_free(&g);
    murk_field_free(f);
}

/* ---- Cloud ---------------------------------------------------------------------------------- */

static void test_cloud(void **state)
{
    (void)state;
    murk_vec3 lo = murk_v3(-1, 0, -1), hi = murk_v3(1, 1.5f, 1);
    murk_field *a = murk_field_cloud(lo, hi, 40, 1234, 3.0f, 5, 0.5f);
    murk_field *b = murk_field_cloud(lo, hi, 40, 1234, 3.0f, 5, 0.5f);
    murk_field *c = murk_field_cloud(lo, hi, 40, 1235, 3.0f, 5, 0.5f);
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(c);
    int r[3];
    const float *da, *db, *dc;
    murk_field_grid(a, r, &da);
    murk_field_grid(b, r, &db);
    murk_field_grid(c, r, &dc);
    assert_int_equal(r[0] * r[1] * r[2], 40 * 40 * 40);
    size_t n = (size_t)r[0] * r[1] * r[2];
    assert_memory_equal(da, db, n * sizeof *da);
    assert_true(memcmp(da, dc, n * sizeof *da) != 0);
    assert_true(murk_field_max(a) > 0.5f && murk_field_max(a) <= 1.5f);
    assert_true(murk_field_max(c) > 0.5f && murk_field_max(c) <= 1.5f);
    assert_true(murk_field_min(a) >= 0.0f);
    /* a substantial part of the box is filled, and not all of it */
    size_t filled = 0;
    for (size_t i = 0; i < n; i++)
        filled += da[i] > 0.05f;
    assert_true(filled > n / 50 && filled < n / 2);
    /* zero on and near the faces */
    murk_rng rng;
    murk_rng_seed(&rng, 3, 3, 3);
    for (int k = 0; k < 3000; k++) {
        int ax = k % 3;
        float p[3] = {frand(&rng, -1, 1), frand(&rng, 0, 1.5f), frand(&rng, -1, 1)};
        float w = (v3(hi, ax) - v3(lo, ax)) / 40.0f;
        p[ax] = k & 8 ? v3(hi, ax) - frand(&rng, 0, 0.5f * w) : v3(lo, ax) + frand(&rng, 0, 0.5f * w);
        assert_true(murk_field_eval(a, murk_v3(p[0], p[1], p[2])) == 0.0f);
    }
    /* coverage grows the cloud */
    murk_field *thin = murk_field_cloud(lo, hi, 40, 1234, 3.0f, 5, 0.1f);
    murk_field *thick = murk_field_cloud(lo, hi, 40, 1234, 3.0f, 5, 0.9f);
    const float *dt, *dk;
    murk_field_grid(thin, r, &dt);
    murk_field_grid(thick, r, &dk);
    size_t nt = 0, nk = 0;
    for (size_t i = 0; i < n; i++) {
        nt += dt[i] > 0.0f;
        nk += dk[i] > 0.0f;
    }
    assert_true(nt < nk);
    murk_field_free(thin);
    murk_field_free(thick);
    /* invalid arguments */
    assert_null(murk_field_cloud(lo, hi, 1, 1, 3.0f, 5, 0.5f));
    assert_null(murk_field_cloud(lo, hi, 8, 1, 0.0f, 5, 0.5f));
    assert_null(murk_field_cloud(lo, hi, 8, 1, 3.0f, 0, 0.5f));
    assert_null(murk_field_cloud(lo, hi, 8, 1, 3.0f, 5, 1.5f));
    assert_null(murk_field_cloud(hi, lo, 8, 1, 3.0f, 5, 0.5f));
    murk_field_free(a);
    murk_field_free(b);
    murk_field_free(c);
}

/* ---- NanoVDB -------------------------------------------------------------------------------- *
 * A minimal writer of one NanoVDB 32.4 float grid (single segment, no compression) whose active
 * voxels fill the box [org, org + n) inside [0, 128)^3 (one root tile, one upper and one lower
 * node, a leaf per touched 8^3 block). Byte offsets follow NanoVDB.h / PNanoVDB.h for float grids:
 * GridData 672, TreeData 64, root 64 + 32 per tile, upper 270400, lower 33856, leaf 2144. The
 * holes[] voxels (if any) are left inactive with the background value. */

#define NV_VERSION ((32u << 21) | (4u << 10) | 2u)
#define NV_MAGIC 0x304244566f6e614eull

typedef struct nv_spec {
    int org[3], n[3];
    const float *values; /* n[0]*n[1]*n[2], x fastest */
    double scale[3], trans[3];
    float background;
    uint32_t grid_class, grid_type;
    uint16_t codec;
    int hole[3]; /* one inactive voxel (absolute ijk), or -1 */
} nv_spec;

static unsigned char *nv_write(const nv_spec *s, size_t *out_size)
{
    enum { GRID = 0, TREE = 672, ROOT = 736, UPPER = 832, LOWER = UPPER + 270400, LEAVES = LOWER + 33856 };
    enum { LEAF_SIZE = 2144 };
    /* leaves: one per 8^3 block touched */
    int lmin[3], lmax[3], nl[3];
    for (int a = 0; a < 3; a++) {
        lmin[a] = s->org[a] / 8;
        lmax[a] = (s->org[a] + s->n[a] - 1) / 8;
        nl[a] = lmax[a] - lmin[a] + 1;
    }
    int nleaves = nl[0] * nl[1] * nl[2];
    size_t gsize = LEAVES + (size_t)nleaves * LEAF_SIZE;
    const char *name = "density";
    size_t namesz = strlen(name) + 1;
    size_t head = 16 + 176 + namesz;
    *out_size = head + gsize;
    unsigned char *f = calloc(1, *out_size);
    unsigned char *g = f + head;
    int bmin[3], bmax[3];
    uint64_t nvox = 0;
    for (int a = 0; a < 3; a++) {
        bmin[a] = s->org[a];
        bmax[a] = s->org[a] + s->n[a] - 1;
    }
    nvox = (uint64_t)s->n[0] * s->n[1] * s->n[2] - (s->hole[0] >= 0);
    /* grid */
    put64(g + 0, NV_MAGIC);
    put64(g + 8, ~0ull);
    put32(g + 16, NV_VERSION);
    put32(g + 20, 0);
    put32(g + 24, 0);
    put32(g + 28, 1);
    put64(g + 32, gsize);
    memcpy(g + 40, name, namesz);
    for (int a = 0; a < 3; a++) { /* map: matf, invmatf, vecf, taperf, matd, invmatd, vecd, taperd */
        putf(g + 296 + 4 * (4 * a), (float)s->scale[a]);
        putf(g + 332 + 4 * (4 * a), (float)(1.0 / s->scale[a]));
        putf(g + 368 + 4 * a, (float)s->trans[a]);
        putd(g + 384 + 8 * (4 * a), s->scale[a]);
        putd(g + 456 + 8 * (4 * a), 1.0 / s->scale[a]);
        putd(g + 528 + 8 * a, s->trans[a]);
        putd(g + 560 + 8 * a, s->trans[a] + s->scale[a] * bmin[a]);            /* world bbox min */
        putd(g + 584 + 8 * a, s->trans[a] + s->scale[a] * (bmax[a] + 1.0));    /* world bbox max */
        putd(g + 608 + 8 * a, s->scale[a]);                                    /* voxel size */
    }
    putf(g + 380, 1.0f);
    putd(g + 552, 1.0);
    put32(g + 632, s->grid_class);
    put32(g + 636, s->grid_type);
    /* tree: node offsets relative to the tree */
    put64(g + TREE + 0, LEAVES - TREE);
    put64(g + TREE + 8, LOWER - TREE);
    put64(g + TREE + 16, UPPER - TREE);
    put64(g + TREE + 24, ROOT - TREE);
    put32(g + TREE + 32, (uint32_t)nleaves);
    put32(g + TREE + 36, 1);
    put32(g + TREE + 40, 1);
    put64(g + TREE + 56, nvox);
    /* root: bbox, one tile (key 0 for [0,4096)^3) pointing at the upper node */
    for (int a = 0; a < 3; a++) {
        put32(g + ROOT + 4 * a, (uint32_t)bmin[a]);
        put32(g + ROOT + 12 + 4 * a, (uint32_t)bmax[a]);
    }
    put32(g + ROOT + 24, 1);
    putf(g + ROOT + 28, s->background);
    put64(g + ROOT + 64 + 0, 0);
    put64(g + ROOT + 64 + 8, (uint64_t)(UPPER - ROOT));
    /* upper: child 0 is the lower node; other table entries hold the background */
    for (int a = 0; a < 3; a++) {
        put32(g + UPPER + 4 * a, 0);
        put32(g + UPPER + 12 + 4 * a, 4095);
    }
    g[UPPER + 4128] = 1; /* child mask bit 0 */
    for (int i = 0; i < 32768; i++)
        putf(g + UPPER + 8256 + 8 * i, s->background);
    put64(g + UPPER + 8256, (uint64_t)(LOWER - UPPER));
    /* lower */
    for (int a = 0; a < 3; a++)
        put32(g + LOWER + 12 + 4 * a, 127);
    for (int i = 0; i < 4096; i++)
        putf(g + LOWER + 1088 + 8 * i, s->background);
    int li = 0;
    for (int lx = lmin[0]; lx <= lmax[0]; lx++)
        for (int ly = lmin[1]; ly <= lmax[1]; ly++)
            for (int lz = lmin[2]; lz <= lmax[2]; lz++, li++) {
                size_t leaf = LEAVES + (size_t)li * LEAF_SIZE;
                int bit = (lx << 8) | (ly << 4) | lz;
                g[LOWER + 544 + bit / 8] |= (unsigned char)(1u << (bit % 8));
                put64(g + LOWER + 1088 + 8 * bit, (uint64_t)(leaf - LOWER));
                put32(g + leaf + 0, (uint32_t)(8 * lx));
                put32(g + leaf + 4, (uint32_t)(8 * ly));
                put32(g + leaf + 8, (uint32_t)(8 * lz));
                for (int v = 0; v < 512; v++) {
                    int x = 8 * lx + (v >> 6), y = 8 * ly + ((v >> 3) & 7), z = 8 * lz + (v & 7);
                    float val = s->background;
                    int active = x >= bmin[0] && x <= bmax[0] && y >= bmin[1] && y <= bmax[1] && z >= bmin[2] &&
                                 z <= bmax[2] && !(x == s->hole[0] && y == s->hole[1] && z == s->hole[2]);
                    if (active) {
                        val = s->values[((size_t)(z - bmin[2]) * s->n[1] + (y - bmin[1])) * s->n[0] + (x - bmin[0])];
                        g[leaf + 16 + v / 8] |= (unsigned char)(1u << (v % 8));
                    }
                    putf(g + leaf + 96 + 4 * v, val);
                }
            }
    /* segment header + metadata + name */
    put64(f + 0, NV_MAGIC);
    put32(f + 8, NV_VERSION);
    f[12] = 1;
    f[14] = (unsigned char)s->codec;
    unsigned char *m = f + 16;
    put64(m + 0, gsize);
    put64(m + 8, gsize);
    put64(m + 24, nvox);
    put32(m + 32, s->grid_type);
    put32(m + 36, s->grid_class);
    for (int a = 0; a < 3; a++) {
        putd(m + 40 + 8 * a, s->trans[a] + s->scale[a] * bmin[a]);
        putd(m + 64 + 8 * a, s->trans[a] + s->scale[a] * (bmax[a] + 1.0));
        put32(m + 88 + 4 * a, (uint32_t)bmin[a]);
        put32(m + 100 + 4 * a, (uint32_t)bmax[a]);
        putd(m + 112 + 8 * a, s->scale[a]);
    }
    put32(m + 136, (uint32_t)namesz);
    put32(m + 140, (uint32_t)nleaves);
    put32(m + 144, 1);
    put32(m + 148, 1);
    put32(m + 152, 1);
    m[168] = (unsigned char)s->codec;
    put32(m + 172, NV_VERSION);
    memcpy(m + 176, name, namesz);
    return f;
}

static float nv_value(int x, int y, int z)
{
    return 0.25f + 0.01f * (float)(x + 3 * y) + 0.5f * (float)((z * 7 + x) % 3);
}

static void nv_default(nv_spec *s, float *vals)
{
    memset(s, 0, sizeof *s);
    int org[3] = {5, 2, 9}, n[3] = {11, 4, 6}; /* spans two leaves in x and z */
    for (int a = 0; a < 3; a++) {
        s->org[a] = org[a];
        s->n[a] = n[a];
        s->hole[a] = -1;
    }
    s->scale[0] = 0.5;
    s->scale[1] = 0.25;
    s->scale[2] = 2.0;
    s->trans[0] = -3.0;
    s->trans[1] = 1.0;
    s->trans[2] = 0.5;
    s->grid_class = 2;
    s->grid_type = 1;
    size_t i = 0;
    for (int z = 0; z < n[2]; z++)
        for (int y = 0; y < n[1]; y++)
            for (int x = 0; x < n[0]; x++)
                vals[i++] = nv_value(x + org[0], y + org[1], z + org[2]);
    s->values = vals;
}

static void nv_expect(const char *name, const unsigned char *b, size_t n, const char *needle)
{
    const char *p = tmp_file(name);
    write_bytes(p, b, n);
    err[0] = 0;
    murk_field *f = murk_field_nvdb_load(p, err, sizeof err);
    if (f)
        fail_msg("%s loaded but should fail with \"%s\"", name, needle);
    expect_err(p, needle);
}

static void test_nvdb(void **state)
{
    (void)state;
    float vals[11 * 4 * 6];
    nv_spec s;
    nv_default(&s, vals);
    s.hole[0] = 7;
    s.hole[1] = 3;
    s.hole[2] = 10;
    size_t n;
    unsigned char *b = nv_write(&s, &n);
    const char *p = tmp_file("grid.nvdb");
    write_bytes(p, b, n);
    murk_field *f = murk_field_nvdb_load(p, err, sizeof err);
    if (!f && strstr(err, "without NanoVDB support")) {
        free(b);
        skip();
    }
    if (!f)
        fail_msg("%s", err);
    /* active index box [5,15] x [2,5] x [9,14], grown by one voxel of zeros: [4,16] x [1,6] x [8,15];
     * world = trans + scale * (ijk -/+ 1/2); 624 voxels, smaller dense than sparse (its sparse form holds two
     * nodes of 16^3 brick pointers): held dense (sparse.c's rule) */
    int res[3];
    const float *d;
    murk_field_grid(f, res, &d);
    assert_non_null(d);
    assert_int_equal(res[0], 13);
    assert_int_equal(res[1], 6);
    assert_int_equal(res[2], 8);
    murk_vec3 lo, hi;
    murk_field_bounds(f, &lo, &hi, NULL);
    assert_true(lo.x == (float)(-3.0 + 0.5 * 3.5) && hi.x == (float)(-3.0 + 0.5 * 16.5));
    assert_true(lo.y == (float)(1.0 + 0.25 * 0.5) && hi.y == (float)(1.0 + 0.25 * 6.5));
    assert_true(lo.z == (float)(0.5 + 2.0 * 7.5) && hi.z == (float)(0.5 + 2.0 * 15.5));
    assert_true(murk_field_voxel(f, 0, 0, 0) == 0.0f && murk_field_voxel(f, 12, 5, 7) == 0.0f);
    for (int z = 9; z <= 14; z++)
        for (int y = 2; y <= 5; y++)
            for (int x = 5; x <= 15; x++) {
                float want = (x == 7 && y == 3 && z == 10) ? 0.0f : nv_value(x, y, z);
                /* voxel ijk sits at map(ijk) */
                murk_vec3 w = murk_v3((float)(-3.0 + 0.5 * x), (float)(1.0 + 0.25 * y), (float)(0.5 + 2.0 * z));
                float got = murk_field_eval(f, w);
                if (fabsf(got - want) > 1e-6f)
                    fail_msg("voxel (%d %d %d): %.9g, want %.9g", x, y, z, (double)got, (double)want);
                assert_true(murk_field_voxel(f, x - 4, y - 1, z - 8) == want);
            }
    murk_field_free(f);

    /* inactive voxels inside the active box are 0 whatever the background (empty space) */
    s.background = 0.125f;
    free(b);
    b = nv_write(&s, &n);
    write_bytes(p, b, n);
    f = murk_field_nvdb_load(p, err, sizeof err);
    if (!f)
        fail_msg("%s", err);
    assert_true(murk_field_voxel(f, 7 - 4, 3 - 1, 10 - 8) == 0.0f);
    murk_field_free(f);
    s.background = 0.0f;
    free(b);

    /* a raw grid buffer (NanoVDB >= 32.6 may write files without a segment header), with either
     * grid magic */
    b = nv_write(&s, &n);
    size_t head = 16 + 176 + strlen("density") + 1;
    const char *raw = tmp_file("raw.nvdb");
    for (int k = 0; k < 2; k++) {
        if (k == 1)
            put64(b + head, 0x314244566f6e614eull); /* "NanoVDB1" */
        write_bytes(raw, b + head, n - head);
        f = murk_field_nvdb_load(raw, err, sizeof err);
        if (!f)
            fail_msg("%s", err);
        murk_field_grid(f, res, &d);
        assert_true(res[0] == 13 && res[1] == 6 && res[2] == 8 && murk_field_voxel(f, 1, 1, 1) == nv_value(5, 2, 9));
        murk_field_free(f);
    }
    put64(b, 0x324244566f6e614eull); /* "NanoVDB2": the segment magic of NanoVDB >= 32.6 */
    write_bytes(raw, b, n);
    f = murk_field_nvdb_load(raw, err, sizeof err);
    if (!f)
        fail_msg("%s", err);
    murk_field_free(f);
    free(b);

    /* error paths */
    b = nv_write(&s, &n);
    unsigned char *c = malloc(n);
    memcpy(c, b, n);
    c[0] = 'X';
    nv_expect("magic.nvdb", c, n, "bad magic");
    memcpy(c, b, n);
    put32(c + 8, (31u << 21));
    nv_expect("version.nvdb", c, n, "version 31");
    memcpy(c, b, n);
    nv_expect("trunc.nvdb", c, n - 100, "truncated");
    nv_expect("short.nvdb", c, 10, "too short");
    put32(c, 0x56444220u);
    nv_expect("openvdb.nvdb", c, 64, "OpenVDB");
    free(c);
    free(b);
    s.codec = 2;
    b = nv_write(&s, &n);
    nv_expect("blosc.nvdb", b, n, "BLOSC");
    free(b);
    s.codec = 1;
    b = nv_write(&s, &n);
    nv_expect("zip.nvdb", b, n, "ZIP");
    free(b);
    s.codec = 0;
    s.grid_type = 2; /* double */
    b = nv_write(&s, &n);
    nv_expect("double.nvdb", b, n, "no float grid");
    free(b);
    s.grid_type = 1;
    s.grid_class = 1; /* level set */
    b = nv_write(&s, &n);
    nv_expect("levelset.nvdb", b, n, "level set");
    free(b);
    s.grid_class = 2;
    vals[17] = -2.0f;
    b = nv_write(&s, &n);
    nv_expect("negative.nvdb", b, n, "negative value");
    free(b);
    vals[17] = 1.0f;
    const char *missing = tmp_file("missing.nvdb");
    assert_null(murk_field_nvdb_load(missing, err, sizeof err));
    expect_err(missing, "No such file");
}

/* murk_fmaxf, murk_fminf, murk_fmax, murk_fmin (murk/math.h: what the majorant walk, ratio tracking and the
 * phase functions use) against libm's own, called through pointers so that nothing is folded: the same bits
 * on the special values (signed zeros, infinities, NaN on either side) and on random bit patterns, so that
 * replacing libm's calls changed no image. Must-fail: murk_maxf / murk_minf (NaN in b gives NaN) differ
 * from fmaxf / fminf on these values, so the values tell such functions apart. */
static uint32_t fbits(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static uint64_t dbits(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static void test_fminmax_libm(void **state)
{
    (void)state;
    float (*volatile fmx)(float, float) = fmaxf, (*volatile fmn)(float, float) = fminf;
    double (*volatile dmx)(double, double) = fmax, (*volatile dmn)(double, double) = fmin;
    float v[] = {0.0f, -0.0f, 1.0f, -1.0f, INFINITY, -INFINITY, NAN, 1e-30f, -3.5f, 2.0f, 1e38f, 1e-45f};
    int n = (int)(sizeof v / sizeof *v), naive = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            float a = v[i], b = v[j];
            if (isnan(a) && isnan(b))
                continue; /* which NaN comes out is not specified */
            assert_int_equal(fbits(murk_fmaxf(a, b)), fbits(fmx(a, b)));
            assert_int_equal(fbits(murk_fminf(a, b)), fbits(fmn(a, b)));
            assert_true(dbits(murk_fmax(a, b)) == dbits(dmx(a, b)));
            assert_true(dbits(murk_fmin(a, b)) == dbits(dmn(a, b)));
            naive += fbits(murk_maxf(a, b)) != fbits(fmx(a, b)) || fbits(murk_minf(a, b)) != fbits(fmn(a, b));
        }
    assert_true(naive > 0); /* must-fail: the values catch a max/min with other NaN rules */
    murk_rng r;
    murk_rng_seed(&r, 29, 1, 2);
    for (int k = 0; k < 1000000; k++) {
        uint32_t x = murk_rng_u32(&r), y = murk_rng_u32(&r);
        float a, b;
        memcpy(&a, &x, sizeof a);
        memcpy(&b, &y, sizeof b);
        if ((isnan(a) && isnan(b)) || (isnan(a) && !(x & 0x400000u)) || (isnan(b) && !(y & 0x400000u)))
            continue; /* two NaNs, or a signalling one (libm quiets it; arithmetic never makes one) */
        assert_int_equal(fbits(murk_fmaxf(a, b)), fbits(fmx(a, b)));
        assert_int_equal(fbits(murk_fminf(a, b)), fbits(fmn(a, b)));
        assert_true(dbits(murk_fmax(a, b)) == dbits(dmx(a, b)));
        assert_true(dbits(murk_fmin(a, b)) == dbits(dmn(a, b)));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant),
        cmocka_unit_test(test_trilinear_linear_exact),
        cmocka_unit_test(test_clamp_and_outside),
        cmocka_unit_test(test_vol_round_trip),
        cmocka_unit_test(test_vol_errors),
        cmocka_unit_test(test_majorant_bounds),
        cmocka_unit_test(test_dda_tiling),
        cmocka_unit_test(test_cloud),
        cmocka_unit_test(test_nvdb),
        cmocka_unit_test(test_fminmax_libm),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
