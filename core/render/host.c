/* host.c — the services table plugins receive: memory, logging, textures, and the scene queries
 * integrators use (closest hit, occlusion, light sampling and its pdf, background). Rays and the cost
 * counters (murk/counters.h) are counted per thread and summed by render.c when a thread's work ends. */
#include "render/host.h"
#include "media/media.h"
#include "render/accel.h"
#include "render/lights.h"
#include "scene/scene.h"
#include "scene/texture.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* The rays being recorded (murk_host_record_rays), or NULL: one predictable branch per ray otherwise. */
static murk_ray_record *ray_record;

void murk_host_record_rays(murk_ray_record *rec) { ray_record = rec; }

static void record_ray(const murk_ray *r, int occluded)
{
    size_t k = atomic_fetch_add(&ray_record->n, 1);
    if (k < ray_record->cap) {
        ray_record->ray[k] = *r;
        ray_record->occluded[k] = (unsigned char)occluded;
    }
}

uint64_t murk_host_thread_rays(void) { return murk_tally()->rays; }

void murk_host_thread_reset(void)
{
    murk_thread_counters_reset(); /* the rays too */
}

static void *host_alloc(size_t n) { return calloc(1, n ? n : 1); }
static void host_free(void *p) { free(p); }

static void host_log(int level, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    murk_log(level, "%s", buf);
}

static void host_tex_eval(const murk_texture *t, const murk_hit *hit, float out[3]) { murk_texture_eval(t, hit, out); }

/* The point of triangle (a, b, c) at barycentrics (b1, b2). */
static murk_vec3 tri_point(murk_vec3 a, murk_vec3 b, murk_vec3 c, float b1, float b2)
{
    float b0 = 1.0f - b1 - b2;
    return murk_add(murk_add(murk_mul(a, b0), murk_mul(b, b1)), murk_mul(c, b2));
}

/* The (u, v) of a triangle whose corners have t0, t1, t2, at barycentrics (b1, b2). */
static void tri_uv(const float *t0, const float *t1, const float *t2, float b1, float b2, murk_hit *h)
{
    float b0 = 1.0f - b1 - b2;
    h->u = b0 * t0[0] + b1 * t1[0] + b2 * t2[0];
    h->v = b0 * t0[1] + b1 * t1[1] + b2 * t2[1];
}

/* What a hit on shape sh takes from the shape once t, p, the normals, (u, v), geom and prim are set. */
static void hit_shape_fields(const murk_shape *sh, murk_hit *h)
{
    h->material = sh->material;
    h->interior = sh->interior;
    h->exterior = sh->exterior;
    h->emission = sh->emission;
    if (sh->emission_tex) {
        float t[3];
        murk_texture_eval(sh->emission_tex, h, t);
        h->emission = murk_rgb3(sh->emission.c[0] * t[0], sh->emission.c[1] * t[1], sh->emission.c[2] * t[2]);
    }
    h->light = sh->light_base < 0 ? -1 : sh->light_base + (sh->type == MURK_SHAPE_SPHERE ? 0 : (int32_t)h->prim);
}

static void fill_hit(const murk_scene *s, const murk_ray *r, const struct RTCRayHit *rh, murk_hit *h)
{
    const murk_shape *sh = &s->shapes[rh->hit.geomID];
    h->t = rh->ray.tfar;
    h->geom = rh->hit.geomID;
    h->prim = rh->hit.primID;
    if (sh->type == MURK_SHAPE_SPHERE) {
        murk_vec3 p = murk_madd(r->o, r->d, h->t);
        murk_vec3 n = murk_normalize(murk_sub(p, sh->center));
        h->p = murk_madd(sh->center, n, sh->radius); /* re-project onto the surface */
        h->ng = h->n = n;
        h->u = 0.5f + atan2f(n.z, n.x) * (0.5f * MURK_INV_PI);
        h->v = acosf(murk_minf(1.0f, murk_maxf(-1.0f, n.y))) * MURK_INV_PI;
    } else {
        /* the corners' indices read once, as size_t: each corner's floats are then one address plus a
         * constant offset (no reloads after the stores to *h, no 32-bit index arithmetic per float) */
        const uint32_t *ix = &sh->idx[3 * (size_t)h->prim];
        const size_t i0 = ix[0], i1 = ix[1], i2 = ix[2];
        float b1 = rh->hit.u, b2 = rh->hit.v, b0 = 1.0f - b1 - b2;
        murk_vec3 a = murk_shape_vertex(sh, i0), b = murk_shape_vertex(sh, i1), c = murk_shape_vertex(sh, i2);
        h->p = tri_point(a, b, c, b1, b2);
        const float *ng = sh->ng ? &sh->ng[3 * (size_t)h->prim] : NULL;
        h->ng = ng ? murk_v3(ng[0], ng[1], ng[2]) : murk_triangle_normal(a, b, c);
        h->n = h->ng;
        if (sh->nrm) {
            const float *n0 = &sh->nrm[3 * i0], *n1 = &sh->nrm[3 * i1], *n2 = &sh->nrm[3 * i2];
            murk_vec3 ns = murk_normalize(murk_v3(b0 * n0[0] + b1 * n1[0] + b2 * n2[0], b0 * n0[1] + b1 * n1[1] + b2 * n2[1],
                                                  b0 * n0[2] + b1 * n1[2] + b2 * n2[2]));
            if (murk_dot(ns, ns) > 0.5f)
                h->n = murk_dot(ns, h->ng) < 0.0f ? murk_neg(ns) : ns;
        }
        if (sh->uv) {
            tri_uv(&sh->uv[2 * i0], &sh->uv[2 * i1], &sh->uv[2 * i2], b1, b2, h);
        } else {
            h->u = b1;
            h->v = b2;
        }
    }
    hit_shape_fields(sh, h);
}

static void to_embree(const murk_ray *r, struct RTCRay *er)
{
    er->org_x = r->o.x, er->org_y = r->o.y, er->org_z = r->o.z;
    er->dir_x = r->d.x, er->dir_y = r->d.y, er->dir_z = r->d.z;
    er->tnear = r->tmin;
    er->tfar = r->tmax;
    er->time = 0.0f;
    er->mask = 0xffffffffu;
    er->id = 0;
    er->flags = 0;
}

/* Embree asserts (SIGABRT) on a ray it cannot carry: an origin or direction beyond 1.8e18 or not finite,
 * a NaN or negative tnear, a NaN tfar. Scene coordinates stay within MURK_MAX_COORD (limit.h), but a
 * path may still wander far out through an unbounded medium: such a ray is not traced (it hits
 * nothing and nothing occludes it), and murk says so once. */
_Static_assert(sizeof(murk_ray) == 8 * sizeof(float), "murk_ray is o, d, tmin, tmax: 8 floats");

static int ray_traceable(const murk_ray *r)
{
#if defined(__SSE2__)
    /* the ray as two vectors (murk_ray is 8 floats: o, d, tmin, tmax), each lane between a lower and an
     * upper bound; every comparison is false for NaN, like the scalar test:
     *   ox oy oz dx   in [-1e18, 1e18]  (|x| <= 1e18)
     *   dy dz         in [-1e18, 1e18]
     *   tmin          in [0, inf]       (tmin >= 0 and not NaN)
     *   tmax          in [-inf, inf]    (not NaN) */
    const __m128 lo_max = _mm_set1_ps(1e18f), lo_min = _mm_set1_ps(-1e18f);
    const __m128 hi_max = _mm_setr_ps(1e18f, 1e18f, INFINITY, INFINITY);
    const __m128 hi_min = _mm_setr_ps(-1e18f, -1e18f, 0.0f, -INFINITY);
    __m128 lo = _mm_loadu_ps(&r->o.x), hi = _mm_loadu_ps(&r->d.y); /* ox oy oz dx, dy dz tmin tmax */
    __m128 in = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(lo_min, lo), _mm_cmple_ps(lo, lo_max)),
                           _mm_and_ps(_mm_cmple_ps(hi_min, hi), _mm_cmple_ps(hi, hi_max)));
    int ok = _mm_movemask_ps(in) == 0xf;
#else
    const float big = 1e18f;
    int ok = fabsf(r->o.x) <= big && fabsf(r->o.y) <= big && fabsf(r->o.z) <= big && fabsf(r->d.x) <= big &&
             fabsf(r->d.y) <= big && fabsf(r->d.z) <= big && r->tmin >= 0.0f && r->tmin <= INFINITY && !isnan(r->tmax);
#endif
    if (!ok)
        murk_warn_once("a ray beyond the range Embree accepts (origin or direction beyond 1e18, or NaN) was not "
                       "traced: a path left the scene through an unbounded medium");
    return ok;
}

/* Where a ray from a point o inside sphere (center, radius) leaves it: the far root of |o + t d - c|^2 =
 * r^2, in the form that does not cancel (Numerical Recipes §5.6); +inf when o is not strictly inside. */
static float sphere_exit(murk_vec3 center, float radius, const murk_ray *r)
{
    murk_vec3 oc = murk_sub(r->o, center);
    float c = murk_dot(oc, oc) - radius * radius, a = murk_dot(r->d, r->d), b = murk_dot(r->d, oc);
    if (!(c < 0.0f) || !(a > 0.0f))
        return INFINITY;
    float q = sqrtf(b * b - a * c);
    return b > 0.0f ? -c / (b + q) : (q - b) / a;
}

/* Where a ray from a point inside box b leaves it: the nearest of the three planes ahead of it, and in
 * *face which (2a for the +a side, 2a + 1 for -a; -1 if the direction is 0). */
static float box_exit(const murk_empty_shape *b, const murk_ray *r, int *face)
{
    float te = INFINITY;
    *face = -1;
    for (int a = 0; a < 3; a++) {
        float d = murk_v3_get(r->d, a), oa = murk_v3_get(r->o, a);
        float ta = d > 0.0f ? (murk_v3_get(b->hi, a) - oa) / d : (d < 0.0f ? (murk_v3_get(b->lo, a) - oa) / d : INFINITY);
        if (ta < te) {
            te = ta;
            *face = 2 * a + (d > 0.0f ? 0 : 1);
        }
    }
    return te;
}

/* A ray from inside an empty medium shape (accel.h): the shape, the distance *t to where the ray leaves
 * it and, for a box, the face it leaves by (-1 for a sphere); NULL when no such shape holds the origin,
 * or when the exit lies at or before tmin (a ray leaving from its surface): Embree decides then. */
static const murk_empty_shape *shape_exit(const murk_scene *s, const murk_ray *r, float *t, int *face)
{
    for (size_t i = 0; i < s->nempty_shapes; i++) {
        const murk_empty_shape *b = &s->empty_shapes[i];
        const murk_vec3 o = r->o;
        if (!(o.x >= b->lo.x && o.x <= b->hi.x && o.y >= b->lo.y && o.y <= b->hi.y && o.z >= b->lo.z &&
              o.z <= b->hi.z))
            continue;
        *face = -1;
        float te = b->sphere ? sphere_exit(b->center, b->radius, r) : box_exit(b, r, face);
        if (b->sphere && isinf(te))
            continue; /* in the sphere's bounds, not inside it */
        if (!(te > r->tmin) || isinf(te))
            return NULL;
        *t = te;
        return b;
    }
    return NULL;
}

/* Where a ray from a point outside sphere (center, radius) enters it: the near root, c / (q - b) (the
 * form that does not cancel); +inf when it does not meet it ahead. */
static float sphere_entry(murk_vec3 center, float radius, const murk_ray *r)
{
    murk_vec3 oc = murk_sub(r->o, center);
    float c = murk_dot(oc, oc) - radius * radius, a = murk_dot(r->d, r->d), b = murk_dot(r->d, oc);
    float disc = b * b - a * c;
    if (!(c > 0.0f) || !(b < 0.0f) || !(disc >= 0.0f))
        return INFINITY;
    return c / (sqrtf(disc) - b);
}

/* Where a ray (origin o, inverse direction inv) from a point outside box b enters it: the slab test, the
 * last plane entered if before the first left; +inf when it does not meet it ahead. Branch-free: every
 * ray that reaches Embree takes it (a zero direction component gives +-inf per slab, or NaN for an
 * origin exactly on that slab's plane, where the ray runs in the plane and either answer is right). */
static float box_entry(const murk_empty_shape *b, murk_vec3 o, murk_vec3 inv)
{
    float x0 = (b->lo.x - o.x) * inv.x, x1 = (b->hi.x - o.x) * inv.x;
    float y0 = (b->lo.y - o.y) * inv.y, y1 = (b->hi.y - o.y) * inv.y;
    float z0 = (b->lo.z - o.z) * inv.z, z1 = (b->hi.z - o.z) * inv.z;
    float tin = murk_maxf(murk_maxf(murk_minf(x0, x1), murk_minf(y0, y1)), murk_minf(z0, z1));
    float tout = murk_minf(murk_minf(murk_maxf(x0, x1), murk_maxf(y0, y1)), murk_maxf(z0, z1));
    return tin <= tout ? tin : INFINITY;
}

/* The face (box_exit's numbering) of box b through which the ray (o, inv) enters it at tin: the slab
 * whose near plane is tin, entered from its -a side when moving towards +a. */
static int box_entry_face(const murk_empty_shape *b, murk_vec3 o, murk_vec3 inv, float tin)
{
    int face = -1;
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        float ia = murk_v3_get(inv, a), oa = murk_v3_get(o, a);
        float t = ((ia > 0.0f ? murk_v3_get(b->lo, a) : murk_v3_get(b->hi, a)) - oa) * ia;
        if (fabsf(t - tin) < best) {
            best = fabsf(t - tin);
            face = 2 * a + (ia > 0.0f ? 1 : 0);
        }
    }
    return face;
}

/* The empty medium shape that a ray from outside all of them meets first within (tmin, tmax], the
 * distance *t and (a box) the face *face; NULL if none. */
static const murk_empty_shape *shape_entry(const murk_scene *s, const murk_ray *r, float tmax, float *t, int *face)
{
    const murk_empty_shape *first = NULL;
    const murk_vec3 inv = murk_v3(1.0f / r->d.x, 1.0f / r->d.y, 1.0f / r->d.z);
    for (size_t i = 0; i < s->nempty_shapes; i++) {
        const murk_empty_shape *b = &s->empty_shapes[i];
        float te = b->sphere ? sphere_entry(b->center, b->radius, r) : box_entry(b, r->o, inv);
        if (te > r->tmin && te <= tmax && te < INFINITY) { /* +inf: it misses */
            first = b;
            tmax = *t = te;
        }
    }
    if (first)
        *face = first->sphere ? -1 : box_entry_face(first, r->o, inv, *t);
    return first;
}

/* The first crossing of sphere (center, radius) by r within (tmin, tmax], or +inf: the centre's foot on
 * the line and the half chord from the perpendicular distance, which does not cancel for a ray far from
 * a small sphere (Haines, Günther, Akenine-Möller 2019, "Precision Improvements for Ray/Sphere
 * Intersection", Ray Tracing Gems ch. 7), as Embree's sphere test does; from inside, the far crossing. */
static float sphere_first(murk_vec3 center, float radius, const murk_ray *r, float tmax)
{
    murk_vec3 oc = murk_sub(center, r->o);
    float inv_a = 1.0f / murk_dot(r->d, r->d), td = murk_dot(oc, r->d) * inv_a;
    murk_vec3 perp = murk_sub(oc, murk_mul(r->d, td));
    float h2 = (radius * radius - murk_dot(perp, perp)) * inv_a;
    if (!(h2 >= 0.0f))
        return INFINITY;
    float h = sqrtf(h2), t0 = td - h, t1 = td + h;
    if (t0 > r->tmin && t0 <= tmax)
        return t0;
    return t1 > r->tmin && t1 <= tmax ? t1 : INFINITY;
}

/* The first of the scene's few spheres (accel.h) that r crosses within (tmin, tmax]: its distance, +inf if
 * none; *geom its shape. */
static float few_spheres_first(const murk_scene *s, const murk_ray *r, float tmax, uint32_t *geom)
{
    float first = INFINITY;
    for (size_t i = 0; i < s->nfew_spheres; i++) {
        const murk_shape *sh = &s->shapes[s->few_spheres[i]];
        float t = sphere_first(sh->center, sh->radius, r, tmax);
        if (t < first) {
            first = tmax = t;
            *geom = s->few_spheres[i];
        }
    }
    return first;
}

/* Barycentrics (b1, b2) of p in box triangle bt, clamped into the triangle; returns the smallest of the
 * three before clamping (negative: p lies outside by that much). */
static float barycentrics(const murk_box_tri *bt, murk_vec3 p, float *b1, float *b2)
{
    murk_vec3 q = murk_sub(p, bt->a);
    float u = murk_dot(q, bt->g1), v = murk_dot(q, bt->g2);
    float least = murk_minf(1.0f - u - v, murk_minf(u, v));
    u = murk_minf(1.0f, murk_maxf(0.0f, u));
    *b1 = u;
    *b2 = murk_minf(1.0f - u, murk_maxf(0.0f, v));
    return least;
}

/* The hit where r meets sphere shape geom at t: its only primitive, as Embree reports it (fill_hit). */
static void sphere_hit(const murk_scene *s, const murk_ray *r, uint32_t geom, float t, murk_hit *h)
{
    struct RTCRayHit rh;
    rh.ray.tfar = t;
    rh.hit.geomID = geom;
    rh.hit.primID = 0;
    rh.hit.u = rh.hit.v = 0.0f;
    fill_hit(s, r, &rh, h);
}

/* The hit where r meets shape b at t (a box: on face f), leaving or entering it, as Embree would report
 * it: a sphere's only primitive (fill_hit); a box face's triangle that holds the point (the first unless
 * the point lies outside it) and its barycentrics, the rest as fill_hit computes it from the face's own
 * copy of that triangle (accel.h). */
static void shape_hit(const murk_scene *s, const murk_ray *r, const murk_empty_shape *b, float t, int f, murk_hit *h)
{
    if (b->sphere) {
        sphere_hit(s, r, b->geom, t, h);
        return;
    }
    float u, v, u1, v1;
    murk_vec3 p = murk_madd(r->o, r->d, t);
    const murk_box_tri *bt = &b->tri[f][0];
    float least = barycentrics(bt, p, &u, &v);
    if (least < 0.0f && barycentrics(&b->tri[f][1], p, &u1, &v1) > least) {
        bt = &b->tri[f][1];
        u = u1;
        v = v1;
    }
    h->t = t;
    h->geom = b->geom;
    h->prim = bt->prim;
    h->p = tri_point(bt->a, bt->b, bt->c, u, v);
    h->ng = h->n = bt->ng;
    tri_uv(&bt->uv[0], &bt->uv[2], &bt->uv[4], u, v, h);
    hit_shape_fields(&s->shapes[b->geom], h);
}

static int host_intersect(const murk_scene *s, const murk_ray *r, murk_hit *h)
{
    if (!ray_traceable(r))
        return 0;
    float te;
    int face;
    const murk_empty_shape *b = s->nempty_shapes ? shape_exit(s, r, &te, &face) : NULL;
    if (b) {
        if (!(te <= r->tmax))
            return 0;
        shape_hit(s, r, b, te, face, h);
        return 1;
    }
    /* the empty shapes are not in Embree's tree (accel.h): the first one the ray enters is the answer
     * unless Embree finds a surface before it, so Embree searches only up to there */
    b = s->nempty_shapes ? shape_entry(s, r, r->tmax, &te, &face) : NULL;
    murk_ray asked = *r; /* what Embree is asked (and a recording replays) */
    if (b)
        asked.tmax = te;
    /* so are a scene's few spheres: the first one crossed before that point is the answer unless Embree
     * finds a surface before it */
    uint32_t sg = 0;
    float ts = s->nfew_spheres ? few_spheres_first(s, r, asked.tmax, &sg) : INFINITY;
    if (ts < INFINITY)
        asked.tmax = ts;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    to_embree(&asked, &rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s->rtc, &ctx, &rh);
    murk_tally()->rays++;
    if (ray_record)
        record_ray(&asked, 0);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID && ts < INFINITY) {
        sphere_hit(s, r, sg, ts, h);
        return 1;
    }
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        if (!b)
            return 0;
        shape_hit(s, r, b, te, face, h);
        return 1;
    }
    fill_hit(s, r, &rh, h);
    return 1;
}

static int host_occluded(const murk_scene *s, const murk_ray *r)
{
    if (!ray_traceable(r))
        return 0;
    float te;
    int face;
    if (s->nempty_shapes && shape_exit(s, r, &te, &face)) /* nothing inside: only its own surface occludes */
        return te <= r->tmax;
    if (s->nempty_shapes && shape_entry(s, r, r->tmax, &te, &face)) /* not in Embree's tree (accel.h) */
        return 1;
    uint32_t sg;
    if (s->nfew_spheres && few_spheres_first(s, r, r->tmax, &sg) < INFINITY) /* nor are these */
        return 1;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay er;
    to_embree(r, &er);
    rtcOccluded1(s->rtc, &ctx, &er);
    murk_tally()->rays++;
    if (ray_record)
        record_ray(r, 1);
    return er.tfar < 0.0f;
}

/* Light sampling lives in lights.c. An integrator older than MURK_ABI_MINOR_LIGHTS holds a shorter
 * murk_light_sample (no flags): it gets that much, filled from a whole one. */
static int host_sample_light_with(const murk_scene *s, murk_vec3 p, const float u[3], int strategy,
                                  murk_light_sample *ls)
{
    if (!s->legacy_lights)
        return murk_lights_sample(s, p, u, strategy, ls);
    murk_light_sample whole;
    int ok = murk_lights_sample(s, p, u, strategy, &whole);
    memcpy(ls, &whole, MURK_LIGHT_SAMPLE_SIZE_1_6);
    return ok;
}

/* 1.3's services are the area strategy. */
static int host_sample_light(const murk_scene *s, murk_vec3 p, const float u[3], murk_light_sample *ls)
{
    return host_sample_light_with(s, p, u, MURK_LIGHT_AREA, ls);
}

static float host_light_pdf(const murk_scene *s, murk_vec3 p, const murk_hit *h)
{
    return murk_lights_pdf(s, p, h, MURK_LIGHT_AREA);
}


static const murk_medium *host_camera_medium(const murk_scene *s) { return s->camera_medium; }

static size_t host_boundaries(const murk_scene *s) { return s->nboundaries; }

static const murk_host host_table = {
    .size = sizeof(murk_host),
    .abi_major = MURK_ABI_MAJOR,
    .abi_minor = MURK_ABI_MINOR,
    .alloc = host_alloc,
    .free = host_free,
    .log = host_log,
    .tex_eval = host_tex_eval,
    .intersect = host_intersect,
    .occluded = host_occluded,
    .sample_light = host_sample_light,
    .light_pdf = host_light_pdf,
    .background = murk_lights_background,
    .camera_medium = host_camera_medium,
    .density = murk_media_density,
    .walk_init = murk_media_walk_init,
    .walk_next = murk_media_walk_next,
    .warn_once = murk_warn_once,
    .phase_eval = murk_phase_hg_eval,
    .phase_sample = murk_phase_hg_sample,
    .counters = murk_media_counters,
    .sample_light_with = host_sample_light_with,
    .light_pdf_with = murk_lights_pdf,
    .boundaries = host_boundaries,
    .environment_pdf = murk_lights_environment_pdf,
    .medium_phase_eval = murk_media_phase_eval,
    .medium_phase_sample = murk_media_phase_sample,
    .albedo = murk_media_albedo,
    .emission = murk_media_emission,
};

/* Exported for libmurklab: murk check calls the methods of the plugins it checks with the real table. */
MURK_API const murk_host *murk_host_table(void) { return &host_table; }
