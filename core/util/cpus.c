/* cpus.c — how many CPUs this process may run on: its affinity mask where the system has one (Linux),
 * else the CPUs online. mpirun binds ranks (Open MPI: to a core when it starts one or two ranks, to a
 * socket or NUMA domain beyond), so a rank's default thread count must follow the mask, not the
 * machine. */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE
#endif
#include "util/util.h"

#include <unistd.h>
#if defined(__linux__)
#include <sched.h>
#endif

MURK_API int murk_cpus_usable(void)
{
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0) {
        int n = CPU_COUNT(&set);
        if (n > 0)
            return n;
    }
#endif
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}
