/* embree_throughput — murk's path-tracing rays per second against Embree's alone on the same scene, one
 * thread each, and their ratios; then the media figure (below).
 *
 *   build/bench/embree_throughput [scene.yaml] [seconds-per-side-per-round] [rounds] [surfaces]
 *
 * (`surfaces`: leave the media figure out.) Three sides, each run for the given CPU seconds per round:
 *   raw     random incoherent rays — origins uniform in the scene's bounding box, directions uniform on
 *           the sphere — through rtcIntersect1 alone (the yardstick of "murk reaches X % of raw Embree");
 *   replay  the rays murk itself traced in a 4-spp render of the scene (recorded by host.c,
 *           murk_host_record_rays), traced again in the same order with the same calls: rtcIntersect1
 *           for camera, BSDF and boundary rays, rtcOccluded1 for shadow rays, a fresh context per ray as
 *           host.c makes it;
 *   murk    `murk render` with the scene's integrator at --threads 1 (camera rays, NEE shadow rays, BSDF
 *           rays, shading, sampling, film), its rays counted as murk counts them.
 * The Embree sides generate or convert their rays outside the timed part; the murk side times everything
 * murk does (per render too: thread start, film, under 1 ms of a 1-s side).
 *
 * The machine's speed drifts (shared, turbo, neighbours), so the sides are measured in several short
 * interleaved rounds — raw, replay, murk, then murk, replay, raw, ... — each round gives one ratio per
 * pair, and the median ratio is quoted with its spread (min and max over the rounds). Defaults: 1 s,
 * 9 rounds. Every side is timed in CPU seconds, not wall time, which on a shared machine counts the
 * other processes' time slices too: the Embree sides in the thread's (CLOCK_THREAD_CPUTIME_ID), murk in
 * the process's (CLOCK_PROCESS_CPUTIME_ID: its one render thread works while the main thread waits).
 *
 * Is it fair? Rays are counted the same way on every side: one Embree call, one ray. murk's path tracer
 * makes an occlusion query per shadow ray and, when it reports a hit, an intersection along the same
 * segment to tell a surface from an index-matched boundary; both are rays, counted once each by murk and
 * replayed once each. But murk's rays are cheaper for Embree than the raw side's — its camera rays are
 * coherent and a third of its calls are occlusion queries cut at the light — so the replay runs about
 * 1.4x as many rays per second as the raw side on the Cornell box, and murk / raw flatters murk by that
 * much. murk / replay is the like-for-like ratio (the same Embree work on both sides); it is also the
 * share of murk's time spent inside Embree. Both are printed; the goal (70 %) was stated against
 * raw. bench/throughput.md has the figures and where the rest of murk's time goes.
 *
 * Then the media figure, on scenes/cornell_smoke.yaml's cloud with the `delta` tracker (grey extinction):
 * free flights through the medium by the tracker plugin (m->vt->sample, with the core's majorant grid
 * walk and density lookups behind the host table) against a bare delta-tracking loop written here over
 * the same majorant grid (the host's walk and density, no plugin, no tracker helpers), on the same
 * segments with the same random numbers. Both take the same tentative collisions (checked: the flights
 * end at the same t), so the ratio of flights/s is the ratio of tracker steps/s; the bare loop's steps
 * (tentative collisions + majorant cells) per second are printed too. Interleaved rounds as above, timed
 * in the thread's CPU seconds (CLOCK_THREAD_CPUTIME_ID). */
#include "host.h"
#include "scene.h"
#include "util.h"

#include "murk/tracking.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* CPU seconds of the calling thread (the Embree sides and the media figure) and of the whole process (the
 * murk side: its render thread's; the main thread waits in pthread_join meanwhile). On a machine shared
 * with other work, wall time would count the others' time slices. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double proc_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double raw_embree(const murk_scene *s, double seconds, uint64_t *nrays)
{
    struct RTCBounds b;
    rtcGetSceneBounds(s->rtc, &b);
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    enum { BATCH = 1 << 16 };
    struct RTCRayHit *rays = murk_xmalloc(BATCH * sizeof *rays);
    uint64_t n = 0, hits = 0;
    double traced = 0;
    while (traced < seconds) {
        for (int i = 0; i < BATCH; i++) { /* generate outside the timed part */
            struct RTCRayHit *r = &rays[i];
            float z = 1 - 2 * murk_rng_float(&rng), phi = 2 * MURK_PI * murk_rng_float(&rng), sz = sqrtf(1 - z * z);
            r->ray.org_x = b.lower_x + (b.upper_x - b.lower_x) * murk_rng_float(&rng);
            r->ray.org_y = b.lower_y + (b.upper_y - b.lower_y) * murk_rng_float(&rng);
            r->ray.org_z = b.lower_z + (b.upper_z - b.lower_z) * murk_rng_float(&rng);
            r->ray.dir_x = sz * cosf(phi), r->ray.dir_y = sz * sinf(phi), r->ray.dir_z = z;
            r->ray.tnear = 0, r->ray.tfar = INFINITY, r->ray.time = 0, r->ray.mask = ~0u, r->ray.id = 0, r->ray.flags = 0;
            r->hit.geomID = RTC_INVALID_GEOMETRY_ID;
        }
        double ts = cpu_now();
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (int i = 0; i < BATCH; i++) {
            rtcIntersect1(s->rtc, &ctx, &rays[i]);
            hits += rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        traced += cpu_now() - ts;
        n += BATCH;
    }
    free(rays);
    *nrays = n;
    return (double)n / traced + 0 * (double)hits;
}

/* ---- the same rays murk traced, replayed through Embree alone ------------------------------------ */

typedef struct replay {
    struct RTCRayHit *rh; /* murk's rays as host.c hands them to Embree */
    unsigned char *occluded;
    size_t n;
} replay;

/* Records the rays of one render of the scene (one thread, `spp` samples per pixel), in order. */
static void replay_record(murk_scene *s, int spp, replay *rp)
{
    murk_ray_record rec = {0};
    rec.cap = (size_t)1 << 22;
    rec.ray = murk_xmalloc(rec.cap * sizeof *rec.ray);
    rec.occluded = murk_xmalloc(rec.cap);
    murk_host_record_rays(&rec);
    murk_render_opts o = {.threads = 1, .spp = spp};
    murk_render_result r;
    murk_render(s, &o, &r);
    murk_host_record_rays(NULL);
    free(r.rgb);
    rp->n = atomic_load(&rec.n) < rec.cap ? atomic_load(&rec.n) : rec.cap;
    rp->rh = murk_xmalloc(rp->n * sizeof *rp->rh);
    rp->occluded = rec.occluded;
    for (size_t i = 0; i < rp->n; i++) { /* host.c's to_embree() */
        const murk_ray *mr = &rec.ray[i];
        struct RTCRay *e = &rp->rh[i].ray;
        e->org_x = mr->o.x, e->org_y = mr->o.y, e->org_z = mr->o.z;
        e->dir_x = mr->d.x, e->dir_y = mr->d.y, e->dir_z = mr->d.z;
        e->tnear = mr->tmin, e->tfar = mr->tmax, e->time = 0.0f, e->mask = 0xffffffffu, e->id = 0, e->flags = 0;
    }
    free(rec.ray);
}

/* Embree's rays/s over the recorded rays, each with the call murk made (rtcIntersect1 or rtcOccluded1
 * with a fresh context, as host.c does), for about `seconds`; only the calls are timed. */
static double replay_side(const murk_scene *s, const replay *rp, double seconds)
{
    struct RTCRayHit *rays = murk_xmalloc(rp->n * sizeof *rays);
    uint64_t n = 0, hits = 0;
    double traced = 0;
    while (traced < seconds) {
        memcpy(rays, rp->rh, rp->n * sizeof *rays); /* outside the timed part: Embree writes tfar and hit */
        for (size_t i = 0; i < rp->n; i++)
            rays[i].hit.geomID = rays[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        double ts = cpu_now();
        for (size_t i = 0; i < rp->n; i++) {
            struct RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            if (rp->occluded[i]) {
                rtcOccluded1(s->rtc, &ctx, &rays[i].ray);
                hits += rays[i].ray.tfar < 0.0f;
            } else {
                rtcIntersect1(s->rtc, &ctx, &rays[i]);
                hits += rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
        }
        traced += cpu_now() - ts;
        n += rp->n;
    }
    free(rays);
    return (double)n / traced + 0 * (double)hits;
}

static size_t count_occluded(const replay *rp)
{
    size_t k = 0;
    for (size_t i = 0; i < rp->n; i++)
        k += rp->occluded[i];
    return k;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* murk's rays/s over one time-limited render of the scene. */
static double murk_side(murk_scene *s, double seconds, int *spp)
{
    murk_render_opts o = {.threads = 1, .time_limit = seconds};
    murk_render_result r;
    double t0 = proc_cpu_now();
    murk_render(s, &o, &r);
    double rps = (double)r.rays / (proc_cpu_now() - t0);
    *spp = r.spp;
    free(r.rgb);
    return rps;
}

/* ---- media: tracker against a bare loop over the same majorant grid ------------------------------ */

enum { NSEG = 1 << 14 };

typedef struct segs {
    murk_ray ray[NSEG];
    float t_tracker[NSEG], t_bare[NSEG];
} segs;

/* Random segments across the scene's bounds: origin uniform inside, direction uniform, up to the closest
 * surface or boundary (so every flight is inside the room). */
static void make_segments(const murk_scene *s, segs *g)
{
    struct RTCBounds b;
    rtcGetSceneBounds(s->rtc, &b);
    const murk_host *h = murk_host_table();
    murk_rng rng;
    murk_rng_seed(&rng, 4, 5, 6);
    for (int i = 0; i < NSEG; i++) {
        murk_ray *r = &g->ray[i];
        float z = 1 - 2 * murk_rng_float(&rng), phi = 2 * MURK_PI * murk_rng_float(&rng), sz = sqrtf(1 - z * z);
        r->o = murk_v3(b.lower_x + (b.upper_x - b.lower_x) * murk_rng_float(&rng),
                       b.lower_y + (b.upper_y - b.lower_y) * murk_rng_float(&rng),
                       b.lower_z + (b.upper_z - b.lower_z) * murk_rng_float(&rng));
        r->d = murk_v3(sz * cosf(phi), sz * sinf(phi), z);
        r->tmin = 0.0f;
        r->tmax = INFINITY;
        murk_hit hit;
        r->tmax = h->intersect(s, r, &hit) ? hit.t : 10.0f;
    }
}

/* Free flights per second of the tracker plugin over the segments, for about `seconds`. */
static double tracker_side(const murk_medium *m, segs *g, double seconds)
{
    murk_path_ctx ctx = {0};
    ctx.beta = murk_rgb1(1.0f);
    uint64_t n = 0;
    double t0 = cpu_now(), el;
    do {
        for (int i = 0; i < NSEG; i++) {
            murk_rng rng;
            murk_rng_seed(&rng, 7, (uint64_t)i, 0);
            murk_medium_event ev;
            m->vt->sample(m->self, &g->ray[i], &ctx, &rng, &ev);
            g->t_tracker[i] = ev.t;
        }
        n += NSEG;
        el = cpu_now() - t0;
    } while (el < seconds);
    return (double)n / el;
}

/* The same flights by a bare delta-tracking loop (grey extinction sigma); *steps_per_s gets the loop's
 * iterations (tentative collisions and majorant cells) per second. */
static double bare_side(const murk_medium_data *d, float sigma, segs *g, double seconds, double *steps_per_s)
{
    const murk_host *h = murk_host_table();
    uint64_t n = 0, steps = 0;
    double t0 = cpu_now(), el;
    do {
        for (int i = 0; i < NSEG; i++) {
            murk_rng rng;
            murk_rng_seed(&rng, 7, (uint64_t)i, 0);
            const murk_ray *r = &g->ray[i];
            murk_majorant_walk w;
            h->walk_init(d->density, r, r->tmin, r->tmax, &w);
            float ta, tb, dmax, dmin, t = r->tmax;
            while (h->walk_next(&w, &ta, &tb, &dmax, &dmin)) {
                steps++;
                float mu = dmax * sigma, tc = ta;
                if (!(mu > 0.0f))
                    continue;
                for (;;) {
                    tc = murk_advance(tc, murk_sample_exp(&rng, mu));
                    if (tc >= tb)
                        break;
                    steps++;
                    float dens = h->density(d->density, murk_madd(r->o, r->d, tc));
                    if (murk_rng_float(&rng) < dens * sigma / mu)
                        goto scattered;
                }
                continue;
            scattered:
                t = tc;
                break;
            }
            g->t_bare[i] = t;
        }
        n += NSEG;
        el = cpu_now() - t0;
    } while (el < seconds);
    *steps_per_s = (double)steps / el;
    return (double)n / el;
}

static int media_figure(double seconds, int rounds)
{
    static const char *const sets[] = {"media.smoke.type=delta"};
    const char *path = MURK_SOURCE_ROOT "/scenes/cornell_smoke.yaml";
    char err[1024];
    murk_scene *s = murk_scene_load(path, sets, 1, err, sizeof err);
    if (!s || s->nmedia < 1) {
        fprintf(stderr, "%s\n", s ? "cornell_smoke.yaml has no medium" : err);
        murk_scene_free(s);
        return 1;
    }
    const murk_medium *m = &s->media[0].m;
    const murk_medium_data *d = &s->media[0].data;
    murk_rgb st = murk_rgb_add(d->sigma_a, d->sigma_s);
    segs *g = murk_xmalloc(sizeof *g);
    make_segments(s, g);
    printf("\nmedia: %s's cloud, tracker 'delta' against a bare delta-tracking loop over the same majorant grid,\n"
           "%d segments, one thread, %d rounds of %.1f s per side, order alternating\n", path, NSEG, rounds, seconds);
    printf("round  bare Mflights/s  bare Msteps/s  tracker Mflights/s  tracker/bare\n");
    double *ratio = murk_xmalloc((size_t)rounds * sizeof *ratio);
    int mismatch = 0;
    for (int k = 0; k < rounds; k++) {
        double bare, steps, tr;
        if (k % 2 == 0) {
            bare = bare_side(d, st.c[0], g, seconds, &steps);
            tr = tracker_side(m, g, seconds);
        } else {
            tr = tracker_side(m, g, seconds);
            bare = bare_side(d, st.c[0], g, seconds, &steps);
        }
        for (int i = 0; i < NSEG; i++)
            mismatch += g->t_tracker[i] != g->t_bare[i];
        ratio[k] = tr / bare;
        printf("%5d  %15.3f  %13.2f  %18.3f  %10.1f %%\n", k + 1, bare / 1e6, steps / 1e6, tr / 1e6, 100.0 * ratio[k]);
    }
    qsort(ratio, (size_t)rounds, sizeof *ratio, cmp_double);
    double median = rounds % 2 ? ratio[rounds / 2] : 0.5 * (ratio[rounds / 2 - 1] + ratio[rounds / 2]);
    printf("tracker / bare loop: median %.1f %%, spread %.1f .. %.1f %% (%d flights ended elsewhere)\n", 100.0 * median,
           100.0 * ratio[0], 100.0 * ratio[rounds - 1], mismatch);
    free(ratio);
    free(g);
    murk_scene_free(s);
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : MURK_SOURCE_ROOT "/scenes/cornell.yaml";
    double seconds = argc > 2 ? atof(argv[2]) : 1.0;
    int rounds = argc > 3 ? atoi(argv[3]) : 9;
    if (!(seconds > 0.0) || rounds < 1 || rounds > 1000) {
        fprintf(stderr, "usage: embree_throughput [scene.yaml] [seconds > 0] [rounds 1..1000] [surfaces]\n");
        return 2;
    }
    /* a low resolution keeps murk's passes short, so its time limit is met closely */
    static const char *const sets[] = {"render.resolution=[128, 128]"};
    char err[1024];
    murk_scene *s = murk_scene_load(path, sets, 1, err, sizeof err);
    if (!s) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    replay rp;
    replay_record(s, 4, &rp);
    printf("scene %s (128x128), one thread each, %d rounds of %.1f s per side, order alternating\n"
           "replay: the %zu rays (%.0f %% occlusion queries) of a 4-spp render of it by murk, traced again by Embree alone\n",
           path, rounds, seconds, rp.n, 100.0 * (double)count_occluded(&rp) / (double)rp.n);
    printf("round  raw Mrays/s  replay Mrays/s  murk Mrays/s  murk/raw  murk/replay\n");
    double *ratio = murk_xmalloc(2 * (size_t)rounds * sizeof *ratio), *rratio = ratio + rounds;
    for (int k = 0; k < rounds; k++) {
        uint64_t nraw;
        int spp;
        double raw, rep, mr;
        if (k % 2 == 0) {
            raw = raw_embree(s, seconds, &nraw);
            rep = replay_side(s, &rp, seconds);
            mr = murk_side(s, seconds, &spp);
        } else {
            mr = murk_side(s, seconds, &spp);
            rep = replay_side(s, &rp, seconds);
            raw = raw_embree(s, seconds, &nraw);
        }
        ratio[k] = mr / raw;
        rratio[k] = mr / rep;
        printf("%5d  %11.2f  %14.2f  %12.2f  %6.1f %%  %9.1f %%\n", k + 1, raw / 1e6, rep / 1e6, mr / 1e6, 100.0 * ratio[k],
               100.0 * rratio[k]);
    }
    qsort(ratio, (size_t)rounds, sizeof *ratio, cmp_double);
    qsort(rratio, (size_t)rounds, sizeof *rratio, cmp_double);
    double median = rounds % 2 ? ratio[rounds / 2] : 0.5 * (ratio[rounds / 2 - 1] + ratio[rounds / 2]);
    double rmedian = rounds % 2 ? rratio[rounds / 2] : 0.5 * (rratio[rounds / 2 - 1] + rratio[rounds / 2]);
    printf("murk / raw Embree (%s integrator): median %.1f %%, spread %.1f .. %.1f %%\n",
           s->integrator_plugin->desc->name, 100.0 * median, 100.0 * ratio[0], 100.0 * ratio[rounds - 1]);
    printf("murk / replay of its own rays (Embree's share of murk's time): median %.1f %%, spread %.1f .. %.1f %%\n",
           100.0 * rmedian, 100.0 * rratio[0], 100.0 * rratio[rounds - 1]);
    free(rp.rh);
    free(rp.occluded);
    free(ratio);
    murk_scene_free(s);
    return argc > 4 && !strcmp(argv[4], "surfaces") ? 0 : media_figure(seconds, rounds);
}
