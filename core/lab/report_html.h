/* report_html.h — the interactive comparison page (`murk compare --html`, `murk bench`'s report.html): one
 * self-contained HTML file holding linear images as half floats, which the page's JavaScript shows with an
 * exposure slider, flipping, a split view, zoom, error and efficiency maps (report_page.{html,css,js},
 * built into libmurklab). Part of libmurklab; needs only libc, libm and murk_write_atomic.
 *
 * Data: every image (3 channels) and error map (1 channel) travels as IEEE 754 binary16, little endian,
 * base64, after division by a power of two 2^e per array (e chosen so that its largest finite |value| is
 * at most 65504, the largest half): exact for exposure, whose steps are powers of two too, and finite for
 * any float image. NaN and infinities keep their identity (the page shows them in colours of their own).
 * Size: the page's image data (the base64 text) is kept within a limit; beyond it every image and map is
 * reduced by the smallest whole factor k that fits (each page pixel the mean of k x k pixels), and the
 * page says so. */
#ifndef MURK_REPORT_HTML_H
#define MURK_REPORT_HTML_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* float -> half, rounding to nearest even; beyond the half range -> +-inf; NaN -> a quiet NaN. */
uint16_t murk_html_half(float v);
/* half -> float (exact). */
float murk_html_half_float(uint16_t h);
/* The e of the array's 2^e divisor: the smallest e with max finite |v| / 2^e <= 65504 (0 if no finite v). */
int murk_html_half_exponent(const float *v, size_t n);

/* Bytes of base64 text for n half floats. */
uint64_t murk_html_base64_bytes(uint64_t nhalves);
/* The smallest factor k >= 1 at which ceil(w/k) x ceil(h/k) pixels of nimages images (3 halves each) and
 * nmaps maps (1 half) take at most max_bytes of base64; k stops at max(w, h) (a single pixel) if none does. */
int murk_html_factor(int w, int h, int nimages, int nmaps, uint64_t max_bytes);
/* src (w x h pixels of ch floats, row-major) reduced by k into dst (ceil(w/k) x ceil(h/k) x ch floats):
 * each pixel the mean of its k x k block (the part inside the image at the right and bottom edges).
 * NaN and infinities propagate as in the sum (a block with a NaN is NaN): the page shows where they are. */
void murk_html_downsample(const float *src, int w, int h, int ch, int k, float *dst);

/* s[0..n) as a JSON string (quoted) that is also safe inside an HTML <script> element: '<' is written
 * \u003c, so no "</script" can end the element early. */
void murk_html_json_string(FILE *f, const char *s, size_t n);

typedef struct murk_html_page murk_html_page;

/* A page for nimages images of w x h pixels, nmaps of which will get an error map; kind is "compare" or
 * "bench" (the page's layout), title its heading. max_bytes: the limit of the image data. */
murk_html_page *murk_html_new(const char *kind, const char *title, int w, int h, int nimages, int nmaps,
                              uint64_t max_bytes);
/* The factor the page's images are reduced by (1: full resolution). */
int murk_html_page_factor(const murk_html_page *p);
/* Image i: its label (the button), a note (what it is: seed, budget), the linear rgb (w x h x 3). The
 * reference is the image the maps compare with: reference = 1 marks it (one image per page). */
void murk_html_image(murk_html_page *p, int i, const char *label, const char *note, const float *rgb, int reference);
/* Image i's per-pixel error (w x h): the mean over channels of the relative squared error against the
 * reference, as murk_metrics_compute's pix (bench: the mean over its seeds). The page's efficiency maps. */
void murk_html_error_map(murk_html_page *p, int i, const float *err);
/* Adds to image i's cost (seconds, density lookups: the efficiency maps' scale) and whole-image relMSE,
 * which start unknown (bench: each seed's share). A cost <= 0 stays unknown. */
void murk_html_cost_add(murk_html_page *p, int i, double seconds, double lookups, double relmse);
/* Text the page shows or reads (a JSON string in the page): "figures" (compare's JSON), "csv" (bench.csv),
 * "bench" (bench.json), "report" (report.md), "command". A second call with the same key replaces it. */
void murk_html_text(murk_html_page *p, const char *key, const char *text);
/* The files of a `murk bench` folder the page shows: DIR/bench.csv ("csv", its tables), DIR/bench.json
 * ("bench"), DIR/report.md ("report") and the charts of tools/bench_report.py (error_vs_time,
 * error_vs_lookups, efficiency, efficiency_map; the SVG, else the PNG) as data URIs. A missing file is no
 * error: the page says what is missing. */
void murk_html_attach_bench(murk_html_page *p, const char *dir);
/* Writes the page through murk_write_atomic. 0, or -1 with err = "path: what went wrong". */
int murk_html_write(const murk_html_page *p, const char *path, char *err, size_t errlen);
void murk_html_free(murk_html_page *p);

/* `murk compare --html PATH` (report_pages.c): the test image a against the reference r (w x h pixels
 * each, their crop c) with compare's figures (its --json object) and the render's cost from a's EXR
 * (<= 0: unknown). 0, or -1 with err. */
struct murk_crop;
int murk_html_compare(const char *path, const char *a_name, const char *r_name, const float *a, const float *r,
                      int w, const struct murk_crop *c, const char *figures, double seconds, double lookups,
                      char *err, size_t errlen);

/* 0 if a page can be written at path (murk_output_check, and its folder exists and is writable), else
 * -1 with err: what murk checks before any work. */
int murk_html_check_path(const char *path, char *err, size_t errlen);

#endif
