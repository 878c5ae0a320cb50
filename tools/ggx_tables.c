/* ggx_tables.c — generates plugins/materials/ggx_tables.h, the tables of the ggx material plugin:
 * M(mu, alpha), the directional albedo term of its energy-conserving diffuse base, with per-cell
 * safety margins, and its cosine-weighted average Mavg. A tool of the repository, not of the plugin:
 *     ninja -C build tools/ggx_tables && ./build/tools/ggx_tables > plugins/materials/ggx_tables.h
 * (about 10 s; tests/meson.build checks that its output equals the committed header).
 *
 * M is integrated in double precision over the unit square of the spherical-cap VNDF
 * parameterisation (where the integrand is bounded and smooth) with tensor Gauss-Legendre quadrature.
 * Safety margins: every table cell is checked at 6 x 6 interior points against the directly
 * integrated M; the cell's largest shortfall of the bilinear interpolant (x 1.25, plus the quadrature
 * error bound and float rounding) is added to the cell's four corners, and a second, differently
 * placed set of check points must then show no shortfall. */
#include <math.h>

#define GGX_TAB_N 32         /* table size per axis */
#define GGX_ALPHA_MIN 1e-3f  /* the plugin clamps alpha to this; the tables assume it */
#define GGX_EAVG_SUB 8       /* E averages per row interval */

#include <stdio.h>
#include <stdlib.h>

static void gen_gauss_legendre(int n, double *x, double *w)
{ /* nodes and weights on [0, 1] */
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < n; i++) {
        double z = cos(pi * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = 0.0;
            for (int k = 0; k < n; k++) {
                double p2 = p1;
                p1 = p0;
                p0 = ((2.0 * k + 1.0) * z * p1 - k * p2) / (k + 1.0);
            }
            dp = n * (z * p0 - p1) / (z * z - 1.0);
            double dz = p0 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        x[i] = 0.5 * (1.0 - z);
        w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
}

/* The three directional integrals over the visible normals h of wo (mu = wo.z), in out[]:
 *   out[0] M  = integral of (1 - wo.h)^5 D_wo(h) dh
 *   out[1] E  = integral of G2(wo, wi) / G1(wo) D_wo(h) dh, wi = reflect(wo, h): the single-scattering
 *               GGX albedo with F = 1 (what reflects once and escapes), as in Kulla & Conty 2017
 *   out[2] E5 = the same with F = (1 - wo.h)^5, so that Schlick's E_ss = F0 E + (1 - F0) E5
 * Height-correlated Smith: G2 / G1(wo) = mu_i (mu_o + R_o) / (mu_i R_o + mu_o R_i), 0 for wi.z <= 0. */
static void gen_MEE(double mu, double alpha, int n, const double *x, const double *w, double out[3])
{
    const double pi = 3.14159265358979323846;
    double ox = sqrt(fmax(0.0, 1.0 - mu * mu)), oz = mu;
    double sx = alpha * ox, sz = oz, l = sqrt(sx * sx + sz * sz);
    sx /= l;
    sz /= l;
    double a2 = alpha * alpha, ro = sqrt(oz * oz * (1.0 - a2) + a2);
    double sm = 0.0, se = 0.0, s5 = 0.0;
    for (int i = 0; i < n; i++) {
        double cp = cos(2.0 * pi * x[i]), sp = sin(2.0 * pi * x[i]);
        for (int j = 0; j < n; j++) {
            double z = (1.0 - x[j]) * (1.0 + sz) - sz, st = sqrt(fmax(0.0, 1.0 - z * z));
            double hx = alpha * (st * cp + sx), hy = alpha * st * sp, hz = z + sz;
            double hl = sqrt(hx * hx + hy * hy + hz * hz);
            if (!(hl > 0.0))
                continue;
            double c = (ox * hx + oz * hz) / hl;
            c = c < 0.0 ? 0.0 : (c > 1.0 ? 1.0 : c);
            double t = 1.0 - c, t5 = t * t * t * t * t, ww = w[i] * w[j];
            sm += ww * t5;
            double mi = 2.0 * c * hz / hl - oz; /* wi.z */
            if (mi > 0.0) {
                mi = fmin(mi, 1.0);
                double ri = sqrt(mi * mi * (1.0 - a2) + a2);
                double g = mi * (oz + ro) / (mi * ro + oz * ri);
                se += ww * g;
                s5 += ww * g * t5;
            }
        }
    }
    out[0] = sm;
    out[1] = se;
    out[2] = s5;
}

enum { GEN_N = GGX_TAB_N, GEN_Q = 128, GEN_Q2 = 64, GEN_SUB = GGX_EAVG_SUB };
static double gen_xq[GEN_Q], gen_wq[GEN_Q];

static double gen_alpha(double r) { return fmax(r * r, (double)GGX_ALPHA_MIN); }
/* the E tables' first axis: w = mu (1 + alpha) / (mu + alpha) in [0, 1]; its inverse */
static double gen_mu_of_w(double w, double alpha) { return fmin(1.0, alpha * w / (1.0 + alpha - w)); }
/* the three integrals at a table position: axis 0 = t (M's table), 1 = w (the E tables') */
static void gen_at(int axis, double x, double r, int q, const double *xq, const double *wq, double out[3])
{
    double a = gen_alpha(r);
    gen_MEE(axis ? gen_mu_of_w(x, a) : x * x, a, q, xq, wq, out);
}
static double gen_interp(double T[GEN_N][GEN_N], double t, double r)
{
    double x = t * (GEN_N - 1), y = r * (GEN_N - 1);
    int i = (int)x, j = (int)y;
    if (i > GEN_N - 2)
        i = GEN_N - 2;
    if (j > GEN_N - 2)
        j = GEN_N - 2;
    double ft = x - i, fr = y - j;
    double a = T[j][i] + (T[j][i + 1] - T[j][i]) * ft, b = T[j + 1][i] + (T[j + 1][i + 1] - T[j + 1][i]) * ft;
    return a + (b - a) * fr;
}

static void print_table(const char *name, double S[GEN_N][GEN_N])
{
    printf("static const float %s[GGX_TAB_N][GGX_TAB_N] = {\n", name);
    for (int j = 0; j < GEN_N; j++) {
        printf("    {");
        for (int i = 0; i < GEN_N; i++)
            printf("%s%.8ef", i == 0 ? "" : (i % 6 == 0 ? ",\n     " : ", "), (double)(float)S[j][i]);
        printf("},\n");
    }
    printf("};\n");
}

static void print_floats(const char *name, const char *size, const double *v, int n)
{
    printf("static const float %s[%s] = {\n", name, size);
    for (int j = 0; j < n; j++)
        printf("%s%.8ef,", j % 6 == 0 ? (j ? "\n    " : "    ") : " ", (double)(float)v[j]);
    printf("\n};\n");
}

/* Integral of the E-table interpolant times 2 mu over mu in [0, 1] at r (alpha = gen_alpha(r)): on each
 * w interval the interpolant is linear in w and mu(w) is smooth, so 24-point Gauss-Legendre in w is exact
 * to rounding. */
static double gen_avg_w(double S[GEN_N][GEN_N], double r, const double *xg, const double *wg)
{
    double a = gen_alpha(r), sum = 0.0;
    for (int i = 0; i < GEN_N - 1; i++)
        for (int k = 0; k < 24; k++) {
            double w = (i + xg[k]) / (GEN_N - 1), mu = gen_mu_of_w(w, a);
            double dmu = a * (1.0 + a) / ((1.0 + a - w) * (1.0 + a - w)) / (GEN_N - 1);
            sum += wg[k] * gen_interp(S, w, r) * 2.0 * mu * dmu;
        }
    return sum;
}

/* Fills S with the table of integral k (0 M, 1 E, 2 E5) on axis `axis` plus safety margins; returns 0
 * if the independent verification finds no shortfall. global_q: one global quadrature error bound
 * (M, as it always was) or each cell's own (the E tables, whose kink at wi.z = 0 makes the quadrature
 * error very uneven; |Q128 - Q64| overestimates the error of Q128 about 3-fold for their kinked
 * integrand, whose Gauss-Legendre error falls as 1 / n^2). */
static int gen_table(int k, int axis, int global_q, double S[GEN_N][GEN_N], double *qmax, double *mmax)
{
    static double T[GEN_N][GEN_N], Q[GEN_N][GEN_N], cellm[GEN_N - 1][GEN_N - 1];
    double x2[GEN_Q2], w2[GEN_Q2], v[3], v2[3];
    gen_gauss_legendre(GEN_Q2, x2, w2);
    double qerr = 0.0, maxdef = 0.0, maxmargin = 0.0;
    const int nc = global_q ? 6 : 4, nv = global_q ? 5 : 4; /* check points per cell and axis */
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double t = i / (double)(GEN_N - 1), r = j / (double)(GEN_N - 1);
            gen_at(axis, t, r, GEN_Q, gen_xq, gen_wq, v);
            gen_at(axis, t, r, GEN_Q2, x2, w2, v2);
            T[j][i] = v[k];
            Q[j][i] = fabs(v[k] - v2[k]);
            qerr = fmax(qerr, Q[j][i]);
        }
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++) {
            double def = 0.0;
            for (int b = 0; b < nc; b++)
                for (int a = 0; a < nc; a++) {
                    double t = (i + (a + 0.5) / nc) / (GEN_N - 1), r = (j + (b + 0.5) / nc) / (GEN_N - 1);
                    gen_at(axis, t, r, GEN_Q, gen_xq, gen_wq, v);
                    def = fmax(def, v[k] - gen_interp(T, t, r));
                }
            maxdef = fmax(maxdef, def);
            double q = qerr; /* global, or the largest of the corners' and their neighbours' */
            if (!global_q) {
                q = 0.0;
                for (int b = j - 1; b <= j + 2; b++)
                    for (int a = i - 1; a <= i + 2; a++)
                        if (a >= 0 && b >= 0 && a < GEN_N && b < GEN_N)
                            q = fmax(q, Q[b][a]);
            }
            cellm[j][i] = global_q ? 1.25 * def + q + 1e-6 : 2.0 * def + q + 5e-5;
        }
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double m = 0.0;
            for (int b = j - 1; b <= j; b++)
                for (int a = i - 1; a <= i; a++)
                    if (a >= 0 && b >= 0 && a < GEN_N - 1 && b < GEN_N - 1)
                        m = fmax(m, cellm[b][a]);
            maxmargin = fmax(maxmargin, m);
            float f = (float)fmin(1.0, T[j][i] + m);
            if ((double)f < fmin(1.0, T[j][i] + m))
                f = nextafterf(f, 2.0f);
            S[j][i] = f;
        }
    /* independent verification */
    double worst = -1.0;
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++)
            for (int b = 0; b < nv; b++)
                for (int a = 0; a < nv; a++) {
                    double t = (i + (a + 0.37) / nv) / (GEN_N - 1), r = (j + (b + 0.61) / nv) / (GEN_N - 1);
                    gen_at(axis, t, r, GEN_Q, gen_xq, gen_wq, v);
                    worst = fmax(worst, fmin(v[k], 1.0) - gen_interp(S, t, r)); /* M, E <= 1 */
                }
    static const char *const names[3] = {"ggx_m", "ggx_e", "ggx_e5"};
    fprintf(stderr, "%-6s: quadrature error bound %.3g, largest interpolation shortfall %.3g, largest margin %.3g, "
                    "verification: largest shortfall %.3g (must be <= 0)\n", names[k], qerr, maxdef, maxmargin, worst);
    *qmax = qerr;
    *mmax = maxmargin;
    return worst > 0.0;
}

int main(void)
{
    static double S[2][GEN_N][GEN_N];
    double qerr[2], margin[2];
    gen_gauss_legendre(GEN_Q, gen_xq, gen_wq);
    int bad = gen_table(0, 0, 1, S[0], &qerr[0], &margin[0]);
    bad |= gen_table(1, 1, 0, S[1], &qerr[1], &margin[1]);
    if (bad)
        return 1;
    /* the E tables' averages at GEN_SUB points per row interval (the plugin interpolates linearly
     * between them); the largest interpolation error of that, at the midpoints, is reported */
    enum { NA = (GEN_N - 1) * GEN_SUB + 1 };
    static double avg[NA];
    double xg[24], wg[24], aerr = 0.0;
    gen_gauss_legendre(24, xg, wg);
    for (int j = 0; j < NA; j++) {
        avg[j] = gen_avg_w(S[1], j / (double)(NA - 1), xg, wg);
        if (j > 0) {
            double mid = gen_avg_w(S[1], (j - 0.5) / (NA - 1), xg, wg);
            aerr = fmax(aerr, fabs(mid - 0.5 * (avg[j] + avg[j - 1])));
        }
    }
    fprintf(stderr, "E averages: largest interpolation error %.3g\n", aerr);
    printf("/* ggx_tables.h — generated by tools/ggx_tables.c; do not edit: regenerate with\n"
           " *     ninja -C build tools/ggx_tables && ./build/tools/ggx_tables > plugins/materials/ggx_tables.h\n"
           " * ggx_m[j][i] = M(mu = t_i^2, alpha = max(r_j^2, GGX_ALPHA_MIN)) + safety margin, t_i = i / (N - 1),\n"
           " * r_j = j / (N - 1); ggx_mavg[j] = exact integral of the (piecewise linear in mu) interpolant times\n"
           " * 2 mu over [0, 1]. ggx_e: E, the single-scattering albedo with F = 1 (multiple-scattering\n"
           " * compensation), + safety margin, on the axis w_i = i / (N - 1), mu = alpha w / (1 + alpha - w) (the\n"
           " * dip of E near mu ~ alpha at low alpha stays resolved); ggx_eavg: the integral of its bilinear interpolant\n"
           " * times 2 mu over mu in [0, 1] at r = k / ((N - 1) GGX_EAVG_SUB) (largest error of linear\n"
           " * interpolation between them %.1e). Included by plugins/materials/ggx.c only. */\n"
           "#ifndef MURK_GGX_TABLES_H\n#define MURK_GGX_TABLES_H\n\n"
           "#define GGX_TAB_N %d\n#define GGX_ALPHA_MIN %.0ef\n#define GGX_EAVG_SUB %d\n\n", aerr, GGX_TAB_N,
           (double)GGX_ALPHA_MIN, GGX_EAVG_SUB);
    printf("/* BEGIN GENERATED TABLES */\n");
    printf("/* generated by tools/ggx_tables.c: quadrature error %.2g, largest margin %.2g */\n", qerr[0],
           margin[0]);
    print_table("ggx_m", S[0]);
    double mavg[GEN_N];
    for (int j = 0; j < GEN_N; j++) {
        /* exact integral of M 2 mu dmu = M 4 t^3 dt, M linear in t on each interval */
        double sum = 0.0;
        for (int i = 0; i < GEN_N - 1; i++) {
            double t0 = i / (double)(GEN_N - 1), t1 = (i + 1) / (double)(GEN_N - 1);
            double B = (S[0][j][i + 1] - S[0][j][i]) / (t1 - t0), A = S[0][j][i] - B * t0;
            sum += A * (pow(t1, 4) - pow(t0, 4)) + B * 0.8 * (pow(t1, 5) - pow(t0, 5));
        }
        mavg[j] = sum;
    }
    print_floats("ggx_mavg", "GGX_TAB_N", mavg, GEN_N);
    printf("/* ggx_e: largest quadrature error %.2g, largest margin %.2g */\n", qerr[1], margin[1]);
    print_table("ggx_e", S[1]);
    print_floats("ggx_eavg", "(GGX_TAB_N - 1) * GGX_EAVG_SUB + 1", avg, NA);
    printf("/* END GENERATED TABLES */\n\n#endif\n");
    return 0;
}
