/* session.c — a render session (session.h): begin checks and loads what the render needs, each
 * run_pass renders one pass (render.c) between the policy parts' hooks, end gives the image. The parts
 * decide everything the session does not: where the passes go (MPI), what is saved (checkpoints), what
 * a stop undoes, how long a pass is. murk_render_err is begin, run_pass until over, end. */
#include "render/mpi_job.h"
#include "render/session.h"
#include "scene/scene.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* With a time limit, stop signal or checkpoint, passes are sized to take about PASS_SECONDS (the loss when
 * a pass is abandoned, the granularity of checkpoints), MPI_PASS_SECONDS under MPI, where every pass moves
 * every tile's state twice; otherwise one pass does every sample. */
#define PASS_SECONDS 0.5
#define MPI_PASS_SECONDS 2.0

static int render_threads(int asked)
{
    int usable = murk_cpus_usable();
    int n = asked > 0 ? asked : usable;
    if (n < 1)
        n = 1;
    if (n > usable)
        murk_log(MURK_LOG_INFO, "%d render threads, but this process may run on %d CPU%s only (its CPU affinity; "
                 "under mpirun: --bind-to none): the threads share %s", n, usable, usable == 1 ? "" : "s",
                 usable == 1 ? "it" : "them");
    return n;
}

static murk_pass_policy *plug(murk_session *ss)
{
    murk_pass_policy *p = &ss->parts[ss->nparts++];
    memset(p, 0, sizeof *p);
    return p;
}

/* The parts the options ask for, in the order their hooks run. */
static void plug_parts(murk_session *ss, int stoppable)
{
    const murk_render_opts *o = &ss->opts;
    if (murk_mpi_size() > 1)
        murk_policy_mpi(plug(ss));
    if (o->checkpoint)
        murk_policy_checkpoint(plug(ss));
    if (o->resume)
        murk_policy_resume(plug(ss));
    if (stoppable)
        murk_policy_rollback(plug(ss));
    if (o->time_limit > 0)
        murk_policy_budget(plug(ss));
    else if (stoppable || o->checkpoint)
        murk_policy_pace(plug(ss), murk_mpi_size() > 1 ? MPI_PASS_SECONDS : PASS_SECONDS);
    ss->next = o->time_limit > 0 || stoppable || o->checkpoint ? 1 : ss->spp; /* passes grow from 1 spp */
}

/* Hidden, for bench/stability/atlas.py: MURK_SAMPLE_DUMP=FILE writes every sample's RGB as float32
 * [pixel][sample][r, g, b] (pixels row by row) after the render, for per-sample statistics (firefly
 * rate, largest sample, non-finite count). Up to 2^26 samples; not with --resume; under MPI, rank 0's
 * tiles only. FILE is checked before the first sample, like every output. */
static int open_dump(murk_session *ss, char *err, size_t errlen)
{
    const char *path = getenv("MURK_SAMPLE_DUMP");
    size_t npix = (size_t)ss->s->width * (size_t)ss->s->height;
    if (!path || !*path || ss->opts.resume || ss->spp <= 0 || npix * (size_t)ss->spp > ((size_t)1 << 26))
        return 0;
    if (murk_output_probe(path, "sample dump (MURK_SAMPLE_DUMP)", err, errlen) != 0)
        return -1;
    ss->job.dump = calloc(3 * npix * (size_t)ss->spp, sizeof(float));
    ss->job.dump_spp = ss->spp;
    ss->dump_path = path;
    return 0;
}

static int fill_dump(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    const murk_job *j = user;
    size_t n = 3 * (size_t)j->s->width * (size_t)j->s->height * (size_t)j->dump_spp;
    return fwrite(j->dump, sizeof(float), n, fp) == n ? 0 : murk_err_file(err, errlen, tmp, "cannot write");
}

static void write_dump(murk_session *ss)
{
    char err[1024];
    if (ss->job.dump && murk_write_atomic(ss->dump_path, fill_dump, &ss->job, err, sizeof err) != 0)
        fprintf(stderr, "murk: MURK_SAMPLE_DUMP: %s\n", err);
}

static void close_session(murk_session *ss)
{
    for (int i = 0; i < ss->nparts; i++)
        if (ss->parts[i].release)
            ss->parts[i].release(ss->parts[i].self);
    murk_job_free(&ss->job);
    free(ss);
}

static void copy_msg(const murk_session *ss, char *err, size_t errlen)
{
    if (err && errlen)
        snprintf(err, errlen, "%s", ss->msg);
}

/* The parts' end hooks, in order, each given the status so far. */
static int end_parts(murk_session *ss, int rc)
{
    for (int i = 0; i < ss->nparts; i++)
        if (ss->parts[i].end)
            rc = ss->parts[i].end(ss, ss->parts[i].self, rc, ss->msg, sizeof ss->msg);
    return rc;
}

murk_session *murk_session_open(const murk_scene *s, const murk_render_opts *opts, int stoppable, char *err,
                                size_t errlen)
{
    murk_session *ss = murk_xmalloc(sizeof *ss);
    ss->s = s;
    ss->opts = *opts;
    ss->spp = opts->spp > 0 ? opts->spp : s->spp;
    ss->nthreads = ss->threads = render_threads(opts->threads);
    ss->follower = murk_mpi_rank() > 0;
    murk_job_init(&ss->job, s, opts->part, opts->parts, !ss->follower);
    if (ss->follower) { /* it renders the passes rank 0 announces, in the tiles rank 0 hands it */
        murk_job_hold(&ss->job, ss->nthreads);
        ss->began = 1;
        return ss;
    }
    ss->job.stop = opts->stop;
    if (opts->progress)
        ss->progress = murk_progress_bar;
    plug_parts(ss, stoppable);
    int rc = open_dump(ss, ss->msg, sizeof ss->msg);
    for (int i = 0; i < ss->nparts && rc == 0; i++)
        if (ss->parts[i].begin)
            rc = ss->parts[i].begin(ss, ss->parts[i].self, ss->msg, sizeof ss->msg);
    if (rc != 0) { /* nothing rendered: the parts end (under MPI the other ranks hear of the failure) */
        end_parts(ss, -1);
        copy_msg(ss, err, errlen);
        close_session(ss);
        return NULL;
    }
    ss->began = 1;
    ss->start = ss->done;
    ss->t0 = murk_now();
    return ss;
}

MURK_API murk_session *murk_session_begin(const murk_scene *s, const murk_render_opts *opts, char *err,
                                          size_t errlen)
{
    return murk_session_open(s, opts, 1, err, errlen);
}

MURK_API void murk_session_set_progress(murk_session *ss, murk_progress_fn fn, void *user)
{
    ss->progress = fn;
    ss->progress_user = user;
}

MURK_API void murk_session_stop(murk_session *ss)
{
    if (!ss->follower) /* the other ranks follow rank 0's passes */
        atomic_store(&ss->job.halt, 1);
}

/* The running pass's progress, as a share of this run's samples. */
static void tick(void *user, double pass_fraction)
{
    murk_session *ss = user;
    const murk_job *j = &ss->job;
    double done = (double)(ss->done - ss->start) + (double)(j->spp1 - j->spp0) * pass_fraction;
    ss->progress(ss->progress_user, done / (double)(ss->spp - ss->start), murk_now() - ss->t0, 0);
}

/* After a whole pass: the parts' after hooks; then the next pass at most doubles (plus one), so the
 * pace's estimate of a sample's time can adapt. 1 to go on, 0 when over, -1 failed. */
static int after_pass(murk_session *ss, char *err, size_t errlen)
{
    for (int i = 0; i < ss->nparts; i++) {
        int r = ss->parts[i].after ? ss->parts[i].after(ss, ss->parts[i].self, ss->msg, sizeof ss->msg) : 0;
        if (r == MURK_PASS_FAIL) {
            ss->rc = -1;
            ss->over = 1;
            copy_msg(ss, err, errlen);
            return -1;
        }
        if (r == MURK_PASS_STOP)
            ss->over = 1;
    }
    if (!(ss->next >= 1)) /* compared so that NaN too becomes 1 */
        ss->next = 1;
    if (ss->next > 2.0 * ss->n + 1)
        ss->next = 2.0 * ss->n + 1;
    if (ss->done >= ss->spp || murk_job_stopped(&ss->job))
        ss->over = 1;
    return ss->over ? 0 : 1;
}

MURK_API int murk_session_run_pass(murk_session *ss, char *err, size_t errlen)
{
    if (ss->follower && !ss->over)
        return murk_follow_pass(ss);
    if (ss->over || ss->done >= ss->spp || murk_job_stopped(&ss->job)) {
        ss->over = 1;
        return ss->rc < 0 ? -1 : 0;
    }
    murk_job *j = &ss->job;
    int n = ss->next < (double)(ss->spp - ss->done) ? (int)ss->next : ss->spp - ss->done;
    j->spp0 = ss->done;
    j->spp1 = ss->done + n;
    for (int i = 0; i < ss->nparts; i++)
        if (ss->parts[i].before)
            ss->parts[i].before(ss, ss->parts[i].self);
    double tp = murk_now();
    murk_job_run_pass(j, ss->nthreads, ss->progress ? tick : NULL, ss);
    for (int i = 0; i < ss->nparts; i++)
        if (ss->parts[i].ran)
            ss->parts[i].ran(ss, ss->parts[i].self);
    if (atomic_load(&j->abandoned)) { /* stopped: the rollback part put the state back */
        ss->over = 1;
        return 0;
    }
    ss->done += n;
    ss->n = n;
    ss->now = murk_now();
    ss->pass_seconds = ss->now - tp;
    return after_pass(ss, err, errlen);
}

/* The image of the whole passes done and this run's figures. */
static void fill_result(murk_session *ss, murk_render_result *out)
{
    murk_job *j = &ss->job;
    size_t npix = (size_t)ss->s->width * (size_t)ss->s->height;
    out->seconds = murk_now() - ss->t0;
    out->spp = ss->done;
    out->interrupted = ss->interrupted;
    out->resumed_spp = ss->resumed_spp;
    out->threads = ss->threads;
    out->thread_seconds = (double)atomic_load(&j->busy_ns) * 1e-9;
    out->rgb = murk_xmalloc(3 * npix * sizeof(float));
    for (size_t i = 0; i < npix; i++)
        for (int c = 0; c < 3; c++)
            out->rgb[3 * i + (size_t)c] = j->count[i] ? (float)(j->sum[3 * i + (size_t)c] / j->count[i]) : 0.0f;
    out->samples = (uint64_t)(ss->done - ss->start) * j->npix_rendered;
    out->rays = atomic_load(&j->rays) - ss->rays_before;
    out->nonfinite = atomic_load(&j->nonfinite);
    out->nmedia = (int)j->nslots;
    out->max_sample = j->max_sample;
    memcpy(out->media, j->media, sizeof j->media);
}

MURK_API int murk_session_end(murk_session *ss, murk_render_result *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    out->width = ss->s->width;
    out->height = ss->s->height;
    out->ranks = murk_mpi_size();
    if (ss->follower) {
        murk_follow_end(ss);
        out->spp = ss->done;
        out->interrupted = ss->interrupted;
        out->threads = ss->threads;
    } else {
        /* short of spp after a stop, or ended before run_pass said it was over (not --time's end) */
        ss->interrupted = ss->done < ss->spp && (murk_job_stopped(&ss->job) || !ss->over);
        ss->over = 1;
        if (ss->progress) {
            int total = ss->spp - ss->start;
            ss->progress(ss->progress_user, (double)(ss->done - ss->start) / (total > 0 ? total : 1),
                         murk_now() - ss->t0, 1);
        }
        ss->rc = end_parts(ss, ss->rc);
        fill_result(ss, out);
        write_dump(ss);
    }
    int rc = ss->rc;
    if (rc != 0)
        copy_msg(ss, err, errlen);
    close_session(ss);
    return rc;
}

MURK_API int murk_render(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out)
{
    return murk_render_err(s, opts, out, NULL, 0);
}

MURK_API int murk_render_err(const murk_scene *s, const murk_render_opts *opts, murk_render_result *out, char *err,
                             size_t errlen)
{
    char errbuf[1024];
    if (!err || !errlen)
        err = errbuf, errlen = sizeof errbuf;
    err[0] = 0;
    memset(out, 0, sizeof *out);
    out->width = s->width;
    out->height = s->height;
    out->ranks = murk_mpi_size();
    murk_session *ss = murk_session_open(s, opts, opts->stop != NULL, err, errlen);
    if (!ss)
        return -1;
    while (murk_session_run_pass(ss, err, errlen) > 0)
        ;
    return murk_session_end(ss, out, err, errlen);
}
