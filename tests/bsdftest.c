/* bsdftest.c — see bsdftest.h */
#include "bsdftest.h"

#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BT_PI 3.14159265358979323846

/* ---- Fake host ----------------------------------------------------------------------------------- */
static void *host_alloc(size_t n) { return calloc(1, n ? n : 1); }
static void host_free(void *p) { free(p); }
static void host_log(int level, const char *fmt, ...) MURK_PRINTF(2, 3);
static long warnings;
long bt_warnings(void) { return warnings; }
static void host_log(int level, const char *fmt, ...)
{
    va_list ap;
    if (level == MURK_LOG_WARN)
        warnings++;
    va_start(ap, fmt);
    fprintf(stderr, "[plugin %s] ", level == MURK_LOG_WARN ? "warning" : "info");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}
static void host_tex_eval(const murk_texture *tex, const murk_hit *hit, float out[3])
{
    (void)tex;
    (void)hit;
    (void)out;
    fprintf(stderr, "bsdftest: tex_eval called, but the fake host has no textures\n");
    abort();
}

const murk_host *bt_host(void)
{
    static murk_host h;
    if (!h.size) {
        h.size = (uint32_t)sizeof h;
        h.abi_major = MURK_ABI_MAJOR;
        h.abi_minor = MURK_ABI_MINOR;
        h.alloc = host_alloc;
        h.free = host_free;
        h.log = host_log;
        h.tex_eval = host_tex_eval;
    }
    return &h;
}

const murk_hit *bt_hit(void)
{
    static murk_hit hit = {1.0f, {0, 0, 0}, {0, 0, 1}, {0, 0, 1}, 0.5f, 0.5f, NULL, NULL, NULL, {{0, 0, 0}}, -1, 0, 0};
    return &hit;
}

/* ---- Loading and creating ----------------------------------------------------------------------- */
static int choice_index(const char *choices, const char *s)
{
    if (!choices || !s)
        return 0;
    size_t n = strlen(s);
    int idx = 0;
    for (const char *p = choices;; idx++) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && strncmp(p, s, n) == 0)
            return idx;
        if (!bar)
            return 0;
        p = bar + 1;
    }
}

bt_mat *bt_create(const char *rel, const bt_set *sets, int nsets)
{
    const char *path = build_path(rel);
    void *dl = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!dl)
        fail_msg("dlopen %s: %s", path, dlerror());
    const murk_abi *abi = dlsym(dl, MURK_PLUGIN_ABI_SYMBOL);
    if (!abi)
        fail_msg("%s: no %s symbol", path, MURK_PLUGIN_ABI_SYMBOL);
    if (abi->major != MURK_ABI_MAJOR || abi->minor > MURK_ABI_MINOR)
        fail_msg("%s: ABI %u.%u, host has %d.%d", path, abi->major, abi->minor, MURK_ABI_MAJOR, MURK_ABI_MINOR);
    void *sym = dlsym(dl, MURK_PLUGIN_ENTRY_SYMBOL);
    if (!sym)
        fail_msg("%s: no %s symbol", path, MURK_PLUGIN_ENTRY_SYMBOL);
    const murk_plugin_desc *(*entry)(void);
    memcpy(&entry, &sym, sizeof entry); /* POSIX: object pointer -> function pointer */
    const murk_plugin_desc *d = entry();
    if (!d)
        fail_msg("%s: entry returned NULL", path);
    if (d->struct_size != sizeof(murk_plugin_desc))
        fail_msg("%s: descriptor struct_size %u, expected %zu", path, d->struct_size, sizeof(murk_plugin_desc));
    if (d->kind != MURK_KIND_MATERIAL)
        fail_msg("%s: kind %u is not a material", path, d->kind);
    /* name == basename without .so */
    const char *base = strrchr(rel, '/');
    base = base ? base + 1 : rel;
    size_t blen = strlen(base);
    if (blen > 3 && strcmp(base + blen - 3, ".so") == 0)
        blen -= 3;
    if (!d->name || strlen(d->name) != blen || strncmp(d->name, base, blen) != 0)
        fail_msg("%s: descriptor name '%s' is not the file's basename", path, d->name ? d->name : "(null)");
    const murk_material_vt *vt = d->vtable;
    if (!vt || vt->size != sizeof(murk_material_vt) || !vt->create || !vt->destroy || !vt->eval || !vt->pdf ||
        !vt->sample)
        fail_msg("%s: bad material vtable", path);
    if (d->nparams && !d->params)
        fail_msg("%s: nparams %u but no params", path, d->nparams);

    murk_value *vals = calloc(d->nparams ? d->nparams : 1, sizeof *vals);
    for (uint32_t i = 0; i < d->nparams; i++) {
        const murk_param *p = &d->params[i];
        if (!p->name || !p->doc)
            fail_msg("%s: parameter %u lacks a name or doc", path, i);
        int ncomp = p->type == MURK_PARAM_RGB ? 3 : 1;
        if (p->type == MURK_PARAM_FLOAT || p->type == MURK_PARAM_INT || p->type == MURK_PARAM_RGB)
            for (int c = 0; c < ncomp; c++)
                if (p->def[c] < p->min || p->def[c] > p->max)
                    fail_msg("%s: default of '%s' outside [%g, %g]", path, p->name, p->min, p->max);
        memcpy(vals[i].f, p->def, sizeof vals[i].f);
        vals[i].s = p->def_str;
        vals[i].choice = p->type == MURK_PARAM_ENUM ? choice_index(p->choices, p->def_str) : 0;
    }
    for (int k = 0; k < nsets; k++) {
        uint32_t i = 0;
        while (i < d->nparams && strcmp(d->params[i].name, sets[k].name) != 0)
            i++;
        if (i == d->nparams)
            fail_msg("%s: no parameter '%s'", path, sets[k].name);
        const murk_param *p = &d->params[i];
        if (p->type != MURK_PARAM_FLOAT && p->type != MURK_PARAM_RGB && p->type != MURK_PARAM_INT &&
            p->type != MURK_PARAM_BOOL)
            fail_msg("%s: bsdftest cannot override '%s' (type %u)", path, p->name, p->type);
        int ncomp = p->type == MURK_PARAM_RGB ? 3 : 1;
        for (int c = 0; c < ncomp; c++)
            if (sets[k].v[c] < p->min || sets[k].v[c] > p->max)
                fail_msg("%s: override of '%s' outside [%g, %g]", path, p->name, p->min, p->max);
        vals[i].set = 1;
        for (int c = 0; c < 3; c++)
            vals[i].f[c] = sets[k].v[ncomp == 3 ? c : 0];
    }

    bt_mat *m = calloc(1, sizeof *m);
    m->dl = dl;
    m->desc = d;
    m->vt = vt;
    m->vals = vals;
    char err[512] = "";
    if (vt->create(bt_host(), vals, &m->self, err, sizeof err) != 0)
        fail_msg("%s: create failed: %s", path, err);
    return m;
}

void bt_destroy(bt_mat *m)
{
    if (!m)
        return;
    m->vt->destroy(m->self);
    free(m->vals);
    dlclose(m->dl);
    free(m);
}

murk_vec3 bt_dir(double theta, double phi)
{
    return murk_v3((float)(sin(theta) * cos(phi)), (float)(sin(theta) * sin(phi)), (float)cos(theta));
}

/* ---- Sphere cells ---------------------------------------------------------------------------------- */
typedef struct frame { double t[3], b[3], n[3]; double warp; } frame;

static void grid_frame(const bt_grid *g, frame *f)
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

int bt_cell_of(const bt_grid *g, murk_vec3 w)
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
        phi += 2.0 * BT_PI;
    int ip = (int)(phi / (2.0 * BT_PI) * g->nphi);
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

#define BT_REL_TOL 1e-6 /* float pdfs carry ~1e-7 relative noise */

typedef struct cellctx {
    const frame *fr;
    bt_fn fn;
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
    return gk_global(inner_f, c, c->x0, c->x1, c->itol, BT_REL_TOL, 48, err);
}

double bt_integrate_cell(bt_fn fn, void *ctx, const bt_grid *g, int it, int ip, double tol, double *err)
{
    frame fr;
    grid_frame(g, &fr);
    double p0 = 2.0 * BT_PI * ip / g->nphi, p1 = 2.0 * BT_PI * (ip + 1) / g->nphi;
    cellctx c = {&fr, fn, ctx, 0.0, (double)it / g->ntheta, (double)(it + 1) / g->ntheta, 0.1 * tol / (p1 - p0)};
    double e = 0.0;
    double r = gk_global(outer_f, &c, p0, p1, tol, BT_REL_TOL, 32, &e);
    if (err)
        *err = e;
    return r;
}

double bt_integrate_sphere(bt_fn fn, void *ctx, const bt_grid *g, double tol, double *err)
{
    double sum = 0.0, esum = 0.0;
    for (int it = 0; it < g->ntheta; it++)
        for (int ip = 0; ip < g->nphi; ip++) {
            double e;
            sum += bt_integrate_cell(fn, ctx, g, it, ip, tol, &e);
            esum += e;
        }
    if (err)
        *err = esum;
    return sum;
}

/* ---- Chi-square ------------------------------------------------------------------------------------ */
double bt_mat_pdf(void *mat, murk_vec3 wo, murk_vec3 wi) { return bt_pdf(mat, wo, wi); }

typedef struct pdfctx { bt_pdf_fn fn; void *ctx; murk_vec3 wo; } pdfctx;
static double pdf_at(void *vc, murk_vec3 w)
{
    const pdfctx *c = vc;
    return c->fn(c->ctx, c->wo, w);
}

static double rel_diff(double a, double b)
{
    double m = fmax(fabs(a), fabs(b));
    return m > 0.0 ? fabs(a - b) / m : 0.0;
}

double bt_chi2(const char *label, const bt_mat *sampler, bt_pdf_fn pdf_fn, void *pdf_ctx, murk_vec3 wo, long n,
               uint64_t seed, const bt_grid *g, bt_chi2_result *res)
{
    int nb = g->ntheta * g->nphi;
    double *obs = calloc((size_t)nb + 1, sizeof *obs), *expd = calloc((size_t)nb + 1, sizeof *expd);
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x6273646674657374ull, 1);
    long valid = 0, mismatch = 0;
    double maxrel = 0.0;
    for (long k = 0; k < n; k++) {
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_bsdf_sample s;
        if (!bt_sample(sampler, wo, u, &s)) {
            obs[nb] += 1.0;
            continue;
        }
        valid++;
        double len = murk_length(s.wi);
        int bad = !isfinite(s.wi.x) || !isfinite(s.wi.y) || !isfinite(s.wi.z) || fabs(len - 1.0) > 1e-4 ||
                  !(s.pdf > 0.0f) || !isfinite(s.pdf) || !murk_rgb_finite(s.f);
        if (!bad) {
            float p = bt_pdf(sampler, wo, s.wi);
            murk_rgb f = bt_eval(sampler, wo, s.wi);
            double r = rel_diff(p, s.pdf);
            double fm = fmax(1e-30, murk_rgb_max(f));
            for (int c = 0; c < 3; c++)
                r = fmax(r, fabs((double)f.c[c] - s.f.c[c]) / fm);
            maxrel = fmax(maxrel, r);
            bad = r > 1e-3;
        }
        if (bad) {
            mismatch++;
            continue;
        }
        obs[bt_cell_of(g, s.wi)] += 1.0;
    }
    pdfctx pc = {pdf_fn ? pdf_fn : bt_mat_pdf, pdf_fn ? pdf_ctx : (void *)sampler, wo};
    double total = 0.0, terr = 0.0, tol = 0.02 / (double)n; /* a fiftieth of a sample per cell */
    for (int it = 0; it < g->ntheta; it++)
        for (int ip = 0; ip < g->nphi; ip++) {
            double e;
            double v = bt_integrate_cell(pdf_at, &pc, g, it, ip, tol, &e);
            expd[it * g->nphi + ip] = v * (double)n;
            total += v;
            terr += e;
        }
    expd[nb] = fmax(0.0, 1.0 - total) * (double)n;
    int dof = 0;
    double p = chi2_test(obs, expd, nb + 1, 5.0, &dof);
    fprintf(stderr, "  chi2 %-34s p = %-10.4g dof %4d  valid %.5f  int pdf %.7f (+-%.1e)  mismatch %ld\n",
            label ? label : "", p, dof, (double)valid / (double)n, total, terr, mismatch);
    if (res) {
        res->p = p;
        res->dof = dof;
        res->n = n;
        res->valid = valid;
        res->pdf_integral = total;
        res->pdf_err = terr;
        res->mismatch = mismatch;
        res->max_rel_mismatch = maxrel;
    }
    free(obs);
    free(expd);
    return p;
}

/* ---- Directional albedo ---------------------------------------------------------------------------- */
void bt_albedo_is(const bt_mat *m, murk_vec3 wo, long n, uint64_t seed, double mean[3], double sigma[3])
{
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x616c6265646f6973ull, 2);
    double s1[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    for (long k = 0; k < n; k++) {
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_bsdf_sample s;
        if (!bt_sample(m, wo, u, &s) || !(s.pdf > 0.0f))
            continue;
        for (int c = 0; c < 3; c++) {
            double w = (double)s.f.c[c] * fmax(0.0, (double)s.wi.z) / (double)s.pdf;
            s1[c] += w;
            s2[c] += w * w;
        }
    }
    for (int c = 0; c < 3; c++) {
        double mu = s1[c] / (double)n;
        double var = fmax(0.0, s2[c] / (double)n - mu * mu) * (double)n / (double)(n > 1 ? n - 1 : 1);
        mean[c] = mu;
        sigma[c] = sqrt(var / (double)n);
    }
}

typedef struct albctx { const bt_mat *m; murk_vec3 wo; int ch; } albctx;
static double alb_at(void *vc, murk_vec3 w)
{
    const albctx *c = vc;
    if (!(w.z > 0.0f))
        return 0.0;
    return (double)bt_eval(c->m, c->wo, w).c[c->ch] * (double)w.z;
}

double bt_albedo_quad(const bt_mat *m, murk_vec3 wo, int channel, const bt_grid *g, double tol, double *err)
{
    albctx c = {m, wo, channel};
    return bt_integrate_sphere(alb_at, &c, g, tol, err);
}
