/* volpath_common.h — the path tracer shared by the path, volpath and volpath_nee plugins (each plugin
 * is one .c file that includes this and chooses `nee` and `media`). Not a public header.
 *
 * Paths carry beta (RGB weight) and R (RGB pdf ratios, see murk/medium.h); a path that reaches
 * emission L adds beta * L / mean(R). A hero channel is chosen uniformly per path for the trackers
 * that sample per channel. Media are tracked through index-matched boundaries (shapes with no
 * material): crossing against the normal enters `interior`, along it leaves to `exterior`; the camera
 * starts in the scene's camera medium. Materials only reflect, so a surface never changes the medium.
 *
 * With nee = 1, every scattering vertex (surface or medium) also samples a light point, estimates the
 * transmittance to it with the media's transmittance() (ratio tracking) through any boundaries, and
 * weights the two strategies with the power heuristic on their directional pdfs (unbiased: the
 * weights depend on the direction only and sum to 1). With nee = 0 emission is found by BSDF / phase
 * sampling alone — a slower, independent estimator of the same image. With media = 0 (the surface
 * `path` integrator) media are ignored and boundaries passed straight through. Russian roulette after
 * rr_depth bounces on the path's largest channel weight, survivors divided by the survival
 * probability. */
#ifndef MURK_VOLPATH_COMMON_H
#define MURK_VOLPATH_COMMON_H

#include "murk/integrator.h"
#include "murk/material.h"
#include "murk/medium.h"

enum { P_MAX_DEPTH, P_RR_DEPTH, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_MAX_DEPTH] = {"max_depth", MURK_PARAM_INT, 0, {64, 0, 0}, NULL, NULL, 1, 100000,
                     "most scattering events (surface or medium) per path"},
    [P_RR_DEPTH] = {"rr_depth", MURK_PARAM_INT, 0, {3, 0, 0}, NULL, NULL, 0, 100000,
                    "scattering events before Russian roulette may end a path"},
};

typedef struct volpath {
    const murk_host *host;
    int max_depth, rr_depth;
} volpath;

static int volpath_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    if (host->size < sizeof(murk_host)) {
        snprintf(err, errlen, "this murk's host table lacks the media services");
        return -1;
    }
    volpath *v = host->alloc(sizeof *v);
    if (!v)
        return -1;
    v->host = host;
    v->max_depth = (int)p[P_MAX_DEPTH].f[0];
    v->rr_depth = (int)p[P_RR_DEPTH].f[0];
    *self = v;
    return 0;
}

static void volpath_destroy(void *self)
{
    volpath *v = self;
    if (v)
        v->host->free(v);
}

static float vp_maxabs(murk_vec3 p) { return murk_maxf(fabsf(p.x), murk_maxf(fabsf(p.y), fabsf(p.z))); }

static murk_vec3 vp_offset(murk_vec3 p, murk_vec3 n, murk_vec3 dir)
{
    float eps = 1e-4f * murk_maxf(1.0f, vp_maxabs(p));
    return murk_madd(p, n, murk_dot(n, dir) >= 0.0f ? eps : -eps);
}

static float vp_power(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

static float vp_mean(murk_rgb r) { return (r.c[0] + r.c[1] + r.c[2]) * (1.0f / 3.0f); }

/* Transmittance of a shadow ray from p to the light point q: 0 if a surface with a material blocks
 * the way, otherwise the product of the media's transmittance() estimates over the legs between
 * index-matched boundaries (with media = 0 boundaries are passed and media ignored, as the `path`
 * integrator's own paths do). m: the medium at p. offset_n: the normal to offset a surface point
 * along (a zero vector for a point inside a medium).
 *
 * Every leg is aimed at q itself: after a boundary the ray restarts just beyond it (offset along the
 * boundary's normal) with its direction and length recomputed towards q, and it stops 1e-4 x |q|
 * short of q. An offset origin is off the original line, so a leg that kept the first direction and
 * a length measured along it would reach a light parallel to the boundary early and count the light
 * itself as an occluder. */
static murk_rgb vp_shadow(const volpath *v, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 q,
                          const murk_medium *m, int media, const murk_path_ctx *ctx, murk_rng *rng)
{
    const murk_host *h = v->host;
    const float end_eps = 1e-4f * murk_maxf(1.0f, vp_maxabs(q));
    murk_rgb T = murk_rgb1(1.0f);
    murk_vec3 o = murk_dot(offset_n, offset_n) > 0.0f ? vp_offset(p, offset_n, murk_sub(q, p)) : p;
    for (int crossings = 0; crossings < 256; crossings++) {
        murk_vec3 d = murk_sub(q, o);
        float len = murk_length(d);
        if (!(len > end_eps))
            return T;
        murk_ray r;
        r.o = o;
        r.d = murk_mul(d, 1.0f / len);
        r.tmin = 0.0f;
        r.tmax = len - end_eps;
        if (!m && !h->occluded(scene, &r)) /* nothing at all in the way: the common case, cheaply */
            return T;
        murk_hit hit;
        int found = h->intersect(scene, &r, &hit);
        if (found && hit.material)
            return murk_rgb1(0.0f);
        if (m) {
            murk_ray s = r;
            s.tmax = found ? hit.t : r.tmax;
            T = murk_rgb_mul(T, m->vt->transmittance(m->self, &s, ctx, rng));
            if (murk_rgb_is_black(T))
                return T;
        }
        if (!found)
            return T;
        if (media)
            m = murk_dot(r.d, hit.ng) < 0.0f ? hit.interior : hit.exterior;
        o = vp_offset(hit.p, hit.ng, r.d);
    }
    return murk_rgb1(0.0f);
}

static murk_rgb volpath_li_impl(const volpath *v, const murk_scene *scene, const murk_ray *camera_ray, murk_rng *rng,
                                int nee, int media)
{
    const murk_host *h = v->host;
    murk_rgb L = murk_rgb1(0.0f), beta = murk_rgb1(1.0f), R = murk_rgb1(1.0f);
    murk_path_ctx ctx;
    ctx.hero = (int)(murk_rng_float(rng) * 3.0f);
    if (ctx.hero > 2)
        ctx.hero = 2;
    const murk_medium *medium = media ? h->camera_medium(scene) : NULL;
    murk_ray ray = *camera_ray;
    float prev_pdf = 0.0f;
    int prev_delta = 1, crossings = 0, depth = 0;
    murk_vec3 prev_p = ray.o;
    for (;;) {
        murk_hit hit;
        int found = h->intersect(scene, &ray, &hit);
        if (medium) {
            murk_ray seg = ray;
            seg.tmax = found ? hit.t : INFINITY;
            murk_medium_event ev;
            ctx.beta = beta;
            medium->vt->sample(medium->self, &seg, &ctx, rng, &ev);
            beta = murk_rgb_mul(beta, ev.weight);
            R = murk_rgb_mul(R, ev.pdf);
            if (murk_rgb_is_black(beta) || !(vp_mean(R) > 0.0f))
                break;
            if (ev.scattered) {
                if (depth >= v->max_depth)
                    break;
                murk_vec3 p = murk_madd(ray.o, ray.d, ev.t), wo = murk_neg(ray.d);
                float g = medium->data->g;
                if (nee) {
                    float ul[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
                    murk_light_sample ls;
                    if (h->sample_light(scene, p, ul, &ls)) {
                        float ph = h->phase_eval(g, wo, ls.wi);
                        murk_rgb T = vp_shadow(v, scene, p, murk_v3(0, 0, 0), murk_madd(p, ls.wi, ls.dist), medium, 1, &ctx, rng);
                        if (!murk_rgb_is_black(T)) {
                            float w = vp_power(ls.pdf, ph) * ph / ls.pdf / vp_mean(R);
                            L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(murk_rgb_mul(beta, T), ls.le), w));
                        }
                    }
                }
                float up[2] = {murk_rng_float(rng), murk_rng_float(rng)}, pdf;
                murk_vec3 wi = h->phase_sample(g, wo, up, &pdf);
                if (!(pdf > 0.0f))
                    break;
                /* HG is sampled exactly: phase / pdf = 1 */
                prev_pdf = pdf;
                prev_delta = 0;
                prev_p = p;
                ray.o = p;
                ray.d = wi;
                ray.tmin = 0.0f;
                ray.tmax = INFINITY;
                depth++;
                goto roulette;
            }
        }
        if (!found) {
            L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(beta, h->background(scene, ray.d)), 1.0f / vp_mean(R)));
            break;
        }
        {
            murk_vec3 wo_w = murk_neg(ray.d);
            if (!hit.material) { /* index-matched boundary: change medium, go straight on */
                if (++crossings > 1000)
                    break;
                if (media)
                    medium = murk_dot(ray.d, hit.ng) < 0.0f ? hit.interior : hit.exterior;
                ray.o = vp_offset(hit.p, hit.ng, ray.d);
                ray.tmin = 0.0f;
                ray.tmax = INFINITY;
                continue;
            }
            murk_rgb le = murk_hit_le(&hit, wo_w);
            if (!murk_rgb_is_black(le)) {
                float w = (nee && !prev_delta) ? vp_power(prev_pdf, h->light_pdf(scene, prev_p, &hit)) : 1.0f;
                L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(beta, le), w / vp_mean(R)));
            }
            if (depth >= v->max_depth)
                break;
            murk_vec3 ng = hit.ng, n = hit.n;
            if (murk_dot(ng, wo_w) < 0.0f) {
                ng = murk_neg(ng);
                n = murk_neg(n);
            }
            murk_vec3 t, b;
            murk_basis(n, &t, &b);
            murk_vec3 wo = murk_to_local(wo_w, t, b, n);
            if (wo.z <= 0.0f)
                wo.z = 1e-6f;
            const murk_material *m = hit.material;
            if (nee) {
                float ul[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
                murk_light_sample ls;
                if (h->sample_light(scene, hit.p, ul, &ls) && murk_dot(ls.wi, ng) > 0.0f) {
                    murk_vec3 wi = murk_to_local(ls.wi, t, b, n);
                    murk_rgb f = m->vt->eval(m->self, &hit, wo, wi);
                    if (!murk_rgb_is_black(f)) {
                        murk_rgb T = vp_shadow(v, scene, hit.p, ng, murk_madd(hit.p, ls.wi, ls.dist), medium, media,
                                               &ctx, rng);
                        if (!murk_rgb_is_black(T)) {
                            float w = vp_power(ls.pdf, m->vt->pdf(m->self, &hit, wo, wi));
                            float k = fabsf(wi.z) * w / ls.pdf / vp_mean(R);
                            L = murk_rgb_add(L, murk_rgb_mul(murk_rgb_mul(murk_rgb_mul(beta, f), T), murk_rgb_scale(ls.le, k)));
                        }
                    }
                }
            }
            float ub[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
            murk_bsdf_sample bs;
            if (!m->vt->sample(m->self, &hit, wo, ub, &bs) || !(bs.pdf > 0.0f))
                break;
            murk_vec3 wi_w = murk_from_local(bs.wi, t, b, n);
            if (murk_dot(wi_w, ng) <= 0.0f)
                break;
            beta = murk_rgb_mul(beta, murk_rgb_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
            prev_pdf = bs.pdf;
            prev_delta = bs.delta;
            prev_p = hit.p;
            ray.o = vp_offset(hit.p, ng, wi_w);
            ray.d = wi_w;
            ray.tmin = 0.0f;
            ray.tmax = INFINITY;
            depth++;
        }
    roulette:
        if (depth > v->rr_depth) {
            float mr = vp_mean(R);
            float q = murk_minf(1.0f, murk_maxf(fabsf(beta.c[0]), murk_maxf(fabsf(beta.c[1]), fabsf(beta.c[2]))) / mr);
            if (q < 0.05f)
                q = 0.05f;
            if (murk_rng_float(rng) >= q)
                break;
            beta = murk_rgb_scale(beta, 1.0f / q);
        }
        if (murk_rgb_is_black(beta))
            break;
    }
    return L;
}

#endif
