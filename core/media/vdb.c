/* vdb.c — OpenVDB .vdb density grids, held sparse: the C side of the shim (vdb_shim.cpp reads the file with
 * libopenvdb and hands its tiles and leaves here, to sparse.c's builder). Built without OpenVDB (meson
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
    if (murk_vdb_read(path, grid, murk_limit(MURK_LIMIT_GRID_VOXELS), &sink, &meta, err, errlen) != 0) {
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
