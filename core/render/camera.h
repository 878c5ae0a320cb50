/* camera.h — a sample's start and its camera ray: the sampler started for (seed, pixel, sample index),
 * slot 0's jitter in the pixel, the pinhole ray through the jittered point. What render.c does before
 * every li(), shared with the programs that run an integrator outside murk_render()
 * (bench/variance_profile, tests/test_variance_profile). */
#ifndef MURK_CAMERA_H
#define MURK_CAMERA_H

#include "scene/scene.h"

#include <math.h>

static inline void murk_camera_sample(const murk_scene *s, int x, int y, uint32_t k, murk_rng *rng, murk_ray *r)
{
    murk_sampler_start(rng, s->sampler, s->seed, (uint64_t)y * (uint64_t)s->width + (uint64_t)x, k);
    float jit[2]; /* slot 0 of the sampler (murk/math.h) */
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
