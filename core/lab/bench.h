/* bench.h — what the files of `murk bench` share (lab/): the bench's options and its reference, and the
 * functions one file gives the others. bench.c: the options, the variants, the command's entry points;
 * bench_run.c: the renders, bench.csv and the other files, the charts, the page; bench_ref.c: the
 * reference and its cache; bench_jobs.c: --emit-jobs and --assemble. Internal to libmurklab. */
#ifndef MURK_LAB_BENCH_H
#define MURK_LAB_BENCH_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "murk/lab.h"
#include "murk/murk.h"

/* One --vary KEY=V1,V2,...: the key and its values. */
typedef struct vary {
    const char *arg; /* KEY=V1,V2,... as given */
    char *key;
    char **vals;
    int nvals;
} vary;

/* One bench: its options, checked (bench.c), and how it reports. */
typedef struct bench {
    const char *scene, *out, *reference;
    const char **sets, **ref_sets;
    size_t nsets, nref_sets;
    vary *vary;
    int nvary, nvariants;
    double *budgets;
    int nbudgets, time_mode, repeat, threads, ref_spp, charts;
    const char *jobs; /* --emit-jobs DIR or --assemble DIR */
    int assemble;
    volatile sig_atomic_t *stop; /* set by SIGINT/SIGTERM/SIGHUP (murk_cli_catch_stop_signals), or the caller's */
    int command;                 /* run as `murk bench`: it catches the stop signals, and may --emit-jobs */
    murk_bench_row_fn row;       /* murk_lab_bench_run's callback, NULL for the command */
    void *user;
} bench;

/* MAX_VARY --vary of at most MAX_BLOCK_KEYS assignments each (a whole plugin block, KEY={type: X, k: v}):
 * the strings murk_bench_sets makes for one render fit in BENCH_STORE. */
enum { REF_CHUNKS = 4, MAX_VARY = 32, MAX_BLOCK_KEYS = 16, BENCH_STORE = MAX_VARY * MAX_BLOCK_KEYS + 1 };

/* The most --set strings murk_bench_sets may give for one render. */
static inline size_t murk_bench_max_sets(const bench *b)
{
    return b->nsets + b->nref_sets + (size_t)b->nvary * MAX_BLOCK_KEYS + 2;
}

/* A signal asked the bench to stop. */
static inline int murk_bench_stopped(const bench *b) { return b->stop && *b->stop; }

/* The image every render is measured against (bench_ref.c). */
typedef struct reference {
    int w, h;
    float *rgb, *var; /* var: the variance of rgb's per-pixel mean; NULL if unknown */
    char path[4096];
    int reused, spp;
    double seconds;
} reference;

/* Text to write through murk_write_atomic (atomic.h): murk_bench_text_fill copies it into the temporary. */
typedef struct text_job {
    const char *p;
    size_t n;
} text_job;


/* bench.c */
/* Variant i's label, "type=delta majorant_factor=4": each --vary key's short name and the variant's value. */
void murk_bench_label(const bench *b, int i, char *buf, size_t n);
/* The --set list of a render: the common sets, variant i's values (i < 0: the reference's sets) and the
 * seed (seed < 0: the scene's), into out; the strings it makes go to store, freed by murk_bench_free_sets. */
size_t murk_bench_sets(const bench *b, int i, long seed, const char **out, char **store, size_t *nstore);
void murk_bench_free_sets(char **store, size_t *n);
/* A variant's scene as `murk render` loads it (every medium and material used); NULL with err. */
murk_scene *murk_bench_load(const bench *b, const char *const *sets, size_t nsets, char *err, size_t errlen);
int murk_bench_mkdirs(const char *path); /* mkdir -p: 0, or -1 with errno */

/* bench_run.c */
/* Renders (or, --assemble, reads back) one render of the bench: variant v (v < 0: reference chunk k),
 * budget bi, seed index k. 0; 1 when a signal abandoned it (no image); -1 after a message. */
int murk_bench_render(const bench *b, int v, int bi, int k, const char *const *sets, size_t n,
                      const murk_render_opts *o, int w, int h, murk_render_result *res);
/* The bench once its options hold and its folder exists: the reference, every render, the files, the
 * charts and the page. The exit status. */
int murk_bench_run(const bench *b, int argc, char **argv);
int murk_bench_text_fill(FILE *f, const char *tmp, void *user, char *err, size_t errlen); /* user: text_job */

/* bench_ref.c */
/* The reference rendered in REF_CHUNKS chunks, or taken from the cache. 0, or -1 (after a message, or
 * when a signal stopped it). */
int murk_bench_reference(const bench *b, reference *r);
void murk_bench_ref_free(reference *r);
/* A w x h EXR's pixels into *out (malloc'd): 0, or -1. */
int murk_bench_read_exr(const char *path, int w, int h, float **out);

/* bench_jobs.c */
/* --emit-jobs: the jobs, slurm.sh and assemble.sh. The exit status. */
int murk_bench_emit_jobs(const bench *b, int argc, char **argv);
/* Where job (variant v, budget bi, seed k) writes its image; v < 0: reference chunk k. */
void murk_bench_job_out(const bench *b, int v, int bi, int k, char *buf, size_t n);
/* A job's image read back as murk_render_err would have returned it: 0, or -1 after a message. */
int murk_bench_read_job(const char *path, int w, int h, murk_render_result *res);
void murk_bench_shell_word(FILE *f, const char *w); /* " WORD" as a POSIX shell reads it back */

#endif
