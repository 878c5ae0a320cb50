/* murk/murk.h — libmurk's embedding API: load a scene, render it, write the images.
 * Plugin authors do not need this header (see murk/plugin.h). */
#ifndef MURK_MURK_H
#define MURK_MURK_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "murk/counters.h"

typedef struct murk_scene murk_scene;

typedef struct murk_render_opts {
    int spp;            /* samples per pixel; 0 = the scene's */
    int threads;        /* 0 = all cores */
    double time_limit;  /* seconds; > 0 stops after the last whole pass that fits (spp is then a cap) */
    int progress;       /* draw a progress bar on stderr */
    /* Interrupt and resume (all optional; zero = off). Whole passes only ever count: the image depends
     * on (scene, seed, spp) alone, however the render was cut into passes, interrupted and resumed. */
    volatile sig_atomic_t *stop; /* set (e.g. by a signal handler): abandon the running pass and return
                                    the spp of the whole passes done, with interrupted = 1 */
    const char *checkpoint;      /* save the accumulated state here (atomically) after a pass when
                                    checkpoint_every seconds have passed, and at the end */
    double checkpoint_every;     /* seconds; 0 = after every pass */
    const char *resume;          /* continue from this checkpoint (same scene, overrides, seed, size) */
    uint64_t scene_hash;         /* identify the scene in a checkpoint: its content hash ... */
    const char *overrides;       /* ... and its --set overrides (NULL = none) */
    /* A share of the image (murk render --part I/N): with parts > 0 only the 16x16 tiles t (row-major)
     * with t % parts == part are rendered; the other pixels stay 0. */
    int part, parts;
} murk_render_opts;

typedef struct murk_render_result {
    int width, height, spp; /* spp actually rendered */
    float *rgb;             /* 3*width*height linear floats, row 0 at the top; free() it (NULL on MPI ranks
                               other than 0: rank 0 gets the image) */
    double seconds;
    uint64_t samples, rays, nonfinite; /* samples and rays: this run's; nonfinite: the image's (resumed too) */
    int interrupted;        /* opts->stop was set before spp was reached (or murk_session_stop called, or the
                               session ended early: murk_session_end) */
    int resumed_spp;        /* spp taken from opts->resume */
    /* This run's cost counters per medium, in the scene's order (murk/counters.h): nmedia blocks, the
     * last one shared when the scene has more than MURK_COUNTER_SLOTS media. */
    int nmedia;
    murk_counters media[MURK_COUNTER_SLOTS];
    double max_sample; /* the largest channel value of a finite sample (this run's): a sign of fireflies */
    /* The job (summed over MPI ranks): processes, render threads, seconds those threads spent in tiles. */
    int ranks, threads;
    double thread_seconds;
} murk_render_result;

/* `sets` are "KEY.PATH=VALUE" overrides. NULL with a one-line "file:line:col: message" in err
 * ("--set KEY.PATH=VALUE: message" for an error an override caused). A --set of a plugin's `type` drops
 * the file's keys of the previous plugin that the new one does not take; a medium or material that a
 * --set creates and nothing uses is refused (a misspelt name). The murk command also refuses the scene
 * file's own unused media and materials; this function loads them, for embedders that call them. */
murk_scene *murk_scene_load(const char *path, const char *const *sets, size_t nsets, char *err, size_t errlen);
void murk_scene_free(murk_scene *scene);
/* Renders the scene: murk_session_begin, murk_session_run_pass until it returns 0 or -1, murk_session_end
 * (below); in passes only when opts asks for them (time_limit, stop, checkpoint), else in one. 0, or -1
 * with a one-line message in err (an output that cannot be written, found before the first sample; a
 * checkpoint that cannot be read, is of another scene, or cannot be saved); err may be NULL. On -1
 * out->rgb is NULL when nothing was rendered, else the image of the whole passes done. */
int murk_render(const murk_scene *scene, const murk_render_opts *opts, murk_render_result *out);
int murk_render_err(const murk_scene *scene, const murk_render_opts *opts, murk_render_result *out, char *err,
                    size_t errlen);

/* A render session: the steps of murk_render_err for a caller that drives the passes itself (a binding,
 * a viewer). An opaque handle and plain C types, for a foreign-function interface such as Python's ctypes:
 *
 *   murk_session *ss = murk_session_begin(scene, &opts, err, sizeof err);    NULL: err says why
 *   while (murk_session_run_pass(ss, err, sizeof err) > 0)
 *       ;                                        between passes: look at Ctrl-C, update a display
 *   int rc = murk_session_end(ss, &result, err, sizeof err);                frees ss; free(result.rgb)
 *
 * Before the first sample, begin checks that every file the session will write can be written
 * (opts->checkpoint; MURK_SAMPLE_DUMP's file) and reads opts->resume. Passes take about half a second
 * each (or fill opts->time_limit), so a stop loses at most one. The image depends on the scene, seed and
 * spp only, however the render was cut into passes, stopped and resumed. Under MPI every rank calls the
 * same functions; rank 0 decides the passes, takes the stops and alone gets the image.
 * libmurk keeps per-thread counters in initial-exec TLS (fast, but from glibc's small static reserve): a
 * process that dlopen()s libmurk after it started (ctypes.CDLL) must be started with
 * GLIBC_TUNABLES=glibc.rtld.optional_static_tls=8192 (or LD_PRELOAD=libmurk.so), else dlopen fails with
 * "cannot allocate memory in static TLS block". */
typedef struct murk_session murk_session;
/* Progress: the share of this run's samples done (0..1; a resumed checkpoint's not counted), seconds since
 * the passes began, last = 1 on the final call (from murk_session_end). Called on the thread that runs
 * murk_session_run_pass, about five times a second during a pass. */
typedef void (*murk_progress_fn)(void *user, double fraction, double seconds, int last);

/* NULL, with a one-line message in err, when the scene cannot be rendered as opts asks: an output that
 * cannot be written (nothing is rendered, nothing written), a checkpoint to resume that cannot be read or
 * is not this render's. opts is copied; its strings (checkpoint, resume,
 * overrides) must outlive ss. */
murk_session *murk_session_begin(const murk_scene *scene, const murk_render_opts *opts, char *err, size_t errlen);
/* Replaces the progress report (opts->progress's bar on stderr, or none) with fn (NULL: none). */
void murk_session_set_progress(murk_session *ss, murk_progress_fn fn, void *user);
/* Renders the next pass. 1: call again; 0: the render is over (spp reached, the time limit spent or a
 * stop taken; this call rendered the last pass or none); -1: it failed (err says why: a checkpoint that
 * could not be saved). Then murk_session_end. */
int murk_session_run_pass(murk_session *ss, char *err, size_t errlen);
/* Asks the session to stop, from any thread (a progress callback too) until murk_session_end, as setting
 * *opts->stop does: the running pass is abandoned and does not count; the next run_pass returns 0. */
void murk_session_stop(murk_session *ss);
/* Ends the session and frees ss: saves the final checkpoint (opts->checkpoint) and fills out as
 * murk_render_err does (out->rgb: the image of the whole passes done; free() it). Ended short of spp after
 * a stop, or before run_pass returned 0, out->interrupted is 1. 0, or -1 with err set (the session
 * failed, or the final checkpoint could not be saved). */
int murk_session_end(murk_session *ss, murk_render_result *out, char *err, size_t errlen);

/* --part I/N: the 16x16 tile (numbered row-major) that holds pixel (x, y) of a w x h image belongs to
 * part tile % parts; murk_part_tiles counts the tiles of one part. */
int murk_part_of(int w, int x, int y, int parts);
int murk_part_tiles(int w, int h, int part, int parts);
/* FNV-1a 64 of a file's bytes (a scene's content hash for checkpoints); 0 with err set if unreadable. */
uint64_t murk_file_hash(const char *path, char *err, size_t errlen);

#endif
