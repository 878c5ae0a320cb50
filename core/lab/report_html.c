/* report_html.c — the interactive comparison page (report_html.h): half-float encoding, the size limit and
 * its downsampling, and the writer that fills the page's template (report_page.html with its CSS and
 * JavaScript, built in by tools/embed.c) with the data. Part of libmurklab. */
#include "lab/report_html.h"

#include "lab/report_page.h" /* generated: murk_page_html, murk_page_css, murk_page_js */
#include "util/atomic.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- half floats ---- */

uint16_t murk_html_half(float v)
{
    uint32_t x;
    memcpy(&x, &v, sizeof x);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;
    if (ax > 0x7f800000u) /* NaN: quiet, with the top of its payload */
        return (uint16_t)(sign | 0x7e00u | ((ax >> 13) & 0x3ffu));
    if (ax >= 0x477ff000u) /* 65520 and above round to infinity (and infinity stays) */
        return (uint16_t)(sign | 0x7c00u);
    if (ax >= 0x38800000u) { /* a normal half (2^-14 and above): rebias, round to nearest even at bit 13 */
        uint32_t r = ax - 0x38000000u;
        r += 0xfffu + ((r >> 13) & 1u);
        return (uint16_t)(sign | (r >> 13));
    }
    if (ax <= 0x33000000u) /* 2^-25 and below round to zero (2^-25 itself: the tie goes to even, 0) */
        return sign;
    /* a subnormal half: a whole number of 2^-24, rounded to nearest even (0x400 is the smallest normal) */
    uint32_t e = ax >> 23, m = (ax & 0x7fffffu) | 0x800000u, shift = 126 - e;
    uint32_t q = m >> shift, rem = m & ((1u << shift) - 1), half = 1u << (shift - 1);
    if (rem > half || (rem == half && (q & 1u)))
        q++;
    return (uint16_t)(sign | q);
}

float murk_html_half_float(uint16_t h)
{
    uint32_t e = (h >> 10) & 31u, m = h & 0x3ffu;
    float f;
    if (e == 31) { /* infinity or NaN, bit for bit */
        uint32_t x = ((uint32_t)(h & 0x8000u) << 16) | 0x7f800000u | (m << 13);
        memcpy(&f, &x, sizeof f);
        return f;
    }
    f = e ? ldexpf((float)(m | 0x400u), (int)e - 25) : ldexpf((float)m, -24);
    return h & 0x8000u ? -f : f;
}

int murk_html_half_exponent(const float *v, size_t n)
{
    double mx = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(v[i]) && fabs(v[i]) > mx)
            mx = fabs(v[i]);
    if (!(mx > 0))
        return 0;
    int e = (int)ceil(log2(mx / 65504.0));
    while (ldexp(mx, -e) > 65504.0)
        e++;
    while (ldexp(mx, 1 - e) <= 65504.0)
        e--;
    return e;
}

/* ---- the size limit ---- */

uint64_t murk_html_base64_bytes(uint64_t nhalves) { return 4 * ((2 * nhalves + 2) / 3); }

static uint64_t page_bytes(int w, int h, int k, int nimages, int nmaps)
{
    uint64_t px = (uint64_t)((w + k - 1) / k) * (uint64_t)((h + k - 1) / k);
    return (uint64_t)nimages * murk_html_base64_bytes(3 * px) + (uint64_t)nmaps * murk_html_base64_bytes(px);
}

int murk_html_factor(int w, int h, int nimages, int nmaps, uint64_t max_bytes)
{
    int most = w > h ? w : h, k = 1;
    while (k < most && page_bytes(w, h, k, nimages, nmaps) > max_bytes)
        k++;
    return k;
}

void murk_html_downsample(const float *src, int w, int h, int ch, int k, float *dst)
{
    int ow = (w + k - 1) / k, oh = (h + k - 1) / k;
    double *sum = murk_xmalloc((size_t)ow * (size_t)ch * sizeof *sum);
    for (int oy = 0; oy < oh; oy++) {
        memset(sum, 0, (size_t)ow * (size_t)ch * sizeof *sum);
        int y1 = (oy + 1) * k < h ? (oy + 1) * k : h;
        for (int y = oy * k; y < y1; y++)
            for (int x = 0; x < w; x++) {
                const float *px = src + ((size_t)y * (size_t)w + (size_t)x) * (size_t)ch;
                for (int c = 0; c < ch; c++)
                    sum[(size_t)(x / k) * (size_t)ch + (size_t)c] += px[c];
            }
        for (int ox = 0; ox < ow; ox++) {
            int x1 = (ox + 1) * k < w ? (ox + 1) * k : w;
            double n = (double)(x1 - ox * k) * (double)(y1 - oy * k);
            for (int c = 0; c < ch; c++)
                dst[((size_t)oy * (size_t)ow + (size_t)ox) * (size_t)ch + (size_t)c] =
                    (float)(sum[(size_t)ox * (size_t)ch + (size_t)c] / n);
        }
    }
    free(sum);
}

/* ---- the page ---- */

typedef struct half_array {
    uint16_t *v; /* NULL: none */
    size_t n;
    int exp; /* the values are v * 2^exp */
} half_array;

typedef struct page_image {
    char *label, *note;
    int reference;
    half_array rgb, err;
    double seconds, lookups, relmse;
} page_image;

typedef struct page_blob { /* a text (kind 0) or a chart (kind 1, bytes with a MIME type) */
    char *key, *title, *mime;
    unsigned char *data;
    size_t len;
} page_blob;

struct murk_html_page {
    char *kind, *title;
    int w, h, k, ow, oh, nimages, nmaps;
    uint64_t max_bytes;
    page_image *img;
    page_blob *texts, *charts;
    int ntexts, ncharts;
    char **missing; /* charts not found */
    int nmissing;
};

murk_html_page *murk_html_new(const char *kind, const char *title, int w, int h, int nimages, int nmaps,
                              uint64_t max_bytes)
{
    murk_html_page *p = murk_xmalloc(sizeof *p);
    p->kind = murk_strdup(kind);
    p->title = murk_strdup(title);
    p->w = w, p->h = h, p->nimages = nimages, p->nmaps = nmaps, p->max_bytes = max_bytes;
    p->k = murk_html_factor(w, h, nimages, nmaps, max_bytes);
    p->ow = (w + p->k - 1) / p->k, p->oh = (h + p->k - 1) / p->k;
    p->img = murk_xmalloc((size_t)nimages * sizeof *p->img);
    for (int i = 0; i < nimages; i++)
        p->img[i].seconds = p->img[i].lookups = p->img[i].relmse = NAN;
    return p;
}

int murk_html_page_factor(const murk_html_page *p) { return p->k; }

/* v (w x h x ch floats) reduced by the page's factor and encoded into a. */
static void encode(const murk_html_page *p, const float *v, int ch, half_array *a)
{
    size_t n = (size_t)p->ow * (size_t)p->oh * (size_t)ch;
    float *small = NULL;
    if (p->k > 1) {
        small = murk_xmalloc(n * sizeof *small);
        murk_html_downsample(v, p->w, p->h, ch, p->k, small);
        v = small;
    }
    free(a->v);
    a->n = n;
    a->exp = murk_html_half_exponent(v, n);
    a->v = murk_xmalloc(n * sizeof *a->v);
    for (size_t i = 0; i < n; i++)
        a->v[i] = murk_html_half((float)ldexp(v[i], -a->exp));
    free(small);
}

void murk_html_image(murk_html_page *p, int i, const char *label, const char *note, const float *rgb, int reference)
{
    page_image *im = &p->img[i];
    free(im->label);
    free(im->note);
    im->label = murk_strdup(label);
    im->note = murk_strdup(note ? note : "");
    im->reference = reference;
    encode(p, rgb, 3, &im->rgb);
}

void murk_html_error_map(murk_html_page *p, int i, const float *err) { encode(p, err, 1, &p->img[i].err); }

static void add(double *sum, double v) { *sum = isnan(*sum) ? v : *sum + v; }

void murk_html_cost_add(murk_html_page *p, int i, double seconds, double lookups, double relmse)
{
    if (seconds > 0)
        add(&p->img[i].seconds, seconds);
    if (lookups > 0)
        add(&p->img[i].lookups, lookups);
    if (isfinite(relmse))
        add(&p->img[i].relmse, relmse);
}

static void blob_set(page_blob *b, const char *key, const char *title, const char *mime, unsigned char *data,
                     size_t len)
{
    b->key = murk_strdup(key);
    b->title = murk_strdup(title ? title : "");
    b->mime = murk_strdup(mime ? mime : "");
    b->data = data;
    b->len = len;
}

static void blob_free(page_blob *b)
{
    free(b->key);
    free(b->title);
    free(b->mime);
    free(b->data);
}

void murk_html_text(murk_html_page *p, const char *key, const char *text)
{
    size_t len = strlen(text);
    unsigned char *copy = murk_xmalloc(len + 1);
    memcpy(copy, text, len);
    for (int i = 0; i < p->ntexts; i++)
        if (!strcmp(p->texts[i].key, key)) {
            blob_free(&p->texts[i]);
            blob_set(&p->texts[i], key, NULL, NULL, copy, len);
            return;
        }
    p->texts = murk_xrealloc(p->texts, (size_t)(p->ntexts + 1) * sizeof *p->texts);
    blob_set(&p->texts[p->ntexts++], key, NULL, NULL, copy, len);
}

/* A whole regular file of at most 256 MiB, NUL-terminated; NULL if there is none. */
static unsigned char *slurp(const char *path, size_t *len)
{
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > (off_t)256 << 20)
        return NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *d = murk_xmalloc((size_t)st.st_size + 1);
    *len = fread(d, 1, (size_t)st.st_size, f);
    int bad = ferror(f) || *len != (size_t)st.st_size;
    fclose(f);
    if (bad) {
        free(d);
        return NULL;
    }
    return d;
}

void murk_html_attach_bench(murk_html_page *p, const char *dir)
{
    static const char *const texts[][2] = {{"csv", "bench.csv"}, {"bench", "bench.json"}, {"report", "report.md"}};
    static const char *const charts[][2] = {
        {"error_vs_time", "Error against render time"},
        {"error_vs_lookups", "Error against density lookups"},
        {"efficiency", "Efficiency relative to the first variant, per budget"},
        {"efficiency_map", "Most efficient variant per pixel (the chart script's map)"},
    };
    size_t n = strlen(dir) + 64, len;
    char *path = murk_xmalloc(n);
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        snprintf(path, n, "%s/%s", dir, texts[i][1]);
        unsigned char *d = slurp(path, &len);
        if (d)
            murk_html_text(p, texts[i][0], (char *)d);
        free(d);
    }
    for (size_t i = 0; i < sizeof charts / sizeof charts[0]; i++) {
        unsigned char *d = NULL;
        const char *mime = NULL;
        for (int svg = 1; svg >= 0 && !d; svg--) {
            snprintf(path, n, "%s/%s.%s", dir, charts[i][0], svg ? "svg" : "png");
            d = slurp(path, &len);
            mime = svg ? "image/svg+xml" : "image/png";
        }
        if (d) {
            p->charts = murk_xrealloc(p->charts, (size_t)(p->ncharts + 1) * sizeof *p->charts);
            blob_set(&p->charts[p->ncharts++], charts[i][0], charts[i][1], mime, d, len);
        } else {
            p->missing = murk_xrealloc(p->missing, (size_t)(p->nmissing + 1) * sizeof *p->missing);
            p->missing[p->nmissing++] = murk_strdup(charts[i][0]);
        }
    }
    free(path);
}

void murk_html_free(murk_html_page *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->nimages; i++) {
        free(p->img[i].label);
        free(p->img[i].note);
        free(p->img[i].rgb.v);
        free(p->img[i].err.v);
    }
    for (int i = 0; i < p->ntexts; i++)
        blob_free(&p->texts[i]);
    for (int i = 0; i < p->ncharts; i++)
        blob_free(&p->charts[i]);
    for (int i = 0; i < p->nmissing; i++)
        free(p->missing[i]);
    free(p->missing);
    free(p->texts);
    free(p->charts);
    free(p->img);
    free(p->kind);
    free(p->title);
    free(p);
}

/* ---- writing ---- */

void murk_html_json_string(FILE *f, const char *s, size_t n)
{
    fputc('"', f);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c == '\n')
            fputs("\\n", f);
        else if (c < 0x20 || c == '<' || c == 0x7f)
            fprintf(f, "\\u%04x", c);
        else if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void json_cstr(FILE *f, const char *s) { murk_html_json_string(f, s, strlen(s)); }

static void json_num(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.9g", v);
    else
        fputs("null", f);
}

static void base64(FILE *f, const unsigned char *d, size_t n)
{
    static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char q[4];
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) | (i + 2 < n ? d[i + 2] : 0);
        q[0] = a[v >> 18], q[1] = a[(v >> 12) & 63];
        q[2] = i + 1 < n ? a[(v >> 6) & 63] : '=';
        q[3] = i + 2 < n ? a[v & 63] : '=';
        fwrite(q, 1, 4, f);
    }
}

/* {"exp": E, "id": ID}: the array's scale and the id of the element holding its halves (half_element). */
static void json_halves(FILE *f, const half_array *a, int id)
{
    if (a->v)
        fprintf(f, "{\"exp\": %d, \"id\": \"murk-half-%d\"}", a->exp, id);
    else
        fputs("null", f);
}

/* The halves as base64 of their little-endian bytes in an element of their own, outside the JSON (the
 * page decodes them natively, with no JSON string to parse), in chunks so that no buffer holds them all. */
static void half_element(FILE *f, const half_array *a, int id)
{
    if (!a->v)
        return;
    fprintf(f, "<script type=\"text/plain\" id=\"murk-half-%d\">", id);
    unsigned char buf[3 * 4096];
    for (size_t i = 0; i < a->n;) {
        size_t m = 0;
        for (; i < a->n && m < sizeof buf; i++) {
            buf[m++] = (unsigned char)(a->v[i] & 0xff);
            buf[m++] = (unsigned char)(a->v[i] >> 8);
        }
        base64(f, buf, m); /* m is a multiple of 3 except at the end */
    }
    fputs("</script>\n", f);
}

static void json_data(FILE *f, const murk_html_page *p)
{
    fputs("{\"kind\": ", f);
    json_cstr(f, p->kind);
    fputs(", \"title\": ", f);
    json_cstr(f, p->title);
    fprintf(f, ", \"width\": %d, \"height\": %d, \"source\": [%d, %d], \"factor\": %d, \"limit\": %llu, "
               "\"bytes\": %llu,\n\"images\": [", p->ow, p->oh, p->w, p->h, p->k, (unsigned long long)p->max_bytes,
            (unsigned long long)page_bytes(p->w, p->h, p->k, p->nimages, p->nmaps));
    for (int i = 0; i < p->nimages; i++) {
        const page_image *im = &p->img[i];
        fputs(i ? ",\n{\"label\": " : "\n{\"label\": ", f);
        json_cstr(f, im->label ? im->label : "?");
        fputs(", \"note\": ", f);
        json_cstr(f, im->note ? im->note : "");
        fprintf(f, ", \"reference\": %s, \"seconds\": ", im->reference ? "true" : "false");
        json_num(f, im->seconds);
        fputs(", \"lookups\": ", f);
        json_num(f, im->lookups);
        fputs(", \"relmse\": ", f);
        json_num(f, im->relmse);
        fputs(",\n \"rgb\": ", f);
        json_halves(f, &im->rgb, 2 * i);
        fputs(",\n \"err\": ", f);
        json_halves(f, &im->err, 2 * i + 1);
        fputc('}', f);
    }
    fputs("],\n\"text\": {", f);
    for (int i = 0; i < p->ntexts; i++) {
        fputs(i ? ",\n" : "\n", f);
        json_cstr(f, p->texts[i].key);
        fputs(": ", f);
        murk_html_json_string(f, (const char *)p->texts[i].data, p->texts[i].len);
    }
    fputs("},\n\"charts\": [", f);
    for (int i = 0; i < p->ncharts; i++) {
        fputs(i ? ",\n{\"name\": " : "\n{\"name\": ", f);
        json_cstr(f, p->charts[i].key);
        fputs(", \"title\": ", f);
        json_cstr(f, p->charts[i].title);
        fprintf(f, ", \"uri\": \"data:%s;base64,", p->charts[i].mime);
        base64(f, p->charts[i].data, p->charts[i].len);
        fputs("\"}", f);
    }
    fputs("],\n\"missing\": [", f);
    for (int i = 0; i < p->nmissing; i++) {
        fputs(i ? ", " : "", f);
        json_cstr(f, p->missing[i]);
    }
    fputs("]}", f);
}

/* The template with its @@CSS@@, @@JS@@, @@DATA@@ and @@HALVES@@ replaced. */
static int page_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen)
{
    const murk_html_page *p = user;
    const char *t = (const char *)murk_page_html;
    (void)tmp;
    for (const char *at; (at = strstr(t, "@@")) != NULL;) {
        fwrite(t, 1, (size_t)(at - t), f);
        if (!strncmp(at, "@@CSS@@", 7)) {
            fputs((const char *)murk_page_css, f);
            t = at + 7;
        } else if (!strncmp(at, "@@JS@@", 6)) {
            fputs((const char *)murk_page_js, f);
            t = at + 6;
        } else if (!strncmp(at, "@@DATA@@", 8)) {
            json_data(f, p);
            t = at + 8;
        } else if (!strncmp(at, "@@HALVES@@", 10)) {
            for (int i = 0; i < p->nimages; i++) {
                half_element(f, &p->img[i].rgb, 2 * i);
                half_element(f, &p->img[i].err, 2 * i + 1);
            }
            t = at + 10;
        } else {
            snprintf(err, errlen, "the page's template has an unknown placeholder");
            return -1;
        }
    }
    fputs(t, f);
    return 0;
}

int murk_html_write(const murk_html_page *p, const char *path, char *err, size_t errlen)
{
    for (int i = 0; i < p->nimages; i++)
        if (!p->img[i].rgb.v) {
            snprintf(err, errlen, "%s: the page's image %d was never given", path, i + 1);
            return -1;
        }
    return murk_write_atomic(path, page_fill, (void *)p, err, errlen);
}

int murk_html_check_path(const char *path, char *err, size_t errlen)
{
    if (murk_output_check(path, err, errlen) != 0)
        return -1;
    const char *slash = strrchr(path, '/');
    char *dir = slash ? murk_strdup(path) : murk_strdup(".");
    if (slash)
        dir[slash == path ? 1 : slash - path] = 0;
    struct stat st;
    int rc = 0, found = stat(dir, &st) == 0;
    if (!found || !S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s: its folder %s %s", path, dir, found ? "is not a folder" : "does not exist");
        rc = -1;
    } else if (access(dir, W_OK | X_OK) != 0) {
        snprintf(err, errlen, "%s: its folder %s is not writable", path, dir);
        rc = -1;
    }
    free(dir);
    return rc;
}
