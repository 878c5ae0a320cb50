/* nanovdb.c — reading NanoVDB .nvdb density grids (see density.h for what is accepted), held sparse: the
 * grid's tree is walked (root tiles, upper and lower internal nodes, leaves) and its leaves and active
 * tiles go to sparse.c's builder, as an OpenVDB grid's do.
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

/* The file's magic: 1 for grid buffers back to back (a raw grid), 0 for NanoVDB's segmented file format, or
 * -1 with err (not NanoVDB, OpenVDB, big-endian, too short). */
static int nvdb_file_kind(const char *path, const unsigned char *b, uint64_t size, char *err, size_t errlen)
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
    return magic == NVDB_MAGIC_GRID || (magic == NVDB_MAGIC_NUMB && nvdb_major(murk_rd_u32(b + 8)) != NVDB_MAJOR &&
                                        size >= 20 && nvdb_major(murk_rd_u32(b + 16)) == NVDB_MAJOR);
}

/* Grid buffers back to back: the first float grid's offset and length. */
static int nvdb_find_raw(const char *path, const unsigned char *b, uint64_t size, uint64_t *off, uint64_t *len,
                         char *err, size_t errlen)
{
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

/* One segment of the file format at byte p: its first float grid's offset and length (1), or where the next
 * segment starts in *next (0), or -1 with err. */
static int nvdb_find_in_segment(const char *path, const unsigned char *b, uint64_t size, uint64_t p, uint64_t *off,
                                uint64_t *len, uint64_t *next, char *err, size_t errlen)
{
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
            return 1;
        }
        data += fsize;
        meta += NVDB_META_SIZE + murk_rd_u32(b + meta + 136);
    }
    *next = data;
    return 0;
}

/* The first float grid of a NanoVDB file (raw grids or the segmented file format): its offset and length. */
static int nvdb_find_grid(const char *path, const unsigned char *b, uint64_t size, uint64_t *off, uint64_t *len,
                          char *err, size_t errlen)
{
    int raw = nvdb_file_kind(path, b, size, err, errlen);
    if (raw < 0)
        return -1;
    if (raw)
        return nvdb_find_raw(path, b, size, off, len, err, errlen);
    for (uint64_t p = 0; p < size;) {
        int rc = nvdb_find_in_segment(path, b, size, p, off, len, &p, err, errlen);
        if (rc)
            return rc > 0 ? 0 : -1;
    }
    murk_err_file(err, errlen, path, "no float grid in the file");
    return -1;
}

#ifdef MURK_HAVE_NANOVDB
#define FLT PNANOVDB_GRID_TYPE_FLOAT

/* The words of a node's bit mask at byte offset off (nbits bits), read one 32-bit word at a time. */
static uint32_t mask_word(pnanovdb_buf_t buf, pnanovdb_address_t node, uint32_t off, uint32_t w)
{
    return pnanovdb_read_uint32(buf, pnanovdb_address_offset(node, off + 4u * w));
}

/* A leaf at origin o: its values and value mask, and a check that it is the leaf its parent places
 * there (a leaf shared by two parents would otherwise be copied to every place). */
static int nvdb_leaf(murk_sparse_build *sb, pnanovdb_buf_t buf, pnanovdb_leaf_handle_t leaf, const int o[3],
                     const char *path, char *err, size_t errlen)
{
    pnanovdb_coord_t m = pnanovdb_leaf_get_bbox_min(buf, leaf);
    if ((m.x & ~7) != o[0] || (m.y & ~7) != o[1] || (m.z & ~7) != o[2])
        return murk_err_file(err, errlen, path, "corrupt tree: the leaf placed at index (%d, %d, %d) says it is at "
                             "(%d, %d, %d)", o[0], o[1], o[2], m.x & ~7, m.y & ~7, m.z & ~7);
    float v[512];
    uint64_t mask[8];
    for (uint32_t w = 0; w < 8; w++)
        mask[w] = (uint64_t)mask_word(buf, leaf.address, PNANOVDB_LEAF_OFF_VALUE_MASK, 2 * w) |
                  (uint64_t)mask_word(buf, leaf.address, PNANOVDB_LEAF_OFF_VALUE_MASK, 2 * w + 1) << 32;
    for (uint32_t i = 0; i < 512; i++)
        v[i] = pnanovdb_read_float(buf, pnanovdb_leaf_get_table_address(FLT, buf, leaf, i));
    return murk_sparse_leaf(sb, o, v, mask, err, errlen);
}

/* An internal node at origin o: a lower node (upper = 0: 16^3 children, leaves of 8^3 voxels) or an upper node
 * (32^3 children, lower nodes of 128^3 voxels); its children and its active tiles. */
static int nvdb_node(murk_sparse_build *sb, pnanovdb_buf_t buf, pnanovdb_address_t node, int upper, const int o[3],
                     const char *path, char *err, size_t errlen)
{
    uint32_t log2 = upper ? 5 : 4, dim = upper ? 128 : 8, words = (1u << (3 * log2)) / 32;
    uint32_t cmo = upper ? PNANOVDB_UPPER_OFF_CHILD_MASK : PNANOVDB_LOWER_OFF_CHILD_MASK;
    uint32_t vmo = upper ? PNANOVDB_UPPER_OFF_VALUE_MASK : PNANOVDB_LOWER_OFF_VALUE_MASK;
    pnanovdb_upper_handle_t up = {node};
    pnanovdb_lower_handle_t low = {node};
    for (uint32_t w = 0; w < words; w++) {
        uint32_t cm = mask_word(buf, node, cmo, w), vm = mask_word(buf, node, vmo, w) & ~cm;
        for (uint32_t k = 0; k < 32 && (cm | vm) >> k; k++) {
            uint32_t n = 32 * w + k, m = (1u << log2) - 1;
            int c[3] = {o[0] + (int)(dim * ((n >> (2 * log2)) & m)), o[1] + (int)(dim * ((n >> log2) & m)),
                        o[2] + (int)(dim * (n & m))};
            int rc = 0;
            if ((cm >> k) & 1u)
                rc = upper ? nvdb_node(sb, buf, pnanovdb_upper_get_child(FLT, buf, up, n).address, 0, c, path, err, errlen)
                           : nvdb_leaf(sb, buf, pnanovdb_lower_get_child(FLT, buf, low, n), c, path, err, errlen);
            else if ((vm >> k) & 1u)
                rc = murk_sparse_tile(sb, c, dim, pnanovdb_read_float(buf, upper ? pnanovdb_upper_get_table_address(FLT,
                                      buf, up, n) : pnanovdb_lower_get_table_address(FLT, buf, low, n)), err, errlen);
            if (rc)
                return -1;
        }
    }
    return 0;
}

/* The root's tiles, each an upper node or a value over 4096^3 voxels; no two may share a key. */
static int nvdb_root(murk_sparse_build *sb, pnanovdb_buf_t buf, pnanovdb_root_handle_t root, uint64_t tiles,
                     const char *path, char *err, size_t errlen)
{
    uint64_t *keys = malloc((tiles ? tiles : 1) * sizeof *keys);
    if (!keys)
        return murk_err_file(err, errlen, path, "out of memory");
    int rc = 0;
    for (uint64_t t = 0; t < tiles && rc == 0; t++) {
        pnanovdb_root_tile_handle_t tile = pnanovdb_root_get_tile(FLT, root, (uint32_t)t);
        uint64_t key = pnanovdb_root_tile_get_key(buf, tile);
        for (uint64_t u = 0; u < t && rc == 0; u++)
            if (keys[u] == key)
                rc = murk_err_file(err, errlen, path, "corrupt tree: two root tiles have the key %llu",
                                   (unsigned long long)key);
        keys[t] = key;
        int o[3] = {(int32_t)(uint32_t)(((key >> 42) & 0xfffffu) << 12), (int32_t)(uint32_t)(((key >> 21) & 0xfffffu) << 12),
                    (int32_t)(uint32_t)((key & 0xfffffu) << 12)};
        if (rc == 0 && pnanovdb_root_tile_get_child(buf, tile) != 0)
            rc = nvdb_node(sb, buf, pnanovdb_root_get_child(FLT, buf, root, tile).address, 1, o, path, err, errlen);
        else if (rc == 0 && pnanovdb_root_tile_get_state(buf, tile))
            rc = murk_sparse_tile(sb, o, 4096, pnanovdb_read_float(buf, pnanovdb_root_tile_get_value_address(FLT, buf,
                                  tile)), err, errlen);
    }
    free(keys);
    return rc;
}

/* The grid in g (len bytes, 8-byte aligned, zero-padded to a multiple of 8) as a sparse field. */
static murk_field *nvdb_sparse(const char *path, const unsigned char *g, uint64_t len, char *err, size_t errlen)
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
    double map[12];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            uint64_t u = murk_rd_u64(g + 384 + 8 * (3 * r + c));
            memcpy(&map[4 * r + c], &u, 8);
        }
        uint64_t u = murk_rd_u64(g + 528 + 8 * r);
        memcpy(&map[4 * r + 3], &u, 8);
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
    int lo[3] = {bmin.x, bmin.y, bmin.z}, hi[3] = {bmax.x, bmax.y, bmax.z};
    murk_sparse_build *sb = murk_sparse_begin(path, lo, hi, err, errlen);
    if (!sb)
        return NULL;
    if (nvdb_root(sb, buf, root, tiles, path, err, errlen)) {
        murk_sparse_abort(sb);
        return NULL;
    }
    return murk_sparse_end(sb, map, err, errlen);
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
    murk_field *f = nvdb_sparse(path, g, len, err, errlen);
    free(g);
    return f;
#else
    free(b);
    murk_err_file(err, errlen, path, "murk was built without NanoVDB support (nanovdb/PNanoVDB.h)");
    return NULL;
#endif
}
