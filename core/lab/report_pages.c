/* report_pages.c — the comparison pages of the commands: `murk compare --html` (below) builds its page
 * from the two images; `murk bench` fills one as it renders (bench.c calls report_html.h directly).
 * Part of libmurklab. */
#include "lab/report_html.h"
#include "util/limit.h"
#include "util/util.h"
#include "murk/lab.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The crop of a w-pixel-wide rgb image as an image of its own. */
static float *crop_rgb(const float *v, int w, const murk_crop *c)
{
    float *o = murk_xmalloc((size_t)c->w * (size_t)c->h * 3 * sizeof *o);
    for (int y = 0; y < c->h; y++)
        memcpy(o + (size_t)y * (size_t)c->w * 3, v + ((size_t)(y + c->y) * (size_t)w + (size_t)c->x) * 3,
               (size_t)c->w * 3 * sizeof *o);
    return o;
}

int murk_html_compare(const char *path, const char *a_name, const char *r_name, const float *a, const float *r,
                      int w, const struct murk_crop *c, const char *figures, double seconds, double lookups,
                      char *err, size_t errlen)
{
    float *ca = crop_rgb(a, w, c), *cr = crop_rgb(r, w, c);
    float *pix = murk_xmalloc((size_t)c->w * (size_t)c->h * sizeof *pix);
    murk_metrics m;
    murk_metrics_compute(ca, cr, NULL, c->w, (murk_crop){0, 0, c->w, c->h}, &m, pix);
    size_t n = strlen(a_name) + strlen(r_name) + 64;
    char *title = murk_xmalloc(n);
    snprintf(title, n, "murk compare: %s against %s", a_name, r_name);
    murk_html_page *p = murk_html_new("compare", title, c->w, c->h, 2, 1, murk_limit(MURK_LIMIT_PAGE_BYTES));
    murk_html_image(p, 0, a_name, "the test image", ca, 0);
    murk_html_image(p, 1, r_name, "the reference", cr, 1);
    murk_html_error_map(p, 0, pix);
    murk_html_cost_add(p, 0, seconds, lookups, m.relmse);
    murk_html_text(p, "figures", figures);
    int rc = murk_html_write(p, path, err, errlen);
    murk_html_free(p);
    free(title);
    free(pix);
    free(ca);
    free(cr);
    return rc;
}
