/* nanovdb.c — reading NanoVDB .nvdb density grids (see density.h for what is accepted).
 *
 * Format (little-endian): either segments — FileHeader (u64 magic, u32 version, u16 gridCount,
 * u16 codec), then gridCount x (176-byte FileMetaData + grid name), then the grid buffers (fileSize
 * bytes each, = gridSize when uncompressed) — or, since NanoVDB 32.6, raw grid buffers back to back.
 * Each grid buffer is read with PNanoVDB (the C port of NanoVDB), bounds-checked, so a corrupt file
 * yields zeros or an error rather than a wild read. */
#include "media/field_impl.h"
#include "util/error.h"
#include "util/file.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__has_include)
#if __has_include(<nanovdb/PNanoVDB.h>)
#define MURK_HAVE_NANOVDB 1
#endif
#endif

#ifdef MURK_HAVE_NANOVDB
#define PNANOVDB_C
#define PNANOVDB_BUF_BOUNDS_CHECK
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-variable"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <nanovdb/PNanoVDB.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif

#define NVDB_MAGIC_NUMB 0x304244566f6e614eull /* "NanoVDB0": grid or file (<= 32.5) */
#define NVDB_MAGIC_GRID 0x314244566f6e614eull /* "NanoVDB1": raw grid buffer (>= 32.6) */
#define NVDB_MAGIC_FILE 0x324244566f6e614eull /* "NanoVDB2": segment header (>= 32.6) */
#define NVDB_MAJOR 32u
#define NVDB_GRID_SIZE 672u  /* GridData */
#define NVDB_TREE_SIZE 64u   /* TreeData */
#define NVDB_META_SIZE 176u  /* io FileMetaData */
#define NVDB_TYPE_FLOAT 1u
#define NVDB_CLASS_LEVEL_SET 1u

static unsigned nvdb_major(uint32_t version) { return (version >> 21) & 2047u; }

static uint64_t bswap64(uint64_t v)
{
    uint64_t r = 0;
    for (int i = 0; i < 8; i++)
        r = (r << 8) | ((v >> (8 * i)) & 0xff);
    return r;
}

/* Finds the first float grid; sets *off / *len to its buffer within the file. */
static int nvdb_find_grid(const char *path, const unsigned char *b, uint64_t size, uint64_t *off, uint64_t *len,
                          char *err, size_t errlen)
{
    if (size >= 4 && murk_rd_u32(b) == 0x56444220u) {
        murk_err_file(err, errlen, path, "an OpenVDB .vdb file, not NanoVDB (convert it with nanovdb_convert)");
        return -1;
    }
    if (size < 16) {
        murk_err_file(err, errlen, path, "too short for a NanoVDB file (%llu bytes)", (unsigned long long)size);
        return -1;
    }
    uint64_t magic = murk_rd_u64(b);
    if (magic == bswap64(NVDB_MAGIC_NUMB) || magic == bswap64(NVDB_MAGIC_GRID) || magic == bswap64(NVDB_MAGIC_FILE)) {
        murk_err_file(err, errlen, path, "big-endian NanoVDB file; murk reads little-endian only");
        return -1;
    }
    if (magic != NVDB_MAGIC_NUMB && magic != NVDB_MAGIC_GRID && magic != NVDB_MAGIC_FILE) {
        murk_err_file(err, errlen, path, "not a NanoVDB file (bad magic)");
        return -1;
    }
    int raw = magic == NVDB_MAGIC_GRID ||
              (magic == NVDB_MAGIC_NUMB && nvdb_major(murk_rd_u32(b + 8)) != NVDB_MAJOR && size >= 20 &&
               nvdb_major(murk_rd_u32(b + 16)) == NVDB_MAJOR);
    if (raw) { /* grid buffers back to back */
        for (uint64_t p = 0; p < size;) {
            if (size - p < NVDB_GRID_SIZE + NVDB_TREE_SIZE) {
                murk_err_file(err, errlen, path, "truncated grid at byte %llu", (unsigned long long)p);
                return -1;
            }
            uint64_t m = murk_rd_u64(b + p);
            uint32_t ver = murk_rd_u32(b + p + 16);
            uint64_t gsize = murk_rd_u64(b + p + 32);
            if (m != NVDB_MAGIC_NUMB && m != NVDB_MAGIC_GRID) {
                murk_err_file(err, errlen, path, "bad grid magic at byte %llu", (unsigned long long)p);
                return -1;
            }
            if (nvdb_major(ver) != NVDB_MAJOR) {
                murk_err_file(err, errlen, path, "NanoVDB grid version %u.%u.%u; murk reads major version %u", nvdb_major(ver), (ver >> 10) & 2047u, ver & 1023u, NVDB_MAJOR);
                return -1;
            }
            if (gsize < NVDB_GRID_SIZE + NVDB_TREE_SIZE || gsize > size - p) {
                murk_err_file(err, errlen, path, "grid at byte %llu claims %llu bytes; %llu remain", (unsigned long long)p, (unsigned long long)gsize, (unsigned long long)(size - p));
                return -1;
            }
            if (murk_rd_u32(b + p + 636) == NVDB_TYPE_FLOAT) {
                *off = p;
                *len = gsize;
                return 0;
            }
            p += gsize;
        }
        murk_err_file(err, errlen, path, "no float grid in the file");
        return -1;
    }
    for (uint64_t p = 0; p < size;) { /* segments */
        if (size - p < 16) {
            murk_err_file(err, errlen, path, "truncated segment header at byte %llu", (unsigned long long)p);
            return -1;
        }
        uint64_t m = murk_rd_u64(b + p);
        uint32_t ver = murk_rd_u32(b + p + 8);
        unsigned count = b[p + 12] | (unsigned)b[p + 13] << 8;
        unsigned codec = b[p + 14] | (unsigned)b[p + 15] << 8;
        if (m != NVDB_MAGIC_NUMB && m != NVDB_MAGIC_FILE) {
            murk_err_file(err, errlen, path, "bad segment magic at byte %llu", (unsigned long long)p);
            return -1;
        }
        if (nvdb_major(ver) != NVDB_MAJOR) {
            murk_err_file(err, errlen, path, "NanoVDB file version %u.%u.%u; murk reads major version %u", nvdb_major(ver), (ver >> 10) & 2047u, ver & 1023u, NVDB_MAJOR);
            return -1;
        }
        if (codec != 0) {
            murk_err_file(err, errlen, path, "grids compressed with %s; murk reads uncompressed NanoVDB files only (re-save "
                   "it without compression)", codec == 1 ? "ZIP" : (codec == 2 ? "BLOSC" : "an unknown codec"));
            return -1;
        }
        /* First pass: find where the grid buffers start (after all metadata and names). */
        uint64_t q = p + 16;
        for (unsigned i = 0; i < count; i++) {
            if (size - q < NVDB_META_SIZE) {
                murk_err_file(err, errlen, path, "truncated grid metadata at byte %llu", (unsigned long long)q);
                return -1;
            }
            uint64_t name = murk_rd_u32(b + q + 136);
            if (name > size - q - NVDB_META_SIZE) {
                murk_err_file(err, errlen, path, "truncated grid name at byte %llu", (unsigned long long)q);
                return -1;
            }
            q += NVDB_META_SIZE + name;
        }
        /* Second pass: walk metadata and buffers together. */
        uint64_t meta = p + 16, data = q;
        for (unsigned i = 0; i < count; i++) {
            uint64_t gsize = murk_rd_u64(b + meta), fsize = murk_rd_u64(b + meta + 8);
            uint32_t type = murk_rd_u32(b + meta + 32);
            unsigned mcodec = b[meta + 168] | (unsigned)b[meta + 169] << 8;
            if (mcodec != 0) {
                murk_err_file(err, errlen, path, "grid %u is compressed; murk reads uncompressed NanoVDB files only", i);
                return -1;
            }
            if (fsize > size - data) {
                murk_err_file(err, errlen, path, "truncated: grid %u needs %llu bytes at byte %llu, %llu remain", i, (unsigned long long)fsize, (unsigned long long)data, (unsigned long long)(size - data));
                return -1;
            }
            if (type == NVDB_TYPE_FLOAT) {
                if (gsize != fsize || gsize < NVDB_GRID_SIZE + NVDB_TREE_SIZE) {
                    murk_err_file(err, errlen, path, "grid %u has inconsistent sizes (%llu in memory, %llu on disk)", i, (unsigned long long)gsize, (unsigned long long)fsize);
                    return -1;
                }
                *off = data;
                *len = gsize;
                return 0;
            }
            data += fsize;
            meta += NVDB_META_SIZE + murk_rd_u32(b + meta + 136);
        }
        p = data;
    }
    murk_err_file(err, errlen, path, "no float grid in the file");
    return -1;
}

#ifdef MURK_HAVE_NANOVDB
/* Densifies the grid in g (len bytes, 8-byte aligned, zero-padded to a multiple of 8). */
static murk_field *nvdb_densify(const char *path, const unsigned char *g, uint64_t len, char *err, size_t errlen)
{
    uint64_t m = murk_rd_u64(g);
    uint32_t ver = murk_rd_u32(g + 16);
    if ((m != NVDB_MAGIC_NUMB && m != NVDB_MAGIC_GRID) || nvdb_major(ver) != NVDB_MAJOR) {
        murk_err_file(err, errlen, path, "bad grid header (magic or version)");
        return NULL;
    }
    if (murk_rd_u32(g + 636) != NVDB_TYPE_FLOAT) {
        murk_err_file(err, errlen, path, "grid is not a float grid");
        return NULL;
    }
    if (murk_rd_u32(g + 632) == NVDB_CLASS_LEVEL_SET) {
        murk_err_file(err, errlen, path, "the float grid is a level set (signed distances), not a density (fog volume)");
        return NULL;
    }
    /* Index-to-world map: double matrix (row-major) at 296+88, translation at 296+232. */
    double mat[9], vec[3], scale[3];
    for (int i = 0; i < 9; i++) {
        uint64_t u = murk_rd_u64(g + 384 + 8 * i);
        memcpy(&mat[i], &u, 8);
    }
    for (int i = 0; i < 3; i++) {
        uint64_t u = murk_rd_u64(g + 528 + 8 * i);
        memcpy(&vec[i], &u, 8);
    }
    for (int r = 0; r < 3; r++) {
        scale[r] = mat[4 * r];
        if (!isfinite(scale[r]) || !(scale[r] > 0.0) || !isfinite(vec[r])) {
            murk_err_file(err, errlen, path, "unsupported index-to-world map (need a positive, finite scale per axis)");
            return NULL;
        }
    }
    double smax = fmax(scale[0], fmax(scale[1], scale[2]));
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            if (r != c && !(fabs(mat[3 * r + c]) <= 1e-9 * smax)) {
                murk_err_file(err, errlen, path, "rotated or sheared index-to-world maps are not supported");
                return NULL;
            }

    pnanovdb_buf_t buf = pnanovdb_make_buf((uint32_t *)(uintptr_t)g, (len + 7) / 8 * 2);
    pnanovdb_grid_handle_t grid = {pnanovdb_address_null()};
    pnanovdb_tree_handle_t tree = pnanovdb_grid_get_tree(buf, grid);
    pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, tree);
    uint64_t roff = root.address.byte_offset;
    if (roff < NVDB_GRID_SIZE + NVDB_TREE_SIZE || roff > len || len - roff < 64) {
        murk_err_file(err, errlen, path, "corrupt grid (root node outside the buffer)");
        return NULL;
    }
    uint64_t tiles = pnanovdb_root_get_tile_count(buf, root);
    if (tiles > (len - roff - 64) / PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_tile_size)) {
        murk_err_file(err, errlen, path, "corrupt grid (root tile table outside the buffer)");
        return NULL;
    }
    pnanovdb_coord_t bmin = pnanovdb_root_get_bbox_min(buf, root), bmax = pnanovdb_root_get_bbox_max(buf, root);
    int64_t r0 = (int64_t)bmax.x - bmin.x + 1, r1 = (int64_t)bmax.y - bmin.y + 1, r2 = (int64_t)bmax.z - bmin.z + 1;
    if (r0 < 1 || r1 < 1 || r2 < 1) {
        murk_err_file(err, errlen, path, "the float grid has no active voxels");
        return NULL;
    }
    uint64_t n = murk_voxel_count(r0, r1, r2);
    if (n == 0) {
        murk_err_file(err, errlen, path, "active bounding box %lld x %lld x %lld exceeds the limit of %llu voxels", (long long)r0, (long long)r1, (long long)r2, (unsigned long long)MURK_FIELD_MAX_VOXELS);
        return NULL;
    }
    int res[3] = {(int)r0, (int)r1, (int)r2}, org[3] = {bmin.x, bmin.y, bmin.z};
    murk_vec3 lo, hi;
    float l[3], h[3];
    for (int a = 0; a < 3; a++) {
        l[a] = (float)(vec[a] + scale[a] * ((double)org[a] - 0.5));
        h[a] = (float)(vec[a] + scale[a] * ((double)org[a] + res[a] - 0.5));
    }
    lo = murk_v3(l[0], l[1], l[2]);
    hi = murk_v3(h[0], h[1], h[2]);
    if (!murk_box_ok(lo, hi)) {
        murk_err_file(err, errlen, path, "the grid's world box is not representable in float");
        return NULL;
    }
    float *data = malloc((size_t)n * sizeof *data);
    if (!data) {
        murk_err_file(err, errlen, path, "out of memory for %llu voxels", (unsigned long long)n);
        return NULL;
    }
    pnanovdb_readaccessor_t acc;
    pnanovdb_readaccessor_init(&acc, root);
    size_t i = 0;
    for (int z = 0; z < res[2]; z++)
        for (int y = 0; y < res[1]; y++)
            for (int x = 0; x < res[0]; x++) {
                pnanovdb_coord_t ijk = {org[0] + x, org[1] + y, org[2] + z};
                pnanovdb_address_t ad = pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, &acc,
                                                                                &ijk);
                data[i++] = pnanovdb_read_float(buf, ad);
            }
    return murk_field_adopt(path, res, org, lo, hi, data, err, errlen);
}
#endif

murk_field *murk_field_nvdb_load(const char *path, char *err, size_t errlen)
{
    uint64_t size = 0, off = 0, len = 0;
    unsigned char *b = murk_file_read_all(path, &size, err, errlen);
    if (!b)
        return NULL;
    if (nvdb_find_grid(path, b, size, &off, &len, err, errlen) != 0) {
        free(b);
        return NULL;
    }
#ifdef MURK_HAVE_NANOVDB
    /* Copy the grid to its own 8-byte aligned, zero-padded buffer (PNanoVDB reads whole words). */
    uint64_t padded = (len + 7) / 8 * 8;
    unsigned char *g = calloc(1, (size_t)padded);
    if (!g) {
        murk_err_file(err, errlen, path, "out of memory");
        free(b);
        return NULL;
    }
    memcpy(g, b + off, (size_t)len);
    free(b);
    murk_field *f = nvdb_densify(path, g, len, err, errlen);
    free(g);
    return f;
#else
    free(b);
    murk_err_file(err, errlen, path, "murk was built without NanoVDB support (nanovdb/PNanoVDB.h)");
    return NULL;
#endif
}
