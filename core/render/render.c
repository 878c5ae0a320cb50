/* render.c — tiles over a thread pool. Each (pixel, sample) has its own random stream seeded from
 * (seed, pixel, sample) and each pixel is accumulated by one thread in sample order, so the image is
 * bitwise identical for any thread count. Non-finite samples are counted and left out of the pixel.
 *
 * Under MPI (mpi_job.h) the same holds for any number of ranks. Rank 0 keeps every pixel's state and
 * decides the passes (the sample ranges: --time, checkpoints and signals are its decisions alone, sent
 * to every rank before each pass). Within a pass its threads take tiles from the shared counter and its
 * main thread hands tiles out to the other ranks on request, one per request: a rank asks for as many
 * tiles as it has threads plus one when the pass starts and for one more with each tile it returns, so
 * a heavy tile holds up one thread, never a rank's queue. A tile travels with its pixels' sums and
 * counts (none in a render's first pass) and comes back with them advanced by the pass's samples in
 * sample order: no pixel is ever summed across ranks, so the sums are the single-process ones bit for
 * bit. Messages per tile and pass: one TILE (16 bytes + 28 per pixel of state) and one RESULT (8 + 28
 * per pixel). The other ranks never hold the image: their render threads advance a tile's state in the
 * TILE message it came in (a held tile), so a rank's memory is its threads + 1 tiles of 7 KB whatever
 * the image's size. After each pass the ranks' rays, NaN counts and busy time are summed into rank 0. */
#include "render/camera.h"
#include "render/checkpoint.h"
#include "render/host.h"
#include "render/mpi_job.h"
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
typedef struct tile_queue {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int *t;
    int cap, head, tail, closed;
} tile_queue;

typedef struct job {
    const murk_scene *s;
    int spp0, spp1; /* sample range of this pass */
    double *sum;    /* 3 per pixel */
    uint32_t *count;
    int tiles_x, ntiles;
    const int *tiles; /* the ntiles tile numbers rendered (all, or one --part's) */
    atomic_int next;
    atomic_int done;
    atomic_uint_fast64_t rays, nonfinite, busy_ns;
    volatile sig_atomic_t *stop; /* set: take no more tiles; the pass is abandoned */
    atomic_int abandoned;
    pthread_mutex_t lock; /* guards media: each thread adds its cost counters once, when it ends */
    size_t nslots;
    murk_counters media[MURK_COUNTER_SLOTS];
    double max_sample; /* the largest channel of a finite sample */
    tile_queue *inq, *outq; /* MPI ranks other than 0: slots of tiles to render, of tiles rendered */
    unsigned char **held;   /* MPI ranks other than 0: the held tiles' TILE messages by slot */
    /* rank 0 under MPI (MURK_MPI_STATS=1 prints them): tiles handed to other ranks, messages and bytes
     * received and sent, seconds its main thread spent handling them, passes */
    uint64_t mpi_tiles, mpi_msgs, mpi_bytes, mpi_passes;
    double mpi_serve;
    float *dump; /* MURK_SAMPLE_DUMP: every sample's RGB, [pixel][sample][3], non-finite ones too */
    int dump_spp;
} job;

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
        if (j->stop && *j->stop) {
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

/* Rank 0's main thread during a pass: serves the other ranks' requests and results, draws the progress
 * bar, and returns when every tile is done (or, once stopped, back) and every rank has been answered. */
static void serve_pass(job *j, int progress, double t_start, int spp_total, int spp_before)
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
        if (!stopped && j->stop && *j->stop) {
            stopped = 1;
            if (atomic_load(&j->next) < j->ntiles)
                atomic_store(&j->abandoned, 1);
        }
        if (waiting == 0 && remote == 0 && (stopped || atomic_load(&j->done) >= j->ntiles))
            break;
        if (progress && murk_now() - drawn > 0.2) {
            drawn = murk_now();
            progress_bar(((double)spp_before + (double)(j->spp1 - j->spp0) * atomic_load(&j->done) / j->ntiles) /
                         (double)spp_total, drawn - t_start);
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

/* Renders samples [spp0, spp1) of every pixel on nthreads threads (under MPI: of this rank). */
static void run_pass(job *j, int nthreads, int progress, double t_start, int spp_total, int spp_before)
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
        serve_pass(j, progress, t_start, spp_total, spp_before);
    else
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
 * loss when a pass is abandoned, the granularity of checkpoints), MPI_PASS_SECONDS under MPI, where every
 * pass moves every tile's state twice; otherwise one pass does every sample.
 * Only whole passes count: a pass abandoned on a stop is rolled back from the copy taken before it. */
#define PASS_SECONDS 0.5
#define MPI_PASS_SECONDS 2.0

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

/* What rank 0 sends every rank before each pass and at the end (cmd PASS_END: spp0 = the spp reached,
 * spp1 = interrupted; PASS_FAIL: rank 0 failed before rendering). */
typedef struct pass_msg {
    int32_t cmd, spp0, spp1, pad;
} pass_msg;
enum { PASS_RUN = 1, PASS_END, PASS_FAIL };

static void send_passes(int cmd, int spp0, int spp1)
{
    pass_msg pm = {cmd, spp0, spp1, 0};
    if (murk_mpi_size() > 1)
        murk_mpi_bcast(&pm, sizeof pm);
}

/* Collective at the end: the render threads, cost counters and largest sample of every rank into rank 0's
 * out and j. */
static void sum_over_ranks(job *j, int nthreads, murk_render_result *out)
{
    enum { N = 1 + MURK_COUNTER_SLOTS * MURK_NCOUNTERS };
    uint64_t v[N];
    _Static_assert(sizeof j->media == MURK_COUNTER_SLOTS * MURK_NCOUNTERS * sizeof(uint64_t), "counters are uint64s");
    v[0] = (uint64_t)nthreads;
    memcpy(v + 1, j->media, sizeof j->media);
    murk_mpi_sum_u64(v, N);
    out->threads = (int)v[0];
    memcpy(j->media, v + 1, sizeof j->media);
    murk_mpi_max_double(&j->max_sample);
}


/* A rank other than 0: renders the passes rank 0 announces, the tiles it hands out, until it says end.
 * Its memory is its nthreads + 1 held tiles' (7 KB each), whatever the image's size. */
static int follow_passes(job *j, int nthreads, murk_render_result *out)
{
    tile_queue inq, outq;
    int nheld = nthreads + 1;
    queue_init(&inq, nheld);
    queue_init(&outq, nheld);
    j->held = murk_xmalloc((size_t)nheld * sizeof *j->held);
    for (int k = 0; k < nheld; k++)
        j->held[k] = murk_xmalloc(HDR_BYTES + TILE_BYTES); /* zeroed: a RESULT's unused bytes are defined */
    j->inq = &inq, j->outq = &outq, j->stop = NULL;
    pass_msg pm;
    for (;;) {
        murk_mpi_bcast(&pm, sizeof pm);
        if (pm.cmd != PASS_RUN)
            break;
        j->spp0 = pm.spp0, j->spp1 = pm.spp1;
        atomic_store(&j->rays, 0);
        atomic_store(&j->nonfinite, 0);
        atomic_store(&j->busy_ns, 0);
        run_pass(j, nthreads, 0, 0, 1, 0);
        uint64_t v[3] = {atomic_load(&j->rays), atomic_load(&j->nonfinite), atomic_load(&j->busy_ns)};
        murk_mpi_sum_u64(v, 3);
    }
    queue_free(&inq);
    queue_free(&outq);
    for (int k = 0; k < nheld; k++)
        free(j->held[k]);
    free(j->held);
    if (getenv("MURK_MPI_STATS")) /* what this rank held at most (tests/test_mpi.c) */
        fprintf(stderr, "murk: mpi: rank %d: peak resident memory %ld kB\n", murk_mpi_rank(), murk_peak_rss_kb());
    if (pm.cmd == PASS_END)
        sum_over_ranks(j, nthreads, out);
    out->spp = pm.spp0;
    out->interrupted = pm.spp1;
    return pm.cmd == PASS_END ? 0 : -1;
}

MURK_API int murk_render_err(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out, char *err,
                             size_t errlen)
{
    char errbuf[1024];
    if (!err || !errlen)
        err = errbuf, errlen = sizeof errbuf;
    err[0] = 0;
    memset(out, 0, sizeof *out);
    int spp = opts->spp > 0 ? opts->spp : s->spp;
    int usable = murk_cpus_usable();
    int nthreads = opts->threads > 0 ? opts->threads : usable;
    if (nthreads < 1)
        nthreads = 1;
    if (nthreads > usable)
        murk_log(MURK_LOG_INFO, "%d render threads, but this process may run on %d CPU%s only (its CPU affinity; "
                 "under mpirun: --bind-to none): the threads share %s", nthreads, usable, usable == 1 ? "" : "s",
                 usable == 1 ? "it" : "them");
    size_t npix = (size_t)s->width * (size_t)s->height;
    job j;
    memset(&j, 0, sizeof j);
    j.s = s;
    j.tiles_x = (s->width + TILE - 1) / TILE;
    j.stop = opts->stop;
    atomic_init(&j.rays, 0);
    atomic_init(&j.nonfinite, 0);
    atomic_init(&j.busy_ns, 0);
    atomic_init(&j.abandoned, 0);
    pthread_mutex_init(&j.lock, NULL);
    j.nslots = s->nmedia < MURK_COUNTER_SLOTS ? s->nmedia : MURK_COUNTER_SLOTS;
    out->width = s->width;
    out->height = s->height;
    out->ranks = murk_mpi_size();
    if (murk_mpi_rank() > 0) { /* it holds the tiles rank 0 hands it, not the image */
        int rc = follow_passes(&j, nthreads, out);
        pthread_mutex_destroy(&j.lock);
        return rc;
    }
    j.sum = murk_xmalloc(3 * npix * sizeof(double));
    j.count = murk_xmalloc(npix * sizeof(uint32_t));
    int alltiles = j.tiles_x * ((s->height + TILE - 1) / TILE);
    int *tiles = murk_xmalloc((size_t)alltiles * sizeof *tiles);
    size_t npix_rendered = 0;
    for (int t = 0; t < alltiles; t++)
        if (murk_part_of(s->width, (t % j.tiles_x) * TILE, (t / j.tiles_x) * TILE, opts->parts) == opts->part) {
            int x0, y0, x1, y1;
            tiles[j.ntiles++] = t;
            tile_rect(&j, t, &x0, &y0, &x1, &y1);
            npix_rendered += (size_t)(x1 - x0) * (size_t)(y1 - y0);
        }
    j.tiles = tiles;
    /* Hidden, for bench/stability/atlas.py: MURK_SAMPLE_DUMP=FILE writes every sample's RGB as float32
     * [pixel][sample][r, g, b] (pixels row by row) after the render, for per-sample statistics (firefly
     * rate, largest sample, non-finite count). Up to 2^26 samples; not with --resume; under MPI, rank 0's
     * tiles only. */
    const char *dump_path = getenv("MURK_SAMPLE_DUMP");
    if (dump_path && *dump_path && !opts->resume && spp > 0 && npix * (size_t)spp <= ((size_t)1 << 26)) {
        j.dump = calloc(3 * npix * (size_t)spp, sizeof(float));
        j.dump_spp = spp;
    }

    int done = 0, rc = 0;
    uint64_t rays_before = 0;
    if (opts->resume) {
        murk_ckpt want = {.scene_hash = opts->scene_hash, .seed = s->seed, .width = s->width, .height = s->height,
                          .overrides = opts->overrides}, c;
        if (murk_ckpt_load(opts->resume, &want, &c, err, errlen) == 0 && c.spp > spp) {
            murk_err_file(err, errlen, opts->resume, "the checkpoint has %d spp, more than the %d asked for", c.spp,
                          spp);
            murk_ckpt_free(&c);
        }
        if (err[0]) {
            send_passes(PASS_FAIL, 0, 0);
            free(j.sum);
            free(j.count);
            free(tiles);
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
        send_passes(PASS_RUN, j.spp0, j.spp1);
        j.mpi_passes++;
        run_pass(&j, nthreads, opts->progress, t0, spp - start, done - start);
        if (murk_mpi_size() > 1) { /* the other ranks' rays, NaNs and busy time of this pass */
            uint64_t v[3] = {0, 0, 0};
            murk_mpi_sum_u64(v, 3);
            atomic_fetch_add(&j.rays, v[0]);
            atomic_fetch_add(&j.nonfinite, v[1]);
            atomic_fetch_add(&j.busy_ns, v[2]);
        }
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
            pass = (int)((murk_mpi_size() > 1 ? MPI_PASS_SECONDS : PASS_SECONDS) / (per_spp > 1e-9 ? per_spp : 1e-9));
        }
        if (pass < 1)
            pass = 1;
        if (pass > 2 * n + 1)
            pass = 2 * n + 1; /* grow gradually so the estimate can adapt */
    }
    out->interrupted = done < spp && opts->stop && *opts->stop;
    send_passes(PASS_END, done, out->interrupted);
    sum_over_ranks(&j, nthreads, out);
    if (rc == 0 && opts->checkpoint && save_checkpoint(s, opts, &j, done, err, errlen) != 0)
        rc = -1;
    free(keep_sum);
    free(keep_count);
    if (opts->progress) {
        progress_bar((double)(done - start) / (spp - start > 0 ? spp - start : 1), murk_now() - t0);
        fputc('\n', stderr);
    }
    if (murk_mpi_size() > 1 && getenv("MURK_MPI_STATS")) /* the measured overheads bench/scaling.py models */
        fprintf(stderr, "murk: mpi: %d ranks, %llu passes, %d tiles per pass, %llu tiles to other ranks, %llu "
                "messages, %llu bytes, rank 0 handled them in %.6f CPU s (%.2f us per tile)\n", murk_mpi_size(),
                (unsigned long long)j.mpi_passes, j.ntiles, (unsigned long long)j.mpi_tiles,
                (unsigned long long)j.mpi_msgs, (unsigned long long)j.mpi_bytes, j.mpi_serve,
                j.mpi_tiles ? 1e6 * j.mpi_serve / (double)j.mpi_tiles : 0.0);
    out->seconds = murk_now() - t0;
    out->spp = done;
    out->thread_seconds = (double)atomic_load(&j.busy_ns) * 1e-9;
    out->rgb = murk_xmalloc(3 * npix * sizeof(float));
    for (size_t i = 0; i < npix; i++)
        for (int c = 0; c < 3; c++)
            out->rgb[3 * i + (size_t)c] = j.count[i] ? (float)(j.sum[3 * i + (size_t)c] / j.count[i]) : 0.0f;
    out->samples = (uint64_t)(done - start) * npix_rendered;
    out->rays = atomic_load(&j.rays) - rays_before;
    out->nonfinite = atomic_load(&j.nonfinite);
    out->nmedia = (int)j.nslots;
    out->max_sample = j.max_sample;
    memcpy(out->media, j.media, sizeof j.media);
    pthread_mutex_destroy(&j.lock);
    if (j.dump) {
        FILE *f = fopen(dump_path, "wb");
        if (!f || fwrite(j.dump, sizeof(float), 3 * npix * (size_t)spp, f) != 3 * npix * (size_t)spp)
            fprintf(stderr, "murk: MURK_SAMPLE_DUMP: cannot write %s\n", dump_path);
        if (f)
            fclose(f);
        free(j.dump);
    }
    free(j.sum);
    free(j.count);
    free(tiles);
    return rc;
}
