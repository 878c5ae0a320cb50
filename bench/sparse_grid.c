/* sparse_grid.c — what a sparse grid costs (issue 28): its memory against its active voxels' floats, and a
 * density lookup against the dense grid's on the same field.
 *
 *   build/bench/sparse_grid [rounds] [lookups per round and side]        (defaults 9 and 2000000)
 *
 * Memory: the synthetic 1024^3 grid of the memory goal, built through the sparse builder as the .vdb and .nvdb
 * readers build it: a ball of radius 197.4 voxels (3.0 % of the box) with non-constant values, and a voxel at
 * two opposite corners so the box spans 1024^3. Printed: its active voxels, their float storage (4 bytes
 * each), the bytes the grid holds (bricks, nodes, top table: murk_field_describe) and their ratio, and the
 * stated overhead (the nodes and the top table, which are not per brick).
 *
 * Lookups: one field held both ways (the same voxels; the sparse box is the active box grown by a voxel of
 * zeros, so values agree to float rounding, checked on the sums), the sparse side built as murk builds a .vdb
 * and held in the form sparse.c's rule gives it (for a grid it holds dense, the forced sparse form is timed
 * too): cornell_smoke's cloud baked at
 * 256^3 (64 MiB dense; its voxels that are 0 are inactive in the sparse copy, 62 % of the box), and a 128^3
 * checker of 0.2 / 1.4 with every voxel active (no empty brick: the sparse cost of a full grid). Two point
 * sets, in the box inset by a voxel (where both hold the same field): 2 000 000 uniform points (every lookup a cache miss for the dense grid as for the sparse
 * one), and points marched along 2000 random rays through the box at a quarter-voxel step (coherent, as a
 * tracker looks up). Each round times the dense and the sparse lookups over the same points (CPU time of
 * this thread), the order alternating from round to round; printed per field and point set: ns per lookup
 * for each, and the median, min and max over the rounds of the per-round ratio sparse / dense.
 *
 * Instruction counts instead of time (an unloaded figure): valgrind --tool=callgrind build/bench/sparse_grid 1
 * 200000, then callgrind_annotate for murk_field_eval's inclusive count with the sparse and dense calls apart
 * (they are the two loops of time_lookups). */
#include "media/field_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static uint64_t mix(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    return x;
}

/* ---- memory --------------------------------------------------------------------------------------- */

static void memory_figure(void)
{
    char err[1024];
    const int c = 512;
    const double r = 197.4;
    int amin[3] = {0, 0, 0}, amax[3] = {1023, 1023, 1023};
    murk_sparse_build *b = murk_sparse_begin("ball", amin, amax, err, sizeof err);
    if (!b) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    float v[512];
    uint64_t mask[8];
    int lo = (int)floor(c - r) & ~7, hi = (int)ceil(c + r);
    for (int x = lo; x <= hi; x += 8)
        for (int y = lo; y <= hi; y += 8)
            for (int z = lo; z <= hi; z += 8) {
                memset(mask, 0, sizeof mask);
                int any = 0;
                for (int i = 0; i < 512; i++) {
                    double dx = x + (i >> 6) - c, dy = y + ((i >> 3) & 7) - c, dz = z + (i & 7) - c;
                    double d = sqrt(dx * dx + dy * dy + dz * dz);
                    v[i] = 0.0f;
                    if (d <= r) {
                        v[i] = (float)(1.0 - d / r + (double)(mix((uint64_t)(x * 1031 + y) * 1031 + (uint64_t)z * 7 +
                                                                   (uint64_t)i) % 1024) / 4096.0);
                        mask[i >> 6] |= 1ull << (i & 63);
                        any = 1;
                    }
                }
                int o[3] = {x, y, z};
                if (any && murk_sparse_leaf(b, o, v, mask, err, sizeof err)) {
                    fprintf(stderr, "%s\n", err);
                    exit(1);
                }
            }
    for (int k = 0; k < 2; k++) { /* the two corners */
        int o[3] = {k ? 1016 : 0, k ? 1016 : 0, k ? 1016 : 0};
        for (int i = 0; i < 512; i++)
            v[i] = 0.5f;
        memset(mask, 0, sizeof mask);
        mask[k ? 7 : 0] = k ? 1ull << 63 : 1ull;
        if (murk_sparse_leaf(b, o, v, mask, err, sizeof err)) {
            fprintf(stderr, "%s\n", err);
            exit(1);
        }
    }
    static const double ident[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    murk_field *f = murk_sparse_end(b, ident, err, sizeof err);
    if (!f) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    murk_field_info fi;
    murk_field_describe(f, &fi);
    if (!fi.sparse) {
        fprintf(stderr, "the 3 %% ball is held dense: sparse.c's rule has changed\n");
        exit(1);
    }
    const murk_sparse *s = f->sparse;
    double floats = 4.0 * (double)fi.active, nodes = (double)s->nnodes * sizeof(murk_sparse_node);
    double top = (double)s->nt[0] * s->nt[1] * s->nt[2] * sizeof *s->top;
    double bricks = (double)fi.bricks * MURK_BRICK_FLOATS * sizeof(float);
    printf("memory: 1024^3 box, %llu active voxels (%.2f %%), their floats %.1f MiB\n", (unsigned long long)fi.active,
           100.0 * (double)fi.active / (1024.0 * 1024.0 * 1024.0), floats / 1048576.0);
    printf("  held %.1f MiB = %.3fx the floats: %zu bricks %.1f MiB (%.3fx: partial bricks at the ball's surface and "
           "each brick's max/min), %zu nodes %.2f MiB, top table %.3f MiB\n", (double)fi.bytes / 1048576.0,
           (double)fi.bytes / floats, fi.bricks, bricks / 1048576.0, bricks / floats, s->nnodes, nodes / 1048576.0,
           top / 1048576.0);
    printf("  goal: <= 1.5x the floats + the stated overhead (nodes and top table, %.2f MiB): %s\n",
           (nodes + top) / 1048576.0, (double)fi.bytes <= 1.5 * floats + nodes + top + 65536.0 ? "met" : "NOT MET");
    murk_field_free(f);
}

/* ---- lookups ----------------------------------------------------------------------------------------- */

/* The sparse copy of a dense grid: its non-zero voxels active, in leaves of the box's index space, held as
 * `hold` says (MURK_HOLD_SMALLER: as murk holds a .vdb of it). */
static murk_field *sparse_copy(const murk_field *d, int hold)
{
    char err[1024];
    int amin[3] = {0, 0, 0}, amax[3] = {d->res[0] - 1, d->res[1] - 1, d->res[2] - 1};
    /* the active box of the non-zero voxels */
    for (int a = 0; a < 3; a++)
        amin[a] = d->res[a], amax[a] = -1;
    for (int z = 0; z < d->res[2]; z++)
        for (int y = 0; y < d->res[1]; y++)
            for (int x = 0; x < d->res[0]; x++)
                if (murk_field_voxel(d, x, y, z) != 0.0f) {
                    int p[3] = {x, y, z};
                    for (int a = 0; a < 3; a++) {
                        amin[a] = p[a] < amin[a] ? p[a] : amin[a];
                        amax[a] = p[a] > amax[a] ? p[a] : amax[a];
                    }
                }
    murk_sparse_build *b = murk_sparse_begin("copy", amin, amax, err, sizeof err);
    float v[512];
    uint64_t mask[8];
    for (int x = 0; b && x < d->res[0]; x += 8)
        for (int y = 0; y < d->res[1]; y += 8)
            for (int z = 0; z < d->res[2]; z += 8) {
                memset(mask, 0, sizeof mask);
                for (int i = 0; i < 512; i++) {
                    int p[3] = {x + (i >> 6), y + ((i >> 3) & 7), z + (i & 7)};
                    v[i] = p[0] < d->res[0] && p[1] < d->res[1] && p[2] < d->res[2] ? murk_field_voxel(d, p[0], p[1], p[2]) : 0;
                    if (v[i] != 0.0f)
                        mask[i >> 6] |= 1ull << (i & 63);
                }
                int o[3] = {x, y, z};
                if (murk_sparse_leaf(b, o, v, mask, err, sizeof err)) {
                    fprintf(stderr, "%s\n", err);
                    exit(1);
                }
            }
    /* index ijk at the dense grid's voxel centre: lo + (ijk + 1/2) * extent / res */
    double map[12] = {0};
    for (int a = 0; a < 3; a++) {
        double h = ((double)murk_v3_get(d->hi, a) - murk_v3_get(d->lo, a)) / d->res[a];
        map[5 * a] = h;
        map[4 * a + 3] = murk_v3_get(d->lo, a) + 0.5 * h;
    }
    murk_field *s = b ? murk_sparse_finish(b, map, hold, err, sizeof err) : NULL;
    if (!s) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    return s;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sum of the field over the points (kept, so that no lookup is optimised away). */
static double sweep(const murk_field *f, const murk_vec3 *p, long n)
{
    double sum = 0.0;
    for (long i = 0; i < n; i++)
        sum += murk_field_eval(f, p[i]);
    return sum;
}

static void time_lookups(const char *label, const murk_field *d, const murk_field *s, const murk_vec3 *p, long n,
                         int rounds)
{
    double *ratio = malloc((size_t)rounds * sizeof *ratio), td = 0, ts = 0;
    for (int r = 0; r < rounds; r++) {
        double t[2], sums[2];
        for (int k = 0; k < 2; k++) {
            int sparse = (r + k) % 2; /* alternate which goes first */
            double t0 = cpu_now();
            sums[sparse] = sweep(sparse ? s : d, p, n);
            t[sparse] = cpu_now() - t0;
        }
        if (!(fabs(sums[0] - sums[1]) <= 1e-5 * fabs(sums[0]))) { /* the same field (the boxes differ by the voxel of
                                                                       zeros, so values by float rounding) */
            fprintf(stderr, "%s: the sparse and dense sums differ (%.17g, %.17g)\n", label, sums[1], sums[0]);
            exit(1);
        }
        ratio[r] = t[1] / t[0];
        td += t[0];
        ts += t[1];
    }
    qsort(ratio, (size_t)rounds, sizeof *ratio, cmp_double);
    printf("  %-34s dense %6.1f ns, as .vdb %6.1f ns per lookup; .vdb / dense median %.3f (min %.3f, max %.3f, %d "
           "rounds)\n", label, 1e9 * td / ((double)n * rounds), 1e9 * ts / ((double)n * rounds), ratio[rounds / 2],
           ratio[0], ratio[rounds - 1], rounds);
    free(ratio);
}

static float checker(int x, int y, int z) { return ((x + y + z) & 1) ? 1.4f : 0.2f; }

int main(int argc, char **argv)
{
    int rounds = argc > 1 ? atoi(argv[1]) : 9;
    long n = argc > 2 ? atol(argv[2]) : 2000000;
    if (rounds < 1 || n < 1) {
        fprintf(stderr, "usage: sparse_grid [rounds] [lookups per round and side]\n");
        return 2;
    }
    double load[3];
    if (getloadavg(load, 3) == 3) /* the machine's load, beside the figures it disturbs */
        printf("load average at the start %.2f %.2f %.2f\n", load[0], load[1], load[2]);
    memory_figure();
    murk_vec3 *uni = malloc((size_t)n * sizeof *uni), *ray = malloc((size_t)n * sizeof *ray);
    murk_field *fields[2];
    fields[0] = murk_field_cloud(murk_v3(-0.6f, 0.05f, -0.6f), murk_v3(0.6f, 1.45f, 0.6f), 256, 7, 2.5f, 5, 0.7f);
    int res[3] = {128, 128, 128};
    float *cv = malloc(128 * 128 * 128 * sizeof *cv);
    for (int z = 0; z < 128; z++)
        for (int y = 0; y < 128; y++)
            for (int x = 0; x < 128; x++)
                cv[((size_t)z * 128 + y) * 128 + x] = checker(x, y, z);
    fields[1] = murk_field_from_voxels(res, murk_v3(0, 0, 0), murk_v3(1, 1, 1), cv);
    free(cv);
    static const char *const names[2] = {"cloud 256^3", "checker 128^3 (all active)"};
    for (int fi = 0; fi < 2; fi++) {
        murk_field *d = fields[fi], *s = sparse_copy(d, MURK_HOLD_SMALLER), *forced = NULL;
        murk_field_info di, si, fo;
        murk_field_describe(d, &di);
        murk_field_describe(s, &si);
        printf("lookups, %s: dense %.1f MiB; as .vdb, held %s (sparse.c's rule): %.1f MiB, its sparse form %.3f MiB "
               "(%zu bytes; dense form %llu bytes) (%llu active voxels)\n", names[fi], (double)di.bytes / 1048576.0,
               si.sparse ? "sparse" : "dense", (double)si.bytes / 1048576.0, (double)si.sparse_bytes / 1048576.0,
               si.sparse_bytes, 4ull * (unsigned long long)s->res[0] * (unsigned long long)s->res[1] *
               (unsigned long long)s->res[2], (unsigned long long)si.active);
        if (!si.sparse) { /* held dense: the sparse form's cost, for the record */
            forced = sparse_copy(d, MURK_HOLD_SPARSE);
            murk_field_describe(forced, &fo);
            printf("  and held sparse (forced): %.1f MiB\n", (double)fo.bytes / 1048576.0);
        }
        murk_rng rng;
        murk_rng_seed(&rng, 42, (uint64_t)fi, 0);
        /* the box inset by one voxel: in the border half-cells the dense grid clamps while the sparse one falls to
         * its voxel of zeros (a fully active grid's border differs there) */
        murk_vec3 vox = murk_v3((d->hi.x - d->lo.x) / (float)d->res[0], (d->hi.y - d->lo.y) / (float)d->res[1],
                                (d->hi.z - d->lo.z) / (float)d->res[2]);
        murk_vec3 lo = murk_add(d->lo, vox), hi = murk_sub(d->hi, vox), e = murk_sub(hi, lo);
        for (long i = 0; i < n; i++)
            uni[i] = murk_add(lo, murk_v3(e.x * murk_rng_float(&rng), e.y * murk_rng_float(&rng), e.z * murk_rng_float(&rng)));
        float step = 0.25f * e.x / (float)d->res[0];
        for (long i = 0; i < n;) { /* random rays from a point in the box, marched until they leave it */
            murk_vec3 o = murk_add(lo, murk_v3(e.x * murk_rng_float(&rng), e.y * murk_rng_float(&rng), e.z * murk_rng_float(&rng)));
            murk_vec3 dir = murk_normalize(murk_v3(murk_rng_float(&rng) - 0.5f, murk_rng_float(&rng) - 0.5f,
                                                   murk_rng_float(&rng) - 0.5f));
            for (float t = 0; i < n; t += step, i++) {
                murk_vec3 q = murk_add(o, murk_mul(dir, t));
                if (q.x < lo.x || q.y < lo.y || q.z < lo.z || q.x > hi.x || q.y > hi.y || q.z > hi.z)
                    break;
                ray[i] = q;
            }
        }
        time_lookups("uniform points", d, s, uni, n, rounds);
        time_lookups("along rays, quarter-voxel steps", d, s, ray, n, rounds);
        if (forced) {
            time_lookups("uniform points, forced sparse", d, forced, uni, n, rounds);
            time_lookups("along rays, forced sparse", d, forced, ray, n, rounds);
            murk_field_free(forced);
        }
        murk_field_free(s);
        murk_field_free(d);
    }
    free(uni);
    free(ray);
    if (getloadavg(load, 3) == 3)
        printf("load average at the end %.2f %.2f %.2f\n", load[0], load[1], load[2]);
    return 0;
}
