/* host.h — the services table the core hands to plugins, and the per-thread ray count behind it. */
#ifndef MURK_HOST_H
#define MURK_HOST_H

#include <stddef.h>
#include <stdint.h>
#include "murk/medium.h"

const murk_host *murk_host_table(void);
/* Rays traced by the calling thread since its last reset (intersect + occluded calls). */
uint64_t murk_host_thread_rays(void);
/* The rays a render traces, in the order each thread traces them: bench/embree_throughput replays them
 * through Embree alone. ray[k] went to occluded() if occluded[k], else to intersect(); n counts every
 * ray (it may pass cap: the first cap are kept). */
typedef struct murk_ray_record {
    murk_ray *ray;
    unsigned char *occluded;
    size_t cap;
    _Atomic size_t n;
} murk_ray_record;
/* Records every ray traced from now on into rec (NULL: stop). Only while no render runs. */
void murk_host_record_rays(murk_ray_record *rec);
/* Zeroes the calling thread's ray count and cost counters (murk_thread_counters, runtime.h). */
void murk_host_thread_reset(void);

#endif
