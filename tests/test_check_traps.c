/* test_check_traps.c — `murk check` (core/lab/check/) against the bugs it once missed, and the honesty of
 * what it prints. Each trap fixture (tests/fixtures/trap_*.c) passed every check when murk check ran a
 * plugin's defaults only and judged means only; each is a must-fail case here, failing exactly where it
 * is broken:
 *   rate      trap_rate, biased at `rate: max` only: the sweep of every enum value fails that set's means
 *             and its agreement with delta, and no other set; `--set rate=mean` passes, `--set rate=max`
 *             fails;
 *   gain      trap_gain, 20 % too much energy: the furnace fails at albedo 1 (the range's end), 1.2, and
 *             nowhere else (0.9 at 75 % passes: why the old sets missed it);
 *   heavy     trap_heavy, unbounded weights in `mode: eager` (unbiased): the variance lines fail there
 *             (variance beyond 20x the analog estimator's), never in `mode: bounded`;
 *   estimator trap_tr_roulette, a transmittance estimator that keeps 1 estimate in 50 (x 50): its
 *             variance lines fail, nothing else;
 *   phase     trap_phase_edge, Henyey-Greenstein sampled from the wrong lobe beyond |g| 0.95 only: the
 *             sweep points g = -0.99 and 0.99 fail their sampled mean cosine, nothing else (the phase
 *             checks once skipped a range's ends).
 * A plugin with more sweep points than murk check runs (CK_MAX_SETS) is told so, never silently cut
 * (ck_param_sets, called directly).
 * And the output: a PASS line never shows |z| > 4 (zero-variance figures say they were compared
 * exactly); NaN is named; a missing plugin and a crashing one give a FAIL line with the reason, the
 * summary line and exit 1. All deterministic: murk check's seeds are fixed. */
#include "testutil.h"
#include "lab/check/sweep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* murk check [args] on a fixture (tests/fixtures/NAME.so); the exit status and the output in *out. */
static int check(char **out, const char *name, const char *set)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", build_path("tests/fixtures"));
    snprintf(path + strlen(path), sizeof path - strlen(path), "/%s.so", name);
    if (set)
        return run_murk(out, "check", "--quick", "--set", set, path, (char *)NULL);
    return run_murk(out, "check", "--quick", path, (char *)NULL);
}

/* Every FAIL line of out lies in a parameter set whose description holds `where` and says `what`; returns
 * how many there are. */
static int fails_only(const char *out, const char *where, const char *what)
{
    int n = 0;
    const char *set = "";
    for (const char *p = out; *p;) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), p);
        if (!strncmp(line, "  set ", 6))
            set = p;
        if (!strncmp(line, "  FAIL ", 7)) {
            char setline[512];
            snprintf(setline, sizeof setline, "%.*s", (int)strcspn(set, "\n"), set);
            if (!strstr(setline, where) || !strstr(line, what))
                fail_msg("a FAIL outside '%s' / '%s':\n%s\nin %s", where, what, line, setline);
            n++;
        }
        p += len + (eol != NULL);
    }
    return n;
}

static void test_rate(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "trap_rate", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_contains(out, "set 1: rate: min (the others at their defaults)");
    assert_contains(out, "set 2: rate: max (the others at their defaults)");
    int n = fails_only(out, "rate: max", "");
    printf("trap_rate: %d FAIL lines, all at rate: max\n", n);
    assert_true(n >= 8);
    free(out);
    rc = check(&out, "trap_rate", "rate=mean");
    assert_int_equal(rc, 0);
    assert_contains(out, "set 0: rate: mean (--set; the others at their defaults)");
    free(out);
    rc = check(&out, "trap_rate", "rate=max");
    assert_int_equal(rc, 1);
    free(out);
}

static void test_gain(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "trap_gain", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_int_equal(fails_only(out, "albedo: [1, 1, 1], its maximum", "furnace"), 3);
    assert_contains(out, "energy albedo 1.2000 1.2000 1.2000 (zero variance: <= 1 exactly)");
    assert_contains(out, "PASS furnace     set 2, wo 45 deg             energy albedo 0.9000 0.7200 0.3600");
    free(out);
}

static void test_heavy(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "trap_heavy", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    fails_only(out, "mode: eager", "");
    int nvar = 0;
    for (const char *p = strstr(out, "  FAIL "); p; p = strstr(p + 1, "  FAIL ")) {
        const char *eol = strchr(p, '\n'), *v = strstr(p, " variance ");
        nvar += v && (!eol || v < eol);
    }
    printf("trap_heavy: %d variance lines FAIL\n", nvar);
    assert_true(nvar >= 3);
    free(out);
    rc = check(&out, "trap_heavy", "mode=bounded");
    assert_int_equal(rc, 0);
    free(out);
}

/* An estimator kept 1 in 50 (x 50): unbiased, its variance lines fail (34x to 86x), nothing else. */
static void test_estimator(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "trap_tr_roulette", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_true(fails_only(out, "defaults", " variance ") >= 3);
    free(out);
}

/* A phase function wrong only near |g| = 1: its two sweep points fail, on the mean cosine alone. */
static void test_phase_edge(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "trap_phase_edge", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_contains(out, "g: -0.99, its minimum (the others at their defaults)");
    assert_contains(out, "g: 0.99, its maximum (the others at their defaults)");
    assert_int_equal(fails_only(out, ", its m", "mean cos"), 2);
    free(out);
    rc = check(&out, "trap_phase_edge", "g=0.9");
    assert_int_equal(rc, 0);
    free(out);
}

/* 30 float parameters: 3 full sets and 60 range ends do not fit into CK_MAX_SETS; the count left out is
 * said. 20 fit (43 sets) and nothing is said. */
static void test_sweep_overflow(void **state)
{
    (void)state;
    static murk_param params[30];
    static char names[30][8];
    for (int i = 0; i < 30; i++) {
        snprintf(names[i], sizeof names[i], "p%d", i);
        params[i] = (murk_param){names[i], MURK_PARAM_FLOAT, 0, {0.5, 0, 0}, NULL, NULL, 0.0, 1.0, "x"};
    }
    murk_plugin_desc d = {sizeof d, MURK_KIND_MATERIAL, "many", "many parameters", params, 30, NULL, NULL};
    static ck_set sets[CK_MAX_SETS];
    char err[512];
    int n = ck_param_sets(&d, NULL, 0, sets, CK_MAX_SETS, err, sizeof err);
    printf("30 parameters: %d sets, '%s'\n", n, err);
    assert_int_equal(n, CK_MAX_SETS);
    char want[128];
    snprintf(want, sizeof want, "%d sweep points beyond the first %d parameter sets not run", 3 + 60 - CK_MAX_SETS,
             CK_MAX_SETS);
    assert_contains(err, want);
    d.nparams = 20;
    n = ck_param_sets(&d, NULL, 0, sets, CK_MAX_SETS, err, sizeof err);
    assert_int_equal(n, 43);
    assert_string_equal(err, "");
}

/* No PASS line shows a z beyond the bound; zero-variance figures say how they were compared. */
static void test_honest_pass(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = run_murk(&out, "check", "--quick", "delta", "diffuse", (char *)NULL);
    assert_int_equal(rc, 0);
    for (const char *p = strstr(out, "  PASS "); p; p = strstr(p + 1, "  PASS ")) {
        const char *eol = strchr(p, '\n');
        for (const char *z = strstr(p, "z "); z && (!eol || z < eol); z = strstr(z + 1, "z ")) {
            double v;
            if (sscanf(z, "z %lf", &v) == 1 && !(fabs(v) <= 4.0))
                fail_msg("a PASS line beyond |z| 4: %.*s", eol ? (int)(eol - p) : (int)strlen(p), p);
        }
    }
    assert_contains(out, "zero variance, compared exactly");
    assert_contains(out, "(zero variance: <= 1 exactly)");
    free(out);
}

/* NaN named; a missing plugin and a crash: a FAIL line with the reason, a summary, exit 1. */
static void test_honest_fail(void **state)
{
    (void)state;
    char *out = NULL;
    int rc = check(&out, "nan_material", NULL);
    assert_int_equal(rc, 1);
    assert_contains(out, "NaN or infinite f, pdf or wi");
    assert_contains(out, "50000 of 50000 samples NaN or infinite");
    free(out);
    rc = run_murk(&out, "check", "--quick", "no_such_plugin", (char *)NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_contains(out, "FAIL no plugin 'no_such_plugin'");
    assert_contains(out, "murk check: 0 passed, 1 failed, 0 skipped");
    free(out);
    rc = check(&out, "crasher", NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    assert_contains(out, "the checks ended early: the process died of signal 11");
    assert_contains(out, "murk check: 0 passed, 1 failed, 0 skipped");
    free(out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_rate), cmocka_unit_test(test_gain), cmocka_unit_test(test_heavy),
                                       cmocka_unit_test(test_estimator), cmocka_unit_test(test_phase_edge),
                                       cmocka_unit_test(test_sweep_overflow),
                                       cmocka_unit_test(test_honest_pass), cmocka_unit_test(test_honest_fail)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
