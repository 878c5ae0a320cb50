/* check.c — `murk check PLUGIN`: the statistical tests murk runs on its own plugins, for any plugin of
 * any kind, so that plugin authors can test theirs the same way (docs/plugins.md, "Testing").
 *
 * Every plugin is exercised through the core exactly as a render uses it: a small scene naming it is
 * written to a temporary folder and loaded with murk_scene_load (so the plugin comes through the normal
 * search path, schema checks and create()), and its methods are called with the real host table.
 * All random numbers come from fixed seeds (--seed changes them): the same plugin gives the same figures.
 *
 * Parameter sets (sweep.c): the defaults, two sets with every numeric range at 25 % / 75 % (RGB channels
 * spread apart), and sweep points: each parameter alone at both ends of its range and at every enum and
 * bool value (albedo 1, g = +-0.99); or only the values given with --set KEY=VALUE. `--quick` runs fewer
 * samples at a sweep point.
 *
 * material   for each parameter set, at wo = 10, 45 and 80 degrees (--quick: a sweep point's chi2 at 45):
 *              chi2       sample() against pdf(): the sphere cut into 16 x 32 cells refined around the
 *                         mirror direction, expected counts from adaptive quadrature of pdf() over each
 *                         cell, one more cell for "no sample or a delta lobe"; fails below p = CK_P (1e-6).
 *                         Also fails if sample()'s f / pdf disagree with eval() / pdf() (relative 1e-3)
 *                         for more than 1e-4 of the samples, or pdf() integrates to more than 1.
 *              furnace    the directional albedo E(wo) = mean of f |cos| / pdf must not exceed 1 by
 *                         more than CK_Z (5) standard errors (energy conservation).
 *              reciprocity f(wo, wi) = f(wi, wo) for 4096 random pairs above the surface (relative 1e-3).
 *            A material that transmits (some sample with wi.z < 0 at 45 degrees from either side) also gets:
 *              eta        the indices s->eta reports (at most 3, those from inside the inverses of those
 *                         from outside);
 *              chi2, furnace from inside (the hit's n against ng), the furnace counting transmitted light as
 *                         energy (x each channel's eta^2);
 *              reciprocity across the surface: f(a, b) / eta_a^2 = f(b, a) / eta_b^2 for a outside, b
 *                         inside, each seen from its own side: per channel the ratio a constant on 4096
 *                         pairs (relative 1e-3), and that constant the square of an index s->eta reports;
 *                         and f(wo, wi) = f(wi, wo) for pairs both inside.
 * medium     (a tracker) on a ray through a homogeneous slab (density 0.5, closed-form optical depth
 *            0.75) and through a checker grid (8^3 voxels alternating 0.2 / 1.4, a ray along voxel
 *            centres: optical depth = voxel size x the sum of the row), each with grey
 *            (sigma_a 0.3, sigma_s 0.9) and chromatic (sigma_a 0.2 1 3, sigma_s 1 0.5 0.1) coefficients:
 *              T          mean of transmittance()                        = exp(-sigma_t D)     per channel
 *              pass       mean of sample()'s weight / mean(pdf_ratio) on pass-through = exp(-sigma_t D)
 *              scatter    the same on scattering events      = (sigma_s / sigma_t)(1 - exp(-sigma_t D))
 *              bin k      (slab) scattering events in each quarter of the segment, closed form
 *            each within CK_Z (5) standard errors (from the sample variance) of the closed form; then the
 *            cross-tracker invariance z-test: every figure against the built-in `delta` tracker on the
 *            same ray, |difference| <= CK_Z combined standard errors; and the variance lines (tail()):
 *            each figure's sample variance at most CK_VAR_FACTOR times the analog estimator's, a heavy
 *            tail (the largest sample's share of the sum of squares) warned of. For each parameter set. A
 *            tracker may refuse chromatic media in create() (reported, not a failure); grey media it must take.
 * transmittance (an estimator) under the built-in `delta` tracker, through murk_medium_transmittance() as a
 *            shadow ray takes it, on the slab and the checker above and a linear ramp (4 x 4 x 16 voxels
 *            0.2 + 1.1 z on [0,1]^3, a slanted ray through z = 0 and z = 1: optical depth 0.75 / d.z), each
 *            grey and chromatic:
 *              T          mean of the estimates = exp(-sigma_t D) per channel, within CK_Z standard errors
 *              finite     every estimate finite
 *              >= 0       every channel of every estimate non-negative, unless the plugin's description
 *                         says its estimates may be negative (the word "negative": murk/transmittance.h)
 *              variance   as for trackers, for each parameter set (check_estimator_tails)
 *            An estimator biased by design (its description says "BIASED", as murk/transmittance.h asks)
 *            has its T figures printed and not judged (SKIP).
 * phase      (a phase function, through the host's medium services as integrators call it) for the default
 *            parameters, the 25 % / 75 % sets and --set's, wo fixed, N sampled directions (at a sweep
 *            point, whose lobe may be narrower than the quadrature resolves, those without quadrature:
 *            each sample against eval(), reciprocity, the sampled mean cosine):
 *              chi2       sample() against eval(): the sphere cut into 16 x 32 cells around the forward
 *                         direction, refined towards it as the mean cosine says (a peak of width ~1 - g spans
 *                         several cells), expected counts by adaptive quadrature of eval() over each cell;
 *                         fails below p = CK_P (1e-6), or if sample()'s pdf or value disagree with eval() (relative
 *                         1e-3) for more than 1e-4 of the samples;
 *              norm       the quadrature of eval() over the sphere is 1 within 1e-3;
 *              reciprocity eval(a, b) = eval(b, a) for 4096 random pairs (relative 1e-4);
 *              mean cos   if the plugin gives mean_cosine(): quadrature of eval() cos theta equals it within 1e-4,
 *                         and the sampled directions' mean cosine within CK_Z standard errors.
 * integrator escaped camera rays return the background (an empty scene, exactly), and a furnace: the
 *            camera inside a closed box of inward-facing quads with albedo 0.5 and emission 0.5, where
 *            the radiance is 0.5 / (1 - 0.5) = 1 everywhere; the image mean must be 1 within CK_Z standard
 *            errors (from the pixel variance). The same box filled with a non-absorbing medium (tracker
 *            `spectral_mis`) must still give 1, whether the integrator handles media or ignores them.
 *
 * Each check was seen to fail against a broken plugin (docs/plugins.md lists which).
 *
 * The statistical bounds are CK_Z = 5 standard errors (two-sided normal tail 5.7e-7 per channel) and
 * chi-square p >= CK_P = 1e-6: murk's test suite runs `murk check --quick` on every shipped plugin and
 * keeps its family-wise false-alarm rate (tests/README.md); the summary line counts the statistical
 * decisions and the sum of their false-alarm probabilities. */
#include "lab/check/sphere.h"
#include "lab/check/sweep.h"
#include "media/density.h"
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "render/host.h"
#include "scene/scene.h"
#include "util/runtime.h"
#include "util/util.h"
#include "murk/lab.h"
#include "murk/murk.h"
#include "murk/phase.h"
#include "murk/transmittance.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define CK_PI 3.14159265358979323846
#define CK_Z 5.0     /* the z bound of every mean */
#define CK_P 1e-6    /* the chi-square's smallest p */
#define CK_ALPHA_Z 5.733e-7 /* 2 (1 - Phi(CK_Z)) */

typedef struct ck {
    uint64_t seed;
    int quick;
    const char *const *assign; /* --set KEY=VALUE: the one parameter set to check (sweep.h) */
    int nassign;
    int fails, passes, skips, warns; /* warns: WARN lines, a figure worth a look that fails no bound */
    long nstat;                      /* statistical decisions made */
    double alpha;                    /* the sum of their false-alarm probabilities */
    char tmp[512];
    char files[32][600]; /* written into tmp, removed at the end */
    int nfiles;
} ck;

/* One line: ok 1 PASS, 0 FAIL, -1 SKIP, 2 WARN (passes, with a figure worth a look). */
static void report(ck *c, int ok, const char *fmt, ...) MURK_PRINTF(3, 4);
static void report(ck *c, int ok, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("  %s ", ok == 2 ? "WARN" : ok > 0 ? "PASS" : ok == 0 ? "FAIL" : "SKIP");
    vprintf(fmt, ap);
    putchar('\n');
    va_end(ap);
    if (ok == 2)
        c->warns++;
    else if (ok > 0)
        c->passes++;
    else if (ok == 0)
        c->fails++;
    else
        c->skips++;
    fflush(stdout);
}

/* Counts n statistical decisions of false-alarm probability a each. */
static void stat_decisions(ck *c, long n, double a)
{
    c->nstat += n;
    c->alpha += (double)n * a;
}

/* ---- scenes in a temporary folder ---------------------------------------------------------------- */

static const char *tmp_file(ck *c, const char *name)
{
    for (int i = 0; i < c->nfiles; i++)
        if (!strcmp(strrchr(c->files[i], '/') + 1, name))
            return c->files[i];
    if (c->nfiles == (int)(sizeof c->files / sizeof c->files[0]))
        return NULL;
    char *p = c->files[c->nfiles++];
    snprintf(p, sizeof c->files[0], "%s/%s", c->tmp, name);
    return p;
}

static murk_scene *load_text(ck *c, const char *name, const char *text, char *err, size_t errlen)
{
    const char *path = tmp_file(c, name);
    FILE *f = path ? fopen(path, "w") : NULL;
    if (!f) {
        snprintf(err, errlen, "cannot write %s", path ? path : name);
        return NULL;
    }
    fputs(text, f);
    fclose(f);
    return murk_scene_load(path, NULL, 0, err, errlen);
}

/* ---- materials ----------------------------------------------------------------------------------- */

typedef struct mat_ref { const murk_material *m; murk_hit hit; } mat_ref;

static double rel_diff(double a, double b)
{
    double m = fmax(fabs(a), fabs(b));
    return m > 0.0 ? fabs(a - b) / m : 0.0;
}

typedef struct pdf_ctx { const mat_ref *r; murk_vec3 wo; } pdf_ctx;
static double pdf_at(void *vc, murk_vec3 w)
{
    const pdf_ctx *p = vc;
    return p->r->m->vt->pdf(p->r->m->self, &p->r->hit, p->wo, w);
}

static void check_chi2(ck *c, const mat_ref *r, murk_vec3 wo, const char *label)
{
    const murk_material *m = r->m;
    long n = c->quick ? 50000 : 200000;
    murk_sph_grid g = {16, 32, murk_v3(-wo.x, -wo.y, wo.z), 2.0};
    int nb = g.ntheta * g.nphi;
    double *obs = calloc((size_t)nb + 1, sizeof *obs), *expd = calloc((size_t)nb + 1, sizeof *expd);
    if (!obs || !expd) {
        free(obs);
        free(expd);
        report(c, 0, "chi2 %s: out of memory", label);
        return;
    }
    murk_rng rng;
    murk_rng_seed(&rng, c->seed, 0x6368693273717561ull, 1);
    long mismatch = 0, valid = 0, nonfinite = 0;
    double maxrel = 0.0;
    for (long k = 0; k < n; k++) {
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_bsdf_sample s;
        memset(&s, 0, sizeof s);
        s.eta = 1.0f; /* as the integrators set it */
        if (!m->vt->sample(m->self, &r->hit, wo, u, &s) || s.delta) {
            obs[nb] += 1.0; /* no sample, or a delta lobe (which pdf() does not describe) */
            continue;
        }
        valid++;
        int inf = !isfinite(s.wi.x) || !isfinite(s.wi.y) || !isfinite(s.wi.z) || !isfinite(s.pdf) || !murk_rgb_finite(s.f);
        int bad = inf || fabs(murk_length(s.wi) - 1.0) > 1e-4 || !(s.pdf > 0.0f);
        if (!bad) {
            float p = m->vt->pdf(m->self, &r->hit, wo, s.wi);
            murk_rgb f = m->vt->eval(m->self, &r->hit, wo, s.wi);
            inf = !isfinite(p) || !murk_rgb_finite(f);
            double d = rel_diff(p, s.pdf), fm = fmax(1e-30, murk_rgb_max(f));
            for (int ch = 0; ch < 3; ch++)
                d = fmax(d, fabs((double)f.c[ch] - s.f.c[ch]) / fm);
            maxrel = inf ? maxrel : fmax(maxrel, d);
            bad = inf || d > 1e-3;
        }
        nonfinite += inf;
        if (bad) {
            mismatch++;
            continue;
        }
        obs[murk_sph_cell_of(&g, s.wi)] += 1.0;
    }
    pdf_ctx pc = {r, wo};
    double total = 0.0, terr = 0.0, tol = 0.02 / (double)n; /* a fiftieth of a sample per cell */
    for (int it = 0; it < g.ntheta; it++)
        for (int ip = 0; ip < g.nphi; ip++) {
            double e = 0.0, v = murk_sph_integrate_cell(pdf_at, &pc, &g, it, ip, tol, &e);
            expd[it * g.nphi + ip] = v * (double)n;
            total += v;
            terr += e;
        }
    expd[nb] = fmax(0.0, 1.0 - total) * (double)n;
    int dof = 0;
    double p = murk_chi2_test(obs, expd, nb + 1, 5.0, &dof);
    stat_decisions(c, 1, CK_P);
    int ok = p >= CK_P && mismatch <= n / 10000 && total <= 1.0 + 1e-3 + terr && nonfinite == 0 && isfinite(total);
    report(c, ok, "chi2        %-28s p = %-9.4g dof %3d  sampled %.4f  int pdf %.5f  f/pdf mismatches %ld (max rel %.1e)%s",
           label, p, dof, (double)valid / (double)n, total, mismatch, maxrel,
           nonfinite ? "; NaN or infinite f, pdf or wi in sample()/eval()/pdf()" : "");
    if (nonfinite)
        printf("       %ld of %ld samples NaN or infinite\n", nonfinite, valid);
    free(obs);
    free(expd);
}

/* How the furnace's bound reads: within 4 standard errors, or exactly where an albedo has no variance. */
static const char *exact_note(const double se[3], const double mean[3])
{
    int n = 0;
    for (int ch = 0; ch < 3; ch++)
        n += se[ch] <= 1e-6 * mean[ch];
    return n == 3 ? "zero variance: <= 1 exactly" : n ? "<= 1 + 4 standard errors, exactly where zero variance"
                                                        : "<= 1 + 4 standard errors";
}

/* eta_ch (NULL: reflection only): each channel's relative index (inside / outside), for the energy of
 * transmitted samples; inside: wo is inside. */
static void check_albedo(ck *c, const mat_ref *r, murk_vec3 wo, const double *eta_ch, int inside, const char *label)
{
    long n = c->quick ? 50000 : 200000;
    murk_rng rng;
    murk_rng_seed(&rng, c->seed, 0x616c6265646f6973ull, 2);
    double s1[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    long nonfinite = 0;
    for (long k = 0; k < n; k++) {
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_bsdf_sample s;
        memset(&s, 0, sizeof s);
        s.eta = 1.0f;
        if (!r->m->vt->sample(r->m->self, &r->hit, wo, u, &s) || !(s.pdf > 0.0f))
            continue;
        for (int ch = 0; ch < 3; ch++) {
            /* energy, not radiance: transmitted radiance is (eta_wo / eta_wi)^2 times the energy (each
             * channel's own index: with dispersion s->eta is only the sampled channel's) */
            double e2 = 1.0;
            if (s.wi.z < 0.0f) {
                double e = eta_ch && eta_ch[ch] > 0.0 ? (inside ? 1.0 / eta_ch[ch] : eta_ch[ch]) : s.eta;
                e2 = e * e;
            }
            double w = (double)s.f.c[ch] * fabs((double)s.wi.z) / (double)s.pdf * e2;
            if (!isfinite(w)) { /* counted, named and left out: one NaN would hide every other figure */
                nonfinite += ch == 0 || isfinite((double)s.f.c[0] * fabs((double)s.wi.z) / (double)s.pdf * e2);
                continue;
            }
            s1[ch] += w;
            s2[ch] += w * w;
        }
    }
    int ok = nonfinite == 0;
    double mean[3], se[3];
    char line[256];
    size_t len = 0;
    for (int ch = 0; ch < 3; ch++) {
        mean[ch] = s1[ch] / (double)n;
        se[ch] = sqrt(fmax(0.0, s2[ch] / (double)n - mean[ch] * mean[ch]) / (double)(n - 1));
        int exact = se[ch] <= 1e-6 * mean[ch]; /* zero variance (a Lambertian at wo anything): no z */
        if (!exact)
            stat_decisions(c, 1, CK_ALPHA_Z / 2.0); /* one-sided */
        if (!(mean[ch] <= 1.0 + (exact ? 1e-5 : CK_Z * se[ch] + 1e-4)))
            ok = 0;
        len += (size_t)snprintf(line + len, sizeof line - len, exact ? " %.4f" : " %.4f+-%.4f", mean[ch], se[ch]);
    }
    report(c, ok, "furnace     %-28s energy albedo%s (%s)%s", label, line, exact_note(se, mean),
           nonfinite ? "; NaN or infinite weights f |cos| / pdf, left out" : "");
    if (nonfinite)
        printf("       %ld of %ld samples NaN or infinite\n", nonfinite, n);
}

static murk_vec3 dir_of(double theta, double phi)
{
    return murk_v3((float)(sin(theta) * cos(phi)), (float)(sin(theta) * sin(phi)), (float)cos(theta));
}

static void check_reciprocity(ck *c, const mat_ref *r, const char *label)
{
    murk_rng rng;
    murk_rng_seed(&rng, c->seed, 0x7265636970726f63ull, 3);
    double worst = 0.0;
    long bad = 0, nonfinite = 0;
    for (int k = 0; k < 4096; k++) {
        /* uniform directions above the surface, kept off the horizon */
        murk_vec3 a = dir_of(acos(0.02 + 0.98 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        murk_vec3 b = dir_of(acos(0.02 + 0.98 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        murk_rgb fab = r->m->vt->eval(r->m->self, &r->hit, a, b), fba = r->m->vt->eval(r->m->self, &r->hit, b, a);
        double scale = fmax(1e-30, fmax(murk_rgb_max(fab), murk_rgb_max(fba)));
        for (int ch = 0; ch < 3; ch++) {
            double d = fabs((double)fab.c[ch] - fba.c[ch]) / scale;
            if (!isfinite(fab.c[ch]) || !isfinite(fba.c[ch])) {
                nonfinite++;
                continue;
            }
            worst = fmax(worst, d);
            bad += d > 1e-3;
        }
    }
    report(c, bad == 0 && nonfinite == 0, "reciprocity %-28s f(wo,wi) = f(wi,wo) on 4096 pairs: max rel diff %.2e%s", label,
           worst, nonfinite ? "; eval() NaN or infinite" : "");
    if (nonfinite)
        printf("       %ld of %d values NaN or infinite\n", nonfinite, 3 * 2 * 4096);
}

/* Transmitting materials: the relative indices sample() reports (s->eta = eta_wi / eta_wo on transmitted
 * samples, murk/material.h), from 20000 samples at wo = 45 degrees on each side. Returns the number of
 * distinct indices seen from outside (into eta[], at most 3: one per channel), 0 if the material does
 * not transmit. Reports one line: every index seen from inside must be the inverse of one seen outside. */
#define CK_MAX_ETA 3
static int learn_eta(ck *c, const mat_ref *out, const mat_ref *in, const char *label, double eta[CK_MAX_ETA])
{
    double seen[2][8];
    int n[2] = {0, 0}, over = 0;
    long ntrans = 0;
    for (int side = 0; side < 2; side++) {
        const mat_ref *r = side ? in : out;
        murk_rng rng;
        murk_rng_seed(&rng, c->seed, 0x657461657461ull, 5u + (uint64_t)side);
        murk_vec3 wo = dir_of(CK_PI / 4.0, 0.3);
        for (int k = 0; k < 20000; k++) {
            float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
            murk_bsdf_sample s;
            memset(&s, 0, sizeof s);
            s.eta = 1.0f;
            if (!r->m->vt->sample(r->m->self, &r->hit, wo, u, &s) || !(s.wi.z < 0.0f))
                continue;
            ntrans++;
            int i = 0;
            while (i < n[side] && !(fabs(seen[side][i] - s.eta) <= 1e-5 * seen[side][i]))
                i++;
            if (i == n[side]) {
                if (n[side] < 8)
                    seen[side][n[side]++] = s.eta;
                else
                    over = 1;
            }
        }
    }
    if (!ntrans)
        return 0;
    int ok = !over && n[0] <= CK_MAX_ETA && n[1] <= CK_MAX_ETA;
    char line[256] = "";
    size_t k = 0;
    for (int side = 0; side < 2; side++) {
        k += (size_t)snprintf(line + k, sizeof line - k, "%s%s", side ? "; inside" : " outside", n[side] ? "" : " none");
        for (int i = 0; i < n[side] && k < sizeof line; i++) {
            k += (size_t)snprintf(line + k, sizeof line - k, " %.5g", seen[side][i]);
            if (side) { /* the inverse of one seen from outside */
                int match = 0;
                for (int j = 0; j < n[0]; j++)
                    match |= fabs(seen[1][i] * seen[0][j] - 1.0) <= 1e-4;
                ok &= match;
            }
        }
    }
    for (int i = 0; i < CK_MAX_ETA; i++)
        eta[i] = i < n[0] ? seen[0][i] : 0.0;
    report(c, ok, "eta         %-28s s->eta of transmitted samples:%s (inside: inverses of outside)", label, line);
    return n[0] > 0 ? n[0] : 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The reciprocity that holds across a refracting surface (murk/material.h): for a outside and b inside,
 * eval(a, b) / eta_a^2 = eval(b, a) / eta_b^2, each seen from its own side (the frame flipped to wo's
 * side: both mirrored in z, the hit saying inside). Per channel, the ratio eval(b, a) / eval(a, b) must
 * be one constant over all pairs (its median is taken), and that constant the square of an index sample()
 * reports (eta[]); with dispersion each channel has its own. Also plain reciprocity among directions
 * inside. */
static void check_reciprocity_tr(ck *c, const mat_ref *out, const mat_ref *in, const double eta[CK_MAX_ETA], const char *label,
                                 double eta_ch[3])
{
    enum { NP = 4096 };
    murk_vec3 *pa = malloc(NP * sizeof *pa), *pb = malloc(NP * sizeof *pb);
    double *q = malloc(NP * sizeof *q);
    if (!pa || !pb || !q) {
        free(pa), free(pb), free(q);
        report(c, 0, "reciprocity %-28s out of memory", label);
        return;
    }
    murk_rng rng;
    murk_rng_seed(&rng, c->seed, 0x7472616e736d6974ull, 6);
    double worst_in = 0.0;
    long bad_in = 0;
    for (int k = 0; k < NP; k++) {
        pa[k] = dir_of(acos(0.02 + 0.98 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        pb[k] = dir_of(acos(0.02 + 0.98 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        murk_rgb g = in->m->vt->eval(in->m->self, &in->hit, pa[k], pb[k]), h = in->m->vt->eval(in->m->self, &in->hit, pb[k], pa[k]);
        for (int ch = 0; ch < 3; ch++) {
            double m = fmax(fabs(g.c[ch]), fabs(h.c[ch])), d = m > 0.0 ? fabs(g.c[ch] - h.c[ch]) / m : 0.0;
            if (!isfinite(g.c[ch]) || !isfinite(h.c[ch]))
                d = INFINITY;
            worst_in = fmax(worst_in, d);
            bad_in += d > 1e-3;
        }
    }
    int ok = 1;
    double worst = 0.0;
    char line[256] = "";
    size_t len = 0;
    for (int ch = 0; ch < 3; ch++) {
        int nq = 0;
        eta_ch[ch] = 0.0;
        for (int pass = 0; pass < 2; pass++) {
            double e2 = 0.0;
            if (pass) { /* the constant: the median ratio */
                if (!nq)
                    break;
                qsort(q, (size_t)nq, sizeof *q, cmp_double);
                e2 = q[nq / 2];
                int match = 0;
                for (int i = 0; i < CK_MAX_ETA; i++)
                    match |= eta[i] > 0.0 && fabs(e2 / (eta[i] * eta[i]) - 1.0) <= 1e-3;
                ok &= match;
                eta_ch[ch] = match ? sqrt(e2) : 0.0; /* the channel's index, for the energy check */
                len += (size_t)snprintf(line + len, sizeof line - len, " %.5g", sqrt(e2));
            }
            for (int k = 0; k < NP; k++) {
                murk_vec3 a = pa[k], b = pb[k], bb = murk_v3(b.x, b.y, -b.z), am = murk_v3(a.x, a.y, -a.z);
                double x = out->m->vt->eval(out->m->self, &out->hit, a, bb).c[ch];
                double y = in->m->vt->eval(in->m->self, &in->hit, b, am).c[ch];
                if (!isfinite(x) || !isfinite(y)) {
                    ok = 0;
                    worst = INFINITY;
                    continue;
                }
                if (!pass) {
                    if (x > 0.0 && y > 0.0)
                        q[nq++] = y / x;
                    else if (x != 0.0 || y != 0.0) { /* one way only */
                        ok = 0;
                        worst = INFINITY;
                    }
                    continue;
                }
                double m = fmax(fabs(x), fabs(y / e2)), d = m > 0.0 ? fabs(x - y / e2) / m : 0.0;
                worst = fmax(worst, d);
                ok &= d <= 1e-3;
            }
        }
        if (!nq)
            len += (size_t)snprintf(line + len, sizeof line - len, " -");
    }
    len += (size_t)snprintf(line + len, sizeof line - len, " (s->eta:");
    for (int i = 0; i < CK_MAX_ETA && eta[i] > 0.0 && len < sizeof line; i++)
        len += (size_t)snprintf(line + len, sizeof line - len, " %.5g", eta[i]);
    if (len < sizeof line)
        snprintf(line + len, sizeof line - len, ")");
    report(c, ok, "reciprocity %-28s transmission f(a,b)/eta_a^2 = f(b,a)/eta_b^2 on 4096 pairs: max rel diff %.2e, eta per channel%s",
           label, worst, line);
    report(c, bad_in == 0, "reciprocity %-28s inside f(wo,wi) = f(wi,wo) on 4096 pairs: max rel diff %.2e", label, worst_in);
    free(pa);
    free(pb);
    free(q);
}

/* The parameter sets to check plugin d with (sweep.h), into sets; their count, or 0 after a FAIL line. */
static int param_sets(ck *c, const murk_plugin_desc *d, ck_set *sets)
{
    char err[1024];
    int n = ck_param_sets(d, c->assign, c->nassign, sets, CK_MAX_SETS, err, sizeof err);
    if (n < 0) {
        report(c, 0, "parameters  %s", err);
        return 0;
    }
    printf("  %d parameter set%s: %s\n", n, n == 1 ? "" : "s",
           c->nassign ? "the --set values" : "the defaults, every range at 25 % and 75 %, each parameter at its ends "
                                             "and every enum and bool value");
    if (err[0])
        report(c, 2, "parameters  %s", err);
    return n;
}

static void check_material(ck *c, const murk_plugin_desc *d)
{
    static const double thetas[3] = {10.0, 45.0, 80.0};
    static ck_set sets[CK_MAX_SETS];
    int nsets = param_sets(c, d, sets);
    for (int set = 0; set < nsets; set++) {
        char text[4096], err[1024], label[64];
        snprintf(text, sizeof text, "murk: 1\nmaterials:\n  m: { type: %s%.1023s }\nshapes: []\n", d->name, sets[set].keys);
        murk_scene *s = load_text(c, "material.yaml", text, err, sizeof err);
        if (!s) {
            report(c, 0, "create      set %d, %s: %s", set, sets[set].what, err);
            continue;
        }
        printf("  set %d: %s\n", set, sets[set].what);
        mat_ref r, rin;
        memset(&r, 0, sizeof r);
        r.m = &s->materials[0].m;
        r.hit.t = 1.0f;
        r.hit.ng = r.hit.n = murk_v3(0, 0, 1);
        r.hit.u = r.hit.v = 0.5f;
        r.hit.material = r.m;
        r.hit.light = -1;
        rin = r; /* wo inside: the frame is flipped to wo's side, the shape's ng is not */
        rin.hit.ng = murk_v3(0, 0, -1);
        double eta[CK_MAX_ETA] = {0.0, 0.0, 0.0};
        snprintf(label, sizeof label, "set %d", set);
        int transmits = learn_eta(c, &r, &rin, label, eta) > 0;
        double eta_ch[3] = {0.0, 0.0, 0.0};
        check_reciprocity(c, &r, label);
        if (transmits)
            check_reciprocity_tr(c, &r, &rin, eta, label, eta_ch);
        for (int side = 0; side < 1 + transmits; side++)
            for (int w = 0; w < 3; w++) {
                murk_vec3 wo = dir_of(thetas[w] * CK_PI / 180.0, 0.3);
                snprintf(label, sizeof label, "set %d, wo %2.0f deg%s", set, thetas[w], side ? " inside" : "");
                if (sets[set].full || !c->quick || w == 1) /* --quick: a sweep point's chi2 at 45 degrees only */
                    check_chi2(c, side ? &rin : &r, wo, label);
                check_albedo(c, side ? &rin : &r, wo, transmits ? eta_ch : NULL, side, label);
            }
        murk_scene_free(s);
    }
}

/* ---- media (trackers) ---------------------------------------------------------------------------- */

#define NBINS 4

typedef struct acc3 { double s[3], s2[3], mx[3]; } acc3; /* mx: the largest |x| */
typedef struct tstats { long n, nonfinite, outside; acc3 T, pass, scat, bin[NBINS]; } tstats;

static void acc_add(acc3 *a, int ch, double x)
{
    a->s[ch] += x;
    a->s2[ch] += x * x;
    if (fabs(x) > a->mx[ch])
        a->mx[ch] = fabs(x);
}
static double acc_mean(const acc3 *a, int ch, long n) { return a->s[ch] / (double)n; }
static double acc_se(const acc3 *a, int ch, long n)
{
    double m = a->s[ch] / (double)n;
    return sqrt(fmax(0.0, a->s2[ch] / (double)n - m * m) / (double)(n - 1));
}

/* n calls of transmittance() and n of sample() on one ray, the hero channel uniform per call, as an
 * integrator calls them (beta = 1). */
static void run_tracker(const murk_medium *m, const murk_ray *ray, long n, uint64_t seed, tstats *st)
{
    memset(st, 0, sizeof *st);
    st->n = n;
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x747261636b6572ull, 4);
    murk_path_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.beta = murk_rgb1(1.0f);
    double width = ((double)ray->tmax - ray->tmin) / NBINS;
    for (long i = 0; i < n; i++) {
        ctx.hero = (int)(murk_rng_float(&rng) * 3.0f);
        murk_rgb T = m->vt->transmittance(m->self, ray, &ctx, &rng);
        ctx.hero = (int)(murk_rng_float(&rng) * 3.0f);
        murk_medium_event ev;
        memset(&ev, 0, sizeof ev);
        m->vt->sample(m->self, ray, &ctx, &rng, &ev);
        double mp = ((double)ev.pdf_ratio.c[0] + ev.pdf_ratio.c[1] + ev.pdf_ratio.c[2]) / 3.0;
        if (!murk_rgb_finite(T) || !murk_rgb_finite(ev.weight) || !murk_rgb_finite(ev.pdf_ratio) || !isfinite(ev.t))
            st->nonfinite++;
        if (ev.scattered && !(ev.t >= ray->tmin && ev.t <= ray->tmax))
            st->outside++;
        int b = ev.scattered ? (int)(((double)ev.t - ray->tmin) / width) : -1;
        if (b >= NBINS)
            b = NBINS - 1;
        for (int ch = 0; ch < 3; ch++) {
            double x = mp > 0.0 && murk_rgb_finite(ev.weight) ? ev.weight.c[ch] / mp : 0.0;
            acc_add(&st->T, ch, murk_rgb_finite(T) ? T.c[ch] : 0.0);
            acc_add(&st->pass, ch, ev.scattered ? 0.0 : x);
            acc_add(&st->scat, ch, ev.scattered ? x : 0.0);
            for (int k = 0; k < NBINS; k++)
                acc_add(&st->bin[k], ch, k == b ? x : 0.0);
        }
    }
}

/* One channel's verdict on an estimate m (standard error se) of e, appended to line: |z| <= CK_Z (a
 * counted decision); or, for an
 * estimate without variance to speak of (se <= 1e-6 |e|: a closed form evaluated in float, such as ratio
 * tracking through a constant density, whose z would only measure rounding), equality up to float
 * rounding (relative 1e-5), said so. 1 if it holds. */
static int judge(ck *c, double m, double se, double e, char *line, size_t n)
{
    double tol = 1e-5 * fabs(e) + 1e-7;
    if (!isfinite(m)) {
        snprintf(line, n, "  %g: NaN or infinite", m);
        return 0;
    }
    if (se <= 1e-6 * fabs(e) || se == 0.0) {
        snprintf(line, n, "  %.5f (%.5f, zero variance, compared exactly: rel diff %.1e)", m, e,
                 fabs(m - e) / fmax(fabs(e), 1e-30));
        return fabs(m - e) <= tol;
    }
    double z = (m - e) / se;
    snprintf(line, n, "  %.5f+-%.5f (%.5f, z %+.1f)", m, se, e, z);
    stat_decisions(c, 1, CK_ALPHA_Z);
    return fabs(z) <= CK_Z;
}

static void figure(ck *c, const char *label, const char *what, const acc3 *a, long n, const double expect[3])
{
    char line[768];
    size_t k = 0;
    int ok = 1;
    for (int ch = 0; ch < 3; ch++) {
        ok &= judge(c, acc_mean(a, ch, n), acc_se(a, ch, n), expect[ch], line + k, sizeof line - k);
        k += strlen(line + k);
    }
    report(c, ok, "%-26s %-8s%s", label, what, line);
}

/* Two estimates of the same figure agree: |z| <= CK_Z on their difference (a counted decision), or, both without variance (as in
 * judge()), equal up to float rounding. */
static void compare(ck *c, const char *label, const char *what, const acc3 *a, long n, const acc3 *b, long nb)
{
    char line[384];
    size_t k = 0;
    int ok = 1;
    for (int ch = 0; ch < 3; ch++) {
        double ma = acc_mean(a, ch, n), mb = acc_mean(b, ch, nb), d = ma - mb;
        double se = hypot(acc_se(a, ch, n), acc_se(b, ch, nb)), scale = fmax(fabs(ma), fabs(mb));
        if (!isfinite(d)) {
            ok = 0;
            k += (size_t)snprintf(line + k, sizeof line - k, "  NaN or infinite");
        } else if (se <= 1e-6 * scale || se == 0.0) {
            ok &= fabs(d) <= 1e-5 * scale + 1e-7;
            k += (size_t)snprintf(line + k, sizeof line - k, "  exact (zero variance): rel diff %.1e",
                                  fabs(d) / fmax(scale, 1e-30));
        } else {
            stat_decisions(c, 1, CK_ALPHA_Z);
            ok &= fabs(d / se) <= CK_Z;
            k += (size_t)snprintf(line + k, sizeof line - k, "  z %+.2f", d / se);
        }
    }
    report(c, ok, "%-26s %-8s vs delta:%s", label, what, line);
}

typedef struct mconfig {
    const char *name;
    int chroma, checker;
} mconfig;

/* The media the trackers (and, under delta, the estimators) are checked on. */
static const mconfig MEDIUM_CFGS[4] = {
    {"slab, grey", 0, 0}, {"slab, chromatic", 1, 0}, {"checker, grey", 0, 1}, {"checker, chromatic", 1, 1}};

static const double GREY_SA[3] = {0.3, 0.3, 0.3}, GREY_SS[3] = {0.9, 0.9, 0.9};
static const double CHROMA_SA[3] = {0.2, 1.0, 3.0}, CHROMA_SS[3] = {1.0, 0.5, 0.1};

#define CHECKER_RES 8
static float checker_value(int x, int y, int z) { return ((x + y + z) & 1) ? 1.4f : 0.2f; }

static int write_checker(ck *c, char *err, size_t errlen)
{
    const char *path = tmp_file(c, "checker.vol");
    if (!path) {
        snprintf(err, errlen, "too many temporary files");
        return -1;
    }
    int res[3] = {CHECKER_RES, CHECKER_RES, CHECKER_RES};
    float v[CHECKER_RES * CHECKER_RES * CHECKER_RES];
    for (int z = 0; z < CHECKER_RES; z++)
        for (int y = 0; y < CHECKER_RES; y++)
            for (int x = 0; x < CHECKER_RES; x++)
                v[(z * CHECKER_RES + y) * CHECKER_RES + x] = checker_value(x, y, z);
    murk_field *f = murk_field_from_voxels(res, murk_v3(0, 0, 0), murk_v3(1, 1, 1), v);
    if (!f) {
        snprintf(err, errlen, "cannot build the checker grid");
        return -1;
    }
    int rc = murk_field_vol_save(path, f, err, errlen);
    murk_field_free(f);
    return rc;
}

static murk_scene *load_medium(ck *c, const char *type, const mconfig *cfg, char *err, size_t errlen)
{
    char text[2048];
    const double *sa = cfg->chroma ? CHROMA_SA : GREY_SA, *ss = cfg->chroma ? CHROMA_SS : GREY_SS;
    snprintf(text, sizeof text,
             "murk: 1\nmedia:\n  m: { type: %s, density: %s, sigma_a: [%g, %g, %g], sigma_s: [%g, %g, %g] }\nshapes: []\n",
             type, cfg->checker ? "{ grid: checker.vol }" : "{ constant: 0.5 }", sa[0], sa[1], sa[2], ss[0], ss[1],
             ss[2]);
    return load_text(c, "medium.yaml", text, err, errlen);
}

/* Calls per configuration: 100000, --quick 20000, and a quarter of that at a --quick sweep point. */
static long sweep_count(const ck *c, const ck_set *set) { return c->quick ? (set->full ? 20000 : 5000) : 100000; }

/* Heavy tails. A tracker or estimator with unbounded weights may be unbiased and pass every mean above
 * (the standard error is taken from the same samples, and a tail that the samples rarely reach inflates
 * neither), yet be useless in a render (a relMSE 10^5 times delta tracking's). Per channel: the sample
 * variance against the analog estimator's mu (1 - mu) (delta tracking's pass and scatter indicators, a
 * track-length transmittance: the variance of a 0/1 estimate of mu, and the most any estimate within
 * [0, 1] can have): above CK_VAR_FACTOR times it FAILs; and the largest sample's share of the sum of
 * squares (about ln(n) / n for a light tail; near 1 when one sample carries the estimate): above
 * CK_TAIL_SHARE it WARNs (spectral tracking's `max` and `average` probabilities, whose weights grow in
 * chromatic media as Kutz et al. 2017 say, do). docs/plugins.md gives the figures of murk's own trackers
 * and estimators against these bounds. */
#define CK_VAR_FACTOR 20.0
#define CK_TAIL_SHARE 0.05
static void tail(ck *c, const char *label, const char *what, const acc3 *a, long n, const double mu[3])
{
    double ratio = 0.0, share = 0.0, big = 0.0;
    for (int ch = 0; ch < 3; ch++) {
        double se = acc_se(a, ch, n), var = se * se * (double)n, ref = fmax(mu[ch] * (1.0 - mu[ch]), 1e-6);
        ratio = fmax(ratio, var / ref);
        share = fmax(share, a->s2[ch] > 0.0 ? a->mx[ch] * a->mx[ch] / a->s2[ch] : 0.0);
        big = fmax(big, a->mx[ch]);
    }
    int ok = !(ratio <= CK_VAR_FACTOR) ? 0 : share <= CK_TAIL_SHARE ? 1 : 2;
    report(c, ok, "%-26s %-8s variance %.3g x the analog estimator's mu(1-mu) (<= %g); largest sample %.3g, %.3g of the "
           "sum of squares (%s %g%s)", label, what, ratio, CK_VAR_FACTOR, big, share, share <= CK_TAIL_SHARE ? "<=" : ">",
           CK_TAIL_SHARE, share <= CK_TAIL_SHARE ? "" : ": a heavy tail");
}

/* The closed forms of a configuration: its ray, T, the scattered weight S and each bin's B. */
static void medium_closed_form(const mconfig *cfg, murk_ray *ray, double *D, double T[3], double S[3], double B[NBINS][3])
{
    double Dbin[NBINS + 1];
    if (cfg->checker) { /* along x through the centres of voxel row (y, z) = (3, 3), entering outside the box */
        float yc = (3 + 0.5f) / CHECKER_RES;
        *ray = (murk_ray){murk_v3(-0.25f, yc, yc), murk_v3(1, 0, 0), 0.0f, 1.5f};
        *D = 0.0; /* trilinear between centres, clamped half cells at the ends: h x sum of the row */
        for (int x = 0; x < CHECKER_RES; x++)
            *D += checker_value(x, 3, 3) / (double)CHECKER_RES;
    } else {
        *ray = (murk_ray){murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(0.3f, 0.4f, 1.0f)), 0.0f, 1.5f};
        *D = 0.5 * 1.5;
        for (int b = 0; b <= NBINS; b++)
            Dbin[b] = 0.5 * 1.5 * b / NBINS;
    }
    const double *sa = cfg->chroma ? CHROMA_SA : GREY_SA, *ss = cfg->chroma ? CHROMA_SS : GREY_SS;
    for (int ch = 0; ch < 3; ch++) {
        double st = sa[ch] + ss[ch], alb = ss[ch] / st;
        T[ch] = exp(-st * *D);
        S[ch] = alb * (1.0 - T[ch]);
        for (int b = 0; b < NBINS && !cfg->checker; b++)
            B[b][ch] = alb * (exp(-st * Dbin[b]) - exp(-st * Dbin[b + 1]));
    }
}

/* One configuration of one parameter set; ref: the built-in delta tracker's figures on it (run once per
 * configuration, *have_ref then 1; -1 if there is no delta to compare with). */
static void medium_config(ck *c, const murk_plugin_desc *d, const ck_set *set, int i, tstats *ref, int *have_ref)
{
    const char *keys = set->keys;
    const mconfig *cfg = &MEDIUM_CFGS[i];
    long n = sweep_count(c, set);
    char err[1024], type[1400];
    murk_ray ray;
    double D, T[3], S[3], B[NBINS][3];
    medium_closed_form(cfg, &ray, &D, T, S, B);
    snprintf(type, sizeof type, "%s%s", d->name, keys);
    murk_scene *s = load_medium(c, type, cfg, err, sizeof err);
    if (!s) {
        if (cfg->chroma)
            report(c, -1, "%-26s create() refused chromatic media (allowed): %s", cfg->name, err);
        else
            report(c, 0, "%-26s create() failed on a grey medium: %s", cfg->name, err);
        return;
    }
    printf("  %s: optical depth %.4f, %ld calls each of transmittance() and sample()\n", cfg->name, D, n);
    tstats st;
    run_tracker(&s->media[0].m, &ray, n, c->seed + (uint64_t)i, &st);
    murk_scene_free(s);
    report(c, st.nonfinite == 0 && st.outside == 0, "%-26s finite    %ld results NaN or infinite, %ld events outside the segment",
           cfg->name, st.nonfinite, st.outside);
    figure(c, cfg->name, "T", &st.T, n, T);
    figure(c, cfg->name, "pass", &st.pass, n, T);
    figure(c, cfg->name, "scatter", &st.scat, n, S);
    for (int b = 0; b < NBINS && !cfg->checker; b++) {
        char w[16];
        snprintf(w, sizeof w, "bin %d", b);
        figure(c, cfg->name, w, &st.bin[b], n, B[b]);
    }
    tail(c, cfg->name, "T", &st.T, n, T);
    tail(c, cfg->name, "pass", &st.pass, n, T);
    tail(c, cfg->name, "scatter", &st.scat, n, S);
    /* cross-tracker invariance: the built-in delta tracker on the same ray */
    if (!strcmp(d->name, "delta") || *have_ref < 0)
        return;
    if (!*have_ref) {
        murk_scene *rs = load_medium(c, "delta", cfg, err, sizeof err);
        if (!rs) {
            report(c, -1, "%-26s no built-in delta tracker to compare with: %s", cfg->name, err);
            *have_ref = -1;
            return;
        }
        run_tracker(&rs->media[0].m, &ray, n, c->seed + 1000u + (uint64_t)i, ref);
        murk_scene_free(rs);
        *have_ref = 1;
    }
    compare(c, cfg->name, "T", &st.T, n, &ref->T, ref->n);
    compare(c, cfg->name, "pass", &st.pass, n, &ref->pass, ref->n);
    compare(c, cfg->name, "scatter", &st.scat, n, &ref->scat, ref->n);
}

/* The checker grid written and the parameter sets of d: their count (0 after a FAIL line). */
static int medium_sets(ck *c, const murk_plugin_desc *d, ck_set *sets)
{
    char err[1024];
    if (write_checker(c, err, sizeof err)) {
        report(c, 0, "checker grid: %s", err);
        return 0;
    }
    return param_sets(c, d, sets);
}

static void check_medium(ck *c, const murk_plugin_desc *d)
{
    static ck_set sets[CK_MAX_SETS];
    tstats ref[4];
    int have_ref[4] = {0, 0, 0, 0};
    int nsets = medium_sets(c, d, sets);
    for (int set = 0; set < nsets; set++) {
        printf("  set %d: %s\n", set, sets[set].what);
        for (int i = 0; i < 4; i++)
            medium_config(c, d, &sets[set], i, &ref[i], &have_ref[i]);
    }
}

/* ---- transmittance estimators: heavy tails -------------------------------------------------------- */

/* An estimator (murk/transmittance.h) under the built-in delta tracker, called as a shadow ray calls it
 * (murk_medium_transmittance, a uniform hero, beta 1) n times on each configuration of the trackers'
 * checks, at each parameter set: every estimate finite, and its tail() lines. */
static void check_estimator_tails(ck *c, const murk_plugin_desc *d)
{
    static ck_set sets[CK_MAX_SETS];
    char err[1024];
    int nsets = medium_sets(c, d, sets);
    for (int set = 0; set < nsets; set++) {
        printf("  set %d: %s\n", set, sets[set].what);
        long n = sweep_count(c, &sets[set]);
        for (int i = 0; i < 4; i++) {
            const mconfig *cfg = &MEDIUM_CFGS[i];
            murk_ray ray;
            double D, T[3], S[3], B[NBINS][3];
            medium_closed_form(cfg, &ray, &D, T, S, B);
            char type[1600];
            snprintf(type, sizeof type, "delta, transmittance: { type: %s%.1023s }", d->name, sets[set].keys);
            murk_scene *s = load_medium(c, type, cfg, err, sizeof err);
            if (!s) {
                report(c, 0, "%-26s create() failed: %s", cfg->name, err);
                continue;
            }
            murk_rng rng;
            murk_rng_seed(&rng, c->seed + 200u + (uint64_t)i, 0x7461696c73ull, 8);
            murk_path_ctx ctx;
            memset(&ctx, 0, sizeof ctx);
            ctx.beta = murk_rgb1(1.0f);
            acc3 acc;
            memset(&acc, 0, sizeof acc);
            long nonfinite = 0;
            for (long k = 0; k < n; k++) {
                ctx.hero = (int)(murk_rng_float(&rng) * 3.0f);
                murk_rgb t = murk_medium_transmittance(&s->media[0].m, &ray, &ctx, &rng);
                nonfinite += !murk_rgb_finite(t);
                for (int ch = 0; ch < 3; ch++)
                    acc_add(&acc, ch, murk_rgb_finite(t) ? t.c[ch] : 0.0);
            }
            murk_scene_free(s);
            printf("  %s: optical depth %.4f, %ld estimates\n", cfg->name, D, n);
            report(c, nonfinite == 0, "%-26s finite    %ld estimates NaN or infinite", cfg->name, nonfinite);
            tail(c, cfg->name, "T", &acc, n, T);
        }
    }
}

/* ---- transmittance estimators -------------------------------------------------------------------- */

#define RAMP_NZ 16
static float ramp_value(int z) { return 0.2f + 1.1f * ((float)z + 0.5f) / RAMP_NZ; }

/* 4 x 4 x RAMP_NZ voxels on [0,1]^3, 0.2 + 1.1 z at the voxel centres: trilinear interpolation gives the
 * line exactly between the first and last centres, and the two clamped half cells' errors cancel, so the
 * integral over z in [0, 1] is 0.2 + 1.1 / 2 = 0.75. */
static int write_ramp(ck *c, char *err, size_t errlen)
{
    const char *path = tmp_file(c, "ramp.vol");
    if (!path) {
        snprintf(err, errlen, "too many temporary files");
        return -1;
    }
    int res[3] = {4, 4, RAMP_NZ};
    float v[4 * 4 * RAMP_NZ];
    for (int i = 0; i < 4 * 4 * RAMP_NZ; i++)
        v[i] = ramp_value(i / 16);
    murk_field *f = murk_field_from_voxels(res, murk_v3(0, 0, 0), murk_v3(1, 1, 1), v);
    if (!f) {
        snprintf(err, errlen, "cannot build the ramp grid");
        return -1;
    }
    int rc = murk_field_vol_save(path, f, err, errlen);
    murk_field_free(f);
    return rc;
}

typedef struct tconfig {
    const char *name;
    int chroma, grid; /* grid: 0 the slab, 1 the checker, 2 the ramp */
} tconfig;

/* The config's ray and the density's optical depth along it. */
static double tr_ray(const tconfig *cfg, murk_ray *ray)
{
    if (cfg->grid == 1) { /* as check_medium's checker ray */
        float yc = (3 + 0.5f) / CHECKER_RES;
        *ray = (murk_ray){murk_v3(-0.25f, yc, yc), murk_v3(1, 0, 0), 0.0f, 1.5f};
        double D = 0.0;
        for (int x = 0; x < CHECKER_RES; x++)
            D += checker_value(x, 3, 3) / (double)CHECKER_RES;
        return D;
    }
    if (cfg->grid == 2) { /* from below z = 0 to past z = 1 */
        murk_vec3 d = murk_normalize(murk_v3(0.2f, 0.1f, 1.0f));
        *ray = (murk_ray){murk_v3(0.3f, 0.4f, -0.5f), d, 0.0f, 2.5f};
        return 0.75 / d.z;
    }
    *ray = (murk_ray){murk_v3(0.1f, -0.2f, 0.3f), murk_normalize(murk_v3(0.3f, 0.4f, 1.0f)), 0.0f, 1.5f};
    return 0.5 * 1.5;
}

static murk_scene *load_estimator(ck *c, const char *type, const tconfig *cfg, char *err, size_t errlen)
{
    static const char *const dens[3] = {"{ constant: 0.5 }", "{ grid: checker.vol }", "{ grid: ramp.vol }"};
    char text[2048];
    const double *sa = cfg->chroma ? CHROMA_SA : GREY_SA, *ss = cfg->chroma ? CHROMA_SS : GREY_SS;
    snprintf(text, sizeof text,
             "murk: 1\nmedia:\n  m: { type: delta, transmittance: %s, density: %s, sigma_a: [%g, %g, %g], "
             "sigma_s: [%g, %g, %g] }\nshapes: []\n", type, dens[cfg->grid], sa[0], sa[1], sa[2], ss[0], ss[1], ss[2]);
    return load_text(c, "transmittance.yaml", text, err, errlen);
}

/* n estimates on ray with a uniform hero each, as shadow rays take them (beta = 1). */
static void run_estimator(const murk_medium *m, const murk_ray *ray, long n, uint64_t seed, acc3 *T, long *nonfinite,
                          long *negative)
{
    memset(T, 0, sizeof *T);
    *nonfinite = *negative = 0;
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x7472616e736d6974ull, 7);
    murk_path_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.beta = murk_rgb1(1.0f);
    for (long i = 0; i < n; i++) {
        ctx.hero = (int)(murk_rng_float(&rng) * 3.0f);
        murk_rgb t = murk_medium_transmittance(m, ray, &ctx, &rng);
        int finite = murk_rgb_finite(t);
        *nonfinite += !finite;
        *negative += finite && (t.c[0] < 0.0f || t.c[1] < 0.0f || t.c[2] < 0.0f);
        for (int ch = 0; ch < 3; ch++)
            acc_add(T, ch, finite ? t.c[ch] : 0.0);
    }
}

static void check_transmittance(ck *c, const murk_plugin_desc *d)
{
    static const tconfig cfgs[6] = {{"slab, grey", 0, 0},    {"slab, chromatic", 1, 0}, {"checker, grey", 0, 1},
                                    {"checker, chromatic", 1, 1}, {"ramp, grey", 0, 2}, {"ramp, chromatic", 1, 2}};
    const int biased = d->description && strstr(d->description, "BIASED") != NULL;
    const int may_negative = d->description && strstr(d->description, "negative") != NULL;
    long n = c->quick ? 20000 : 100000;
    char err[1024];
    if (write_checker(c, err, sizeof err) || write_ramp(c, err, sizeof err)) {
        report(c, 0, "grids: %s", err);
        return;
    }
    for (int i = 0; i < 6; i++) {
        const tconfig *cfg = &cfgs[i];
        murk_ray ray;
        double D = tr_ray(cfg, &ray), T[3];
        const double *sa = cfg->chroma ? CHROMA_SA : GREY_SA, *ss = cfg->chroma ? CHROMA_SS : GREY_SS;
        for (int ch = 0; ch < 3; ch++)
            T[ch] = exp(-(sa[ch] + ss[ch]) * D);
        murk_scene *s = load_estimator(c, d->name, cfg, err, sizeof err);
        if (!s) {
            report(c, 0, "%-26s create() failed: %s", cfg->name, err);
            continue;
        }
        printf("  %s: optical depth %.4f, %ld estimates\n", cfg->name, D, n);
        acc3 acc;
        long nonfinite, negative;
        run_estimator(&s->media[0].m, &ray, n, c->seed + 100u + (uint64_t)i, &acc, &nonfinite, &negative);
        murk_scene_free(s);
        report(c, nonfinite == 0, "%-26s finite    %ld non-finite estimates", cfg->name, nonfinite);
        report(c, negative == 0 || may_negative, "%-26s >= 0      %ld estimates with a negative channel%s", cfg->name,
               negative, may_negative ? " (its description allows them)" : "");
        if (!biased) {
            figure(c, cfg->name, "T", &acc, n, T);
            continue;
        }
        report(c, -1, "%-26s T         %.5f %.5f %.5f (closed form %.5f %.5f %.5f): biased by design, not judged",
               cfg->name, acc_mean(&acc, 0, n), acc_mean(&acc, 1, n), acc_mean(&acc, 2, n), T[0], T[1], T[2]);
    }
}

/* ---- integrators --------------------------------------------------------------------------------- */

/* Six inward-facing quads around [-1, 1]^3 (a quad emits and faces along normalize(u x v)). */
static const char FURNACE_WALLS[] =
    "  - { type: quad, center: [1, 0, 0], u: [0, 0, 1], v: [0, 1, 0], material: wall, emission: 0.5%s }\n"
    "  - { type: quad, center: [-1, 0, 0], u: [0, 1, 0], v: [0, 0, 1], material: wall, emission: 0.5%s }\n"
    "  - { type: quad, center: [0, 1, 0], u: [1, 0, 0], v: [0, 0, 1], material: wall, emission: 0.5%s }\n"
    "  - { type: quad, center: [0, -1, 0], u: [0, 0, 1], v: [1, 0, 0], material: wall, emission: 0.5%s }\n"
    "  - { type: quad, center: [0, 0, 1], u: [0, 1, 0], v: [1, 0, 0], material: wall, emission: 0.5%s }\n"
    "  - { type: quad, center: [0, 0, -1], u: [1, 0, 0], v: [0, 1, 0], material: wall, emission: 0.5%s }\n";

/* ---- phase functions ----------------------------------------------------------------------------- */

typedef struct ph_ref { const murk_host *h; const murk_medium *m; murk_vec3 wo; } ph_ref;

static double ph_eval_at(void *vc, murk_vec3 w)
{
    const ph_ref *r = vc;
    return r->h->medium_phase_eval(r->m, r->wo, w);
}

static double ph_cos_at(void *vc, murk_vec3 w)
{
    const ph_ref *r = vc;
    return ph_eval_at(vc, w) * -(double)murk_dot(r->wo, w);
}

/* Draws n directions: cell counts on g (obs may be NULL), the mean cosine and its standard error, and how
 * many samples disagree with eval() (pdf or value, relative 1e-3). */
static long ph_sample(const ph_ref *r, const murk_sph_grid *g, long n, uint64_t seed, double *obs, double *mean,
                      double *se)
{
    murk_rng rng;
    murk_rng_seed(&rng, seed, 0x7068617365ull, 3);
    double s1 = 0.0, s2 = 0.0;
    long bad = 0;
    for (long k = 0; k < n; k++) {
        float u[2] = {murk_rng_float(&rng), murk_rng_float(&rng)}, pdf = 0.0f;
        murk_vec3 wi = murk_v3(0, 0, 0);
        float v = r->h->medium_phase_sample(r->m, r->wo, u, &wi, &pdf);
        float e = r->h->medium_phase_eval(r->m, r->wo, wi);
        if (!(pdf > 0.0f) || !isfinite(v) || fabs(murk_length(wi) - 1.0) > 1e-4 || rel_diff(pdf, e) > 1e-3 ||
            rel_diff(v, e) > 1e-3) {
            bad++;
            continue;
        }
        double mu = -(double)murk_dot(r->wo, wi);
        s1 += mu;
        s2 += mu * mu;
        if (obs)
            obs[murk_sph_cell_of(g, wi)] += 1.0;
    }
    long good = n - bad > 1 ? n - bad : 2;
    *mean = s1 / (double)good;
    *se = sqrt(fmax(0.0, s2 / (double)good - *mean * *mean) / (double)(good - 1));
    return bad;
}

/* eval(a, b) = eval(b, a) for 4096 random pairs (relative 1e-4). */
static void phase_reciprocity(ck *c, const ph_ref *r, const char *label)
{
    murk_rng rng;
    murk_rng_seed(&rng, c->seed, 0x7265636970ull, 4);
    double worst = 0.0;
    for (int k = 0; k < 4096; k++) {
        murk_vec3 a = dir_of(acos(1.0 - 2.0 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        murk_vec3 b = dir_of(acos(1.0 - 2.0 * murk_rng_float(&rng)), 2.0 * CK_PI * murk_rng_float(&rng));
        worst = fmax(worst, rel_diff(r->h->medium_phase_eval(r->m, a, b), r->h->medium_phase_eval(r->m, b, a)));
    }
    report(c, worst <= 1e-4, "reciprocity %-20s max rel difference %.1e over 4096 pairs", label, worst);
}

/* A sweep point (one parameter at a range's end, g = +-0.99 say): its lobe may be narrower than the
 * quadrature behind chi2, norm and the quadrature's mean cosine resolves, so only what needs none: every
 * sample's pdf and value against eval(), reciprocity, and the sampled mean cosine against mean_cosine()
 * within CK_Z standard errors. A sampling routine that breaks near |g| = 1 fails the last. */
static void check_phase_point(ck *c, const murk_medium *m, const char *label)
{
    const murk_phase *ph = murk_media_phase(m);
    ph_ref r = {murk_host_table(), m, murk_normalize(murk_v3(0.3f, -0.5f, 0.8f))};
    long n = c->quick ? 50000 : 200000;
    double mean, se;
    long bad = ph_sample(&r, NULL, n, c->seed, NULL, &mean, &se);
    report(c, bad <= n / 10000, "sampling    %-20s eval/sample mismatches or NaN %ld of %ld", label, bad, n);
    phase_reciprocity(c, &r, label);
    if (!(ph->vt && MURK_HAS(ph->vt->size, murk_phase_vt, mean_cosine) && ph->vt->mean_cosine)) {
        report(c, -1, "mean cos    %-20s no closed form (mean_cosine NULL); sampled %.5f +- %.5f", label, mean, se);
        return;
    }
    double gbar = ph->vt->mean_cosine(ph->self);
    stat_decisions(c, 1, CK_ALPHA_Z);
    report(c, fabs(mean - gbar) <= CK_Z * se + 1e-6, "mean cos    %-20s closed form %.6f, sampled %.6f +- %.6f (z %.1f)",
           label, gbar, mean, se, se > 0.0 ? (mean - gbar) / se : 0.0);
}

static void check_phase_set(ck *c, const murk_medium *m, const char *label)
{
    const murk_phase *ph = murk_media_phase(m);
    ph_ref r = {murk_host_table(), m, murk_normalize(murk_v3(0.3f, -0.5f, 0.8f))};
    long n = c->quick ? 200000 : 1000000;
    int has_mean = ph->vt && MURK_HAS(ph->vt->size, murk_phase_vt, mean_cosine) && ph->vt->mean_cosine;
    double gbar = has_mean ? ph->vt->mean_cosine(ph->self) : 0.0, se;
    if (!has_mean) /* a pilot run for the grid's refinement */
        ph_sample(&r, NULL, 20000, c->seed, NULL, &gbar, &se);
    /* refine towards the higher of the forward and backward peaks: a peak of height P spans about
     * u = (1 - cos) / 2 < 1 / (16 pi P) (HG: P = (1 + g) / (4 pi (1 - g)^2)), put a quarter into the grid */
    double pf = ph_eval_at(&r, murk_neg(r.wo)), pb = ph_eval_at(&r, r.wo), peak = fmax(pf, pb);
    double up = fmin(0.25, fmax(1e-12, 1.0 / (16.0 * CK_PI * fmax(peak, 1e-30))));
    murk_vec3 pole = pf >= pb ? murk_neg(r.wo) : r.wo;
    murk_sph_grid g = {16, 32, pole, fmin(24.0, fmax(1.0, log(up) / log(0.25)))};
    int nb = g.ntheta * g.nphi;
    double *obs = calloc((size_t)nb, sizeof *obs), *expd = calloc((size_t)nb, sizeof *expd);
    if (!obs || !expd) {
        free(obs);
        free(expd);
        report(c, 0, "phase %s: out of memory", label);
        return;
    }
    double mean;
    long bad = ph_sample(&r, &g, n, c->seed, obs, &mean, &se);
    double total = 0.0, terr = 0.0, tol = 0.02 / (double)n;
    for (int it = 0; it < g.ntheta; it++)
        for (int ip = 0; ip < g.nphi; ip++) {
            double e = 0.0, v = murk_sph_integrate_cell(ph_eval_at, &r, &g, it, ip, tol, &e);
            expd[it * g.nphi + ip] = v * (double)n;
            total += v;
            terr += e;
        }
    int dof = 0;
    double p = murk_chi2_test(obs, expd, nb, 5.0, &dof);
    stat_decisions(c, 1, CK_P);
    report(c, p >= CK_P && bad <= n / 10000, "chi2        %-20s p = %-9.4g dof %3d  warp %.2f  eval/sample "
           "mismatches %ld", label, p, dof, g.warp, bad);
    report(c, fabs(total - 1.0) <= 1e-3 + terr, "norm        %-20s int p = %.6f (quadrature error %.1e)", label, total,
           terr);
    free(obs);
    free(expd);
    phase_reciprocity(c, &r, label);
    if (!has_mean) {
        report(c, -1, "mean cos    %-20s no closed form (mean_cosine NULL); sampled %.5f +- %.5f", label, mean, se);
        return;
    }
    double qe = 0.0, q = murk_sph_integrate(ph_cos_at, &r, &g, 1e-3 / (double)nb, &qe);
    stat_decisions(c, 1, CK_ALPHA_Z);
    report(c, fabs(q - gbar) <= 1e-4 + qe && fabs(mean - gbar) <= CK_Z * se + 1e-6,
           "mean cos    %-20s closed form %.6f, quadrature %.6f, sampled %.5f +- %.5f", label, gbar, q, mean, se);
}

static void check_phase(ck *c, const murk_plugin_desc *d)
{
    static ck_set sets[CK_MAX_SETS];
    int nsets = param_sets(c, d, sets);
    for (int set = 0; set < nsets; set++) {
        char text[4096], err[1024], label[64];
        snprintf(text, sizeof text, "murk: 1\nmedia:\n  m: { type: delta, phase: { type: %s%.1023s } }\nshapes: []\n",
                 d->name, sets[set].keys);
        murk_scene *s = load_text(c, "phase.yaml", text, err, sizeof err);
        if (!s) {
            report(c, 0, "create      set %d, %s: %s", set, sets[set].what, err);
            continue;
        }
        printf("  set %d: %s\n", set, sets[set].what);
        snprintf(label, sizeof label, "set %d", set);
        /* the full sets (defaults, 25 % / 75 %, --set) get every check; a sweep point (a range's end, where
         * the lobe may be narrower than the quadrature resolves) those that need no quadrature */
        if (sets[set].full)
            check_phase_set(c, &s->media[0].m, label);
        else
            check_phase_point(c, &s->media[0].m, label);
        murk_scene_free(s);
    }
}

static int render_scene(ck *c, const char *name, const char *text, murk_render_result *res, char *err, size_t errlen)
{
    murk_scene *s = load_text(c, name, text, err, errlen);
    if (!s)
        return -1;
    murk_render_opts o;
    memset(&o, 0, sizeof o);
    memset(res, 0, sizeof *res);
    int rc = murk_render(s, &o, res);
    murk_scene_free(s);
    if (rc) {
        snprintf(err, errlen, "render failed");
        return -1;
    }
    return 0;
}

static void furnace(ck *c, const char *label, const char *text)
{
    char err[1024];
    murk_render_result res;
    if (render_scene(c, "furnace.yaml", text, &res, err, sizeof err)) {
        report(c, strstr(label, "medium") ? -1 : 0, "%-22s %s", label, err);
        return;
    }
    long np = (long)res.width * res.height;
    double mean[3], se[3];
    int ok = res.nonfinite == 0;
    for (int ch = 0; ch < 3; ch++) {
        double s1 = 0.0, s2 = 0.0;
        for (long i = 0; i < np; i++) {
            double v = res.rgb[3 * i + ch];
            s1 += v;
            s2 += v * v;
        }
        mean[ch] = s1 / (double)np;
        se[ch] = sqrt(fmax(0.0, s2 / (double)np - mean[ch] * mean[ch]) / (double)(np - 1));
        stat_decisions(c, 1, CK_ALPHA_Z);
        if (!(fabs(mean[ch] - 1.0) <= CK_Z * se[ch] + 1e-4))
            ok = 0;
    }
    report(c, ok, "%-22s image mean %.4f+-%.4f %.4f+-%.4f %.4f+-%.4f (1; z %+.1f %+.1f %+.1f), %d spp, %llu non-finite", label,
           mean[0], se[0], mean[1], se[1], mean[2], se[2], se[0] > 0 ? (mean[0] - 1) / se[0] : 0.0,
           se[1] > 0 ? (mean[1] - 1) / se[1] : 0.0, se[2] > 0 ? (mean[2] - 1) / se[2] : 0.0, res.spp,
           (unsigned long long)res.nonfinite);
    free(res.rgb);
}

static void integrator_set(ck *c, const char *type)
{
    char text[4096], walls[2048], err[1024];
    int spp = c->quick ? 16 : 64;
    /* 1. escaped camera rays see the background */
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: [8, 8], spp: 4, seed: %llu }\n"
             "camera: { from: [0, 0, 0], at: [0, 0, -1], up: [0, 1, 0], fov: 60 }\n"
             "integrator: { type: %s }\nbackground: [0.25, 0.5, 0.75]\nshapes: []\n",
             (unsigned long long)c->seed, type);
    murk_render_result res;
    if (render_scene(c, "background.yaml", text, &res, err, sizeof err)) {
        report(c, 0, "background             %s", err);
    } else {
        double worst = 0.0;
        static const double bg[3] = {0.25, 0.5, 0.75};
        for (long i = 0; i < (long)res.width * res.height; i++)
            for (int ch = 0; ch < 3; ch++)
                worst = fmax(worst, fabs(res.rgb[3 * i + ch] - bg[ch]) / bg[ch]);
        report(c, worst <= 1e-4, "background             empty scene returns the background: max rel error %.2e", worst);
        free(res.rgb);
    }
    /* 2. the furnace: L = e / (1 - a) = 1 */
    const char *head = "murk: 1\nrender: { resolution: [16, 16], spp: %d, seed: %llu }\n"
                       "camera: { from: [0.1, -0.2, 0.3], at: [0.5, 0.1, -1], up: [0, 1, 0], fov: 90%s }\n"
                       "integrator: { type: %s }\nbackground: [0, 0, 0]\n"
                       "materials: { wall: { type: diffuse, albedo: 0.5 } }\n%sshapes:\n";
    size_t k = (size_t)snprintf(text, sizeof text, head, spp, (unsigned long long)c->seed, "", type, "");
    snprintf(walls, sizeof walls, FURNACE_WALLS, "", "", "", "", "", "");
    snprintf(text + k, sizeof text - k, "%s", walls);
    furnace(c, "furnace", text);
    /* 3. the same furnace filled with a scattering, non-absorbing medium; its tracker spectral_mis reports
     * null-collision probabilities, so every integrator mode (nee_mis: null_scattering too) can run */
    k = (size_t)snprintf(text, sizeof text, head, spp, (unsigned long long)c->seed, ", medium: fog", type,
                         "media: { fog: { type: spectral_mis, density: { constant: 1 }, sigma_a: 0, sigma_s: 0.8, g: 0.3 } }\n");
    const char *ext = ", exterior: fog";
    snprintf(walls, sizeof walls, FURNACE_WALLS, ext, ext, ext, ext, ext, ext);
    snprintf(text + k, sizeof text - k, "%s", walls);
    furnace(c, "furnace with a medium", text);
}

static void check_integrator(ck *c, const murk_plugin_desc *d)
{
    static ck_set sets[CK_MAX_SETS];
    int nsets = param_sets(c, d, sets);
    for (int set = 0; set < nsets; set++) {
        char type[1400];
        printf("  set %d: %s\n", set, sets[set].what);
        snprintf(type, sizeof type, "%s%.1023s", d->name, sets[set].keys);
        integrator_set(c, type);
    }
}

/* ---- command line -------------------------------------------------------------------------------- */

static int usage(const char *msg)
{
    if (msg)
        fprintf(stderr, "murk: %s\n", msg);
    fputs("usage: murk check [--seed S] [--quick] [--set KEY=VALUE]... PLUGIN...   (PLUGIN: a name on the plugin path, or\n"
          "       a path to NAME.so; --set: check one plugin at those parameter values instead of the sweep)\n",
          stderr);
    return 2;
}

/* Puts dir first on MURK_PLUGIN_PATH so that scenes naming the plugin load this very file. */
static void prepend_plugin_path(const char *dir)
{
    const char *old = getenv("MURK_PLUGIN_PATH");
    size_t n = strlen(dir) + (old ? strlen(old) : 0) + 2;
    char *v = malloc(n);
    if (!v)
        return;
    snprintf(v, n, "%s%s%s", dir, old && *old ? ":" : "", old ? old : "");
    setenv("MURK_PLUGIN_PATH", v, 1);
    free(v);
}

static int check_one(ck *c, const char *arg)
{
    char err[1024], name[256];
    const char *slash = strrchr(arg, '/');
    size_t alen = strlen(arg);
    int is_path = slash || (alen > 3 && !strcmp(arg + alen - 3, ".so"));
    murk_registry reg;
    murk_registry_init(&reg);
    if (is_path) {
        char *real = realpath(arg, NULL);
        if (!real) {
            report(c, 0, "%s: %s", arg, strerror(errno));
            printf("%s: FAILED (not checked)\n", arg);
            murk_registry_free(&reg);
            return 1;
        }
        char *base = strrchr(real, '/');
        *base = '\0';
        prepend_plugin_path(real[0] ? real : "/");
        snprintf(name, sizeof name, "%s", base + 1);
        free(real);
        size_t n = strlen(name);
        if (n > 3 && !strcmp(name + n - 3, ".so"))
            name[n - 3] = '\0';
        murk_registry_free(&reg);
        murk_registry_init(&reg); /* again: the search path changed */
    } else {
        snprintf(name, sizeof name, "%s", arg);
    }
    const murk_plugin *p = murk_registry_load(&reg, 0, name, err, sizeof err);
    if (!p) {
        report(c, 0, "%s", err);
        printf("%s: FAILED (not checked)\n", arg);
        murk_registry_free(&reg);
        return 1;
    }
    const murk_plugin_desc *d = p->desc;
    printf("%s (%s, ABI %u.%u, %s)\n", d->name, murk_kind_name((int)d->kind), p->abi.major, p->abi.minor, p->path);
    int fails0 = c->fails;
    if (d->kind == MURK_KIND_MATERIAL)
        check_material(c, d);
    else if (d->kind == MURK_KIND_MEDIUM)
        check_medium(c, d);
    else if (d->kind == MURK_KIND_INTEGRATOR)
        check_integrator(c, d);
    else if (d->kind == MURK_KIND_TRANSMITTANCE)
        check_transmittance(c, d);
    else if (d->kind == MURK_KIND_PHASE)
        check_phase(c, d);
    if (d->kind == MURK_KIND_TRANSMITTANCE)
        check_estimator_tails(c, d);
    printf("%s: %s\n", d->name, c->fails == fails0 ? "all checks passed" : "FAILED");
    murk_registry_free(&reg);
    return c->fails == fails0 ? 0 : 1;
}

/* Reads n bytes (all of them, or what came before the end). */
static size_t read_all(int fd, void *buf, size_t n)
{
    size_t got = 0;
    while (got < n) {
        ssize_t k = read(fd, (char *)buf + got, n - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            break;
        got += (size_t)k;
    }
    return got;
}

/* check_one in a child process, so that a plugin that crashes, aborts or exits ends only its own checks:
 * the child sends its tallies back through a pipe; a child that died first is one FAIL line with the
 * reason, and the summary counts it. */
static int check_isolated(ck *c, const char *arg)
{
    int fd[2];
    fflush(stdout);
    fflush(stderr);
    if (pipe(fd))
        return check_one(c, arg);
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return check_one(c, arg);
    }
    if (pid == 0) {
        close(fd[0]);
        setvbuf(stdout, NULL, _IOLBF, 0); /* every line out before a crash can cut the rest */
        int rc = check_one(c, arg);
        fflush(stdout);
        fflush(stderr);
        _exit(write(fd[1], c, sizeof *c) == (ssize_t)sizeof *c ? rc : 3);
    }
    close(fd[1]);
    ck *back = malloc(sizeof *back);
    size_t got = back ? read_all(fd[0], back, sizeof *back) : 0;
    close(fd[0]);
    int st = 0;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
    if (got == sizeof *back) {
        memcpy(c, back, sizeof *c);
        free(back);
        return WIFEXITED(st) ? WEXITSTATUS(st) != 0 : 1;
    }
    free(back);
    fflush(stdout);
    if (WIFSIGNALED(st))
        report(c, 0, "%s: the checks ended early: the process died of signal %d (%s); the lines above are what ran", arg,
               WTERMSIG(st), strsignal(WTERMSIG(st)));
    else
        report(c, 0, "%s: the checks ended early: exit status %d before they finished (did the plugin call exit()?)", arg,
               WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    printf("%s: FAILED\n", arg);
    return 1;
}

/* Removes the scratch folder and whatever the checks left in it (a child that died leaves its files). */
static void remove_tmp(const char *dir)
{
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        char p[1200];
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            unlink(p);
        }
    }
    if (d)
        closedir(d);
    rmdir(dir);
}

MURK_API int murk_lab_check(int argc, char **argv)
{
    ck *c = calloc(1, sizeof *c);
    if (!c)
        return 1;
    c->seed = 1;
    const char *plugins[64], *assign[64];
    int np = 0;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            c->quick = 1;
        } else if (!strcmp(argv[i], "--set") && i + 1 < argc) {
            if (!strchr(argv[i + 1], '=') || argv[i + 1][0] == '=')
                return free(c), usage("--set needs KEY=VALUE (a parameter of the plugin)");
            if (c->nassign < 64)
                assign[c->nassign++] = argv[i + 1];
            i++;
        } else if (!strcmp(argv[i], "--seed") && i + 1 < argc) {
            char *end;
            c->seed = strtoull(argv[++i], &end, 10);
            if (*end)
                return free(c), usage("--seed needs a whole number");
        } else if (argv[i][0] == '-') {
            return free(c), usage("unknown check option");
        } else if (np < 64) {
            plugins[np++] = argv[i];
        }
    }
    if (!np)
        return free(c), usage("check needs a plugin");
    if (c->nassign && np > 1)
        return free(c), usage("--set gives one plugin's parameters: name one plugin");
    c->assign = assign;
    const char *td = getenv("TMPDIR");
    snprintf(c->tmp, sizeof c->tmp, "%s/murk-check-XXXXXX", td && *td ? td : "/tmp");
    if (!mkdtemp(c->tmp)) {
        fprintf(stderr, "murk: cannot create a temporary folder %s: %s\n", c->tmp, strerror(errno));
        free(c);
        return 1;
    }
    murk_set_quiet(1); /* plugins' info lines would drown the figures; warnings still count */
    int rc = 0;
    for (int i = 0; i < np; i++)
        rc |= check_isolated(c, plugins[i]);
    printf("murk check: %d passed, %d failed, %d skipped; %ld statistical decisions, false-alarm bound %.2e",
           c->passes, c->fails, c->skips, c->nstat, c->alpha);
    if (c->warns)
        printf(", %d warned", c->warns);
    printf("\n");
    remove_tmp(c->tmp);
    free(c);
    return rc;
}
