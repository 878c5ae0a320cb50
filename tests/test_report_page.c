/* test_report_page.c — murk's comparison page used as a person uses it, in Debian's headless Chromium
 * (tests/page_driver.py drives it over the DevTools pipe): `murk compare --html` of two EXRs this test
 * writes, then keys (flip to the reference and back, the maps, split), a click on the exposure slider,
 * the mouse over a NaN pixel, a wheel zoom; after each step the view canvas's pixels are read back and
 * compared with the tone mapping of the linear data computed here, independently of the page:
 * sRGB(clamp(v * 2^EV)) in 8 bits, +-1 for the half-float rounding of the data. NaN must show magenta and
 * infinities cyan, never black; the readout must say NaN. Also: a page over the size limit says it was
 * downsampled, a `murk bench` page builds its tables and flips, and no page loads anything from outside
 * or logs an error. Skips (77) without Chromium (tools/build.sh installs Debian's `chromium`). */
#include "testutil.h"

#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

enum { W = 48, H = 32 };

static const char *chromium(void)
{
    static const char *const where[] = {"/usr/bin/chromium", "/usr/lib/chromium/chromium"};
    const char *env = getenv("MURK_CHROMIUM");
    if (env && *env)
        return access(env, X_OK) == 0 ? env : NULL;
    for (size_t i = 0; i < sizeof where / sizeof where[0]; i++)
        if (access(where[i], X_OK) == 0)
            return where[i];
    return NULL;
}

/* The test image a and the reference r: smooth ramps over the tone curve's range (0 .. 1.3, linear toe
 * and clamp included), r = 0.9 a + 0.01; in a, pixel (5, 5) has a NaN, (6, 5) +Inf, (7, 5) -Inf. */
static float value(int which, int x, int y, int c)
{
    double v = c == 0 ? 1.3 * (x + W * y) / (W * H) : c == 1 ? 0.02 * x / W : 0.4 + 0.6 * sin(0.3 * x + 0.2 * y);
    if (which == 1)
        v = 0.9 * v + 0.01;
    if (which == 0 && y == 5 && x >= 5 && x <= 7 && c == x - 5)
        return x == 5 ? NAN : x == 6 ? INFINITY : -INFINITY;
    return (float)v;
}

static void write_exr(const char *path, int which)
{
    float *rgb = malloc(W * H * 3 * sizeof *rgb);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                rgb[3 * (y * W + x) + c] = value(which, x, y, c);
    char err[1024];
    if (murk_exr_write(path, rgb, W, H, NULL, 0, err, sizeof err) != 0)
        fail_msg("%s", err);
    free(rgb);
}

/* The expected 8-bit value: IEC 61966-2-1's sRGB encoding of v * 2^ev clamped to [0, 1]. */
static int tone(double v, double ev)
{
    double x = fmin(fmax(v * pow(2.0, ev), 0.0), 1.0);
    x = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
    return (int)floor(255 * x + 0.5);
}

/* The driver's output, consumed line by line in the order of the script's printing commands. */
typedef struct lines {
    char *text, *at;
} lines;

static const char *next(lines *l, const char *prefix)
{
    char *nl = strchr(l->at, '\n');
    if (!nl)
        fail_msg("the driver's output ended; wanted a '%s' line:\n%s", prefix, l->text);
    *nl = 0;
    const char *line = l->at;
    l->at = nl + 1;
    if (strncmp(line, prefix, strlen(prefix)) != 0)
        fail_msg("wanted a '%s' line, got '%s'; the driver's output:\n%s", prefix, line, l->text);
    return line + strlen(prefix);
}

static void next_pixel(lines *l, int x, int y, int rgb[3])
{
    int px, py, a;
    const char *s = next(l, "pixel ");
    if (sscanf(s, "%d %d %d %d %d %d", &px, &py, &rgb[0], &rgb[1], &rgb[2], &a) != 6 || px != x || py != y || a != 255)
        fail_msg("bad pixel line '%s' for (%d, %d)", s, x, y);
}

/* The next pixel line must show image `which` at (x, y) tone mapped at ev, each channel within 1. */
static int expect_tone(lines *l, int which, int x, int y, double ev)
{
    int got[3], worst = 0;
    next_pixel(l, x, y, got);
    for (int c = 0; c < 3; c++) {
        int want = tone(value(which, x, y, c), ev);
        if (abs(got[c] - want) > 1)
            fail_msg("image %d pixel (%d, %d) at %+.1f EV: channel %d shows %d, the linear %.6g tone maps to %d", which,
                     x, y, ev, c, got[c], (double)value(which, x, y, c), want);
        worst = abs(got[c] - want) > worst ? abs(got[c] - want) : worst;
    }
    return got[0] + got[1] + got[2];
}

static void expect_colour(lines *l, int x, int y, int r, int g, int b, const char *what)
{
    int got[3];
    next_pixel(l, x, y, got);
    if (got[0] != r || got[1] != g || got[2] != b)
        fail_msg("pixel (%d, %d) should be %s (%d %d %d), shows %d %d %d", x, y, what, r, g, b, got[0], got[1], got[2]);
}

/* The signed map's colour (blue -1, white 0, red +1) of (a - r) / (|r| + 0.01), channel mean. */
static void expect_signed(lines *l, int x, int y)
{
    double s = 0;
    for (int c = 0; c < 3; c++) {
        double a = value(0, x, y, c), r = value(1, x, y, c);
        s += (a - r) / (fabs(r) + 0.01) / 3;
    }
    double t = fmin(fmax(s, -1.0), 1.0);
    int want[3] = {t > 0 ? 255 : (int)lround(255 * (1 + t)), (int)lround(255 * (1 - fabs(t))),
                   t < 0 ? 255 : (int)lround(255 * (1 - t))}, got[3];
    next_pixel(l, x, y, got);
    for (int c = 0; c < 3; c++)
        if (abs(got[c] - want[c]) > 1)
            fail_msg("signed map at (%d, %d), s = %.4f: channel %d shows %d, expected %d", x, y, s, c, got[c], want[c]);
}

static const int samples[][2] = {{0, 0}, {3, 1}, {11, 2}, {40, 9}, {17, 14}, {30, 20}, {8, 27}, {47, 31}};
enum { NSAMPLES = sizeof samples / sizeof samples[0] };

static void pixel_lines(FILE *f)
{
    for (int i = 0; i < NSAMPLES; i++)
        fprintf(f, "pixel %d %d\n", samples[i][0], samples[i][1]);
}

static int expect_all(lines *l, int which, double ev)
{
    int sum = 0;
    for (int i = 0; i < NSAMPLES; i++)
        sum += expect_tone(l, which, samples[i][0], samples[i][1], ev);
    return sum;
}

static char *run_driver(const char *script_text)
{
    const char *script = write_tmp("script.txt", script_text), *driver = getenv("MURK_PAGE_DRIVER");
    const char *argv[] = {"/usr/bin/python3", driver ? driver : src_path("tests/page_driver.py"), "--chromium",
                          chromium(), script, NULL};
    char *out = NULL;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int st = run_argv(&out, argv);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("browser session: %.1f s\n", (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    if (st != 0)
        fail_msg("page_driver.py failed (%d):\n%s", st, out);
    return out;
}

static const char tiny[] =
    "murk: 1\n"
    "render: { resolution: [24, 16], spp: 4, seed: 0 }\n"
    "camera: { from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 40 }\n"
    "integrator: { type: volpath_nee, max_depth: 16 }\n"
    "background: [0.2, 0.2, 0.2]\n"
    "materials: { white: { type: diffuse, albedo: 0.7 } }\n"
    "media:\n"
    "  smoke: { type: delta, density: { constant: 0.5 }, sigma_s: 2, sigma_a: 0.2 }\n"
    "shapes:\n"
    "  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: smoke }\n"
    "  - { type: quad, center: [0, 2.5, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: 8 }\n";

static void the_page(void **state)
{
    (void)state;
    char a[1024], r[1024], page[1024], small[1024], bench[1024], *out = NULL;
    snprintf(a, sizeof a, "%s/a.exr", tmp_dir());
    snprintf(r, sizeof r, "%s/r.exr", tmp_dir());
    snprintf(page, sizeof page, "%s/cmp.html", tmp_dir());
    snprintf(small, sizeof small, "%s/small.html", tmp_dir());
    snprintf(bench, sizeof bench, "%s/bench", tmp_dir());
    write_exr(a, 0);
    write_exr(r, 1);
    const char *cmp[] = {"compare", a, r, "--html", page, NULL};
    run_murk_ok(cmp, NULL);
    setenv("MURK_MAX_PAGE_BYTES", "4000", 1); /* 48x32 needs 28672 bytes of data, 24x16 7168: downsampled 3x */
    const char *cmp_small[] = {"compare", a, r, "--html", small, NULL};
    run_murk_ok(cmp_small, NULL);
    unsetenv("MURK_MAX_PAGE_BYTES");
    const char *b[] = {"bench", write_tmp("tiny.yaml", tiny), "--vary", "media.smoke.type=delta,decomposition", "--spp",
                       "1,2", "--repeat", "2", "--ref-spp", "16", "--threads", "2", "--no-charts", "-o", bench, NULL};
    run_murk_ok(b, NULL);

    char *script = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&script, &len);
    fprintf(f, "open %s\n", page);
    pixel_lines(f);                 /* 1: the test image at 0 EV */
    fprintf(f, "key 2\n");          /* flip to the reference */
    pixel_lines(f);
    fprintf(f, "click_at #exposure 0.56\neval murkPage.state.ev\ntext #exposure-value\n");
    pixel_lines(f);                 /* the reference at the slider's exposure */
    fprintf(f, "key 1\n");
    pixel_lines(f);                 /* the test image at that exposure */
    fprintf(f, "pixel 5 5\npixel 6 5\npixel 7 5\nhover 5 5\ntext #readout\nhover 6 5\ntext #readout\n");
    fprintf(f, "key d\npixel 4 9\npixel 40 20\npixel 5 5\nkey e\npixel 5 5\n");
    fprintf(f, "key i\nkey s\npixel 2 10\npixel 45 10\n"); /* split: the test image left, the reference right */
    fprintf(f, "key s\nwheel 20 12 -100\neval murkPage.state.zoom\npixel 20 12\npixel 21 12\n");
    fprintf(f, "open %s\ntext #notices\neval [murkPage.width, murkPage.height]\n", small);
    fprintf(f, "open %s/report.html\neval document.querySelectorAll('#tables table')[0].tBodies[0].rows.length\n"
               "text #notices\nkey 3\nkey w\nkey f\neval [murkPage.state.cur, murkPage.state.mode]\n", bench);
    fclose(f);
    out = run_driver(script);
    free(script);

    lines l = {out, out};
    int base = expect_all(&l, 0, 0.0);
    expect_all(&l, 1, 0.0);
    double ev = atof(next(&l, "eval "));
    if (!(ev > 0.3 && ev < 2.5)) /* 56 % along -10 .. 10 */
        fail_msg("the exposure slider moved to %g EV, not about +1.2", ev);
    char want[64];
    snprintf(want, sizeof want, "+%.1f EV", ev);
    assert_contains(next(&l, "text "), want);
    expect_all(&l, 1, ev);
    int brighter = expect_all(&l, 0, ev);
    assert_true(brighter > base + 100); /* the exposure did change what is shown */

    expect_colour(&l, 5, 5, 255, 0, 255, "magenta (NaN)");
    expect_colour(&l, 6, 5, 0, 255, 255, "cyan (+Inf)");
    expect_colour(&l, 7, 5, 0, 255, 255, "cyan (-Inf, in blue)");
    const char *ro = next(&l, "text ");
    assert_contains(ro, "pixel x 5, y 5");
    assert_contains(ro, "R NaN");
    assert_contains(next(&l, "text "), "G +Inf");

    expect_signed(&l, 4, 9);
    expect_signed(&l, 40, 20);
    expect_colour(&l, 5, 5, 255, 0, 255, "magenta (NaN) in the signed map");
    expect_colour(&l, 5, 5, 255, 0, 255, "magenta (NaN) in the relative-error map");

    expect_tone(&l, 0, 2, 10, ev);  /* split: left, the test image */
    expect_tone(&l, 1, 45, 10, ev); /* right, the reference */
    double zoom = atof(next(&l, "eval "));
    assert_true(zoom > 1.0);
    expect_tone(&l, 0, 20, 12, ev); /* zoomed: still nearest-neighbour pixels of the data */
    expect_tone(&l, 0, 21, 12, ev);

    const char *notice = next(&l, "text ");
    assert_contains(notice, "Downsampled: these images are 3\\u00d7 smaller than the renders (48\\u00d732");
    assert_contains(notice, "limit of 3.9 KiB");
    assert_string_equal(next(&l, "eval "), "[16, 11]");

    assert_string_equal(next(&l, "eval "), "2"); /* a row per variant */
    assert_contains(next(&l, "text "), "Charts not found");
    assert_string_equal(next(&l, "eval "), "[2, \"efficiency\"]"); /* key 3: the reference; w then f */

    assert_string_equal(next(&l, "requests "), "0");
    const char *errors = next(&l, "errors ");
    if (strcmp(errors, "0") != 0)
        fail_msg("the page logged errors:\n%s", out);
    free(out);
}

int main(void)
{
    if (!chromium()) {
        printf("no Chromium (/usr/bin/chromium; Debian's package chromium, which tools/build.sh installs): skipped\n");
        return 77;
    }
    char cache[512]; /* the bench's reference goes to this test's folder, not the user's cache */
    snprintf(cache, sizeof cache, "%s/cache", tmp_dir());
    setenv("MURK_CACHE_DIR", cache, 1);
    const struct CMUnitTest tests[] = {cmocka_unit_test(the_page)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
