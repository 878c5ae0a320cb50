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
    int interrupted;        /* opts->stop was set before spp was reached */
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

/* `sets` are "KEY.PATH=VALUE" overrides. NULL with a one-line "file:line:col: message" in err. */
murk_scene *murk_scene_load(const char *path, const char *const *sets, size_t nsets, char *err, size_t errlen);
void murk_scene_free(murk_scene *scene);
/* 0, or -1 with a one-line message in err (a checkpoint that cannot be read, is of another scene, or
 * cannot be written); err may be NULL. */
int murk_render(const murk_scene *scene, const murk_render_opts *opts, murk_render_result *out);
int murk_render_err(const murk_scene *scene, const murk_render_opts *opts, murk_render_result *out, char *err,
                    size_t errlen);
/* --part I/N: the 16x16 tile (numbered row-major) that holds pixel (x, y) of a w x h image belongs to
 * part tile % parts; murk_part_tiles counts the tiles of one part. */
int murk_part_of(int w, int x, int y, int parts);
int murk_part_tiles(int w, int h, int part, int parts);
/* FNV-1a 64 of a file's bytes (a scene's content hash for checkpoints); 0 with err set if unreadable. */
uint64_t murk_file_hash(const char *path, char *err, size_t errlen);

#endif
