/* sphere.c — numerical integration over the sphere of directions and Pearson's chi-square test, for
 * `murk check` and the BSDF tests (tests/bsdftest.c wraps these): see sphere.h. */
#include "lab/check/sphere.h"

#include <math.h>
#include <stdlib.h>

#define SPH_PI 3.14159265358979323846

/* ---- Sphere cells ---------------------------------------------------------------------------------- */
typedef struct frame { double t[3], b[3], n[3]; double warp; } frame;

static void grid_frame(const murk_sph_grid *g, frame *f)
{
    double n[3] = {g->pole.x, g->pole.y, g->pole.z};
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(l > 0.0)) {
        n[0] = n[1] = 0.0;
        n[2] = l = 1.0;
    }
    for (int k = 0; k < 3; k++)
        f->n[k] = n[k] / l;
    /* Duff et al. 2017 */
    double sign = copysign(1.0, f->n[2]), a = -1.0 / (sign + f->n[2]), bb = f->n[0] * f->n[1] * a;
    f->t[0] = 1.0 + sign * f->n[0] * f->n[0] * a;
    f->t[1] = sign * bb;
    f->t[2] = -sign * f->n[0];
    f->b[0] = bb;
    f->b[1] = sign + f->n[1] * f->n[1] * a;
    f->b[2] = -f->n[1];
    f->warp = g->warp >= 1.0 ? g->warp : 1.0;
}

/* direction for cell coordinates (x, phi) */
static murk_vec3 frame_dir(const frame *f, double x, double phi)
{
    double u = pow(x, f->warp);
    double c = 1.0 - 2.0 * u, s = 2.0 * sqrt(fmax(0.0, u * (1.0 - u)));
    double lx = s * cos(phi), ly = s * sin(phi);
    return murk_v3((float)(f->t[0] * lx + f->b[0] * ly + f->n[0] * c), (float)(f->t[1] * lx + f->b[1] * ly + f->n[1] * c),
                   (float)(f->t[2] * lx + f->b[2] * ly + f->n[2] * c));
}

int murk_sph_cell_of(const murk_sph_grid *g, murk_vec3 w)
{
    frame f;
    grid_frame(g, &f);
    double v[3] = {w.x, w.y, w.z};
    double lx = v[0] * f.t[0] + v[1] * f.t[1] + v[2] * f.t[2];
    double ly = v[0] * f.b[0] + v[1] * f.b[1] + v[2] * f.b[2];
    double lz = v[0] * f.n[0] + v[1] * f.n[1] + v[2] * f.n[2];
    double l = sqrt(lx * lx + ly * ly + lz * lz);
    lx /= l;
    ly /= l;
    lz /= l;
    double one_minus_c = lz >= 0.0 ? (lx * lx + ly * ly) / (1.0 + lz) : 1.0 - lz;
    double u = fmin(1.0, fmax(0.0, 0.5 * one_minus_c));
    double x = pow(u, 1.0 / f.warp);
    int it = (int)(x * g->ntheta);
    if (it >= g->ntheta)
        it = g->ntheta - 1;
    double phi = atan2(ly, lx);
    if (phi < 0.0)
        phi += 2.0 * SPH_PI;
    int ip = (int)(phi / (2.0 * SPH_PI) * g->nphi);
    if (ip >= g->nphi)
        ip = g->nphi - 1;
    if (ip < 0)
        ip = 0;
    return it * g->nphi + ip;
}

/* ---- Adaptive Gauss-Kronrod ------------------------------------------------------------------------ */
static const double gk_x[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                               0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                               0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                               0.207784955007898467600689403773245, 0.0};
static const double gk_wk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double gk_wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

/* f(ctx, x, &err): value at x; adds the value's own error (for nested integrals) to *err. */
typedef double (*f1d)(void *ctx, double x, double *err);

static double gk15(f1d f, void *ctx, double a, double b, double *err, double *inner_err)
{
    double c = 0.5 * (a + b), h = 0.5 * (b - a);
    double ie = 0.0;
    double fc = f(ctx, c, &ie);
    double k = fc * gk_wk[7], gs = fc * gk_wg[3], ierr = ie * gk_wk[7];
    for (int i = 0; i < 7; i++) {
        double e1 = 0.0, e2 = 0.0;
        double f1 = f(ctx, c - h * gk_x[i], &e1), f2 = f(ctx, c + h * gk_x[i], &e2);
        k += gk_wk[i] * (f1 + f2);
        ierr += gk_wk[i] * (e1 + e2);
        if (i & 1)
            gs += gk_wg[i >> 1] * (f1 + f2);
    }
    *err = fabs((k - gs) * h);
    *inner_err = ierr * fabs(h);
    return k * h;
}

/* Globally adaptive (QAG-like): bisect the interval with the largest error estimate until the summed
 * estimate is below max(tol, rel |integral|) or `limit` intervals exist. The budget bounds the cost where
 * float noise or a discontinuity (the horizon) keeps the estimate from converging. */
enum { GK_MAXLIM = 64 };
static double gk_global(f1d f, void *ctx, double a, double b, double tol, double rel, int limit, double *err)
{
    double ia[GK_MAXLIM], ib[GK_MAXLIM], ir[GK_MAXLIM], ie[GK_MAXLIM], ii[GK_MAXLIM];
    if (limit > GK_MAXLIM)
        limit = GK_MAXLIM;
    int n = 1;
    ia[0] = a;
    ib[0] = b;
    ir[0] = gk15(f, ctx, a, b, &ie[0], &ii[0]);
    for (;;) {
        double sr = 0.0, se = 0.0;
        int worst = 0;
        for (int k = 0; k < n; k++) {
            sr += ir[k];
            se += ie[k];
            if (ie[k] > ie[worst])
                worst = k;
        }
        if (se <= fmax(tol, rel * fabs(sr)) || n >= limit)
            break;
        double m = 0.5 * (ia[worst] + ib[worst]);
        ia[n] = m;
        ib[n] = ib[worst];
        ir[n] = gk15(f, ctx, m, ib[worst], &ie[n], &ii[n]);
        ib[worst] = m;
        ir[worst] = gk15(f, ctx, ia[worst], m, &ie[worst], &ii[worst]);
        n++;
    }
    double sr = 0.0;
    for (int k = 0; k < n; k++) {
        sr += ir[k];
        *err += ie[k] + ii[k];
    }
    return sr;
}

#define SPH_REL_TOL 1e-6 /* float pdfs carry ~1e-7 relative noise */

typedef struct cellctx {
    const frame *fr;
    murk_sph_fn fn;
    void *ctx;
    double phi;           /* inner: fixed phi */
    double x0, x1, itol;  /* inner range and tolerance */
} cellctx;

static double inner_f(void *vc, double x, double *err)
{
    (void)err;
    const cellctx *c = vc;
    double w = c->fr->warp;
    double jac = 2.0 * w * (w == 1.0 ? 1.0 : pow(x, w - 1.0)); /* |d cos theta' / dx| */
    if (jac == 0.0)
        return 0.0;
    return c->fn(c->ctx, frame_dir(c->fr, x, c->phi)) * jac;
}

static double outer_f(void *vc, double phi, double *err)
{
    cellctx *c = vc;
    c->phi = phi;
    return gk_global(inner_f, c, c->x0, c->x1, c->itol, SPH_REL_TOL, 48, err);
}

double murk_sph_integrate_cell(murk_sph_fn fn, void *ctx, const murk_sph_grid *g, int it, int ip, double tol, double *err)
{
    frame fr;
    grid_frame(g, &fr);
    double p0 = 2.0 * SPH_PI * ip / g->nphi, p1 = 2.0 * SPH_PI * (ip + 1) / g->nphi;
    cellctx c = {&fr, fn, ctx, 0.0, (double)it / g->ntheta, (double)(it + 1) / g->ntheta, 0.1 * tol / (p1 - p0)};
    double e = 0.0;
    double r = gk_global(outer_f, &c, p0, p1, tol, SPH_REL_TOL, 32, &e);
    if (err)
        *err = e;
    return r;
}

double murk_sph_integrate(murk_sph_fn fn, void *ctx, const murk_sph_grid *g, double tol, double *err)
{
    double sum = 0.0, esum = 0.0;
    for (int it = 0; it < g->ntheta; it++)
        for (int ip = 0; ip < g->nphi; ip++) {
            double e;
            sum += murk_sph_integrate_cell(fn, ctx, g, it, ip, tol, &e);
            esum += e;
        }
    if (err)
        *err = esum;
    return sum;
}

/* ---- Chi-square ---------------------------------------------------------------------------------- */
static double gamma_q(double a, double x)
{
    if (x <= 0.0)
        return 1.0;
    double gln = lgamma(a);
    if (x < a + 1.0) {
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < 10000; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * 1e-15)
                break;
        }
        return 1.0 - sum * exp(-x + a * log(x) - gln);
    }
    double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < 1e-300)
            d = 1e-300;
        c = b + an / c;
        if (fabs(c) < 1e-300)
            c = 1e-300;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1.0) < 1e-15)
            break;
    }
    return exp(-x + a * log(x) - gln) * h;
}

typedef struct { double obs, exp; } bin;
static int cmp_bin(const void *a, const void *b)
{
    double x = ((const bin *)a)->exp, y = ((const bin *)b)->exp;
    return (x > y) - (x < y);
}

double murk_chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out)
{
    bin *b = malloc(sizeof *b * (size_t)nbins);
    for (int i = 0; i < nbins; i++) {
        b[i].obs = observed[i];
        b[i].exp = expected[i];
    }
    qsort(b, (size_t)nbins, sizeof *b, cmp_bin);
    double chsq = 0.0, pool_obs = 0.0, pool_exp = 0.0;
    int cells = 0;
    for (int i = 0; i < nbins; i++) {
        if (b[i].exp == 0.0) {
            if (b[i].obs > 0.0) { /* a sample where the pdf says none can fall */
                free(b);
                if (dof_out)
                    *dof_out = 0;
                return 0.0;
            }
            continue;
        }
        pool_obs += b[i].obs;
        pool_exp += b[i].exp;
        if (pool_exp >= min_expected) {
            double d = pool_obs - pool_exp;
            chsq += d * d / pool_exp;
            cells++;
            pool_obs = pool_exp = 0.0;
        }
    }
    if (pool_exp > 0.0) { /* leftover low-expectation mass joins the last cell */
        double d = pool_obs - pool_exp;
        chsq += d * d / (pool_exp > 0 ? pool_exp : 1.0);
        cells++;
    }
    free(b);
    int dof = cells - 1;
    if (dof_out)
        *dof_out = dof;
    if (dof < 1)
        return 1.0;
    return gamma_q(dof / 2.0, chsq / 2.0);
}

