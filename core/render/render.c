/* render.c — tiles over a thread pool. Each (pixel, sample) has its own random stream seeded from
 * (seed, pixel, sample) and each pixel is accumulated by one thread in sample order, so the image is
 * bitwise identical for any thread count. Non-finite samples are counted and left out of the pixel. */
#include "host.h"
#include "scene.h"
#include "util.h"

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
    for (;;) {
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
                    n++;
                }
                j->sum[3 * pix] = acc[0], j->sum[3 * pix + 1] = acc[1], j->sum[3 * pix + 2] = acc[2];
                j->count[pix] = n;
            }
        atomic_fetch_add(&j->done, 1);
    }
    atomic_fetch_add(&j->rays, murk_host_thread_rays());
    atomic_fetch_add(&j->nonfinite, bad);
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
    pthread_t *th = murk_xmalloc((size_t)nthreads * sizeof *th);
    int started = 0;
    for (; started < nthreads; started++)
        if (pthread_create(&th[started], NULL, worker, j) != 0)
            break;
    if (started == 0) {
        free(th);
        worker(j); /* no threads to be had: render here */
    } else {
        while (progress && atomic_load(&j->done) < j->ntiles) {
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

MURK_API int murk_render(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out)
{
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
    atomic_init(&j.rays, 0);
    atomic_init(&j.nonfinite, 0);

    double t0 = murk_now();
    int done = 0, pass = 1;
    while (done < spp) {
        int n = opts->time_limit > 0 ? pass : spp - done;
        if (n > spp - done)
            n = spp - done;
        j.spp0 = done;
        j.spp1 = done + n;
        double tp = murk_now();
        run_pass(&j, nthreads, opts->progress, t0, spp, done);
        done += n;
        if (opts->time_limit > 0) {
            double now = murk_now(), per_spp = (now - tp) / n, left = opts->time_limit - (now - t0);
            if (left <= per_spp)
                break;
            pass = (int)(left / per_spp * 0.9); /* next pass fills most of what is left */
            if (pass < 1)
                pass = 1;
            if (pass > 2 * n + 1)
                pass = 2 * n + 1; /* grow gradually so the estimate can adapt */
        }
    }
    if (opts->progress) {
        progress_bar((double)done / spp, murk_now() - t0);
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
    out->samples = (uint64_t)done * npix;
    out->rays = atomic_load(&j.rays);
    out->nonfinite = atomic_load(&j.nonfinite);
    free(j.sum);
    free(j.count);
    return 0;
}
