/* test_sampler.c — the sampler of murk/math.h (issue 15): the padded Owen-scrambled Sobol points are
 * stratified in every slot, differ per pixel and per seed, integrate a disk faster than independent
 * numbers; the points are bit for bit those of the definition (a slow reference here), whatever fast
 * formulation math.h uses; the independent sampler is the PCG stream in call order; renders with sobol are bitwise
 * identical for 1 and 2 threads, for --time passes and for a checkpoint resumed; render.sampler is
 * read and checked like every scene key. And the solid-angle sampling of rectangular lights
 * (MURK_LIGHT_SOLID_ANGLE, lights.c): a chi-square of the sampled points against the pdf. */
#include "testutil.h"
#include "stat.h"
#include "render/host.h"
#include "image/image.h"
#include "scene/scene.h"

#include "murk/math.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The slots the integrators use (pathtracer.c: camera 0, hero 1, then 5 per scattering event) for the
 * first 12 events, and more: every slot is made the same way. */
enum { NSLOTS = 2 + 5 * 12 };

/* test_sobol_definition's checksum of the points (murk 0.1.0, plugin ABI 1.4, the sampler's first version) */
#define SOBOL_CHECKSUM 0x5f3ec6738da35b7bull

static void point(uint32_t sampler, uint64_t seed, uint64_t pixel, uint32_t index, uint32_t slot, float u[2])
{
    murk_rng r;
    murk_sampler_start(&r, sampler, seed, pixel, index);
    murk_sample_seek(&r, slot);
    murk_sample_2d(&r, u);
}

/* The first 2^k samples of slot s and of the partner of slot p (murk_sample_2d_with; p = s when paired
 * right) as 4-D points, dimensions 0, 1 the slot's point and 2, 3 the partner's: 1 if, over `ndims` of
 * the four from `first`, every elementary interval of volume 2^(t - k) holds 2^t points (a (t, k,
 * ndims)-net; t = 0, ndims 2: one point in each 2^-a x 2^-(k-a) cell of the slot's own point). */
static int joint_net(uint64_t seed, uint64_t pixel, uint32_t s, uint32_t p, int k, int t, int first, int ndims)
{
    uint32_t n = 1u << k;
    float(*x)[4] = malloc(n * sizeof *x);
    uint32_t *count = malloc(n * sizeof *count);
    assert_non_null(x);
    assert_non_null(count);
    for (uint32_t i = 0; i < n; i++) {
        murk_rng r;
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, seed, pixel, i);
        murk_sample_seek(&r, s);
        murk_sample_2d(&r, x[i]);
        murk_sample_2d_with(&r, p, x[i] + 2);
        for (int d = 0; d < 4; d++)
            assert_true(x[i][d] >= 0.0f && x[i][d] < 1.0f);
    }
    int ok = 1, m = k - t; /* bits split over the dimensions: b[0] + ... = m */
    int b[4] = {0, 0, 0, 0};
    for (uint32_t code = 0; ok && code < (1u << (4 * ndims)); code++) { /* every split, up to 15 bits a dim */
        int sum = 0;
        for (int d = 0; d < ndims; d++)
            sum += b[d] = (int)((code >> (4 * d)) & 15u);
        if (sum != m)
            continue;
        memset(count, 0, n * sizeof *count);
        for (uint32_t i = 0; i < n; i++) {
            uint32_t cell = 0;
            for (int d = 0; d < ndims; d++)
                cell = (cell << b[d]) | (uint32_t)(x[i][first + d] * (float)(1u << b[d]));
            count[cell]++;
        }
        for (uint32_t c = 0; c < (1u << m); c++)
            if (count[c] != (1u << t)) {
                fprintf(stderr, "seed %llu pixel %llu slot %u (partner of %u): 2^%d points, %u in a cell of the "
                        "split %d %d %d %d (dims %d..%d), not 2^%d\n", (unsigned long long)seed,
                        (unsigned long long)pixel, s, p, k, count[c], b[0], b[1], b[2], b[3], first,
                        first + ndims - 1, t);
                ok = 0;
                break;
            }
    }
    free(count);
    free(x);
    return ok;
}

static void test_stratified(void **state)
{
    (void)state;
    static const uint64_t seeds[] = {0, 1, 12345};
    static const uint64_t pixels[] = {0, 1, 777, 262143};
    for (size_t s = 0; s < 3; s++)
        for (size_t p = 0; p < 4; p++)
            for (uint32_t slot = 0; slot < NSLOTS; slot++)
                for (int k = 0; k <= 10; k += (k < 6 ? 1 : 4))
                    assert_true(joint_net(seeds[s], pixels[p], slot, slot, k, 0, 0, 2));
    /* 1-D slots give the first coordinate of the 2-D point of the same slot */
    for (uint32_t i = 0; i < 64; i++) {
        murk_rng r;
        float u[2];
        point(MURK_SAMPLER_SOBOL, 3, 9, i, 7, u);
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, 3, 9, i);
        murk_sample_seek(&r, 7);
        assert_true(murk_sample_1d(&r) == u[0]);
    }
}

/* Correlation of u[c] between two streams over n samples, for slot `slot`. */
static double correlation(uint64_t s1, uint64_t p1, uint32_t slot1, uint64_t s2, uint64_t p2, uint32_t slot2, int c,
                          uint32_t n, uint32_t *same)
{
    double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
    *same = 0;
    for (uint32_t i = 0; i < n; i++) {
        float a[2], b[2];
        point(MURK_SAMPLER_SOBOL, s1, p1, i, slot1, a);
        point(MURK_SAMPLER_SOBOL, s2, p2, i, slot2, b);
        *same += a[0] == b[0] && a[1] == b[1];
        sa += a[c], sb += b[c], sab += (double)a[c] * b[c], saa += (double)a[c] * a[c], sbb += (double)b[c] * b[c];
    }
    double cov = sab / n - (sa / n) * (sb / n);
    return cov / sqrt((saa / n - (sa / n) * (sa / n)) * (sbb / n - (sb / n) * (sb / n)));
}

/* Neighbouring pixels, seeds and slots see different, uncorrelated sequences: |corr| within STAT_Z standard
 * errors (1 / sqrt(n) for independent uniforms) and no point shared. Must-fail: a mutant sequence that
 * repeats the other's number at every fifth sample (correlation 0.2). */
static void test_decorrelated(void **state)
{
    (void)state;
    const uint32_t n = 4096;
    const double tol = STAT_Z / sqrt((double)n);
    struct { uint64_t s1, p1, s2, p2; uint32_t slot1, slot2; const char *what; } cases[] = {
        {0, 100, 0, 101, 0, 0, "neighbouring pixels"}, {0, 100, 1, 100, 0, 0, "seeds 0 and 1"},
        {5, 7, 5, 7 + 512, 4, 4, "pixels a row apart"}, {5, 7, 5, 7, 3, 4, "slots 3 and 4"},
        {9, 0, 10, 1, 2, 2, "seed and pixel both + 1"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        for (int c = 0; c < 2; c++) {
            uint32_t same;
            double r = correlation(cases[i].s1, cases[i].p1, cases[i].slot1, cases[i].s2, cases[i].p2, cases[i].slot2, c,
                                   n, &same);
            printf("%-26s coordinate %d: correlation %+.4f (limit %.4f), %u shared points\n", cases[i].what, c, r, tol,
                   same);
            assert_true(stat_z_ok(r, 1.0 / sqrt((double)n), 0.0, 0.0));
            assert_int_equal(same, 0);
        }
    double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
    for (uint32_t i = 0; i < n; i++) {
        float a[2], b[2];
        point(MURK_SAMPLER_SOBOL, 0, 100, i, 0, a);
        point(MURK_SAMPLER_SOBOL, 0, 101, i, 0, b);
        double x = a[0], y = i % 5 == 0 ? a[0] : b[0];
        sa += x, sb += y, sab += x * y, saa += x * x, sbb += y * y;
    }
    double r = (sab / n - sa / n * sb / n) / sqrt((saa / n - sa / n * sa / n) * (sbb / n - sb / n * sb / n));
    double z = r * sqrt((double)n);
    printf("mutant (every fifth number repeated): correlation %+.4f (limit %.4f)\n", r, tol);
    assert_true(stat_must_fail("neighbouring pixels, every fifth number shared", fabs(z) > STAT_Z, z));
}

/* The Sobol points exactly as murk/math.h's comment defines them, computed here bit by bit with no
 * shortcut (bit loops for the reversals, Sobol dimension 1 from its direction numbers), against
 * murk_sample_1d/2d: any faster formulation of the inline sampler must give the same bits. And a
 * checksum of the points, so that the definition itself cannot drift (images are pinned by it). */
static uint64_t ref_mix(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

static uint32_t ref_rev(uint32_t x)
{
    uint32_t y = 0;
    for (int b = 0; b < 32; b++)
        y |= ((x >> b) & 1u) << (31 - b);
    return y;
}

static uint32_t ref_sobol1(uint32_t i) /* the generator matrix's columns v_j = v_(j-1) ^ (v_(j-1) >> 1) */
{
    uint32_t v = 1u << 31, x = 0;
    for (int j = 0; j < 32; j++, v ^= v >> 1)
        if ((i >> j) & 1u)
            x ^= v;
    return x;
}

/* (the Laine-Karras hash is math.h's own, murk_lk_hash_: the checksum pins its constants) */
static float ref_u24(uint32_t x) { return (float)(x >> 8) / 16777216.0f; }

/* Slot `slot` of sample `index` of `pixel`: u[0] (a 1-D slot's number) and u[1]. */
static void ref_point(uint64_t seed, uint64_t pixel, uint32_t index, uint32_t slot, float u[2])
{
    uint64_t scramble = ref_mix(ref_mix(seed ^ 0x5851f42d4c957f2dull) ^ pixel);
    uint64_t h = ref_mix(scramble + 0x9e3779b97f4a7c15ull * ((uint64_t)slot + 1u));
    uint32_t i = ref_rev(murk_lk_hash_(ref_rev(index), (uint32_t)h)); /* Owen-scrambled index */
    u[0] = ref_u24(ref_rev(murk_lk_hash_(ref_rev(ref_rev(i)), (uint32_t)(h >> 32)))); /* Sobol 0 is the reversal */
    u[1] = ref_u24(ref_rev(murk_lk_hash_(ref_rev(ref_sobol1(i)), (uint32_t)ref_mix(h))));
}

static void test_sobol_definition(void **state)
{
    (void)state;
    uint64_t sum = 0xcbf29ce484222325ull; /* FNV-1a over the bits of every point */
    int n = 0;
    for (uint64_t seed = 0; seed < 3; seed++)
        for (uint64_t pixel = 0; pixel < 300; pixel += 7)
            for (uint32_t index = 0; index < 300; index += (index < 64 ? 1 : 61)) {
                murk_rng r1, r2;
                murk_sampler_start(&r1, MURK_SAMPLER_SOBOL, seed, pixel, index * 2654435761u >> (index < 64 ? 26 : 0));
                r2 = r1;
                for (uint32_t slot = 0; slot < 24; slot++) {
                    float u[2], want[2];
                    murk_sample_2d(&r1, u);
                    ref_point(seed, pixel, r1.index, slot, want);
                    assert_memory_equal(u, want, sizeof u);
                    float v = murk_sample_1d(&r2);
                    assert_memory_equal(&v, want, sizeof v);
                    uint32_t bits[2];
                    memcpy(bits, u, sizeof bits);
                    for (int c = 0; c < 2; c++)
                        sum = (sum ^ bits[c]) * 0x100000001b3ull;
                    n++;
                }
            }
    printf("sobol definition: %d points equal to the reference, checksum %016llx\n", n, (unsigned long long)sum);
    assert_true(sum == SOBOL_CHECKSUM);
}

/* ---- murk_sample_2d_with: a slot's partner, Sobol dimensions 2 and 3 of the slot's shuffled index ---- */

/* Joe and Kuo's direction numbers from their primitive polynomial (degree deg, inner coefficients a)
 * and initial m: the generator matrix's columns, most significant bit first, by the recurrence. */
static void ref_directions(int deg, uint32_t a, const uint32_t *m0, uint32_t v[32])
{
    uint32_t m[32];
    for (int k = 0; k < 32; k++) {
        if (k < deg) {
            m[k] = m0[k];
        } else {
            m[k] = m[k - deg] ^ (m[k - deg] << deg);
            for (int j = 1; j < deg; j++)
                if ((a >> (deg - 1 - j)) & 1u)
                    m[k] ^= m[k - j] << j;
        }
        v[k] = m[k] << (31 - k);
    }
}

static uint32_t ref_sobol(const uint32_t v[32], uint32_t i)
{
    uint32_t x = 0;
    for (int k = 0; k < 32; k++)
        if ((i >> k) & 1u)
            x ^= v[k];
    return x;
}

/* The partner of slot `with` for sample `index` of `pixel`, as murk/math.h's comment defines it. */
static void ref_partner(uint64_t seed, uint64_t pixel, uint32_t index, uint32_t with, float u[2])
{
    static const uint32_t m2[] = {1, 3}, m3[] = {1, 3, 1};
    uint32_t v2[32], v3[32];
    ref_directions(2, 1, m2, v2); /* x^2 + x + 1 */
    ref_directions(3, 1, m3, v3); /* x^3 + x + 1 */
    uint64_t scramble = ref_mix(ref_mix(seed ^ 0x5851f42d4c957f2dull) ^ pixel);
    uint64_t h = ref_mix(scramble + 0x9e3779b97f4a7c15ull * ((uint64_t)with + 1u));
    uint32_t i = ref_rev(murk_lk_hash_(ref_rev(index), (uint32_t)h)); /* the slot's own shuffle */
    uint64_t g = ref_mix(h ^ 0xd1b54a32d192ed03ull);
    u[0] = ref_u24(ref_rev(murk_lk_hash_(ref_rev(ref_sobol(v2, i)), (uint32_t)g)));
    u[1] = ref_u24(ref_rev(murk_lk_hash_(ref_rev(ref_sobol(v3, i)), (uint32_t)(g >> 32))));
}

/* The fast partner is the definition's, bit for bit; it takes a slot's place (the counter moves on);
 * with the independent sampler it is murk_sample_2d. */
static void test_partner_definition(void **state)
{
    (void)state;
    int n = 0;
    for (uint64_t seed = 0; seed < 3; seed++)
        for (uint64_t pixel = 0; pixel < 300; pixel += 37)
            for (uint32_t index = 0; index < 200; index += (index < 64 ? 1 : 45))
                for (uint32_t with = 0; with < 40; with += 3) {
                    murk_rng r;
                    float u[2], want[2];
                    murk_sampler_start(&r, MURK_SAMPLER_SOBOL, seed, pixel, index);
                    murk_sample_seek(&r, 500);
                    murk_sample_2d_with(&r, with, u);
                    assert_int_equal(r.dim, 501);
                    ref_partner(seed, pixel, index, with, want);
                    assert_memory_equal(u, want, sizeof u);
                    n++;
                }
    murk_rng a, b;
    float ua[2], ub[2];
    murk_sampler_start(&a, MURK_SAMPLER_INDEPENDENT, 4, 5, 6);
    b = a;
    murk_sample_2d_with(&a, 3, ua);
    murk_sample_2d(&b, ub);
    assert_memory_equal(ua, ub, sizeof ua);
    printf("partner definition: %d points equal to the reference\n", n);
}

/* A slot and its partner are one 4-D Sobol point: their first 2^k samples form a (3, k, 4)-net (the
 * first four Sobol dimensions' t-value), the partner alone a (2, k, 2)-net. Must-fail: the partner of
 * another slot (another shuffle of the index) is no 4-D net with the slot (two independent slots). */
static void test_partner_stratified(void **state)
{
    (void)state;
    static const uint64_t seeds[] = {0, 12345};
    static const uint64_t pixels[] = {0, 777, 262143};
    for (size_t si = 0; si < 2; si++)
        for (size_t pi = 0; pi < 3; pi++)
            for (uint32_t slot = 0; slot < NSLOTS; slot += 5)
                for (int k = 3; k <= 10; k++) {
                    assert_true(joint_net(seeds[si], pixels[pi], slot, slot, k, 3, 0, 4));
                    assert_true(joint_net(seeds[si], pixels[pi], slot, slot, k, 2, 2, 2));
                }
    int caught = 0;
    for (int k = 3; k <= 10; k++)
        caught += !joint_net(0, 777, 7, 12, k, 3, 0, 4);
    printf("partner of another slot: not a (3, k, 4)-net for %d of 8 sample counts 2^3..2^10\n", caught);
    assert_true(stat_must_fail("the partner of another slot is jointly stratified with this one", caught > 0,
                               INFINITY)); /* deterministic: no chance to pass */
}

/* The independent sampler (and a stream murk_rng_seed made) is the PCG stream in call order. */
static void test_independent_is_pcg(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 16; i++) {
        murk_rng a, b, c;
        murk_sampler_start(&a, MURK_SAMPLER_INDEPENDENT, 4, 5, i);
        murk_rng_seed(&b, 4, 5, i);
        murk_rng_seed(&c, 4, 5, i);
        float u[2];
        murk_sample_seek(&a, 9);
        murk_sample_2d(&a, u);
        assert_true(u[0] == murk_rng_float(&b) && u[1] == murk_rng_float(&b));
        assert_true(murk_sample_1d(&a) == murk_rng_float(&b));
        murk_rng_seed(&b, 4, 5, i);
        murk_sample_2d(&c, u); /* an rng murk_rng_seed made draws independently too */
        assert_true(u[0] == murk_rng_float(&b) && u[1] == murk_rng_float(&b));
        assert_true(murk_sample_1d(&c) == murk_rng_float(&b));
    }
}

/* Root-mean-square error of the disk-area estimate with 2^k points over `reps` pixels (replicates),
 * k = 0..kmax, and the standard error of each log2 RMSE (from the spread of the squared errors). */
static void disk_rmse(uint32_t sampler, int kmax, int reps, double *log2_rmse, double *se)
{
    const double r2 = 0.4 * 0.4, truth = M_PI * r2;
    uint32_t n = 1u << kmax;
    double *m = calloc((size_t)kmax + 1, sizeof *m), *m2 = calloc((size_t)kmax + 1, sizeof *m2);
    assert_non_null(m);
    assert_non_null(m2);
    for (int rep = 0; rep < reps; rep++) {
        double hits = 0;
        for (uint32_t i = 0; i < n; i++) {
            float u[2];
            point(sampler, 2026, (uint64_t)rep, i, 3, u);
            double dx = u[0] - 0.5, dy = u[1] - 0.5;
            hits += dx * dx + dy * dy < r2;
            if (((i + 1) & i) == 0) { /* i + 1 is a power of two */
                int k = 0;
                while ((1u << k) < i + 1)
                    k++;
                double e = hits / (double)(i + 1) - truth;
                m[k] += e * e, m2[k] += e * e * e * e;
            }
        }
    }
    for (int k = 0; k <= kmax; k++) {
        double mse = m[k] / reps, var = m2[k] / reps - mse * mse;
        log2_rmse[k] = 0.5 * log2(mse);
        se[k] = 0.5 * sqrt(var / reps) / mse / log(2.0);
    }
    free(m);
    free(m2);
}

/* Least-squares slope of y over k = k0..k1 and its standard error from the per-point errors. */
static double slope(const double *y, const double *se, int k0, int k1, double *slope_se)
{
    double kbar = 0, ybar = 0, sxx = 0, sxy = 0, var = 0;
    int n = k1 - k0 + 1;
    for (int k = k0; k <= k1; k++)
        kbar += k, ybar += y[k];
    kbar /= n, ybar /= n;
    for (int k = k0; k <= k1; k++)
        sxx += (k - kbar) * (k - kbar), sxy += (k - kbar) * (y[k] - ybar);
    for (int k = k0; k <= k1; k++)
        var += (k - kbar) * (k - kbar) * se[k] * se[k];
    *slope_se = sqrt(var) / sxx;
    return sxy / sxx;
}

/* The disk's area (a discontinuous integrand): independent numbers converge as N^-1/2, scrambled Sobol
 * as N^-3/4 (variance N^-3/2, Owen 1997). The fitted slope must lie STAT_Z standard errors below -1/2, and
 * at N = 1024 the RMSE must be below independent's by more than STAT_Z standard errors; independent
 * numbers' slope within STAT_Z standard errors of -1/2 (the harness sees Monte Carlo's rate). The
 * standard errors treat the powers of two as independent, which they are not (each N's points hold the
 * smaller N's): the slopes' true spread is somewhat larger than printed. */
static void test_disk_convergence(void **state)
{
    (void)state;
    enum { KMAX = 10, REPS = 1024 };
    double ys[KMAX + 1], ses[KMAX + 1], yi[KMAX + 1], sei[KMAX + 1], ss, si;
    disk_rmse(MURK_SAMPLER_SOBOL, KMAX, REPS, ys, ses);
    disk_rmse(MURK_SAMPLER_INDEPENDENT, KMAX, REPS, yi, sei);
    double bs = slope(ys, ses, 4, KMAX, &ss), bi = slope(yi, sei, 4, KMAX, &si);
    printf("disk area RMSE slope over N = 16..1024: sobol %.3f +- %.3f, independent %.3f +- %.3f\n", bs, ss, bi, si);
    printf("RMSE at N = 1024: sobol %.3g, independent %.3g (ratio %.1f)\n", exp2(ys[KMAX]), exp2(yi[KMAX]),
           exp2(yi[KMAX] - ys[KMAX]));
    assert_true(stat_z_ok(bi, si, -0.5, 0.0)); /* the harness sees Monte Carlo's rate */
    stat_count(2, stat_tail2(STAT_Z) / 2.0);   /* one-sided: */
    assert_true(bs + STAT_Z * ss < -0.5);      /* measurably faster than it */
    assert_true(ys[KMAX] + STAT_Z * hypot(ses[KMAX], sei[KMAX]) < yi[KMAX]);
}

/* ---- renders ------------------------------------------------------------------------------- */

static void render_ok(const char *out, const char *const *extra)
{
    const char *args[] = {"render", src_path("scenes/cornell_smoke.yaml"), "-o", out, "--quiet",
                          "--set", "render.resolution=[40,32]", "--set", "render.sampler=sobol", NULL};
    run_murk_ok(args, extra);
}

static const char *out_path(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmp_dir(), name);
    return buf[k];
}

/* cornell_smoke (surfaces, a cloud, NEE through it) with sobol: 1 and 2 threads, one pass and --time's
 * passes, a checkpoint at 3 spp resumed to 8: every pixel bitwise the same. And independent differs. */
static void test_render_bitwise(void **state)
{
    (void)state;
    const char *ref = out_path("one.exr");
    const char *one[] = {"--threads", "1", "--spp", "8", NULL};
    render_ok(ref, one);
    const char *two[] = {"--threads", "2", "--spp", "8", NULL};
    render_ok(out_path("two.exr"), two);
    assert_true(same_pixels(ref, out_path("two.exr")));
    const char *timed[] = {"--threads", "2", "--spp", "8", "--time", "600", NULL}; /* passes of 1, then more */
    render_ok(out_path("timed.exr"), timed);
    assert_true(same_pixels(ref, out_path("timed.exr")));
    const char *ck = out_path("ck");
    const char *part[] = {"--threads", "2", "--spp", "3", "--checkpoint", ck, "--every", "0", NULL};
    render_ok(out_path("part.exr"), part);
    const char *rest[] = {"--threads", "2", "--spp", "8", "--resume", ck, NULL};
    render_ok(out_path("resumed.exr"), rest);
    assert_true(same_pixels(ref, out_path("resumed.exr")));
    const char *indep[] = {"--threads", "2", "--spp", "8", "--set", "render.sampler=independent", NULL};
    render_ok(out_path("indep.exr"), indep);
    assert_false(same_pixels(ref, out_path("indep.exr")));
}

static void test_scene_key(void **state)
{
    (void)state;
    const char *scene = write_tmp("bad_sampler.yaml", "murk: 1\n"
                                                      "render: { resolution: [8, 8], sampler: halton }\n"
                                                      "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }\n");
    char *log = NULL;
    int rc = run_murk(&log, "render", scene, "-o", out_path("bad.exr"), "--quiet", (char *)NULL);
    assert_int_equal(rc, 1);
    assert_contains(log, "bad_sampler.yaml:2:");
    assert_contains(log, "render.sampler must be one of independent|sobol, got 'halton'");
    free(log);
    rc = run_murk(&log, "render", scene, "-o", out_path("bad.exr"), "--quiet", "--set", "render.sampler=[1]", (char *)NULL);
    assert_int_equal(rc, 1);
    assert_contains(log, "render.sampler");
    free(log);
}


/* ---- light sampling ------------------------------------------------------------------------ */

/* MURK_LIGHT_SOLID_ANGLE on a tilted rectangular light seen from a far, a near, a side and two grazing
 * points:
 * 200k samples binned 16 x 16 over the rectangle's (a, b) coordinates against the expected counts
 * N * integral over the bin of pdf(w) dw = N * sum pdf cos_l / d^2 dA (32 x 32 midpoints per bin);
 * p >= STAT_P (stat.h), the expected counts sum to N (the pdf integrates to 1) and every sample's pdf
 * equals light_pdf_with() at its point. Must-fail: the same samples against area sampling's pdf. */
static void test_rect_light_chi2(void **state)
{
    (void)state;
    const char *text = "murk: 1\n"
                       "render: { resolution: [8, 8] }\n"
                       "camera: { from: [0, 1, 4], at: [0, 1, 0], up: [0, 1, 0], fov: 30 }\n"
                       "materials: { m: { type: diffuse, albedo: 0.5 } }\n"
                       "shapes:\n"
                       "  - { type: quad, center: [0.3, 2, -0.2], u: [0.4, 0.1, 0], v: [0, 0, 0.3], material: m, emission: [4, 3, 2] }\n";
    char err[512];
    murk_scene *s = murk_scene_load(write_tmp("rect.yaml", text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    const murk_host *h = murk_host_table();
    assert_true(MURK_HAS(h->size, murk_host, light_pdf_with));
    const murk_vec3 c = murk_v3(0.3f, 2.0f, -0.2f), u = murk_v3(0.4f, 0.1f, 0.0f), v = murk_v3(0.0f, 0.0f, 0.3f);
    const murk_vec3 p0 = murk_sub(murk_sub(c, u), v), ex = murk_mul(u, 2.0f), ey = murk_mul(v, 2.0f);
    const murk_vec3 n = murk_normalize(murk_cross(ex, ey));
    const double area = murk_length(murk_cross(ex, ey));
    /* offsets from the centre along (u, v, n): far below, near, to the side, and two grazing ones */
    static const float pts[][3] = {{-0.3f, 0.2f, 1.5f}, {0.1f, 0.1f, 0.15f}, {1.0f, 0.5f, 0.3f},
                                   {1.2f, 0.0f, 0.01f}, {0.1f, 0.8f, 0.02f}};
    enum { NB = 16, SUB = 32, N = 200000 };
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        murk_vec3 p = murk_add(c, murk_add(murk_add(murk_mul(murk_normalize(u), pts[k][0]), murk_mul(murk_normalize(v), pts[k][1])),
                                           murk_mul(n, pts[k][2])));
        assert_true(murk_dot(murk_sub(p, p0), n) > 0.0f); /* on the emitting side */
        static double obs[NB * NB], expct[NB * NB], wrong[NB * NB];
        memset(obs, 0, sizeof obs);
        memset(expct, 0, sizeof expct);
        memset(wrong, 0, sizeof wrong);
        murk_rng rng;
        murk_rng_seed(&rng, 15, k, 0);
        long bad_pdf = 0;
        for (long i = 0; i < N; i++) {
            float uu[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
            murk_light_sample ls;
            assert_true(h->sample_light_with(s, p, uu, MURK_LIGHT_SOLID_ANGLE, &ls));
            murk_vec3 q = murk_madd(p, ls.wi, ls.dist), d = murk_sub(q, p0);
            double a = murk_dot(d, ex) / murk_dot(ex, ex), b = murk_dot(d, ey) / murk_dot(ey, ey);
            assert_true(a > -1e-4 && a < 1.0 + 1e-4 && b > -1e-4 && b < 1.0 + 1e-4);
            int ia = (int)(a * NB), ib = (int)(b * NB);
            ia = ia < 0 ? 0 : (ia >= NB ? NB - 1 : ia);
            ib = ib < 0 ? 0 : (ib >= NB ? NB - 1 : ib);
            obs[ia * NB + ib] += 1.0;
            murk_hit hit = {0};
            hit.p = q;
            hit.light = 0;
            float pdf = h->light_pdf_with(s, p, &hit, MURK_LIGHT_SOLID_ANGLE);
            bad_pdf += fabsf(pdf - ls.pdf) > 1e-4f * ls.pdf;
        }
        double total = 0.0;
        for (int ia = 0; ia < NB * SUB; ia++)
            for (int ib = 0; ib < NB * SUB; ib++) {
                double a = (ia + 0.5) / (NB * SUB), b = (ib + 0.5) / (NB * SUB);
                murk_vec3 q = murk_add(p0, murk_add(murk_mul(ex, (float)a), murk_mul(ey, (float)b)));
                murk_vec3 d = murk_sub(q, p);
                double d2 = murk_dot(d, d), cosl = -murk_dot(n, d) / sqrt(d2);
                murk_hit hit = {0};
                hit.p = q;
                hit.light = 1;
                double dA = area / ((double)NB * SUB * NB * SUB);
                double e = h->light_pdf_with(s, p, &hit, MURK_LIGHT_SOLID_ANGLE) * cosl / d2 * dA;
                expct[(ia / SUB) * NB + ib / SUB] += N * e;
                wrong[(ia / SUB) * NB + ib / SUB] += N * h->light_pdf_with(s, p, &hit, MURK_LIGHT_AREA) * cosl / d2 * dA;
                total += e;
            }
        int dof;
        double pv = chi2_test(obs, expct, NB * NB, 5.0, &dof);
        printf("rectangle light from (%.2f, %.2f, %.2f): chi2 p = %.4f (%d dof), integral of pdf %.5f, "
               "%ld pdf mismatches\n", p.x, p.y, p.z, pv, dof, total, bad_pdf);
        assert_true(stat_chi2_ok(pv));
        assert_true(fabs(total - 1.0) < 2e-3);
        char label[96];
        snprintf(label, sizeof label, "rectangle light point %zu: against area sampling's pdf", k);
        assert_true(stat_must_fail_chi2(label, chi2_test(obs, wrong, NB * NB, 5.0, &dof)));
        assert_int_equal(bad_pdf, 0);
    }
    murk_scene_free(s);
}

/* ---- the expected image ------------------------------------------------------------------------ */

/* The sobol sampler with solid-angle light sampling against (independent, area), murk's estimators
 * before both: two estimators of the same image, block-wise z-test over 8 independent seeds each
 * (img_stack_agree) on the Cornell box, cornell_smoke's cloud and a constant chromatic medium (suite
 * 'long'); must-fail: one block brighter by 10 of its standard errors (the resolution, printed). */
static void long_same_image(void **state)
{
    (void)state;
    static const char *const medium[] = {"--set", "media.smoke.density={constant: 1}", "--set",
                                         "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "--set",
                                         "media.smoke.sigma_s=[1.2, 0.8, 0.4]", NULL};
    struct { const char *label, *scene, *spp; const char *const *extra; } cases[] = {
        {"cornell", "scenes/cornell.yaml", "256", NULL},
        {"cornell_smoke", "scenes/cornell_smoke.yaml", "64", NULL},
        {"constant chromatic medium", "scenes/cornell_smoke.yaml", "64", medium},
    };
    int nfail = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *a_args[24] = {"--set", "render.resolution=[32,32]", "--spp", cases[i].spp}, *b_args[24];
        size_t n = 4;
        for (size_t k = 0; cases[i].extra && cases[i].extra[k]; k++)
            a_args[n++] = cases[i].extra[k];
        memcpy(b_args, a_args, sizeof a_args);
        b_args[n] = "--set", b_args[n + 1] = "render.sampler=independent";
        b_args[n + 2] = "--set", b_args[n + 3] = "integrator.light_sampling=area", b_args[n + 4] = NULL;
        a_args[n] = "--set", a_args[n + 1] = "integrator.light_sampling=solid_angle", a_args[n + 2] = NULL;
        img_stack a, b;
        img_stack_render(&a, src_path(cases[i].scene), "new.exr", 8, 10, a_args);
        img_stack_render(&b, src_path(cases[i].scene), "old.exr", 8, 1000, b_args);
        nfail += !img_stack_agree(cases[i].label, &a, &b, 4);
        nfail += !img_stack_must_differ_block(cases[i].label, &a, &b, 4, 0.0);
        img_stack_free(&a);
        img_stack_free(&b);
    }
    assert_int_equal(nfail, 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stratified),
        cmocka_unit_test(test_decorrelated),
        cmocka_unit_test(test_independent_is_pcg),
        cmocka_unit_test(test_sobol_definition),
        cmocka_unit_test(test_partner_definition),
        cmocka_unit_test(test_partner_stratified),
        cmocka_unit_test(test_disk_convergence),
        cmocka_unit_test(test_rect_light_chi2),
        cmocka_unit_test(test_scene_key),
        cmocka_unit_test(test_render_bitwise),
        cmocka_unit_test(long_same_image),
    };
    return STAT_RUN(tests, argc, argv);
}
