/* density.c — scalar density fields: constant, Mitsuba .vol, NanoVDB, procedural cloud; bound grids;
 * a 3-D DDA. See density.h for the conventions (values at cell centres, trilinear, clamp, 0 outside).
 *
 * File formats (all little-endian):
 *   .vol: 'V' 'O' 'L' 3 | int32 encoding (1 = float32) | int32 xres, yres, zres | int32 channels |
 *         float32 xmin ymin zmin xmax ymax zmax | float32 data[((z*yres + y)*xres + x)*channels + c].
 *   .nvdb: either segments — FileHeader (u64 magic, u32 version, u16 gridCount, u16 codec), then
 *         gridCount x (176-byte FileMetaData + grid name), then the grid buffers (fileSize bytes each,
 *         = gridSize when uncompressed) — or, since NanoVDB 32.6, raw grid buffers back to back. Each
 *         grid buffer is read with PNanoVDB (the C port of NanoVDB), bounds-checked, so a corrupt
 *         file yields zeros or an error rather than a wild read. */
#include "density.h"
#include "atomic.h"
#include "error.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

enum { FIELD_CONSTANT, FIELD_GRID };

struct murk_field {
    int kind;
    float value;          /* FIELD_CONSTANT */
    int res[3];           /* FIELD_GRID: voxels per axis */
    murk_vec3 lo, hi;     /* world box */
    float scale[3];       /* res / (hi - lo): world to cell units */
    float *data;
    float vmin, vmax;     /* voxel extremes */
};

static float v3get(murk_vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }

/* ---- Little-endian scalars ------------------------------------------------------------------ */

static uint32_t rd_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t rd_u64(const unsigned char *p) { return (uint64_t)rd_u32(p) | (uint64_t)rd_u32(p + 4) << 32; }
static float rd_f32(const unsigned char *p)
{
    uint32_t u = rd_u32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}
static void wr_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}
static void wr_f32(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    wr_u32(p, u);
}
static int host_is_little_endian(void)
{
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* ---- Construction --------------------------------------------------------------------------- */

murk_field *murk_field_constant(float value)
{
    if (!isfinite(value) || value < 0.0f)
        return NULL;
    murk_field *f = calloc(1, sizeof *f);
    if (!f)
        return NULL;
    f->kind = FIELD_CONSTANT;
    f->value = f->vmin = f->vmax = value;
    f->res[0] = f->res[1] = f->res[2] = 1;
    f->lo = murk_v3(-INFINITY, -INFINITY, -INFINITY);
    f->hi = murk_v3(INFINITY, INFINITY, INFINITY);
    return f;
}

/* Multiplies three positive resolutions; 0 if the product exceeds MURK_FIELD_MAX_VOXELS. */
static uint64_t voxel_count(int64_t x, int64_t y, int64_t z)
{
    if (x < 1 || y < 1 || z < 1 || x > (int64_t)MURK_FIELD_MAX_VOXELS || y > (int64_t)MURK_FIELD_MAX_VOXELS ||
        z > (int64_t)MURK_FIELD_MAX_VOXELS)
        return 0;
    uint64_t xy = (uint64_t)x * (uint64_t)y; /* < 2^60 */
    if (xy > MURK_FIELD_MAX_VOXELS || (uint64_t)z > MURK_FIELD_MAX_VOXELS / xy)
        return 0;
    return xy * (uint64_t)z;
}

/* A grid field taking ownership of data (freed on failure). The box must be finite with lo < hi. */
static murk_field *grid_new(const int res[3], murk_vec3 lo, murk_vec3 hi, float *data)
{
    murk_field *f = calloc(1, sizeof *f);
    if (!f) {
        free(data);
        return NULL;
    }
    f->kind = FIELD_GRID;
    f->lo = lo;
    f->hi = hi;
    f->data = data;
    for (int a = 0; a < 3; a++) {
        f->res[a] = res[a];
        f->scale[a] = (float)res[a] / (v3get(hi, a) - v3get(lo, a));
    }
    uint64_t n = (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2];
    f->vmin = INFINITY;
    f->vmax = -INFINITY;
    for (uint64_t i = 0; i < n; i++) {
        f->vmin = fminf(f->vmin, data[i]);
        f->vmax = fmaxf(f->vmax, data[i]);
    }
    return f;
}

static int box_ok(murk_vec3 lo, murk_vec3 hi)
{
    for (int a = 0; a < 3; a++) {
        float l = v3get(lo, a), h = v3get(hi, a);
        if (!isfinite(l) || !isfinite(h) || !(l < h) || !isfinite(h - l))
            return 0;
    }
    return 1;
}

/* Checks every voxel is finite and >= 0; on failure writes "path: ..." and returns -1. */
static int check_values(const char *path, const float *data, const int res[3], const int origin[3], char *err,
                        size_t errlen)
{
    size_t i = 0;
    for (int z = 0; z < res[2]; z++)
        for (int y = 0; y < res[1]; y++)
            for (int x = 0; x < res[0]; x++, i++) {
                float v = data[i];
                if (isfinite(v) && v >= 0.0f)
                    continue;
                murk_err_file(err, errlen, path, "%s %g at voxel (%d, %d, %d); densities must be finite and >= 0", isnan(v) ? "invalid value" : (isinf(v) ? "infinite value" : "negative density"), (double)v, x + origin[0], y + origin[1], z + origin[2]);
                return -1;
            }
    return 0;
}

murk_field *murk_field_from_voxels(const int res[3], murk_vec3 lo, murk_vec3 hi, const float *data)
{
    uint64_t n = voxel_count(res[0], res[1], res[2]);
    if (n == 0 || !box_ok(lo, hi))
        return NULL;
    for (uint64_t i = 0; i < n; i++)
        if (!(isfinite(data[i]) && data[i] >= 0.0f))
            return NULL;
    float *copy = malloc((size_t)n * sizeof *copy);
    if (!copy)
        return NULL;
    memcpy(copy, data, (size_t)n * sizeof *copy);
    return grid_new(res, lo, hi, copy);
}

/* ---- Mitsuba .vol ----------------------------------------------------------------------------- */

#define VOL_HEADER 48

/* Opens a regular file for reading and gives its size; NULL with err set otherwise. */
static FILE *open_regular(const char *path, uint64_t *size, char *err, size_t errlen)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        murk_err_file(err, errlen, path, "%s", strerror(errno));
        return NULL;
    }
    struct stat st;
    if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
        murk_err_file(err, errlen, path, "not a regular file");
        fclose(fp);
        return NULL;
    }
    *size = (uint64_t)st.st_size;
    return fp;
}

murk_field *murk_field_vol_load(const char *path, char *err, size_t errlen)
{
    uint64_t fsize;
    FILE *fp = open_regular(path, &fsize, err, errlen);
    if (!fp)
        return NULL;
    unsigned char h[VOL_HEADER];
    size_t got = fread(h, 1, sizeof h, fp);
    if (got >= 3 && memcmp(h, "VOL", 3) != 0) {
        murk_err_file(err, errlen, path, "not a .vol file (bad magic; expected 'VOL')");
        goto fail;
    }
    if (got < sizeof h) {
        murk_err_file(err, errlen, path, "truncated header (%zu bytes; a .vol header has %d)", got, VOL_HEADER);
        goto fail;
    }
    if (h[3] != 3) {
        murk_err_file(err, errlen, path, "unsupported .vol version %d (murk reads version 3)", h[3]);
        goto fail;
    }
    int32_t enc = (int32_t)rd_u32(h + 4);
    if (enc != 1) {
        murk_err_file(err, errlen, path, "unsupported .vol encoding %d (murk reads 1 = float32)", (int)enc);
        goto fail;
    }
    int32_t rx = (int32_t)rd_u32(h + 8), ry = (int32_t)rd_u32(h + 12), rz = (int32_t)rd_u32(h + 16);
    int32_t ch = (int32_t)rd_u32(h + 20);
    uint64_t n = voxel_count(rx, ry, rz);
    if (n == 0) {
        if (rx < 1 || ry < 1 || rz < 1)
            murk_err_file(err, errlen, path, "bad resolution %d x %d x %d", (int)rx, (int)ry, (int)rz);
        else
            murk_err_file(err, errlen, path, "resolution %d x %d x %d exceeds the limit of %llu voxels", (int)rx, (int)ry, (int)rz, (unsigned long long)MURK_FIELD_MAX_VOXELS);
        goto fail;
    }
    if (ch != 1) {
        murk_err_file(err, errlen, path, "%d channels; a density grid needs exactly 1 (extract one channel)", (int)ch);
        goto fail;
    }
    murk_vec3 lo = murk_v3(rd_f32(h + 24), rd_f32(h + 28), rd_f32(h + 32));
    murk_vec3 hi = murk_v3(rd_f32(h + 36), rd_f32(h + 40), rd_f32(h + 44));
    if (!box_ok(lo, hi)) {
        murk_err_file(err, errlen, path, "bad bounding box (%g %g %g)-(%g %g %g); need finite min < max on every axis", (double)lo.x, (double)lo.y, (double)lo.z, (double)hi.x, (double)hi.y, (double)hi.z);
        goto fail;
    }
    uint64_t want = n * 4u, have = fsize - VOL_HEADER;
    if (have < want) {
        murk_err_file(err, errlen, path, "truncated data: %d x %d x %d voxels need %llu bytes, the file holds %llu", (int)rx, (int)ry, (int)rz, (unsigned long long)want, (unsigned long long)have);
        goto fail;
    }
    if (have > want) {
        murk_err_file(err, errlen, path, "%llu bytes after the data (does the header's resolution %d x %d x %d match?)", (unsigned long long)(have - want), (int)rx, (int)ry, (int)rz);
        goto fail;
    }
    float *data = malloc((size_t)n * sizeof *data);
    if (!data) {
        murk_err_file(err, errlen, path, "out of memory for %llu voxels", (unsigned long long)n);
        goto fail;
    }
    if (fread(data, 4, (size_t)n, fp) != (size_t)n) {
        murk_err_file(err, errlen, path, "read error: %s", ferror(fp) ? strerror(errno) : "unexpected end of file");
        free(data);
        goto fail;
    }
    fclose(fp);
    if (!host_is_little_endian())
        for (uint64_t i = 0; i < n; i++)
            data[i] = rd_f32((const unsigned char *)&data[i]);
    int res[3] = {rx, ry, rz}, org[3] = {0, 0, 0};
    if (check_values(path, data, res, org, err, errlen) != 0) {
        free(data);
        return NULL;
    }
    murk_field *f = grid_new(res, lo, hi, data);
    if (!f)
        murk_err_file(err, errlen, path, "out of memory");
    return f;
fail:
    fclose(fp);
    return NULL;
}

typedef struct vol_out {
    const char *path;
    const murk_field *f;
} vol_out;

/* Fills the temporary with the header and the voxels of a grid field. */
static int vol_fill(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    const vol_out *o = user;
    const murk_field *f = o->f;
    (void)tmp;
    errno = 0;
    unsigned char h[VOL_HEADER];
    memcpy(h, "VOL", 3);
    h[3] = 3;
    wr_u32(h + 4, 1);
    wr_u32(h + 8, (uint32_t)f->res[0]);
    wr_u32(h + 12, (uint32_t)f->res[1]);
    wr_u32(h + 16, (uint32_t)f->res[2]);
    wr_u32(h + 20, 1);
    for (int a = 0; a < 3; a++) {
        wr_f32(h + 24 + 4 * a, v3get(f->lo, a));
        wr_f32(h + 36 + 4 * a, v3get(f->hi, a));
    }
    int ok = fwrite(h, 1, sizeof h, fp) == sizeof h;
    size_t n = (size_t)f->res[0] * (size_t)f->res[1] * (size_t)f->res[2];
    unsigned char buf[4096];
    for (size_t i = 0; ok && i < n;) {
        size_t k = 0;
        for (; k < sizeof buf / 4 && i < n; k++, i++)
            wr_f32(buf + 4 * k, f->data[i]);
        ok = fwrite(buf, 4, k, fp) == k;
    }
    if (!ok)
        return murk_err_file(err, errlen, o->path, "write error: %s", errno ? strerror(errno) : "I/O error");
    return 0;
}

MURK_API int murk_field_vol_save(const char *path, const murk_field *f, char *err, size_t errlen)
{
    if (!f || f->kind != FIELD_GRID)
        return murk_err_file(err, errlen, path, "only grid fields can be saved as .vol (this one is constant)");
    vol_out o = {path, f};
    return murk_write_atomic(path, vol_fill, &o, err, errlen);
}

/* ---- NanoVDB -------------------------------------------------------------------------------- */

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

/* Reads a whole file; returns the malloc'd bytes (NULL with err set on failure). */
static unsigned char *read_all(const char *path, uint64_t *size, char *err, size_t errlen)
{
    FILE *fp = open_regular(path, size, err, errlen);
    if (!fp)
        return NULL;
    if (*size > (uint64_t)SIZE_MAX - 8) {
        murk_err_file(err, errlen, path, "file too large");
        fclose(fp);
        return NULL;
    }
    unsigned char *b = malloc((size_t)*size + 8);
    if (!b) {
        murk_err_file(err, errlen, path, "out of memory reading %llu bytes", (unsigned long long)*size);
        fclose(fp);
        return NULL;
    }
    if (fread(b, 1, (size_t)*size, fp) != (size_t)*size) {
        murk_err_file(err, errlen, path, "read error");
        free(b);
        fclose(fp);
        return NULL;
    }
    fclose(fp);
    return b;
}

/* Finds the first float grid; sets *off / *len to its buffer within the file. */
static int nvdb_find_grid(const char *path, const unsigned char *b, uint64_t size, uint64_t *off, uint64_t *len,
                          char *err, size_t errlen)
{
    if (size >= 4 && rd_u32(b) == 0x56444220u) {
        murk_err_file(err, errlen, path, "an OpenVDB .vdb file, not NanoVDB (convert it with nanovdb_convert)");
        return -1;
    }
    if (size < 16) {
        murk_err_file(err, errlen, path, "too short for a NanoVDB file (%llu bytes)", (unsigned long long)size);
        return -1;
    }
    uint64_t magic = rd_u64(b);
    if (magic == bswap64(NVDB_MAGIC_NUMB) || magic == bswap64(NVDB_MAGIC_GRID) || magic == bswap64(NVDB_MAGIC_FILE)) {
        murk_err_file(err, errlen, path, "big-endian NanoVDB file; murk reads little-endian only");
        return -1;
    }
    if (magic != NVDB_MAGIC_NUMB && magic != NVDB_MAGIC_GRID && magic != NVDB_MAGIC_FILE) {
        murk_err_file(err, errlen, path, "not a NanoVDB file (bad magic)");
        return -1;
    }
    int raw = magic == NVDB_MAGIC_GRID ||
              (magic == NVDB_MAGIC_NUMB && nvdb_major(rd_u32(b + 8)) != NVDB_MAJOR && size >= 20 &&
               nvdb_major(rd_u32(b + 16)) == NVDB_MAJOR);
    if (raw) { /* grid buffers back to back */
        for (uint64_t p = 0; p < size;) {
            if (size - p < NVDB_GRID_SIZE + NVDB_TREE_SIZE) {
                murk_err_file(err, errlen, path, "truncated grid at byte %llu", (unsigned long long)p);
                return -1;
            }
            uint64_t m = rd_u64(b + p);
            uint32_t ver = rd_u32(b + p + 16);
            uint64_t gsize = rd_u64(b + p + 32);
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
            if (rd_u32(b + p + 636) == NVDB_TYPE_FLOAT) {
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
        uint64_t m = rd_u64(b + p);
        uint32_t ver = rd_u32(b + p + 8);
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
            uint64_t name = rd_u32(b + q + 136);
            if (name > size - q - NVDB_META_SIZE) {
                murk_err_file(err, errlen, path, "truncated grid name at byte %llu", (unsigned long long)q);
                return -1;
            }
            q += NVDB_META_SIZE + name;
        }
        /* Second pass: walk metadata and buffers together. */
        uint64_t meta = p + 16, data = q;
        for (unsigned i = 0; i < count; i++) {
            uint64_t gsize = rd_u64(b + meta), fsize = rd_u64(b + meta + 8);
            uint32_t type = rd_u32(b + meta + 32);
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
            meta += NVDB_META_SIZE + rd_u32(b + meta + 136);
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
    uint64_t m = rd_u64(g);
    uint32_t ver = rd_u32(g + 16);
    if ((m != NVDB_MAGIC_NUMB && m != NVDB_MAGIC_GRID) || nvdb_major(ver) != NVDB_MAJOR) {
        murk_err_file(err, errlen, path, "bad grid header (magic or version)");
        return NULL;
    }
    if (rd_u32(g + 636) != NVDB_TYPE_FLOAT) {
        murk_err_file(err, errlen, path, "grid is not a float grid");
        return NULL;
    }
    if (rd_u32(g + 632) == NVDB_CLASS_LEVEL_SET) {
        murk_err_file(err, errlen, path, "the float grid is a level set (signed distances), not a density (fog volume)");
        return NULL;
    }
    /* Index-to-world map: double matrix (row-major) at 296+88, translation at 296+232. */
    double mat[9], vec[3], scale[3];
    for (int i = 0; i < 9; i++) {
        uint64_t u = rd_u64(g + 384 + 8 * i);
        memcpy(&mat[i], &u, 8);
    }
    for (int i = 0; i < 3; i++) {
        uint64_t u = rd_u64(g + 528 + 8 * i);
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
    uint64_t n = voxel_count(r0, r1, r2);
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
    if (!box_ok(lo, hi)) {
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
    if (check_values(path, data, res, org, err, errlen) != 0) {
        free(data);
        return NULL;
    }
    murk_field *f = grid_new(res, lo, hi, data);
    if (!f)
        murk_err_file(err, errlen, path, "out of memory");
    return f;
}
#endif

murk_field *murk_field_nvdb_load(const char *path, char *err, size_t errlen)
{
    uint64_t size = 0, off = 0, len = 0;
    unsigned char *b = read_all(path, &size, err, errlen);
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

/* ---- Procedural cloud ----------------------------------------------------------------------- */

static uint64_t lattice_hash(uint64_t seed, int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)x * 0x9e3779b97f4a7c15ull ^ (uint64_t)y * 0xc2b2ae3d27d4eb4full ^
                 (uint64_t)z * 0x165667b19e3779f9ull;
    return murk_hash64(h ^ murk_hash64(seed));
}

static double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/* Gradient noise (Perlin 2002 style: quintic fade, 12 edge gradients), roughly in [-1, 1]. */
static double gradient_noise(uint64_t seed, double x, double y, double z)
{
    static const signed char G[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                         {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    double fx = floor(x), fy = floor(y), fz = floor(z);
    int64_t ix = (int64_t)fx, iy = (int64_t)fy, iz = (int64_t)fz;
    double dx = x - fx, dy = y - fy, dz = z - fz;
    double c[8];
    for (int k = 0; k < 8; k++) {
        int ox = k & 1, oy = (k >> 1) & 1, oz = (k >> 2) & 1;
        const signed char *g = G[lattice_hash(seed, ix + ox, iy + oy, iz + oz) % 12u];
        c[k] = g[0] * (dx - ox) + g[1] * (dy - oy) + g[2] * (dz - oz);
    }
    double u = fade(dx), v = fade(dy), w = fade(dz);
    double x00 = c[0] + u * (c[1] - c[0]), x10 = c[2] + u * (c[3] - c[2]);
    double x01 = c[4] + u * (c[5] - c[4]), x11 = c[6] + u * (c[7] - c[6]);
    double y0 = x00 + v * (x10 - x00), y1 = x01 + v * (x11 - x01);
    return y0 + w * (y1 - y0);
}

static double smoothstep01(double a, double b, double x)
{
    double t = (x - a) / (b - a);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return t * t * (3.0 - 2.0 * t);
}

MURK_API murk_field *murk_field_cloud(murk_vec3 lo, murk_vec3 hi, int res, uint64_t seed, float frequency, int octaves,
                             float coverage)
{
    if (!box_ok(lo, hi) || res < 2 || res > 1024 || !(frequency > 0.0f) || !isfinite(frequency) || octaves < 1 ||
        octaves > 16 || !(coverage >= 0.0f && coverage <= 1.0f))
        return NULL;
    uint64_t n = voxel_count(res, res, res);
    if (n == 0)
        return NULL;
    float *data = malloc((size_t)n * sizeof *data);
    if (!data)
        return NULL;
    double ext[3], emax = 0.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = (double)v3get(hi, a) - v3get(lo, a);
        emax = fmax(emax, ext[a]);
    }
    /* Per-octave seeds and offsets decorrelate the octaves. */
    uint64_t oseed[16];
    double off[16][3], norm = 0.0;
    for (int o = 0; o < octaves; o++) {
        oseed[o] = murk_hash64(seed + 0x51ed27u * (uint64_t)(o + 1));
        for (int a = 0; a < 3; a++)
            off[o][a] = (double)(murk_hash64(oseed[o] + (uint64_t)a) >> 40) * (1.0 / 16777216.0) * 64.0;
        norm += ldexp(1.0, -o);
    }
    double vmax = 0.0;
    size_t i = 0;
    for (int z = 0; z < res; z++)
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++, i++) {
                int c[3] = {x, y, z};
                if (x == 0 || y == 0 || z == 0 || x == res - 1 || y == res - 1 || z == res - 1) {
                    data[i] = 0.0f; /* the outermost layer: density reaches 0 at the faces */
                    continue;
                }
                double q[3], np[3], r2 = 0.0, window = 1.0;
                for (int a = 0; a < 3; a++) {
                    double t = (c[a] + 0.5) / res;                /* 0..1 across the box */
                    q[a] = 2.0 * t - 1.0;                         /* -1..1 */
                    np[a] = t * ext[a] / emax * frequency;        /* isotropic noise space */
                    r2 += q[a] * q[a];
                    window *= smoothstep01(0.0, 0.2, 1.0 - fabs(q[a]));
                }
                double sum = 0.0;
                for (int o = 0; o < octaves; o++) {
                    double s = ldexp(1.0, o);
                    sum += ldexp(1.0, -o) * gradient_noise(oseed[o], np[0] * s + off[o][0], np[1] * s + off[o][1],
                                                           np[2] * s + off[o][2]);
                }
                double fbm = sum / norm;                          /* roughly -0.7..0.7 */
                double shape = 1.0 - sqrt(r2);                    /* 1 at the centre, <= 0 outside the ball */
                double d = (shape + 0.8 * fbm - 0.6 * (1.0 - coverage)) * window;
                d = d > 0.0 ? d : 0.0;
                data[i] = (float)d;
                vmax = fmax(vmax, (double)data[i]);
            }
    if (vmax > 0.0) {
        float peak = (float)vmax; /* divide (not multiply by a reciprocal) so the maximum is exactly 1 */
        for (size_t k = 0; k < (size_t)n; k++)
            data[k] /= peak;
    }
    int r[3] = {res, res, res};
    return grid_new(r, lo, hi, data);
}

/* ---- Queries -------------------------------------------------------------------------------- */

float murk_field_eval(const murk_field *f, murk_vec3 p)
{
    if (f->kind == FIELD_CONSTANT)
        return f->value;
    if (!(p.x >= f->lo.x && p.x <= f->hi.x && p.y >= f->lo.y && p.y <= f->hi.y && p.z >= f->lo.z && p.z <= f->hi.z))
        return 0.0f;
    int i0[3], i1[3];
    float w[3];
    for (int a = 0; a < 3; a++) {
        int n = f->res[a];
        float u = (v3get(p, a) - v3get(f->lo, a)) * f->scale[a] - 0.5f;
        if (u < 0.0f)
            u = 0.0f;
        if (u > (float)(n - 1))
            u = (float)(n - 1);
        int i = (int)u;
        if (i > n - 2)
            i = n >= 2 ? n - 2 : 0;
        i0[a] = i;
        i1[a] = n >= 2 ? i + 1 : i;
        w[a] = u - (float)i;
    }
    const float *d = f->data;
    size_t sx = 1, sy = (size_t)f->res[0], sz = (size_t)f->res[0] * (size_t)f->res[1];
    size_t z0 = (size_t)i0[2] * sz, z1 = (size_t)i1[2] * sz, y0 = (size_t)i0[1] * sy, y1 = (size_t)i1[1] * sy;
    size_t x0 = (size_t)i0[0] * sx, x1 = (size_t)i1[0] * sx;
    float c00 = d[z0 + y0 + x0] + w[0] * (d[z0 + y0 + x1] - d[z0 + y0 + x0]);
    float c10 = d[z0 + y1 + x0] + w[0] * (d[z0 + y1 + x1] - d[z0 + y1 + x0]);
    float c01 = d[z1 + y0 + x0] + w[0] * (d[z1 + y0 + x1] - d[z1 + y0 + x0]);
    float c11 = d[z1 + y1 + x0] + w[0] * (d[z1 + y1 + x1] - d[z1 + y1 + x0]);
    float c0 = c00 + w[1] * (c10 - c00), c1 = c01 + w[1] * (c11 - c01);
    float v = c0 + w[2] * (c1 - c0);
    return v > 0.0f ? v : 0.0f; /* rounding cannot make a density of non-negative voxels negative */
}

void murk_field_bounds(const murk_field *f, murk_vec3 *lo, murk_vec3 *hi, int *infinite)
{
    if (lo)
        *lo = f->lo;
    if (hi)
        *hi = f->hi;
    if (infinite)
        *infinite = f->kind == FIELD_CONSTANT;
}

MURK_API float murk_field_max(const murk_field *f) { return f->vmax; }
float murk_field_min(const murk_field *f) { return f->vmin; }

void murk_field_grid(const murk_field *f, int res[3], const float **data)
{
    for (int a = 0; a < 3; a++)
        res[a] = f->res[a];
    if (data)
        *data = f->data;
}

MURK_API void murk_field_free(murk_field *f)
{
    if (!f)
        return;
    free(f->data);
    free(f);
}

/* ---- Bound grid ----------------------------------------------------------------------------- */

int murk_bound_grid_build(const murk_field *f, int target_res, murk_bound_grid *g)
{
    memset(g, 0, sizeof *g);
    if (target_res < 1)
        return -1;
    if (f->kind == FIELD_CONSTANT) {
        g->res[0] = g->res[1] = g->res[2] = 1;
        g->lo = f->lo;
        g->hi = f->hi;
        g->maj = malloc(sizeof *g->maj);
        g->min = malloc(sizeof *g->min);
        if (!g->maj || !g->min) {
            murk_bound_grid_free(g);
            return -1;
        }
        g->maj[0] = g->min[0] = f->value;
        return 0;
    }
    double ext[3], emax = 0.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = (double)v3get(f->hi, a) - v3get(f->lo, a);
        emax = fmax(emax, ext[a]);
    }
    for (int a = 0; a < 3; a++) {
        double r = ceil(target_res * ext[a] / emax - 1e-9);
        g->res[a] = r < 1.0 ? 1 : (r > target_res ? target_res : (int)r);
    }
    if (voxel_count(g->res[0], g->res[1], g->res[2]) == 0) {
        memset(g, 0, sizeof *g);
        return -1;
    }
    g->lo = f->lo;
    g->hi = f->hi;
    size_t n = (size_t)g->res[0] * (size_t)g->res[1] * (size_t)g->res[2];
    g->maj = malloc(n * sizeof *g->maj);
    g->min = malloc(n * sizeof *g->min);
    if (!g->maj || !g->min) {
        murk_bound_grid_free(g);
        return -1;
    }
    /* Per axis and bound cell: the voxel index range whose interpolation support overlaps the cell.
     * In continuous index space u = (w - lo) * res / ext - 1/2 voxel i has support (i-1, i+1), and
     * the clamped border half-cells use voxel 0 / res-1 only; so the range is
     * [floor(clamp(ua)), ceil(clamp(ub))], widened by 1e-3 voxel so that neither float rounding
     * in eval nor a DDA segment overshooting its cell by a rounding error can reach a voxel
     * outside it. The bound grid's box is the field's box, so no cell reaches outside it (where
     * the density, 0, would force min = 0). */
    int *range[3];
    for (int a = 0; a < 3; a++) {
        range[a] = malloc(2 * (size_t)g->res[a] * sizeof(int));
        if (!range[a]) {
            for (int b = 0; b < a; b++)
                free(range[b]);
            murk_bound_grid_free(g);
            return -1;
        }
        int nv = f->res[a];
        double lo = v3get(f->lo, a), cell = ext[a] / g->res[a], s = nv / ext[a];
        for (int c = 0; c < g->res[a]; c++) {
            double wa = lo + c * cell, wb = lo + (c + 1) * cell;
            double ua = (wa - lo) * s - 0.5 - 1e-3, ub = (wb - lo) * s - 0.5 + 1e-3;
            ua = ua < 0.0 ? 0.0 : (ua > nv - 1 ? nv - 1 : ua);
            ub = ub < 0.0 ? 0.0 : (ub > nv - 1 ? nv - 1 : ub);
            range[a][2 * c] = (int)floor(ua);
            range[a][2 * c + 1] = (int)ceil(ub);
        }
    }
    size_t sy = (size_t)f->res[0], sz = (size_t)f->res[0] * (size_t)f->res[1];
    size_t k = 0;
    for (int cz = 0; cz < g->res[2]; cz++)
        for (int cy = 0; cy < g->res[1]; cy++)
            for (int cx = 0; cx < g->res[0]; cx++, k++) {
                float mx = 0.0f, mn = INFINITY;
                for (int z = range[2][2 * cz]; z <= range[2][2 * cz + 1]; z++)
                    for (int y = range[1][2 * cy]; y <= range[1][2 * cy + 1]; y++) {
                        const float *row = f->data + (size_t)z * sz + (size_t)y * sy;
                        for (int x = range[0][2 * cx]; x <= range[0][2 * cx + 1]; x++) {
                            mx = fmaxf(mx, row[x]);
                            mn = fminf(mn, row[x]);
                        }
                    }
                g->maj[k] = mx;
                g->min[k] = mn;
            }
    for (int a = 0; a < 3; a++)
        free(range[a]);
    return 0;
}

void murk_bound_grid_free(murk_bound_grid *g)
{
    free(g->maj);
    free(g->min);
    g->maj = g->min = NULL;
}

/* ---- DDA ------------------------------------------------------------------------------------ */

/* Parameter at which the ray leaves the current cell along axis a (INFINITY if it never does, or
 * if it cannot step further because this is the last cell: the last cell then absorbs rounding). */
static double dda_tnext(const murk_dda *it, int a)
{
    int s = it->step[a], i = it->idx[a];
    if (s == 0 || (s > 0 && i >= it->g->res[a] - 1) || (s < 0 && i <= 0))
        return INFINITY;
    double b = v3get(it->g->lo, a) + (s > 0 ? i + 1 : i) * it->h[a];
    return (b - it->o[a]) * it->inv_d[a];
}

enum { DDA_BEFORE, DDA_ENTER, DDA_INSIDE, DDA_AFTER, DDA_DONE };

void murk_dda_init(murk_dda *it, const murk_bound_grid *g, const murk_ray *r, float t0, float t1)
{
    memset(it, 0, sizeof *it);
    it->g = g;
    it->t = t0;
    it->t1 = t1;
    it->cell[0] = it->cell[1] = it->cell[2] = -1;
    for (int a = 0; a < 3; a++) {
        it->o[a] = v3get(r->o, a);
        it->d[a] = v3get(r->d, a);
    }
    it->tin = 1.0f;
    it->tout = 0.0f; /* missed unless proved otherwise */
    if (!(t0 < t1)) {
        it->phase = DDA_DONE;
        return;
    }
    it->phase = DDA_AFTER;
    if (isinf(g->lo.x)) { /* infinite (constant) grid: one segment */
        it->tin = t0;
        it->tout = t1;
        it->phase = DDA_INSIDE;
        return;
    }
    double tin = t0, tout = t1;
    for (int a = 0; a < 3; a++) {
        double o = it->o[a], d = it->d[a], lo = v3get(g->lo, a), hi = v3get(g->hi, a);
        if (!isfinite(o) || !isfinite(d))
            return; /* a broken ray sees no density */
        if (d == 0.0) {
            if (o < lo || o > hi)
                return;
            continue;
        }
        double ta = (lo - o) / d, tb = (hi - o) / d;
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        tin = fmax(tin, ta);
        tout = fmin(tout, tb);
    }
    /* t0 <= tin and tout <= t1 in double, so also after rounding to float (t0, t1 are floats). */
    float fin = (float)tin, fout = (float)tout;
    if (!(fin < fout))
        return; /* missed, or only touched */
    it->tin = fin;
    it->tout = fout;
    it->phase = fin > t0 ? DDA_BEFORE : DDA_ENTER;
}

/* Enters the box at it->t: the cell holding the ray point there, and the step directions. */
static void dda_enter(murk_dda *it)
{
    const murk_bound_grid *g = it->g;
    for (int a = 0; a < 3; a++) {
        double d = it->d[a];
        it->step[a] = d > 0.0 ? 1 : (d < 0.0 ? -1 : 0);
        it->h[a] = ((double)v3get(g->hi, a) - v3get(g->lo, a)) / g->res[a];
        it->inv_d[a] = d != 0.0 ? 1.0 / d : 0.0;
        double u = (it->o[a] + d * it->t - v3get(g->lo, a)) / it->h[a];
        it->idx[a] = u <= 0.0 ? 0 : (u >= g->res[a] - 1 ? g->res[a] - 1 : (int)floor(u));
    }
}

int murk_dda_next(murk_dda *it, float *ta, float *tb, float *maj, float *min)
{
    const murk_bound_grid *g = it->g;
    float a0, b0, mj = 0.0f, mn = 0.0f;
    it->cell[0] = it->cell[1] = it->cell[2] = -1;
    switch (it->phase) {
    case DDA_BEFORE:
        a0 = it->t;
        b0 = it->t = it->tin;
        it->phase = DDA_ENTER;
        break;
    case DDA_ENTER:
        dda_enter(it);
        it->phase = DDA_INSIDE;
        /* fall through */
    case DDA_INSIDE:
        if (isinf(g->lo.x)) {
            a0 = it->t;
            b0 = it->t = it->t1;
            mj = g->maj[0];
            mn = g->min[0];
            it->cell[0] = it->cell[1] = it->cell[2] = 0;
            it->phase = DDA_DONE;
            break;
        }
        for (;;) {
            int axis = -1;
            double tn = INFINITY;
            for (int a = 0; a < 3; a++) {
                double t = dda_tnext(it, a);
                if (t < tn) {
                    tn = t;
                    axis = a;
                }
            }
            float end = tn >= (double)it->tout ? it->tout : (float)tn;
            if (!(end > it->t)) { /* zero length (rounding, or an edge/corner crossing): step silently */
                if (axis < 0 || end >= it->tout) {
                    it->phase = DDA_AFTER;
                    return murk_dda_next(it, ta, tb, maj, min);
                }
                it->idx[axis] += it->step[axis];
                continue;
            }
            size_t k = ((size_t)it->idx[2] * (size_t)g->res[1] + (size_t)it->idx[1]) * (size_t)g->res[0] +
                       (size_t)it->idx[0];
            a0 = it->t;
            b0 = it->t = end;
            mj = g->maj[k];
            mn = g->min[k];
            for (int a = 0; a < 3; a++)
                it->cell[a] = it->idx[a];
            if (end >= it->tout)
                it->phase = DDA_AFTER;
            else
                it->idx[axis] += it->step[axis];
            break;
        }
        break;
    case DDA_AFTER: /* after the box, or the whole range for a miss */
        if (!(it->t < it->t1)) {
            it->phase = DDA_DONE;
            return 0;
        }
        a0 = it->t;
        b0 = it->t = it->t1;
        it->phase = DDA_DONE;
        break;
    default:
        return 0;
    }
    if (ta)
        *ta = a0;
    if (tb)
        *tb = b0;
    if (maj)
        *maj = mj;
    if (min)
        *min = mn;
    return 1;
}
