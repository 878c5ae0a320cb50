/* merge.c — `murk merge OUT.exr PART.exr...`: the parts of a `murk render --part I/N` render into the
 * whole image, bitwise identical to a single-process render of the same scene, --set, seed and spp.
 *
 * A part is an EXR of the full resolution holding the pixels of its tiles: the 16x16 tiles, numbered
 * row-major, with tile % N == I (murk_part_of); the other pixels are 0. Its murk:* attributes say what
 * it is (murk:part I/N, murk:part_split, murk:part_tiles, murk:scene_hash, murk:exposure) and what
 * render it belongs to. Every part must belong to the same render as the first one given (scene hash,
 * --set, seed, spp, resolution, split, murk version, integrator, plugins), be whole (not interrupted),
 * and every I of 0..N-1 must be given exactly once; otherwise the error names the file (or the missing
 * part). Parts are read one at a time, so memory holds two images whatever N. The merged EXR carries
 * the first part's attributes with the times, NaN counts, ranks, threads and cost counters (the numbers
 * of murk:counters) summed over the parts — so its counters are the single-process render's — the
 * largest murk:max_sample, and
 * its PNG preview is written beside it as `render` does: both files or neither. */
#include "cli/cli.h"
#include "image/image.h"
#include "util/atomic.h"
#include "murk/murk.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The attributes every part must share with the first one. */
static const char *const same_keys[] = {
    "murk:scene_hash", "murk:set", "murk:seed", "murk:spp", "murk:part_split", "murk:version",
    "murk:integrator", "murk:plugins", "murk:exposure",
};
/* Attributes summed over the parts in the merged image (printed with %.3f when they hold a '.'). */
static const char *const sum_keys[] = {"murk:render_time", "murk:nonfinite_samples", "murk:ranks", "murk:threads",
                                       "murk:thread_time"};
/* Attributes of a part that the merged image does not carry. */
static const char *const part_keys[] = {"murk:part", "murk:part_tiles"};

/* acc += add for two JSON texts of one shape (murk:counters of the parts of one render): every number
 * outside a string is summed, everything else must be the same. 0, or -1 (acc unchanged) if not. */
static int json_add(char *acc, size_t n, const char *add)
{
    char *out = murk_xmalloc(n);
    const char *a = acc, *b = add;
    size_t k = 0;
    int in_str = 0;
    while (*a && k + 1 < n) {
        if (!in_str && *a >= '0' && *a <= '9' && *b >= '0' && *b <= '9') {
            char *ea, *eb;
            unsigned long long x = strtoull(a, &ea, 10), y = strtoull(b, &eb, 10);
            k += (size_t)snprintf(out + k, n - k, "%llu", x + y);
            a = ea, b = eb;
            continue;
        }
        if (*a != *b)
            break;
        if (*a == '"')
            in_str = !in_str;
        else if (in_str && *a == '\\' && a[1] && a[1] == b[1])
            out[k++] = *a++, b++;
        out[k++] = *a++, b++;
    }
    int ok = !*a && !*b && k < n;
    if (ok) {
        out[k] = 0;
        memcpy(acc, out, k + 1);
    }
    free(out);
    return ok ? 0 : -1;
}

static const char *meta_or_empty(const murk_image *img, const char *key)
{
    const char *v = murk_image_meta(img, key);
    return v ? v : "";
}

/* The message with its (untrusted) words made printable (murk_cli_q); returns 1. */
static int merge_fail(const char *fmt, const char *a, const char *b, const char *c, const char *d)
{
    fprintf(stderr, fmt, murk_cli_q(a ? a : ""), murk_cli_q(b ? b : ""), murk_cli_q(c ? c : ""),
            murk_cli_q(d ? d : ""));
    return 1;
}

/* "I/N" of a part into *i and *n; -1 if it is not one. */
static int part_index(const char *v, int *i, int *n)
{
    char tail;
    if (!v || sscanf(v, "%d/%d%c", i, n, &tail) != 2 || *n < 1 || *i < 0 || *i >= *n)
        return -1;
    return 0;
}

enum { NSUM = sizeof sum_keys / sizeof sum_keys[0] };

/* A merge under way: the first part (its attributes go to the merged image), the merged pixels, which file
 * gave each part index, and the figures summed over the parts read. */
typedef struct merge {
    const char *const *files;
    murk_image first;
    float *rgb;
    const char **owner; /* the file given for each part index */
    int n;              /* the number of parts of the render */
    double sums[NSUM];
    double max_sample;     /* the largest murk:max_sample */
    char counters[16384]; /* murk:counters summed over the parts ("" when not of one shape) */
} merge;

/* Part p (files[k]) is a whole part of the first one's render, one not given before; its index into *i.
 * 0, or 1 after the message. The first part sets the number of parts and the image's size. */
static int check_part(merge *m, int k, const murk_image *p, int *i)
{
    const char *file = m->files[k];
    int nn;
    if (part_index(murk_image_meta(p, "murk:part"), i, &nn) != 0)
        return merge_fail("murk: %s: not a part of a murk render --part I/N (no murk:part attribute)\n", file, NULL,
                          NULL, NULL);
    const char *why = murk_image_meta(p, "murk:interrupted");
    if (!why || strcmp(why, "no") != 0)
        return merge_fail("murk: %s: part %s was interrupted (%s): render it again (or resume its checkpoint)\n", file,
                          murk_image_meta(p, "murk:part"), why ? why : "murk:interrupted missing", NULL);
    if (k == 0) {
        m->n = nn;
        m->owner = murk_xmalloc((size_t)nn * sizeof *m->owner);
        m->rgb = murk_xmalloc(3 * sizeof(float) * (size_t)p->w * (size_t)p->h);
    } else {
        const char *diff = nn != m->n ? "murk:part" : p->w != m->first.w || p->h != m->first.h ? "the resolution" : NULL;
        for (size_t s = 0; !diff && s < sizeof same_keys / sizeof same_keys[0]; s++)
            if (strcmp(meta_or_empty(p, same_keys[s]), meta_or_empty(&m->first, same_keys[s])) != 0)
                diff = same_keys[s];
        if (diff)
            return merge_fail("murk: %s: is a part of another render than %s (%s differs); merge the parts of one "
                              "render\n", file, m->files[0], diff, NULL);
        if (m->owner[*i]) {
            char idx[64];
            snprintf(idx, sizeof idx, "%d/%d", *i, m->n);
            return merge_fail("murk: %s: part %s is given twice (also %s)\n", file, idx, m->owner[*i], NULL);
        }
    }
    char tiles[32];
    snprintf(tiles, sizeof tiles, "%d", murk_part_tiles(p->w, p->h, *i, m->n));
    if (strcmp(meta_or_empty(p, "murk:part_tiles"), tiles) != 0)
        return merge_fail("murk: %s: murk:part_tiles is '%s', but part %s of this image has %s tiles\n", file,
                          meta_or_empty(p, "murk:part_tiles"), murk_image_meta(p, "murk:part"), tiles);
    return 0;
}

/* Part i (files[k], p) into the merged image: its tiles' pixels, its times and counts. */
static void add_part(merge *m, int k, const murk_image *p, int i)
{
    m->owner[i] = m->files[k];
    for (int y = 0; y < p->h; y++)
        for (int x = 0; x < p->w; x++)
            if (murk_part_of(p->w, x, y, m->n) == i)
                memcpy(m->rgb + 3 * ((size_t)y * (size_t)p->w + (size_t)x),
                       p->rgb + 3 * ((size_t)y * (size_t)p->w + (size_t)x), 3 * sizeof(float));
    for (size_t s = 0; s < NSUM; s++)
        m->sums[s] += strtod(meta_or_empty(p, sum_keys[s]), NULL);
    if (strtod(meta_or_empty(p, "murk:max_sample"), NULL) > m->max_sample)
        m->max_sample = strtod(meta_or_empty(p, "murk:max_sample"), NULL);
    if (k == 0)
        snprintf(m->counters, sizeof m->counters, "%s", meta_or_empty(p, "murk:counters"));
    else if (json_add(m->counters, sizeof m->counters, meta_or_empty(p, "murk:counters")) != 0)
        m->counters[0] = 0; /* not of one shape: left out rather than wrong */
}

/* Reads, checks and adds every part, one at a time; then every index must have its part. 0, or 1. */
static int read_parts(merge *m, int nparts)
{
    char err[2048];
    for (int k = 0; k < nparts; k++) {
        murk_image img = {0}, *p = k ? &img : &m->first;
        int i, rc = 0;
        if (murk_exr_read(m->files[k], p, err, sizeof err) != 0)
            rc = merge_fail("murk: %s\n", err, NULL, NULL, NULL);
        else if ((rc = check_part(m, k, p, &i)) == 0)
            add_part(m, k, p, i);
        murk_image_free(&img);
        if (rc)
            return rc;
    }
    for (int i = 0; i < m->n; i++)
        if (!m->owner[i]) {
            char idx[64];
            snprintf(idx, sizeof idx, "%d/%d", i, m->n);
            merge_fail("murk: part %s is missing: render it with --part %s and merge again\n", idx, idx, NULL, NULL);
            fprintf(stderr, "murk: given:");
            for (int k = 0; k < m->n; k++)
                if (m->owner[k])
                    fprintf(stderr, " %d:%s", k, m->owner[k]);
            fputc('\n', stderr);
            return 1;
        }
    return 0;
}

/* The merged EXR, with the first part's murk:* attributes (but a part's own), the sums, the largest
 * sample and the counters, and its PNG preview: both files or neither. 0, or 1 after the message. */
static int write_merged(merge *m, const char *out, const char *png)
{
    size_t nm = (size_t)m->first.nmeta, k = 0;
    murk_kv *meta = murk_xmalloc((nm + 1) * sizeof *meta);
    char vals[NSUM][64], maxs[40], merged[64], err[2048];
    for (size_t a = 0; a < nm; a++) {
        const char *key = m->first.meta[a].key, *val = m->first.meta[a].value;
        int skip = strncmp(key, "murk:", 5) != 0; /* the file's own attributes are the writer's */
        for (size_t s = 0; s < sizeof part_keys / sizeof part_keys[0]; s++)
            skip |= !strcmp(key, part_keys[s]);
        if (!strcmp(key, "murk:max_sample")) {
            snprintf(maxs, sizeof maxs, "%.17g", m->max_sample);
            val = maxs;
        }
        if (!strcmp(key, "murk:counters")) {
            skip |= !m->counters[0];
            val = m->counters;
        }
        for (size_t s = 0; s < NSUM; s++)
            if (!strcmp(key, sum_keys[s])) {
                snprintf(vals[s], sizeof vals[s], strchr(val, '.') ? "%.3f" : "%.0f", m->sums[s]);
                val = vals[s];
            }
        if (!skip)
            meta[k++] = (murk_kv){key, val};
    }
    snprintf(merged, sizeof merged, "%d parts", m->n);
    meta[k++] = (murk_kv){"murk:merged_from", merged};
    float exposure = strtof(meta_or_empty(&m->first, "murk:exposure"), NULL);
    int rc = 0;
    murk_output_begin();
    if (murk_exr_write(out, m->rgb, m->first.w, m->first.h, meta, (int)k, err, sizeof err) != 0 ||
        murk_png_write(png, m->rgb, m->first.w, m->first.h, exposure, err, sizeof err) != 0 ||
        murk_output_commit(err, sizeof err) != 0) {
        murk_output_abort();
        rc = merge_fail("murk: %s\n", err, NULL, NULL, NULL);
    } else {
        printf("%s, %s: %dx%d, %d parts merged\n", out, png, m->first.w, m->first.h, m->n);
    }
    free(meta);
    return rc;
}

int murk_cli_merge(int argc, char **argv)
{
    const char *out = NULL;
    const char **parts = murk_xmalloc((size_t)(argc > 0 ? argc : 1) * sizeof *parts);
    int nparts = 0;
    for (int i = 0; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1]) {
            free(parts);
            return merge_fail("murk: unknown merge option '%s'\nusage: murk merge OUT.exr PART.exr...\n", argv[i],
                              NULL, NULL, NULL) + 1;
        }
        if (!out)
            out = argv[i];
        else
            parts[nparts++] = argv[i];
    }
    size_t ol = out ? strlen(out) : 0;
    if (!out || !nparts || ol < 5 || strcmp(out + ol - 4, ".exr") != 0) {
        free(parts);
        fputs("murk: merge needs an output .exr and the parts (the EXRs of murk render --part I/N)\n"
              "usage: murk merge OUT.exr PART.exr...\n", stderr);
        return 2;
    }
    char err[2048], *png = murk_xmalloc(ol + 1);
    memcpy(png, out, ol - 4);
    memcpy(png + ol - 4, ".png", 5);
    int rc = 0;
    merge *m = murk_xmalloc(sizeof *m);
    m->files = parts;
    if (murk_output_probe(out, "image", err, sizeof err) || murk_output_probe(png, "PNG preview", err, sizeof err))
        rc = merge_fail("murk: %s\n", err, NULL, NULL, NULL);
    if (rc == 0)
        rc = read_parts(m, nparts);
    if (rc == 0)
        rc = write_merged(m, out, png);
    murk_image_free(&m->first);
    free(m->owner);
    free(m->rgb);
    free(m);
    free(png);
    free(parts);
    return rc;
}
