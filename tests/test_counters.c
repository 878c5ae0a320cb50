/* test_counters.c — the cost counters (murk/counters.h): a closed form for tentative collisions, every
 * estimator's and tracker's collisions against its lookups, zero lookups without media, and per-thread
 * counts that merge to the same totals on any thread count. */
#include "mediatest.h"
#include "stat.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Delta tracking in a homogeneous slab of extinction mu and length L, with the majorant f x mu: the
 * tentative collisions are a Poisson process of rate f mu, thinned with probability 1/f into the real
 * ones, and the flight stops at the first real one or at L. So the mean number of tentative collisions
 * per flight is  f mu E[min(L, Exp(mu))] = f (1 - exp(-mu L))  (f mu L when mu L is small), and every
 * flight scatters with probability 1 - exp(-mu L). Checked within STAT_Z standard errors of the sample
 * (the per-flight counts' own variance; stat.h), on 200 000 flights; the lookups equal the collisions.
 * Must-fail: the counts against those of a majorant 3 % larger, the scattered fraction against a medium
 * 5 % denser. */
static void slab_closed_form(void **state)
{
    (void)state;
    const double f = 4.0, mu = 1.2 * 0.5, L = 1.5; /* sigma_t 1.2 x density 0.5 */
    const mt_spec spec = {"slab", "type: delta", 0};
    murk_scene *s = mt_load_media("slab.yaml", MT_GREY_KEYS ", density: { constant: 0.5 }, majorant_factor: 4", "",
                                  &spec, 1);
    const murk_medium *m = &s->media[0].m;
    murk_host_thread_reset();
    murk_rng rng;
    murk_rng_seed(&rng, 17, 0, 0);
    const int n = 200000;
    double sum = 0, sum2 = 0;
    uint64_t scattered = 0;
    for (int i = 0; i < n; i++) {
        murk_ray ray = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, (float)L};
        murk_path_ctx ctx = {0, murk_rgb1(1.0f)};
        murk_medium_event ev;
        uint64_t before = murk_thread_counters[0].collisions;
        m->vt->sample(m->self, &ray, &ctx, &rng, &ev);
        double k = (double)(murk_thread_counters[0].collisions - before);
        sum += k;
        sum2 += k * k;
        scattered += ev.scattered != 0;
    }
    double mean = sum / n, var = (sum2 - sum * sum / n) / (n - 1), se = sqrt(var / n);
    double expect = f * (1.0 - exp(-mu * L));
    printf("slab: %.5f tentative collisions per flight (closed form %.5f, se %.5f)\n", mean, expect, se);
    assert_true(stat_z_ok(mean, se, expect, 0.0));
    double zf = fabs(mean - 1.03 * expect) / se;
    assert_true(stat_must_fail("tentative collisions against a majorant 3% larger", zf > STAT_Z, zf));
    const murk_counters *c = &murk_thread_counters[0];
    assert_true(c->lookups == c->collisions);
    assert_true(c->scatters == scattered);
    double ps = 1.0 - exp(-mu * L), sp = sqrt(ps * (1.0 - ps) / n);
    assert_true(stat_z_ok((double)scattered / n, sp, ps, 0.0));
    double pd = 1.0 - exp(-1.05 * mu * L), zd = fabs((double)scattered / n - pd) / sp;
    assert_true(stat_must_fail("scattered fraction against a medium 5% denser", zd > STAT_Z, zd));
    assert_true(c->cells >= (uint64_t)n); /* every flight enters the constant field's one cell */
    murk_scene_free(s);
}

/* The collisions every estimator and tracker counts, against its lookups (murk/counters.h), on a
 * constant medium (density 0.5, sigma_t 1.2, majorant_factor 2: tau_bar = 2.4 on a ray of length 2):
 *  - the transmittance estimators that draw points (ratio, residual_ratio, track_length, power_series)
 *    read the density once per point and nowhere else: collisions == lookups > 0, exactly;
 *  - the ray marchers (raymarch, unbiased_raymarch) draw no collision points: 0 collisions, lookups > 0;
 *  - power_series' one chunk (tau_bar 2.4 < chunk_depth 4) has N = max(K, k0) points, K ~ Poisson(2.4)
 *    and k0 the order where the Poisson CMF reaches 1 - 1e-8: E[collisions] = sum_k max(k, k0) Pois(k),
 *    checked within 4 se (+ 1e-9 relative: N is k0 but for a 1e-8 tail, so se is about 0);
 *  - every tracker's free flights (sample()) and its own transmittance(): collisions == lookups > 0,
 *    but decomposition's control collisions, which read no density and end the flight:
 *    lookups <= collisions <= lookups + flights.
 * power_series once counted nothing (bench.csv's collisions column 0): the first check failed. */
static void collisions_match_lookups(void **state)
{
    (void)state;
    static const mt_spec est[] = {
        {"ratio", "type: delta, transmittance: ratio", 0},
        {"residual_ratio", "type: delta, transmittance: { type: residual_ratio, control: 0.5 }", 0},
        {"track_length", "type: delta, transmittance: track_length", 0},
        {"power_series", "type: delta, transmittance: power_series", 0},
        {"raymarch", "type: delta, transmittance: raymarch", 0},
        {"unbiased_raymarch", "type: delta, transmittance: unbiased_raymarch", 0},
        {"delta", "type: delta", 0},
        {"spectral", "type: spectral", 0},
        {"naive_spectral", "type: naive_spectral", 0},
        {"spectral_mis", "type: spectral_mis", 0},
        {"decomposition", "type: decomposition", 0},
    };
    enum { NEST = sizeof est / sizeof est[0], NPOINTS = 4, NRAYMARCH = 6 };
    const double L = 2.0, tau = 2.0 * 0.5 * 1.2 * L; /* majorant_factor x density x sigma_t x length */
    murk_scene *s = mt_load_media("collide.yaml", MT_GREY_KEYS ", density: { constant: 0.5 }, majorant_factor: 2",
                                  "", est, NEST);
    const int n = 20000;
    for (int e = 0; e < NEST; e++) {
        const murk_medium *m = &s->media[e].m;
        int calls = e < NRAYMARCH ? 1 : 2; /* an estimator: transmittance(); a tracker: sample() too */
        for (int call = 0; call < calls; call++) {
            murk_host_thread_reset();
            murk_rng rng;
            murk_rng_seed(&rng, 29, (uint64_t)e, (uint64_t)call);
            double sum = 0, sum2 = 0;
            for (int i = 0; i < n; i++) {
                murk_ray ray = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, (float)L};
                murk_path_ctx ctx = {mt_hero(&rng), murk_rgb1(1.0f)};
                murk_medium_event ev;
                uint64_t before = murk_thread_counters[e].collisions;
                if (call == 0)
                    (void)murk_medium_transmittance(m, &ray, &ctx, &rng);
                else
                    m->vt->sample(m->self, &ray, &ctx, &rng, &ev);
                double k = (double)(murk_thread_counters[e].collisions - before);
                sum += k;
                sum2 += k * k;
            }
            const murk_counters *c = &murk_thread_counters[e];
            printf("%-18s %-13s %9llu collisions %9llu lookups (%.4f per call)\n", est[e].label,
                   call ? "sample" : "transmittance", (unsigned long long)c->collisions,
                   (unsigned long long)c->lookups, sum / n);
            assert_true(c->lookups > 0);
            if (e >= NPOINTS && e < NRAYMARCH) {
                assert_true(c->collisions == 0);
            } else if (call == 1 && !strcmp(est[e].label, "decomposition")) {
                assert_true(c->collisions >= c->lookups && c->collisions <= c->lookups + (uint64_t)n);
                assert_true(c->collisions > c->lookups); /* some flights end at a control collision */
            } else {
                assert_true(c->collisions == c->lookups);
            }
            if (!strcmp(est[e].label, "power_series")) {
                int k0 = 0; /* as power_series.c finds it */
                double pk = exp(-tau), cmf = pk, expect = 0.0, pj = exp(-tau);
                while (cmf < 1.0 - 1e-8) {
                    k0++;
                    pk *= tau / k0;
                    cmf += pk;
                }
                for (int j = 0; j < 200; j++) {
                    if (j > 0)
                        pj *= tau / j;
                    expect += (j > k0 ? j : k0) * pj;
                }
                double mean = sum / n, se = sqrt(fmax(0.0, (sum2 - sum * sum / n) / (n - 1)) / n);
                printf("  power_series: %.6f points per estimate, E max(K, k0 = %d) = %.6f\n", mean, k0, expect);
                assert_true(stat_z_ok(mean, se, expect, 1e-9 * expect));
                double zp = (fabs(mean - (expect + 0.01)) - 1e-9 * expect) / se;
                assert_true(stat_must_fail("power_series points against 0.01 more per estimate", zp > STAT_Z, zp));
            }
        }
    }
    murk_scene_free(s);
}

static murk_render_result render(const char *file, const char *text, int threads)
{
    char err[2048];
    murk_scene *s = murk_scene_load(write_tmp(file, text), NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    murk_render_opts o = {.spp = 2, .threads = threads};
    murk_render_result r;
    assert_int_equal(murk_render(s, &o, &r), 0);
    free(r.rgb);
    r.rgb = NULL;
    murk_scene_free(s);
    return r;
}

static const char box_head[] =
    "murk: 1\nrender: { resolution: [24, 24], spp: 2, seed: 3 }\n"
    "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
    "integrator: { type: volpath_nee, max_depth: 16 }\nbackground: [0.5, 0.5, 0.5]\n"
    "materials: { white: { type: diffuse, albedo: 0.7 } }\n";

/* No media: no lookups, cells or collisions; the rays are still counted. */
static void no_media_no_lookups(void **state)
{
    (void)state;
    char text[2048];
    snprintf(text, sizeof text, "%sshapes:\n  - { type: sphere, center: [0, 0, 0], radius: 1, material: white }\n",
             box_head);
    murk_render_result r = render("plain.yaml", text, 2);
    assert_int_equal(r.nmedia, 0);
    for (int i = 0; i < MURK_COUNTER_SLOTS; i++)
        assert_true(r.media[i].lookups == 0 && r.media[i].collisions == 0 && r.media[i].cells == 0);
    assert_true(r.rays > 0);
}

/* Two media, one with an estimator plugin: each counted in its own block, and since every pixel's
 * samples are drawn from its own random streams, the totals are the same on 1 and 3 threads. */
static void per_medium_any_threads(void **state)
{
    (void)state;
    char text[4096];
    snprintf(text, sizeof text,
             "%smedia:\n"
             "  a: { type: delta, density: { constant: 2 }, sigma_s: 1, sigma_a: 0.1 }\n"
             "  b: { type: decomposition, density: { constant: 1 }, sigma_s: 0.5, transmittance: ratio }\n"
             "shapes:\n"
             "  - { type: sphere, center: [-0.6, 0, 0], radius: 0.5, interior: a }\n"
             "  - { type: sphere, center: [0.6, 0, 0], radius: 0.5, interior: b }\n"
             "  - { type: quad, center: [0, 2, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: 5 }\n",
             box_head);
    murk_render_result r1 = render("two.yaml", text, 1), r3 = render("two.yaml", text, 3);
    assert_int_equal(r1.nmedia, 2);
    for (int i = 0; i < 2; i++) {
        const murk_counters *a = &r1.media[i], *b = &r3.media[i];
        printf("medium %d: %llu lookups, %llu cells, %llu collisions, %llu scatters, %llu shadow\n", i,
               (unsigned long long)a->lookups, (unsigned long long)a->cells, (unsigned long long)a->collisions,
               (unsigned long long)a->scatters, (unsigned long long)a->shadow);
        assert_true(a->lookups > 0 && a->cells > 0 && a->collisions > 0 && a->scatters > 0 && a->shadow > 0);
        assert_memory_equal(a, b, sizeof *a);
    }
    assert_true(r1.rays == r3.rays);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(slab_closed_form),
        cmocka_unit_test(collisions_match_lookups),
        cmocka_unit_test(no_media_no_lookups),
        cmocka_unit_test(per_medium_any_threads),
    };
    return STAT_RUN(tests, argc, argv);
}
