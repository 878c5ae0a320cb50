/* long_paths — murk's density lookups per CPU second on long paths through a dense, bright medium, against a
 * bare loop that makes the same lookups along the same majorant walks, and murk's time per scattering event.
 *
 *   build/bench/long_paths [scene.yaml] [seconds-per-side-per-round] [rounds] [--set KEY=VALUE ...]
 *
 * Default scene: scenes/dense_cloud.yaml (optical depth 53-61 through the centre, single-scattering albedo
 * 0.994-0.995: hundreds of scattering events per path) at 16x16 pixels of a narrow view (fov 8 degrees: every
 * camera ray enters the cloud near its centre), its own tracker and integrator (--set overrides them).
 *   murk   `murk render` in-process on one thread for the given CPU seconds: its density lookups (the
 *          core's counters, host->density) per CPU second of the process, and CPU seconds per real
 *          scattering event (the core's `scatters` counter) — a whole path tracer: flights, NEE with its
 *          shadow rays' transmittance, phase sampling, Embree, the sampler, the film;
 *   bare   the density lookups and majorant-walk steps a 1-spp render of the same scene made, recorded
 *          in order (murk_media_record_lookups: every host->density(), walk_init() and walk_next()) and
 *          replayed by a loop that calls the same core functions on the same points and walks and does
 *          nothing else: what the lookups alone cost.
 * The ratio murk / bare of lookups per second is the share of murk's time that its lookups and walks take;
 * the rest is everything else a path tracer does per lookup. The check figure: the sum of the densities the
 * replay read beside the sum the recorded render read (they must be equal: the same lookups).
 * Interleaved rounds, the order alternating, each side timed in CPU seconds (the process's for murk, whose
 * one render thread works while the main thread waits; the thread's for the replay); median and spread
 * (min, max) of the per-round ratio. */
#include "media/media.h"
#include "render/counters.h"
#include "scene/scene.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_s(clockid_t c)
{
    struct timespec ts;
    clock_gettime(c, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* "M [A .. B]" of n values (sorts them); a static buffer. */
static const char *median_spread(double *r, int n, double scale)
{
    static char buf[96];
    qsort(r, (size_t)n, sizeof *r, cmp_double);
    double median = n % 2 ? r[n / 2] : 0.5 * (r[n / 2 - 1] + r[n / 2]);
    snprintf(buf, sizeof buf, "%.3g [%.3g .. %.3g]", scale * median, scale * r[0], scale * r[n - 1]);
    return buf;
}

typedef struct side {
    double lookups_per_s, s_per_scatter, scatters_per_path;
} side;

/* One time-limited render of s on one thread. */
static void murk_side(murk_scene *s, double seconds, side *out)
{
    murk_render_opts o = {.threads = 1, .time_limit = seconds};
    murk_render_result r;
    double t0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    murk_render(s, &o, &r);
    double el = clock_s(CLOCK_PROCESS_CPUTIME_ID) - t0;
    murk_counters c = murk_counters_total(&r);
    out->lookups_per_s = (double)c.lookups / el;
    out->s_per_scatter = c.scatters ? el / (double)c.scatters : 0.0;
    out->scatters_per_path = (double)c.scatters / ((double)r.spp * s->width * s->height);
    free(r.rgb);
}

/* The recorded lookups and walks, replayed for about `seconds`; *sum gets the densities of one replay. */
static double bare_side(const murk_lookup_record *rec, double seconds, double *sum)
{
    enum { LIVE = 8 }; /* walks alive at once (a flight's and its NEE's, nested at most a few deep) */
    const void *key[LIVE];
    murk_majorant_walk w[LIVE];
    size_t n = rec->n < rec->cap ? rec->n : rec->cap;
    uint64_t lookups = 0;
    double t0 = clock_s(CLOCK_THREAD_CPUTIME_ID), el, s = 0.0;
    do {
        memset(key, 0, sizeof key);
        s = 0.0;
        for (size_t i = 0; i < n; i++) {
            const murk_lookup_event *e = &rec->ev[i];
            if (e->kind == MURK_LOOKUP_DENSITY) {
                s += (double)murk_media_density(e->d, e->ray.o);
                lookups++;
                continue;
            }
            int k = 0; /* the walk's slot: its own, else a free one (round robin past LIVE) */
            while (k < LIVE && key[k] != e->walk)
                k++;
            if (k == LIVE) {
                for (k = 0; k < LIVE && key[k]; k++)
                    ;
                if (k == LIVE)
                    k = (int)(i % LIVE);
                key[k] = e->walk;
            }
            float ta, tb, dmax, dmin;
            if (e->kind == MURK_LOOKUP_WALK_INIT)
                murk_media_walk_init(e->d, &e->ray, e->t0, e->t1, &w[k]);
            else
                murk_media_walk_next(&w[k], &ta, &tb, &dmax, &dmin);
        }
        el = clock_s(CLOCK_THREAD_CPUTIME_ID) - t0;
    } while (el < seconds);
    *sum = s;
    return (double)lookups / el;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : MURK_SOURCE_ROOT "/scenes/dense_cloud.yaml";
    double seconds = argc > 2 ? atof(argv[2]) : 1.0;
    int rounds = argc > 3 ? atoi(argv[3]) : 9;
    if (!(seconds > 0.0) || rounds < 1 || rounds > 1000) {
        fprintf(stderr, "usage: long_paths [scene.yaml] [seconds > 0] [rounds 1..1000] [--set KEY=VALUE ...]\n");
        return 2;
    }
    const char *sets[64] = {"render.resolution=[16, 16]", "camera.fov=8"};
    int nsets = 2;
    for (int i = 4; i + 1 < argc && nsets < 64; i += 2)
        if (!strcmp(argv[i], "--set"))
            sets[nsets++] = argv[i + 1];
    char err[1024];
    murk_scene *s = murk_scene_load(path, sets, nsets, err, sizeof err);
    if (!s || s->nmedia < 1) {
        fprintf(stderr, "%s\n", s ? "the scene has no medium" : err);
        murk_scene_free(s);
        return 1;
    }
    /* the record: one spp of the whole image */
    murk_lookup_record rec = {0};
    rec.cap = (size_t)1 << 22;
    rec.ev = murk_xmalloc(rec.cap * sizeof *rec.ev);
    murk_media_record_lookups(&rec);
    murk_render_opts o = {.threads = 1, .spp = 1};
    murk_render_result r;
    murk_render(s, &o, &r);
    murk_media_record_lookups(NULL);
    free(r.rgb);
    size_t lookups = 0;
    for (size_t i = 0; i < rec.n && i < rec.cap; i++)
        lookups += rec.ev[i].kind == MURK_LOOKUP_DENSITY;
    printf("scene %s (16x16, fov 8, medium '%s', tracker '%s'), one thread each, %d rounds of %.1f s per side, order "
           "alternating\nrecord: %zu lookups and walk steps of a 1-spp render (%zu density lookups)%s\n",
           path, s->media[0].name, s->media[0].plugin->desc->name, rounds, seconds, rec.n, lookups,
           rec.n > rec.cap ? ", cut at the record's capacity" : "");
    printf("round  murk Mlookups/s  bare Mlookups/s  murk/bare  murk us/scatter  scatters/path\n");
    double *ratio = murk_xmalloc(3 * (size_t)rounds * sizeof *ratio), *per = ratio + rounds, *spp_ = per + rounds;
    double sum = 0.0;
    for (int k = 0; k < rounds; k++) {
        side m;
        double bare;
        if (k % 2 == 0) {
            bare = bare_side(&rec, seconds, &sum);
            murk_side(s, seconds, &m);
        } else {
            murk_side(s, seconds, &m);
            bare = bare_side(&rec, seconds, &sum);
        }
        ratio[k] = m.lookups_per_s / bare;
        per[k] = m.s_per_scatter;
        spp_[k] = m.scatters_per_path;
        printf("%5d  %15.2f  %15.2f  %8.1f %%  %15.3f  %13.1f\n", k + 1, m.lookups_per_s / 1e6, bare / 1e6,
               100.0 * ratio[k], 1e6 * m.s_per_scatter, m.scatters_per_path);
    }
    printf("murk / bare lookups per CPU second: %s %%\n", median_spread(ratio, rounds, 100.0));
    printf("murk's CPU time per scattering event: %s us", median_spread(per, rounds, 1e6));
    printf(" (%s scattering events per path)\n", median_spread(spp_, rounds, 1.0));
    printf("check: sum of the densities read, recorded render %.6e, bare replay %.6e\n", rec.sum, sum);
    free(ratio);
    free(rec.ev);
    murk_scene_free(s);
    return 0;
}
