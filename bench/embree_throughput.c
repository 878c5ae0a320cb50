/* embree_throughput — raw Embree rtcIntersect1 rays/s against murk's path-tracing rays/s on the same
 * scene, on one thread each, and their ratio.
 *
 *   build/bench/embree_throughput [scene.yaml] [seconds-per-side-per-round] [rounds]
 *
 * The machine's speed drifts (shared, turbo, neighbours), so the two sides are measured in several
 * short interleaved rounds — raw then murk, murk then raw, ... — each round gives one ratio, and the
 * median ratio is quoted with its spread (min and max over the rounds). Defaults: 1 s, 9 rounds.
 *
 * The raw side traces random incoherent rays (origins uniform in the scene's bounding box, directions
 * uniform on the sphere) with no shading at all; the murk side is `murk render` with the scene's
 * integrator at --threads 1 (camera rays, NEE shadow rays, BSDF rays, shading, sampling, film).
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

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double raw_embree(const murk_scene *s, double seconds, uint64_t *nrays)
{
    struct RTCBounds b;
    rtcGetSceneBounds(s->rtc, &b);
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    enum { BATCH = 1 << 16 };
    struct RTCRayHit *rays = murk_xmalloc(BATCH * sizeof *rays);
    uint64_t n = 0, hits = 0;
    double t0 = murk_now(), traced = 0;
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
        double ts = murk_now();
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (int i = 0; i < BATCH; i++) {
            rtcIntersect1(s->rtc, &ctx, &rays[i]);
            hits += rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        traced += murk_now() - ts;
        n += BATCH;
    }
    (void)t0;
    free(rays);
    *nrays = n;
    return (double)n / traced + 0 * (double)hits;
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
    murk_render(s, &o, &r);
    double rps = (double)r.rays / r.seconds;
    *spp = r.spp;
    free(r.rgb);
    return rps;
}

/* ---- media: tracker against a bare loop over the same majorant grid ------------------------------ */

enum { NSEG = 1 << 14 };

/* This thread's CPU seconds: on a machine shared with other work, wall time would count the others. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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
        fprintf(stderr, "usage: embree_throughput [scene.yaml] [seconds > 0] [rounds 1..1000]\n");
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
    printf("scene %s (128x128), one thread each, %d rounds of %.1f s per side, order alternating\n", path, rounds,
           seconds);
    printf("round  raw Mrays/s  murk Mrays/s  murk/raw\n");
    double *ratio = murk_xmalloc((size_t)rounds * sizeof *ratio);
    for (int k = 0; k < rounds; k++) {
        uint64_t nraw;
        int spp;
        double raw, mr;
        if (k % 2 == 0) {
            raw = raw_embree(s, seconds, &nraw);
            mr = murk_side(s, seconds, &spp);
        } else {
            mr = murk_side(s, seconds, &spp);
            raw = raw_embree(s, seconds, &nraw);
        }
        ratio[k] = mr / raw;
        printf("%5d  %11.2f  %12.2f  %7.1f %%\n", k + 1, raw / 1e6, mr / 1e6, 100.0 * ratio[k]);
    }
    qsort(ratio, (size_t)rounds, sizeof *ratio, cmp_double);
    double median = rounds % 2 ? ratio[rounds / 2] : 0.5 * (ratio[rounds / 2 - 1] + ratio[rounds / 2]);
    printf("murk / raw Embree (%s integrator): median %.1f %%, spread %.1f .. %.1f %%\n",
           s->integrator_plugin->desc->name, 100.0 * median, 100.0 * ratio[0], 100.0 * ratio[rounds - 1]);
    free(ratio);
    murk_scene_free(s);
    return media_figure(seconds, rounds);
}
