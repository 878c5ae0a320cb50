/* pass.h — one pass of a render (render.c): samples [spp0, spp1) of every tile of the image (or of one
 * --part) over the render threads and, under MPI, over the ranks. The session (session.h) decides the
 * passes; this is what runs one. Internal to libmurk.
 *
 * The job holds every pixel's state — the sum of its finite samples (3 doubles) and their count — on
 * rank 0; a rank other than 0 holds only the tiles rank 0 hands it (murk_job_hold). */
#ifndef MURK_PASS_H
#define MURK_PASS_H

#include "murk/counters.h"

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

typedef struct murk_scene murk_scene;
struct murk_tile_queue;

typedef struct murk_job {
    const murk_scene *s;
    int spp0, spp1; /* sample range of this pass */
    double *sum;    /* 3 per pixel (rank 0) */
    uint32_t *count;
    int tiles_x, ntiles;
    int *tiles; /* the ntiles tile numbers rendered (all, or one --part's) */
    size_t npix_rendered;
    atomic_int next;
    atomic_int done;
    atomic_uint_fast64_t rays, nonfinite, busy_ns;
    volatile sig_atomic_t *stop; /* set (a signal): take no more tiles; the pass is abandoned */
    atomic_int halt;             /* the same, set by murk_session_stop from any thread */
    atomic_int abandoned;
    pthread_mutex_t lock; /* guards media: each thread adds its cost counters once, when it ends */
    size_t nslots;
    murk_counters media[MURK_COUNTER_SLOTS];
    double max_sample; /* the largest channel of a finite sample */
    struct murk_tile_queue *inq, *outq; /* MPI ranks other than 0: slots of tiles to render, of tiles rendered */
    unsigned char **held;               /* MPI ranks other than 0: the held tiles' TILE messages by slot */
    int nheld;
    /* rank 0 under MPI (MURK_MPI_STATS=1 prints them): tiles handed to other ranks, messages and bytes
     * received and sent, seconds its main thread spent handling them, passes */
    uint64_t mpi_tiles, mpi_msgs, mpi_bytes, mpi_passes;
    double mpi_serve;
    float *dump; /* MURK_SAMPLE_DUMP: every sample's RGB, [pixel][sample][3], non-finite ones too */
    int dump_spp;
} murk_job;

/* Called on the thread running the pass about five times a second with the share of its tiles done. */
typedef void (*murk_pass_tick)(void *user, double pass_fraction);

/* A job over scene s: with image = 1 (rank 0) the pixels' state (zeroed) and the tiles of part `part` of
 * `parts` (all with parts = 0); with image = 0 (a rank other than 0) neither. */
void murk_job_init(murk_job *j, const murk_scene *s, int part, int parts, int image);
void murk_job_free(murk_job *j);
/* A rank other than 0: the slots of the nthreads + 1 tiles it holds at most; released by murk_job_free. */
void murk_job_hold(murk_job *j, int nthreads);
/* Renders samples [j->spp0, j->spp1) on nthreads threads; tick (may be NULL) reports progress. A stop
 * abandons the pass (j->abandoned: some tiles are advanced, some not). */
void murk_job_run_pass(murk_job *j, int nthreads, murk_pass_tick tick, void *user);

/* 1 once a stop was asked for (the signal flag or murk_session_stop). */
static inline int murk_job_stopped(murk_job *j)
{
    return (j->stop && *j->stop) || atomic_load(&j->halt);
}

#endif
