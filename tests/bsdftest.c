/* bsdftest.c — see bsdftest.h. The sphere quadrature and the chi-square test are core/lab/check/sphere.c,
 * the same code `murk check` runs on any material. */
#include "bsdftest.h"

#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* ---- Sphere cells and quadrature: core/lab/check/sphere.c (shared with `murk check`) ---------------------- */
double bt_integrate_cell(bt_fn fn, void *ctx, const bt_grid *g, int it, int ip, double tol, double *err)
{
    return murk_sph_integrate_cell(fn, ctx, g, it, ip, tol, err);
}

double bt_integrate_sphere(bt_fn fn, void *ctx, const bt_grid *g, double tol, double *err)
{
    return murk_sph_integrate(fn, ctx, g, tol, err);
}

int bt_cell_of(const bt_grid *g, murk_vec3 w) { return murk_sph_cell_of(g, w); }

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
    double p = murk_chi2_test(obs, expd, nb + 1, 5.0, &dof);
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
