/* render.c — tiles over a thread pool. Each (pixel, sample) has its own random stream seeded from
 * (seed, pixel, sample) and each pixel is accumulated by one thread in sample order, so the image is
 * bitwise identical for any thread count. Non-finite samples are counted and left out of the pixel. */
#include "checkpoint.h"
#include "error.h"
#include "host.h"
#include "scene.h"
#include "util.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#define MURK_HAVE_FTZ 1
#endif

enum { TILE = 16 };

typedef struct job {
    const murk_scene *s;
    int spp0, spp1; /* sample range of this pass */
    double *sum;    /* 3 per pixel */
    uint32_t *count;
    int tiles_x, ntiles;
    atomic_int next;
    atomic_int done;
    atomic_uint_fast64_t rays, nonfinite;
    volatile sig_atomic_t *stop; /* set: take no more tiles; the pass is abandoned */
    atomic_int abandoned;
    pthread_mutex_t lock; /* guards media: each thread adds its cost counters once, when it ends */
    size_t nslots;
    murk_counters media[MURK_COUNTER_SLOTS];
    double max_sample; /* the largest channel of a finite sample */
} job;

static void camera_ray(const murk_scene *s, float fx, float fy, murk_ray *r)
{
    float aspect = (float)s->width / (float)s->height;
    float px = (2.0f * fx / (float)s->width - 1.0f) * s->cam_tan * aspect;
    float py = (1.0f - 2.0f * fy / (float)s->height) * s->cam_tan;
    r->o = s->cam_from;
    r->d = murk_normalize(murk_add(s->cam_w, murk_add(murk_mul(s->cam_u, px), murk_mul(s->cam_v, py))));
    r->tmin = 0.0f;
    r->tmax = INFINITY;
}

static void *worker(void *arg)
{
    job *j = arg;
#ifdef MURK_HAVE_FTZ
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    const murk_scene *s = j->s;
    murk_host_thread_reset();
    uint64_t bad = 0;
    float peak = 0.0f;
    for (;;) {
        if (j->stop && *j->stop) {
            if (atomic_load(&j->next) < j->ntiles)
                atomic_store(&j->abandoned, 1);
            break;
        }
        int t = atomic_fetch_add(&j->next, 1);
        if (t >= j->ntiles)
            break;
        int x0 = (t % j->tiles_x) * TILE, y0 = (t / j->tiles_x) * TILE;
        int x1 = x0 + TILE < s->width ? x0 + TILE : s->width, y1 = y0 + TILE < s->height ? y0 + TILE : s->height;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                size_t pix = (size_t)y * (size_t)s->width + (size_t)x;
                double acc[3] = {j->sum[3 * pix], j->sum[3 * pix + 1], j->sum[3 * pix + 2]};
                uint32_t n = j->count[pix];
                for (int k = j->spp0; k < j->spp1; k++) {
                    murk_rng rng;
                    murk_rng_seed(&rng, s->seed, pix, (uint64_t)k);
                    float jx = murk_rng_float(&rng), jy = murk_rng_float(&rng);
                    murk_ray r;
                    camera_ray(s, (float)x + jx, (float)y + jy, &r);
                    murk_rgb L = s->integrator_vt->li(s->integrator, s, &r, &rng);
                    if (!murk_rgb_finite(L)) {
                        bad++;
                        continue;
                    }
                    acc[0] += L.c[0], acc[1] += L.c[1], acc[2] += L.c[2];
                    for (int c = 0; c < 3; c++) /* plain compares: fmaxf is a libm call here */
                        peak = fabsf(L.c[c]) > peak ? fabsf(L.c[c]) : peak;
                    n++;
                }
                j->sum[3 * pix] = acc[0], j->sum[3 * pix + 1] = acc[1], j->sum[3 * pix + 2] = acc[2];
                j->count[pix] = n;
            }
        atomic_fetch_add(&j->done, 1);
    }
    atomic_fetch_add(&j->rays, murk_host_thread_rays());
    atomic_fetch_add(&j->nonfinite, bad);
    pthread_mutex_lock(&j->lock);
    murk_host_thread_counters_add(j->media, j->nslots);
    if (peak > j->max_sample)
        j->max_sample = peak;
    pthread_mutex_unlock(&j->lock);
    return NULL;
}

static void progress_bar(double frac, double elapsed)
{
    int width = 40, fill = (int)(frac * width + 0.5);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[width] = 0;
    double eta = frac > 0.001 ? elapsed * (1.0 - frac) / frac : 0.0;
    fprintf(stderr, "\r[%s] %5.1f%%  %6.1fs  ETA %6.1fs ", bar, 100.0 * frac, elapsed, eta);
    fflush(stderr);
}

/* Renders samples [spp0, spp1) of every pixel on nthreads threads. */
static int run_pass(job *j, int nthreads, int progress, double t_start, int spp_total, int spp_before)
{
    atomic_store(&j->next, 0);
    atomic_store(&j->done, 0);
    atomic_store(&j->abandoned, 0);
    pthread_t *th = murk_xmalloc((size_t)nthreads * sizeof *th);
    int started = 0;
    for (; started < nthreads; started++)
        if (pthread_create(&th[started], NULL, worker, j) != 0)
            break;
    if (started == 0) {
        free(th);
        worker(j); /* no threads to be had: render here */
    } else {
        while (progress && atomic_load(&j->done) < j->ntiles && !(j->stop && *j->stop)) {
            double frac = ((double)spp_before + (double)(j->spp1 - j->spp0) * atomic_load(&j->done) / j->ntiles) /
                          (double)spp_total;
            progress_bar(frac, murk_now() - t_start);
            struct timespec ts = {0, 200 * 1000 * 1000};
            nanosleep(&ts, NULL);
        }
        for (int i = 0; i < started; i++)
            pthread_join(th[i], NULL);
        free(th);
    }
    return 0;
}

/* Saves the state after `done` whole samples per pixel; 0 or -1 with err set. */
static int save_checkpoint(const murk_scene *s, const murk_render_opts *opts, const job *j, int done, char *err,
                           size_t errlen)
{
    murk_ckpt c = {.scene_hash = opts->scene_hash, .seed = s->seed, .width = s->width, .height = s->height,
                   .spp = done, .overrides = opts->overrides ? opts->overrides : "",
                   .nonfinite = (uint64_t)atomic_load(&j->nonfinite), .rays = (uint64_t)atomic_load(&j->rays),
                   .sum = j->sum, .count = j->count};
    return murk_ckpt_save(opts->checkpoint, &c, err, errlen);
}

MURK_API int murk_render(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out)
{
    return murk_render_err(s, opts, out, NULL, 0);
}

/* Passes: with a time limit, stop signal or checkpoint, passes are sized to take about PASS_SECONDS (the
 * loss when a pass is abandoned, the granularity of checkpoints); otherwise one pass does every sample.
 * Only whole passes count: a pass abandoned on a stop is rolled back from the copy taken before it. */
#define PASS_SECONDS 0.5

MURK_API int murk_render_err(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out, char *err,
                             size_t errlen)
{
    char errbuf[1024];
    if (!err || !errlen)
        err = errbuf, errlen = sizeof errbuf;
    err[0] = 0;
    memset(out, 0, sizeof *out);
    int spp = opts->spp > 0 ? opts->spp : s->spp;
    int nthreads = opts->threads > 0 ? opts->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (nthreads < 1)
        nthreads = 1;
    size_t npix = (size_t)s->width * (size_t)s->height;
    job j;
    memset(&j, 0, sizeof j);
    j.s = s;
    j.sum = murk_xmalloc(3 * npix * sizeof(double));
    j.count = murk_xmalloc(npix * sizeof(uint32_t));
    j.tiles_x = (s->width + TILE - 1) / TILE;
    j.ntiles = j.tiles_x * ((s->height + TILE - 1) / TILE);
    j.stop = opts->stop;
    atomic_init(&j.rays, 0);
    atomic_init(&j.nonfinite, 0);
    atomic_init(&j.abandoned, 0);
    pthread_mutex_init(&j.lock, NULL);
    j.nslots = s->nmedia < MURK_COUNTER_SLOTS ? s->nmedia : MURK_COUNTER_SLOTS;

    int done = 0, rc = 0;
    uint64_t rays_before = 0;
    if (opts->resume) {
        murk_ckpt want = {.scene_hash = opts->scene_hash, .seed = s->seed, .width = s->width, .height = s->height,
                          .overrides = opts->overrides}, c;
        if (murk_ckpt_load(opts->resume, &want, &c, err, errlen) != 0) {
            free(j.sum);
            free(j.count);
            return -1;
        }
        if (c.spp > spp) {
            murk_err_file(err, errlen, opts->resume, "the checkpoint has %d spp, more than the %d asked for", c.spp,
                          spp);
            murk_ckpt_free(&c);
            free(j.sum);
            free(j.count);
            return -1;
        }
        memcpy(j.sum, c.sum, 3 * npix * sizeof(double));
        memcpy(j.count, c.count, npix * sizeof(uint32_t));
        atomic_store(&j.nonfinite, c.nonfinite);
        atomic_store(&j.rays, c.rays);
        rays_before = c.rays;
        done = out->resumed_spp = c.spp;
        murk_ckpt_free(&c);
    }
    int adaptive = opts->time_limit > 0 || opts->stop || opts->checkpoint;
    double *keep_sum = opts->stop ? murk_xmalloc(3 * npix * sizeof(double)) : NULL;
    uint32_t *keep_count = opts->stop ? murk_xmalloc(npix * sizeof(uint32_t)) : NULL;

    double t0 = murk_now(), last_ckpt = t0;
    int pass = 1, start = done;
    while (done < spp && !(opts->stop && *opts->stop)) {
        int n = adaptive ? pass : spp - done;
        if (n > spp - done)
            n = spp - done;
        j.spp0 = done;
        j.spp1 = done + n;
        uint64_t bad_before = (uint64_t)atomic_load(&j.nonfinite);
        if (keep_sum) {
            memcpy(keep_sum, j.sum, 3 * npix * sizeof(double));
            memcpy(keep_count, j.count, npix * sizeof(uint32_t));
        }
        double tp = murk_now();
        run_pass(&j, nthreads, opts->progress, t0, spp - start, done - start);
        if (atomic_load(&j.abandoned)) { /* roll the partial pass back: only whole passes count */
            memcpy(j.sum, keep_sum, 3 * npix * sizeof(double));
            memcpy(j.count, keep_count, npix * sizeof(uint32_t));
            atomic_store(&j.nonfinite, bad_before);
            break;
        }
        done += n;
        double now = murk_now(), per_spp = (now - tp) / n;
        if (opts->checkpoint && done < spp && now - last_ckpt >= opts->checkpoint_every &&
            !(opts->stop && *opts->stop)) {
            if (save_checkpoint(s, opts, &j, done, err, errlen) != 0) {
                if (opts->stop && *opts->stop) { /* the signal cut the write short: the final save redoes it */
                    err[0] = 0;
                    break;
                }
                rc = -1;
                break;
            }
            last_ckpt = murk_now();
        }
        if (opts->time_limit > 0) {
            double left = opts->time_limit - (now - t0);
            if (left <= per_spp)
                break;
            pass = (int)(left / per_spp * 0.9); /* next pass fills most of what is left */
        } else if (adaptive) {
            pass = (int)(PASS_SECONDS / (per_spp > 1e-9 ? per_spp : 1e-9));
        }
        if (pass < 1)
            pass = 1;
        if (pass > 2 * n + 1)
            pass = 2 * n + 1; /* grow gradually so the estimate can adapt */
    }
    out->interrupted = done < spp && opts->stop && *opts->stop;
    if (rc == 0 && opts->checkpoint && save_checkpoint(s, opts, &j, done, err, errlen) != 0)
        rc = -1;
    free(keep_sum);
    free(keep_count);
    if (opts->progress) {
        progress_bar((double)(done - start) / (spp - start > 0 ? spp - start : 1), murk_now() - t0);
        fputc('\n', stderr);
    }
    out->seconds = murk_now() - t0;
    out->width = s->width;
    out->height = s->height;
    out->spp = done;
    out->rgb = murk_xmalloc(3 * npix * sizeof(float));
    for (size_t i = 0; i < npix; i++)
        for (int c = 0; c < 3; c++)
            out->rgb[3 * i + (size_t)c] = j.count[i] ? (float)(j.sum[3 * i + (size_t)c] / j.count[i]) : 0.0f;
    out->samples = (uint64_t)(done - start) * npix;
    out->rays = atomic_load(&j.rays) - rays_before;
    out->nonfinite = atomic_load(&j.nonfinite);
    out->nmedia = (int)j.nslots;
    out->max_sample = j.max_sample;
    memcpy(out->media, j.media, sizeof j.media);
    pthread_mutex_destroy(&j.lock);
    free(j.sum);
    free(j.count);
    return rc;
}
