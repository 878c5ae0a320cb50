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
    if (murk_output_check(out, err, sizeof err) || murk_output_check(png, err, sizeof err)) {
        merge_fail("murk: %s\n", err, NULL, NULL, NULL);
        free(png);
        free(parts);
        return 1;
    }

    murk_image first = {0}, img = {0};
    float *rgb = NULL;
    const char **owner = NULL; /* the file given for each part index */
    double sums[sizeof sum_keys / sizeof sum_keys[0]] = {0};
    static char counters[16384]; /* murk:counters summed over the parts */
    double max_sample = 0;         /* and the largest of their murk:max_sample */
    char maxs[40];
    int n = 0, rc = 0;
    for (int k = 0; k < nparts && rc == 0; k++) {
        murk_image *p = k ? &img : &first;
        int i, nn;
        if (murk_exr_read(parts[k], p, err, sizeof err) != 0) {
            rc = merge_fail("murk: %s\n", err, NULL, NULL, NULL);
            break;
        }
        if (part_index(murk_image_meta(p, "murk:part"), &i, &nn) != 0) {
            rc = merge_fail("murk: %s: not a part of a murk render --part I/N (no murk:part attribute)\n", parts[k],
                            NULL, NULL, NULL);
            break;
        }
        const char *why = murk_image_meta(p, "murk:interrupted");
        if (!why || strcmp(why, "no") != 0) {
            rc = merge_fail("murk: %s: part %s was interrupted (%s): render it again (or resume its checkpoint)\n",
                            parts[k], murk_image_meta(p, "murk:part"), why ? why : "murk:interrupted missing", NULL);
            break;
        }
        if (k == 0) {
            n = nn;
            owner = murk_xmalloc((size_t)n * sizeof *owner);
            rgb = murk_xmalloc(3 * sizeof(float) * (size_t)p->w * (size_t)p->h);
        } else {
            char what[64];
            const char *diff = NULL;
            if (nn != n)
                diff = "murk:part";
            else if (p->w != first.w || p->h != first.h)
                diff = "the resolution";
            for (size_t s = 0; !diff && s < sizeof same_keys / sizeof same_keys[0]; s++)
                if (strcmp(meta_or_empty(p, same_keys[s]), meta_or_empty(&first, same_keys[s])) != 0)
                    diff = same_keys[s];
            if (diff) {
                snprintf(what, sizeof what, "%s", diff);
                rc = merge_fail("murk: %s: is a part of another render than %s (%s differs); merge the parts of "
                                "one render\n", parts[k], parts[0], what, NULL);
                break;
            }
            if (owner[i]) {
                char idx[64];
                snprintf(idx, sizeof idx, "%d/%d", i, n);
                rc = merge_fail("murk: %s: part %s is given twice (also %s)\n", parts[k], idx, owner[i], NULL);
                break;
            }
        }
        char tiles[32];
        snprintf(tiles, sizeof tiles, "%d", murk_part_tiles(p->w, p->h, i, n));
        if (strcmp(meta_or_empty(p, "murk:part_tiles"), tiles) != 0) {
            rc = merge_fail("murk: %s: murk:part_tiles is '%s', but part %s of this image has %s tiles\n", parts[k],
                            meta_or_empty(p, "murk:part_tiles"), murk_image_meta(p, "murk:part"), tiles);
            break;
        }
        owner[i] = parts[k];
        for (int y = 0; y < p->h; y++)
            for (int x = 0; x < p->w; x++)
                if (murk_part_of(p->w, x, y, n) == i)
                    memcpy(rgb + 3 * ((size_t)y * (size_t)p->w + (size_t)x),
                           p->rgb + 3 * ((size_t)y * (size_t)p->w + (size_t)x), 3 * sizeof(float));
        for (size_t s = 0; s < sizeof sum_keys / sizeof sum_keys[0]; s++)
            sums[s] += strtod(meta_or_empty(p, sum_keys[s]), NULL);
        if (strtod(meta_or_empty(p, "murk:max_sample"), NULL) > max_sample)
            max_sample = strtod(meta_or_empty(p, "murk:max_sample"), NULL);
        if (k == 0)
            snprintf(counters, sizeof counters, "%s", meta_or_empty(p, "murk:counters"));
        else if (json_add(counters, sizeof counters, meta_or_empty(p, "murk:counters")) != 0)
            counters[0] = 0; /* not of one shape: left out rather than wrong */
        if (k)
            murk_image_free(&img);
    }
    for (int i = 0; i < n && rc == 0; i++)
        if (!owner[i]) {
            char idx[64];
            snprintf(idx, sizeof idx, "%d/%d", i, n);
            rc = merge_fail("murk: part %s is missing: render it with --part %s and merge again\n", idx, idx, NULL,
                            NULL);
            fprintf(stderr, "murk: given:");
            for (int k = 0; k < n; k++)
                if (owner[k])
                    fprintf(stderr, " %d:%s", k, owner[k]);
            fputc('\n', stderr);
        }
    if (rc == 0) {
        size_t nm = (size_t)first.nmeta, m = 0;
        murk_kv *meta = murk_xmalloc((nm + 1) * sizeof *meta);
        char (*vals)[64] = murk_xmalloc(sizeof sum_keys / sizeof sum_keys[0] * sizeof *vals);
        for (size_t a = 0; a < nm; a++) {
            const char *key = first.meta[a].key, *val = first.meta[a].value;
            int skip = strncmp(key, "murk:", 5) != 0; /* the file's own attributes are the writer's */
            for (size_t s = 0; s < sizeof part_keys / sizeof part_keys[0]; s++)
                skip |= !strcmp(key, part_keys[s]);
            if (!strcmp(key, "murk:max_sample")) {
                snprintf(maxs, sizeof maxs, "%.17g", max_sample);
                val = maxs;
            }
            if (!strcmp(key, "murk:counters")) {
                skip |= !counters[0];
                val = counters;
            }
            for (size_t s = 0; s < sizeof sum_keys / sizeof sum_keys[0]; s++)
                if (!strcmp(key, sum_keys[s])) {
                    snprintf(vals[s], sizeof vals[s], strchr(val, '.') ? "%.3f" : "%.0f", sums[s]);
                    val = vals[s];
                }
            if (!skip)
                meta[m++] = (murk_kv){key, val};
        }
        char merged[64];
        snprintf(merged, sizeof merged, "%d parts", n);
        meta[m++] = (murk_kv){"murk:merged_from", merged};
        float exposure = strtof(meta_or_empty(&first, "murk:exposure"), NULL);
        murk_output_begin();
        if (murk_exr_write(out, rgb, first.w, first.h, meta, (int)m, err, sizeof err) != 0 ||
            murk_png_write(png, rgb, first.w, first.h, exposure, err, sizeof err) != 0 ||
            murk_output_commit(err, sizeof err) != 0) {
            murk_output_abort();
            rc = merge_fail("murk: %s\n", err, NULL, NULL, NULL);
        } else {
            printf("%s, %s: %dx%d, %d parts merged\n", out, png, first.w, first.h, n);
        }
        free(vals);
        free(meta);
    }
    murk_image_free(&first);
    murk_image_free(&img);
    free(owner);
    free(rgb);
    free(png);
    free(parts);
    return rc;
}
