/* vdb.c — OpenVDB .vdb density grids, held sparse: the C side of the shim (vdb_shim.cpp reads the file with
 * libopenvdb and hands its tiles and leaves here, to sparse.c's builder). libmurk does not link libopenvdb,
 * whose relocations would cost every murk process its start-up time: the shim is the module
 * murk_vdb.so, loaded here the first time a .vdb is read (core/meson.build). Built without OpenVDB (meson
 * -Dopenvdb=disabled, or libopenvdb-dev missing), murk_field_vdb_load says so. */
#include "media/field_impl.h"
#include "util/error.h"
#include "util/file.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>

#ifdef MURK_HAVE_OPENVDB
#include "media/vdb_shim.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <string.h>

/* Defined when the shim is linked in (the tests, benches and fuzz harnesses link it statically); in
 * libmurk.so it is not, and this weak reference is null. */
int murk_vdb_read(const char *path, const char *grid, uint64_t max_active, const murk_vdb_sink *sink,
                  murk_vdb_meta *meta, char *err, size_t errlen) __attribute__((weak, visibility("hidden")));

typedef int (*vdb_read_fn)(const char *, const char *, uint64_t, const murk_vdb_sink *, murk_vdb_meta *, char *,
                           size_t);
static vdb_read_fn vdb_read;
static char vdb_load_error[1024];
static pthread_once_t vdb_once = PTHREAD_ONCE_INIT;

/* dlopen()s the module: beside libmurk (the build tree: core/murk_vdb.so), in the install's LIBDIR/murk
 * beside libmurk (a moved or staged install), then in the configured prefix's. Kept loaded: OpenVDB keeps
 * registries that outlive a read. */
static void vdb_load_module(void)
{
    if (murk_vdb_read) {
        vdb_read = murk_vdb_read;
        return;
    }
    char dir[PATH_MAX];
    const char *tried[3] = {NULL, NULL, MURK_VDB_MODULE};
    char beside[2][PATH_MAX + 32];
    if (murk_library_dir(dir, sizeof dir) == 0) {
        snprintf(beside[0], sizeof beside[0], "%s/murk_vdb.so", dir);
        snprintf(beside[1], sizeof beside[1], "%s/murk/murk_vdb.so", dir);
        tried[0] = beside[0];
        tried[1] = beside[1];
    }
    size_t used = 0;
    for (int i = 0; i < 3; i++) {
        if (!tried[i])
            continue;
        void *h = dlopen(tried[i], RTLD_NOW | RTLD_LOCAL);
        void *fn = h ? dlsym(h, "murk_vdb_read") : NULL;
        if (fn) {
            memcpy(&vdb_read, &fn, sizeof fn); /* ISO C has no object-to-function pointer cast */
            return;
        }
        const char *why = h ? "has no murk_vdb_read" : dlerror(); /* dlerror() names the file */
        int k = snprintf(vdb_load_error + used, sizeof vdb_load_error - used, "%s%s%s%s", used ? "; " : "",
                         h || !why ? tried[i] : "", h || !why ? ": " : "", why ? why : "cannot be loaded");
        if (k > 0)
            used += (size_t)k < sizeof vdb_load_error - used ? (size_t)k : sizeof vdb_load_error - 1 - used;
    }
}

typedef struct sink_state {
    const char *path;
    murk_sparse_build *b;
} sink_state;

static int sink_begin(void *user, const int bmin[3], const int bmax[3], char *err, size_t errlen)
{
    sink_state *s = user;
    s->b = murk_sparse_begin(s->path, bmin, bmax, err, errlen);
    return s->b ? 0 : -1;
}

static int sink_tile(void *user, const int origin[3], long long dim, float value, char *err, size_t errlen)
{
    return murk_sparse_tile(((sink_state *)user)->b, origin, dim, value, err, errlen);
}

static int sink_leaf(void *user, const int origin[3], const float *values, const uint64_t *mask, char *err,
                     size_t errlen)
{
    return murk_sparse_leaf(((sink_state *)user)->b, origin, values, mask, err, errlen);
}
#endif

MURK_API int murk_field_vdb_supported(void)
{
#ifdef MURK_HAVE_OPENVDB
    return 1;
#else
    return 0;
#endif
}

MURK_API murk_field *murk_field_vdb_load(const char *path, const char *grid, int *no_such_grid, char *err,
                                         size_t errlen)
{
    if (no_such_grid)
        *no_such_grid = 0;
    uint64_t size;
    FILE *fp = murk_file_open_regular(path, &size, err, errlen); /* a regular file within the size limit */
    if (!fp)
        return NULL;
    fclose(fp);
#ifdef MURK_HAVE_OPENVDB
    sink_state st = {path, NULL};
    murk_vdb_sink sink = {&st, sink_begin, sink_tile, sink_leaf};
    murk_vdb_meta meta;
    pthread_once(&vdb_once, vdb_load_module);
    if (!vdb_read) {
        murk_err_file(err, errlen, path, "murk was built with OpenVDB, but its module murk_vdb.so cannot be loaded "
                      "(%s)", vdb_load_error);
        return NULL;
    }
    meta.no_such_grid = 0;
    if (vdb_read(path, grid, murk_limit(MURK_LIMIT_GRID_VOXELS), &sink, &meta, err, errlen) != 0) {
        murk_sparse_abort(st.b);
        if (no_such_grid)
            *no_such_grid = meta.no_such_grid;
        return NULL;
    }
    if (meta.background != 0.0)
        murk_log(MURK_LOG_WARN, "%s: grid '%s' has background %g; murk takes its inactive voxels as 0 (empty space)",
                 path, grid ? grid : "(the only one)", meta.background);
    return murk_sparse_end(st.b, meta.map, err, errlen);
#else
    (void)grid;
    murk_err_file(err, errlen, path, "murk was built without OpenVDB support, so it cannot read .vdb files (install "
                  "libopenvdb-dev and rebuild: tools/build.sh, or meson configure -Dopenvdb=enabled)");
    return NULL;
#endif
}
