/* test_report_html.c — the comparison page's C side (core/lab/report_html.c): the half-float encoding
 * (every half round-trips, random floats go to the nearest half with ties to even, NaN/Inf/denormals keep
 * what they are), the per-array power-of-two scale, the size limit and its downsampling, the written
 * page; and `murk compare --html` on bad input: images of different sizes, an unwritable or odd --html
 * path (refused before the images are read; nothing written), a page over the size limit (downsampled and
 * said so), NaN pixels (kept as NaN in the page's data). The page in a browser: test_report_page.c. */
#include "testutil.h"

#include "image/image.h"
#include "lab/report_html.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

static float float_of(uint32_t x)
{
    float f;
    memcpy(&f, &x, sizeof f);
    return f;
}

/* Every half bit pattern decodes and encodes back to itself (NaNs to a NaN of the same sign). */
static void half_round_trip(void **state)
{
    (void)state;
    for (uint32_t h = 0; h < 65536; h++) {
        float f = murk_html_half_float((uint16_t)h);
        uint16_t back = murk_html_half(f);
        if ((h & 0x7c00) == 0x7c00 && (h & 0x3ff)) {
            assert_true(isnan(f));
            assert_int_equal(back & 0x7c00, 0x7c00);
            assert_int_not_equal(back & 0x3ff, 0);
            assert_int_equal(back & 0x8000, h & 0x8000);
        } else if (back != h) {
            fail_msg("half 0x%04x -> %a -> 0x%04x", (unsigned)h, (double)f, back);
        }
    }
}

/* The values that mark the edges: zero's sign, the smallest subnormal, the subnormal/normal boundary, one,
 * the largest half and the rounding just below and at the overflow threshold, the infinities, NaN. */
static void half_special_values(void **state)
{
    (void)state;
    static const struct { float f; uint16_t h; } cases[] = {
        {0.0f, 0x0000}, {-0.0f, 0x8000}, {1.0f, 0x3c00}, {-2.0f, 0xc000}, {0x1p-24f, 0x0001},
        {0x1p-25f, 0x0000},            /* half way to the smallest subnormal: the tie goes to even 0 */
        {0x1.8p-25f, 0x0001},          /* above half way */
        {0x1p-26f, 0x0000},            {0x3ffp-24f, 0x03ff}, /* the largest subnormal */
        {0x3ff.8p-24f, 0x0400},        /* 1023.5 x 2^-24: ties to even, the smallest normal */
        {0x1p-14f, 0x0400},            {1.0f + 0x1p-11f, 0x3c00}, /* a tie: to even */
        {1.0f + 0x3p-11f, 0x3c02},     {65504.0f, 0x7bff}, {65519.0f, 0x7bff}, {65520.0f, 0x7c00},
        {1e30f, 0x7c00},               {-1e30f, 0xfc00}, {INFINITY, 0x7c00}, {-INFINITY, 0xfc00},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (murk_html_half(cases[i].f) != cases[i].h)
            fail_msg("%a -> 0x%04x, expected 0x%04x", (double)cases[i].f, murk_html_half(cases[i].f), cases[i].h);
    uint16_t n = murk_html_half(NAN), m = murk_html_half(-NAN);
    assert_int_equal(n & 0x7c00, 0x7c00);
    assert_int_not_equal(n & 0x3ff, 0);
    assert_int_equal(m & 0x8000, 0x8000);
    assert_true(isnan(murk_html_half_float(n)));
    assert_true(isinf(murk_html_half_float(0x7c00)) && murk_html_half_float(0xfc00) < 0);
    assert_true(murk_html_half_float(0x0001) == 0x1p-24f && murk_html_half_float(0x8000) == 0.0f &&
                signbit(murk_html_half_float(0x8000)));
}

/* Random floats over the whole finite range: the result is a nearest half (no other half is closer),
 * with ties going to the even one. An independent check in double precision. */
static void half_nearest(void **state)
{
    (void)state;
    uint64_t s = 0x9e3779b97f4a7c15ull;
    for (int i = 0; i < 2000000; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        /* exponents around the half range (2^-30 .. 2^17) get most draws; the rest, any finite float */
        uint32_t x = i % 4 ? (uint32_t)(s & 0x807fffffu) | (uint32_t)(97 + (s >> 40) % 48) << 23 : (uint32_t)s;
        float f = float_of(x);
        if (!isfinite(f))
            continue;
        uint16_t h = murk_html_half(f);
        double d = fabs((double)f - murk_html_half_float(h));
        if (fabs((double)f) >= 65520.0) {
            assert_true(isinf(murk_html_half_float(h)));
            continue;
        }
        for (int dh = -1; dh <= 1; dh += 2) {
            int o = (h & 0x7fff) + dh;
            if (o < 0 || o > 0x7bff)
                continue;
            double od = fabs((double)f - murk_html_half_float((uint16_t)((h & 0x8000) | o)));
            if (od < d || (od == d && (h & 1)))
                fail_msg("%a -> 0x%04x (off by %g) but 0x%04x is off by %g", (double)f, h, d, (h & 0x8000) | o, od);
        }
    }
}

/* The scale 2^e: the largest finite |value| / 2^e lands in (32752, 65504], NaN and infinities ignored. */
static void half_exponent(void **state)
{
    (void)state;
    float a[] = {1.0f, -1e5f, NAN, INFINITY, 3.0f};
    assert_int_equal(murk_html_half_exponent(a, 5), 1); /* 1e5 / 2 = 50000 */
    float b[] = {65504.0f}, c[] = {65505.0f}, z[] = {0.0f, NAN, -INFINITY};
    assert_int_equal(murk_html_half_exponent(b, 1), 0);
    assert_int_equal(murk_html_half_exponent(c, 1), 1);
    assert_int_equal(murk_html_half_exponent(z, 3), 0);
    float tiny[] = {3e-7f, 1e-9f};
    int e = murk_html_half_exponent(tiny, 2);
    double top = ldexp(3e-7f, -e);
    assert_true(top <= 65504.0 && top > 32752.0);
    float huge[] = {3e38f};
    e = murk_html_half_exponent(huge, 1);
    assert_true(ldexp(3e38f, -e) <= 65504.0 && ldexp(3e38f, -e) > 32752.0);
    /* scaled by 2^-e, every normal half keeps 11 significant bits: relative error <= 2^-11 */
    float v[] = {123456.0f, 0.001f, 7.5f};
    e = murk_html_half_exponent(v, 3);
    for (int i = 0; i < 3; i++) {
        double back = ldexp(murk_html_half_float(murk_html_half((float)ldexp(v[i], -e))), e);
        assert_true(fabs(back - v[i]) <= 0x1p-11 * v[i]);
    }
}

/* The limit: the smallest whole factor whose pixels fit, in base64 bytes of 3 halves per image pixel and
 * 1 per map pixel. */
static void size_limit(void **state)
{
    (void)state;
    assert_int_equal(murk_html_base64_bytes(3), 8);  /* 6 bytes -> 8 characters */
    assert_int_equal(murk_html_base64_bytes(1), 4);  /* 2 bytes, padded */
    uint64_t full = 2 * murk_html_base64_bytes(3 * 100 * 60) + murk_html_base64_bytes(100 * 60);
    assert_int_equal(murk_html_factor(100, 60, 2, 1, full), 1);
    assert_int_equal(murk_html_factor(100, 60, 2, 1, full - 1), 2);
    uint64_t half = 2 * murk_html_base64_bytes(3 * 50 * 30) + murk_html_base64_bytes(50 * 30);
    assert_int_equal(murk_html_factor(100, 60, 2, 1, half), 2);
    assert_int_equal(murk_html_factor(101, 61, 2, 1, half), 3); /* 51 x 31 at 2 does not fit */
    assert_int_equal(murk_html_factor(100, 60, 2, 1, 1), 100);   /* nothing fits: one pixel */
}

/* Block means, the partial blocks at the right and bottom edges, and NaN/Inf staying in their block. */
static void downsample(void **state)
{
    (void)state;
    enum { W = 5, H = 3 };
    float src[W * H * 2], dst[3 * 2 * 2];
    for (int i = 0; i < W * H; i++) {
        src[2 * i] = (float)i;
        src[2 * i + 1] = 1.0f;
    }
    src[2 * 6 + 1] = NAN;          /* pixel (1, 1): block (0, 0), channel 1 */
    src[2 * 14] = INFINITY;        /* pixel (4, 2): block (2, 1) */
    murk_html_downsample(src, W, H, 2, 2, dst);
    const float mean[6] = {(0 + 1 + 5 + 6) / 4.0f, (2 + 3 + 7 + 8) / 4.0f, (4 + 9) / 2.0f, (10 + 11) / 2.0f,
                           (12 + 13) / 2.0f, INFINITY};
    for (int b = 0; b < 6; b++) {
        assert_true(dst[2 * b] == mean[b]);
        if (b == 0)
            assert_true(isnan(dst[1]));
        else
            assert_true(dst[2 * b + 1] == 1.0f);
    }
    float one[W * H * 2];
    murk_html_downsample(src, W, H, 2, 1, one); /* factor 1: a copy */
    for (int i = 0; i < W * H * 2; i++)
        assert_true(one[i] == src[i] || (isnan(one[i]) && isnan(src[i])));
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    s[fread(s, 1, (size_t)n, f)] = 0;
    fclose(f);
    return s;
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* A page written through the C interface: the template's placeholders filled, the limit applied, text
 * that could end the <script> element escaped. */
static void page_write(void **state)
{
    (void)state;
    enum { W = 40, H = 20 };
    float rgb[W * H * 3], err[W * H];
    for (int i = 0; i < W * H * 3; i++)
        rgb[i] = (float)i / (W * H * 3);
    for (int i = 0; i < W * H; i++)
        err[i] = 0.01f;
    uint64_t limit = 2 * murk_html_base64_bytes(3 * 20 * 10) + murk_html_base64_bytes(20 * 10);
    murk_html_page *p = murk_html_new("compare", "a </script> title", W, H, 2, 1, limit);
    assert_int_equal(murk_html_page_factor(p), 2);
    murk_html_image(p, 0, "test", "note", rgb, 0);
    murk_html_image(p, 1, "ref", "", rgb, 1);
    murk_html_error_map(p, 0, err);
    murk_html_cost_add(p, 0, 2.0, -1, 0.5);
    murk_html_text(p, "figures", "{\"x\": \"</script><b>\"}");
    char path[1024], msg[1024];
    snprintf(path, sizeof path, "%s/page.html", tmp_dir());
    assert_int_equal(murk_html_write(p, path, msg, sizeof msg), 0);
    murk_html_free(p);
    char *s = slurp(path);
    assert_non_null(s);
    assert_not_contains(s, "@@");
    assert_contains(s, "\"width\": 20, \"height\": 10, \"source\": [40, 20], \"factor\": 2");
    assert_contains(s, "\"seconds\": 2, \"lookups\": null, \"relmse\": 0.5");
    assert_contains(s, "a \\u003c/script> title");
    const char *data = strstr(s, "<script id=\"murk-data\"");
    assert_non_null(data);
    const char *end = strstr(data, "</script>"), *content = strchr(data, '>') + 1;
    assert_ptr_equal(strchr(content, '<'), end); /* no '<' in the data: nothing can end the element early */
    assert_non_null(strstr(end, "'use strict'")); /* the JavaScript follows */
    free(s);
}

/* A bench folder's files in the page: the texts as JSON strings, each chart as a data URI (the SVG when
 * there is one, else the PNG), the missing charts named. */
static void page_attach_bench(void **state)
{
    (void)state;
    char dir[1024], path[1200], msg[1024];
    snprintf(dir, sizeof dir, "%s/benchdir", tmp_dir());
    assert_int_equal(mkdir(dir, 0777), 0);
    static const char *const files[][2] = {
        {"bench.csv", "variant,label\n0,\"a\"\n"}, {"bench.json", "{\"variants\": [\"a\"]}"},
        {"report.md", "# murk bench\n"}, {"error_vs_time.svg", "<svg/>"}, {"error_vs_time.png", "PNG?"},
        {"efficiency.png", "PNG"},
    };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "benchdir/%s", files[i][0]);
        write_tmp(path, files[i][1]);
    }
    float rgb[3] = {1, 2, 3};
    murk_html_page *p = murk_html_new("bench", "b", 1, 1, 1, 0, 1 << 20);
    murk_html_image(p, 0, "reference", "", rgb, 1);
    murk_html_attach_bench(p, dir);
    snprintf(path, sizeof path, "%s/bench.html", tmp_dir());
    assert_int_equal(murk_html_write(p, path, msg, sizeof msg), 0);
    murk_html_free(p);
    char *s = slurp(path);
    assert_contains(s, "\"csv\": \"variant,label\\n0,\\\"a\\\"\\n\"");
    assert_contains(s, "\"report\": \"# murk bench\\n\"");
    assert_contains(s, "\"uri\": \"data:image/svg+xml;base64,PHN2Zy8+\"");  /* <svg/>, not the PNG beside it */
    assert_contains(s, "\"uri\": \"data:image/png;base64,UE5H\"");         /* PNG */
    assert_contains(s, "\"missing\": [\"error_vs_lookups\", \"efficiency_map\"]");
    free(s);
}

/* murk_html_check_path: what murk refuses before any work. */
static void check_path(void **state)
{
    (void)state;
    char msg[1024], path[1024];
    snprintf(path, sizeof path, "%s/no/such/folder/p.html", tmp_dir());
    assert_int_equal(murk_html_check_path(path, msg, sizeof msg), -1);
    assert_contains(msg, "does not exist");
    assert_int_equal(murk_html_check_path(tmp_dir(), msg, sizeof msg), -1);
    assert_contains(msg, "is a directory");
    assert_int_equal(murk_html_check_path("/dev/null", msg, sizeof msg), -1);
    assert_contains(msg, "character device");
    snprintf(path, sizeof path, "%s/fine.html", tmp_dir());
    assert_int_equal(murk_html_check_path(path, msg, sizeof msg), 0);
    assert_int_equal(murk_html_check_path("fine.html", msg, sizeof msg), 0); /* the current folder */
}

static const char *exr(const char *name, int w, int h, float nan_at)
{
    float *rgb = malloc((size_t)w * (size_t)h * 3 * sizeof *rgb);
    for (int i = 0; i < w * h * 3; i++)
        rgb[i] = 0.25f + 0.5f * (float)(i % 7) / 7;
    if (nan_at >= 0)
        rgb[3 * (int)nan_at] = NAN;
    const char *path = tmp_path(name);
    char msg[1024];
    if (murk_exr_write(path, rgb, w, h, NULL, 0, msg, sizeof msg) != 0)
        fail_msg("%s", msg);
    free(rgb);
    return path;
}

/* murk compare --html on bad input. */
static void compare_bad_input(void **state)
{
    (void)state;
    char a[1024], b[1024], c[1024], page[1024], *out = NULL;
    snprintf(a, sizeof a, "%s", exr("a.exr", 16, 8, 5));
    snprintf(b, sizeof b, "%s", exr("b.exr", 16, 8, -1));
    snprintf(c, sizeof c, "%s", exr("c.exr", 8, 8, -1));
    snprintf(page, sizeof page, "%s/cmp.html", tmp_dir());

    /* different sizes: the located message, no page */
    assert_int_equal(run_murk(&out, "compare", a, c, "--html", page, NULL), 1);
    assert_contains(out, "a.exr is 16x8 but ");
    assert_contains(out, "c.exr is 8x8");
    assert_false(file_exists(page));
    free(out);

    /* a path murk cannot write: refused before the images are read (they do not even exist here) */
    assert_int_equal(run_murk(&out, "compare", "missing1.exr", "missing2.exr", "--html", "/no/such/dir/p.html", NULL),
                     1);
    assert_contains(out, "/no/such/dir/p.html: its folder /no/such/dir does not exist");
    assert_not_contains(out, "missing1.exr");
    free(out);
    assert_int_equal(run_murk(&out, "compare", a, b, "--html", tmp_dir(), NULL), 1);
    assert_contains(out, "is a directory");
    free(out);
    assert_int_equal(run_murk(&out, "compare", a, b, "--html", NULL), 2);
    assert_contains(out, "--html needs an .html file name");
    free(out);

    /* NaN pixels: a page whose data keep them (the browser test shows them); the figures skip them */
    assert_int_equal(run_murk(&out, "compare", a, b, "--html", page, NULL), 0);
    assert_contains(out, "comparison page: ");
    assert_contains(out, "1 non-finite values skipped");
    free(out);
    char *s = slurp(page);
    assert_contains(s, "\"factor\": 1,");
    assert_contains(s, "\\\"nonfinite\\\": 1"); /* in compare's figures, a JSON string in the page */
    free(s);
}

/* A page over the limit: downsampled by the smallest factor that fits, and the page data say so. */
static void compare_over_limit(void **state)
{
    (void)state;
    char a[1024], b[1024], page[1024], *out = NULL;
    snprintf(a, sizeof a, "%s", exr("big_a.exr", 64, 32, -1));
    snprintf(b, sizeof b, "%s", exr("big_b.exr", 64, 32, 3));
    snprintf(page, sizeof page, "%s/small.html", tmp_dir());
    setenv("MURK_MAX_PAGE_BYTES", "8000", 1); /* 64x32: 38232 bytes; at 2, 9560; at 3 (22x11), 4520 */
    int st = run_murk(&out, "compare", a, b, "--html", page, NULL);
    unsetenv("MURK_MAX_PAGE_BYTES");
    assert_int_equal(st, 0);
    free(out);
    char *s = slurp(page);
    assert_contains(s, "\"width\": 22, \"height\": 11, \"source\": [64, 32], \"factor\": 3, \"limit\": 8000");
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(half_round_trip),   cmocka_unit_test(half_special_values),
        cmocka_unit_test(half_nearest),      cmocka_unit_test(half_exponent),
        cmocka_unit_test(size_limit),        cmocka_unit_test(downsample),
        cmocka_unit_test(page_write),        cmocka_unit_test(page_attach_bench),
        cmocka_unit_test(check_path),
        cmocka_unit_test(compare_bad_input), cmocka_unit_test(compare_over_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
