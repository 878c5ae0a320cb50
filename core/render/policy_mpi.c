/* policy_mpi.c — the session's MPI coordination (session.h). Rank 0 decides the passes (their sample
 * ranges: --time, checkpoints and signals are its decisions alone): before each pass it announces the
 * range to every rank, after it sums the other ranks' rays, NaN counts and busy time into its own, and at
 * the end it says so and sums their render threads, cost counters and largest sample. A rank other than 0
 * runs no policy: it follows (murk_follow_pass), rendering each announced pass in the tiles rank 0 hands
 * it (render.c), until the end or rank 0's failure before its first pass. */
#include "render/mpi_job.h"
#include "render/session.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What rank 0 sends every rank before each pass and at the end (cmd PASS_END: spp0 = the spp reached,
 * spp1 = interrupted; PASS_FAIL: rank 0 failed before rendering). */
typedef struct pass_msg {
    int32_t cmd, spp0, spp1, pad;
} pass_msg;
enum { PASS_RUN = 1, PASS_END, PASS_FAIL };

static void send_passes(int cmd, int spp0, int spp1)
{
    pass_msg pm = {cmd, spp0, spp1, 0};
    murk_mpi_bcast(&pm, sizeof pm);
}

/* Collective at the end: the render threads, cost counters and largest sample of every rank into rank 0's. */
static void sum_over_ranks(murk_session *ss)
{
    murk_job *j = &ss->job;
    enum { N = 1 + MURK_COUNTER_SLOTS * MURK_NCOUNTERS };
    uint64_t v[N];
    _Static_assert(sizeof j->media == MURK_COUNTER_SLOTS * MURK_NCOUNTERS * sizeof(uint64_t), "counters are uint64s");
    v[0] = (uint64_t)ss->nthreads;
    memcpy(v + 1, j->media, sizeof j->media);
    murk_mpi_sum_u64(v, N);
    ss->threads = (int)v[0];
    memcpy(j->media, v + 1, sizeof j->media);
    murk_mpi_max_double(&j->max_sample);
}

/* Collective after each pass: this pass's rays, NaNs and busy time of the ranks into rank 0's. */
static void sum_pass(murk_job *j, int rank0)
{
    uint64_t v[3] = {0, 0, 0};
    if (!rank0)
        v[0] = atomic_load(&j->rays), v[1] = atomic_load(&j->nonfinite), v[2] = atomic_load(&j->busy_ns);
    murk_mpi_sum_u64(v, 3);
    if (rank0) {
        atomic_fetch_add(&j->rays, v[0]);
        atomic_fetch_add(&j->nonfinite, v[1]);
        atomic_fetch_add(&j->busy_ns, v[2]);
    }
}

static void announce(murk_session *ss, void *self)
{
    (void)self;
    send_passes(PASS_RUN, ss->job.spp0, ss->job.spp1);
    ss->job.mpi_passes++;
}

static void collect(murk_session *ss, void *self)
{
    (void)self;
    sum_pass(&ss->job, 1);
}

static int finish(murk_session *ss, void *self, int rc, char *err, size_t errlen)
{
    (void)self, (void)err, (void)errlen;
    const murk_job *j = &ss->job;
    if (!ss->began) {
        send_passes(PASS_FAIL, 0, 0);
        return rc;
    }
    send_passes(PASS_END, ss->done, ss->interrupted);
    sum_over_ranks(ss);
    if (getenv("MURK_MPI_STATS")) /* the measured overheads bench/scaling.py models */
        fprintf(stderr, "murk: mpi: %d ranks, %llu passes, %d tiles per pass, %llu tiles to other ranks, %llu "
                "messages, %llu bytes, rank 0 handled them in %.6f CPU s (%.2f us per tile)\n", murk_mpi_size(),
                (unsigned long long)j->mpi_passes, j->ntiles, (unsigned long long)j->mpi_tiles,
                (unsigned long long)j->mpi_msgs, (unsigned long long)j->mpi_bytes, j->mpi_serve,
                j->mpi_tiles ? 1e6 * j->mpi_serve / (double)j->mpi_tiles : 0.0);
    return rc;
}

void murk_policy_mpi(murk_pass_policy *p)
{
    p->name = "mpi";
    p->before = announce;
    p->ran = collect;
    p->end = finish;
}

int murk_follow_pass(murk_session *ss)
{
    murk_job *j = &ss->job;
    pass_msg pm;
    murk_mpi_bcast(&pm, sizeof pm);
    if (pm.cmd != PASS_RUN) {
        ss->over = 1;
        ss->rc = pm.cmd == PASS_END ? 0 : -1;
        ss->done = pm.spp0;
        ss->interrupted = pm.spp1;
        return ss->rc;
    }
    j->spp0 = pm.spp0, j->spp1 = pm.spp1;
    atomic_store(&j->rays, 0);
    atomic_store(&j->nonfinite, 0);
    atomic_store(&j->busy_ns, 0);
    murk_job_run_pass(j, ss->nthreads, NULL, NULL);
    sum_pass(j, 0);
    return 1;
}

void murk_follow_end(murk_session *ss)
{
    while (!ss->over)
        murk_follow_pass(ss);
    if (getenv("MURK_MPI_STATS")) /* what this rank held at most (tests/test_mpi.c) */
        fprintf(stderr, "murk: mpi: rank %d: peak resident memory %ld kB\n", murk_mpi_rank(), murk_peak_rss_kb());
    if (ss->rc == 0)
        sum_over_ranks(ss);
}
