/* transmittance — every transmittance estimator on real shadow-ray segments, in-process: density
 * lookups, time and error per estimate against a converged reference. Prints CSV on stdout.
 *
 *   build/bench/transmittance [segments] [estimates-per-segment]      (defaults 200 and 200)
 *   docs/results/plot.py runs it and draws the PNG charts in docs/results/ (see docs/results.md)
 *
 * Scenes: scenes/cornell_smoke.yaml as it is (the cloud of sigma_t 18.5 in the Cornell box) and the
 * same cloud made dense (coverage 0.3, scale 3: about 5x the optical depth). Shadow-ray segments are
 * what volpath_nee traces from a medium vertex: a point in the cloud's box drawn in proportion to the
 * density (rejection against the majorant), a light point from host->sample_light, and the segment up to
 * where that ray leaves the medium (the box boundary, host->intersect). The reference per segment is
 * the midpoint rule with 20000 steps on the field as the core interpolates it (converged to ~1e-7).
 *
 * Estimators are created through their plugins' vtables with a copy of the core's host table whose
 * density() counts lookups (one thread). Per estimator and segment, S estimates give the mean and the
 * variance; the CSV's columns, averaged over segments:
 *   lookups     density lookups per estimate
 *   ns          wall time per estimate (nanoseconds)
 *   var_c       variance of one estimate, channel c
 *   bias2_c     squared bias (mean - reference)^2 - var / S, clamped at 0 (0 within noise when unbiased)
 *   rmse_c      root mean squared error of one estimate = sqrt(var + bias2)
 *   eff_lookups efficiency against ratio at equal lookups: (var x lookups)_ratio / (mse x lookups)
 *   eff_time    the same at equal time
 * The error of the mean of n estimates is sqrt(bias2 + var / n); plot.py draws it against n x lookups
 * and n x time, so a biased estimator flattens at its floor sqrt(bias2). */
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "render/host.h"
#include "scene/scene.h"
#include "util/util.h"

#include "murk/transmittance.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static long nlookups;
static const murk_host *real;
static float counting_density(const murk_density *d, murk_vec3 p)
{
    nlookups++;
    return real->density(d, p);
}

typedef struct espec {
    const char *label, *plugin;
    const char *pname[3];
    double pval[3];
} espec;

static const espec ESTIMATORS[] = {
    {"ratio", "ratio", {0}, {0}},
    {"residual_ratio", "residual_ratio", {0}, {0}},
    {"track_length", "track_length", {0}, {0}},
    {"unbiased_raymarch", "unbiased_raymarch", {0}, {0}},
    {"unbiased_raymarch_ds4", "unbiased_raymarch", {"depth_step"}, {4}},
    {"unbiased_raymarch_ds0.25", "unbiased_raymarch", {"depth_step"}, {0.25}},
    {"power_series", "power_series", {0}, {0}},
    {"power_series_cd1", "power_series", {"chunk_depth"}, {1}},
    {"power_series_cd16", "power_series", {"chunk_depth"}, {16}},
    {"raymarch_0.1", "raymarch", {"step"}, {0.1}},
    {"raymarch_0.03", "raymarch", {"step"}, {0.03}},
    {"raymarch_0.01", "raymarch", {"step"}, {0.01}},
};
#define NEST ((int)(sizeof ESTIMATORS / sizeof ESTIMATORS[0]))

/* The schema's defaults with the spec's overrides (numbers only). */
static void params_for(const murk_plugin_desc *d, const espec *e, murk_value *v)
{
    for (uint32_t i = 0; i < d->nparams; i++) {
        const murk_param *p = &d->params[i];
        memset(&v[i], 0, sizeof v[i]);
        memcpy(v[i].f, p->def, sizeof v[i].f);
        v[i].s = p->def_str;
        for (int k = 0; k < 3 && e->pname[k]; k++)
            if (strcmp(e->pname[k], p->name) == 0) {
                v[i].set = 1;
                v[i].f[0] = v[i].f[1] = v[i].f[2] = e->pval[k];
            }
    }
}

typedef struct seg {
    murk_ray ray;
    double T[3];
} seg;

/* Shadow-ray segments from medium vertices of the scene's first medium. */
static seg *make_segments(const murk_scene *s, int nseg)
{
    const murk_host *h = murk_host_table();
    const murk_named_medium *nm = &s->media[0];
    const murk_medium_data *md = &nm->data;
    murk_vec3 lo = murk_v3(-0.6f, 0.05f, -0.6f), hi = murk_v3(0.6f, 1.45f, 0.6f); /* the cloud's box */
    float dmax = 0.0f;
    { /* a bound for rejection sampling: the majorant grid's largest cell along 64 lines through the box
       * (a cell above it would only be under-sampled, which matters little for a benchmark) */
        murk_majorant_walk w;
        for (int k = 0; k < 64; k++) {
            murk_ray r = {murk_v3(-1.0f, lo.y + (hi.y - lo.y) * (k + 0.5f) / 64.0f, lo.z + (hi.z - lo.z) * ((k * 37) % 64 + 0.5f) / 64.0f),
                          murk_v3(1, 0, 0), 0.0f, 2.0f};
            h->walk_init(md->density, &r, 0.0f, 2.0f, &w);
            float ta, tb, mx, mn;
            while (h->walk_next(&w, &ta, &tb, &mx, &mn))
                dmax = murk_maxf(dmax, mx);
        }
    }
    seg *out = murk_xmalloc((size_t)nseg * sizeof *out);
    murk_rng rng;
    murk_rng_seed(&rng, 2024, 7, 1);
    murk_rgb st = murk_rgb_add(md->sigma_a, md->sigma_s);
    for (int n = 0; n < nseg;) {
        murk_vec3 p = murk_v3(lo.x + (hi.x - lo.x) * murk_rng_float(&rng), lo.y + (hi.y - lo.y) * murk_rng_float(&rng),
                              lo.z + (hi.z - lo.z) * murk_rng_float(&rng));
        if (murk_rng_float(&rng) * dmax >= h->density(md->density, p))
            continue;
        float u[3] = {murk_rng_float(&rng), murk_rng_float(&rng), murk_rng_float(&rng)};
        murk_light_sample ls;
        if (!h->sample_light(s, p, u, &ls) || !(ls.pdf > 0.0f))
            continue;
        murk_ray r = {p, ls.wi, 0.0f, ls.dist};
        murk_hit hit;
        if (!h->intersect(s, &r, &hit))
            continue;
        r.tmax = hit.t; /* where the shadow ray leaves the medium (or meets a surface) */
        double D = 0.0;
        const int steps = 20000;
        double dt = ((double)r.tmax - r.tmin) / steps;
        for (int i = 0; i < steps; i++)
            D += dt * h->density(md->density, murk_madd(r.o, r.d, (float)(r.tmin + dt * (i + 0.5))));
        out[n].ray = r;
        for (int c = 0; c < 3; c++)
            out[n].T[c] = exp(-(double)st.c[c] * D);
        n++;
    }
    return out;
}

static void bench_scene(const char *label, const char *path, const char *const *sets, size_t nsets, int nseg, int S)
{
    char err[2048];
    murk_scene *s = murk_scene_load(path, sets, nsets, err, sizeof err);
    if (!s) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    seg *segs = make_segments(s, nseg);
    double meanT = 0.0;
    for (int i = 0; i < nseg; i++)
        meanT += segs[i].T[0] / nseg;
    fprintf(stderr, "%s: %d segments, mean reference T %.4f\n", label, nseg, meanT);
    static murk_host counting;
    real = murk_host_table();
    counting = *real;
    counting.density = counting_density;
    const murk_named_medium *nm = &s->media[0];
    double ref_var = 0, ref_lookups = 0, ref_ns = 0;
    for (int e = -1; e < NEST; e++) { /* e = -1: ratio once unprinted, to warm caches and clocks */
        const int ei = e < 0 ? 0 : e;
        char lerr[1024];
        const murk_plugin *p = murk_registry_load(&s->reg, MURK_KIND_TRANSMITTANCE, ESTIMATORS[ei].plugin, lerr, sizeof lerr);
        if (!p) {
            fprintf(stderr, "%s\n", lerr);
            exit(1);
        }
        murk_value vals[16];
        params_for(p->desc, &ESTIMATORS[ei], vals);
        const murk_transmittance_vt *vt = p->desc->vtable;
        void *self = NULL;
        if (vt->create(&counting, &nm->data, vals, &self, lerr, sizeof lerr) != 0) {
            fprintf(stderr, "%s\n", lerr);
            exit(1);
        }
        double var[3] = {0}, bias2[3] = {0};
        long lookups = 0;
        double secs = 0.0;
        for (int i = 0; i < nseg; i++) {
            murk_rng rng;
            murk_rng_seed(&rng, 99, (uint64_t)i, (uint64_t)ei);
            murk_path_ctx ctx = {0, murk_rgb1(1.0f)};
            double sum[3] = {0}, sum2[3] = {0};
            nlookups = 0;
            double t0 = murk_now();
            for (int k = 0; k < S; k++) {
                ctx.hero = k % 3;
                murk_rgb T = vt->estimate(self, &segs[i].ray, &ctx, &rng);
                for (int c = 0; c < 3; c++) {
                    double x = T.c[c] - segs[i].T[c];
                    sum[c] += x;
                    sum2[c] += x * x;
                }
            }
            secs += murk_now() - t0;
            lookups += nlookups;
            for (int c = 0; c < 3; c++) {
                double m = sum[c] / S, v = fmax(0.0, (sum2[c] - S * m * m) / (S - 1));
                var[c] += v / nseg;
                bias2[c] += (m * m - v / S) / nseg;
            }
        }
        vt->destroy(self);
        double L = (double)lookups / ((double)nseg * S), ns = 1e9 * secs / ((double)nseg * S);
        double mse = 0.0;
        for (int c = 0; c < 3; c++) {
            bias2[c] = fmax(0.0, bias2[c]);
            mse += (var[c] + bias2[c]) / 3.0;
        }
        if (e < 0)
            continue;
        if (e == 0) {
            ref_var = mse;
            ref_lookups = L;
            ref_ns = ns;
        }
        printf("%s,%s,%.3f,%.1f,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.4f,%.4f\n", label, ESTIMATORS[e].label, L,
               ns, var[0], var[1], var[2], bias2[0], bias2[1], bias2[2], sqrt(var[0] + bias2[0]),
               sqrt(var[1] + bias2[1]), sqrt(var[2] + bias2[2]), (ref_var * ref_lookups) / (mse * fmax(L, 1e-9)),
               (ref_var * ref_ns) / (mse * ns));
        fflush(stdout);
    }
    free(segs);
    murk_scene_free(s);
}

int main(int argc, char **argv)
{
    int nseg = argc > 1 ? atoi(argv[1]) : 200, S = argc > 2 ? atoi(argv[2]) : 200;
    if (nseg < 1 || S < 2) {
        fprintf(stderr, "usage: transmittance [segments >= 1] [estimates-per-segment >= 2]\n");
        return 2;
    }
    const char *scene = MURK_SOURCE_ROOT "/scenes/cornell_smoke.yaml";
    printf("scene,estimator,lookups,ns,var_r,var_g,var_b,bias2_r,bias2_g,bias2_b,rmse_r,rmse_g,rmse_b,eff_lookups,eff_time\n");
    bench_scene("cornell_smoke", scene, NULL, 0, nseg, S);
    static const char *const dense[] = {"media.smoke.density.cloud.coverage=0.3", "media.smoke.scale=3"};
    bench_scene("dense_cloud", scene, dense, 2, nseg, S);
    static const char *const chroma[] = {"media.smoke.sigma_a=[0.2, 1, 4]", "media.smoke.sigma_s=[18, 12, 6]"};
    bench_scene("chromatic_smoke", scene, chroma, 2, nseg, S);
    return 0;
}
