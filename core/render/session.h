/* session.h — a render session (session.c): begin, passes, end, with the pass policy in separate parts
 * plugged into it. Internal to libmurk; murk/murk.h declares the API embedders use.
 *
 * The session owns the job (pass.h: the pixels' state, the tiles) and runs one pass per call. It knows
 * none of the policies: each is a murk_pass_policy, a table of hooks with its own state, plugged in at
 * begin from the options, and called in the order plugged:
 *
 *   mpi         policy_mpi.c         rank 0 under MPI: announces each pass to the other ranks, sums their
 *                                    counters after it, says the end (the other ranks follow: murk_follow_*)
 *   checkpoint  policy_checkpoint.c  --checkpoint: its path checked at begin, saved after a pass when due
 *                                    and at the end
 *   resume      policy_checkpoint.c  --resume: the saved state loaded at begin
 *   rollback    policy_stop.c        a stop (signal, murk_session_stop): the state copied before each pass
 *                                    and put back when the pass was abandoned, so only whole passes count
 *   pace        policy_pace.c        the size of the next pass: about PASS_SECONDS each (a stop then
 *                                    loses at most one), or --time's budget, or none (one pass)
 *
 * Progress is a callback (murk_progress_fn) the session calls during and after passes; the bar on
 * stderr (policy_progress.c) is the one the murk command plugs in. A new policy is a new file with a
 * constructor: the session's loop does not change. Hooks a part does not need are NULL. */
#ifndef MURK_SESSION_H
#define MURK_SESSION_H

#include "murk/murk.h"
#include "render/pass.h"

#include <stddef.h>

typedef struct murk_session murk_session;

/* What an `after` hook returns. */
enum { MURK_PASS_FAIL = -1, MURK_PASS_GO = 0, MURK_PASS_STOP = 1 };

typedef struct murk_pass_policy {
    const char *name;
    void *self; /* the part's own state, freed by release */
    /* Once, before the first sample: check what the part will need (an output it will write); 0, or -1
     * with err set: the session fails before rendering anything. */
    int (*begin)(murk_session *ss, void *self, char *err, size_t errlen);
    /* Before each pass (ss->job.spp0 .. spp1). */
    void (*before)(murk_session *ss, void *self);
    /* After each pass, whole or abandoned (ss->job.abandoned). */
    void (*ran)(murk_session *ss, void *self);
    /* After each whole pass (ss->done counts it): MURK_PASS_GO, MURK_PASS_STOP (the render ends here,
     * not as an error), or MURK_PASS_FAIL with err set. */
    int (*after)(murk_session *ss, void *self, char *err, size_t errlen);
    /* Once at the end, with the session's status rc (also when begin failed: ss->began = 0); returns
     * the new status (-1 with err set on a failure). */
    int (*end)(murk_session *ss, void *self, int rc, char *err, size_t errlen);
    void (*release)(void *self);
} murk_pass_policy;

enum { MURK_SESSION_PARTS = 8 };

struct murk_session {
    const murk_scene *s;
    murk_render_opts opts; /* the caller's, copied (its strings stay the caller's) */
    murk_job job;
    int nthreads, threads; /* this rank's render threads; the job's (summed over the ranks at the end) */
    int spp;               /* the spp asked for */
    int start, done;       /* spp when the passes began (a resumed checkpoint's), spp of whole passes now */
    int resumed_spp;
    uint64_t rays_before; /* the resumed checkpoint's rays */
    double next;          /* spp of the next pass, as the pace part set it */
    int n;                /* spp of the last pass */
    double t0, now, pass_seconds; /* when the passes began; the end and length of the last whole pass */
    int began, over, interrupted, rc, follower;
    murk_pass_policy parts[MURK_SESSION_PARTS];
    int nparts;
    murk_progress_fn progress;
    void *progress_user;
    const char *dump_path; /* MURK_SAMPLE_DUMP */
    char msg[2048];        /* the error that failed the session */
};

/* The parts (each file's constructor fills p). */
void murk_policy_mpi(murk_pass_policy *p);
void murk_policy_checkpoint(murk_pass_policy *p);
void murk_policy_resume(murk_pass_policy *p);
void murk_policy_rollback(murk_pass_policy *p);
void murk_policy_pace(murk_pass_policy *p, double seconds); /* passes of about `seconds` each */
void murk_policy_budget(murk_pass_policy *p);               /* whole passes while they fit in opts.time_limit */

/* A rank other than 0 under MPI follows rank 0's passes (policy_mpi.c): renders the next one it
 * announces (1), or takes the end (0) or rank 0's failure (-1); and at the end, sums its counters into
 * rank 0's. */
int murk_follow_pass(murk_session *ss);
void murk_follow_end(murk_session *ss);

/* The progress bar on stderr (policy_progress.c): a murk_progress_fn. */
void murk_progress_bar(void *user, double fraction, double seconds, int last);

/* The session's steps (session.c); murk/murk.h documents them. stoppable: keep what a stop needs
 * (murk_render_err: only with opts->stop; murk_session_begin: always). */
murk_session *murk_session_open(const murk_scene *s, const murk_render_opts *opts, int stoppable, char *err,
                                size_t errlen);

#endif
