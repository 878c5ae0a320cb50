/* stat.c — see stat.h */
#include "stat.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static long ndecisions, nmust;
static double alpha_sum, beta_sum;

double stat_tail2(double z) { return erfc(fabs(z) / sqrt(2.0)); }

double stat_tail2_t(double t, double nu)
{
    /* 2 x the integral of the density from |t| on (Simpson in u = 1 / x over (0, 1 / |t|]: no infinite
     * range), the density c (1 + x^2 / nu)^(-(nu + 1) / 2) */
    double a = fabs(t);
    if (!(a > 0.0))
        return 1.0;
    double lc = lgamma((nu + 1.0) / 2.0) - lgamma(nu / 2.0) - 0.5 * log(nu * 3.14159265358979323846);
    const int n = 2000;
    double h = (1.0 / a) / n, sum = 0.0;
    for (int i = 0; i <= n; i++) {
        double u = i * h, f = 0.0;
        if (u > 0.0) { /* x = 1 / u, dx = du / u^2 */
            double x = 1.0 / u;
            f = exp(lc - 0.5 * (nu + 1.0) * log1p(x * x / nu)) / (u * u);
        }
        sum += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
    }
    return 2.0 * sum * h / 3.0;
}

double stat_probit_upper(double p)
{
    if (!(p > 1e-300))
        return 37.0;
    if (p >= 0.5)
        return 0.0;
    double lo = 0.0, hi = 37.0; /* 1 - Phi(z) = erfc(z / sqrt 2) / 2 falls monotonically */
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        if (0.5 * erfc(mid / sqrt(2.0)) > p)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

void stat_count(long n, double alpha)
{
    ndecisions += n;
    alpha_sum += (double)n * alpha;
}

int stat_z_ok(double est, double se, double expect, double slack)
{
    stat_count(1, stat_tail2(STAT_Z));
    return fabs(est - expect) <= STAT_Z * se + slack; /* NaN fails */
}

double stat_eb_bound(double var, long n, double range)
{
    double L = log(4.0 / stat_tail2(STAT_Z)), dn = (double)n;
    return sqrt(2.0 * fmax(var, 0.0) * L / dn) + 7.0 * range * L / (3.0 * (dn - 1.0));
}

int stat_bounded_ok(double est, double var, long n, double expect, double range, double slack)
{
    stat_count(1, stat_tail2(STAT_Z));
    return fabs(est - expect) <= stat_eb_bound(var, n, range) + slack;
}

double stat_z2(double a, double se_a, double b, double se_b)
{
    double se = hypot(se_a, se_b);
    if (se > 0.0)
        return (a - b) / se;
    return a == b ? 0.0 : INFINITY;
}

int stat_count_check(const char *out)
{
    const char *at = out ? strstr(out, "murk check: ") : NULL;
    int passed = 0, failed = -1, skipped = 0;
    long n = 0;
    double alpha = 0.0;
    if (!at || sscanf(at, "murk check: %d passed, %d failed, %d skipped; %ld statistical decisions, false-alarm bound %lg",
                      &passed, &failed, &skipped, &n, &alpha) != 5)
        fail_msg("no summary line in murk check's output:\n%s", out ? out : "(null)");
    stat_count(n, n > 0 ? alpha / (double)n : 0.0);
    return failed;
}

int stat_chi2_ok(double p)
{
    stat_count(1, STAT_P);
    return p >= STAT_P;
}

int stat_must_fail(const char *label, int failed, double z)
{
    double k = fabs(z);
    /* P(|Z + k| <= STAT_Z): the check passes although the input is biased by k standard errors */
    double beta = isfinite(k) ? 0.5 * (erfc((k - STAT_Z) / sqrt(2.0)) - erfc((k + STAT_Z) / sqrt(2.0))) : 0.0;
    nmust++;
    beta_sum += failed ? beta : 1.0;
    int judged = stat_power();
    printf("  must-fail %-60s %s (bias %.1f se; passes by chance with p %.1e)%s\n", label,
           failed ? "failed, as it must" : "PASSED", fmin(k, 9999.0), beta, failed || !judged ? "" : "  <-- FAIL");
    return failed || !judged;
}

int stat_must_fail_chi2(const char *label, double p)
{
    /* as a one-sided z: the check passes with probability about Phi(z_threshold - z) */
    return stat_must_fail(label, !(p >= STAT_P), stat_probit_upper(p) - stat_probit_upper(STAT_P) + STAT_Z);
}

double stat_scale(void)
{
    static double scale = -1.0;
    if (scale < 0.0) {
        const char *v = getenv("MURK_TEST_SCALE");
        scale = v && *v ? atof(v) : 1.0;
        if (!(scale > 0.0) || scale > 1.0)
            scale = 1.0;
    }
    return scale;
}

long stat_n_min(long n, long lo)
{
    long m = (long)((double)n * stat_scale());
    return m > lo ? m : (lo < n ? lo : n);
}

long stat_n(long n) { return stat_n_min(n, 2000); }

int stat_power(void) { return stat_scale() >= 1.0; }

int stat_run_tests(const char *name, const struct CMUnitTest *tests, size_t n, int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* keep the figures in order with murk's messages on stderr */
    int want_long = argc > 1 && !strcmp(argv[1], "--long");
    if (want_long)
        cmocka_set_test_filter(argc > 2 ? argv[2] : "long_*");
    else {
        cmocka_set_skip_filter("long_*");
        if (argc > 1)
            cmocka_set_test_filter(argv[1]);
    }
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    int rc = _cmocka_run_group_tests(base, tests, n, NULL, NULL);
    printf("stat: %s%s: %ld checks, false-alarm bound %.2e; %ld must-fail cases, chance that one passes %.2e%s\n",
           base, want_long ? " --long" : "", ndecisions, alpha_sum, nmust, beta_sum,
           stat_power() ? "" : " (MURK_TEST_SCALE < 1: power not judged)");
    return rc;
}
