/* test_vdb.c — sparse density grids (issue 28): the brick structure of core/media/sparse.c, OpenVDB files read
 * through the C++ shim (written here by tests/vdb_write, a C++ helper against libopenvdb built only in the test
 * build), and what a scene sees of them.
 *
 *   sparse = dense     random sparse grids built leaf by leaf and tile by tile (random masks, constant leaves
 *                      and tiles, tile and brick borders), saved as a dense .vol and loaded back: the same box,
 *                      voxels, bound grids, and murk_field_eval bit for bit at 300 000 points (random, voxel
 *                      centres, brick faces, the box's faces); the comparison itself must see a 1-ulp change
 *                      of one voxel (must-fail).
 *   held dense         sparse.c's rule: the bench's fully active 128^3 checker is held dense (its dense form is
 *                      within 1/16 of its sparse form), and gives bitwise the lookups, voxels and bound grids of it
 *                      held sparse (axis-aligned and rotated maps; must-fail: a voxel 1 ulp higher); a ball of 3 %
 *                      of its box stays sparse and equals its dense form the same way.
 *   inactive, tiles    inactive voxels read 0 whatever they hold; a tile's value at its borders; a leaf of one
 *                      value and a tile share one brick; the builder's errors (a negative, a NaN, a leaf met
 *                      twice or outside the box, a box too large) each say what and where.
 *   vdb grids          float, half and double grids, values at voxel centres; the grid name missing (the error
 *                      lists the file's grids), unnamed in a file of two, vec3s / int32 / level set / frustum /
 *                      no active voxels / truncated / random bytes / a metadata count over the file's size /
 *                      a root claiming 600 children where the file holds one (the walk of the topology):
 *                      each a "path: ..." error.
 *   closed form        a constant grid of two active 128^3 tiles with an empty tile between them: every
 *                      unbiased transmittance estimator against exp(-sigma_t c n h) within 4 se (the figure
 *                      resolves a 3 % error), and the field's quadrature against the closed form.
 *   rotated            a map that scales, rotates and translates: values at the mapped voxel centres, 0 outside
 *                      the rotated box, the majorant walk bounding the density on random rays, and the closed
 *                      form along an index axis through a constant block.
 *   images             cornell_smoke's cloud, and a checker, as a .vdb against the same field as a .vol: block-wise
 *                      z-test, independent seeds; the .vdb against its own voxels saved as .vol (and the checker,
 *                      whose box is the .vol's, against the original .vol): bitwise the same image; the cloud .vdb
 *                      with its density 20 % higher must DIFFER.
 *   memory             a 1024^3 grid with 3 % of its voxels active (a ball): `murk info`'s peak resident
 *                      memory over that of the same scene with a one-voxel grid stays within 1.5x the active
 *                      voxels' float storage; the grid's own bytes too.
 *   bad scenes         a truncated .vdb, random bytes, a missing grid, a vec3s grid, a near-singular map, more
 *                      active voxels than MURK_MAX_GRID_VOXELS: `murk render` exits 1 with "scene.yaml:L:C:"
 *                      and writes no image.
 *   fields             albedo, emission and temperature read from .vdb grids (issue 27; scalar grids only, so
 *                      grey): at every voxel centre the albedo a tracker gets is the value written, bit for bit,
 *                      and the emission the emission grid's value x Planck's colour at the written temperature;
 *                      a cloud of .vdb albedo 0.7 renders as `albedo: 0.7` (block-wise z, independent seeds;
 *                      must-fail: the .vdb at 0.665) and as the same constant in a .vol grid (bitwise); a
 *                      temperature grid with a negative or NaN voxel, an emission grid with an infinite one and
 *                      an albedo grid above 1 are refused, located at the key, naming the voxel. */
#include "mediatest.h"
#include "media/field_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* murk_sparse_finish, failing the test on an error. */
static murk_field *finish(murk_sparse_build *b, const double map[12], int hold)
{
    murk_field *f = murk_sparse_finish(b, map, hold, err, sizeof err);
    if (!f)
        fail_msg("%s", err);
    return f;
}

/* The grid of the plan, held as `hold` says (MURK_HOLD_SPARSE: the brick structure under test). */
static murk_field *build_plan(const plan_item *it, int n, const int amin[3], const int amax[3], const double map[12],
                              int hold)
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
    return finish(b, map, hold);
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
        murk_field *s = build_plan(it, n, amin, amax, MAP_SCALED, MURK_HOLD_SPARSE);
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
    murk_field *f = murk_sparse_finish(b, ident, MURK_HOLD_SPARSE, err, sizeof err); /* its 18 x 18 x 10 box is
                                                                                        smaller dense */
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

/* ---- the form a grid is held in ------------------------------------------------------------------ */

/* A grid through the builder, held as `hold` says: full, the bench's 128^3 checker of 0.2 / 1.4 (varied per voxel,
 * so that no two bricks are alike) with every voxel active; otherwise a ball of 3 % of a 128^3 box (radius 24.7
 * voxels, and a voxel at two opposite corners so that the box spans 128^3). */
static murk_field *build_form(int full, const double map[12], int hold)
{
    int amin[3] = {0, 0, 0}, amax[3] = {127, 127, 127};
    murk_sparse_build *b = murk_sparse_begin("form", amin, amax, err, sizeof err);
    if (!b)
        fail_msg("%s", err);
    float v[512];
    uint64_t mask[8];
    for (int x = 0; x < 128; x += 8)
        for (int y = 0; y < 128; y += 8)
            for (int z = 0; z < 128; z += 8) {
                memset(mask, 0, sizeof mask);
                for (int i = 0; i < 512; i++) {
                    int c[3] = {x + (i >> 6), y + ((i >> 3) & 7), z + (i & 7)};
                    double dx = c[0] - 63.5, dy = c[1] - 63.5, dz = c[2] - 63.5;
                    int corner = (c[0] == 0 && c[1] == 0 && c[2] == 0) || (c[0] == 127 && c[1] == 127 && c[2] == 127);
                    int on = full || corner || dx * dx + dy * dy + dz * dz <= 24.7 * 24.7;
                    v[i] = (((c[0] + c[1] + c[2]) & 1) ? 1.4f : 0.2f) * (1.0f + (float)((c[0] * 7 + c[1] * 13 + c[2] * 5) % 64) / 256.0f);
                    if (on)
                        mask[i >> 6] |= 1ull << (i & 63);
                }
                int o[3] = {x, y, z};
                if (murk_sparse_leaf(b, o, v, mask, err, sizeof err)) {
                    murk_sparse_abort(b);
                    fail_msg("%s", err);
                }
            }
    return finish(b, map, hold);
}

/* Same box, extremes and voxels; the number of lookups (compare_eval) and bound-grid cells that differ. */
static long compare_forms(const murk_field *s, const murk_field *d, uint64_t seed)
{
    int rs[3], rd[3];
    murk_field_grid(s, rs, NULL);
    murk_field_grid(d, rd, NULL);
    assert_memory_equal(rs, rd, sizeof rs);
    murk_vec3 l1, h1, l2, h2;
    murk_field_bounds(s, &l1, &h1, NULL);
    murk_field_bounds(d, &l2, &h2, NULL);
    assert_memory_equal(&l1, &l2, sizeof l1);
    assert_memory_equal(&h1, &h2, sizeof h1);
    assert_true(same_float(murk_field_max(s), murk_field_max(d)) && same_float(murk_field_min(s), murk_field_min(d)));
    long voxels_bad = 0;
    for (int z = 0; z < rs[2]; z++)
        for (int y = 0; y < rs[1]; y++)
            for (int x = 0; x < rs[0]; x++)
                voxels_bad += !same_float(murk_field_voxel(s, x, y, z), murk_field_voxel(d, x, y, z));
    assert_int_equal(voxels_bad, 0);
    return compare_eval(s, d, seed, 100000) + compare_bounds(s, d);
}

/* sparse.c's rule: a grid is held dense when its dense form (4 bytes a voxel of its box) is at most 1/16 larger
 * than its sparse form. The fully active checker is (its dense form, with the box's border of zeros, is a few
 * KiB larger than its bricks and nodes: held dense only thanks to the 1/16), and gives bitwise the lookups, voxels
 * and bound grids of the same grid held sparse, with an axis-aligned map and a rotated one; the ball of 3 % stays
 * sparse, and equals its dense form (forced) the same way. Must-fail: one voxel of the held-dense checker 1 ulp
 * higher is seen. */
static void test_held_dense(void **state)
{
    (void)state;
    double c = cos(0.5), sn = sin(0.5);
    const double rotated[12] = {0.01 * c, -0.01 * sn, 0, 0.1, 0.01 * sn, 0.01 * c, 0, -0.2, 0, 0, 0.008, 0.3};
    for (int k = 0; k < 3; k++) {
        int full = k < 2;
        const double *map = k == 1 ? rotated : MAP_SCALED;
        murk_field *a = build_form(full, map, MURK_HOLD_SMALLER), *sp = build_form(full, map, MURK_HOLD_SPARSE);
        murk_field *other = full ? a : build_form(0, map, MURK_HOLD_DENSE);
        murk_field_info fa, fs, fo;
        murk_field_describe(a, &fa);
        murk_field_describe(sp, &fs);
        murk_field_describe(other, &fo);
        int res[3];
        const float *data;
        murk_field_grid(a, res, &data);
        uint64_t dense = 4ull * (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2];
        printf("%s%s: box %dx%dx%d, %llu active voxels; dense form %llu bytes, sparse form %zu bytes (%.4fx): held %s, "
               "%zu bytes\n", full ? "checker, every voxel active" : "ball, 3 % active", k == 1 ? ", rotated" : "",
               res[0], res[1], res[2], (unsigned long long)fs.active, (unsigned long long)dense, fs.sparse_bytes,
               (double)dense / (double)fs.sparse_bytes, fa.held_dense ? "dense" : "sparse", fa.bytes);
        assert_true(fs.sparse && !fs.held_dense && fo.held_dense && !fo.sparse);
        assert_int_equal(fa.held_dense, full);
        assert_int_equal(fa.sparse, !full);
        assert_true(full ? data != NULL : data == NULL);
        assert_int_equal(fa.held_dense, dense <= fs.sparse_bytes + fs.sparse_bytes / 16);
        assert_int_equal(fo.sparse_bytes, fs.sparse_bytes);
        assert_int_equal(fo.active, fs.active);
        assert_int_equal(fo.transformed, k == 1);
        assert_int_equal(fo.bytes, sizeof(murk_field) + dense);
        long bad = compare_forms(sp, other, 40 + (uint64_t)k);
        printf("  against it held sparse: %ld of 100000 lookups and bound-grid cells differ\n", bad);
        assert_int_equal(bad, 0);
        if (k == 0) { /* must-fail: a voxel in the middle of the held-dense grid 1 ulp higher */
            murk_field_grid(a, res, &data);
            float *mut = (float *)(uintptr_t)data;
            size_t at = ((size_t)64 * res[1] + 64) * res[0] + 64;
            mut[at] = nextafterf(mut[at], INFINITY);
            murk_vec3 lo, hi;
            murk_field_bounds(a, &lo, &hi, NULL);
            long seen = 0;
            for (int j = 0; j < 64; j++) {
                float f[3] = {(64.5f + 0.1f * (float)(j % 4)) / (float)res[0], (64.5f - 0.1f * (float)(j / 4 % 4)) / (float)res[1],
                              (64.5f + 0.05f * (float)(j / 16)) / (float)res[2]};
                murk_vec3 q = murk_v3(lo.x + (hi.x - lo.x) * f[0], lo.y + (hi.y - lo.y) * f[1], lo.z + (hi.z - lo.z) * f[2]);
                seen += !same_float(murk_field_eval(a, q), murk_field_eval(sp, q));
            }
            printf("  must-fail: one voxel of the held-dense grid 1 ulp higher: %ld of 64 lookups around it differ\n", seen);
            assert_true(seen > 0);
        }
        if (other != a)
            murk_field_free(other);
        murk_field_free(a);
        murk_field_free(sp);
    }
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
    expect_build_error(amin, amax, o, v, 0, "negative value -2 at voxel (11, 2, 5)");
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

/* ---- .vdb files written by tests/vdb_write ---------------------------------------------------------- */

/* Writes tmp_dir()/name from spec with vdb_write; skips the test when murk or the tests were built without
 * OpenVDB. Returns the path (static buffer rotated 8 ways). */
static const char *vdb_file(const char *name, const char *spec)
{
    const char *w = getenv("MURK_VDB_WRITE");
    if (!w || !*w || !murk_field_vdb_supported())
        skip();
    static char paths[8][512];
    static int next;
    char *out = paths[next++ & 7];
    snprintf(out, sizeof paths[0], "%s", tmp_path(name));
    char specname[300], cmd[2048];
    snprintf(specname, sizeof specname, "%s.spec", name);
    const char *sp = write_tmp(specname, spec);
    snprintf(cmd, sizeof cmd, "'%s' '%s' < '%s'", w, out, sp);
    char *log = NULL;
    const char *argv[] = {"/bin/sh", "-c", cmd, NULL};
    int rc = run_argv(&log, argv);
    if (rc != 0)
        fail_msg("vdb_write %s failed (%d): %s", name, rc, log);
    free(log);
    return out;
}

static murk_field *load_vdb(const char *path, const char *grid)
{
    murk_field *f = murk_field_vdb_load(path, grid, NULL, err, sizeof err);
    if (!f)
        fail_msg("%s", err);
    return f;
}

static void expect_vdb_error(const char *path, const char *grid, const char *needle)
{
    int missing = 0;
    err[0] = 0;
    murk_field *f = murk_field_vdb_load(path, grid, &missing, err, sizeof err);
    if (f)
        fail_msg("%s (grid %s) loaded; expected \"%s\"", path, grid ? grid : "none", needle);
    printf("  %s\n", err);
    assert_contains(err, path);
    assert_contains(err, needle);
}

static void test_vdb_grids(void **state)
{
    (void)state;
    const char *p = vdb_file("grids.vdb", "grid density float\nmap 0.1 0.1 0.1 0 0 0\n"
                                         "checker 0 0 0 10 0.2 1.4\nfill 16 0 0 47 15 15 0.5\ninactive 12 3 3 7\n"
                                         "grid temperature half\nvoxel 1 2 3 1500\nvoxel 4 2 3 0.1\n"
                                         "grid wide double\nvoxel 0 0 0 0.25\nvoxel 9 0 0 1e-300\n");
    murk_field *d = load_vdb(p, "density");
    int res[3];
    murk_field_grid(d, res, NULL);
    assert_true(res[0] == 50 && res[1] == 18 && res[2] == 18); /* index -1..48 x -1..16 x -1..16 */
    for (int x = 0; x < 48; x++)
        for (int y = 0; y < 16; y++) {
            int z = (x * 7 + y) % 16;
            float want = x < 10 && y < 10 && z < 10 ? (((x + y + z) & 1) ? 1.4f : 0.2f) : (x >= 16 ? 0.5f : 0.0f);
            float got = murk_field_eval(d, murk_v3(0.1f * (float)x, 0.1f * (float)y, 0.1f * (float)z));
            if (fabsf(got - want) > 1e-5f) /* world 0.1 x is not exactly on a centre in float */
                fail_msg("density at voxel (%d, %d, %d): %g, want %g", x, y, z, (double)got, (double)want);
            assert_true(murk_field_voxel(d, x + 1, y + 1, z + 1) == want);
        }
    assert_true(murk_field_voxel(d, 13, 4, 4) == 0.0f); /* inactive (holds 7): 0 */
    murk_field_free(d);
    murk_field *t = load_vdb(p, "temperature"); /* half: 1500 exactly, 0.1 rounded to half */
    assert_true(murk_field_voxel(t, 1, 1, 1) == 1500.0f);
    float h = murk_field_voxel(t, 4, 1, 1);
    printf("half: 1500 -> %g, 0.1 -> %.9g\n", (double)murk_field_voxel(t, 1, 1, 1), (double)h);
    assert_true(h != 0.1f && fabsf(h - 0.1f) < 1e-4f);
    murk_field_free(t);
    murk_field *w = load_vdb(p, "wide"); /* double: rounded to float; 1e-300 underflows to 0 */
    assert_true(murk_field_voxel(w, 1, 1, 1) == 0.25f && murk_field_voxel(w, 10, 1, 1) == 0.0f);
    murk_field_free(w);

    printf("errors:\n");
    int missing = 0;
    assert_null(murk_field_vdb_load(p, "dens", &missing, err, sizeof err));
    assert_true(missing);
    assert_contains(err, "no grid 'dens'; the file has 'density', 'temperature', 'wide'");
    expect_vdb_error(p, NULL, "the file holds 3 grids ('density', 'temperature', 'wide'); name one with grid: NAME");
    expect_vdb_error(vdb_file("vec.vdb", "grid velocity vec3s\nvoxel 1 1 1 2\n"), NULL, "holds vec3s values");
    expect_vdb_error(vdb_file("int.vdb", "grid id int32\nvoxel 1 1 1 2\n"), NULL, "holds int32 values");
    expect_vdb_error(vdb_file("ls.vdb", "grid surface levelset\nvoxel 1 1 1 2\n"), NULL, "is a level set");
    expect_vdb_error(vdb_file("frustum.vdb", "grid density float\nfrustum\nvoxel 1 1 1 2\n"), NULL, "non-linear");
    expect_vdb_error(vdb_file("empty.vdb", "grid density float\n"), NULL, "has no active voxels");
    expect_vdb_error(vdb_file("negative.vdb", "grid density float\nvoxel 1 2 3 -0.5\n"), NULL,
                     "negative value -0.5 at voxel (1, 2, 3)");
    /* a truncated file, random bytes, a directory, a missing file */
    const char *tr = tmp_path("truncated.vdb");
    FILE *in = fopen(p, "rb"), *out = fopen(tr, "wb");
    assert_true(in && out);
    char buf[2000];
    size_t n = fread(buf, 1, sizeof buf, in);
    assert_true(fwrite(buf, 1, n, out) == n);
    fclose(in);
    fclose(out);
    expect_vdb_error(tr, "density", "not a readable OpenVDB file");
    /* the file's metadata count (byte 57, after the 57-byte header) claiming 2^31 - 1 entries: libopenvdb would
     * loop on its failed stream that many times (the fuzz harness's hang); the framing check refuses it */
    const char *claims = tmp_path("claims.vdb");
    in = fopen(p, "rb"), out = fopen(claims, "wb");
    assert_true(in && out);
    n = fread(buf, 1, sizeof buf, in);
    const unsigned char many[4] = {0xff, 0xff, 0xff, 0x7f};
    memcpy(buf + 57, many, 4);
    assert_true(fwrite(buf, 1, n, out) == n);
    fclose(in);
    fclose(out);
    expect_vdb_error(claims, "density", "truncated: the file's metadata (2147483647 entries) at byte 61");
    /* a root that claims 600 children where the file holds one (uncompressed, so libopenvdb's reads past the
     * end fail silently): libopenvdb would build a 264 KB node for each from its failed stream, 158 MB from a
     * file of a few KB (the fuzz harness's out-of-memory); the walk of the topology refuses it. The root's
     * counts follow the buffer count 1 and the background 0: tiles 0, children 1, the child at (0, 0, 0). */
    const char *one = vdb_file("one_child.vdb", "grid density float\ncompress none\nvoxel 1 2 3 0.5\n");
    const char *kids = tmp_path("children.vdb");
    in = fopen(one, "rb"), out = fopen(kids, "wb");
    assert_true(in && out);
    static char whole[65536];
    n = fread(whole, 1, sizeof whole, in);
    assert_true(n > 0 && n < sizeof whole);
    static const unsigned char root[28] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}; /* ... and the origin */
    size_t at = 0, found = 0;
    for (size_t i = 0; i + sizeof root <= n; i++)
        if (memcmp(whole + i, root, sizeof root) == 0)
            at = i, found++;
    assert_int_equal(found, 1);
    const unsigned char six_hundred[4] = {600 & 0xff, 600 >> 8, 0, 0};
    memcpy(whole + at + 12, six_hundred, 4);
    assert_true(fwrite(whole, 1, n, out) == n);
    fclose(in);
    fclose(out);
    murk_field_free(load_vdb(one, "density")); /* the file as written loads */
    expect_vdb_error(kids, "density", "truncated: grid 'density' root children at byte");
    /* the grid's delayed-load metadata claiming 2^32 - 1 leaves: libopenvdb sizes its arrays by the claim
     * (4 GB; 36 GB for the compressed sizes) before it reads them */
    const char *dl = tmp_path("delayed_load.vdb");
    in = fopen(one, "rb"), out = fopen(dl, "wb");
    assert_true(in && out);
    n = fread(whole, 1, sizeof whole, in);
    static const char tag[] = "__delayedload";
    char *at_tag = NULL;
    for (size_t i = 0; !at_tag && i + sizeof tag <= n; i++)
        if (memcmp(whole + i, tag, sizeof tag - 1) == 0)
            at_tag = whole + i;
    assert_non_null(at_tag);
    memset(at_tag + sizeof tag - 1 + 4, 0xff, 4); /* after the type name, the value's byte count, then the count */
    assert_true(fwrite(whole, 1, n, out) == n);
    fclose(in);
    fclose(out);
    expect_vdb_error(dl, "density", "file_delayed_load claims 4294967295 leaves");
    murk_rng rng;
    murk_rng_seed(&rng, 3, 4, 5);
    for (size_t i = 0; i < sizeof buf; i++)
        buf[i] = (char)murk_rng_u32(&rng);
    const char *rnd = tmp_path("random.vdb");
    out = fopen(rnd, "wb");
    assert_true(out && fwrite(buf, 1, sizeof buf, out) == sizeof buf);
    fclose(out);
    expect_vdb_error(rnd, "density", "not a VDB file");
    expect_vdb_error(tmp_dir(), "density", "not a regular file");
    expect_vdb_error(tmp_path("nowhere.vdb"), "density", "No such file");
}

/* ---- closed forms -------------------------------------------------------------------------------- */

static const mt_spec ESTIMATORS[] = {
    {"ratio", "transmittance: ratio", 0},
    {"residual_ratio", "transmittance: residual_ratio", 0},
    {"track_length", "transmittance: track_length", 0},
    {"unbiased_raymarch", "transmittance: unbiased_raymarch", 0},
    {"power_series", "transmittance: power_series", 0},
};
#define NEST ((int)(sizeof ESTIMATORS / sizeof ESTIMATORS[0]))

/* Every estimator on ray through the density block `density` against exp(-sigma_t D), grey and chromatic
 * (4 se, 3 % resolution: mt_check); the quadrature of the field the core built must match D first. */
static int check_depth(const char *label, const char *density, const murk_ray *ray, double D, long n)
{
    int nfail = 0;
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: %s, %s", density, mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("vdb_tr.yaml", common, "type: delta, ", ESTIMATORS, NEST);
        double q = mt_quadrature(&s->media[0].m, ray), T[3];
        printf("%s, %s: optical depth of the density %.6f, quadrature %.6f\n", label, chroma ? "chromatic" : "grey", D, q);
        if (!(fabs(q - D) <= 1e-4 * D + 1e-9))
            fail_msg("%s: quadrature %.6f != closed form %.6f", label, q, D);
        for (int c = 0; c < 3; c++)
            T[c] = exp(-mt_sigma_t[chroma][c] * D);
        for (int i = 0; i < NEST; i++) {
            murk_rng rng;
            murk_rng_seed(&rng, 900 + (uint64_t)i, 0x7472, (uint64_t)chroma);
            murk_path_ctx ctx;
            ctx.beta = murk_rgb1(1.0f);
            mt_acc a = {0};
            for (long k = 0; k < n; k++) {
                ctx.hero = mt_hero(&rng);
                murk_rgb Tr = murk_medium_transmittance(&s->media[i].m, ray, &ctx, &rng);
                mt_acc_add(&a, (double[3]){Tr.c[0], Tr.c[1], Tr.c[2]});
            }
            char head[64];
            snprintf(head, sizeof head, "  %-18s", ESTIMATORS[i].label);
            nfail += mt_check(head, &a, T, 2e-6, "");
        }
        murk_scene_free(s);
    }
    return nfail;
}

static void test_vdb_closed_form(void **state)
{
    (void)state;
    /* index x 0..383 at h = 1/128: two active 128^3 tiles of 0.5 with an empty (inactive) tile between */
    const char *p = vdb_file("tiles.vdb", "grid density float\nmap 0.0078125 0.0078125 0.0078125 0 0 0\n"
                                          "fill 0 0 0 127 127 127 0.5\nfill 256 0 0 383 127 127 0.5\n");
    murk_field *f = load_vdb(p, "density");
    murk_field_info fi;
    murk_field_describe(f, &fi);
    printf("tiles.vdb: %llu active voxels, %zu bricks, %zu bytes\n", (unsigned long long)fi.active, fi.bricks, fi.bytes);
    assert_int_equal(fi.active, 2 * 128 * 128 * 128);
    assert_int_equal(fi.bricks, 1);
    /* values: 0.5 inside the tiles, 0 in the empty one, 0.25 half-way across each border */
    float h = 0.0078125f;
    assert_true(murk_field_eval(f, murk_v3(h * 60, h * 60, h * 60)) == 0.5f);
    assert_true(murk_field_eval(f, murk_v3(h * 200, h * 60, h * 60)) == 0.0f);
    assert_true(murk_field_eval(f, murk_v3(h * 127.5f, h * 60, h * 60)) == 0.25f);
    assert_true(murk_field_eval(f, murk_v3(h * 255.5f, h * 60, h * 60)) == 0.25f);
    assert_true(murk_field_eval(f, murk_v3(h * -0.5f, h * 60, h * 60)) == 0.25f);
    murk_field_free(f);
    /* a ray along x through a row of voxel centres: each run of n active voxels contributes c n h (the ramps
     * across the cells at its ends add c h / 2 each): D = 0.5 * 256 / 128 = 1 */
    char dens[600];
    snprintf(dens, sizeof dens, "{ vdb: %s, grid: density }", p);
    murk_ray ray = {murk_v3(-0.4f, h * 63, h * 70), murk_v3(1, 0, 0), 0.0f, 3.5f};
    int nfail = check_depth("two tiles around an empty one, along x", dens, &ray, 1.0, 100000);
    /* the same through the empty tile only: nothing */
    murk_ray gap = {murk_v3(h * 200, h * 63, -0.5f), murk_v3(0, 0, 1), 0.0f, 2.0f};
    nfail += check_depth("through the empty tile, along z", dens, &gap, 0.0, 2000);
    assert_int_equal(nfail, 0);
}

/* The map: scale (0.02, 0.03, 0.025), rotate (30, 45, 10) degrees about x, y, z, translate (0.3, -0.2, 0.1), as
 * vdb_write composes it (and the scene's transform does): world = T Rz Ry Rx S ijk. */
static murk_vec3 rot_map(double x, double y, double z)
{
    double s[3] = {0.02 * x, 0.03 * y, 0.025 * z}, a = 30 * M_PI / 180, b = 45 * M_PI / 180, g = 10 * M_PI / 180;
    double y1 = cos(a) * s[1] - sin(a) * s[2], z1 = sin(a) * s[1] + cos(a) * s[2], x1 = s[0];
    double x2 = cos(b) * x1 + sin(b) * z1, z2 = -sin(b) * x1 + cos(b) * z1, y2 = y1;
    double x3 = cos(g) * x2 - sin(g) * y2, y3 = sin(g) * x2 + cos(g) * y2, z3 = z2;
    return murk_v3((float)(x3 + 0.3), (float)(y3 - 0.2), (float)(z3 + 0.1));
}

static void test_vdb_rotated(void **state)
{
    (void)state;
    const char *p = vdb_file("rotated.vdb", "grid density float\nmap 0.02 0.03 0.025 0.3 -0.2 0.1 30 45 10\n"
                                            "checker 5 3 -2 12 0.2 1.4\nfill 24 0 0 55 31 31 1.5\n");
    murk_field *f = load_vdb(p, "density");
    murk_field_info fi;
    murk_field_describe(f, &fi);
    assert_true(fi.transformed);
    double worst = 0;
    for (int x = 5; x < 17; x++) /* the checker's voxel centres, mapped */
        for (int y = 3; y < 15; y++)
            for (int z = -2; z < 10; z++) {
                float want = ((x - 5 + y - 3 + z + 2) & 1) ? 1.4f : 0.2f, got = murk_field_eval(f, rot_map(x, y, z));
                worst = fmax(worst, fabs(got - want));
            }
    printf("rotated: largest error at the checker's mapped voxel centres %.3g\n", worst);
    assert_true(worst < 1e-3);
    murk_vec3 lo, hi;
    murk_field_bounds(f, &lo, &hi, NULL);
    assert_true(murk_field_eval(f, lo) == 0.0f && murk_field_eval(f, hi) == 0.0f); /* corners of the world box */
    assert_true(murk_field_eval(f, rot_map(40, 15, 15)) == 1.5f);
    assert_true(murk_field_eval(f, rot_map(40, 15, 33)) == 0.0f); /* past the block, in the rotated box's corner */
    murk_field_free(f);

    /* the majorant walk bounds the density along random rays through the rotated box */
    char dens[600];
    snprintf(dens, sizeof dens, "{ vdb: %s, grid: density }", p);
    static const mt_spec one[] = {{"rot", "sigma_s: 1", 0}};
    char common[700];
    snprintf(common, sizeof common, "density: %s, majorant_resolution: 24", dens);
    murk_scene *s = mt_load_media("vdb_rot.yaml", common, "type: delta, ", one, 1);
    const murk_density *den = s->media[0].data.density;
    murk_rng rng;
    murk_rng_seed(&rng, 11, 12, 13);
    long checked = 0, violated = 0;
    murk_vec3 c = rot_map(30, 15, 14);
    for (int r = 0; r < 2000; r++) {
        murk_vec3 d = murk_normalize(murk_v3(murk_rng_float(&rng) - 0.5f, murk_rng_float(&rng) - 0.5f,
                                             murk_rng_float(&rng) - 0.5f));
        murk_ray ray = {murk_sub(c, murk_mul(d, 2.0f)), d, 0.0f, 4.0f};
        murk_majorant_walk w;
        murk_media_walk_init(den, &ray, 0.0f, 4.0f, &w);
        float ta, tb, mx, mn;
        while (murk_media_walk_next(&w, &ta, &tb, &mx, &mn))
            for (int k = 0; k < 8; k++) {
                float t = ta + (tb - ta) * murk_rng_float(&rng);
                float v = murk_media_density(den, murk_add(ray.o, murk_mul(ray.d, t)));
                checked++;
                violated += v > mx * (1 + 1e-5f) + 1e-6f || v < mn * (1 - 1e-5f) - 1e-6f;
            }
    }
    printf("rotated: %ld points on 2000 random rays, %ld outside their segment's [minorant, majorant]\n", checked,
           violated);
    assert_int_equal(violated, 0);
    murk_scene_free(s);
    /* the closed form along the index x axis through the block's voxel centres: 32 voxels of 1.5, 0.02 apart */
    murk_vec3 a = rot_map(10, 15, 15), b = rot_map(70, 15, 15);
    murk_vec3 d = murk_normalize(murk_sub(b, a));
    murk_ray ray = {a, d, 0.0f, murk_length(murk_sub(b, a))};
    /* from index x 10 to 70: the checker row (x 5..16 at y 15: outside the checker, y < 15) is not crossed */
    assert_int_equal(check_depth("rotated block, along its index x axis", dens, &ray, 1.5 * 32 * 0.02, 100000), 0);
}

/* ---- images ------------------------------------------------------------------------------------------ */

#define IMG_SEEDS 6

/* cornell_smoke at 32x32 with its density replaced. */
static void render_density(img_stack *st, const char *density, int seed0, const char *more)
{
    char set[800];
    snprintf(set, sizeof set, "media.smoke.density=%s", density);
    const char *extra[] = {"--set", "render.resolution=[32, 32]", "--spp", "64", "--set", set, more ? "--set" : NULL,
                           more, NULL};
    img_stack_free(st);
    img_stack_render(st, src_path("scenes/cornell_smoke.yaml"), "vdb_img.exr", IMG_SEEDS, seed0, extra);
}

/* One render of cornell_smoke with the density, seed 5, into tmp_dir()/out. */
static const char *render_once(const char *density, const char *out)
{
    char set[800];
    snprintf(set, sizeof set, "media.smoke.density=%s", density);
    const char *path = tmp_path(out);
    const char *args[] = {"render", src_path("scenes/cornell_smoke.yaml"), "-o", path, "--threads", "2", "--quiet",
                          "--set", "render.resolution=[32, 32]", "--spp", "16", "--set", "render.seed=5", "--set",
                          set, NULL};
    run_murk_ok(args, NULL);
    static char keep[4][512];
    static int next;
    char *k = keep[next++ & 3];
    snprintf(k, sizeof keep[0], "%s", path);
    return k;
}

/* cornell_smoke's box [-0.6, 0.05, -0.6]-[0.6, 1.45, 0.6], 16^3: 0.2 / 1.4 alternating, the outer layer 0 (so that
 * the .vol's clamped border and the .vdb's voxel of zeros agree) */
static float checker_with_border(int x, int y, int z, float cx, float cy, float cz)
{
    (void)cx, (void)cy, (void)cz;
    if (x == 0 || y == 0 || z == 0 || x == 15 || y == 15 || z == 15)
        return 0.0f;
    return ((x + y + z) & 1) ? 1.4f : 0.2f;
}

/* suite 'long' (test_vdb --long): the image comparison takes most of the program's time */
static void long_vdb_images(void **state)
{
    (void)state;
    murk_vec3 lo = murk_v3(-0.6f, 0.05f, -0.6f), hi = murk_v3(0.6f, 1.45f, 0.6f);
    murk_field *cloud = murk_field_cloud(lo, hi, 64, 7, 2.5f, 5, 0.7f); /* cornell_smoke's own cloud */
    assert_non_null(cloud);
    char cloud_vol[600], checker_vol[600], spec[1400], d_vol[700], d_vdb[700];
    snprintf(cloud_vol, sizeof cloud_vol, "%s", tmp_path("cloud.vol"));
    if (murk_field_vol_save(cloud_vol, cloud, err, sizeof err))
        fail_msg("%s", err);
    murk_field_free(cloud);
    int res[3] = {16, 16, 16};
    snprintf(checker_vol, sizeof checker_vol, "%s", mt_save_grid("checker16.vol", res, lo, hi, checker_with_border));
    int nfail = 0;
    for (int k = 0; k < 2; k++) {
        const char *vol = k ? checker_vol : cloud_vol, *label = k ? "checker" : "cloud";
        snprintf(spec, sizeof spec, "grid density float\nvol %s\n", vol);
        const char *vdb = vdb_file(k ? "checker16.vdb" : "cloud.vdb", spec);
        snprintf(d_vol, sizeof d_vol, "{ grid: %s }", vol);
        snprintf(d_vdb, sizeof d_vdb, "{ vdb: %s, grid: density }", vdb);
        img_stack a = {0}, b = {0}, c = {0};
        render_density(&a, d_vol, 200, NULL);
        render_density(&b, d_vdb, 300, NULL); /* independent seeds */
        printf("cornell_smoke 32x32, %d seeds x 64 spp, the %s as .vdb against .vol:\n", IMG_SEEDS, label);
        nfail += !img_stack_agree(label, &b, &a, 4);
        if (k == 0) { /* the must-fail, on the cloud */
            render_density(&c, d_vdb, 400, "media.smoke.scale=1.2");
            if (!img_stack_must_differ("the .vdb 20 % denser", &c, &a, 4)) {
                printf("  the comparison cannot see a 20 %% denser medium  <-- FAIL\n");
                nfail++;
            }
        }
        img_stack_free(&a);
        img_stack_free(&b);
        img_stack_free(&c);
        /* the .vdb's own voxels saved as .vol: the same field, the same box, so the same image bit for bit */
        murk_field *f = load_vdb(vdb, "density");
        char own[600];
        snprintf(own, sizeof own, "%s", tmp_path(k ? "checker_own.vol" : "cloud_own.vol"));
        if (murk_field_vol_save(own, f, err, sizeof err))
            fail_msg("%s", err);
        murk_field_free(f);
        char d_own[700];
        snprintf(d_own, sizeof d_own, "{ grid: %s }", own);
        const char *i1 = render_once(d_vdb, "once_vdb.exr"), *i2 = render_once(d_own, "once_own.exr");
        int same = same_pixels(i1, i2);
        printf("  the %s .vdb and its voxels as .vol, seed 5: %s\n", label, same ? "bitwise the same" : "DIFFER");
        nfail += !same;
        if (k == 1) { /* the checker's box is the .vol's: the same image as the original .vol too */
            const char *i3 = render_once(d_vol, "once_vol.exr");
            same = same_pixels(i1, i3);
            printf("  the checker .vdb and the original .vol, seed 5: %s\n", same ? "bitwise the same" : "DIFFER");
            nfail += !same;
        }
    }
    assert_int_equal(nfail, 0);
}

/* ---- memory ------------------------------------------------------------------------------------------ */

/* `murk info` on a scene whose medium reads grid `density` of vdb: the peak resident memory and the grid's
 * bytes and active voxels as it reports them, in bytes. */
static void info_memory(const char *vdb, double *peak, double *grid, double *active)
{
    char text[1200];
    snprintf(text, sizeof text, "murk: 1\nmedia:\n  smoke: { type: delta, sigma_s: 1, density: { vdb: %s, grid: density } }\n"
             "shapes:\n  - { type: box, min: [-2, -2, -2], max: [1100, 1100, 1100], interior: smoke }\n", vdb);
    const char *scene = write_tmp("memory.yaml", text);
    char *out = NULL;
    const char *args[] = {"info", scene, NULL};
    if (run_murk_argv(&out, args) != 0)
        fail_msg("murk info failed:\n%s", out);
    const char *p = strstr(out, "(VmHWM) "), *g = strstr(out, "\n  grid     smoke"), *a = g ? strstr(g, " active voxels") : NULL;
    assert_true(p && g && a);
    double v;
    char unit[8];
    assert_int_equal(sscanf(p + 8, "%lf %7s", &v, unit), 2);
    *peak = v * (unit[0] == 'G' ? 1073741824.0 : unit[0] == 'M' ? 1048576.0 : unit[0] == 'K' ? 1024.0 : 1.0);
    assert_int_equal(sscanf(g + 17, "%lf %7s", &v, unit), 2);
    *grid = v * (unit[0] == 'G' ? 1073741824.0 : unit[0] == 'M' ? 1048576.0 : unit[0] == 'K' ? 1024.0 : 1.0);
    while (a > out && a[-1] != ',')
        a--;
    assert_int_equal(sscanf(a, "%lf", active), 1);
    free(out);
}

static void test_vdb_memory(void **state)
{
    (void)state;
    /* a ball of radius 197.4 voxels: 3.0 % of the 1023^3 box its corner voxels span */
    const char *big = vdb_file("ball1024.vdb", "grid density float\nball 511 197.4\n");
    const char *tiny = vdb_file("one.vdb", "grid density float\nvoxel 0 0 0 1\n");
    double peak, grid, active, peak0, grid0, active0;
    info_memory(tiny, &peak0, &grid0, &active0);
    info_memory(big, &peak, &grid, &active);
    double floats = 4.0 * active, box = 1023.0 * 1023.0 * 1023.0;
    printf("1023^3 box, %.0f active voxels (%.2f %%): their floats %.1f MiB; the grid holds %.1f MiB (%.3fx); murk info's "
           "peak resident memory %.1f MiB over %.1f MiB with a one-voxel grid: +%.1f MiB (%.3fx the floats)\n", active,
           100.0 * active / box, floats / 1048576.0, grid / 1048576.0, grid / floats, peak / 1048576.0,
           peak0 / 1048576.0, (peak - peak0) / 1048576.0, (peak - peak0) / floats);
    assert_true(active / box > 0.029 && active / box < 0.031);
    assert_true(grid <= 1.5 * floats);
    /* The process's resident memory says what murk holds only without a sanitizer: AddressSanitizer adds
       shadow memory and a quarantine of freed blocks to every allocation. The grid's own count above still
       holds there. */
    const char *san = getenv("MURK_B_SANITIZE");
    if (san && *san && strcmp(san, "none") != 0)
        printf("built with -fsanitize=%s: the peak resident memory is not judged\n", san);
    else
        assert_true(peak - peak0 <= 1.5 * floats);
    remove(big);
}

/* ---- bad scenes ------------------------------------------------------------------------------------------ */

/* `murk render` of a scene reading density {vdb: vdb, grid: grid}: exit 1, "scene:LINE:COL: ... needle", no image. */
static void expect_scene_error(const char *vdb, const char *grid, const char *env, const char *needle)
{
    char text[1200];
    snprintf(text, sizeof text, "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\nmedia:\n"
             "  smoke: { type: delta, density: { vdb: %s, grid: %s } }\n"
             "shapes:\n  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: smoke }\n", vdb, grid);
    const char *scene = write_tmp("bad_vdb.yaml", text), *out = tmp_path("bad_vdb.exr");
    remove(out);
    char *log = NULL;
    const char *args[] = {"/usr/bin/env", env ? env : "MURK_NOTHING=1", getenv("MURK_EXE"), "render", scene, "-o", out,
                          NULL};
    int rc = run_argv(&log, args);
    char where[700];
    snprintf(where, sizeof where, "%s:4:", scene);
    assert_refused(log, rc, where, needle, out);
}

static void test_vdb_bad_scenes(void **state)
{
    (void)state;
    const char *ok = vdb_file("ok.vdb", "grid density float\nchecker 0 0 0 12 0.5 1\ngrid velocity vec3s\nvoxel 0 0 0 1\n");
    /* truncated and random bytes */
    FILE *in = fopen(ok, "rb");
    assert_non_null(in);
    static unsigned char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf, in);
    fclose(in);
    const char *tr = tmp_path("cut.vdb");
    FILE *o = fopen(tr, "wb");
    assert_true(o && fwrite(buf, 1, n / 2, o) == n / 2);
    fclose(o);
    expect_scene_error(tr, "density", NULL, "not a readable OpenVDB file");
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    for (size_t i = 0; i < 4096; i++)
        buf[i] = (unsigned char)murk_rng_u32(&rng);
    const char *rnd = tmp_path("noise.vdb");
    o = fopen(rnd, "wb");
    assert_true(o && fwrite(buf, 1, 4096, o) == 4096);
    fclose(o);
    expect_scene_error(rnd, "density", NULL, "not a VDB file");
    expect_scene_error(ok, "dens", NULL, "no grid 'dens'; the file has 'density', 'velocity'");
    expect_scene_error(ok, "velocity", NULL, "holds vec3s values");
    expect_scene_error(ok, "density", "MURK_MAX_GRID_VOXELS=1000", "more than the limit of 1000");
    /* a singular map: the scale 0.1234375 written by OpenVDB, then set to 0 in the file */
    const char *sing = vdb_file("singular.vdb", "grid density float\nmap 1 1 0.1234375 0 0 0\nvoxel 1 1 1 1\n");
    in = fopen(sing, "rb");
    assert_non_null(in);
    n = fread(buf, 1, sizeof buf, in);
    fclose(in);
    double want = 0.1234375, zero = 0.0;
    int patched = 0;
    for (size_t i = 0; i + 8 <= n; i++)
        if (!memcmp(buf + i, &want, 8)) {
            memcpy(buf + i, &zero, 8);
            patched++;
        }
    assert_true(patched > 0);
    o = fopen(sing, "wb");
    assert_true(o && fwrite(buf, 1, n, o) == n);
    fclose(o);
    expect_scene_error(sing, "density", NULL, "density vdb:");
}

/* ---- albedo, emission and temperature fields from .vdb grids (issue 27) ---------------------------- */

/* murk reads scalar grids only (a vec3s grid is refused: test_vdb_grids), so a .vdb albedo or emission is
 * grey, one grid for the three channels. The grids below sit on a map of scale 1/8: voxel ijk's centre is
 * world ijk / 8 exactly in float, where the trilinear lookup returns the voxel's value bit for bit. */
#define FV_N 8

static float fv_albedo(int x, int y, int z) { return (float)(1 + (x * 37 + y * 11 + z * 5) % 63) / 64.0f; }
static float fv_emission(int x, int y, int z) { return (float)(1 + (x * 5 + y * 3 + z * 7) % 16) / 8.0f; }
static float fv_temperature(int x, int y, int z) { return 0.5f + (float)((x * 13 + y * 7 + z * 3) % 32) / 16.0f; }

/* The .vdb of four grids, density 1 over the FV_N^3 voxels and the three fields above, each voxel written. */
static const char *fields_vdb(void)
{
    static const char *grids[] = {"density", "albedo", "emission", "temperature"};
    size_t cap = 4 * (64 + (size_t)FV_N * FV_N * FV_N * 40), k = 0;
    char *spec = malloc(cap);
    assert_non_null(spec);
    for (int g = 0; g < 4; g++) {
        k += (size_t)snprintf(spec + k, cap - k, "grid %s float\nmap 0.125 0.125 0.125 0 0 0\n", grids[g]);
        for (int z = 0; z < FV_N; z++)
            for (int y = 0; y < FV_N; y++)
                for (int x = 0; x < FV_N; x++) {
                    float v = g == 0 ? 1.0f : g == 1 ? fv_albedo(x, y, z) : g == 2 ? fv_emission(x, y, z)
                                                                                  : fv_temperature(x, y, z);
                    k += (size_t)snprintf(spec + k, cap - k, "voxel %d %d %d %.9g\n", x, y, z, (double)v);
                }
    }
    assert_true(k < cap);
    const char *p = vdb_file("fields.vdb", spec);
    free(spec);
    return p;
}

/* The albedo and the emitted radiance a medium of these grids gives its trackers (host->albedo and
 * host->emission) at every voxel centre: the albedo the value written, bit for bit; the emission the
 * emission grid's value times Planck's colour at T = (value - 0.25) x 2000 K (500 to 4375 K), to the blackbody
 * table's interpolation (2e-3, test_fields' tolerance for it). A temperature one voxel off is 125 K off or more. */
static void test_vdb_fields(void **state)
{
    (void)state;
    const char *p = fields_vdb();
    char common[2048];
    snprintf(common, sizeof common, "density: { vdb: %s, grid: density }, sigma_a: 0.5, sigma_s: 1, "
             "albedo: { vdb: %s, grid: albedo }, emission: { vdb: %s, grid: emission }, "
             "temperature: { vdb: %s, grid: temperature }, temperature_scale: 2000, temperature_offset: 0.25", p, p, p, p);
    static const mt_spec one[] = {{"fire", "", 0}};
    murk_scene *s = mt_load_media("vdb_fields.yaml", common, "type: delta", one, 1);
    const murk_medium_data *md = &s->media[0].data;
    assert_true((md->fields & MURK_FIELD_ALBEDO) && (md->fields & MURK_FIELD_EMISSION));
    long albedo_bad = 0, emission_bad = 0;
    double worst = 0.0;
    for (int z = 0; z < FV_N; z++)
        for (int y = 0; y < FV_N; y++)
            for (int x = 0; x < FV_N; x++) {
                murk_vec3 c = murk_v3(0.125f * (float)x, 0.125f * (float)y, 0.125f * (float)z);
                murk_rgb a = murk_media_albedo(md->density, c), e = murk_media_emission(md->density, c);
                float want = fv_albedo(x, y, z);
                if (!(a.c[0] == want && a.c[1] == want && a.c[2] == want) && albedo_bad++ < 5)
                    printf("  albedo at voxel (%d, %d, %d): %.9g %.9g %.9g, written %.9g\n", x, y, z, (double)a.c[0],
                           (double)a.c[1], (double)a.c[2], (double)want);
                double T = ((double)fv_temperature(x, y, z) - 0.25) * 2000.0;
                murk_rgb bb = murk_blackbody_rgb(T);
                for (int ch = 0; ch < 3; ch++) {
                    double ref = (double)fv_emission(x, y, z) * bb.c[ch];
                    double d = fabs(e.c[ch] - ref) / fmax(ref, 1e-3 * (double)fv_emission(x, y, z) * bb.c[0]);
                    worst = fmax(worst, d);
                    if (!(d <= 2e-3) && emission_bad++ < 5)
                        printf("  emission at voxel (%d, %d, %d) ch %d: %.6g, want %.6g (T %.1f K)\n", x, y, z, ch,
                               (double)e.c[ch], ref, T);
                }
            }
    printf("%d voxel centres: albedo differs from the written value at %ld; emission against emission x "
           "blackbody(T): largest relative difference %.2e, %ld channels beyond 2e-3\n", FV_N * FV_N * FV_N,
           albedo_bad, worst, emission_bad);
    assert_int_equal(albedo_bad, 0);
    assert_int_equal(emission_bad, 0);
    /* between centres the albedo is the trilinear mix; outside the grid's box 0 */
    murk_rgb mid = murk_media_albedo(md->density, murk_v3(0.0625f, 0.0f, 0.0f));
    assert_true(fabsf(mid.c[0] - 0.5f * (fv_albedo(0, 0, 0) + fv_albedo(1, 0, 0))) <= 1e-6f);
    assert_true(murk_media_albedo(md->density, murk_v3(-1.0f, 0.0f, 0.0f)).c[0] == 0.0f);
    murk_scene_free(s);
}

/* A box of chromatic fog seen against a background, `albedo` given as `fog` says. */
static const char *fog_scene(const char *name, const char *albedo)
{
    char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [32, 32], spp: 16 }\n"
             "camera: { from: [0, 0, 3], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }\n"
             "integrator: { type: volpath_nee }\nbackground: [0.5, 0.6, 0.7]\n"
             "media: { fog: { type: spectral_mis, density: { constant: 1 }, sigma_a: 0, sigma_s: [2, 3, 4], "
             "albedo: %s } }\n"
             "shapes:\n  - { type: box, min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5], interior: fog }\n", albedo);
    static char keep[4][512];
    static int next;
    char *k = keep[next++ & 3];
    snprintf(k, sizeof keep[0], "%s", write_tmp(name, text));
    return k;
}

static float const_07(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy, (void)cz;
    return 0.7f;
}

/* A .vdb albedo of 0.7 wherever the fog is (an active block from -0.75 to 0.75, past the fog's box, so no
 * lookup falls in the last cell where the value drops to 0): against `albedo: 0.7`, which murk folds into
 * sigma_a and sigma_s (no field: another code path, so not bitwise), block-wise z over 4 seeds each,
 * independent seeds; the must-fail is the .vdb at 0.665 (5 % less albedo). Against the same constant as a
 * .vol grid (the same code path, and the same value at every point the fog holds) bitwise the same image. */
static void test_vdb_albedo_render(void **state)
{
    (void)state;
    const char *c07 = vdb_file("albedo07.vdb", "grid albedo float\nmap 0.125 0.125 0.125 0 0 0\n"
                                              "fill -6 -6 -6 6 6 6 0.7\n");
    const char *c0665 = vdb_file("albedo0665.vdb", "grid albedo float\nmap 0.125 0.125 0.125 0 0 0\n"
                                                  "fill -6 -6 -6 6 6 6 0.665\n");
    const char *vol = mt_save_grid("albedo07.vol", (int[]){4, 4, 4}, murk_v3(-0.75f, -0.75f, -0.75f),
                                   murk_v3(0.75f, 0.75f, 0.75f), const_07);
    char a_vdb[700], a_low[700], a_vol[700];
    snprintf(a_vdb, sizeof a_vdb, "{ vdb: %s, grid: albedo }", c07);
    snprintf(a_low, sizeof a_low, "{ vdb: %s, grid: albedo }", c0665);
    snprintf(a_vol, sizeof a_vol, "{ grid: %s }", vol);
    const char *s_const = fog_scene("fog_const.yaml", "0.7"), *s_vdb = fog_scene("fog_vdb.yaml", a_vdb);
    const char *s_low = fog_scene("fog_low.yaml", a_low), *s_vol = fog_scene("fog_vol.yaml", a_vol);
    img_stack a = {0}, b = {0}, c = {0};
    img_stack_render(&a, s_const, "fog_const.exr", 4, 100, NULL);
    img_stack_render(&b, s_vdb, "fog_vdb.exr", 4, 200, NULL); /* independent seeds */
    img_stack_render(&c, s_low, "fog_low.exr", 4, 300, NULL);
    printf("fog 32x32, 4 seeds x 16 spp, a .vdb albedo of 0.7 against albedo: 0.7:\n");
    int agree = img_stack_agree(".vdb albedo 0.7 vs albedo: 0.7", &b, &a, 4);
    int differ = img_stack_must_differ(".vdb albedo 0.665 vs albedo: 0.7", &c, &a, 4);
    img_stack_free(&a);
    img_stack_free(&b);
    img_stack_free(&c);
    char o1[512], o2[512];
    snprintf(o1, sizeof o1, "%s", tmp_path("fog_vdb_once.exr"));
    snprintf(o2, sizeof o2, "%s", tmp_path("fog_vol_once.exr"));
    run_murk_ok((const char *const[]){"render", s_vdb, "-o", o1, "--quiet", "--threads", "2", NULL}, NULL);
    run_murk_ok((const char *const[]){"render", s_vol, "-o", o2, "--quiet", "--threads", "2", NULL}, NULL);
    int same = same_pixels(o1, o2);
    printf("  the .vdb albedo and the same constant as a .vol grid, seed 0: %s\n", same ? "bitwise the same" : "DIFFER");
    assert_true(agree);
    assert_true(differ);
    assert_true(same);
}

/* `murk render` of a medium whose `key` reads grid `grid` of vdb: exit 1 with the error at the vdb's file name
 * (line 4, its column), the needle, no image. */
static void expect_field_error(const char *key, const char *vdb, const char *grid, const char *needle)
{
    char line[1200], text[1600];
    snprintf(line, sizeof line, "  fire: { type: delta, density: { constant: 1 }, sigma_a: 1, %s: { vdb: %s, grid: %s } }",
             key, vdb, grid);
    snprintf(text, sizeof text, "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\nmedia:\n%s\n"
             "shapes:\n  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: fire }\n", line);
    const char *scene = write_tmp("bad_field.yaml", text), *out = tmp_path("bad_field.exr");
    remove(out);
    char key_at[64];
    snprintf(key_at, sizeof key_at, "%s: { vdb: ", key);
    const char *at = strstr(line, key_at);
    assert_non_null(at);
    /* the file name's column, or for a value above 1 (found after the grid was read) the grid name's */
    const char *name = strcmp(key, "albedo") ? strstr(at, vdb) : strstr(at, "grid: ") + 6;
    char where[800];
    snprintf(where, sizeof where, "%s:4:%d: %s", scene, (int)(name - line) + 1, key);
    char *log = NULL;
    const char *args[] = {getenv("MURK_EXE"), "render", scene, "-o", out, NULL};
    int rc = run_argv(&log, args);
    assert_refused(log, rc, where, needle, out);
}

/* A temperature grid with a negative or a NaN voxel, an emission grid with an infinite one and an albedo grid
 * above 1: each a located error naming the voxel. */
static void test_vdb_fields_bad(void **state)
{
    (void)state;
    const char *neg = vdb_file("t_neg.vdb", "grid temperature float\nvoxel 0 0 0 1500\nvoxel 1 2 3 -5\n");
    const char *nan = vdb_file("t_nan.vdb", "grid temperature float\nvoxel 0 0 0 1500\nvoxel 1 2 3 nan\n");
    const char *inf = vdb_file("e_inf.vdb", "grid emission float\nvoxel 0 0 0 1\nvoxel 2 2 2 inf\n");
    const char *hi = vdb_file("a_hi.vdb", "grid albedo float\nvoxel 0 0 0 0.5\nvoxel 3 4 5 1.5\n");
    expect_field_error("temperature", neg, "temperature", "negative value -5 at voxel (1, 2, 3)");
    expect_field_error("temperature", nan, "temperature", "invalid value nan at voxel (1, 2, 3)");
    expect_field_error("emission", inf, "emission", "infinite value inf at voxel (2, 2, 2)");
    /* the box starts one voxel below the active index box (0, 0, 0): index (3, 4, 5) is its voxel (4, 5, 6) */
    expect_field_error("albedo", hi, "albedo", "albedo: value 1.5 at voxel (4, 5, 6) of the grid's box is above 1");
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sparse_equals_dense),
        cmocka_unit_test(test_inactive_and_tiles),
        cmocka_unit_test(test_held_dense),
        cmocka_unit_test(test_builder_errors),
        cmocka_unit_test(test_vdb_grids),
        cmocka_unit_test(test_vdb_closed_form),
        cmocka_unit_test(test_vdb_rotated),
        cmocka_unit_test(long_vdb_images),
        cmocka_unit_test(test_vdb_memory),
        cmocka_unit_test(test_vdb_bad_scenes),
        cmocka_unit_test(test_vdb_fields),
        cmocka_unit_test(test_vdb_albedo_render),
        cmocka_unit_test(test_vdb_fields_bad),
    };
    if (getenv("MURK_TEST_FILTER")) /* e.g. MURK_TEST_FILTER='test_vdb_*' */
        cmocka_set_test_filter(getenv("MURK_TEST_FILTER"));
    return STAT_RUN(tests, argc, argv);
}
