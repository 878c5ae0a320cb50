/* host.h — the services table the core hands to plugins, and the per-thread counters behind it. */
#ifndef MURK_HOST_H
#define MURK_HOST_H

#include <stdint.h>
#include "murk/plugin.h"

const murk_host *murk_host_table(void);
/* Rays traced by the calling thread since its last reset (intersect + occluded calls). */
uint64_t murk_host_thread_rays(void);
void murk_host_thread_reset(void);

#endif
