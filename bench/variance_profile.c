/* variance_profile — where a path tracer's variance comes from: each contribution of murk's path tracer
 * (plugins/integrators/pathtracer.c, compiled in here with -DMURK_PT_TAP) by technique and bounce count,
 * its share of the pixel mean and of the pixel variance, and how the paths ended (Russian roulette,
 * max_depth, absorption, escape) per bounce count.
 *
 *   build/bench/variance_profile SCENE.yaml [--set KEY.PATH=VALUE]... [--spp N] [--crop X,Y,W,H]
 *                                [--stride S] [--csv]
 *
 * The scene loads as for `murk render` (its integrator must be path, volpath or volpath_nee: its
 * parameters are the ones used). Every pixel of the crop (default the whole image) whose x and y are
 * multiples of the stride (relative to the crop; default 1) takes --spp samples (default the scene's)
 * exactly as `murk render` draws them — the scene's sampler and seed, the same camera ray — on one
 * thread, through this program's copy of the path tracer whose add_light() reports every term it adds
 * to the sample (murk_pt_tap): surface NEE, medium NEE (at a free-flight vertex), equiangular NEE,
 * emission found by BSDF sampling, by phase sampling, by the camera ray, the background.
 *
 * A term's value per sample is what it adds to L (R, G and B apart); a term absent from a sample counts as
 * 0 there. Bounces: the scattering events on the light path the term estimates, its own NEE vertex
 * counted (0: emission seen by the camera ray, 1: direct light at the first vertex = single scattering
 * in a medium, 2: one more bounce, ...), bucketed 0, 1, 2, 3, 4-7, 8+. Per pixel and channel, the sums
 * of each term (each (technique, bounces) cell, each technique over all bounces, each bounce bucket over
 * all techniques) and of its square give its mean and its variance per sample. Printed per term:
 *   mean     the term's mean over the pixels and channels (the sample's mean is the sum of these);
 *   mean%    its share of the sample's mean;
 *   var%     Var(term) / Var(sample) per pixel (variances summed over the channels), averaged over the
 *            pixels whose sample has variance;
 *   relMSE%  its share of the image's relMSE per sample: the sum over pixels and channels of Var(term) /
 *            (m^2 + 0.01) over the same sum of Var(sample) (m: the pixel's channel mean; murk compare's
 *            relMSE weights, so the relMSE per sample printed at the end is murk compare's relMSE of an
 *            N-spp image times N, for independent samples).
 * Terms covary (a path that finds light at bounce 1 tends to find it at bounce 2; MIS pairs trade off),
 * so the variance shares of a set of terms do not sum to 100 %: each group's sum is printed with it.
 * Then the paths' ends per bounce count (scattering events done when the path ended): Russian roulette,
 * max_depth, absorbed (a free flight's weight 0: a tracker's absorption), escaped (to the background);
 * the paths that ended otherwise (a BSDF sample that failed or weighed 0, a non-finite value, the
 * watchdog: no bounce count reported) are counted apart. The sample's relMSE per sample
 * and the seconds per sample (this loop, one thread, the tap included) end the table. --csv prints the
 * same numbers as CSV. Deterministic: a function of the scene (seed included), crop, stride and spp. */
#include "pathtracer.h"
#include "pathtracer_tap.h"
#include "scene/scene.h"
#include "util/util.h"

#include "render/camera.h"
#include "render/host.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NB = 6 };                          /* bounce buckets: 0, 1, 2, 3, 4-7, 8+ */
enum { NCELL = MURK_PT_NTERMS * NB };     /* (technique, bucket) */
enum { G_TECH = NCELL, G_BOUNCE = G_TECH + MURK_PT_NTERMS, G_ALL = G_BOUNCE + NB, NG };

static const char *const term_name[MURK_PT_NTERMS] = {"surface NEE",     "medium NEE",        "equiangular NEE",
                                                      "BSDF emission",   "phase emission",    "camera emission",
                                                      "background"};
static const char *const end_name[MURK_PT_NENDS] = {"roulette", "max_depth", "absorbed", "escaped"};
static const char *const bucket_name[NB] = {"0", "1", "2", "3", "4-7", "8+"};

static int bucket(int bounces) { return bounces < 4 ? (bounces < 0 ? 0 : bounces) : bounces < 8 ? 4 : 5; }

/* ---- the tap (one thread) -------------------------------------------------------------------------- */

static double cur[NCELL][3];                 /* this sample's terms, per channel */
static int ended;                            /* this sample's path reported its end */
static uint64_t ends[NB][MURK_PT_NENDS];     /* per bucket: paths ended each way */
static uint64_t events;                      /* scattering events of the paths that reported their end */

void murk_pt_tap(int depth, int term, murk_rgb value)
{
    int nee = term == MURK_PT_TERM_SURFACE_NEE || term == MURK_PT_TERM_MEDIUM_NEE || term == MURK_PT_TERM_EQUIANGULAR_NEE;
    for (int c = 0; c < 3; c++)
        cur[term * NB + bucket(depth + nee)][c] += value.c[c];
}

void murk_pt_tap_end(int depth, int why)
{
    ends[bucket(depth)][why]++;
    events += (uint64_t)depth;
    ended = 1;
}

/* ---- the render loop ------------------------------------------------------------------------------- */

typedef struct profile {
    double mean[NG];   /* sum over pixels of each term's pixel mean */
    double share[NG];  /* sum over pixels with variance of Var(term) / Var(sample) */
    double rel[NG];    /* sum over pixels of Var(term) / (m^2 + 0.01) */
    long npix, nvar;   /* pixels; pixels whose sample has variance */
    uint64_t samples, nonfinite, ended_untapped;
    double max_sum_err; /* largest |sum of the terms - sample| / (|sample| + sum |terms|) */
    double seconds;
} profile;

/* The groups a sample's cells add up to, per channel. */
static void groups(double cell[NCELL][3], double g[NG][3])
{
    memset(g + G_TECH, 0, (NG - G_TECH) * sizeof *g);
    for (int t = 0; t < MURK_PT_NTERMS; t++)
        for (int b = 0; b < NB; b++)
            for (int c = 0; c < 3; c++) {
                double x = cell[t * NB + b][c];
                g[t * NB + b][c] = x;
                g[G_TECH + t][c] += x;
                g[G_BOUNCE + b][c] += x;
                g[G_ALL][c] += x;
            }
}

/* Per pixel and channel c: the mean m_c and the variance per sample V_c of every group. A group's mean
 * is the mean over channels; its variance share is sum_c V_c(group) / sum_c V_c(sample); its relMSE is
 * sum_c V_c(group) / (m_c(sample)^2 + 0.01) / 3 (murk compare's relMSE, per sample). */
static void run(const murk_scene *s, const murk_pt *pt, const int crop[4], int stride, int spp, profile *p)
{
    static double s1[NG][3], s2[NG][3], g[NG][3];
    double t0 = murk_now();
    for (int y = crop[1]; y < crop[1] + crop[3]; y += stride)
        for (int x = crop[0]; x < crop[0] + crop[2]; x += stride) {
            memset(s1, 0, sizeof s1);
            memset(s2, 0, sizeof s2);
            int n = 0;
            for (int k = 0; k < spp; k++) {
                murk_rng rng;
                murk_ray r;
                murk_camera_sample(s, x, y, (uint32_t)k, &rng, &r);
                memset(cur, 0, sizeof cur);
                ended = 0;
                murk_rgb L = murk_pt_li(pt, s, &r, &rng);
                p->samples++;
                if (!ended)
                    p->ended_untapped++;
                if (!murk_rgb_finite(L)) { /* left out of the pixel, as murk render does */
                    p->nonfinite++;
                    continue;
                }
                groups(cur, g);
                for (int c = 0; c < 3; c++) {
                    double abs_sum = 0.0;
                    for (int i = 0; i < NCELL; i++)
                        abs_sum += fabs(cur[i][c]);
                    double err = fabs(g[G_ALL][c] - L.c[c]) / (fabs(L.c[c]) + abs_sum + 1e-30);
                    p->max_sum_err = err > p->max_sum_err ? err : p->max_sum_err;
                }
                for (int i = 0; i < NG; i++)
                    for (int c = 0; c < 3; c++) {
                        s1[i][c] += g[i][c];
                        s2[i][c] += g[i][c] * g[i][c];
                    }
                n++;
            }
            if (n < 2)
                continue;
            double var[NG], rel[NG], w[3];
            for (int c = 0; c < 3; c++) {
                double m = s1[G_ALL][c] / n;
                w[c] = 1.0 / (3.0 * (m * m + 0.01));
            }
            for (int i = 0; i < NG; i++) {
                var[i] = rel[i] = 0.0;
                for (int c = 0; c < 3; c++) {
                    double m = s1[i][c] / n, v = fmax(0.0, (s2[i][c] - s1[i][c] * m) / (n - 1));
                    p->mean[i] += m / 3.0;
                    var[i] += v;
                    rel[i] += v * w[c];
                }
                p->rel[i] += rel[i];
            }
            if (var[G_ALL] > 0.0) {
                for (int i = 0; i < NG; i++)
                    p->share[i] += var[i] / var[G_ALL];
                p->nvar++;
            }
            p->npix++;
        }
    p->seconds = murk_now() - t0;
}

/* ---- output ------------------------------------------------------------------------------------------- */

static double pct(double a, double b) { return b != 0.0 ? 100.0 * a / b : 0.0; }

static void row(const profile *p, int i, const char *tech, const char *b, int csv)
{
    double mean = p->mean[i] / (double)p->npix, mshare = pct(p->mean[i], p->mean[G_ALL]);
    double vshare = p->nvar ? 100.0 * p->share[i] / (double)p->nvar : 0.0, rshare = pct(p->rel[i], p->rel[G_ALL]);
    if (csv)
        printf("term,%s,%s,%.6g,%.4f,%.4f,%.4f\n", tech, b, mean, mshare, vshare, rshare);
    else
        printf("  %-16s %-4s %11.5f %7.2f %7.2f %8.2f\n", tech, b, mean, mshare, vshare, rshare);
}

/* The rows of group `from`..`from + n - 1` with any mean or variance, then their shares' sum. */
static void rows(const profile *p, int from, int n, int stride, const char *const *tech, const char *const *b, int csv,
                 const char *sum_label)
{
    double sm = 0, sv = 0, sr = 0;
    for (int k = 0; k < n; k++) {
        int i = from + k * stride;
        double m = pct(p->mean[i], p->mean[G_ALL]), v = p->nvar ? 100.0 * p->share[i] / (double)p->nvar : 0.0,
               r = pct(p->rel[i], p->rel[G_ALL]);
        sm += m, sv += v, sr += r;
        if (p->mean[i] == 0.0 && p->rel[i] == 0.0)
            continue;
        if (!csv && fabs(m) < 0.005 && v < 0.005 && r < 0.005) /* the table shows no row that is 0.00 0.00 0.00 */
            continue;
        row(p, i, tech ? tech[k] : "", b ? b[k] : "", csv);
    }
    if (csv)
        printf("sum,%s,,,%.4f,%.4f,%.4f\n", sum_label, sm, sv, sr);
    else
        printf("  %-21s %11s %7.2f %7.2f %8.2f\n", sum_label, "", sm, sv, sr);
}

/* Mean scattering events of the paths that reported their end. */
static double events_per_path(const profile *p)
{
    uint64_t n = p->samples - p->ended_untapped;
    return n ? (double)events / (double)n : 0.0;
}

static void print(const profile *p, const char *path, const murk_scene *s, int spp, int csv)
{
    double relmse = p->rel[G_ALL] / (double)p->npix;
    if (csv) {
        printf("kind,technique,bounces,mean,mean_share,var_share,relmse_share\n");
        for (int t = 0; t < MURK_PT_NTERMS; t++) {
            const char *tb[NB];
            for (int b = 0; b < NB; b++)
                tb[b] = term_name[t];
            rows(p, t * NB, NB, 1, tb, bucket_name, csv, term_name[t]);
        }
        rows(p, G_TECH, MURK_PT_NTERMS, 1, term_name, NULL, csv, "techniques");
        rows(p, G_BOUNCE, NB, 1, NULL, bucket_name, csv, "bounces");
        printf("end,bounces,why,paths\n");
        for (int b = 0; b < NB; b++)
            for (int e = 0; e < MURK_PT_NENDS; e++)
                printf("end,%s,%s,%llu\n", bucket_name[b], end_name[e], (unsigned long long)ends[b][e]);
        printf("end,,other,%llu\n", (unsigned long long)p->ended_untapped);
        printf("total,pixels,%ld,samples,%llu,relmse_per_sample,%.6g,seconds_per_sample,%.6g,mean,%.6g,"
               "events_per_path,%.4f\n",
               p->npix, (unsigned long long)p->samples, relmse, p->seconds / (double)p->samples,
               p->mean[G_ALL] / (double)p->npix, events_per_path(p));
        return;
    }
    printf("%s: %s integrator, %ld pixels x %d spp (sampler %s, seed %llu), one thread\n", path,
           s->integrator_plugin->desc->name, p->npix, spp, s->sampler == MURK_SAMPLER_SOBOL ? "sobol" : "independent",
           (unsigned long long)s->seed);
    printf("  %-16s %-4s %11s %7s %7s %8s\n", "technique", "bnc", "mean", "mean%", "var%", "relMSE%");
    printf("by technique (all bounces):\n");
    rows(p, G_TECH, MURK_PT_NTERMS, 1, term_name, NULL, 0, "sum of shares");
    printf("by bounce count (all techniques):\n");
    rows(p, G_BOUNCE, NB, 1, NULL, bucket_name, 0, "sum of shares");
    printf("by technique and bounce count:\n");
    for (int t = 0; t < MURK_PT_NTERMS; t++) {
        if (p->mean[G_TECH + t] == 0.0 && p->rel[G_TECH + t] == 0.0)
            continue;
        if (fabs(pct(p->mean[G_TECH + t], p->mean[G_ALL])) < 0.005 && pct(p->rel[G_TECH + t], p->rel[G_ALL]) < 0.005)
            continue;
        const char *tb[NB];
        char label[64];
        for (int b = 0; b < NB; b++)
            tb[b] = term_name[t];
        snprintf(label, sizeof label, "%s, sum", term_name[t]);
        rows(p, t * NB, NB, 1, tb, bucket_name, 0, label);
    }
    printf("paths ended, by scattering events done:\n  %-5s", "bnc");
    for (int e = 0; e < MURK_PT_NENDS; e++)
        printf(" %10s", end_name[e]);
    printf(" %10s\n", "all");
    for (int b = 0; b < NB; b++) {
        uint64_t all = 0;
        for (int e = 0; e < MURK_PT_NENDS; e++)
            all += ends[b][e];
        printf("  %-5s", bucket_name[b]);
        for (int e = 0; e < MURK_PT_NENDS; e++)
            printf(" %10llu", (unsigned long long)ends[b][e]);
        printf(" %10llu\n", (unsigned long long)all);
    }
    uint64_t col[MURK_PT_NENDS] = {0};
    for (int b = 0; b < NB; b++)
        for (int e = 0; e < MURK_PT_NENDS; e++)
            col[e] += ends[b][e];
    printf("  %-5s", "all");
    for (int e = 0; e < MURK_PT_NENDS; e++)
        printf(" %9.2f%%", pct((double)col[e], (double)p->samples));
    printf("\n  (%llu paths ended elsewhere: a failed or zero BSDF sample, a non-finite value, the watchdog); "
           "%.3f scattering events per path (the others)\n",
           (unsigned long long)p->ended_untapped, events_per_path(p));
    printf("sample mean %.5f, relMSE per sample %.5f (at N spp: about this / N with independent numbers), "
           "%.2f us per sample; %llu samples, %llu non-finite; terms sum to the sample within %.1e (relative)\n",
           p->mean[G_ALL] / (double)p->npix, relmse, 1e6 * p->seconds / (double)p->samples,
           (unsigned long long)p->samples, (unsigned long long)p->nonfinite, p->max_sum_err);
}

/* ---- main ------------------------------------------------------------------------------------------ */

static int usage(void)
{
    fprintf(stderr, "usage: variance_profile SCENE.yaml [--set KEY.PATH=VALUE]... [--spp N] [--crop X,Y,W,H] "
                    "[--stride S] [--csv]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    const char **sets = murk_xmalloc((size_t)argc * sizeof *sets);
    size_t nsets = 0;
    int spp = 0, stride = 1, csv = 0, crop[4] = {0, 0, -1, -1};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--set") && i + 1 < argc)
            sets[nsets++] = argv[++i];
        else if (!strcmp(a, "--spp") && i + 1 < argc)
            spp = atoi(argv[++i]);
        else if (!strcmp(a, "--stride") && i + 1 < argc)
            stride = atoi(argv[++i]);
        else if (!strcmp(a, "--crop") && i + 1 < argc) {
            if (sscanf(argv[++i], "%d,%d,%d,%d", &crop[0], &crop[1], &crop[2], &crop[3]) != 4)
                return usage();
        } else if (!strcmp(a, "--csv"))
            csv = 1;
        else if (a[0] != '-' && !path)
            path = a;
        else
            return usage();
    }
    if (!path || spp < 0 || stride < 1)
        return usage();
    char err[1024];
    murk_scene *s = murk_scene_load(path, sets, nsets, err, sizeof err);
    free(sets);
    if (!s) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    const char *name = s->integrator_plugin->desc->name;
    if (strcmp(name, "path") && strcmp(name, "volpath") && strcmp(name, "volpath_nee")) {
        fprintf(stderr, "%s: integrator '%s' is not murk's path tracer (path, volpath, volpath_nee)\n", path, name);
        murk_scene_free(s);
        return 1;
    }
    if (crop[2] < 0)
        crop[2] = s->width, crop[3] = s->height;
    if (crop[0] < 0 || crop[1] < 0 || crop[2] < 1 || crop[3] < 1 || crop[0] + crop[2] > s->width ||
        crop[1] + crop[3] > s->height) {
        fprintf(stderr, "--crop %d,%d,%d,%d: not inside the %dx%d image\n", crop[0], crop[1], crop[2], crop[3],
                s->width, s->height);
        murk_scene_free(s);
        return 2;
    }
    if (!spp)
        spp = s->spp;
    /* the plugin's own state (murk_pt, pathtracer.h: the same struct here), so its parameters hold */
    murk_pt pt = *(const murk_pt *)s->integrator;
    murk_host_thread_reset();
    profile p = {0};
    run(s, &pt, crop, stride, spp, &p);
    if (!p.npix) {
        fprintf(stderr, "no pixel got 2 finite samples\n");
        murk_scene_free(s);
        return 1;
    }
    print(&p, path, s, spp, csv);
    murk_scene_free(s);
    return 0;
}
