/* test_flight_choice.c — what test_flight.c's checks did not see of stratified free flights
 * (murk/tracking.h: murk_flight_float, murk_flight_choice, murk_collisions_choice): the choice at a
 * flight's FIRST collision, and the first flight's distance in heterogeneous media. Every tracker in
 * plugins/media/, and the SDK's example_delta, is driven through its sample() as the path tracer calls
 * it: render.sampler sobol, the rng sought to one flight slot, over a pixel's first 2^k samples.
 *
 *   first choice    a constant grey medium at majorant_factor 1.5: the first tentative collision lies
 *                   where the slot's first coordinate puts it (no flight may end before it) and is
 *                   real with probability q = 2/3 (spectral: absorbed with 1/6). The slot's second
 *                   coordinate is one per interval of 2^-k and every tracker takes a branch when that
 *                   number is below the branch's cumulative probability (a prefix [0, p)), so over 2^k
 *                   samples the count of first collisions that were real (absorbed) is round(p 2^k)
 *                   within +-1: a deterministic bound, for k = 4, 6, 8, 10 x 3 pixels x 3 slots. A
 *                   tracker that draws that choice from the PCG stream (murk_rng_float) gives binomial
 *                   counts instead; the same counts made from PCG numbers here must fail the bound in
 *                   at least half the 36 cases (the test's own power check: 21 fail). With
 *                   murk_rng_float in place of murk_collisions_choice / murk_flight_choice each tracker
 *                   failed 21 of the 36 cases (spectral 33). decomposition with control 0: its first
 *                   draw is then the residual's, whose choice is the slot's.
 *   first distance  three grey heterogeneous media — cornell_smoke's procedural cloud (sigma_t 18.5,
 *                   majorant cells mostly above the density: the first flight crosses cells and meets
 *                   null collisions), a dense smooth grid (0.6 .. 1.4, where decomposition's first draw
 *                   is its first cell's control distance) and test_media.c's plateau (constant cells
 *                   first: spectral_mis closed_form takes them) — 3 rays each. The distance T of a
 *                   flight's first real collision has the closed form P(T > t) = exp(-sigma_t D(t))
 *                   (D: the density's integral along the ray, by quadrature), so
 *                   Y = 1 - exp(-sigma_t D(T)) (1 - exp(-sigma_t D(tmax)) if the flight passes) is
 *                   min(V, Ymax) with V uniform: mean Ymax - Ymax^2 / 2 and P(Y < c) = c. Per tracker,
 *                   medium and ray, 128 pixels (independent scrambles) x 1024 samples, with sobol and
 *                   with independent numbers: those five statistics within STAT_Z se of the closed form (a
 *                   t with 127 degrees of freedom: counted with its tail, stat_tail2_t), the
 *                   se from the spread of the 128 pixel means (the samples within a pixel are not
 *                   independent), at least one sample's worth (1 / 131072: where the first coordinate
 *                   alone decides, the pixel counts are exact and the spread is 0). Stratification
 *                   makes the se small enough to see a first flight 5% short, which test_flight.c's
 *                   images do not on the cloud: with the stratified first draw x 0.95 in
 *                   murk_collisions_next, the trackers that use it failed with max |z| 7-14 per ray on
 *                   the cloud, 95-111 on the grid, 457-536 on the plateau; in decomposition_depth,
 *                   decomposition 5.3-10.6 on the cloud, 42-51 on the grid, 339-414 on the plateau
 *                   (before decomposition carried its first number over cells, its slot drew only the
 *                   first residual distance in the cloud's first non-empty cell: |z| < 1.4); in
 *                   spectral_mis's closed form, closed_form: true 429-470 on the plateau. Every other
 *                   figure stayed within |z| 2.4. The must-fail cases run that mutant on the tracker's
 *                   own samples: each flight's distance scaled by 0.99 (sobol), per tracker and medium. */
#include "testutil.h"
#include "mediatest.h"
#include "stat.h"

#include "murk/math.h"
#include "murk/tracking.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* and the SDK's example_delta (tests/fixtures, as built in-tree), which docs/plugins.md and its header
 * promise draws its choices as murk's trackers do */
#define NTRACKERS 6
static const char *const TRACKERS[NTRACKERS] = {"delta", "decomposition", "spectral", "spectral_mis",
                                                "naive_spectral", "example_delta"};

/* The slots and pixels of test_flight.c's test_stratified: the path tracer's first flight slot, one of
 * a later bounce, and a low one. */
static const uint32_t SLOTS[] = {0x20000000u, 0x20000000u + 3u * 1024u + 1u, 7u};
#define NSLOTS 3
#define NPIXELS 3

/* ---- the first collision's choice ------------------------------------------------------------ */

#define FACTOR 1.5 /* majorant_factor: the first tentative collision is real with probability 1 / FACTOR */

/* Counts over samples 0 .. 2^k - 1 of (seed, pixel) at `slot`: how many flights had their first
 * tentative collision real (*real) and absorbed there (*absorbed: weight 0), and how many ended before
 * it (*early: never, if the first distance is the slot's). mu: the majorant rate. */
static void first_choices(const murk_medium *m, uint64_t seed, uint64_t pixel, uint32_t slot, int k, double mu,
                          int *real, int *absorbed, int *early)
{
    murk_ray ray = {{0.5f, 0.5f, 0}, {0, 0, 1}, 0.0f, INFINITY};
    *real = *absorbed = *early = 0;
    for (int i = 0; i < 1 << k; i++) {
        murk_rng r;
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, seed, pixel, (uint32_t)i);
        murk_sample_seek(&r, slot);
        murk_rng peek = r;
        float u[2];
        murk_sample_2d(&peek, u); /* the slot's point: u[0] gives the first tentative collision */
        double t1 = -log1p(-(double)u[0]) / mu;
        murk_path_ctx ctx = {.hero = i % 3, .beta = {{1, 1, 1}}};
        murk_medium_event ev;
        m->vt->sample(m->self, &ray, &ctx, &r, &ev);
        assert_true(ev.scattered && isfinite(ev.t));
        if (ev.t < t1 * (1.0 - 1e-5) - 1e-6) {
            (*early)++;
        } else if (ev.t <= t1 * (1.0 + 1e-5) + 1e-6) {
            (*real)++;
            *absorbed += murk_rgb_is_black(ev.weight);
        }
    }
}

/* The count of real first collisions from PCG numbers, as a tracker that drew the first choice with
 * murk_rng_float would make it: what the bound must reject. */
static int pcg_real(uint64_t seed, uint64_t pixel, int k, double q)
{
    int real = 0;
    for (int i = 0; i < 1 << k; i++) {
        murk_rng r;
        murk_sampler_start(&r, MURK_SAMPLER_SOBOL, seed, pixel, (uint32_t)i);
        real += murk_rng_float(&r) < q;
    }
    return real;
}

/* |count - round(p n)| <= 1 */
static int near(int count, double p, int n) { return abs(count - (int)lround(p * n)) <= 1; }

static void test_first_choice(void **state)
{
    (void)state;
    char keys[NTRACKERS][64];
    mt_spec ms[NTRACKERS];
    for (int i = 0; i < NTRACKERS; i++) {
        snprintf(keys[i], sizeof keys[i], "type: %s%s", TRACKERS[i], i == 1 ? ", control: 0" : "");
        ms[i] = (mt_spec){TRACKERS[i], keys[i], 0};
    }
    char common[256];
    snprintf(common, sizeof common, "density: { constant: 1 }, majorant_factor: %g, %s", FACTOR, MT_GREY_KEYS);
    murk_scene *s = mt_load_media("choice.yaml", common, "", ms, NTRACKERS);
    const double st = mt_sigma_t[0][0], mu = FACTOR * st, q = 1.0 / FACTOR, qa = mt_sigma_a[0][0] / mu;
    int ncases = 0, pcg_bad = 0, nfail = 0;
    for (int i = 0; i < NTRACKERS; i++) {
        int bad = 0, early = 0, worst = 0;
        char worst_line[160] = "";
        ncases = 0;
        for (int k = 4; k <= 10; k += 2)
            for (uint64_t pixel = 0; pixel < NPIXELS; pixel++)
                for (int sl = 0; sl < NSLOTS; sl++, ncases++) {
                    int n = 1 << k, nr, na, ne;
                    first_choices(&s->media[i].m, 5u + pixel, pixel * 977u, SLOTS[sl], k, mu, &nr, &na, &ne);
                    int spectral = !strcmp(TRACKERS[i], "spectral"); /* the only one that absorbs */
                    int ok = near(nr, q, n) && near(na, spectral ? qa : 0.0, n);
                    early += ne;
                    bad += !ok;
                    int dev = abs(nr - (int)lround(q * n));
                    if (dev >= worst) {
                        worst = dev;
                        snprintf(worst_line, sizeof worst_line, "k %d pixel %d slot %u: real %d of %d (expected %.2f), "
                                 "absorbed %d (%.2f)", k, (int)pixel, SLOTS[sl], nr, n, q * n, na,
                                 spectral ? qa * n : 0.0);
                    }
                    if (i == 0) /* as delta would count them */
                        pcg_bad += !near(pcg_real(5u + pixel, pixel * 977u, k, q), q, n);
                }
        printf("first choice, %-15s real (absorbed) first collisions within +-1 of round(p 2^k) in %d of %d cases, "
               "%d flights ended before the first collision; worst: %s%s\n", TRACKERS[i], ncases - bad, ncases, early,
               worst_line, bad || early ? "  <-- FAIL" : "");
        nfail += bad > 0 || early > 0;
    }
    printf("first choice, the same counts from PCG numbers (a choice drawn with murk_rng_float): within the bound "
           "in %d of %d cases\n", ncases - pcg_bad, ncases);
    murk_scene_free(s);
    assert_int_equal(nfail, 0);
    assert_true(pcg_bad >= ncases / 2);
}

/* ---- the first flight's distance in heterogeneous media --------------------------------------- */

#define NBINS 8192 /* the optical depth's quadrature bins along a ray */
#define NSTATS 5

/* D(t) from mt_depths' bin edges over [tmin, tmax], linear within a bin. */
static double depth_at(const double *D, const murk_ray *ray, double t)
{
    double x = (t - ray->tmin) / ((double)ray->tmax - ray->tmin) * NBINS;
    if (!(x > 0.0))
        return 0.0;
    if (x >= NBINS)
        return D[NBINS];
    int b = (int)x;
    return D[b] + (x - b) * (D[b + 1] - D[b]);
}

/* Y's statistics: its mean, and P(Y < c) for c = 1/16, 1/8, 1/4, 1/2 (the short flights, where a flight
 * shortened in its first cell shows most). Expected (Y = min(V, ymax), V uniform, ymax > 1/2):
 * ymax - ymax^2 / 2, and c. */
static const double CUTS[NSTATS - 1] = {0.0625, 0.125, 0.25, 0.5};
static const char *const STAT_NAMES[NSTATS] = {"mean", "<1/16", "<1/8", "<1/4", "<1/2"};

/* z of each statistic over npix pixels x 2^k samples of the flight at the path tracer's first flight
 * slot, against the closed form: the mean over all samples, its standard error from the spread of the
 * npix pixel means (independent scrambles and streams; the samples within a pixel are not
 * independent). *se_mean: the mean's standard error. zm: the same statistics of a mutant tracker whose
 * first flights are SHORT shorter (the flight's t from the same samples, scaled towards tmin). */
#define SHORT 0.01
static void flight_stats(const murk_medium *m, const murk_ray *ray, const double *D, double sigma_t, uint32_t sampler,
                         uint64_t seed, int npix, int k, double z[NSTATS], double zm[NSTATS], double *se_mean)
{
    double tmax = sigma_t * D[NBINS], ymax = -expm1(-tmax), expect[NSTATS] = {ymax - 0.5 * ymax * ymax};
    for (int j = 1; j < NSTATS; j++)
        expect[j] = CUTS[j - 1];
    double s[2][NSTATS] = {{0}}, s2[2][NSTATS] = {{0}};
    int n = 1 << k;
    for (int p = 0; p < npix; p++) {
        double acc[2][NSTATS] = {{0}};
        for (int i = 0; i < n; i++) {
            murk_rng r;
            murk_sampler_start(&r, sampler, seed, (uint64_t)p * 7919u + 13u, (uint32_t)i);
            murk_sample_seek(&r, SLOTS[0]);
            murk_path_ctx ctx = {.hero = i % 3, .beta = {{1, 1, 1}}};
            murk_medium_event ev;
            m->vt->sample(m->self, ray, &ctx, &r, &ev);
            assert_true(isfinite(ev.t));
            for (int mut = 0; mut < 2; mut++) {
                double t = mut ? ray->tmin + (1.0 - SHORT) * (ev.t - ray->tmin) : ev.t;
                double y = ev.scattered ? -expm1(-sigma_t * depth_at(D, ray, t)) : ymax;
                acc[mut][0] += y;
                for (int j = 1; j < NSTATS; j++)
                    acc[mut][j] += y < CUTS[j - 1];
            }
        }
        for (int mut = 0; mut < 2; mut++)
            for (int j = 0; j < NSTATS; j++) {
                double d = acc[mut][j] / n - expect[j];
                s[mut][j] += d;
                s2[mut][j] += d * d;
            }
    }
    for (int mut = 0; mut < 2; mut++)
        for (int j = 0; j < NSTATS; j++) {
            double dm = s[mut][j] / npix, se = sqrt(fmax(0.0, (s2[mut][j] - npix * dm * dm) / (npix - 1.0)) / npix);
            (mut ? zm : z)[j] = dm / fmax(se, 1.0 / ((double)npix * n));
            if (j == 0 && !mut)
                *se_mean = se;
        }
}

/* A dense heterogeneous grid, 0.6 .. 1.4 on [0, 1]^3: every majorant cell has a control for
 * decomposition, whose stratified first draw is then its first cell's control distance. */
static float dense_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z;
    return 1.0f + 0.4f * sinf(5.0f * cx + 1.0f) * sinf(4.0f * cy + 0.3f) * cosf(3.0f * cz);
}

/* test_media.c's plateau: 0.8 for z < 0.5, rising to 2.3 at z = 1 (4x4x16 voxels on [0,1]^3): constant
 * majorant cells first, where spectral_mis's closed_form takes the flight, varying ones after. */
static float plateau_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy;
    return cz < 0.5f ? 0.8f : 0.8f + 3.0f * (cz - 0.5f);
}

#define NCONFIGS (NTRACKERS + 1)
#define NPIX (int)stat_n_min(128, 16)

static void test_first_distance(void **state)
{
    (void)state;
    char grid[512], plateau[512];
    snprintf(grid, sizeof grid, "density: { grid: '%s' }, scale: 3, %s",
             mt_save_grid("dense.vol", (int[]){16, 16, 16}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), dense_f), MT_GREY_KEYS);
    snprintf(plateau, sizeof plateau, "density: { grid: '%s' }, scale: 3, %s",
             mt_save_grid("plateau.vol", (int[]){4, 4, 16}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), plateau_f),
             MT_GREY_KEYS);
    const struct {
        const char *name, *common;
        double sigma_t;
        murk_ray rays[3];
    } media[] = {
        /* cornell_smoke's cloud: through the centre, slanted from below, through the upper part, each from
         * outside the box to past it */
        {"cloud",
         "density: { cloud: { min: [-0.6, 0.05, -0.6], max: [0.6, 1.45, 0.6], seed: 7, frequency: 2.5, octaves: 5, "
         "coverage: 0.7, resolution: 64 } }, sigma_a: 0.5, sigma_s: 18",
         18.5,
         {{{0.0f, 0.75f, 1.0f}, {0, 0, -1}, 0.0f, 2.2f},
          {{-1.0f, 0.3f, 0.9f}, {0.7071068f, 0.3535534f, -0.6123724f}, 0.0f, 2.8f},
          {{0.9f, 1.15f, -0.2f}, {-0.9805807f, 0.0f, 0.1961161f}, 0.0f, 2.0f}}},
        /* the dense grid from its faces */
        {"grid", grid, 3.0 * mt_sigma_t[0][0],
         {{{0.0f, 0.4f, 0.6f}, {1, 0, 0}, 0.0f, 1.5f},
          {{0.0f, 0.1f, 0.2f}, {0.7071068f, 0.5f, 0.5f}, 0.0f, 1.5f},
          {{0.3f, 0.0f, 0.7f}, {0, 1, 0}, 0.0f, 1.5f}}},
        /* the plateau from below it, slanted (test_media.c's ramp ray) and from inside it */
        {"plateau", plateau, 3.0 * mt_sigma_t[0][0],
         {{{0.5f, 0.5f, -0.2f}, {0, 0, 1}, 0.0f, 1.5f},
          {{0.3f, 0.4f, -0.5f}, {0.1951800f, 0.0975900f, 0.9759001f}, 0.0f, 2.5f},
          {{0.1f, 0.2f, 0.1f}, {0.5050763f, 0.3030458f, 0.8081220f}, 0.0f, 1.5f}}},
    };
    mt_spec ms[NCONFIGS];
    char keys[NCONFIGS][64];
    for (int i = 0; i < NTRACKERS; i++) {
        snprintf(keys[i], sizeof keys[i], "type: %s", TRACKERS[i]);
        ms[i] = (mt_spec){TRACKERS[i], keys[i], 0};
    }
    ms[NTRACKERS] = (mt_spec){"spectral_mis_cf", "type: spectral_mis, closed_form: true", 0};
    double *D = malloc((NBINS + 1) * sizeof *D), zshort[NCONFIGS] = {0};
    assert_non_null(D);
    int nbad = 0;
    for (size_t md = 0; md < sizeof media / sizeof media[0]; md++) {
        murk_scene *s = mt_load_media("first.yaml", media[md].common, "", ms, NCONFIGS);
        for (int r = 0; r < 3; r++) {
            const murk_ray *ray = &media[md].rays[r];
            mt_depths(&s->media[0].m, NULL, ray, NBINS, 64, D);
            printf("%s, ray %d (optical depth %.2f): z of Y's", media[md].name, r, media[md].sigma_t * D[NBINS]);
            for (int j = 0; j < NSTATS; j++)
                printf(" %s", STAT_NAMES[j]);
            printf(" (sobol | independent)\n");
            for (int i = 0; i < NCONFIGS; i++) {
                double z[2][NSTATS], zm[2][NSTATS], se[2];
                int bad = 0;
                for (int smp = 0; smp < 2; smp++) {
                    flight_stats(&s->media[i].m, ray, D, media[md].sigma_t,
                                 smp ? MURK_SAMPLER_INDEPENDENT : MURK_SAMPLER_SOBOL, 11u + (uint64_t)r, NPIX, 10, z[smp],
                                 zm[smp], &se[smp]);
                    for (int j = 0; j < NSTATS; j++) {
                        stat_count(1, stat_tail2_t(STAT_Z, NPIX - 1)); /* t: the se from NPIX pixel means */
                        bad |= !(fabs(z[smp][j]) <= STAT_Z);
                        zshort[i] = fmax(zshort[i], smp ? 0.0 : fabs(zm[smp][j]));
                    }
                }
                printf("  %-15s", ms[i].label);
                for (int smp = 0; smp < 2; smp++) {
                    for (int j = 0; j < NSTATS; j++)
                        printf(" %+6.2f", z[smp][j]);
                    printf(smp ? "" : "  |");
                }
                printf("   se of the mean: sobol %.2fx independent's%s\n", se[0] / se[1], bad ? "  <-- FAIL" : "");
                nbad += bad;
            }
        }
        /* the must-fail cases: each tracker's first flights SHORT short (sobol), over the medium's rays */
        for (int i = 0; i < NCONFIGS; i++) {
            char label[96];
            snprintf(label, sizeof label, "%s %s: first flights %g%% short", media[md].name, ms[i].label, 100.0 * SHORT);
            nbad += !stat_must_fail(label, zshort[i] > STAT_Z, zshort[i]);
            zshort[i] = 0.0;
        }
        murk_scene_free(s);
    }
    free(D);
    assert_int_equal(nbad, 0);
}

int main(int argc, char **argv)
{
    setenv("MURK_PLUGIN_PATH", build_path("tests/fixtures"), 1); /* example_delta */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_first_choice), cmocka_unit_test(test_first_distance)};
    return STAT_RUN(tests, argc, argv);
}
