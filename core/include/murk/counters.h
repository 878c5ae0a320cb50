/* murk/counters.h — the cost counters: how much work a render did, per medium, machine-independent.
 *
 * Every render thread has its own block per medium (no atomics, no locks on the hot path); the core
 * sums them when the render ends (murk_render_result.media) and `murk render` prints them and stores
 * them in the EXR (`murk:counters`). What counts what:
 *   lookups, cells   the core, in host->density() and host->walk_next(): every tracker and estimator
 *                    that reads the density through the host is counted, whatever its code;
 *   collisions       the tracker or transmittance estimator: murk/tracking.h's helpers
 *                    (murk_collisions_next, murk_ratio_tracking) count theirs; one that draws collision
 *                    points itself adds one per tentative (null or real) collision to
 *                    murk_tracker_counters()->collisions. A tentative collision is a point drawn at
 *                    random along the ray (a Poisson process of the majorant, or points of its density)
 *                    where the density is then read or a collision is decided: decomposition's control
 *                    collisions (no lookup) and residual ones, every point of power_series' series
 *                    (Poisson or top-up: collisions = lookups). Ray marchers (raymarch,
 *                    unbiased_raymarch) read the density at the points of a jittered lattice and decide
 *                    no collision: they count none, only lookups;
 *   scatters, shadow the core, around every medium's sample() (flights that ended in a real scattering
 *                    event) and transmittance estimate (shadow-ray segments).
 * Rays traced (the intersect and occluded calls that reach Embree; a ray from inside an empty medium box or
 * sphere, and an occlusion query that one or one of a scene's few spheres blocks, is answered in closed
 * form and not counted) are counted per render, not per medium (murk_render_result.rays). */
#ifndef MURK_COUNTERS_H
#define MURK_COUNTERS_H

#include <stdint.h>

typedef struct murk_counters {
    uint64_t lookups;    /* density lookups (host->density) */
    uint64_t cells;      /* majorant-grid cells visited (segments host->walk_next returned) */
    uint64_t collisions; /* tentative (null + real) collisions */
    uint64_t scatters;   /* real scattering events (free flights that ended scattered) */
    uint64_t shadow;     /* transmittance estimates (shadow-ray segments through the medium) */
} murk_counters;

/* Media beyond the first MURK_COUNTER_SLOTS - 1 of a scene share the last block. */
#define MURK_COUNTER_SLOTS 64

/* The counters' names, in struct order, as murk prints them and bench.csv heads its columns. */
#define MURK_COUNTER_NAMES {"lookups", "cells", "collisions", "scatters", "shadow"}
#define MURK_NCOUNTERS 5

#endif
