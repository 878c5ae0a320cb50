/* test_stability.c — wrong majorants and controls (issue 9, docs/stability.md): murk's repairs keep every
 * estimate unbiased and the weights bounded.
 *
 *   load-time repair   majorant_factor 0.25 (majorant_repair: true, the default) and decomposition
 *                      control 10 (repair: true) give bitwise the events and transmittances of the
 *                      bounding case (factor 1, control 1) from the same random stream, every tracker,
 *                      grey and chromatic, on the sinusoid grid: the repair happens before rendering and
 *                      leaves nothing to chance.
 *   per-flight repair  majorant_factor 0.25 with majorant_repair: false (a tentative collision at density
 *                      up to 4x the majorant) and decomposition control 10 with repair: false (control 10x
 *                      the density) against the closed forms of a homogeneous segment (D = 0.75):
 *                      E[T] = E[pass-through weight] = exp(-sigma_t D), E[scatter weight] = albedo (1 - T),
 *                      and the largest |weight| (printed) must stay below WMAX: the per-flight raise bounds
 *                      it. Also on the sinusoid (no closed form: the quadrature of the interpolated field).
 *                      The weights are heavy-tailed (that is the point), so every figure is judged by
 *                      mt_check_bounded's bound from the weights' maximum (the empirical Bernstein bound,
 *                      valid for any distribution on [-W, W]): W = 7 on the constant density with grey
 *                      sigma (one violating collision of real share a = 4 weighs at most |a| + |1 - a|,
 *                      and raises the flight's majorant 8x, past the density; 21 for naive_spectral's 3x
 *                      hero), a stated 32 with chromatic sigma, and WMAX, the bound this test asserts, on
 *                      the sinusoid. So wide a bound sees only a large bias (printed as +-: 2 to 20 % of T
 *                      on the constant density, 10 to 50 % on the sinusoid): the must-fail cases are a
 *                      medium 30 % (constant) and 50 % (sinusoid) denser. Without the per-flight raise the
 *                      largest weights were 240 to 37700: the WMAX assertion sees that.
 * Checked by hand that it fails when wrong: dropping the weight of the violating collision in delta.c (the
 * raise alone) fails delta's pass-through and scatter by > 30 se; raising the majorant before the
 * collision's choice instead of after it fails them as well. The render-level checks are the
 * `stability_quick` test (every sweep's extreme points of the atlas finite: bench/stability/atlas.py
 * --quick --check --finite-only) and the suite 'stability' (the whole atlas, |z| <= 5 against the
 * bounding case or the closed form). */
#include "mediatest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const TRACKERS[] = {"delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"};
#define NTR 5

/* ---- load-time repair: bitwise the bounding case ------------------------------------------------ */

/* n pairs of transmittance() and sample() on media a and b from the same stream: 1 if every result is
 * bitwise equal. */
static int same_events(const murk_medium *a, const murk_medium *b, const murk_ray *ray, long n)
{
    murk_rng ra, rb;
    murk_rng_seed(&ra, 99, 1, 2);
    murk_rng_seed(&rb, 99, 1, 2);
    murk_path_ctx ca = {0, murk_rgb1(1.0f)}, cb = ca;
    for (long i = 0; i < n; i++) {
        ca.hero = cb.hero = (int)(i % 3);
        murk_rgb Ta = a->vt->transmittance(a->self, ray, &ca, &ra), Tb = b->vt->transmittance(b->self, ray, &cb, &rb);
        murk_medium_event ea, eb;
        a->vt->sample(a->self, ray, &ca, &ra, &ea);
        b->vt->sample(b->self, ray, &cb, &rb, &eb);
        if (memcmp(&Ta, &Tb, sizeof Ta) || ea.scattered != eb.scattered || memcmp(&ea.t, &eb.t, sizeof ea.t) ||
            memcmp(&ea.weight, &eb.weight, sizeof ea.weight) || memcmp(&ea.pdf_ratio, &eb.pdf_ratio, sizeof ea.pdf_ratio))
            return 0;
    }
    return 1;
}

static void test_load_repair_is_exact(void **state)
{
    (void)state;
    mt_case sc = mt_sinus_case();
    int fails = 0;
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", sc.grid, mt_sigma_keys(chroma));
        mt_spec ms[2 * NTR + 2];
        char keys[2 * NTR + 2][128];
        for (int i = 0; i < NTR; i++) {
            snprintf(keys[2 * i], sizeof keys[0], "type: %s", TRACKERS[i]);
            snprintf(keys[2 * i + 1], sizeof keys[0], "type: %s, majorant_factor: 0.25", TRACKERS[i]);
            ms[2 * i] = (mt_spec){TRACKERS[i], keys[2 * i], 0};
            ms[2 * i + 1] = (mt_spec){"repaired", keys[2 * i + 1], 0};
        }
        ms[2 * NTR] = (mt_spec){"control_1", "type: decomposition, control: 1", 0};
        ms[2 * NTR + 1] = (mt_spec){"control_10", "type: decomposition, control: 10", 0};
        /* labels must be unique media names */
        char labels[2 * NTR][32];
        for (int i = 0; i < 2 * NTR; i++) {
            snprintf(labels[i], sizeof labels[0], "%s%s", TRACKERS[i / 2], i % 2 ? "_f025" : "");
            ms[i].label = labels[i];
        }
        murk_scene *s = mt_load_media("repair.yaml", common, "", ms, 2 * NTR + 2);
        for (int i = 0; i < NTR + 1; i++) {
            int ok = same_events(&s->media[2 * i].m, &s->media[2 * i + 1].m, &sc.ray, 20000);
            printf("  %-8s %-16s vs %-22s 20000 events bitwise equal: %s\n", chroma ? "chromatic" : "grey",
                   ms[2 * i].label, ms[2 * i + 1].label, ok ? "yes" : "NO  <-- FAIL");
            fails += !ok;
        }
        murk_scene_free(s);
    }
    assert_int_equal(fails, 0);
}

/* ---- per-flight repair: unbiased, bounded ------------------------------------------------------- */

typedef struct rstats {
    mt_acc T, pass, scat;
    double wmax;
    long nonfinite;
} rstats;

static void run(const murk_medium *m, const murk_ray *ray, long n, uint64_t seed, rstats *st)
{
    memset(st, 0, sizeof *st);
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x73746162, 0);
    for (long i = 0; i < n; i++) {
        murk_rgb T;
        murk_medium_event ev;
        double w[3];
        if (!mt_call(m, ray, &rng, &T, &ev, w))
            st->nonfinite++;
        double xT[3], xp[3], xs[3];
        for (int c = 0; c < 3; c++) {
            double x = w[c];
            st->wmax = fmax(st->wmax, fabs(x));
            xT[c] = T.c[c];
            xp[c] = ev.scattered ? 0.0 : x;
            xs[c] = ev.scattered ? x : 0.0;
        }
        mt_acc_add(&st->T, xT);
        mt_acc_add(&st->pass, xp);
        mt_acc_add(&st->scat, xs);
    }
}

#define N_RUN stat_n(200000)
/* The largest |weight| / mean pdf ratio allowed: one violating collision at a = 4 weighs 2a - 1 = 7 (x3 for
 * naive_spectral's hero, up to ~80 for chromatic history-aware choices over two violations); without the
 * per-flight raise the weights multiply by 7 at every violating collision and pass it. */
#define WMAX 100.0
/* On the constant density with chromatic sigma: a stated maximum (naive_spectral's 21 = 3 x 7, the
 * others below 9 seen in 2 x 10^5 flights; a larger one only widens the bound). */
#define WCHROMA 32.0

/* Every tracker with its majorant 4x too low (and decomposition's control 10x too high), repairs off,
 * on `common` along ray with optical depth D (< 0: quadrature); wgrey > 0 (the constant density): the
 * derived maximum |weight| for grey sigma (3x for naive_spectral) and WCHROMA for chromatic, with a
 * must-fail case 30 % denser; else WMAX and 50 % denser. */
static int check_runtime(const char *name, const char *common, const murk_ray *ray, double D, int chroma, double wgrey)
{
    mt_spec ms[NTR + 1];
    char keys[NTR + 1][128];
    for (int i = 0; i < NTR; i++) {
        snprintf(keys[i], sizeof keys[0], "type: %s, majorant_factor: 0.25, majorant_repair: false", TRACKERS[i]);
        ms[i] = (mt_spec){TRACKERS[i], keys[i], 0};
    }
    ms[NTR] = (mt_spec){"decomposition_c10", "type: decomposition, control: 10, repair: false", 0};
    murk_scene *s = mt_load_media("runtime.yaml", common, "", ms, NTR + 1);
    if (D < 0)
        D = mt_quadrature(&s->media[0].m, ray);
    printf("%s (optical depth %.4f per unit extinction)\n", name, D);
    double T[3], S[3], Td[3], Sd[3], dense = wgrey > 0.0 ? 0.3 : 0.5;
    for (int c = 0; c < 3; c++) {
        T[c] = exp(-mt_sigma_t[chroma][c] * D);
        S[c] = mt_sigma_s[chroma][c] / mt_sigma_t[chroma][c] * (1.0 - T[c]);
        Td[c] = exp(-mt_sigma_t[chroma][c] * D * (1.0 + dense));
        Sd[c] = mt_sigma_s[chroma][c] / mt_sigma_t[chroma][c] * (1.0 - Td[c]);
    }
    int fails = 0;
    for (int i = 0; i < NTR + 1; i++) {
        double w = !(wgrey > 0.0) ? WMAX : chroma ? WCHROMA : (i == 4 ? 3.0 : 1.0) * wgrey;
        rstats st;
        run(&s->media[i].m, ray, N_RUN, 500 + (uint64_t)i, &st);
        char head[96], tail[64];
        snprintf(tail, sizeof tail, "  max |weight| %.3g", st.wmax);
        snprintf(head, sizeof head, "  %-18s T      ", ms[i].label);
        fails += mt_check_bounded(head, &st.T, T, 1.0001, ""); /* ratio-tracking factors |1 - x|, x in [0, 2] */
        snprintf(head, sizeof head, "  %-18s pass   ", ms[i].label);
        fails += mt_check_bounded(head, &st.pass, T, w, tail);
        snprintf(head, sizeof head, "  %-18s scatter", ms[i].label);
        fails += mt_check_bounded(head, &st.scat, S, w, "");
        if (st.nonfinite || !(st.wmax < WMAX)) {
            printf("  %-18s %ld non-finite, max |weight| %.3g  <-- FAIL\n", ms[i].label, st.nonfinite, st.wmax);
            fails++;
        }
        /* the must-fail case: the same figures against a denser medium's closed forms */
        double z = fmax(mt_zmax_bounded(&st.pass, Td, w), mt_zmax_bounded(&st.scat, Sd, w));
        char label[96];
        snprintf(label, sizeof label, "%s %s pass, scatter against a %g%% denser medium", chroma ? "chromatic" : "grey",
                 ms[i].label, 100.0 * dense);
        fails += !stat_must_fail(label, z > STAT_Z, z);
    }
    murk_scene_free(s);
    return fails;
}

static void test_runtime_repair_constant(void **state)
{
    (void)state;
    int fails = 0;
    murk_ray ray = {murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(1, 2, -2)), 0.0f, 1.5f};
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[256];
        snprintf(common, sizeof common, "density: { constant: 0.5 }, %s", mt_sigma_keys(chroma));
        fails += check_runtime(chroma ? "constant 0.5, chromatic, repairs off" : "constant 0.5, grey, repairs off",
                               common, &ray, 0.75, chroma, 7.0001);
    }
    assert_int_equal(fails, 0);
}

static void test_runtime_repair_sinus(void **state)
{
    (void)state;
    int fails = 0;
    mt_case sc = mt_sinus_case();
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[1024];
        snprintf(common, sizeof common, "density: { grid: %s }, %s", sc.grid, mt_sigma_keys(chroma));
        fails += check_runtime(chroma ? "sinusoid, chromatic, repairs off" : "sinusoid, grey, repairs off", common,
                               &sc.ray, -1.0, chroma, 0.0);
    }
    assert_int_equal(fails, 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_repair_is_exact),
        cmocka_unit_test(test_runtime_repair_constant),
        cmocka_unit_test(test_runtime_repair_sinus),
    };
    return STAT_RUN(tests, argc, argv);
}
