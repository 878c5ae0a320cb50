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
 * integrator at --threads 1 (camera rays, NEE shadow rays, BSDF rays, shading, sampling, film). */
#include "host.h"
#include "scene.h"
#include "util.h"

#include <stdio.h>
#include <stdlib.h>

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
    return 0;
}
