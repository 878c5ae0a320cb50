/* test_fields.c — a medium's fields beside density (murk/medium.h): albedo, emission, temperature.
 *   - emission, closed form: a homogeneous, purely absorbing slab of thickness d emitting Le, seen along
 *     its normal, gives Le (1 - exp(-sigma_a d)) per channel: every tracker (and the SDK's example_delta),
 *     grey and chromatic sigma_a, within STAT_Z (5) standard errors; and the same figures would have shown a 1 %
 *     error in the emission (must-fail: each is also checked against 1.01 x the closed form, and fails);
 *   - a scattering, emitting medium with an albedo grid: every tracker's mean emitted radiance and mean
 *     scattering weight agree with delta tracking's on the same ray (z-test, 4 sigma);
 *   - albedo: a constant albedo renders the bits of the sigma_a / sigma_s it stands for; an albedo grid
 *     constant at that value gives, tracker by tracker, the same scattering weights within noise;
 *   - blackbody: the CIE 1931 chromaticities of Planck's law at 2000, 4000 and 6500 K against the
 *     published Planckian locus (Wyszecki and Stiles, Color Science, 1982: (0.5267, 0.4133), (0.3805,
 *     0.3768), (0.3135, 0.3237)), and murk's XYZ against this test's own integration of Planck's law
 *     (Simpson's rule on the same 5 nm table) within 1e-3;
 *   - bad input: negative or NaN emission / temperature / albedo, albedo above 1, temperature keys
 *     without a temperature, a tracker built before ABI 1.9 on a medium with fields: located errors,
 *     nothing written; density and temperature grids of different boxes and sizes are allowed;
 *   - plugins of older minors: a 1.8 tracker on a medium without fields and a 1.7 integrator on a medium with
 *     an albedo field render; the 1.7 integrator on an emitting medium is refused, located;
 *   - determinism: explosion.yaml (three trackers) and dense_cloud_sun.yaml give the same bits at 1 and 3
 *     threads. */
#include "mediatest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const trackers[] = {"delta", "decomposition", "spectral", "spectral_mis", "naive_spectral",
                                       "example_delta"};
#define NTRACKERS 6

static int setup(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", build_path("tests/fixtures"), 1); /* example_delta */
    murk_set_quiet(1);
    return 0;
}

/* One flight as an integrator of ABI 1.9 makes it (beta 1, pdf ratios 1, uniform hero): x = emitted, y =
 * the event's weight over its mean pdf ratio. */
static void flight(const murk_medium *m, const murk_ray *ray, murk_rng *rng, double x[3], double y[3])
{
    murk_path_ctx ctx = {.hero = mt_hero(rng), .beta = murk_rgb1(1.0f), .pdf_ratio = murk_rgb1(1.0f), .flags = 0};
    murk_medium_event ev;
    ev.emitted = murk_rgb1(0.0f);
    ev.null_prob = -1.0f;
    m->vt->sample(m->self, ray, &ctx, rng, &ev);
    double mp = ((double)ev.pdf_ratio.c[0] + ev.pdf_ratio.c[1] + ev.pdf_ratio.c[2]) / 3.0;
    for (int c = 0; c < 3; c++) {
        x[c] = ev.emitted.c[c];
        y[c] = mp > 0.0 ? ev.weight.c[c] / mp : 0.0;
    }
}

static murk_scene *load_trackers(const char *file, const char *common)
{
    mt_spec ms[NTRACKERS];
    for (int i = 0; i < NTRACKERS; i++)
        ms[i] = (mt_spec){trackers[i], trackers[i], 0};
    return mt_load_media(file, common, "type: ", ms, NTRACKERS);
}

static void test_emission_slab(void **state)
{
    (void)state;
    static const double le[3] = {1.0, 2.0, 3.0}, sa[2][3] = {{1.0, 1.0, 1.0}, {0.5, 1.0, 2.0}}, d = 1.5;
    long n = 200000;
    int bad = 0, seen = 0;
    for (int chroma = 0; chroma < 2; chroma++) {
        char common[256];
        snprintf(common, sizeof common, "density: { constant: 1 }, sigma_a: [%g, %g, %g], sigma_s: 0, emission: "
                 "[1, 2, 3]", sa[chroma][0], sa[chroma][1], sa[chroma][2]);
        murk_scene *s = load_trackers("slab.yaml", common);
        double expect[3], off[3];
        for (int c = 0; c < 3; c++) {
            expect[c] = le[c] * (1.0 - exp(-sa[chroma][c] * d));
            off[c] = 1.01 * expect[c];
        }
        murk_ray ray = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, (float)d};
        for (int i = 0; i < NTRACKERS; i++) {
            murk_rng rng;
            murk_rng_seed(&rng, 11, (uint64_t)i, (uint64_t)chroma);
            mt_acc a = {0};
            long nk = strcmp(trackers[i], "naive_spectral") ? n : 10 * n; /* one channel per flight, x3 */
            for (long k = 0; k < nk; k++) {
                double x[3], y[3];
                flight(&s->media[i].m, &ray, &rng, x, y);
                mt_acc_add(&a, x);
            }
            char head[96];
            snprintf(head, sizeof head, "%-15s %-9s", trackers[i], chroma ? "chromatic" : "grey");
            bad += mt_check(head, &a, expect, 0.0, "") != 0;
            /* the must-fail: the same figures against a 1 % brighter emission */
            int off_seen = mt_zmax(&a, off, 0.0) > STAT_Z;
            printf("%*s a 1%% error in Le: %s\n", 25, "", off_seen ? "seen" : "NOT SEEN");
            seen += off_seen;
        }
        murk_scene_free(s);
    }
    assert_int_equal(bad, 0);
    assert_int_equal(seen, 2 * NTRACKERS);
}

/* sigma_t 1.2 / 1.5 / 3.1 per unit density over the sinusoid grid; albedo from a 3-channel grid; emission a
 * grey grid times a temperature cloud. */
static float alb_r(int x, int y, int z, float cx, float cy, float cz)
{
    (void)x, (void)y, (void)z, (void)cy, (void)cz;
    return 0.5f + 0.4f * sinf(3.0f * cx);
}

/* Writes tmp_dir()/name, a .vol of res^3 voxels and ch channels over [-1, 1]^3, as is (no checks: bad
 * values stay bad). */
static const char *write_vol(const char *name, int res, int ch, const float *v)
{
    unsigned char h[48] = {'V', 'O', 'L', 3};
    int32_t hdr[5] = {1, res, res, res, ch};
    float box[6] = {-1, -1, -1, 1, 1, 1};
    memcpy(h + 4, hdr, sizeof hdr);
    memcpy(h + 24, box, sizeof box);
    const char *path = tmp_path(name);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fwrite(h, 1, 48, fp);
    fwrite(v, sizeof *v, (size_t)ch * res * res * res, fp);
    fclose(fp);
    return path;
}

/* An RGB .vol: red f (or g where f is NULL), green g x red (g where f is NULL), blue b. */
static const char *save_rgb_vol(const char *name, int res, float (*f)(int, int, int, float, float, float), float g,
                                float b)
{
    size_t n = (size_t)res * res * res;
    float *v = malloc(3 * n * sizeof *v);
    size_t i = 0;
    for (int z = 0; z < res; z++)
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++, i++) {
                float c[3] = {-1.0f + 2.0f * (x + 0.5f) / res, -1.0f + 2.0f * (y + 0.5f) / res, -1.0f + 2.0f * (z + 0.5f) / res};
                v[3 * i] = f ? f(x, y, z, c[0], c[1], c[2]) : g;
                v[3 * i + 1] = f ? g * v[3 * i] : g;
                v[3 * i + 2] = b;
            }
    const char *path = write_vol(name, res, 3, v);
    free(v);
    return path;
}

static void compare_to_delta(const char *label, murk_scene *s, const murk_ray *ray, long n, int *bad)
{
    mt_acc ax[NTRACKERS], ay[NTRACKERS];
    for (int i = 0; i < NTRACKERS; i++) {
        murk_rng rng;
        murk_rng_seed(&rng, 23, (uint64_t)i, 7);
        memset(&ax[i], 0, sizeof ax[i]);
        memset(&ay[i], 0, sizeof ay[i]);
        for (long k = 0; k < n; k++) {
            double x[3], y[3];
            flight(&s->media[i].m, ray, &rng, x, y);
            mt_acc_add(&ax[i], x);
            mt_acc_add(&ay[i], y);
        }
    }
    for (int i = 1; i < NTRACKERS; i++) {
        double zx = 0.0, zy = 0.0;
        int ok = 1;
        for (int c = 0; c < 3; c++) {
            double sx = hypot(mt_se(&ax[i], c), mt_se(&ax[0], c)), sy = hypot(mt_se(&ay[i], c), mt_se(&ay[0], c));
            zx = fmax(zx, sx > 0 ? fabs(mt_mean(&ax[i], c) - mt_mean(&ax[0], c)) / sx : 0.0);
            zy = fmax(zy, sy > 0 ? fabs(mt_mean(&ay[i], c) - mt_mean(&ay[0], c)) / sy : 0.0);
            ok &= stat_z_ok(mt_mean(&ax[i], c), sx, mt_mean(&ax[0], c), 0.0);
            ok &= stat_z_ok(mt_mean(&ay[i], c), sy, mt_mean(&ay[0], c), 0.0);
        }
        printf("%-9s %-15s vs delta: emitted %.4f %.4f %.4f (|z| <= %.1f), weight (|z| <= %.1f)%s\n", label,
               trackers[i], mt_mean(&ax[i], 0), mt_mean(&ax[i], 1), mt_mean(&ax[i], 2), zx, zy,
               ok ? "" : "  <-- FAIL");
        *bad += !ok;
    }
}

static void test_emission_scattering(void **state)
{
    (void)state;
    const char *dens = mt_save_grid("sinus_e.vol", (int[]){16, 16, 16}, murk_v3(-1, -1, -1), murk_v3(1, 1, 1), mt_sinus_f);
    const char *alb = save_rgb_vol("albedo.vol", 8, alb_r, 0.8f, 0.3f);
    char common[1024];
    snprintf(common, sizeof common, "density: { grid: %s }, scale: 4, sigma_a: [0.2, 1, 3], sigma_s: [1, 0.5, 0.1], "
             "albedo: { grid: %s }, emission: [1, 1.5, 2], temperature: { cloud: { min: [-1, -1, -1], max: [1, 1, 1], "
             "resolution: 16, seed: 3 } }, temperature_scale: 3000", dens, alb);
    murk_scene *s = load_trackers("scatter_emit.yaml", common);
    murk_ray ray = {murk_v3(-1.5f, -0.2f, 0.1f), murk_normalize(murk_v3(1, 0.1f, -0.05f)), 0.0f, 4.0f};
    int bad = 0;
    compare_to_delta("emitting", s, &ray, 100000, &bad);
    murk_scene_free(s);
    assert_int_equal(bad, 0);
}

/* The constant albedo 0.75 of sigma_t 1 is sigma_a 0.25, sigma_s 0.75 exactly: the same image, bit for bit. */
static void test_albedo_constant_bitwise(void **state)
{
    (void)state;
    const char *fmt = "murk: 1\nrender: { resolution: [20, 20], spp: 8, seed: 2 }\n"
                      "camera: { from: [0, 0, 3], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
                      "integrator: { type: volpath_nee }\nbackground: [0.5, 0.6, 0.7]\n"
                      "media: { fog: { type: spectral, density: { cloud: { resolution: 16 } }, scale: 6, %s } }\n"
                      "shapes:\n  - { type: box, min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5], interior: fog }\n";
    char a[1024], b[1024], oa[512], ob[512];
    snprintf(a, sizeof a, fmt, "sigma_a: [0.25, 0.5, 0.125], sigma_s: [0.75, 0.5, 0.875]");
    snprintf(b, sizeof b, fmt, "sigma_a: 0, sigma_s: 1, albedo: [0.75, 0.5, 0.875]");
    const char *pa = write_tmp("alb_sig.yaml", a), *pb = write_tmp("alb_const.yaml", b);
    snprintf(oa, sizeof oa, "%s", tmp_path("alb_sig.exr"));
    snprintf(ob, sizeof ob, "%s", tmp_path("alb_const.exr"));
    run_murk_ok((const char *const[]){"render", pa, "-o", oa, "--quiet", "--threads", "2", NULL}, NULL);
    run_murk_ok((const char *const[]){"render", pb, "-o", ob, "--quiet", "--threads", "2", NULL}, NULL);
    assert_same_pixels(oa, ob);
}

/* An albedo grid that is 0.75 / 0.5 / 0.875 everywhere against the same constant: per tracker, the flights'
 * weights agree within noise (a field takes the other code path, so not bitwise). */
static void test_albedo_grid_constant(void **state)
{
    (void)state;
    const char *dens = mt_save_grid("sinus_a.vol", (int[]){16, 16, 16}, murk_v3(-1, -1, -1), murk_v3(1, 1, 1), mt_sinus_f);
    const char *alb = save_rgb_vol("albedo_c.vol", 4, NULL, 0.5f, 0.875f); /* (0.5, 0.5, 0.875) everywhere */
    char ca[512], cb[512];
    snprintf(ca, sizeof ca, "density: { grid: %s }, scale: 3, sigma_a: [0.5, 1, 0.25], sigma_s: [0.5, 1, 1.75]", dens);
    snprintf(cb, sizeof cb, "density: { grid: %s }, scale: 3, sigma_a: 0, sigma_s: [1, 2, 2], albedo: { grid: %s }", dens, alb);
    murk_ray ray = {murk_v3(-1.5f, 0.2f, 0.1f), murk_normalize(murk_v3(1, -0.1f, 0.05f)), 0.0f, 4.0f};
    int bad = 0;
    for (int i = 0; i < NTRACKERS; i++) {
        mt_spec ms[2] = {{"consts", trackers[i], 0}, {"field", trackers[i], 0}};
        char keys[2][1200];
        snprintf(keys[0], sizeof keys[0], "%s, %s", trackers[i], ca);
        snprintf(keys[1], sizeof keys[1], "%s, %s", trackers[i], cb);
        ms[0].keys = keys[0];
        ms[1].keys = keys[1];
        murk_scene *s = mt_load_media("albedo_grid.yaml", "stratify_flights: false", "type: ", ms, 2);
        mt_acc acc[2];
        for (int j = 0; j < 2; j++) {
            murk_rng rng;
            murk_rng_seed(&rng, 31, (uint64_t)i, (uint64_t)j);
            memset(&acc[j], 0, sizeof acc[j]);
            for (long k = 0; k < 100000; k++) {
                double x[3], y[3];
                flight(&s->media[j].m, &ray, &rng, x, y);
                mt_acc_add(&acc[j], y);
            }
        }
        double z = 0.0;
        int ok = 1;
        for (int c = 0; c < 3; c++) {
            double se = hypot(mt_se(&acc[0], c), mt_se(&acc[1], c));
            z = fmax(z, fabs(mt_mean(&acc[0], c) - mt_mean(&acc[1], c)) / se);
            ok &= stat_z_ok(mt_mean(&acc[1], c), se, mt_mean(&acc[0], c), 0.0);
        }
        printf("albedo grid %-15s weights %.4f %.4f %.4f vs constants %.4f %.4f %.4f (|z| <= %.1f)\n", trackers[i],
               mt_mean(&acc[1], 0), mt_mean(&acc[1], 1), mt_mean(&acc[1], 2), mt_mean(&acc[0], 0), mt_mean(&acc[0], 1),
               mt_mean(&acc[0], 2), z);
        bad += !ok;
        murk_scene_free(s);
    }
    assert_int_equal(bad, 0);
}

/* Planck's law integrated by Simpson's rule on the table murk uses (the test's own Planck, in double,
 * without expm1), normalised to its peak: XYZ / sum ybar. */
static void planck_simpson(double T, double xyz[3])
{
    const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23, lmax = 2.897771955e-3 / T;
    double peak = 2.0 * h * c * c / pow(lmax, 5) / (exp(h * c / (lmax * k * T)) - 1.0), ysum = 0.0;
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    for (int i = 0; i < 95; i++) {
        double l = (360.0 + 5.0 * i) * 1e-9, w = (i == 0 || i == 94) ? 1.0 : (i & 1) ? 4.0 : 2.0;
        double b = 2.0 * h * c * c / pow(l, 5) / (exp(h * c / (l * k * T)) - 1.0) / peak, cmf[3];
        murk_cie1931(i, cmf);
        for (int j = 0; j < 3; j++)
            xyz[j] += w * b * cmf[j];
        ysum += w * cmf[1];
    }
    for (int j = 0; j < 3; j++)
        xyz[j] /= ysum;
}

static void test_blackbody(void **state)
{
    (void)state;
    static const double T[3] = {2000.0, 4000.0, 6500.0}, ref[3][2] = {{0.5267, 0.4133}, {0.3805, 0.3768}, {0.3135, 0.3237}};
    for (int i = 0; i < 3; i++) {
        double m[3], r[3];
        murk_blackbody_xyz(T[i], m);
        planck_simpson(T[i], r);
        double x = m[0] / (m[0] + m[1] + m[2]), y = m[1] / (m[0] + m[1] + m[2]), worst = 0.0;
        for (int j = 0; j < 3; j++)
            worst = fmax(worst, fabs(m[j] - r[j]) / r[1]);
        printf("%5.0f K: xy %.4f %.4f (published %.4f %.4f), Y %.5f, XYZ vs Simpson max rel %.1e\n", T[i], x, y,
               ref[i][0], ref[i][1], m[1], worst);
        assert_true(fabs(x - ref[i][0]) <= 3e-4 && fabs(y - ref[i][1]) <= 3e-4);
        assert_true(worst <= 1e-3);
        murk_rgb c = murk_blackbody_rgb(T[i]);
        assert_true(c.c[0] >= 0.0f && c.c[1] >= 0.0f && c.c[2] >= 0.0f);
    }
    /* the table the renderer reads agrees with the function between its entries */
    murk_blackbody_table t;
    assert_int_equal(murk_blackbody_table_build(&t, 6000.0), 0);
    for (double Tk = 1000.0; Tk <= 6000.0; Tk += 437.3) {
        murk_rgb a = murk_blackbody_lookup(&t, (float)Tk), b = murk_blackbody_rgb(Tk);
        for (int j = 0; j < 3; j++)
            assert_true(fabs(a.c[j] - b.c[j]) <= 2e-3 * fmax(b.c[j], 1e-3 * b.c[0]) + 1e-9);
    }
    murk_blackbody_table_free(&t);
}

/* A scene of one medium (tracker and keys) in a box, rendered by integrator; its file's path. */
static const char *box_scene(const char *name, const char *integrator, const char *tracker, const char *keys)
{
    char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\n"
             "camera: { from: [0, 0, 3], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
             "integrator: { type: %s }\n"
             "media: { fire: { type: %s, density: { constant: 1 }, sigma_a: 1, %s } }\n"
             "shapes:\n  - { type: box, min: [-0.5, -0.5, -0.5], max: [0.5, 0.5, 0.5], interior: fire }\n",
             integrator, tracker, keys);
    return write_tmp(name, text);
}

static void expect_error_with(const char *name, const char *integrator, const char *tracker, const char *keys,
                              const char *what)
{
    char out_exr[512], *out;
    const char *path = box_scene(name, integrator, tracker, keys);
    snprintf(out_exr, sizeof out_exr, "%s.exr", path);
    unlink(out_exr);
    int rc = run_murk(&out, "render", path, "-o", out_exr, "--quiet", NULL);
    printf("%s\n  -> %s", keys, out);
    assert_int_not_equal(rc, 0);
    char loc[600];
    snprintf(loc, sizeof loc, "%s:5:", path);
    assert_contains(out, loc);
    assert_contains(out, what);
    assert_int_not_equal(access(out_exr, F_OK), 0);
    free(out);
}

static void expect_error(const char *name, const char *tracker, const char *keys, const char *what)
{
    expect_error_with(name, "volpath_nee", tracker, keys, what);
}

/* Plugins of the minors before fields still load: a tracker of ABI 1.8 on a medium without fields, an
 * integrator of 1.7 on a medium with an albedo field (trackers apply it); the emission such an integrator
 * could not collect is refused at the medium's emission key. */
static void test_old_plugins(void **state)
{
    (void)state;
    static const char *const ok[][3] = {{"old_tr.yaml", "volpath_nee", "old_tracker"},
                                        {"old_int.yaml", "old_integrator", "delta"}};
    static const char *const keys[] = {"sigma_s: 1", "sigma_s: 1, albedo: { cloud: { resolution: 8 } }"};
    for (int i = 0; i < 2; i++) {
        char out_exr[512];
        const char *path = box_scene(ok[i][0], ok[i][1], ok[i][2], keys[i]);
        snprintf(out_exr, sizeof out_exr, "%s.exr", path);
        run_murk_ok((const char *const[]){"render", path, "-o", out_exr, "--quiet", NULL}, NULL);
    }
    expect_error_with("old_int_emit.yaml", "old_integrator", "delta", "emission: [1, 2, 3]",
                      "before volume emission");
}

static void test_bad_input(void **state)
{
    (void)state;
    expect_error("e_neg.yaml", "delta", "emission: [1, -1, 1]", "emission must be");
    expect_error("e_nan.yaml", "delta", "emission: [1, .nan, 1]", "emission");
    expect_error("a_hi.yaml", "delta", "albedo: 1.2", "albedo must be");
    expect_error("a_neg.yaml", "delta", "albedo: [0.5, -0.1, 0.5]", "albedo must be");
    char keys[1024];
    const char *hi = save_rgb_vol("albedo_hi.vol", 4, NULL, 0.5f, 1.25f);
    snprintf(keys, sizeof keys, "albedo: { grid: %s }", hi);
    expect_error("a_grid.yaml", "delta", keys, "is above 1");
    float t[64], e[3 * 64];
    for (int i = 0; i < 64; i++) {
        t[i] = i == 21 ? -5.0f : 300.0f;
        e[3 * i] = e[3 * i + 1] = 1.0f;
        e[3 * i + 2] = i == 5 ? NAN : 1.0f;
    }
    snprintf(keys, sizeof keys, "temperature: { grid: %s }", write_vol("temp_neg.vol", 4, 1, t));
    expect_error("t_neg.yaml", "delta", keys, "negative");
    snprintf(keys, sizeof keys, "emission: { grid: %s }", write_vol("e_nan.vol", 4, 3, e));
    expect_error("e_grid.yaml", "delta", keys, "invalid value");
    expect_error("t_scale.yaml", "delta", "temperature_scale: 100", "need a temperature field");
    expect_error("t_const.yaml", "delta", "temperature: { constant: -3 }", "temperature.constant must be");
    expect_error("old.yaml", "old_tracker", "emission: 1", "built for plugin ABI 1.8");
}

/* Density and temperature of different boxes and resolutions: allowed (each field has its own box, 0
 * outside it); the render finishes with finite pixels. */
static void test_different_boxes(void **state)
{
    (void)state;
    const char *dens = mt_save_grid("dens_box.vol", (int[]){8, 8, 8}, murk_v3(-0.5f, -0.5f, -0.5f), murk_v3(0.5f, 0.5f, 0.5f),
                                    mt_sinus_f);
    char text[2048], out_exr[512];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [16, 16], spp: 4 }\n"
             "camera: { from: [0, 0, 3], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\nintegrator: { type: volpath }\n"
             "media: { fire: { type: spectral_mis, density: { grid: %s }, scale: 5, sigma_a: 1, sigma_s: 1, "
             "temperature: { cloud: { min: [-0.2, -0.9, -0.3], max: [0.9, 0.3, 0.4], resolution: 12 } }, "
             "temperature_scale: 2500 } }\n"
             "shapes:\n  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: fire }\n", dens);
    const char *path = write_tmp("boxes.yaml", text);
    snprintf(out_exr, sizeof out_exr, "%s.exr", path);
    run_murk_ok((const char *const[]){"render", path, "-o", out_exr, "--quiet", NULL}, NULL);
}

/* The scenes render the same bits for any thread count: the explosion (emission from a temperature
 * field, every tracker that collects it) at 1 and 3 threads, and dense_cloud_sun (hg_draine, the sky). */
static void test_deterministic(void **state)
{
    (void)state;
    static const char *const runs[][2] = {{"explosion", "spectral_mis"}, {"explosion", "decomposition"},
                                          {"explosion", "delta"}, {"dense_cloud_sun", "decomposition"}};
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
        char scene[512], type[128], name[64], out[2][512];
        snprintf(scene, sizeof scene, "scenes/%s.yaml", runs[i][0]);
        snprintf(type, sizeof type, "media.%s.type=%s", strcmp(runs[i][0], "explosion") ? "cloud" : "fire",
                 runs[i][1]);
        for (int k = 0; k < 2; k++) {
            snprintf(name, sizeof name, "det_%zu_%d.exr", i, k);
            snprintf(out[k], sizeof out[k], "%s", tmp_path(name));
            run_murk_ok((const char *const[]){"render", src_path(scene), "-o", out[k], "--quiet", "--threads",
                                              k ? "3" : "1", "--spp", "2", "--set", "render.resolution=[24,24]",
                                              "--set", type, NULL}, NULL);
        }
        assert_same_pixels(out[0], out[1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_emission_slab),
        cmocka_unit_test(test_emission_scattering),
        cmocka_unit_test(test_albedo_constant_bitwise),
        cmocka_unit_test(test_albedo_grid_constant),
        cmocka_unit_test(test_blackbody),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_old_plugins),
        cmocka_unit_test(test_different_boxes),
        cmocka_unit_test(test_deterministic),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
