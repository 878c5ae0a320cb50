/* test_media.c — the tracker plugins in-process, against closed forms (murk/medium.h's invariants).
 *
 * Scenes are written to tmp_dir() and loaded with murk_scene_load (the plugins come from the build
 * tree); each tracker is then called directly through s->media[i].m.vt with murk_host_table() and a
 * murk_path_ctx {hero, beta = (1,1,1)}, exactly as volpath calls it.
 *
 * For a segment [tmin, tmax] of a ray through a medium with optical depth D(t) = int_tmin^t density:
 *   transmittance()            E[T_c]                                         = exp(-sigma_t,c D(tmax))
 *   sample(), pass-through     E[ weight_c / mean_k(pdf_k) 1{not scattered} ] = exp(-sigma_t,c D(tmax))
 *   sample(), collisions in a  E[ weight_c / mean_k(pdf_k) 1{scattered, t in bin} ]
 *   bin [t0, t1]                  = (sigma_s,c / sigma_t,c) (exp(-sigma_t,c D(t0)) - exp(-sigma_t,c D(t1)))
 * the hero drawn uniformly per call (the integrator's weighting: for naive_spectral 1/mean(pdf) is the
 * 3x on the hero channel; for spectral_mis it is the balance heuristic over channels). Summed over all
 * bins the collision term is (sigma_s,c / sigma_t,c)(1 - T_c) for any density.
 *
 * Every figure is a sample mean over N independent calls with a fixed seed (one stream per medium); it
 * must lie within STAT_Z = 5 standard errors (sample variance) of the closed form, per channel (stat.h).
 * The bias the checks exist for is a wrong density (the reference report's decomposition bias): each
 * tracker's must-fail cases are its own T, and its pass-through and collisions, against the closed
 * forms of a medium DENSER denser (5 % here, 3 % in the suite 'long' with 2.5x the samples), which must
 * fail; naive_spectral, whose hero-only weights have three times the variance, gets three times the
 * calls. The figures are printed: mean +- se (expected, z) per channel.
 *
 * Tests: constant / linear-ramp / sinusoidal grid density x grey / chromatic sigma for every tracker
 * (and spectral's three probability schemes, and spectral_mis's closed_form: in closed form on the
 * constant grid, tracked on the others); decomposition control 0, 0.1, 0.5, 1, 2 and majorant
 * factor 4 against the closed form and against control 0 (two-sample, must-fail: means DENSER larger);
 * majorant factor 0.5 with the repair off (weighted collisions, heavy-tailed: the empirical Bernstein
 * bound of mt_check_bounded, from the weights' maximum) for every tracker at full density;
 * Henyey-Greenstein sampling against phase_eval (chi-square and mean cosine; must-fail: g off by 0.02). */
#include "mediatest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NBINS 8
/* 1 in the suite 'long' (the long_ tests): 2.5x the samples, and a 3 % denser medium to detect. */
static int longrun;
/* The bias the closed-form checks exist for: a density DENSER too high. */
#define DENSER (longrun ? 0.03 : 0.05)
/* Calls per tracker and ray (each call: one transmittance() and one sample(), about 2 us on the
 * sinusoid): enough that DENSER is about 10 standard errors of the noisiest tracker's sample() figures
 * (naive_spectral gets 3x: see check_scene). */
static long n_main(void) { return stat_n(longrun ? 250000 : 100000); }

static int nfail; /* checks that failed in the current test (all are printed before the test fails) */

/* ---- scenes ----------------------------------------------------------------------------------- */

/* Every tracker (and spectral's three probability schemes) with its default parameters. */
static const mt_spec ALL_TRACKERS[] = {
    {"delta", "type: delta", 0},
    {"decomposition", "type: decomposition", 0},
    {"spectral", "type: spectral", 0},
    {"spectral_max", "type: spectral, probabilities: max", 0},
    {"spectral_avg", "type: spectral, probabilities: average", 0},
    {"spectral_mis", "type: spectral_mis", 0},
    {"spectral_mis_cf", "type: spectral_mis, closed_form: true", 0},
    {"naive_spectral", "type: naive_spectral", 0},
};
#define NTRACKERS ((int)(sizeof ALL_TRACKERS / sizeof ALL_TRACKERS[0]))

/* ---- estimation ------------------------------------------------------------------------------- */

typedef struct stats {
    long n, nonfinite, bad_t;
    mt_acc T, pass, scat, bin[NBINS];
} stats;

/* n calls of transmittance() and n of sample() on one ray, heroes uniform, one fixed-seed stream. */
static void run_tracker(const murk_medium *m, const murk_ray *ray, long n, uint64_t seed, stats *st)
{
    memset(st, 0, sizeof *st);
    st->n = n;
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x6d656469, 0);
    double width = ((double)ray->tmax - ray->tmin) / NBINS;
    for (long i = 0; i < n; i++) {
        murk_rgb T;
        murk_medium_event ev;
        double w[3];
        if (!mt_call(m, ray, &rng, &T, &ev, w))
            st->nonfinite++;
        if ((ev.scattered != 0 && ev.scattered != 1) || (ev.scattered && !(ev.t >= ray->tmin && ev.t <= ray->tmax)))
            st->bad_t++;
        int b = ev.scattered ? (int)(((double)ev.t - ray->tmin) / width) : -1;
        if (b >= NBINS)
            b = NBINS - 1;
        double xT[3], xp[3], xs[3], xb[NBINS][3];
        for (int c = 0; c < 3; c++) {
            double x = w[c];
            xT[c] = T.c[c];
            xp[c] = ev.scattered ? 0.0 : x;
            xs[c] = ev.scattered ? x : 0.0;
            for (int k = 0; k < NBINS; k++)
                xb[k][c] = k == b ? x : 0.0;
        }
        mt_acc_add(&st->T, xT);
        mt_acc_add(&st->pass, xp);
        mt_acc_add(&st->scat, xs);
        for (int k = 0; k < NBINS; k++)
            mt_acc_add(&st->bin[k], xb[k]);
    }
}

/* mt_check of one figure (|mean - expect| <= STAT_Z se, per channel), or mt_check_bounded's bound from
 * the weights' maximum wmax if wmax > 0 (weighted collisions: heavy-tailed). */
static void check3(const char *label, const char *what, const mt_acc *a, const double expect[3], double wmax)
{
    char head[128];
    snprintf(head, sizeof head, "  %-22s %-8s", label, what);
    nfail += wmax > 0.0 ? mt_check_bounded(head, a, expect, wmax, "") : mt_check(head, a, expect, 1e-5, "");
}

/* The bias a weighted figure's bound can see is far larger: its must-fail case. */
#define WEIGHTED_DENSER 0.3

/* The closed forms of a segment whose optical depth per unit extinction is D (and D0, D1 at a bin's
 * edges) times `dense`: T, all collisions S, and the bin's share B. */
static void closed_forms(const double sa[3], const double ss[3], double D, double dense, double T[3], double S[3])
{
    for (int c = 0; c < 3; c++) {
        double st = sa[c] + ss[c];
        T[c] = exp(-st * D * dense);
        S[c] = ss[c] / st * (1.0 - T[c]);
    }
}

typedef struct config {
    const char *name;
    murk_ray ray;
    double sa[3], ss[3]; /* per unit density, scale applied */
    double D_exact;      /* closed-form optical depth over the segment, or < 0 if only quadrature */
    const char *grid;    /* the .vol file of a grid density (NULL: constant) */
} config;

/* Runs every medium of s (made from ms) on cfg->ray and checks transmittance, pass-through, collisions
 * per bin and in all against the closed forms (mt_check, or mt_check_bounded for a medium with a stated
 * weight maximum), with the must-fail cases of a denser medium. Returns the stats of each medium in out
 * (if non-NULL). */
static void check_scene(const murk_scene *s, const mt_spec *ms, const config *cfg, long n, stats *out)
{
    printf("%s\n", cfg->name);
    /* the reference: D at the bin edges, 4096 midpoint steps per bin, on the field as the core
     * interpolates it */
    double D[NBINS + 1];
    mt_depths(&s->media[0].m, cfg->grid, &cfg->ray, NBINS, 4096, D);
    if (cfg->D_exact >= 0) {
        printf("  optical depth: quadrature %.6f, closed form %.6f\n", D[NBINS], cfg->D_exact);
        assert_true(fabs(D[NBINS] - cfg->D_exact) < 1e-4 * cfg->D_exact);
    } else {
        printf("  optical depth (quadrature of the interpolated field): %.6f\n", D[NBINS]);
    }
    double T[3], S[3], B[NBINS][3], Td[3], Sd[3], Dt = cfg->D_exact >= 0 ? cfg->D_exact : D[NBINS];
    closed_forms(cfg->sa, cfg->ss, Dt, 1.0, T, S);
    closed_forms(cfg->sa, cfg->ss, Dt, 1.0 + DENSER, Td, Sd);
    for (int c = 0; c < 3; c++) {
        double st = cfg->sa[c] + cfg->ss[c], alb = cfg->ss[c] / st;
        for (int b = 0; b < NBINS; b++)
            B[b][c] = alb * (exp(-st * D[b]) - exp(-st * D[b + 1]));
    }
    for (size_t i = 0; i < s->nmedia; i++) {
        const murk_medium *m = &s->media[i].m;
        stats st;
        double t0 = mt_seconds();
        long ni = strstr(ms[i].keys, "naive_spectral") ? 3 * n : n; /* its hero-only weights: 3x the variance */
        run_tracker(m, &cfg->ray, ni, 1000 + i, &st);
        printf("  %-22s %ld calls each of transmittance() and sample() in %.2f s\n", m->name, ni, mt_seconds() - t0);
        if (st.nonfinite || st.bad_t) {
            printf("  %-22s %ld non-finite results, %ld events outside the segment  <-- FAIL\n", m->name,
                   st.nonfinite, st.bad_t);
            nfail++;
        }
        double w = ms[i].wmax;
        check3(m->name, "T", &st.T, T, w);
        check3(m->name, "pass", &st.pass, T, w);
        check3(m->name, "scatter", &st.scat, S, w);
        for (int b = 0; b < NBINS; b++) {
            char what[16];
            snprintf(what, sizeof what, "bin %d", b);
            check3(m->name, what, &st.bin[b], B[b], w);
        }
        /* the must-fail cases: transmittance() and sample() must each see a denser medium */
        double zt, zs, dense = w > 0.0 ? WEIGHTED_DENSER : DENSER;
        if (w > 0.0) {
            closed_forms(cfg->sa, cfg->ss, Dt, 1.0 + dense, Td, Sd);
            zt = mt_zmax_bounded(&st.T, Td, w);
            zs = fmax(mt_zmax_bounded(&st.pass, Td, w), mt_zmax_bounded(&st.scat, Sd, w));
            closed_forms(cfg->sa, cfg->ss, Dt, 1.0 + DENSER, Td, Sd);
        } else {
            zt = mt_zmax(&st.T, Td, 1e-5);
            zs = fmax(mt_zmax(&st.pass, Td, 1e-5), mt_zmax(&st.scat, Sd, 1e-5));
        }
        char label[96];
        snprintf(label, sizeof label, "%s T against a %g%% denser medium", m->name, 100.0 * dense);
        nfail += !stat_must_fail(label, zt > STAT_Z, zt);
        snprintf(label, sizeof label, "%s pass, scatter against a %g%% denser medium", m->name, 100.0 * dense);
        nfail += !stat_must_fail(label, zs > STAT_Z, zs);
        if (out)
            out[i] = st;
    }
}

static void set_sigma(config *cfg, int chroma)
{
    memcpy(cfg->sa, mt_sigma_a[chroma], sizeof cfg->sa);
    memcpy(cfg->ss, mt_sigma_s[chroma], sizeof cfg->ss);
}


/* ---- 1a/1b: transmittance and collisions, every tracker --------------------------------------- */

/* Constant density 0.5 (infinite extent) over a segment of length 1.5: D = 0.75. */
static void test_constant(void **state)
{
    (void)state;
    nfail = 0;
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[256];
        snprintf(common, sizeof common, "density: { constant: 0.5 }, %s", mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("constant.yaml", common, "", ALL_TRACKERS, NTRACKERS);
        config cfg = {chroma ? "constant density, chromatic" : "constant density, grey",
                      {murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(1, 2, -2)), 0.0f, 1.5f}, {0}, {0}, 0.75, NULL};
        set_sigma(&cfg, chroma);
        check_scene(s, ALL_TRACKERS, &cfg, n_main(), NULL);
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* The ramp 0.2 + 1.1 z on [0,1]^3 (4x4x16 voxels) along a slanted ray entering through z = 0 and
 * leaving through z = 1, segment from outside the box to past it: D = 0.75 / d.z. */
static void test_ramp(void **state)
{
    (void)state;
    nfail = 0;
    mt_case rc = mt_ramp_case();
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", rc.grid, mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("ramp.yaml", common, "", ALL_TRACKERS, NTRACKERS);
        config cfg = {chroma ? "linear ramp, chromatic" : "linear ramp, grey",
                      rc.ray, {0}, {0}, rc.D, rc.grid};
        set_sigma(&cfg, chroma);
        check_scene(s, ALL_TRACKERS, &cfg, n_main(), NULL);
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* The 3-D sinusoid on [-1,1]^3 (16^3 voxels) along a diagonal ray whose segment starts inside the box
 * and ends outside it; the reference is the quadrature of the interpolated field. */
static void test_sinus(void **state)
{
    (void)state;
    nfail = 0;
    mt_case sc = mt_sinus_case();
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", sc.grid, mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("sinus.yaml", common, "", ALL_TRACKERS, NTRACKERS);
        config cfg = {chroma ? "sinusoid, chromatic" : "sinusoid, grey",
                      sc.ray, {0}, {0}, sc.D, sc.grid};
        set_sigma(&cfg, chroma);
        check_scene(s, ALL_TRACKERS, &cfg, n_main(), NULL);
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* A plateau: density 0.8 for z < 0.5, rising to 2.3 at z = 1 (4x4x16 voxels on [0,1]^3). The ramp
 * case's slanted ray crosses majorant cells of constant density first, then varying ones: spectral_mis's
 * closed_form takes the first part in closed form and tracks the rest. */
static float plateau_f(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cx, (void)cy;
    return cz < 0.5f ? 0.8f : 0.8f + 3.0f * (cz - 0.5f);
}

static void test_plateau(void **state)
{
    (void)state;
    nfail = 0;
    static const mt_spec ms[] = {
        {"spectral_mis", "type: spectral_mis", 0},
        {"spectral_mis_cf", "type: spectral_mis, closed_form: true", 0},
    };
    const char *grid = mt_save_grid("plateau.vol", (int[]){4, 4, 16}, murk_v3(0, 0, 0), murk_v3(1, 1, 1), plateau_f);
    mt_case rc = mt_ramp_case();
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", grid, mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("plateau.yaml", common, "", ms, 2);
        config cfg = {chroma ? "plateau, chromatic" : "plateau, grey", rc.ray, {0}, {0}, -1.0, grid};
        set_sigma(&cfg, chroma);
        check_scene(s, ms, &cfg, n_main(), NULL);
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* ---- 1c: decomposition's control and the majorant factor do not change the expectation -------- */

/* Two-sample comparison of every figure of b against a (|difference| <= STAT_Z combined se, per channel);
 * its must-fail case: the same with b's means DENSER larger. */
static void compare_stats(const char *la, const stats *a, const char *lb, const stats *b)
{
    const mt_acc *pa[3] = {&a->T, &a->pass, &a->scat}, *pb[3] = {&b->T, &b->pass, &b->scat};
    static const char *const what[3] = {"T", "pass", "scatter"};
    double zbiased = 0.0;
    for (int q = 0; q < 3; q++) {
        char line[512];
        size_t k = (size_t)snprintf(line, sizeof line, "  %s vs %s %-8s", lb, la, what[q]);
        int bad = 0;
        for (int c = 0; c < 3; c++) {
            double mb = mt_mean(pb[q], c), sb = mt_se(pb[q], c), ma = mt_mean(pa[q], c), sa = mt_se(pa[q], c);
            double se = hypot(sa, sb);
            bad |= !stat_z_ok(mb - ma, se, 0.0, 1e-6);
            zbiased = fmax(zbiased, (fabs(mb * (1.0 + DENSER) - ma) - 1e-6) / se);
            k += (size_t)snprintf(line + k, sizeof line - k, "  diff %+.5f+-%.5f", mb - ma, se);
        }
        printf("%s%s\n", line, bad ? "  <-- FAIL" : "");
        nfail += bad;
    }
    char label[128];
    snprintf(label, sizeof label, "%s vs %s, its means %g%% larger", lb, la, 100.0 * DENSER);
    nfail += !stat_must_fail(label, zbiased > STAT_Z, zbiased);
}

static void test_decomposition_control(void **state)
{
    (void)state;
    nfail = 0;
    static const mt_spec ms[] = {
        {"control_0", "type: decomposition, control: 0", 0},
        {"control_0.1", "type: decomposition, control: 0.1", 0},
        {"control_0.5", "type: decomposition, control: 0.5", 0},
        {"control_1", "type: decomposition, control: 1", 0},
        {"control_2", "type: decomposition, control: 2, repair: false", 16}, /* weighted: at most 7 seen */
        {"control_0.5_majorant_4", "type: decomposition, control: 0.5, majorant_factor: 4", 0},
        {"control_1_majorant_4", "type: decomposition, control: 1, majorant_factor: 4", 0},
        {"delta_majorant_4", "type: delta, majorant_factor: 4", 0},
        {"spectral_majorant_4", "type: spectral, majorant_factor: 4", 0},
        {"smis_majorant_4", "type: spectral_mis, majorant_factor: 4", 0},
        {"naive_majorant_4", "type: naive_spectral, majorant_factor: 4", 0},
    };
    int n = (int)(sizeof ms / sizeof ms[0]);
    mt_case sc = mt_sinus_case();
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", sc.grid, mt_sigma_keys(chroma));
        /* the other trackers' majorant_factor 4 only with chromatic sigma (grey adds little) */
        int nm = chroma ? n : 7;
        murk_scene *s = mt_load_media("control.yaml", common, "", ms, nm);
        config cfg = {chroma ? "decomposition control / majorant factor, sinusoid, chromatic"
                             : "decomposition control / majorant factor, sinusoid, grey",
                      sc.ray, {0}, {0}, sc.D, sc.grid};
        set_sigma(&cfg, chroma);
        stats st[16];
        check_scene(s, ms, &cfg, n_main(), st);
        for (int i = 1; i < 7; i++) /* every decomposition variant against control 0 (= delta tracking) */
            compare_stats(ms[0].label, &st[0], ms[i].label, &st[i]);
        murk_scene_free(s);
    }
    /* the same on a constant density, where control 1 takes every collision in closed form */
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[256];
        snprintf(common, sizeof common, "density: { constant: 0.5 }, %s", mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("control_c.yaml", common, "", ms, 7);
        config cfg = {chroma ? "decomposition control, constant, chromatic" : "decomposition control, constant, grey",
                      {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, 1.5f}, {0}, {0}, 0.75, NULL};
        set_sigma(&cfg, chroma);
        check_scene(s, ms, &cfg, n_main(), NULL);
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* majorant_factor 0.5 does not bound the density: every tracker must switch to weighted collisions
 * and stay unbiased and finite, at full density. The weights are heavy-tailed (rare large ones; the
 * sample variance misses them: at optical depth 0.6 x 3.1 a 150k-sample mean once sat 4.7 "se" below the
 * truth, before the per-flight raise existed), so the figures are judged by mt_check_bounded's bound from
 * the weights' maximum. On a constant density 0.5 (segment 1.5: D = 0.75) the density is twice the
 * majorant everywhere: the first tentative collision of a flight has the real share a = 2, is weighted
 * by at most |a| + |1 - a| = 3 (murk/tracking.h) and raises the rest of the flight's majorant 2a = 4x, so
 * no later collision violates it: the largest |weight| is 3 with grey sigma (9 for naive_spectral's 3x
 * hero; the float weights round up to 9.00001), as seen; with chromatic sigma the history-aware
 * probabilities spread it over the channels unevenly (spectral's 'max' probabilities reach 34 in 2 x 10^5
 * flights, the others stay below 12): WMAX_CHROMA is a stated maximum there, not a derived one (a
 * larger weight would widen the bound, mt_check_bounded). The bias the bound can see is large (about 5 % of T grey, 10-20 % chromatic: the printed
 * +- is the bound), so its must-fail case is a medium 30 % denser. T, a product of ratio-tracking
 * factors 1 - x with x in [0, 2] before the raise, stays within [-1, 1]: its bound uses 1.
 * naive_spectral, three times as noisy, gets twice the calls. */
#define WMAX_GREY 9.0001
#define WMAX_CHROMA 64.0
#define HALF_DENSER 0.3
static void test_majorant_half(void **state)
{
    (void)state;
    nfail = 0;
    static const mt_spec ms[] = {
        {"delta", "type: delta, majorant_factor: 0.5, majorant_repair: false", 0},
        {"decomposition", "type: decomposition, majorant_factor: 0.5, majorant_repair: false", 0},
        {"decomposition_c0", "type: decomposition, control: 0, majorant_factor: 0.5, majorant_repair: false", 0},
        {"spectral", "type: spectral, majorant_factor: 0.5, majorant_repair: false", 0},
        {"spectral_max", "type: spectral, probabilities: max, majorant_factor: 0.5, majorant_repair: false", 0},
        {"spectral_mis", "type: spectral_mis, majorant_factor: 0.5, majorant_repair: false", 0},
        {"naive_spectral", "type: naive_spectral, majorant_factor: 0.5, majorant_repair: false", 0},
    };
    int n = (int)(sizeof ms / sizeof ms[0]);
    long N = stat_n(longrun ? 1000000 : 200000);
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { constant: 0.5 }, %s", mt_sigma_keys(chroma));
        murk_scene *s = mt_load_media("half.yaml", common, "", ms, n);
        double sa[3], ss[3], T[3], S[3], Td[3], Sd[3], wmax = chroma ? WMAX_CHROMA : WMAX_GREY;
        memcpy(sa, mt_sigma_a[chroma], sizeof sa);
        memcpy(ss, mt_sigma_s[chroma], sizeof ss);
        closed_forms(sa, ss, 0.75, 1.0, T, S);
        closed_forms(sa, ss, 0.75, 1.0 + HALF_DENSER, Td, Sd);
        printf("majorant_factor 0.5, constant density, %s, full density; bounds from |weight| <= %g\n",
               chroma ? "chromatic" : "grey", wmax);
        murk_ray ray = {murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(1, 2, -2)), 0.0f, 1.5f};
        for (int i = 0; i < n; i++) {
            stats st;
            run_tracker(&s->media[i].m, &ray, strstr(ms[i].keys, "naive") ? 2 * N : N, 2000 + (uint64_t)i, &st);
            if (st.nonfinite || st.bad_t) {
                printf("  %-22s %ld non-finite results, %ld events outside the segment  <-- FAIL\n", ms[i].label,
                       st.nonfinite, st.bad_t);
                nfail++;
            }
            char head[96];
            snprintf(head, sizeof head, "  %-22s T       ", ms[i].label);
            nfail += mt_check_bounded(head, &st.T, T, 1.0001, "");
            snprintf(head, sizeof head, "  %-22s pass    ", ms[i].label);
            nfail += mt_check_bounded(head, &st.pass, T, wmax, "");
            snprintf(head, sizeof head, "  %-22s scatter ", ms[i].label);
            nfail += mt_check_bounded(head, &st.scat, S, wmax, "");
            double z = fmax(mt_zmax_bounded(&st.pass, Td, wmax), mt_zmax_bounded(&st.scat, Sd, wmax));
            char label[96];
            snprintf(label, sizeof label, "%s pass, scatter against a %g%% denser medium", ms[i].label, 100.0 * HALF_DENSER);
            nfail += !stat_must_fail(label, z > STAT_Z, z);
        }
        murk_scene_free(s);
    }
    assert_int_equal(nfail, 0);
}

/* ---- 1d: Henyey-Greenstein sampling against its pdf ------------------------------------------- */

#define NCOS 50
#define NPHI 8

/* The expected share of every (cos theta, phi) cell around -wo: phase_eval with g integrated over the cell
 * (midpoint rule, 400 x 8 points per cell; cos theta = dot(wi, -wo)); *total is their sum and *maxrel the
 * largest relative deviation of a cos-theta row from the analytic HG marginal (phase_eval is HG about -wo). */
static void hg_expect(const murk_host *h, float g, murk_vec3 wo, murk_vec3 tb, murk_vec3 bb, double *expect,
                      double *total, double *maxrel)
{
    murk_vec3 axis = murk_neg(wo);
    *total = *maxrel = 0.0;
    for (int i = 0; i < NCOS; i++) {
        double cell_cos = 0.0;
        for (int j = 0; j < NPHI; j++) {
            double sum = 0.0;
            const int sc = 400, sp = 8;
            for (int a = 0; a < sc; a++)
                for (int b = 0; b < sp; b++) {
                    double ct = -1.0 + 2.0 * (i + (a + 0.5) / sc) / NCOS;
                    double ph = 2.0 * M_PI * (j + (b + 0.5) / sp) / NPHI, stt = sqrt(fmax(0.0, 1.0 - ct * ct));
                    murk_vec3 wi = murk_from_local(murk_v3((float)(stt * cos(ph)), (float)(stt * sin(ph)), (float)ct),
                                                   tb, bb, axis);
                    sum += h->phase_eval(g, wo, wi);
                }
            expect[i * NPHI + j] = sum * (2.0 / NCOS / sc) * (2.0 * M_PI / NPHI / sp);
            cell_cos += expect[i * NPHI + j];
            *total += expect[i * NPHI + j];
        }
        double c0 = -1.0 + 2.0 * i / NCOS, c1 = -1.0 + 2.0 * (i + 1) / NCOS, exact;
        if (fabs(g) < 1e-6)
            exact = (c1 - c0) / 2.0;
        else
            exact = (1.0 - g * g) / (2.0 * g) *
                    (1.0 / sqrt(1.0 + g * g - 2.0 * g * c1) - 1.0 / sqrt(1.0 + g * g - 2.0 * g * c0));
        *maxrel = fmax(*maxrel, fabs(cell_cos - exact) / exact);
    }
}

/* phase_sample against phase_eval: the chi-square of the sampled directions' cells and the mean cosine
 * (HG's is g); the must-fail cases are both against HG with g + G_OFF. */
#define G_OFF 0.02
static void test_hg_phase(void **state)
{
    (void)state;
    const murk_host *h = murk_host_table();
    static const float gs[] = {-0.7f, 0.0f, 0.3f, 0.9f};
    const long N = stat_n(1000000);
    murk_vec3 wo = murk_normalize(murk_v3(0.3f, -0.5f, 0.8f)), axis = murk_neg(wo), tb, bb;
    murk_basis(axis, &tb, &bb);
    int fails = 0;
    for (int gi = 0; gi < 4; gi++) {
        float g = gs[gi];
        static double expect[NCOS * NPHI], wrong[NCOS * NPHI], obs[NCOS * NPHI];
        double total, maxrel, total_w, maxrel_w;
        hg_expect(h, g, wo, tb, bb, expect, &total, &maxrel);
        hg_expect(h, g + (float)G_OFF, wo, tb, bb, wrong, &total_w, &maxrel_w);
        murk_rng rng;
        murk_rng_seed(&rng, 77, (uint64_t)gi, 0);
        memset(obs, 0, sizeof obs);
        double sc = 0.0, sc2 = 0.0;
        long badpdf = 0;
        for (long k = 0; k < N; k++) {
            float u[2] = {murk_rng_float(&rng), murk_rng_float(&rng)}, pdf = -1.0f;
            murk_vec3 wi = h->phase_sample(g, wo, u, &pdf);
            float pe = h->phase_eval(g, wo, wi);
            if (!(fabsf(pdf - pe) <= 1e-4f * pe) || !(fabsf(murk_length(wi) - 1.0f) < 1e-4f))
                badpdf++;
            double ct = murk_dot(wi, axis), ph = atan2(murk_dot(wi, bb), murk_dot(wi, tb));
            if (ph < 0)
                ph += 2.0 * M_PI;
            int i = (int)((ct + 1.0) * 0.5 * NCOS), j = (int)(ph / (2.0 * M_PI) * NPHI);
            i = i < 0 ? 0 : (i >= NCOS ? NCOS - 1 : i);
            j = j < 0 ? 0 : (j >= NPHI ? NPHI - 1 : j);
            obs[i * NPHI + j] += 1.0;
            sc += ct;
            sc2 += ct * ct;
        }
        for (int i = 0; i < NCOS * NPHI; i++) {
            expect[i] *= (double)N;
            wrong[i] *= (double)N;
        }
        int dof = 0, dof_w = 0;
        double p = chi2_test(obs, expect, NCOS * NPHI, 5.0, &dof), pw = chi2_test(obs, wrong, NCOS * NPHI, 5.0, &dof_w);
        double mc = sc / N, mse = sqrt((sc2 / N - mc * mc) / (N - 1));
        int ok = stat_chi2_ok(p) & stat_z_ok(mc, mse, g, 0.0);
        printf("HG g %+.1f: integral of phase_eval %.6f, max rel. dev. of cos-theta bins from the analytic "
               "marginal %.2g, chi2 p = %.4g (dof %d), mean cos(wi, -wo) %.5f+-%.5f (expected %.1f), "
               "pdf != phase_eval: %ld%s\n",
               g, total, maxrel, p, dof, mc, mse, g, badpdf, ok ? "" : "  <-- FAIL");
        fails += !ok || !(fabs(total - 1.0) < 1e-4) || !(maxrel < 1e-3) || badpdf;
        char label[96];
        snprintf(label, sizeof label, "HG g %+.1f: chi-square against g %+.2f", g, g + G_OFF);
        fails += !stat_must_fail_chi2(label, pw);
        snprintf(label, sizeof label, "HG g %+.1f: mean cosine against g %+.2f", g, g + G_OFF);
        double zw = (fabs(mc - (g + G_OFF))) / mse;
        fails += !stat_must_fail(label, zw > STAT_Z, zw);
    }
    assert_int_equal(fails, 0);
}

/* The suite 'long': every test again with 2.5x the samples (the weighted one 5x) and a 3 % denser medium. */
#define LONG(name) STAT_LONG_OF(name, longrun)
LONG(constant)
LONG(ramp)
LONG(sinus)
LONG(plateau)
LONG(decomposition_control)
LONG(majorant_half)

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant),
        cmocka_unit_test(test_ramp),
        cmocka_unit_test(test_sinus),
        cmocka_unit_test(test_plateau),
        cmocka_unit_test(test_decomposition_control),
        cmocka_unit_test(test_majorant_half),
        cmocka_unit_test(test_hg_phase),
        cmocka_unit_test(long_constant),
        cmocka_unit_test(long_ramp),
        cmocka_unit_test(long_sinus),
        cmocka_unit_test(long_plateau),
        cmocka_unit_test(long_decomposition_control),
        cmocka_unit_test(long_majorant_half),
    };
    return STAT_RUN(tests, argc, argv);
}
