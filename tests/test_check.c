/* test_check.c — `murk check` (core/lab/check/check.c) in the default suite.
 *
 *   shipped    `murk check --quick` on every plugin the build made (the .so files in build/plugins: materials,
 *              trackers, transmittance estimators, integrators) passes, the dielectric's transmission lines
 *              among them (test_dielectric checks its transmitting fixtures). Its statistical decisions (the
 *              count and false-alarm bound murk check prints) enter this program's sums (stat.h).
 *   broken     transmittance estimators broken on purpose (tests/fixtures/transmittance_flaw.h) fail
 *              where they are broken: tr_denser (a medium 3 % denser: its closed-form T figures, by
 *              thousands of standard errors) and tr_negative (unbiased, a sixth of its estimates
 *              negative: the >= 0 lines), and only there. (The broken materials are test_dielectric's.) */
#include "testutil.h"
#include "stat.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static void test_shipped(void **state)
{
    (void)state;
    const char *args[80] = {"check", "--quick"};
    char *names[64];
    int n = 0;
    DIR *dir = opendir(build_path("plugins"));
    assert_non_null(dir);
    for (struct dirent *e; (e = readdir(dir)) && n < 64;) {
        size_t len = strlen(e->d_name);
        if (len > 3 && !strcmp(e->d_name + len - 3, ".so"))
            names[n++] = strndup(e->d_name, len - 3);
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    assert_true(n >= 17); /* 3 materials, 5 trackers, 6 estimators, 3 integrators at least */
    for (int i = 0; i < n; i++)
        args[2 + i] = names[i];
    args[2 + n] = NULL;
    char *out = NULL;
    int rc = run_murk_argv(&out, args);
    int failed = stat_count_check(out);
    printf("murk check --quick on %d plugins: exit %d, %d failed\n%s\n", n, rc, failed,
           rc || failed ? out : strstr(out, "murk check: "));
    assert_int_equal(rc, 0);
    assert_int_equal(failed, 0);
    /* the dielectric's section covers transmission: the chi-square from inside at 80 degrees (mostly total
     * internal reflection) and the eta^2-weighted reciprocity across the boundary ran and passed */
    const char *from = strstr(out, "\ndielectric (material,"), *to = from ? strstr(from, "\ndielectric: all checks passed") : NULL;
    assert_non_null(to);
    char *section = strndup(from, (size_t)(to - from));
    assert_contains(section, "PASS chi2        set 1, wo 80 deg inside");
    assert_contains(section, "PASS reciprocity set 2                        transmission f(a,b)/eta_a^2 = f(b,a)/eta_b^2");
    free(section);
    free(out);
    for (int i = 0; i < n; i++)
        free(names[i]);
}

/* murk check on a broken fixture: exit 1, and failed lines only of the kind `what` (count: n). */
static void broken(const char *fixture, const char *what, int n)
{
    char *out = NULL;
    int rc = run_murk(&out, "check", "--quick", build_path(fixture), (char *)NULL);
    printf("%s", out);
    assert_int_equal(rc, 1);
    int failed = 0;
    for (const char *p = strstr(out, "  FAIL "); p; p = strstr(p + 1, "  FAIL ")) {
        const char *eol = strchr(p, '\n');
        char line[512];
        snprintf(line, sizeof line, "%.*s", eol ? (int)(eol - p) : (int)strlen(p), p);
        assert_contains(line, what);
        failed++;
    }
    assert_int_equal(failed, n);
    char label[96];
    snprintf(label, sizeof label, "murk check on %s", strrchr(fixture, '/') + 1);
    assert_true(stat_must_fail(label, failed == n, INFINITY)); /* deterministic: its bias is thousands of se */
    free(out);
}

static void test_broken(void **state)
{
    (void)state;
    broken("tests/fixtures/tr_denser.so", " T ", 6);
    broken("tests/fixtures/tr_negative.so", ">= 0", 6);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_shipped), cmocka_unit_test(test_broken)};
    return STAT_RUN(tests, argc, argv);
}
