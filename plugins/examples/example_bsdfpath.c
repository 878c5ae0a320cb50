/* example_bsdfpath — a brute-force surface path tracer: the smallest complete integrator plugin.
 *
 * Parameters
 *   max_depth  INT in [1, 1024], default 16. Surface bounces before the path is cut.
 *   rr_depth   INT in [0, 1024], default 4. Bounces after which Russian roulette may end a path.
 *
 * Light is found by BSDF sampling alone (no light sampling, no MIS): a path collects the emission of
 * every surface it hits and the background when it escapes. Unbiased but noisy for small lights; good
 * for environment-lit scenes and as a reference. Media are ignored: index-matched boundaries (hits
 * without a material) are passed through. Delta lobes need no special case here since there is no MIS.
 *
 * Contract (murk/integrator.h): li() returns the radiance along a camera ray; it is called from every
 * render thread at once with the same `self`, so it keeps all per-path state on its stack and draws
 * every random number from `rng`. The scene is reached only through the host table kept at create(). */
#include "murk/integrator.h"
#include "murk/material.h"

#include <math.h>
#include <stdio.h>

enum { P_MAX_DEPTH, P_RR_DEPTH, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_MAX_DEPTH] = {"max_depth", MURK_PARAM_INT, 0, {16, 0, 0}, NULL, NULL, 1, 1024, "surface bounces before a path is cut"},
    [P_RR_DEPTH] = {"rr_depth", MURK_PARAM_INT, 0, {4, 0, 0}, NULL, NULL, 0, 1024, "bounces before Russian roulette"},
};

typedef struct bsdfpath {
    const murk_host *host;
    int max_depth, rr_depth;
} bsdfpath;

static int bp_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    bsdfpath *b = host->alloc(sizeof *b);
    if (!b) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    b->host = host;
    b->max_depth = (int)p[P_MAX_DEPTH].f[0];
    b->rr_depth = (int)p[P_RR_DEPTH].f[0];
    *self = b;
    return 0;
}

static void bp_destroy(void *self)
{
    bsdfpath *b = self;
    if (b)
        b->host->free(b);
}

/* A ray leaving p (on a surface with geometric normal ng) in direction d, moved off the surface. */
static murk_ray spawn(murk_vec3 p, murk_vec3 ng, murk_vec3 d)
{
    float m = murk_maxf(1.0f, murk_maxf(fabsf(p.x), murk_maxf(fabsf(p.y), fabsf(p.z))));
    float eps = 1e-4f * m;
    murk_ray r = {murk_madd(p, ng, murk_dot(ng, d) >= 0.0f ? eps : -eps), d, 0.0f, INFINITY};
    return r;
}

static murk_rgb bp_li(const void *self, const murk_scene *scene, const murk_ray *camera_ray, murk_rng *rng)
{
    const bsdfpath *b = self;
    const murk_host *h = b->host;
    murk_rgb L = murk_rgb1(0.0f), beta = murk_rgb1(1.0f);
    murk_ray ray = *camera_ray;
    int depth = 0, crossings = 0;
    for (;;) {
        murk_hit hit;
        if (!h->intersect(scene, &ray, &hit)) { /* escaped: the environment */
            L = murk_rgb_add(L, murk_rgb_mul(beta, h->background(scene, ray.d)));
            break;
        }
        murk_vec3 wo = murk_neg(ray.d);
        L = murk_rgb_add(L, murk_rgb_mul(beta, murk_hit_le(&hit, wo)));
        if (!hit.material) { /* an index-matched medium boundary: go straight on */
            if (++crossings > 1000)
                break;
            ray = spawn(hit.p, hit.ng, ray.d);
            continue;
        }
        if (depth >= b->max_depth)
            break;
        /* The shading frame on wo's side (two-sided materials): the material sees wo.z >= 0. */
        murk_vec3 ng = hit.ng, n = hit.n;
        if (murk_dot(ng, wo) < 0.0f) {
            ng = murk_neg(ng);
            n = murk_neg(n);
        }
        murk_vec3 t, bt;
        murk_basis(n, &t, &bt);
        murk_vec3 wo_l = murk_to_local(wo, t, bt, n);
        if (wo_l.z <= 0.0f)
            wo_l.z = 1e-6f;
        float u[3] = {murk_rng_float(rng), murk_rng_float(rng), murk_rng_float(rng)};
        murk_bsdf_sample s;
        const murk_material *mat = hit.material;
        if (!mat->vt->sample(mat->self, &hit, wo_l, u, &s) || !(s.pdf > 0.0f))
            break;
        murk_vec3 wi = murk_from_local(s.wi, t, bt, n);
        if (murk_dot(wi, ng) <= 0.0f) /* below the geometric surface: reflection only */
            break;
        beta = murk_rgb_mul(beta, murk_rgb_scale(s.f, fabsf(s.wi.z) / s.pdf));
        if (++depth > b->rr_depth) { /* Russian roulette, unbiased: survivors are divided by q */
            float q = murk_minf(1.0f, murk_maxf(0.05f, murk_rgb_max(beta)));
            if (murk_rng_float(rng) >= q)
                break;
            beta = murk_rgb_scale(beta, 1.0f / q);
        }
        ray = spawn(hit.p, ng, wi);
    }
    return L;
}

static const murk_integrator_vt vt = {
    sizeof(murk_integrator_vt), MURK_KIND_INTEGRATOR, bp_create, bp_destroy, bp_li,
};

MURK_INTEGRATOR_PLUGIN("example_bsdfpath", "example: path tracing with BSDF sampling only (copy me)", params, P_COUNT,
                       &vt)
