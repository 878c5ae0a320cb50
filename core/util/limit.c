/* limit.c — the limits murk enforces on input sizes, with their environment overrides (limit.h). */
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>

static const struct {
    const char *name;
    uint64_t def;
} table[MURK_LIMIT_COUNT] = {
    [MURK_LIMIT_IMAGE_PIXELS] = {"MURK_MAX_IMAGE_PIXELS", (uint64_t)1 << 26},
    [MURK_LIMIT_GRID_VOXELS] = {"MURK_MAX_GRID_VOXELS", (uint64_t)1 << 27},
    [MURK_LIMIT_FILE_BYTES] = {"MURK_MAX_FILE_BYTES", (uint64_t)1 << 30},
    [MURK_LIMIT_MESH_TRIANGLES] = {"MURK_MAX_MESH_TRIANGLES", (uint64_t)1 << 26},
    [MURK_LIMIT_PAGE_BYTES] = {"MURK_MAX_PAGE_BYTES", (uint64_t)1 << 26},
    [MURK_LIMIT_GRID_BOX] = {"MURK_MAX_GRID_BOX", (uint64_t)1 << 40},
};

static uint64_t value[MURK_LIMIT_COUNT];
static pthread_once_t once = PTHREAD_ONCE_INIT;

static void read_env(void)
{
    for (int i = 0; i < MURK_LIMIT_COUNT; i++) {
        value[i] = table[i].def;
        const char *v = getenv(table[i].name);
        if (!v)
            continue;
        char *end = NULL;
        errno = 0;
        unsigned long long x = v[0] >= '0' && v[0] <= '9' ? strtoull(v, &end, 10) : 0;
        if (!end || *end || errno || x == 0)
            murk_log(MURK_LOG_WARN, "%s must be a positive whole number; ignored (the limit stays %llu)",
                     table[i].name, (unsigned long long)table[i].def);
        else
            value[i] = x;
    }
}

MURK_API uint64_t murk_limit(murk_limit_id id)
{
    pthread_once(&once, read_env);
    return id < MURK_LIMIT_COUNT ? value[id] : 0;
}

MURK_API const char *murk_limit_name(murk_limit_id id) { return id < MURK_LIMIT_COUNT ? table[id].name : "?"; }
