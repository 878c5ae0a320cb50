/* ggx_tables.c — generates the tables of two material plugins; a tool of the repository, not of the
 * plugins (tools/meson.build checks that its output equals the committed headers):
 *     ninja -C build tools/ggx_tables && ./build/tools/ggx_tables > plugins/materials/ggx_tables.h
 *     ./build/tools/ggx_tables dielectric > plugins/materials/dielectric_tables.h
 * The GGX and Fresnel formulas it shares with the plugins come from murk/microfacet.h (in double).
 *
 * ggx_tables.h: M(mu, alpha), the directional albedo term of ggx's energy-conserving diffuse base, with
 * per-cell safety margins, and its cosine-weighted average Mavg; E(mu, alpha), the coat's
 * single-scattering albedo, and Eavg. M is integrated in double precision over the unit square of the
 * spherical-cap VNDF parameterisation (where the integrand is bounded and smooth) with tensor
 * Gauss-Legendre quadrature. Safety margins: every table cell is checked at 6 x 6 interior points against
 * the directly integrated M; the cell's largest shortfall of the bilinear interpolant (x 1.25, plus the
 * quadrature error bound and float rounding) is added to the cell's four corners, and a second,
 * differently placed set of check points must then show no shortfall.
 *
 * dielectric_tables.h: E(mu, alpha, eta), the energy albedo (reflection + transmission, the transmitted
 * part counted as energy: radiance x eta^2) of the dielectric plugin's single-scattering rough model,
 * for wo on the outside (relative index eta) and on the inside (1 / eta); see
 * dielectric_main() below. */
#include "murk/microfacet.h"

#include <math.h>

#define GGX_TAB_N 32         /* table size per axis */
#define GGX_ALPHA_MIN 1e-3f  /* the plugin clamps alpha to this; the tables assume it */
#define GGX_EAVG_SUB 8       /* E averages per row interval */

#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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
    double a2 = alpha * alpha, ro = murk_ggx_smith_r_d(oz, a2);
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
                double ri = murk_ggx_smith_r_d(mi, a2);
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

static int ggx_main(void)
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

/* ---- dielectric_tables.h ------------------------------------------------------------------------
 * E(mu, alpha, eta): the energy albedo of plugins/materials/dielectric.c's single-scattering rough
 * model for wo above the surface (mu = wo.z > 0) and relative index eta of the side below (< 1 for wo
 * inside a body of index 1 / eta: the model is the same seen from either side). Over the visible
 * normals h of wo (VNDF, as the plugin samples them):
 *     E = integral of [ F(wo.h) G2(wo, wr) / G1(wo) + (1 - F(wo.h)) G2(wo, wt) / G1(wo) ] D_wo(h) dh,
 * wr = reflect(wo, h) counted where it stays above, wt = refract(wo, h) where it goes below (the
 * transmitted radiance times eta^2, the energy), height-correlated Smith G2 = 1 / (1 + L(wo) + L(wi)).
 * The integrand has a kink where wr or wt grazes the surface and, for eta < 1, the square-root edge of
 * total internal reflection, so it is integrated piecewise: at fixed azimuth phi of the cap
 * parameterisation, the cap coordinate u1 is split where any of the three edges crosses (found by a scan
 * of DI_SCAN points and bisection), and phi (over [0, pi]: the integrand is even in phi) is split where
 * the number of crossings changes; Gauss-Legendre with DI_Q points on every piece. Doubling DI_Q and
 * DI_SCAN changes no entry by more than the printed quadrature error.
 *
 * Axes (dielectric_tables_axis.h, shared with the plugin): roughness r_j = j / (DI_TAB_NR - 1), alpha_j =
 * max(r_j^2, DI_ALPHA_MIN); eta_k = 1 + 3 x_k^2, x_k = k / (DI_TAB_NETA - 1), denser near 1 where E changes
 * fastest; mu on each row's own axis (di_u_of_mu: resolves the dip near mu ~ alpha and puts the kink at
 * the critical angle inside on one node). The plugin blends the rows of the two indices around its ior
 * and averages its rows in closed form (di_row_avg); dielectric_main() checks its interpolation against
 * E integrated at random points and prints the largest errors. */
#define DI_TAB_NMU 33 /* odd: u = 1/2 is a node */
#define DI_TAB_NR 32
#define DI_TAB_NETA 16
#define DI_ALPHA_MIN 1e-3
enum { DI_Q = 24, DI_SCAN = 24, DI_BISECT = 44, DI_MAXBR = 64 };

typedef struct di_gen {
    double ox, oz, sx, sz, alpha, a2, ro, eta, ccrit; /* wo = (ox, 0, oz); the cap's centre (sx, 0, sz) */
    double cp, sp;                                    /* cos, sin of the current azimuth */
    const double *xq, *wq;                            /* nq Gauss-Legendre nodes and weights on [0, 1] */
    int nq;
} di_gen;

/* G2 / G1(wo) for an outgoing cosine m (> 0 on its own side) */
static double di_g(const di_gen *d, double m)
{
    m = fmin(m, 1.0);
    double ri = murk_ggx_smith_r_d(m, d->a2);
    return m * (d->oz + d->ro) / (m * d->ro + d->oz * ri);
}

/* The integrand at cap coordinate u1 (azimuth in d), and its three edge functions in e[]: wr.z, wo.h minus
 * the critical cosine, -wt.z (each changes sign where the integrand has a kink or an edge). */
static double di_point(const di_gen *d, double u1, double e[3])
{
    double z = (1.0 - u1) * (1.0 + d->sz) - d->sz, st = sqrt(fmax(0.0, 1.0 - z * z));
    double hx = d->alpha * (st * d->cp + d->sx), hy = d->alpha * st * d->sp, hz = z + d->sz;
    double hl = sqrt(hx * hx + hy * hy + hz * hz);
    e[0] = e[1] = e[2] = -1.0;
    if (!(hl > 0.0))
        return 0.0;
    hx /= hl;
    hy /= hl;
    hz /= hl;
    double c = fmin(1.0, fmax(0.0, d->ox * hx + d->oz * hz));
    double F = murk_fresnel_dielectric_cos_d(c, d->eta), v = 0.0, mr = 2.0 * c * hz - d->oz;
    e[0] = mr;
    e[1] = c - d->ccrit;
    if (mr > 0.0)
        v += F * di_g(d, mr);
    if (F < 1.0) { /* wt = -wo / eta + h (c / eta - cos theta_t) */
        double k = c / d->eta - sqrt(fmax(0.0, 1.0 - (1.0 - c * c) / (d->eta * d->eta)));
        double tx = -d->ox / d->eta + hx * k, ty = hy * k, tz = -d->oz / d->eta + hz * k;
        tz /= sqrt(tx * tx + ty * ty + tz * tz);
        e[2] = -tz;
        if (tz < 0.0)
            v += (1.0 - F) * di_g(d, -tz);
    }
    return v;
}

/* Sorted breakpoints in [0, 1] (0 and 1 included) of f's sign changes, f(x, k) for k < nf: a scan of
 * DI_SCAN points, then bisection. Returns their number. */
typedef int (*di_signs)(const di_gen *d, double x, int s[3]);
static int di_breaks(const di_gen *d, di_signs f, double *br)
{
    int n = 0, sp[3], s[3];
    br[n++] = 0.0;
    f(d, 0.0, sp);
    for (int i = 1; i <= DI_SCAN; i++) {
        double b = (double)i / DI_SCAN;
        f(d, b, s);
        for (int k = 0; k < 3; k++) {
            if (s[k] == sp[k] || n >= DI_MAXBR - 1)
                continue;
            double lo = (double)(i - 1) / DI_SCAN, hi = b;
            for (int it = 0; it < DI_BISECT; it++) {
                double m = 0.5 * (lo + hi);
                int sm[3];
                f(d, m, sm);
                if (sm[k] == sp[k])
                    lo = m;
                else
                    hi = m;
            }
            br[n++] = 0.5 * (lo + hi);
        }
        for (int k = 0; k < 3; k++)
            sp[k] = s[k];
    }
    br[n++] = 1.0;
    for (int i = 1; i < n; i++) /* insertion sort */
        for (int j = i; j > 0 && br[j] < br[j - 1]; j--) {
            double t = br[j];
            br[j] = br[j - 1];
            br[j - 1] = t;
        }
    return n;
}

static int di_signs_u1(const di_gen *d, double u1, int s[3])
{
    double e[3];
    di_point(d, u1, e);
    for (int k = 0; k < 3; k++)
        s[k] = e[k] > 0.0;
    return 0;
}

/* The integral over u1 at the azimuth phi = pi x; *nbr receives its number of breakpoints. */
static double di_inner(di_gen *d, double x, int *nbr)
{
    const double pi = 3.14159265358979323846;
    double br[DI_MAXBR], e[3], sum = 0.0;
    d->cp = cos(pi * x);
    d->sp = sin(pi * x);
    int n = di_breaks(d, di_signs_u1, br);
    *nbr = n;
    for (int i = 0; i + 1 < n; i++)
        for (int j = 0; j < d->nq; j++)
            sum += d->wq[j] * (br[i + 1] - br[i]) * di_point(d, br[i] + (br[i + 1] - br[i]) * d->xq[j], e);
    return sum;
}

static int di_signs_phi(const di_gen *d, double x, int s[3])
{ /* the breakpoint count in bits: changes where a crossing appears or vanishes */
    di_gen c = *d;
    int n;
    c.nq = 1; /* only the breakpoints are wanted */
    di_inner(&c, x, &n);
    s[0] = n & 1;
    s[1] = (n >> 1) & 1;
    s[2] = (n >> 2) & 1;
    return 0;
}

static double di_E(double mu, double alpha, double eta, int nq, const double *xq, const double *wq)
{
    di_gen d;
    memset(&d, 0, sizeof d);
    d.ox = sqrt(fmax(0.0, 1.0 - mu * mu));
    d.oz = mu;
    double l = sqrt(alpha * alpha * d.ox * d.ox + mu * mu);
    d.sx = alpha * d.ox / l;
    d.sz = mu / l;
    d.alpha = alpha;
    d.a2 = alpha * alpha;
    d.ro = murk_ggx_smith_r_d(mu, d.a2);
    d.eta = eta;
    d.ccrit = eta < 1.0 ? sqrt(1.0 - eta * eta) : -1.0;
    d.xq = xq;
    d.wq = wq;
    d.nq = nq;
    double br[DI_MAXBR], sum = 0.0;
    int n = di_breaks(&d, di_signs_phi, br), nb;
    for (int i = 0; i + 1 < n; i++)
        for (int j = 0; j < nq; j++)
            sum += wq[j] * (br[i + 1] - br[i]) * di_inner(&d, br[i] + (br[i + 1] - br[i]) * xq[j], &nb);
    return sum;
}

static double di_alpha(int j) { double r = j / (double)(DI_TAB_NR - 1); return fmax(r * r, DI_ALPHA_MIN); }
static double di_eta(int k, int inside)
{
    double x = k / (double)(DI_TAB_NETA - 1), e = 1.0 + 3.0 * x * x;
    return inside ? 1.0 / e : e;
}
#include "../plugins/materials/dielectric_tables_axis.h" /* di_mucrit, di_u_of_mu, di_mu_of_u, di_row_avg */

/* The node values by [side][k][j][i], as the header holds them (rounded to float) */
static double di_tab[2][DI_TAB_NETA][DI_TAB_NR][DI_TAB_NMU];

/* What the plugin builds at create() for its index eta, in double: per side and roughness row, the rows of
 * the two nearest eta nodes blended (on the aligned axis u), and each row's exact average. */
typedef struct di_inst { double eta, mc, e[2][DI_TAB_NR][DI_TAB_NMU], avg[2][DI_TAB_NR]; } di_inst;
static void di_inst_make(di_inst *in, double eta)
{
    double x = sqrt((eta - 1.0) / 3.0) * (DI_TAB_NETA - 1);
    int k = (int)x;
    k = k > DI_TAB_NETA - 2 ? DI_TAB_NETA - 2 : k;
    double fx = x - k;
    in->eta = eta;
    in->mc = di_mucrit(eta);
    for (int side = 0; side < 2; side++)
        for (int j = 0; j < DI_TAB_NR; j++) {
            double *row = in->e[side][j], a = di_alpha(j);
            for (int i = 0; i < DI_TAB_NMU; i++)
                row[i] = di_tab[side][k][j][i] + (di_tab[side][k + 1][j][i] - di_tab[side][k][j][i]) * fx;
            double sum = di_row_avg(row, DI_TAB_NMU, side, a, in->mc);
            in->avg[side][j] = sum;
        }
}
static double di_inst_row(const di_inst *in, int side, int j, double mu)
{
    double u = di_u_of_mu(side, mu, di_alpha(j), in->mc) * (DI_TAB_NMU - 1);
    int i = (int)u;
    i = i > DI_TAB_NMU - 2 ? DI_TAB_NMU - 2 : i;
    return in->e[side][j][i] + (in->e[side][j][i + 1] - in->e[side][j][i]) * (u - i);
}
static double di_inst_E(const di_inst *in, int side, double mu, double alpha)
{
    double r = sqrt(alpha) * (DI_TAB_NR - 1);
    int j = (int)r;
    j = j > DI_TAB_NR - 2 ? DI_TAB_NR - 2 : j;
    double a = di_inst_row(in, side, j, mu), b = di_inst_row(in, side, j + 1, mu);
    return a + (b - a) * (r - j);
}

static int dielectric_main(void)
{
    static double xq[DI_Q], wq[DI_Q];
    gen_gauss_legendre(DI_Q, xq, wq);
    static double flat[2 * DI_TAB_NETA * DI_TAB_NR * DI_TAB_NMU];
    int n = 0;
    for (int side = 0; side < 2; side++)
        for (int k = 0; k < DI_TAB_NETA; k++)
            for (int j = 0; j < DI_TAB_NR; j++)
                for (int i = 0; i < DI_TAB_NMU; i++) {
                    double a = di_alpha(j), eta = di_eta(k, 0);
                    double mu = fmax(1e-6, di_mu_of_u(side, i / (double)(DI_TAB_NMU - 1), a, di_mucrit(eta)));
                    double v = di_E(mu, a, side ? 1.0 / eta : eta, DI_Q, xq, wq);
                    di_tab[side][k][j][i] = flat[n++] = (double)(float)fmin(1.0, v);
                }
    /* interpolation error at random points, against E integrated there; and a check that an instance's
     * averages are those of its interpolant (by a fine midpoint rule in mu) */
    double worst[2] = {0.0, 0.0}, worst_far[2] = {0.0, 0.0}, avgerr = 0.0;
    uint64_t st = 0x9e3779b97f4a7c15ull;
    static di_inst in;
    for (int t = 0; t < 1000; t++) {
        double u[3];
        for (int c = 0; c < 3; c++) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            u[c] = (double)(st >> 11) * (1.0 / 9007199254740992.0);
        }
        double mu = fmax(1e-6, u[0]), alpha = fmax(DI_ALPHA_MIN, u[1] * u[1]), eta = 1.0 + 3.0 * u[2] * u[2];
        di_inst_make(&in, eta);
        for (int side = 0; side < 2; side++) {
            double e = fabs(di_inst_E(&in, side, mu, alpha) - fmin(1.0, di_E(mu, alpha, side ? 1.0 / eta : eta, DI_Q, xq, wq)));
            worst[side] = fmax(worst[side], e);
            if (mu >= 0.1 && eta >= 1.1)
                worst_far[side] = fmax(worst_far[side], e);
            if (getenv("DI_DEBUG") && e > 1e-3)
                fprintf(stderr, "  interpolation %.2g at mu %.3g alpha %.3g eta %.3g side %d\n", e, mu, alpha, eta, side);
        }
        if (t < 20) {
            int side = t & 1, j = t % DI_TAB_NR;
            double sum = 0.0;
            for (int m = 0; m < 200000; m++) {
                double mm = (m + 0.5) / 200000;
                sum += di_inst_row(&in, side, j, mm) * 2.0 * mm / 200000;
            }
            avgerr = fmax(avgerr, fabs(sum - in.avg[side][j]));
        }
    }
    /* quadrature error: a sample of nodes integrated again with twice the points */
    double qerr = 0.0;
    {
        static double x2[2 * DI_Q], w2[2 * DI_Q];
        gen_gauss_legendre(2 * DI_Q, x2, w2);
        for (int t = 0; t < 64; t++) {
            int side = t & 1, k = (t * 7) % DI_TAB_NETA, j = (t * 11) % DI_TAB_NR, i = (t * 5) % DI_TAB_NMU;
            double a = di_alpha(j), eta = di_eta(k, 0);
            double mu = fmax(1e-6, di_mu_of_u(side, i / (double)(DI_TAB_NMU - 1), a, di_mucrit(eta)));
            eta = side ? 1.0 / eta : eta;
            double e2 = fabs(di_E(mu, a, eta, 2 * DI_Q, x2, w2) - di_E(mu, a, eta, DI_Q, xq, wq));
            if (getenv("DI_DEBUG") && e2 > 1e-4)
                fprintf(stderr, "  quadrature %.2g at mu %.3g alpha %.3g eta %.3g\n", e2, mu, a, eta);
            qerr = fmax(qerr, e2);
        }
    }
    fprintf(stderr, "dielectric E: quadrature error (%d vs %d points, 64 nodes) %.2g; interpolation error outside %.2g, "
                    "inside %.2g (at mu >= 0.1, eta >= 1.1: %.2g, %.2g); averages (vs a midpoint rule) %.2g\n", DI_Q,
            2 * DI_Q, qerr, worst[0], worst[1], worst_far[0], worst_far[1], avgerr);
    printf("/* dielectric_tables.h — generated by tools/ggx_tables.c; do not edit: regenerate with\n"
           " *     ninja -C build tools/ggx_tables && ./build/tools/ggx_tables dielectric > plugins/materials/dielectric_tables.h\n"
           " * di_e[side][k][j][i] (flat) = E(mu, alpha_j, eta_k), the energy albedo (reflection + transmission x\n"
           " * eta^2) of the single-scattering rough dielectric for wo outside (side 0, relative index eta_k) and\n"
           " * inside (side 1, 1 / eta_k); eta_k = 1 + 3 x_k^2, x_k = k / (DI_TAB_NETA - 1); alpha_j = max(r_j^2,\n"
           " * DI_ALPHA_MIN), r_j = j / (DI_TAB_NR - 1); mu at u_i = i / (DI_TAB_NMU - 1) on the row's own axis\n"
           " * (dielectric_tables_axis.h: di_u_of_mu). Largest errors of the plugin's interpolation at 1000\n"
           " * random points: %.1e outside, %.1e inside (%.1e, %.1e at mu >= 0.1 and\n"
           " * eta >= 1.1; the largest are at grazing mu with eta near 1); quadrature %.1e. Included by\n"
           " * plugins/materials/dielectric.c only. */\n"
           "#ifndef MURK_DIELECTRIC_TABLES_H\n#define MURK_DIELECTRIC_TABLES_H\n\n"
           "#define DI_TAB_NMU %d\n#define DI_TAB_NR %d\n#define DI_TAB_NETA %d\n#define DI_ALPHA_MIN %.0ef\n\n",
           worst[0], worst[1], worst_far[0], worst_far[1], qerr, DI_TAB_NMU, DI_TAB_NR, DI_TAB_NETA, DI_ALPHA_MIN);
    printf("/* BEGIN GENERATED TABLES */\n");
    print_floats("di_e", "2 * DI_TAB_NETA * DI_TAB_NR * DI_TAB_NMU", flat, n);
    printf("/* END GENERATED TABLES */\n\n#endif\n");
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "dielectric"))
        return dielectric_main();
    if (argc != 1) {
        fprintf(stderr, "usage: ggx_tables [dielectric]   (writes the header to stdout)\n");
        return 2;
    }
    return ggx_main();
}
