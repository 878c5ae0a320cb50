/* stat.h — the statistical decisions of murk's tests: one rule for all of them, counted.
 *
 * A statistical check is a decision that a correct murk fails now and then by chance, whenever the
 * random numbers change (other seeds, another order of drawing them, another Embree kernel). Every such
 * check decides through this file, which counts the decisions and adds up their false-alarm
 * probabilities; each program prints the sums when it ends and tests/README.md adds the programs up.
 * By Bonferroni's inequality the chance that any check fails on a correct murk is at most that sum,
 * whatever the dependence between the checks.
 *
 *   z-test       |estimate - expectation| <= STAT_Z se (+ a stated slack for float rounding): se from
 *                the sample variance of many (>= 1000) independent samples, the estimate's error
 *                taken as normal: false alarm 2 (1 - Phi(5)) = 5.7e-7 per decision.
 *   chi-square   p >= STAT_P = 1e-6: false alarm 1e-6 per decision.
 *   must-fail    a check run on an input with a known, stated bias (a mutant estimator, a denser medium,
 *                a shifted expectation) must fail. It is the check's power shown, not claimed; by
 *                chance it passes with probability about Phi(STAT_Z - |z|) (|z|: the bias in standard
 *                errors, measured), which this file adds to a second sum: a must-fail case that passes
 *                is a false alarm of the suite too.
 *
 * MURK_TEST_SCALE (a number in (0, 1], default 1) multiplies the sample counts of the programs that
 * use stat_n (CI's sanitizer run sets 0.1: it looks for memory errors, not bias). Below 1 the checks
 * keep their false-alarm rate (their bounds follow the standard errors) but lose power, so must-fail
 * cases and power demands are printed and not judged. */
#ifndef MURK_STAT_H
#define MURK_STAT_H

#include "testutil.h"

#define STAT_Z 5.0
#define STAT_P 1e-6

/* Two-sided normal tail 2 (1 - Phi(z)). */
double stat_tail2(double z);
/* Two-sided tail of Student's t with nu degrees of freedom (a mean whose se comes from nu + 1 values). */
double stat_tail2_t(double t, double nu);
/* The z with one-sided tail 1 - Phi(z) = p (p in (0, 0.5]; p below 1e-300 gives 37). */
double stat_probit_upper(double p);

/* Counts n decisions, each with false-alarm probability alpha (for checks not made through the
 * functions below). */
void stat_count(long n, double alpha);
/* The z-test: 1 if |est - expect| <= STAT_Z se + slack. Counts one decision. se 0 (a zero-variance
 * estimate) is compared within slack alone. */
int stat_z_ok(double est, double se, double expect, double slack);
/* z of a difference of two independent estimates (their standard errors combined). */
double stat_z2(double a, double se_a, double b, double se_b);
/* The empirical Bernstein bound (Maurer and Pontil 2009, theorem 4, both sides) on |mean - expectation|
 * of n independent samples with sample variance var that lie in an interval of length range, at the
 * false-alarm probability of a STAT_Z z-test: sqrt(2 var L / n) + 7 range L / (3 (n - 1)), L =
 * ln(4 / stat_tail2(STAT_Z)). It holds for any such distribution, also where the sample variance misses
 * rare values (heavy tails, or nearly constant samples with rare exceptions); the price is the second
 * term. stat_bounded_ok: |est - expect| within it plus slack, counted as one decision. */
double stat_eb_bound(double var, long n, double range);
int stat_bounded_ok(double est, double var, long n, double expect, double range, double slack);
/* Counts the decisions of `murk check`'s summary line in its output out ("N statistical decisions,
 * false-alarm bound A": murk check decides by the same rule) and returns its failed checks; fails the
 * test if out holds no summary line. Only for runs that must pass: a must-fail run is not a decision. */
int stat_count_check(const char *out);
/* The chi-square decision: 1 if p >= STAT_P. Counts one decision. */
int stat_chi2_ok(double p);

/* A must-fail case: `failed` is whether the check failed on the biased input, z the bias in standard
 * errors it measured (the chi-square's p converted: stat_probit_upper). Prints one line and returns 1
 * if the case failed as it must; 0 (a failed test) if it passed, unless the scale is below 1 (then it
 * is only printed and 1 is returned). Adds the chance of a pass to the second sum. */
int stat_must_fail(const char *label, int failed, double z);
/* The same for a chi-square: p of the mutant. */
int stat_must_fail_chi2(const char *label, double p);

/* MURK_TEST_SCALE (1 if unset); stat_n(n): n x the scale, at least min(n, 2000); stat_n_min: at least
 * lo (sample counts of renders: spp). */
double stat_scale(void);
long stat_n(long n);
long stat_n_min(long n, long lo);
/* 1 when power is judged (the scale is 1). */
int stat_power(void);

/* Runs the program's cmocka tests and prints the sums. With the argument "--long" only the tests
 * whose names start with "long_" run (they are the program's part in the suite 'long'; a second
 * argument narrows them: --long long_image), otherwise those are skipped; any other argument is a
 * cmocka test filter. */
int stat_run_tests(const char *name, const struct CMUnitTest *tests, size_t n, int argc, char **argv);
/* long_NAME: test_NAME again with `flag` set to 1 (the program's switch to more samples), as a test of the
 * suite 'long'. */
#define STAT_LONG_OF(name, flag)                                                                       \
    static void long_##name(void **state)                                                              \
    {                                                                                                  \
        flag = 1;                                                                                      \
        test_##name(state);                                                                            \
    }
#define STAT_RUN(tests, argc, argv) stat_run_tests(__FILE__, tests, sizeof(tests) / sizeof((tests)[0]), argc, argv)

#endif
