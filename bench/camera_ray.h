/* camera_ray.h — a sample's start and camera ray exactly as core/render/render.c makes them (there they
 * are static): the sampler started for (seed, pixel, sample index), slot 0's jitter, the pinhole ray
 * through the jittered point. For the programs that run the path tracer outside murk_render()
 * (bench/variance_profile, tests/test_variance_profile). */
#ifndef MURK_BENCH_CAMERA_RAY_H
#define MURK_BENCH_CAMERA_RAY_H

#include "scene.h"

static inline void camera_sample_start(const murk_scene *s, int x, int y, int k, murk_rng *rng, murk_ray *r)
{
    murk_sampler_start(rng, s->sampler, s->seed, (uint64_t)y * (uint64_t)s->width + (uint64_t)x, (uint32_t)k);
    float jit[2];
    murk_sample_2d(rng, jit);
    float fx = (float)x + jit[0], fy = (float)y + jit[1], aspect = (float)s->width / (float)s->height;
    float px = (2.0f * fx / (float)s->width - 1.0f) * s->cam_tan * aspect;
    float py = (1.0f - 2.0f * fy / (float)s->height) * s->cam_tan;
    r->o = s->cam_from;
    r->d = murk_normalize(murk_add(s->cam_w, murk_add(murk_mul(s->cam_u, px), murk_mul(s->cam_v, py))));
    r->tmin = 0.0f;
    r->tmax = INFINITY;
}

#endif
