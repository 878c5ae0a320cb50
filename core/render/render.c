/* render.c — one pass of a render (pass.h): tiles over a thread pool; the session (session.c) decides the
 * passes. Each (pixel, sample) has its own random stream seeded from (seed, pixel, sample) and each pixel
 * is accumulated by one thread in sample order, so the image is bitwise identical for any thread count
 * and any split into passes. Non-finite samples are counted and left out of the pixel.
 *
 * Under MPI (mpi_job.h) the same holds for any number of ranks. Rank 0 keeps every pixel's state and
 * decides the passes (the sample ranges: --time, checkpoints and signals are its decisions alone, sent
 * to every rank before each pass: policy_mpi.c). Within a pass its threads take tiles from the shared counter and its
 * main thread hands tiles out to the other ranks on request, one per request: a rank asks for as many
 * tiles as it has threads plus one when the pass starts and for one more with each tile it returns, so
 * a heavy tile holds up one thread, never a rank's queue. A tile travels with its pixels' sums and
 * counts (none in a render's first pass) and comes back with them advanced by the pass's samples in
 * sample order: no pixel is ever summed across ranks, so the sums are the single-process ones bit for
 * bit. Messages per tile and pass: one TILE (16 bytes + 28 per pixel of state) and one RESULT (8 + 28
 * per pixel). The other ranks never hold the image: their render threads advance a tile's state in the
 * TILE message it came in (a held tile), so a rank's memory is its threads + 1 tiles of 7 KB whatever
 * the image's size. */
#include "render/camera.h"
#include "render/host.h"
#include "render/mpi_job.h"
#include "render/pass.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/runtime.h"
#include "util/util.h"

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

/* Slots of held tiles (take_tile) handed between a rank's main thread and its render threads (MPI ranks
 * other than 0): a ring of cap entries, as many as the rank holds tiles at most, so it never overflows. */
typedef struct murk_tile_queue {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int *t;
    int cap, head, tail, closed;
} tile_queue;

typedef murk_job job;

static void queue_init(tile_queue *q, int n)
{
    pthread_mutex_init(&q->mu, NULL);
    pthread_cond_init(&q->cv, NULL);
    q->cap = n > 0 ? n : 1;
    q->t = murk_xmalloc((size_t)q->cap * sizeof *q->t);
    q->head = q->tail = q->closed = 0;
}

static void queue_free(tile_queue *q)
{
    pthread_mutex_destroy(&q->mu);
    pthread_cond_destroy(&q->cv);
    free(q->t);
}

static void queue_push(tile_queue *q, int t)
{
    pthread_mutex_lock(&q->mu);
    q->t[q->tail++ % q->cap] = t;
    pthread_cond_signal(&q->cv);
    pthread_mutex_unlock(&q->mu);
}

/* The next tile, or -1 once the queue is empty and (wait) closed or (!wait) at once. */
static int queue_pop(tile_queue *q, int wait)
{
    pthread_mutex_lock(&q->mu);
    while (wait && q->head == q->tail && !q->closed)
        pthread_cond_wait(&q->cv, &q->mu);
    int t = q->head < q->tail ? q->t[q->head++ % q->cap] : -1;
    pthread_mutex_unlock(&q->mu);
    return t;
}

static void queue_close(tile_queue *q)
{
    pthread_mutex_lock(&q->mu);
    q->closed = 1;
    pthread_cond_broadcast(&q->cv);
    pthread_mutex_unlock(&q->mu);
}

/* A held tile: a rank other than 0 keeps the TILE message a tile came in until its RESULT goes back:
 * a 16-byte header (int32 tile number, has state, 0, 0), then for its n pixels, row by row, n x 3 double
 * sums and n uint32 counts. The render threads advance the state there, so a rank other than 0 holds
 * tiles only, never the image. */
enum { HDR_BYTES = 16 };

/* The sums and counts of a held tile of n pixels, p pointing past its header. */
static double *state_sum(unsigned char *p) { return (double *)(void *)p; }
static uint32_t *state_count(unsigned char *p, size_t n) { return (uint32_t *)(void *)(p + 3 * n * sizeof(double)); }

/* The next tile of this pass for a render thread, or -1 when there is none; *slot is its held tile's slot
 * (MPI ranks other than 0) or -1 (its state is in the image's j->sum and j->count). */
static int take_tile(job *j, int *slot)
{
    *slot = -1;
    if (j->inq) {
        int32_t t;
        if ((*slot = queue_pop(j->inq, 1)) < 0)
            return -1;
        memcpy(&t, j->held[*slot], sizeof t);
        return t;
    }
    int k = atomic_fetch_add(&j->next, 1);
    return k < j->ntiles ? j->tiles[k] : -1;
}

static void tile_done(job *j, int slot, double seconds)
{
    atomic_fetch_add(&j->busy_ns, (uint64_t)(seconds * 1e9));
    if (j->outq)
        queue_push(j->outq, slot);
    atomic_fetch_add(&j->done, 1);
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
        if (murk_job_stopped(j)) {
            if (atomic_load(&j->next) < j->ntiles)
                atomic_store(&j->abandoned, 1);
            break;
        }
        int slot, t = take_tile(j, &slot);
        if (t < 0)
            break;
        double t_tile = murk_now();
        int x0 = (t % j->tiles_x) * TILE, y0 = (t / j->tiles_x) * TILE;
        int x1 = x0 + TILE < s->width ? x0 + TILE : s->width, y1 = y0 + TILE < s->height ? y0 + TILE : s->height;
        /* the state of pixel (x, y) is sum[3 * at], count[at]: at is its index in the image or in the tile */
        double *sum = j->sum;
        uint32_t *count = j->count;
        size_t stride = (size_t)s->width, ox = 0, oy = 0;
        if (slot >= 0) {
            stride = (size_t)(x1 - x0), ox = (size_t)x0, oy = (size_t)y0;
            sum = state_sum(j->held[slot] + HDR_BYTES);
            count = state_count(j->held[slot] + HDR_BYTES, stride * (size_t)(y1 - y0));
        }
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                size_t pix = (size_t)y * (size_t)s->width + (size_t)x, at = ((size_t)y - oy) * stride + (size_t)x - ox;
                double acc[3] = {sum[3 * at], sum[3 * at + 1], sum[3 * at + 2]};
                uint32_t n = count[at];
                for (int k = j->spp0; k < j->spp1; k++) {
                    murk_rng rng;
                    murk_ray r;
                    murk_camera_sample(s, x, y, (uint32_t)k, &rng, &r);
                    murk_rgb L = s->integrator_vt->li(s->integrator, s, &r, &rng);
                    if (j->dump && k < j->dump_spp)
                        memcpy(j->dump + 3 * (pix * (size_t)j->dump_spp + (size_t)k), L.c, sizeof L.c);
                    if (!murk_rgb_finite(L)) {
                        bad++;
                        continue;
                    }
                    acc[0] += L.c[0], acc[1] += L.c[1], acc[2] += L.c[2];
                    for (int c = 0; c < 3; c++) /* plain compares: fmaxf is a libm call here */
                        peak = fabsf(L.c[c]) > peak ? fabsf(L.c[c]) : peak;
                    n++;
                }
                sum[3 * at] = acc[0], sum[3 * at + 1] = acc[1], sum[3 * at + 2] = acc[2];
                count[at] = n;
            }
        tile_done(j, slot, murk_now() - t_tile);
    }
    atomic_fetch_add(&j->rays, murk_host_thread_rays());
    atomic_fetch_add(&j->nonfinite, bad);
    pthread_mutex_lock(&j->lock);
    murk_thread_counters_add(j->media, j->nslots);
    if (peak > j->max_sample)
        j->max_sample = peak;
    pthread_mutex_unlock(&j->lock);
    return NULL;
}

/* ---- tiles between ranks ---------------------------------------------------------------------- */

/* The pixel rectangle of tile t. */
static void tile_rect(const job *j, int t, int *x0, int *y0, int *x1, int *y1)
{
    const murk_scene *s = j->s;
    *x0 = (t % j->tiles_x) * TILE, *y0 = (t / j->tiles_x) * TILE;
    *x1 = *x0 + TILE < s->width ? *x0 + TILE : s->width, *y1 = *y0 + TILE < s->height ? *y0 + TILE : s->height;
}

/* Bytes of a tile's state: 3 double sums and a uint32 count per pixel. */
enum { PIX_BYTES = 3 * sizeof(double) + sizeof(uint32_t), TILE_BYTES = TILE * TILE * PIX_BYTES };

/* Rank 0: copies tile t's state from the image to (dir > 0) or from (dir < 0) the message bytes p, laid
 * out as a held tile's. */
static void tile_state(job *j, int t, unsigned char *p, int dir)
{
    int x0, y0, x1, y1;
    tile_rect(j, t, &x0, &y0, &x1, &y1);
    size_t w = (size_t)(x1 - x0), n = w * (size_t)(y1 - y0);
    unsigned char *sums = p, *counts = p + 3 * n * sizeof(double);
    for (int y = y0; y < y1; y++) {
        size_t pix = (size_t)y * (size_t)j->s->width + (size_t)x0, row = (size_t)(y - y0) * w;
        unsigned char *sum = (unsigned char *)(j->sum + 3 * pix), *count = (unsigned char *)(j->count + pix);
        unsigned char *msum = sums + 3 * row * sizeof(double), *mcount = counts + row * sizeof(uint32_t);
        if (dir > 0) {
            memcpy(msum, sum, 3 * w * sizeof(double));
            memcpy(mcount, count, w * sizeof(uint32_t));
        } else {
            memcpy(sum, msum, 3 * w * sizeof(double));
            memcpy(count, mcount, w * sizeof(uint32_t));
        }
    }
}

/* Rank 0: answers one request of rank `to` with a tile (and its state, after the first pass) or, when
 * there is none left or the pass is being abandoned, with END. */
static void hand_out(job *j, int to, int stopped, int *remote)
{
    int k = stopped ? j->ntiles : atomic_fetch_add(&j->next, 1);
    j->mpi_msgs++;
    if (k >= j->ntiles) {
        int32_t *end = murk_xmalloc(sizeof *end);
        murk_mpi_post(to, MURK_TAG_END, end, sizeof *end);
        j->mpi_bytes += sizeof *end;
        return;
    }
    int t = j->tiles[k], state = j->spp0 > 0;
    size_t n = HDR_BYTES + (state ? TILE_BYTES : 0);
    unsigned char *msg = murk_xmalloc(n);
    int32_t hdr[4] = {t, state, 0, 0};
    memcpy(msg, hdr, sizeof hdr);
    if (state)
        tile_state(j, t, msg + HDR_BYTES, 1);
    murk_mpi_post(to, MURK_TAG_TILE, msg, n);
    (*remote)++;
    j->mpi_tiles++;
    j->mpi_bytes += n;
}

/* CPU seconds of the calling thread (the overhead measurements: not inflated by preemption). */
static double thread_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void nap(void)
{
    struct timespec ts = {0, 200 * 1000};
    nanosleep(&ts, NULL);
}

/* Rank 0's main thread during a pass: serves the other ranks' requests and results, reports progress, and
 * returns when every tile is done (or, once stopped, back) and every rank has been answered. */
static void serve_pass(job *j, murk_pass_tick tick, void *user)
{
    int waiting = murk_mpi_size() - 1, remote = 0, stopped = 0;
    size_t cap = HDR_BYTES + TILE_BYTES;
    unsigned char *buf = murk_xmalloc(cap);
    double drawn = 0;
    for (;;) {
        int from, tag, busy = 0;
        size_t n;
        while (murk_mpi_poll(-1, &from, &tag, &n)) {
            double t_msg = thread_cpu();
            busy = 1;
            j->mpi_msgs++;
            j->mpi_bytes += n;
            if (n > cap)
                buf = murk_xrealloc(buf, cap = n);
            murk_mpi_recv(from, tag, buf, n);
            int32_t k = 1;
            if (tag == MURK_TAG_REQ) {
                memcpy(&k, buf, sizeof k);
                waiting--;
            } else if (tag == MURK_TAG_RESULT) {
                int32_t t;
                memcpy(&t, buf, sizeof t);
                tile_state(j, t, buf + 8, -1);
                remote--;
                atomic_fetch_add(&j->done, 1);
            }
            for (; k > 0; k--)
                hand_out(j, from, stopped, &remote);
            j->mpi_serve += thread_cpu() - t_msg;
        }
        if (!stopped && murk_job_stopped(j)) {
            stopped = 1;
            if (atomic_load(&j->next) < j->ntiles)
                atomic_store(&j->abandoned, 1);
        }
        if (waiting == 0 && remote == 0 && (stopped || atomic_load(&j->done) >= j->ntiles))
            break;
        if (tick && murk_now() - drawn > 0.2) {
            drawn = murk_now();
            tick(user, (double)atomic_load(&j->done) / j->ntiles);
        }
        if (!busy)
            nap();
    }
    free(buf);
    murk_mpi_flush();
}

/* The main thread of a rank other than 0 during a pass: asks for `ask` tiles, receives each tile that
 * comes into a free held tile's slot (there is one: a rank holds at most as many tiles as it asked for)
 * and queues it for its render threads, returns each rendered tile (which asks for the next) and
 * returns when every request has been answered and every tile it got is back. */
static void work_pass(job *j, int ask)
{
    int32_t *req = murk_xmalloc(sizeof *req);
    *req = ask;
    murk_mpi_post(0, MURK_TAG_REQ, req, sizeof *req);
    int asked = ask, held = 0, nfree = ask, *freed = murk_xmalloc((size_t)ask * sizeof *freed);
    for (int k = 0; k < ask; k++)
        freed[k] = k;
    for (;;) {
        int from, tag, k, busy = 0;
        size_t n;
        while (murk_mpi_poll(0, &from, &tag, &n)) {
            busy = 1;
            asked--;
            if (tag != MURK_TAG_TILE) { /* END */
                int32_t end;
                murk_mpi_recv(0, tag, &end, sizeof end);
                continue;
            }
            if (nfree == 0) { /* rank 0 sent more tiles than were asked for: never, by the protocol */
                fprintf(stderr, "murk: rank %d (%s): a tile beyond the %d asked for\n", murk_mpi_rank(),
                        murk_mpi_host(), ask);
                murk_mpi_abort(1);
            }
            unsigned char *msg = j->held[k = freed[--nfree]];
            murk_mpi_recv(0, tag, msg, n > HDR_BYTES + TILE_BYTES ? HDR_BYTES + TILE_BYTES : n);
            int32_t hdr[4];
            memcpy(hdr, msg, sizeof hdr);
            if (!hdr[1]) /* a render's first pass: no state yet */
                memset(msg + HDR_BYTES, 0, TILE_BYTES);
            held++;
            queue_push(j->inq, k);
        }
        while ((k = queue_pop(j->outq, 0)) >= 0) {
            busy = 1;
            unsigned char *msg = murk_xmalloc(8 + TILE_BYTES);
            int32_t hdr[2];
            memcpy(hdr, j->held[k], sizeof hdr[0]);
            hdr[1] = 0;
            memcpy(msg, hdr, sizeof hdr);
            memcpy(msg + 8, j->held[k] + HDR_BYTES, TILE_BYTES);
            murk_mpi_post(0, MURK_TAG_RESULT, msg, 8 + TILE_BYTES);
            freed[nfree++] = k;
            held--;
            asked++;
        }
        if (asked == 0 && held == 0)
            break;
        if (!busy)
            nap();
    }
    free(freed);
    queue_close(j->inq);
    murk_mpi_flush();
}

void murk_job_run_pass(job *j, int nthreads, murk_pass_tick tick, void *user)
{
    atomic_store(&j->next, 0);
    atomic_store(&j->done, 0);
    atomic_store(&j->abandoned, 0);
    if (j->inq) {
        j->inq->head = j->inq->tail = j->inq->closed = 0;
        j->outq->head = j->outq->tail = 0;
    }
    pthread_t *th = murk_xmalloc((size_t)nthreads * sizeof *th);
    int started = 0;
    for (; started < nthreads; started++)
        if (pthread_create(&th[started], NULL, worker, j) != 0)
            break;
    if (started == 0 && murk_mpi_size() > 1) {
        fprintf(stderr, "murk: rank %d (%s): cannot start a render thread\n", murk_mpi_rank(), murk_mpi_host());
        murk_mpi_abort(1);
    }
    if (started == 0) {
        free(th);
        worker(j); /* no threads to be had: render here */
        return;
    }
    if (j->inq)
        work_pass(j, started + 1); /* at most nthreads + 1: as many as there are slots of held tiles */
    else if (murk_mpi_size() > 1)
        serve_pass(j, tick, user);
    else
        while (tick && atomic_load(&j->done) < j->ntiles && !murk_job_stopped(j)) {
            tick(user, (double)atomic_load(&j->done) / j->ntiles);
            struct timespec ts = {0, 200 * 1000 * 1000};
            nanosleep(&ts, NULL);
        }
    for (int i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    free(th);
}

MURK_API int murk_part_of(int w, int x, int y, int parts)
{
    int tiles_x = (w + TILE - 1) / TILE;
    return parts > 0 ? ((y / TILE) * tiles_x + x / TILE) % parts : 0;
}

MURK_API int murk_part_tiles(int w, int h, int part, int parts)
{
    int n = ((w + TILE - 1) / TILE) * ((h + TILE - 1) / TILE);
    return parts > 0 ? n / parts + (part < n % parts) : n;
}

void murk_job_init(job *j, const murk_scene *s, int part, int parts, int image)
{
    memset(j, 0, sizeof *j);
    j->s = s;
    j->tiles_x = (s->width + TILE - 1) / TILE;
    atomic_init(&j->next, 0);
    atomic_init(&j->done, 0);
    atomic_init(&j->rays, 0);
    atomic_init(&j->nonfinite, 0);
    atomic_init(&j->busy_ns, 0);
    atomic_init(&j->halt, 0);
    atomic_init(&j->abandoned, 0);
    pthread_mutex_init(&j->lock, NULL);
    j->nslots = s->nmedia < MURK_COUNTER_SLOTS ? s->nmedia : MURK_COUNTER_SLOTS;
    if (!image) /* a rank other than 0 holds the tiles rank 0 hands it, not the image */
        return;
    size_t npix = (size_t)s->width * (size_t)s->height;
    j->sum = murk_xmalloc(3 * npix * sizeof(double));
    j->count = murk_xmalloc(npix * sizeof(uint32_t));
    int alltiles = j->tiles_x * ((s->height + TILE - 1) / TILE);
    j->tiles = murk_xmalloc((size_t)alltiles * sizeof *j->tiles);
    for (int t = 0; t < alltiles; t++)
        if (murk_part_of(s->width, (t % j->tiles_x) * TILE, (t / j->tiles_x) * TILE, parts) == part) {
            int x0, y0, x1, y1;
            j->tiles[j->ntiles++] = t;
            tile_rect(j, t, &x0, &y0, &x1, &y1);
            j->npix_rendered += (size_t)(x1 - x0) * (size_t)(y1 - y0);
        }
}

void murk_job_hold(job *j, int nthreads)
{
    j->nheld = nthreads + 1;
    j->inq = murk_xmalloc(sizeof *j->inq);
    j->outq = murk_xmalloc(sizeof *j->outq);
    queue_init(j->inq, j->nheld);
    queue_init(j->outq, j->nheld);
    j->held = murk_xmalloc((size_t)j->nheld * sizeof *j->held);
    for (int k = 0; k < j->nheld; k++)
        j->held[k] = murk_xmalloc(HDR_BYTES + TILE_BYTES); /* zeroed: a RESULT's unused bytes are defined */
}

void murk_job_free(job *j)
{
    if (j->inq) {
        queue_free(j->inq);
        queue_free(j->outq);
        free(j->inq);
        free(j->outq);
    }
    for (int k = 0; k < j->nheld; k++)
        free(j->held[k]);
    free(j->held);
    free(j->sum);
    free(j->count);
    free(j->tiles);
    free(j->dump);
    pthread_mutex_destroy(&j->lock);
}
