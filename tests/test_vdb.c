/* test_vdb.c — sparse density grids (issue 28): the brick structure of core/media/sparse.c, OpenVDB files read
 * through the C++ shim (written here by tests/vdb_write, a C++ helper against libopenvdb built only in the test
 * build), and what a scene sees of them.
 *
 *   sparse = dense     random sparse grids built leaf by leaf and tile by tile (random masks, constant leaves
 *                      and tiles, tile and brick borders), saved as a dense .vol and loaded back: the same box,
 *                      voxels, bound grids, and murk_field_eval bit for bit at 300 000 points (random, voxel
 *                      centres, brick faces, the box's faces); the comparison itself must see a 1-ulp change
 *                      of one voxel (must-fail).
 *   inactive, tiles    inactive voxels read 0 whatever they hold; a tile's value at its borders; a leaf of one
 *                      value and a tile share one brick; the builder's errors (a negative, a NaN, a leaf met
 *                      twice or outside the box, a box too large) each say what and where.
 *   vdb grids          float, half and double grids, values at voxel centres; the grid name missing (the error
 *                      lists the file's grids), unnamed in a file of two, vec3s / int32 / level set / frustum /
 *                      no active voxels / truncated / random bytes: each a "path: ..." error.
 *   closed form        a constant grid of two active 128^3 tiles with an empty tile between them: every
 *                      unbiased transmittance estimator against exp(-sigma_t c n h) within 4 se (the figure
 *                      resolves a 3 % error), and the field's quadrature against the closed form.
 *   rotated            a map that scales, rotates and translates: values at the mapped voxel centres, 0 outside
 *                      the rotated box, the majorant walk bounding the density on random rays, and the closed
 *                      form along an index axis through a constant block.
 *   images             cornell_smoke's cloud as a .vdb against the same cloud as a .vol: block-wise z-test,
 *                      independent seeds; the .vdb against its own voxels saved as .vol: bitwise the same
 *                      image; the .vdb with its density 6 % higher must DIFFER.
 *   memory             a 1024^3 grid with 3 % of its voxels active (a ball): `murk info`'s peak resident
 *                      memory over that of the same scene with a one-voxel grid stays within 1.5x the active
 *                      voxels' float storage; the grid's own bytes too.
 *   bad scenes         a truncated .vdb, random bytes, a missing grid, a vec3s grid, a near-singular map, more
 *                      active voxels than MURK_MAX_GRID_VOXELS: `murk render` exits 1 with "scene.yaml:L:C:"
 *                      and writes no image. */
#include "mediatest.h"
#include "media/field_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static char err[4096];

/* ---- random sparse grids through the builder ----------------------------------------------------- */

typedef struct plan_item {
    int tile;          /* 1: a tile of dim voxels of one value */
    int o[3], dim;
    float value;
    float v[512];
    uint64_t mask[8];
} plan_item;

/* Leaves and tiles on an 8-voxel lattice of nb[0] x nb[1] x nb[2] blocks from index org: each block empty,
 * a leaf (random mask of density p, random values; one in 6 of one value, fully active) or a tile (one in
 * 8: 8^3 or, on even blocks, 16^3 of one value, sometimes 0). Returns the items and their active box. */
static plan_item *plan_grid(uint64_t seed, const int org[3], const int nb[3], int *n, int amin[3], int amax[3])
{
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x5ba5, 0);
    size_t cap = (size_t)nb[0] * nb[1] * nb[2];
    plan_item *it = calloc(cap, sizeof *it);
    char *used = calloc(cap, 1);
    assert_true(it && used);
    *n = 0;
    for (int a = 0; a < 3; a++)
        amin[a] = INT32_MAX, amax[a] = INT32_MIN;
    for (int z = 0; z < nb[2]; z++)
        for (int y = 0; y < nb[1]; y++)
            for (int x = 0; x < nb[0]; x++) {
                size_t k = ((size_t)z * nb[1] + y) * nb[0] + x;
                float r = murk_rng_float(&rng);
                if (used[k] || r < 0.3f)
                    continue;
                plan_item *p = &it[(*n)++];
                int b[3] = {x, y, z};
                for (int a = 0; a < 3; a++)
                    p->o[a] = org[a] + 8 * b[a];
                if (r > 0.875f) {
                    p->tile = 1;
                    p->dim = 8;
                    if (x % 2 == 0 && y % 2 == 0 && z % 2 == 0 && x + 1 < nb[0] && y + 1 < nb[1] && z + 1 < nb[2] &&
                        !used[k + 1] && !used[k + (size_t)nb[0]] && !used[k + (size_t)nb[0] * nb[1]] &&
                        murk_rng_float(&rng) < 0.5f && (org[0] % 16 == 0) && (org[1] % 16 == 0) && (org[2] % 16 == 0)) {
                        p->dim = 16;
                        for (int dz = 0; dz < 2; dz++)
                            for (int dy = 0; dy < 2; dy++)
                                for (int dx = 0; dx < 2; dx++)
                                    used[k + (size_t)dx + (size_t)dy * nb[0] + (size_t)dz * nb[0] * nb[1]] = 1;
                    }
                    p->value = murk_rng_float(&rng) < 0.2f ? 0.0f : (float)(int)(murk_rng_float(&rng) * 4) * 0.5f;
                    for (int a = 0; a < 3; a++) {
                        amin[a] = p->o[a] < amin[a] ? p->o[a] : amin[a];
                        amax[a] = p->o[a] + p->dim - 1 > amax[a] ? p->o[a] + p->dim - 1 : amax[a];
                    }
                } else {
                    int constant = murk_rng_float(&rng) < 1.0f / 6.0f;
                    float pa = constant ? 1.0f : murk_rng_float(&rng), cv = (float)(int)(murk_rng_float(&rng) * 3) + 0.25f;
                    for (int i = 0; i < 512; i++) {
                        int on = murk_rng_float(&rng) < pa;
                        p->v[i] = constant ? cv : (on ? 2.0f * murk_rng_float(&rng) : 9.0f); /* inactive: 9, read as 0 */
                        if (on) {
                            p->mask[i >> 6] |= 1ull << (i & 63);
                            int c[3] = {p->o[0] + (i >> 6), p->o[1] + ((i >> 3) & 7), p->o[2] + (i & 7)};
                            for (int a = 0; a < 3; a++) {
                                amin[a] = c[a] < amin[a] ? c[a] : amin[a];
                                amax[a] = c[a] > amax[a] ? c[a] : amax[a];
                            }
                        }
                    }
                }
                used[k] = 1;
            }
    free(used);
    return it;
}

static murk_field *build_plan(const plan_item *it, int n, const int amin[3], const int amax[3], const double map[12])
{
    murk_sparse_build *b = murk_sparse_begin("plan", amin, amax, err, sizeof err);
    if (!b)
        fail_msg("%s", err);
    for (int i = 0; i < n; i++) {
        int rc = it[i].tile ? murk_sparse_tile(b, it[i].o, it[i].dim, it[i].value, err, sizeof err)
                            : murk_sparse_leaf(b, it[i].o, it[i].v, it[i].mask, err, sizeof err);
        if (rc) {
            murk_sparse_abort(b);
            fail_msg("%s", err);
        }
    }
    murk_field *f = murk_sparse_end(b, map, err, sizeof err);
    if (!f)
        fail_msg("%s", err);
    return f;
}

static int same_float(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Points where sparse and dense must agree: uniform over the box grown by 5 %, voxel centres, the faces
 * between voxels at brick borders (index multiples of 8 and their neighbours) and the box's own faces.
 * Returns the number of points at which eval differs (printing the first few). */
static long compare_eval(const murk_field *s, const murk_field *d, uint64_t seed, long n)
{
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0xe7a1, 0);
    murk_vec3 lo, hi;
    murk_field_bounds(s, &lo, &hi, NULL);
    int res[3];
    murk_field_grid(s, res, NULL);
    long bad = 0;
    for (long i = 0; i < n; i++) {
        float p[3];
        int kind = (int)(i % 4);
        for (int a = 0; a < 3; a++) {
            float l = murk_v3_get(lo, a), h = murk_v3_get(hi, a), e = h - l, u = murk_rng_float(&rng);
            int v = (int)(u * (float)res[a]);
            switch (kind) {
            case 0: p[a] = l - 0.05f * e + 1.1f * e * murk_rng_float(&rng); break;
            case 1: p[a] = l + e * ((float)v + 0.5f) / (float)res[a]; break;      /* a voxel centre */
            case 2: p[a] = l + e * (float)((v & ~7) + (int)(murk_rng_u32(&rng) % 3)) / (float)res[a]; break; /* brick face */
            default: p[a] = murk_rng_float(&rng) < 0.5f ? (murk_rng_float(&rng) < 0.5f ? l : h) : l + e * u; /* box face */
            }
        }
        murk_vec3 q = murk_v3(p[0], p[1], p[2]);
        float a = murk_field_eval(s, q), b = murk_field_eval(d, q);
        if (!same_float(a, b) && bad++ < 5)
            printf("  eval(%.9g, %.9g, %.9g): sparse %.9g, dense %.9g\n", (double)p[0], (double)p[1], (double)p[2],
                   (double)a, (double)b);
    }
    return bad;
}

/* The bound grids of both at several resolutions, cell by cell. */
static long compare_bounds(const murk_field *s, const murk_field *d)
{
    static const int resolutions[] = {1, 3, 7, 16, 40};
    long bad = 0;
    for (size_t r = 0; r < sizeof resolutions / sizeof resolutions[0]; r++) {
        murk_bound_grid a, b;
        assert_int_equal(murk_bound_grid_build(s, resolutions[r], &a), 0);
        assert_int_equal(murk_bound_grid_build(d, resolutions[r], &b), 0);
        assert_memory_equal(a.res, b.res, sizeof a.res);
        size_t n = (size_t)a.res[0] * a.res[1] * a.res[2];
        for (size_t i = 0; i < n; i++)
            bad += !same_float(a.maj[i], b.maj[i]) || !same_float(a.min[i], b.min[i]);
        murk_bound_grid_free(&a);
        murk_bound_grid_free(&b);
    }
    return bad;
}

static const double MAP_SCALED[12] = {0.05, 0, 0, -0.3, 0, 0.0625, 0, 0.2, 0, 0, 0.04, 1.5};

static murk_field *dense_copy(const murk_field *s, const char *name)
{
    const char *p = tmp_path(name);
    if (murk_field_vol_save(p, s, err, sizeof err) != 0)
        fail_msg("%s", err);
    murk_field *d = murk_field_vol_load(p, err, sizeof err);
    if (!d)
        fail_msg("%s", err);
    return d;
}

static void test_sparse_equals_dense(void **state)
{
    (void)state;
    static const int origins[][3] = {{0, 0, 0}, {-24, 8, -40}, {-8, -16, 16}};
    static const int blocks[][3] = {{6, 5, 7}, {9, 4, 6}, {5, 8, 3}};
    for (int c = 0; c < 3; c++) {
        int n, amin[3], amax[3];
        plan_item *it = plan_grid(100 + (uint64_t)c, origins[c], blocks[c], &n, amin, amax);
        murk_field *s = build_plan(it, n, amin, amax, MAP_SCALED);
        murk_field *d = dense_copy(s, "sparse_dense.vol");
        int rs[3], rd[3];
        const float *data;
        murk_field_grid(s, rs, &data);
        assert_null(data);
        murk_field_grid(d, rd, &data);
        assert_memory_equal(rs, rd, sizeof rs);
        for (int a = 0; a < 3; a++)
            assert_int_equal(rs[a], amax[a] - amin[a] + 3); /* the active box and a voxel of zeros each side */
        murk_vec3 l1, h1, l2, h2;
        murk_field_bounds(s, &l1, &h1, NULL);
        murk_field_bounds(d, &l2, &h2, NULL);
        assert_memory_equal(&l1, &l2, sizeof l1);
        assert_memory_equal(&h1, &h2, sizeof h1);
        long voxels_bad = 0;
        for (int z = 0; z < rs[2]; z++)
            for (int y = 0; y < rs[1]; y++)
                for (int x = 0; x < rs[0]; x++)
                    voxels_bad += !same_float(murk_field_voxel(s, x, y, z), data[((size_t)z * rs[1] + y) * rs[0] + x]);
        long eval_bad = compare_eval(s, d, 7 + (uint64_t)c, 100000), bounds_bad = compare_bounds(s, d);
        printf("grid %d: %d x %d x %d voxels, %d leaves and tiles; differing: %ld voxels, %ld of 100000 lookups, "
               "%ld bound cells\n", c, rs[0], rs[1], rs[2], n, voxels_bad, eval_bad, bounds_bad);
        assert_int_equal(voxels_bad, 0);
        assert_int_equal(eval_bad, 0);
        assert_int_equal(bounds_bad, 0);
        if (c == 0) { /* must-fail: the comparison sees one voxel changed by one ulp */
            float *mut = (float *)(uintptr_t)data;
            size_t k = ((size_t)(rs[2] / 2) * rs[1] + rs[1] / 2) * rs[0] + rs[0] / 2;
            for (size_t j = 0; mut[k] == 0.0f && j < (size_t)rs[0]; j++)
                k++;
            mut[k] = nextafterf(mut[k], INFINITY);
            long seen = 0;
            int x = (int)(k % (size_t)rs[0]), y = (int)(k / (size_t)rs[0] % (size_t)rs[1]), z = (int)(k / ((size_t)rs[0] * rs[1]));
            murk_vec3 lo, hi;
            murk_field_bounds(s, &lo, &hi, NULL);
            for (int j = 0; j < 64; j++) { /* points around the changed voxel */
                float f[3] = {((float)x + 0.5f + 0.1f * (float)(j % 4)) / (float)rs[0],
                              ((float)y + 0.5f - 0.1f * (float)(j / 4 % 4)) / (float)rs[1],
                              ((float)z + 0.5f + 0.05f * (float)(j / 16)) / (float)rs[2]};
                murk_vec3 q = murk_v3(lo.x + (hi.x - lo.x) * f[0], lo.y + (hi.y - lo.y) * f[1], lo.z + (hi.z - lo.z) * f[2]);
                seen += !same_float(murk_field_eval(s, q), murk_field_eval(d, q));
            }
            printf("must-fail: one voxel of the dense copy 1 ulp higher: %ld of 64 lookups around it differ\n", seen);
            assert_true(seen > 0);
        }
        murk_field_free(s);
        murk_field_free(d);
        free(it);
    }
}

static void test_inactive_and_tiles(void **state)
{
    (void)state;
    /* a leaf at (0,0,0) with its odd voxels active (inactive ones hold 7), a tile of 0.75 at (8,0,0), a
     * leaf of one value (1.25, all active) at (0,8,0) and a tile of the same value at (8,8,0) */
    float v[512], c[512];
    uint64_t mask[8], none[8];
    for (int i = 0; i < 512; i++) {
        v[i] = (i & 1) ? 0.5f + (float)i / 1024.0f : 7.0f;
        c[i] = 1.25f;
    }
    for (int w = 0; w < 8; w++) {
        mask[w] = 0xaaaaaaaaaaaaaaaaull;
        none[w] = 0;
    }
    int amin[3] = {0, 0, 0}, amax[3] = {15, 15, 7};
    murk_sparse_build *b = murk_sparse_begin("t", amin, amax, err, sizeof err);
    assert_non_null(b);
    int o0[3] = {0, 0, 0}, o1[3] = {8, 0, 0}, o2[3] = {0, 8, 0}, o3[3] = {8, 8, 0}, o4[3] = {64, 64, 64};
    assert_int_equal(murk_sparse_leaf(b, o0, v, mask, err, sizeof err), 0);
    assert_int_equal(murk_sparse_tile(b, o1, 8, 0.75f, err, sizeof err), 0);
    assert_int_equal(murk_sparse_leaf(b, o2, c, NULL, err, sizeof err), 0);
    assert_int_equal(murk_sparse_tile(b, o3, 8, 1.25f, err, sizeof err), 0);
    assert_int_equal(murk_sparse_leaf(b, o4, v, none, err, sizeof err), 0); /* no active voxel: nothing */
    static const double ident[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    murk_field *f = murk_sparse_end(b, ident, err, sizeof err);
    assert_non_null(f);
    /* box voxel (x, y, z) is index (x - 1, y - 1, z - 1); index ijk's value sits at world ijk */
    for (int i = 0; i < 512; i++) {
        int x = i >> 6, y = (i >> 3) & 7, z = i & 7;
        float want = (i & 1) ? v[i] : 0.0f;
        assert_true(murk_field_voxel(f, x + 1, y + 1, z + 1) == want);
        assert_true(murk_field_eval(f, murk_v3((float)x, (float)y, (float)z)) == want);
        assert_true(murk_field_eval(f, murk_v3((float)x + 8, (float)y, (float)z)) == 0.75f);
        assert_true(murk_field_eval(f, murk_v3((float)x, (float)y + 8, (float)z)) == 1.25f);
        assert_true(murk_field_eval(f, murk_v3((float)x + 8, (float)y + 8, (float)z)) == 1.25f);
    }
    /* across the border between the leaf of 1.25 and the tile of 1.25: 1.25; between the tile of 0.75 and it:
     * the average; past the active box: falling to 0 across the voxel of zeros, then 0 */
    assert_true(murk_field_eval(f, murk_v3(7.5f, 10.0f, 3.0f)) == 1.25f);
    assert_true(murk_field_eval(f, murk_v3(10.0f, 7.5f, 3.0f)) == 1.0f);
    assert_true(murk_field_eval(f, murk_v3(15.5f, 10.0f, 3.0f)) == 0.625f);
    assert_true(murk_field_eval(f, murk_v3(16.5f, 10.0f, 3.0f)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(17.0f, 10.0f, 3.0f)) == 0.0f);
    murk_field_info fi;
    murk_field_describe(f, &fi);
    printf("bricks %zu (the leaf, the tile of 0.75, one of 1.25 shared by the leaf and the tile), active %llu, "
           "%zu bytes\n", fi.bricks, (unsigned long long)fi.active, fi.bytes);
    assert_int_equal(fi.bricks, 3);
    assert_int_equal(fi.active, 256 + 3 * 512);
    assert_true(fi.sparse && fi.grid && !fi.transformed);
    murk_field_free(f);
}

/* A builder fed one bad thing: the error must contain needle. */
static void expect_build_error(const int amin[3], const int amax[3], const int o[3], const float *v, float tile,
                               const char *needle)
{
    err[0] = 0;
    murk_sparse_build *b = murk_sparse_begin("bad.vdb", amin, amax, err, sizeof err);
    if (b) {
        int o0[3] = {0, 0, 0};
        float one[512];
        for (int i = 0; i < 512; i++)
            one[i] = 0.5f + (float)i;
        int rc = murk_sparse_leaf(b, o0, one, NULL, err, sizeof err);
        if (rc == 0)
            rc = v ? murk_sparse_leaf(b, o, v, NULL, err, sizeof err) : murk_sparse_tile(b, o, 8, tile, err, sizeof err);
        if (rc == 0)
            fail_msg("no error; expected \"%s\"", needle);
        murk_sparse_abort(b);
    }
    printf("  %s\n", err);
    assert_contains(err, "bad.vdb: ");
    assert_contains(err, needle);
}

static void test_builder_errors(void **state)
{
    (void)state;
    float v[512];
    for (int i = 0; i < 512; i++)
        v[i] = 0.25f;
    int amin[3] = {0, 0, 0}, amax[3] = {15, 7, 7}, o[3] = {8, 0, 0}, same[3] = {0, 0, 0}, out[3] = {16, 0, 0};
    v[3 * 64 + 2 * 8 + 5] = -2.0f;
    expect_build_error(amin, amax, o, v, 0, "negative density -2 at voxel (11, 2, 5)");
    v[3 * 64 + 2 * 8 + 5] = NAN;
    expect_build_error(amin, amax, o, v, 0, "invalid value");
    v[3 * 64 + 2 * 8 + 5] = 0.25f;
    expect_build_error(amin, amax, o, NULL, INFINITY, "infinite value");
    expect_build_error(amin, amax, same, v, 0, "two nodes hold the voxels at index (0, 0, 0)");
    expect_build_error(amin, amax, out, v, 0, "outside the active box");
    int huge[3] = {1 << 24, 7, 7};
    expect_build_error(amin, huge, o, v, 0, "murk takes at most 16777214");
    int wide[3] = {1 << 20, 1 << 20, 7};
    expect_build_error(amin, wide, o, v, 0, "MURK_MAX_GRID_BOX");
    int empty[3] = {-1, 7, 7};
    expect_build_error(amin, empty, o, v, 0, "no active voxels");
    static const double singular[12] = {1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0}, bad[12] = {1, 0, 0, NAN, 0, 1, 0, 0, 0, 0, 1, 0};
    for (int k = 0; k < 2; k++) {
        murk_sparse_build *b = murk_sparse_begin("bad.vdb", amin, amax, err, sizeof err);
        assert_non_null(b);
        assert_null(murk_sparse_end(b, k ? bad : singular, err, sizeof err));
        printf("  %s\n", err);
        assert_contains(err, k ? "not finite" : "singular");
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sparse_equals_dense),
        cmocka_unit_test(test_inactive_and_tiles),
        cmocka_unit_test(test_builder_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
