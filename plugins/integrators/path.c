/* path — unidirectional surface path tracing with next-event estimation.
 *
 * Parameters
 *   max_depth  int in [1, 100000], default 64: the most bounces a path may take (1 = direct light only).
 *   rr_depth   int in [0, 100000], default 3: bounces before Russian roulette may end a path; the
 *              survival probability is min(1, max throughput channel), at least 0.05, and survivors are
 *              divided by it, so roulette adds noise but no bias.
 *
 * At every surface it samples one light point (host->sample_light) and one BSDF direction, and weights
 * both with the power heuristic (Veach 1995); emission found by a delta BSDF sample or by the camera ray
 * is taken with weight 1. The constant background is reached by BSDF sampling only (it is not a light
 * that NEE samples). Index-matched medium boundaries (shapes with no material) are passed through:
 * this integrator ignores media — use volpath or volpath_nee for them. */
#include "murk/integrator.h"
#include "murk/material.h"

enum { P_MAX_DEPTH, P_RR_DEPTH, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_MAX_DEPTH] = {"max_depth", MURK_PARAM_INT, 0, {64, 0, 0}, NULL, NULL, 1, 100000,
                     "most bounces per path (1 = direct lighting only)"},
    [P_RR_DEPTH] = {"rr_depth", MURK_PARAM_INT, 0, {3, 0, 0}, NULL, NULL, 0, 100000,
                    "bounces before Russian roulette may end a path"},
};

typedef struct path {
    const murk_host *host;
    int max_depth, rr_depth;
} path;

static int path_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    path *pt = host->alloc(sizeof *pt);
    if (!pt)
        return -1;
    pt->host = host;
    pt->max_depth = (int)p[P_MAX_DEPTH].f[0];
    pt->rr_depth = (int)p[P_RR_DEPTH].f[0];
    *self = pt;
    return 0;
}

static void path_destroy(void *self)
{
    path *pt = self;
    if (pt)
        pt->host->free(pt);
}

/* Origin for a ray leaving p on the side of n that dir points to. */
static murk_vec3 offset_origin(murk_vec3 p, murk_vec3 n, murk_vec3 dir)
{
    float m = murk_maxf(fabsf(p.x), murk_maxf(fabsf(p.y), fabsf(p.z)));
    float eps = 1e-4f * murk_maxf(1.0f, m);
    return murk_madd(p, n, murk_dot(n, dir) >= 0.0f ? eps : -eps);
}

static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

static murk_rgb path_li(const void *self, const murk_scene *scene, const murk_ray *camera_ray, murk_rng *rng)
{
    const path *pt = self;
    const murk_host *h = pt->host;
    murk_rgb L = murk_rgb1(0.0f), beta = murk_rgb1(1.0f);
    murk_ray ray = *camera_ray;
    float prev_pdf = 0.0f;
    int prev_delta = 1, crossings = 0;
    murk_vec3 prev_p = ray.o;
    for (int depth = 0;;) {
        murk_hit hit;
        if (!h->intersect(scene, &ray, &hit)) {
            L = murk_rgb_add(L, murk_rgb_mul(beta, h->background(scene, ray.d)));
            break;
        }
        murk_vec3 wo_w = murk_neg(ray.d);
        if (!hit.material) { /* medium boundary: continue straight on */
            if (++crossings > 1000)
                break;
            ray.o = offset_origin(hit.p, hit.ng, ray.d);
            ray.tmin = 0.0f;
            ray.tmax = INFINITY;
            continue;
        }
        murk_rgb le = murk_hit_le(&hit, wo_w);
        if (!murk_rgb_is_black(le)) {
            float w = 1.0f;
            if (!prev_delta)
                w = power_heuristic(prev_pdf, h->light_pdf(scene, prev_p, &hit));
            L = murk_rgb_add(L, murk_rgb_scale(murk_rgb_mul(beta, le), w));
        }
        if (depth >= pt->max_depth)
            break;
        /* shading frame on the side of wo (two-sided materials) */
        murk_vec3 ng = hit.ng, n = hit.n;
        if (murk_dot(ng, wo_w) < 0.0f) {
            ng = murk_neg(ng);
            n = murk_neg(n);
        }
        murk_vec3 t, b;
        murk_basis(n, &t, &b);
        murk_vec3 wo = murk_to_local(wo_w, t, b, n);
        if (wo.z <= 0.0f) /* shading normal disagrees with the geometry: nothing sensible to do */
            wo.z = 1e-6f;
        const murk_material *m = hit.material;

        /* next-event estimation */
        float ul[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
        murk_light_sample ls;
        if (h->sample_light(scene, hit.p, ul, &ls) && murk_dot(ls.wi, ng) > 0.0f) {
            murk_vec3 wi = murk_to_local(ls.wi, t, b, n);
            murk_rgb f = m->vt->eval(m->self, &hit, wo, wi);
            if (!murk_rgb_is_black(f)) {
                murk_ray sr;
                sr.o = offset_origin(hit.p, ng, ls.wi);
                sr.d = ls.wi;
                sr.tmin = 0.0f;
                sr.tmax = ls.dist * (1.0f - 1e-3f);
                if (!h->occluded(scene, &sr)) {
                    float w = power_heuristic(ls.pdf, m->vt->pdf(m->self, &hit, wo, wi));
                    float k = fabsf(wi.z) * w / ls.pdf;
                    L = murk_rgb_add(L, murk_rgb_mul(murk_rgb_mul(beta, f), murk_rgb_scale(ls.le, k)));
                }
            }
        }

        /* BSDF sampling */
        float ub[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
        murk_bsdf_sample bs;
        if (!m->vt->sample(m->self, &hit, wo, ub, &bs) || !(bs.pdf > 0.0f))
            break;
        murk_vec3 wi_w = murk_from_local(bs.wi, t, b, n);
        if (murk_dot(wi_w, ng) <= 0.0f) /* reflection only: below the geometric surface */
            break;
        beta = murk_rgb_mul(beta, murk_rgb_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_p = hit.p;
        depth++;
        if (depth > pt->rr_depth) {
            float q = murk_minf(1.0f, murk_rgb_max(beta));
            if (q < 0.05f)
                q = 0.05f;
            if (murk_rng_float(rng) >= q)
                break;
            beta = murk_rgb_scale(beta, 1.0f / q);
        }
        if (murk_rgb_is_black(beta))
            break;
        ray.o = offset_origin(hit.p, ng, wi_w);
        ray.d = wi_w;
        ray.tmin = 0.0f;
        ray.tmax = INFINITY;
    }
    return L;
}

static const murk_integrator_vt vt = {sizeof(murk_integrator_vt), path_create, path_destroy, path_li};

static const murk_plugin_desc desc = {
    sizeof(murk_plugin_desc), MURK_KIND_INTEGRATOR, "path",
    "surface path tracing, NEE + BSDF sampling with MIS, Russian roulette", params, P_COUNT, &vt,
};

MURK_PLUGIN(&desc)
