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

static double gen_M(double mu, double alpha, int n, const double *x, const double *w)
{
    const double pi = 3.14159265358979323846;
    double ox = sqrt(fmax(0.0, 1.0 - mu * mu)), oz = mu;
    double sx = alpha * ox, sz = oz, l = sqrt(sx * sx + sz * sz);
    sx /= l;
    sz /= l;
    double sum = 0.0;
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
            double t = 1.0 - c;
            sum += w[i] * w[j] * t * t * t * t * t;
        }
    }
    return sum;
}

enum { GEN_N = GGX_TAB_N, GEN_Q = 128, GEN_Q2 = 64 };
static double gen_xq[GEN_Q], gen_wq[GEN_Q];

static double gen_alpha(double r) { return fmax(r * r, (double)GGX_ALPHA_MIN); }
static double gen_true(double t, double r) { return gen_M(t * t, gen_alpha(r), GEN_Q, gen_xq, gen_wq); }
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

int main(void)
{
    static double T[GEN_N][GEN_N], cellm[GEN_N - 1][GEN_N - 1];
    double x2[GEN_Q2], w2[GEN_Q2];
    gen_gauss_legendre(GEN_Q, gen_xq, gen_wq);
    gen_gauss_legendre(GEN_Q2, x2, w2);
    double qerr = 0.0;
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double t = i / (double)(GEN_N - 1), r = j / (double)(GEN_N - 1);
            T[j][i] = gen_true(t, r);
            qerr = fmax(qerr, fabs(T[j][i] - gen_M(t * t, gen_alpha(r), GEN_Q2, x2, w2)));
        }
    double maxdef = 0.0, maxmargin = 0.0;
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++) {
            double def = 0.0;
            for (int b = 0; b < 6; b++)
                for (int a = 0; a < 6; a++) {
                    double t = (i + (a + 0.5) / 6.0) / (GEN_N - 1), r = (j + (b + 0.5) / 6.0) / (GEN_N - 1);
                    def = fmax(def, gen_true(t, r) - gen_interp(T, t, r));
                }
            maxdef = fmax(maxdef, def);
            cellm[j][i] = 1.25 * def + qerr + 1e-6;
        }
    static double S[GEN_N][GEN_N];
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double m = 0.0;
            for (int b = j - 1; b <= j; b++)
                for (int a = i - 1; a <= i; a++)
                    if (a >= 0 && b >= 0 && a < GEN_N - 1 && b < GEN_N - 1)
                        m = fmax(m, cellm[b][a]);
            maxmargin = fmax(maxmargin, m);
            float v = (float)fmin(1.0, T[j][i] + m);
            if ((double)v < fmin(1.0, T[j][i] + m))
                v = nextafterf(v, 2.0f);
            S[j][i] = v;
        }
    /* independent verification */
    double worst = -1.0;
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++)
            for (int b = 0; b < 5; b++)
                for (int a = 0; a < 5; a++) {
                    double t = (i + (a + 0.37) / 5.0) / (GEN_N - 1), r = (j + (b + 0.61) / 5.0) / (GEN_N - 1);
                    worst = fmax(worst, gen_true(t, r) - gen_interp(S, t, r));
                }
    fprintf(stderr, "quadrature error bound %.3g, largest interpolation shortfall %.3g, largest margin %.3g, "
                    "verification: largest shortfall %.3g (must be <= 0)\n", qerr, maxdef, maxmargin, worst);
    if (worst > 0.0)
        return 1;
    printf("/* ggx_tables.h — generated by tools/ggx_tables.c; do not edit: regenerate with\n"
           " *     ninja -C build tools/ggx_tables && ./build/tools/ggx_tables > plugins/materials/ggx_tables.h\n"
           " * ggx_m[j][i] = M(mu = t_i^2, alpha = max(r_j^2, GGX_ALPHA_MIN)) + safety margin, t_i = i / (N - 1),\n"
           " * r_j = j / (N - 1); ggx_mavg[j] = exact integral of the (piecewise linear in mu) interpolant times\n"
           " * 2 mu over [0, 1]. Included by plugins/materials/ggx.c only. */\n"
           "#ifndef MURK_GGX_TABLES_H\n#define MURK_GGX_TABLES_H\n\n"
           "#define GGX_TAB_N %d\n#define GGX_ALPHA_MIN %.0ef\n\n", GGX_TAB_N, (double)GGX_ALPHA_MIN);
    printf("/* BEGIN GENERATED TABLES */\n");
    printf("/* generated by tools/ggx_tables.c: quadrature error %.2g, largest margin %.2g */\n", qerr,
           maxmargin);
    printf("static const float ggx_m[GGX_TAB_N][GGX_TAB_N] = {\n");
    for (int j = 0; j < GEN_N; j++) {
        printf("    {");
        for (int i = 0; i < GEN_N; i++)
            printf("%s%.8ef", i == 0 ? "" : (i % 6 == 0 ? ",\n     " : ", "), (double)(float)S[j][i]);
        printf("},\n");
    }
    printf("};\nstatic const float ggx_mavg[GGX_TAB_N] = {\n");
    for (int j = 0; j < GEN_N; j++) {
        /* exact integral of M 2 mu dmu = M 4 t^3 dt, M linear in t on each interval */
        double sum = 0.0;
        for (int i = 0; i < GEN_N - 1; i++) {
            double t0 = i / (double)(GEN_N - 1), t1 = (i + 1) / (double)(GEN_N - 1);
            double B = (S[j][i + 1] - S[j][i]) / (t1 - t0), A = S[j][i] - B * t0;
            sum += A * (pow(t1, 4) - pow(t0, 4)) + B * 0.8 * (pow(t1, 5) - pow(t0, 5));
        }
        printf("%s%.8ef,", j % 6 == 0 ? (j ? "\n    " : "    ") : " ", (double)(float)sum);
    }
    printf("\n};\n/* END GENERATED TABLES */\n\n#endif\n");
    return 0;
}
