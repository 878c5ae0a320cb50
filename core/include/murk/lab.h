/* murk/lab.h — libmurklab, murk's lab: the commands that measure renders and plugins (`murk bench`,
 * `murk compare`, `murk check`), apart from the renderer. It links libmurk (murk/murk.h); a program that
 * only renders needs neither this header nor this library, and plugins never use either.
 *   cc prog.c $(pkg-config --cflags --libs murk-lab) */
#ifndef MURK_LAB_H
#define MURK_LAB_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "murk/counters.h"
#include "murk/plugin.h"

/* The commands, as the murk command runs them: argv holds the arguments after the command's name
 * (argv[0] is the first argument, not "bench"), the return value is the command's exit status, and
 * output and errors go to stdout and stderr as the command's do. */
int murk_lab_bench(int argc, char **argv);   /* murk bench SCENE.yaml [--vary KEY=V1,V2,...]... */
int murk_lab_compare(int argc, char **argv); /* murk compare TEST.exr REFERENCE.exr [...] */
int murk_lab_check(int argc, char **argv);   /* murk check [--seed S] [--quick] PLUGIN... */

/* ---- An image against a reference: the figures `murk compare` prints and `murk bench` records ---- */

/* A rectangle of pixels: x, y (top-left), w, h. */
typedef struct murk_crop { int x, y, w, h; } murk_crop;

typedef struct murk_metrics {
    size_t n;           /* pixel-channels compared (finite in both images) */
    size_t nonfinite;   /* pixel-channels skipped: NaN or infinite in either image */
    double mse;         /* mean (a - r)^2 */
    double relmse_raw;  /* mean (a - r)^2 / (r^2 + 0.01) */
    double ref_noise;   /* mean v / (r^2 + 0.01): the reference's own noise in relMSE (0 without v) */
    double relmse;      /* relmse_raw - ref_noise: the noise-corrected relMSE (unbiased for a's error) */
    double relmse_se;   /* its standard error, from the spread of the per-pixel terms */
    double mare;        /* mean |a - r| / (|r| + 0.01) */
    double diff[4], diff_se[4]; /* mean of a - r and its standard error per channel, [3]: all channels */
} murk_metrics;

/* Compares a with the reference r (both 3 floats per pixel, row stride w pixels) over the rectangle c.
 * v, if non-NULL, is the variance of r's per-pixel mean (same layout): subtracted from every squared
 * difference, so E[relmse] is a's own relMSE whatever the reference's noise. pix, if non-NULL, gets
 * c.w x c.h floats: each pixel's channel-mean of the corrected relative squared error. */
void murk_metrics_compute(const float *a, const float *r, const float *v, int w, murk_crop c, murk_metrics *m,
                          float *pix);

/* ---- A bench, row by row ---- */

/* One row of bench.csv (its columns, in order): a whole render, its work and its figures against the
 * reference. */
typedef struct murk_bench_row {
    int variant;            /* the variant's index (the cross product of the --vary lists, the last fastest) */
    const char *label;      /* its --vary values: "type=delta majorant_factor=4" ("scene" without --vary) */
    double budget;          /* spp, or seconds with --time */
    int seed;               /* 1 .. --repeat */
    int spp;                /* rendered */
    double seconds;         /* the render's time */
    uint64_t rays;
    murk_counters counters; /* summed over the scene's media (murk/counters.h) */
    murk_metrics metrics;   /* against the reference, its noise subtracted when known */
    uint64_t nonfinite;     /* the render's non-finite samples plus the pixel-channels the metrics skipped */
    double max_sample;      /* the render's largest finite sample */
} murk_bench_row;

/* Called once per whole render, as its row is added; row and its label live until the call returns. */
typedef void (*murk_bench_row_fn)(void *user, const murk_bench_row *row);

/* `murk bench` with the command's arguments and files (bench.csv, maps, bench.json, charts, report.html),
 * for a program: each row also handed to row(user, ...) (row may be NULL), and no signal handlers set.
 * stop, if not NULL, plays their part: once *stop is set the running render is abandoned and the bench
 * ends as the command does on SIGINT (bench-interrupted.csv with the whole renders' rows; status 130).
 * --emit-jobs is refused (status 2): its jobs run the murk command. Returns the command's exit status. */
int murk_lab_bench_run(int argc, char **argv, volatile sig_atomic_t *stop, murk_bench_row_fn row, void *user);

/* ---- Plugins' schemas as data: what `murk plugins NAME` prints ---- */

typedef struct murk_lab_plugin murk_lab_plugin; /* an open plugin; its info lives until it is closed */

typedef struct murk_lab_plugin_info {
    const char *name, *description;
    const char *version;     /* the plugin's own version, NULL if it has none */
    const char *path;        /* the file it was loaded from */
    int kind;                /* murk_kind */
    murk_abi abi;            /* the ABI it was built for */
    const murk_param *params; /* its parameters, in schema order (murk/plugin.h) */
    uint32_t nparams;
} murk_lab_plugin_info;

/* Finds NAME.so on the plugin search path ($MURK_PLUGIN_PATH, then the build's or the installed plugin
 * folder) and opens it as a scene would: ABI and descriptor checked. NULL with a one-line message in err
 * (naming the file and the cause) if it is missing or refused. */
murk_lab_plugin *murk_lab_plugin_open(const char *name, murk_lab_plugin_info *info, char *err, size_t errlen);
void murk_lab_plugin_close(murk_lab_plugin *plugin); /* NULL is fine */
/* The keys every medium takes besides its tracker's parameters (sigma_a, sigma_s, ...; *n of them), in
 * the order `murk plugins TRACKER` lists them. Two more are not of a schema's types: `density` (a map)
 * and `transmittance` (an estimator's name, or a map with its `type`). */
const murk_param *murk_lab_medium_params(uint32_t *n);

#endif
