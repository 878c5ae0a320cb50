/* testutil.h — helpers shared by murk's cmocka test programs. */
#ifndef MURK_TESTUTIL_H
#define MURK_TESTUTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

/* Absolute path of a file in the source tree / build tree (static buffer rotated 8 ways). */
const char *src_path(const char *rel);
const char *build_path(const char *rel);
/* Runs the murk executable with the given arguments (NULL-terminated), capturing stdout+stderr into
 * *out (malloc'd, NUL-terminated). Returns the exit status (or 128+signal). */
int run_murk(char **out, const char *arg0, ...);
/* A fresh temporary directory for this test program (created once, removed by the OS's tmp cleaning). */
const char *tmp_dir(void);
/* Writes text to tmp_dir()/name and returns its path. */
const char *write_tmp(const char *name, const char *text);

/* Pearson chi-square test of observed counts against expected counts, merging bins (in order of
 * increasing expectation) until each holds at least min_expected. Returns the p-value. */
double chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out);

#endif
