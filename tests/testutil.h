/* testutil.h — helpers shared by murk's cmocka test programs. */
#ifndef MURK_TESTUTIL_H
#define MURK_TESTUTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

/* Fails the test, printing the haystack, unless hay (may be NULL) contains needle / does not. */
#define assert_contains(hay, needle)                                                                   \
    do {                                                                                               \
        const char *h_ = (hay), *n_ = (needle);                                                        \
        if (!h_ || !strstr(h_, n_))                                                                    \
            fail_msg("expected \"%s\" in:\n%s", n_, h_ ? h_ : "(null)");                               \
    } while (0)

#define assert_not_contains(hay, needle)                                                               \
    do {                                                                                               \
        const char *h_ = (hay), *n_ = (needle);                                                        \
        if (h_ && strstr(h_, n_))                                                                      \
            fail_msg("did not expect \"%s\" in:\n%s", n_, h_);                                         \
    } while (0)

/* Absolute path of a file in the source tree / build tree (static buffer rotated 8 ways). */
const char *src_path(const char *rel);
const char *build_path(const char *rel);
/* Runs the murk executable with the given arguments (NULL-terminated), capturing stdout+stderr into
 * *out (malloc'd, NUL-terminated). Returns the exit status (or 128+signal). */
int run_murk(char **out, const char *arg0, ...);
/* A fresh temporary directory for this test program (created once, removed by the OS's tmp cleaning). */
const char *tmp_dir(void);
/* tmp_dir()/name (static buffer rotated 8 ways with src_path's and build_path's). */
const char *tmp_path(const char *name);
/* 1 if the files at a and b both open and hold the same bytes. */
int files_equal(const char *a, const char *b);
/* Writes text to tmp_dir()/name and returns its path. */
const char *write_tmp(const char *name, const char *text);

/* The same with the arguments in a NULL-terminated array. */
int run_murk_argv(char **out, const char *const *args);
/* Runs murk with the arguments of args and then of extra (both NULL-terminated, extra may be NULL; 64
 * in all at most) and fails the test, printing murk's output, unless it exits 0. */
void run_murk_ok(const char *const *args, const char *const *extra);
/* The same with stdout into *out and stderr into *err apart (both malloc'd). */
int run_murk_split(char **out, char **err, const char *const *args);
/* The same for any program: argv[0] is its path (e.g. mpirun's, with murk's among the arguments). */
int run_argv(char **out, const char *const *argv);
/* Checks a run that must refuse its input: it printed its log, exited 1, said where ("scene.yaml:...") and
 * needle, and left no output file out. Frees log. */
void assert_refused(char *log, int rc, const char *where, const char *needle, const char *out);

/* Fails the test unless the EXRs a and b hold bitwise the same pixels (their attributes may differ). */
void assert_same_pixels(const char *a, const char *b);
/* 1 if they do, 0 if not (the size or a pixel differs); fails the test if one cannot be read. */
int same_pixels(const char *a, const char *b);

/* A scene rendered with several seeds: per pixel and channel (r, g, b, and their average in channel
 * 3) the mean over the renders and the variance of that mean (sample variance over the seeds / n). */
typedef struct img_stack {
    int w, h, n;
    double (*mean)[4], (*var)[4];
} img_stack;

/* Renders scene `nseeds` times (--set render.seed=seed0+k, --threads 2, --quiet, plus the extra
 * arguments, NULL-terminated, may be NULL) into tmp_dir()/out; fails the test if a render fails or
 * drops a NaN/inf sample. */
void img_stack_render(img_stack *st, const char *scene, const char *out, int nseeds, int seed0,
                      const char *const *extra);
void img_stack_free(img_stack *st);

/* Block-wise z-test of a against the reference r (two independent estimates of one image: independent
 * seeds): per block of block x block pixels and channel, the difference of block means over its standard
 * error from both stacks' per-pixel variances. They agree when no block differs by more than STAT_Z
 * sigma in any channel and the mean over blocks of the channel-average z is within STAT_Z / sqrt(nblocks)
 * of 0 (independent blocks, each z ~ N(0, 1)); stat.h counts every block and channel as a decision. The
 * per-pixel variances come from the seeds (n - 1 degrees of freedom each, summed over a block's pixels).
 * Prints one line (worst block, mean z, the reference's block standard error in percent) and returns 1
 * if they agree. Fewer than 16 blocks with signal is a failure (too little to judge). */
int img_stack_agree(const char *label, const img_stack *a, const img_stack *r, int block);
/* The same comparison as a must-fail case (stat_must_fail, not counted as decisions): a has a known bias
 * and must differ. Returns 1 if it does. */
int img_stack_must_differ(const char *label, const img_stack *a, const img_stack *r, int block);
/* The must-fail case "a bias in one block": a with its centre block's means times 1 + bias against r.
 * bias <= 0: 10 standard errors of that block's difference in its noisiest channel (printed in percent:
 * the comparison's resolution where no mutant of the renderer is at hand). */
int img_stack_must_differ_block(const char *label, const img_stack *a, const img_stack *r, int block, double bias);

/* Pearson chi-square test of observed counts against expected counts, merging bins (in order of
 * increasing expectation) until each holds at least min_expected. Returns the p-value. */
double chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out);

#endif
