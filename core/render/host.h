/* host.h — the services table the core hands to plugins, and the per-thread counters behind it. */
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
/* Zeroes the calling thread's ray count and cost counters. */
void murk_host_thread_reset(void);

/* The calling thread's cost counters (murk/counters.h), one block per counter slot: a medium's slot is
 * its index in the scene (the last slot is shared by the media beyond it). Plain thread-local memory:
 * the hot paths (density lookups, majorant cells) add to it without atomics or locks. */
#if defined(__GNUC__)
extern _Thread_local murk_counters murk_thread_counters[MURK_COUNTER_SLOTS] __attribute__((tls_model("initial-exec")));
#else
extern _Thread_local murk_counters murk_thread_counters[MURK_COUNTER_SLOTS];
#endif
/* Adds the calling thread's first n blocks into sum[0..n) (once per thread when its work ends). */
void murk_host_thread_counters_add(murk_counters *sum, size_t n);
/* The slot for the scene's i-th medium. */
static inline unsigned murk_counter_slot(size_t i)
{
    return i < MURK_COUNTER_SLOTS - 1 ? (unsigned)i : MURK_COUNTER_SLOTS - 1;
}

/* Wraps a scene's medium (its tracker and, if any, its transmittance estimator) so that every free
 * flight that scatters and every transmittance estimate is counted in the medium's slot. The wrapped
 * destroy() frees the wrapper too. */
void murk_host_count_medium(murk_medium *m, unsigned slot);

#endif
