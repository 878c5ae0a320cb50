/* bench_ref.c — `murk bench`'s reference (bench.h): rendered in independent chunks, whose spread gives
 * the variance of its per-pixel mean, and cached by content. Part of libmurklab. */
#include "lab/bench.h"

#include "cmd/cmd.h"
#include "image/image.h"
#include "load/load.h"
#include "util/atomic.h"
#include "util/util.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

static void cache_dir(char *buf, size_t n)
{
    const char *d = getenv("MURK_CACHE_DIR"), *x = getenv("XDG_CACHE_HOME"), *h = getenv("HOME");
    if (d && *d)
        snprintf(buf, n, "%s", d);
    else if (x && *x)
        snprintf(buf, n, "%s/murk", x);
    else
        snprintf(buf, n, "%s/.cache/murk", h && *h ? h : "/tmp");
}

void murk_bench_ref_free(reference *r)
{
    free(r->rgb);
    free(r->var);
}

int murk_bench_read_exr(const char *path, int w, int h, float **out)
{
    murk_image im = {0};
    char err[1024];
    if (murk_exr_read(path, &im, err, sizeof err) || im.w != w || im.h != h) {
        murk_image_free(&im);
        return -1;
    }
    *out = im.rgb;
    im.rgb = NULL;
    murk_image_free(&im);
    return 0;
}

/* Renders the reference in REF_CHUNKS independent chunks (seeds 900001..): the mean of the chunks is the
 * reference and the variance of its per-pixel mean is estimated without bias from the chunks' spread,
 * s^2 / REF_CHUNKS (s^2 the chunks' sample variance). Cached under the content hash of the scene file and
 * of every file it loads, the --set overrides, the spp, murk's version and the commit it was built from
 * (so a build that renders differently never compares against an older build's reference; a build with
 * uncommitted edits, "-dirty", shares the key of its commit): the mean and the variance as one group of
 * atomic writes (both files or neither). A stop signal abandons it (-1, nothing cached). */
int murk_bench_reference(const bench *b, reference *r)
{
    char err[2048], dir[3072];
    const char **sets = murk_xmalloc(murk_bench_max_sets(b) * sizeof *sets);
    char *store[BENCH_STORE];
    size_t nstore = 0, n = murk_bench_sets(b, -1, -1, sets, store, &nstore);
    /* the scene file and every file it loads (meshes, grids, textures), as a checkpoint hashes them */
    murk_scene *hs = murk_bench_load(b, sets, n, err, sizeof err);
    uint64_t sh = hs ? murk_scene_hash(hs, err, sizeof err) : 0;
    murk_scene_free(hs);
    if (!sh) {
        fprintf(stderr, "%s\n", err);
        murk_bench_free_sets(store, &nstore);
        free(sets);
        return -1;
    }
    uint64_t h = fnv(1469598103934665603ull, "murk bench reference 1", 23);
    h = fnv(h, MURK_VERSION, sizeof MURK_VERSION);
    h = fnv(h, murk_build_commit(), strlen(murk_build_commit()) + 1);
    h = fnv(h, &sh, sizeof sh);
    h = fnv(h, &b->ref_spp, sizeof b->ref_spp);
    for (size_t i = 0; i < n; i++)
        h = fnv(h, sets[i], strlen(sets[i]) + 1);
    cache_dir(dir, sizeof dir);
    char var_path[4200];
    snprintf(r->path, sizeof r->path, "%s/bench-ref-%016llx.exr", dir, (unsigned long long)h);
    snprintf(var_path, sizeof var_path, "%s/bench-ref-%016llx-var.exr", dir, (unsigned long long)h);
    r->spp = b->ref_spp;
    if (!b->assemble && murk_bench_read_exr(r->path, r->w, r->h, &r->rgb) == 0 &&
        murk_bench_read_exr(var_path, r->w, r->h, &r->var) == 0) {
        r->reused = 1;
        murk_bench_free_sets(store, &nstore);
        free(sets);
        return 0;
    }
    free(r->rgb);
    r->rgb = NULL;
    size_t np = (size_t)r->w * (size_t)r->h * 3;
    double *s1 = calloc(np, sizeof *s1), *s2 = calloc(np, sizeof *s2);
    int rc = s1 && s2 ? 0 : -1;
    for (int c = 0; c < REF_CHUNKS && rc == 0; c++) {
        char seed[40];
        snprintf(seed, sizeof seed, "render.seed=%d", 900001 + c);
        sets[n] = seed;
        murk_render_opts o = {.spp = (b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS, .threads = b->threads,
                              .stop = b->stop};
        if (murk_bench_stopped(b)) {
            rc = -1;
            break;
        }
        murk_render_result res;
        if (murk_cli_progress() && !b->assemble)
            fprintf(stderr, "\rmurk bench: reference chunk %d of %d (%d spp)...   ", c + 1, REF_CHUNKS, o.spp);
        if (murk_bench_render(b, -1, 0, c, sets, n + 1, &o, r->w, r->h, &res) != 0) {
            rc = -1;
        } else {
            for (size_t i = 0; i < np; i++) {
                s1[i] += res.rgb[i];
                s2[i] += (double)res.rgb[i] * res.rgb[i];
            }
            r->seconds += res.seconds;
        }
        free(res.rgb);
    }
    if (murk_cli_progress() && !b->assemble)
        fputc('\n', stderr);
    if (rc == 0) {
        r->rgb = murk_xmalloc(np * sizeof(float));
        r->var = murk_xmalloc(np * sizeof(float));
        for (size_t i = 0; i < np; i++) {
            double m = s1[i] / REF_CHUNKS, v = (s2[i] - s1[i] * m) / (REF_CHUNKS - 1);
            r->rgb[i] = (float)m;
            r->var[i] = (float)(fmax(v, 0.0) / REF_CHUNKS);
        }
        char spp[32];
        snprintf(spp, sizeof spp, "%d", REF_CHUNKS * ((b->ref_spp + REF_CHUNKS - 1) / REF_CHUNKS));
        murk_kv meta[] = {{"murk:scene", b->scene}, {"murk:spp", spp}, {"murk:version", MURK_VERSION},
                          {"murk:bench", "reference: the mean of 4 chunks"}};
        murk_kv vmeta[] = {{"murk:scene", b->scene}, {"murk:bench", "variance of the reference's per-pixel mean"}};
        err[0] = 0;
        murk_output_begin();
        if (murk_bench_mkdirs(dir) != 0 || murk_exr_write(r->path, r->rgb, r->w, r->h, meta, 4, err, sizeof err) != 0 ||
            murk_exr_write(var_path, r->var, r->w, r->h, vmeta, 2, err, sizeof err) != 0 ||
            murk_output_commit(err, sizeof err) != 0) {
            murk_output_abort();
            fprintf(stderr, "murk: warning: could not cache the reference in %s (%s); it will be rendered again "
                    "next time\n", murk_cli_q(dir), err[0] ? err : strerror(errno));
        }
    }
    free(s1);
    free(s2);
    murk_bench_free_sets(store, &nstore);
    free(sets);
    return rc;
}
