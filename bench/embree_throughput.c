/* embree_throughput — raw Embree rtcIntersect1 rays/s against murk's path-tracing rays/s on the same
 * scene, measured in one run on one thread each, and their ratio.
 *
 *   build/bench/embree_throughput [scene.yaml] [seconds-per-side]
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

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : MURK_SOURCE_ROOT "/scenes/cornell.yaml";
    double seconds = argc > 2 ? atof(argv[2]) : 5.0;
    char err[1024];
    murk_scene *s = murk_scene_load(path, NULL, 0, err, sizeof err);
    if (!s) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    uint64_t nraw;
    double raw = raw_embree(s, seconds, &nraw);
    murk_render_opts o = {.threads = 1, .time_limit = seconds};
    murk_render_result r;
    murk_render(s, &o, &r);
    double murk_rps = (double)r.rays / r.seconds;
    printf("scene %s, one thread each\n", path);
    printf("raw Embree rtcIntersect1, random incoherent rays: %.2f Mrays/s (%llu rays)\n", raw / 1e6,
           (unsigned long long)nraw);
    printf("murk %s integrator, full render:                %.2f Mrays/s (%llu rays, %d spp, %.1f s)\n",
           s->integrator_plugin->desc->name, murk_rps / 1e6, (unsigned long long)r.rays, r.spp, r.seconds);
    printf("ratio murk / raw Embree: %.1f %%\n", 100.0 * murk_rps / raw);
    free(r.rgb);
    murk_scene_free(s);
    return 0;
}
