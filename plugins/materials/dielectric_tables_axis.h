/* dielectric_tables_axis.h — the axes of dielectric_tables.h, shared by the generator that writes the
 * tables (tools/ggx_tables.c) and the plugin that reads them (plugins/materials/dielectric.c), so that
 * both place E's nodes in the same directions and average the same interpolant.
 *
 * Row (side, eta, alpha) of E(mu) is tabulated at u_i = i / (DI_TAB_NMU - 1) on an axis that follows
 * E's shape. With v(m, a) = (w + m) / 2, w = m (1 + a) / (m + a) — half the nodes spread evenly, half
 * crowded near m = 0 into E's dip of width ~a there:
 *   outside (side 0)  u = v(mu, alpha);
 *   inside (side 1)   u = v(mu / mc, alpha) / 2 below the critical cosine mc = sqrt(1 - 1 / eta^2) (total
 *                     internal reflection) and u = 1/2 + (mu - mc) / (2 (1 - mc)) above it: E has a kink
 *                     at mc, which sits on the node u = 1/2 (DI_TAB_NMU is odd) in every row, so blending
 *                     the rows of two indices moves the kink instead of blurring it.
 * A row's interpolant is linear in u between nodes — linear in v, or in mu above mc — so its average
 * (integral of E 2 mu dmu over [0, 1]) has a closed form. Needs <math.h>. */
#ifndef MURK_DIELECTRIC_TABLES_AXIS_H
#define MURK_DIELECTRIC_TABLES_AXIS_H

/* the cosine of the critical angle inside a body of relative index eta (0 for eta <= 1) */
static inline double di_mucrit(double eta) { return sqrt(fmax(0.0, 1.0 - 1.0 / (eta * eta))); }
static inline double di_v(double m, double a) { return 0.5 * (m * (1.0 + a) / (m + a) + m); }
/* its inverse: m^2 + m (1 + 2 a - 2 v) - 2 v a = 0 */
static inline double di_m_of_v(double v, double a)
{
    double b = 1.0 + 2.0 * a - 2.0 * v, q = sqrt(b * b + 8.0 * v * a);
    return fmin(1.0, b > 0.0 ? 4.0 * v * a / (b + q) : 0.5 * (q - b)); /* without cancellation */
}

static inline double di_u_of_mu(int side, double mu, double a, double mc)
{
    if (!side)
        return di_v(mu, a);
    if (mu < mc)
        return 0.5 * di_v(mu / mc, a);
    return mc < 1.0 ? 0.5 + 0.5 * (mu - mc) / (1.0 - mc) : 1.0;
}

static inline double di_mu_of_u(int side, double u, double a, double mc)
{
    if (side && u >= 0.5)
        return fmin(1.0, mc + (2.0 * u - 1.0) * (1.0 - mc));
    double m = di_m_of_v(side ? 2.0 * u : u, a);
    return side ? m * mc : m;
}

/* integral of v(m, a) 2 m dm: (1 + a) (m^2 / 2 - a m + a^2 log(m + a)) + m^3 / 3 */
static inline double di_P(double m, double a)
{
    return (1.0 + a) * (0.5 * m * m - a * m + a * a * log(m + a)) + m * m * m / 3.0;
}

/* The exact average of a row's interpolant times 2 mu over mu in [0, 1] (n nodes) */
static inline double di_row_avg(const double *row, int n, int side, double a, double mc)
{
    double sum = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        double u0 = i / (double)(n - 1), u1 = (i + 1) / (double)(n - 1);
        double m0 = di_mu_of_u(side, u0, a, mc), m1 = di_mu_of_u(side, u1, a, mc);
        if (!(m1 > m0))
            continue;
        if (side && u0 >= 0.5) { /* E = A + B mu */
            double B = (row[i + 1] - row[i]) / (m1 - m0), A = row[i] - B * m0;
            sum += A * (m1 * m1 - m0 * m0) + B * (2.0 / 3.0) * (m1 * m1 * m1 - m0 * m0 * m0);
        } else { /* E = A + B v(x), mu = s x (s = mc inside, 1 outside) */
            double sc = side ? mc : 1.0, x0 = m0 / sc, x1 = m1 / sc, v0 = di_v(x0, a), v1 = di_v(x1, a);
            double B = (row[i + 1] - row[i]) / (v1 - v0), A = row[i] - B * v0;
            sum += sc * sc * (A * (x1 * x1 - x0 * x0) + B * (di_P(x1, a) - di_P(x0, a)));
        }
    }
    return sum;
}

#endif
