/* embree_throughput — murk's path-tracing rays per second against Embree's alone on the same scene, one
 * thread each, and their ratios; then the media figure (below).
 *
 *   build/bench/embree_throughput [scene.yaml] [seconds-per-side-per-round] [rounds] [surfaces]
 *
 * (`surfaces`: leave the media figure out.) Three sides, and on a scene of diffuse triangles (no
 * media, boundaries, spheres, shading normals or textures) the bare tracer's five rungs, each run for
 * the given CPU seconds per round:
 *   raw     random incoherent rays — origins uniform in the scene's bounding box, directions uniform on
 *           the sphere — through rtcIntersect1 alone (the yardstick of "murk reaches X % of raw Embree"),
 *           on the tree murk renders with (without the empty medium shapes and a scene's few spheres,
 *           which murk's host tests itself: render/accel.h);
 *   replay  the rays murk itself traced in a 4-spp render of the scene (recorded by host.c,
 *           murk_host_record_rays), traced again in the same order with the same calls: rtcIntersect1
 *           for camera, BSDF and boundary rays, rtcOccluded1 for shadow rays, a fresh context per ray as
 *           host.c makes it;
 *   bare    `path`'s algorithm (NEE by area with the power heuristic, cosine sampling, murk's roulette
 *           and slots) written straight against Embree, with nothing of murk's layers (bare_li): what a
 *           renderer without plugins reaches on this yardstick, with the scene's sampler (`bare`) and
 *           with independent numbers (`bare-pcg`); then the rungs towards murk, each adding one layer
 *           to the one before: `+host rays` (the host table's intersect() / occluded(), murk_hit),
 *           `+host lights` (sample_light_with() / light_pdf_with()), `+materials` (the material
 *           plugin's eval / pdf / sample in the shading frame). Each rung's image mean is printed
 *           beside murk's: they estimate the same image;
 *   murk    `murk render` with the scene's integrator at --threads 1 (camera rays, NEE shadow rays, BSDF
 *           rays, shading, sampling, film), its rays counted as murk counts them.
 * The Embree sides generate or convert their rays outside the timed part; the murk side times everything
 * murk does (per render too: thread start and film, small against a 1-s side).
 *
 * The machine's speed drifts (shared, turbo, neighbours), so the sides are measured in several short
 * interleaved rounds — raw, replay, the rungs, murk, then the same in reverse, ... — each round gives one
 * ratio per pair, and the median ratio is quoted with its spread (min and max over the rounds). Defaults:
 * 1 s, 9 rounds. Every side is timed in CPU seconds, not wall time, which on a shared machine counts the
 * other processes' time slices too: the Embree sides in the thread's (CLOCK_THREAD_CPUTIME_ID), murk in
 * the process's (CLOCK_PROCESS_CPUTIME_ID: its one render thread works while the main thread waits).
 *
 * Is it fair? Rays are counted the same way on every side: one Embree call, one ray. murk's path tracer
 * makes an occlusion query per shadow ray and, when it reports a hit in a scene with index-matched
 * boundaries, an intersection along the same segment to tell a surface from a boundary; both are rays,
 * counted once each by murk and replayed once each. But murk's rays are cheaper for Embree than the raw
 * side's — its camera rays are coherent and a third of its calls are occlusion queries cut at the light —
 * so the replay runs more rays per second than the raw side, and murk / raw flatters murk by that factor
 * (bench/throughput.md has it). murk / replay is the like-for-like ratio (the same Embree work on both
 * sides); it is also the share of murk's time spent inside Embree. Both are printed; the goal
 * (70 %) was stated against raw. On a scene the bare tracer supports, murk / bare (murk's rays per second
 * over the `bare` rung's, per round) is the yardstick of murk's layers: what the plugin design costs. bench/throughput.md has the figures and where the rest of murk's time
 * goes.
 *
 * Then the media figure, on scenes/cornell_smoke.yaml's cloud with the `delta` tracker (grey extinction):
 * free flights through the medium by the tracker plugin (m->vt->sample, with the core's majorant grid
 * walk and density lookups behind the host table) against a bare delta-tracking loop written here over
 * the same majorant grid (the host's walk and density, no plugin, no tracker helpers), on the same
 * segments with the same random numbers. Both take the same tentative collisions (checked: the flights
 * end at the same t), so the ratio of flights/s is the ratio of tracker steps/s; the bare loop's steps
 * (tentative collisions + majorant cells) per second are printed too. Interleaved rounds as above, timed
 * in the thread's CPU seconds (CLOCK_THREAD_CPUTIME_ID). */
#include "render/accel.h"
#include "render/camera.h"
#include "render/host.h"
#include "scene/scene.h"
#include "util/util.h"

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
    murk_vec3 lo, hi;
    murk_accel_bounds(s, &lo, &hi);
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
            r->ray.org_x = lo.x + (hi.x - lo.x) * murk_rng_float(&rng);
            r->ray.org_y = lo.y + (hi.y - lo.y) * murk_rng_float(&rng);
            r->ray.org_z = lo.z + (hi.z - lo.z) * murk_rng_float(&rng);
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

/* "median M %, spread A .. B %" of n ratios (sorts them); a static buffer. */
static const char *median_spread(double *r, int n)
{
    static char buf[96];
    qsort(r, (size_t)n, sizeof *r, cmp_double);
    double median = n % 2 ? r[n / 2] : 0.5 * (r[n / 2 - 1] + r[n / 2]);
    snprintf(buf, sizeof buf, "median %.1f %%, spread %.1f .. %.1f %%", 100.0 * median, 100.0 * r[0], 100.0 * r[n - 1]);
    return buf;
}

/* murk's rays/s over one time-limited render of the scene. */
static double murk_side(murk_scene *s, double seconds, int *spp, double *mean)
{
    murk_render_opts o = {.threads = 1, .time_limit = seconds};
    murk_render_result r;
    double t0 = proc_cpu_now();
    murk_render(s, &o, &r);
    double rps = (double)r.rays / (proc_cpu_now() - t0);
    *spp = r.spp;
    double sum = 0.0;
    for (size_t i = 0; i < 3 * (size_t)s->width * (size_t)s->height; i++)
        sum += r.rgb[i];
    *mean = sum / (3.0 * s->width * s->height);
    free(r.rgb);
    return rps;
}

/* ---- a bare path tracer: what a renderer without murk's layers reaches on this yardstick ---------
 * The `path` integrator's algorithm on a scene of diffuse triangles, written straight against Embree:
 * camera ray (murk_camera_sample), rtcIntersect1 / rtcOccluded1 called here, the hit point o + t d and the
 * triangle's stored normal, the albedo read once per shape before timing (the material's eval at normal
 * incidence, times pi), NEE by area with the power heuristic against cosine sampling, emission weighted
 * the same way, murk's Russian roulette (after 3 events, q = max(beta) / 0.3 clamped to [0.05, 1]: the default
 * rr_threshold), max depth
 * 64. No plugin calls, no murk_hit, no NaN checks, no boundaries, no media. Its numbers come from murk's
 * sampler: `bare` with the scene's (sobol), `bare-pcg` with independent numbers. Its image agrees with
 * murk's in expectation (the mean of both renders is printed). Rays counted per Embree call, as murk's. */
/* the path integrators' default rr_threshold (pathtracer.c), so that the bare paths are as long as murk's */
#define BARE_RR_THRESHOLD 0.3f

typedef struct bare_pt {
    const murk_scene *s;
    murk_rgb *albedo; /* per shape */
} bare_pt;

static int bare_supported(const murk_scene *s, murk_rgb **albedo)
{
    if (s->nmedia || s->nboundaries || s->camera_medium || s->ntextures) /* one albedo per shape: no textures */
        return 0;
    for (size_t i = 0; i < s->nmaterials; i++)
        if (strcmp(s->materials[i].plugin->desc->name, "diffuse") != 0)
            return 0;
    *albedo = murk_xmalloc(s->nshapes * sizeof **albedo);
    for (size_t i = 0; i < s->nshapes; i++) {
        const murk_shape *sh = &s->shapes[i];
        if (sh->type == MURK_SHAPE_SPHERE || !sh->material || sh->nrm)
            return free(*albedo), 0;
        murk_hit h = {0};
        h.n = h.ng = murk_v3(0, 0, 1);
        h.material = sh->material;
        murk_vec3 z = murk_v3(0, 0, 1);
        (*albedo)[i] = murk_rgb_scale(sh->material->vt->eval(sh->material->self, &h, z, z), MURK_PI);
    }
    return 1;
}

static float bare_power(float a, float b) { return a * a / (a * a + b * b); }

static murk_vec3 bare_offset(murk_vec3 p, murk_vec3 n)
{
    float m = murk_maxf(fabsf(p.x), murk_maxf(fabsf(p.y), fabsf(p.z)));
    return murk_madd(p, n, 1e-4f * murk_maxf(1.0f, m));
}

/* The rungs of the ladder from the bare tracer towards murk, each adding one of murk's layers to the one
 * before (all with the scene's sampler; BARE_PCG is BARE with independent numbers). */
enum { BARE_PCG, BARE, BARE_HOST_RAYS, BARE_HOST_LIGHTS, BARE_MATERIALS, BARE_RUNGS };
static const char *const bare_rung_name[BARE_RUNGS] = {"bare-pcg", "bare", "+host rays", "+host lights", "+materials"};

#if defined(__GNUC__)
#define BARE_INLINE inline __attribute__((always_inline))
#else
#define BARE_INLINE inline
#endif

/* One sample of the bare tracer at rung `rung` (a constant where it is called, so each rung is compiled
 * without the others' branches):
 *   BARE              rtcIntersect1 / rtcOccluded1 called here, the triangle's stored normal, o + t d,
 *                     the light chosen and sampled here, the diffuse BSDF written out;
 *   BARE_HOST_RAYS    rays through the host table's intersect() / occluded() (murk_hit filled, ray checks);
 *   BARE_HOST_LIGHTS  and NEE and the emission's MIS pdf through sample_light_with() / light_pdf_with();
 *   BARE_MATERIALS    and the BSDF through the material plugin (eval, pdf, sample in the shading frame,
 *                     on a copy of the hit), as pathtracer.c calls it.
 * What is left between the last rung and murk is pathtracer.c's generality (boundaries, media, delta
 * lobes, NaN checks, the lobe and hero slots) and render.c's loop (tiles, film). */
static BARE_INLINE murk_rgb bare_li(const bare_pt *bt, murk_ray cam, murk_rng *rng, uint64_t *rays, int rung)
{
    const murk_scene *s = bt->s;
    const murk_host *h = murk_host_table();
    murk_rgb L = murk_rgb1(0.0f), beta = murk_rgb1(1.0f);
    struct RTCRayHit rh;
    murk_hit hit;
    murk_vec3 o = cam.o, d = cam.d, prev_p = cam.o;
    float prev_pdf = 0.0f;
    int prev_cam = 1;
    for (int depth = 0;; depth++) {
        murk_vec3 ng, p;
        float t;
        const murk_shape *sh;
        if (rung >= BARE_HOST_RAYS) {
            murk_ray r = {o, d, 0.0f, INFINITY};
            ++*rays;
            if (!h->intersect(s, &r, &hit)) {
                L = murk_rgb_add(L, murk_rgb_mul(beta, s->background));
                break;
            }
            sh = &s->shapes[hit.geom];
            ng = hit.ng, p = hit.p, t = hit.t;
        } else {
            struct RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
            rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
            rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.time = 0.0f;
            rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(s->rtc, &ctx, &rh);
            ++*rays;
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                L = murk_rgb_add(L, murk_rgb_mul(beta, s->background));
                break;
            }
            sh = &s->shapes[rh.hit.geomID];
            const float *ngp = &sh->ng[3 * rh.hit.primID];
            ng = murk_v3(ngp[0], ngp[1], ngp[2]), t = rh.ray.tfar, p = murk_madd(o, d, t);
        }
        float cos_o = -murk_dot(ng, d);
        if (sh->light_base >= 0 && cos_o > 0.0f) { /* emission, MIS-weighted against the NEE that could find it */
            float w = 1.0f;
            if (!prev_cam) {
                float lpdf;
                if (rung >= BARE_HOST_LIGHTS) {
                    lpdf = h->light_pdf_with(s, prev_p, &hit, MURK_LIGHT_AREA);
                } else {
                    uint32_t prim = rung >= BARE_HOST_RAYS ? hit.prim : rh.hit.primID;
                    const murk_light *l = &s->lights[sh->light_base + (int32_t)prim];
                    lpdf = l->pmf * t * t / (cos_o * l->area);
                }
                w = bare_power(prev_pdf, lpdf);
            }
            L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(beta, sh->emission), w));
        }
        if (depth >= 64)
            break;
        murk_vec3 n = cos_o >= 0.0f ? ng : murk_neg(ng), tt, bb;
        murk_basis(n, &tt, &bb);
        murk_hit mh; /* the material's copy and wo in its frame (BARE_MATERIALS) */
        murk_vec3 wo_local = murk_v3(0.0f, 0.0f, 1.0f);
        if (rung >= BARE_MATERIALS)
            mh = hit, mh.n = n, wo_local = murk_to_local(murk_neg(d), tt, bb, n);
        murk_rgb albedo = bt->albedo[sh - s->shapes], f = murk_rgb_scale(albedo, MURK_INV_PI);
        murk_vec3 po = bare_offset(p, n);
        float u[3];
        murk_sample_seek(rng, 2u + (uint32_t)depth * 5u); /* the slots `path` uses (pathtracer.c) */
        u[0] = murk_sample_1d(rng); /* the light point: the partner of the camera jitter or last direction */
        murk_sample_2d_with(rng, depth ? 2u + (uint32_t)(depth - 1) * 5u + 2u : 0u, u + 1);
        murk_vec3 wi, q;
        float lpdf, dist, cosi = 0.0f;
        murk_rgb le = murk_rgb1(0.0f);
        int lit = 0;
        if (rung >= BARE_HOST_LIGHTS) {
            murk_light_sample ls;
            if (h->sample_light_with(s, p, u, MURK_LIGHT_AREA, &ls)) {
                wi = ls.wi, lpdf = ls.pdf, dist = ls.dist, le = ls.le, q = murk_madd(p, wi, dist);
                cosi = murk_dot(n, wi);
                lit = cosi > 0.0f;
            }
        } else if (s->nlights) { /* a light triangle by power, a point on it by area */
            size_t lo = 0, len = s->nlights;
            while (len > 1) {
                size_t half = len / 2;
                lo = s->light_cdf[lo + half] <= u[0] ? lo + half : lo;
                len -= half;
            }
            const murk_light *l = &s->lights[lo];
            float su = sqrtf(u[1]);
            q = murk_add(l->p0, murk_add(murk_mul(l->e1, su * (1.0f - u[2])), murk_mul(l->e2, su * u[2])));
            murk_vec3 dl = murk_sub(q, po);
            float dist2 = murk_dot(dl, dl);
            dist = sqrtf(dist2);
            wi = murk_mul(dl, 1.0f / dist);
            float cosl = -murk_dot(l->n, wi);
            cosi = murk_dot(n, wi);
            lpdf = l->pmf * dist2 / (cosl * l->area);
            le = l->le;
            lit = cosl > 0.0f && cosi > 0.0f;
        }
        if (lit) {
            murk_rgb fl = f;
            float bpdf = cosi * MURK_INV_PI;
            if (rung >= BARE_MATERIALS) {
                murk_vec3 wl = murk_to_local(wi, tt, bb, n);
                fl = sh->material->vt->eval(sh->material->self, &mh, wo_local, wl);
                bpdf = sh->material->vt->pdf(sh->material->self, &mh, wo_local, wl);
            }
            float end = 1e-4f * murk_maxf(1.0f, murk_maxf(fabsf(q.x), murk_maxf(fabsf(q.y), fabsf(q.z))));
            murk_vec3 dl = murk_sub(q, po);
            float len = murk_length(dl);
            int blocked;
            ++*rays;
            if (rung >= BARE_HOST_RAYS) {
                murk_ray sr = {po, murk_mul(dl, 1.0f / len), 0.0f, len - end};
                blocked = h->occluded(s, &sr);
            } else {
                struct RTCIntersectContext ctx;
                struct RTCRay sr = {po.x, po.y, po.z, 0.0f, wi.x, wi.y, wi.z, 0.0f, dist - end, ~0u, 0, 0};
                rtcInitIntersectContext(&ctx);
                rtcOccluded1(s->rtc, &ctx, &sr);
                blocked = sr.tfar < 0.0f;
            }
            if (!blocked)
                L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(murk_rgb_mul(beta, fl), le),
                                                   cosi * bare_power(lpdf, bpdf) / lpdf));
        }
        murk_sample_seek(rng, 2u + (uint32_t)depth * 5u + 2u);
        murk_sample_2d(rng, u);
        if (rung >= BARE_MATERIALS) {
            murk_bsdf_sample bs;
            u[2] = 0.5f;
            if (!sh->material->vt->sample(sh->material->self, &mh, wo_local, u, &bs) || !(bs.pdf > 0.0f))
                break;
            d = murk_from_local(bs.wi, tt, bb, n);
            prev_pdf = bs.pdf;
            beta = murk_rgb_mul(beta, murk_rgb_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
        } else {
            float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1], x = r * cosf(phi), y = r * sinf(phi);
            float z = sqrtf(murk_maxf(0.0f, 1.0f - x * x - y * y));
            if (z <= 0.0f)
                break;
            d = murk_from_local(murk_v3(x, y, z), tt, bb, n);
            prev_pdf = z * MURK_INV_PI;
            beta = murk_rgb_mul(beta, albedo); /* f cos / pdf */
        }
        o = po;
        prev_p = p;
        prev_cam = 0;
        if (depth + 1 > 3) {
            float qq = murk_maxf(0.05f, murk_minf(1.0f, murk_maxf(beta.c[0], murk_maxf(beta.c[1], beta.c[2])) / BARE_RR_THRESHOLD));
            murk_sample_seek(rng, 2u + (uint32_t)depth * 5u + 4u);
            if (murk_sample_1d(rng) >= qq)
                break;
            beta = murk_rgb_scale(beta, 1.0f / qq);
        }
    }
    return L;
}

/* Rung `rung`'s rays/s over whole 128x128 passes for about `seconds`; *mean gets its image's mean (over
 * the passes, all channels). */
static double bare_pt_side(const bare_pt *bt, int rung, double seconds, double *mean)
{
    const murk_scene *s = bt->s;
    uint64_t rays = 0, k = 0;
    double sum = 0.0, el, t0 = cpu_now();
    murk_scene tmp = *s; /* murk_camera_sample takes the sampler from the scene */
    tmp.sampler = rung == BARE_PCG ? MURK_SAMPLER_INDEPENDENT : s->sampler;
    do {
        for (int y = 0; y < s->height; y++)
            for (int x = 0; x < s->width; x++) {
                murk_rng rng;
                murk_ray cam;
                murk_rgb c;
                murk_camera_sample(&tmp, x, y, (uint32_t)k, &rng, &cam);
                switch (rung) { /* constant rungs: bare_li is compiled once for each */
                case BARE_PCG:
                case BARE: c = bare_li(bt, cam, &rng, &rays, BARE); break;
                case BARE_HOST_RAYS: c = bare_li(bt, cam, &rng, &rays, BARE_HOST_RAYS); break;
                case BARE_HOST_LIGHTS: c = bare_li(bt, cam, &rng, &rays, BARE_HOST_LIGHTS); break;
                default: c = bare_li(bt, cam, &rng, &rays, BARE_MATERIALS); break;
                }
                sum += (double)c.c[0] + c.c[1] + c.c[2];
            }
        k++;
        el = cpu_now() - t0;
    } while (el < seconds);
    *mean = sum / (3.0 * (double)k * s->width * s->height);
    return (double)rays / el;
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
    murk_vec3 lo, hi;
    murk_accel_bounds(s, &lo, &hi);
    const murk_host *h = murk_host_table();
    murk_rng rng;
    murk_rng_seed(&rng, 4, 5, 6);
    for (int i = 0; i < NSEG; i++) {
        murk_ray *r = &g->ray[i];
        float z = 1 - 2 * murk_rng_float(&rng), phi = 2 * MURK_PI * murk_rng_float(&rng), sz = sqrtf(1 - z * z);
        r->o = murk_v3(lo.x + (hi.x - lo.x) * murk_rng_float(&rng), lo.y + (hi.y - lo.y) * murk_rng_float(&rng),
                       lo.z + (hi.z - lo.z) * murk_rng_float(&rng));
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
    printf("tracker / bare loop: %s (%d flights ended elsewhere)\n", median_spread(ratio, rounds), mismatch);
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
    bare_pt bt = {s, NULL};
    int bare = bare_supported(s, &bt.albedo);
    printf("bare: %s\n", bare ? "`path`'s algorithm written straight against Embree, and the rungs towards "
                                "murk (bare_li)"
                              : "left out (the scene has media, boundaries, spheres, shading normals, textures or "
                                "non-diffuse materials)");
    printf("round  raw Mrays/s  replay Mrays/s  murk Mrays/s  murk/raw  murk/replay");
    for (int j = 0; bare && j < BARE_RUNGS; j++)
        printf("  %s/raw", bare_rung_name[j]);
    printf("\n");
    double *ratio = murk_xmalloc((3 + BARE_RUNGS) * (size_t)rounds * sizeof *ratio), *rratio = ratio + rounds,
           *bratio = rratio + rounds, /* bratio[j * rounds + k] */
        *lratio = bratio + BARE_RUNGS * (size_t)rounds; /* murk / bare (sobol): what murk's layers leave */
    double bmean[BARE_RUNGS] = {0}, mmean = 0.0;
    for (int k = 0; k < rounds; k++) {
        uint64_t nraw;
        int spp;
        double raw = 0.0, rep = 0.0, mr = 0.0, br[BARE_RUNGS] = {0}, m;
        /* the sides in turn, the order reversed every other round: raw, replay, bare rungs, murk */
        for (int i = 0; i < 3 + BARE_RUNGS; i++) {
            int side = k % 2 == 0 ? i : 2 + BARE_RUNGS - i;
            if (side == 0)
                raw = raw_embree(s, seconds, &nraw);
            else if (side == 1)
                rep = replay_side(s, &rp, seconds);
            else if (side == 2 + BARE_RUNGS)
                mr = murk_side(s, seconds, &spp, &m), mmean += m / rounds;
            else if (bare)
                br[side - 2] = bare_pt_side(&bt, side - 2, seconds, &m), bmean[side - 2] += m / rounds;
        }
        ratio[k] = mr / raw;
        rratio[k] = mr / rep;
        printf("%5d  %11.2f  %14.2f  %12.2f  %6.1f %%  %9.1f %%", k + 1, raw / 1e6, rep / 1e6, mr / 1e6, 100.0 * ratio[k],
               100.0 * rratio[k]);
        lratio[k] = bare ? mr / br[BARE] : 0.0; /* the bare tracer with the scene's sampler */
        for (int j = 0; bare && j < BARE_RUNGS; j++) {
            bratio[j * rounds + k] = br[j] / raw;
            printf("  %*.1f %%", (int)strlen(bare_rung_name[j]) + 2, 100.0 * bratio[j * rounds + k]);
        }
        printf("\n");
    }
    printf("murk / raw Embree (%s integrator): %s\n", s->integrator_plugin->desc->name, median_spread(ratio, rounds));
    printf("murk / replay of its own rays (Embree's share of murk's time): %s\n", median_spread(rratio, rounds));
    if (bare) {
        for (int j = 0; j < BARE_RUNGS; j++)
            printf("%s / raw Embree: %s\n", bare_rung_name[j], median_spread(bratio + j * rounds, rounds));
        printf("murk / bare (the layers' ratio: murk's rays per CPU second over the bare tracer's with the same "
               "sampler, per round): %s\n", median_spread(lratio, rounds));
        printf("image means (all channels, over the rounds): murk %.5f", mmean);
        for (int j = 0; j < BARE_RUNGS; j++)
            printf(", %s %.5f", bare_rung_name[j], bmean[j]);
        printf("\n");
        free(bt.albedo);
    }
    free(rp.rh);
    free(rp.occluded);
    free(ratio);
    murk_scene_free(s);
    return argc > 4 && !strcmp(argv[4], "surfaces") ? 0 : media_figure(seconds, rounds);
}
