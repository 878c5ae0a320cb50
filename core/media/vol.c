/* vol.c — Mitsuba 3 .vol grids: density (1 channel) and RGB (1 or 3 channels: albedo, emission) reading,
 * density writing (see density.h for what is accepted).
 *
 * Format (little-endian): 'V' 'O' 'L' 3 | int32 encoding (1 = float32) | int32 xres, yres, zres |
 * int32 channels | float32 xmin ymin zmin xmax ymax zmax | float32 data[((z*yres + y)*xres + x)*channels + c]. */
#include "media/field_impl.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/file.h"
#include "util/util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float rd_f32(const unsigned char *p)
{
    uint32_t u = murk_rd_u32(p);
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

#define VOL_HEADER 48

/* Reads a .vol file of 1 to max_ch channels: *ch, the resolution, the box and the interleaved float32
 * voxels (*data, the caller's to free). -1 with err on any fault. */
static int vol_read(const char *path, int max_ch, int *ch_out, int res[3], murk_vec3 *lo_out, murk_vec3 *hi_out,
                    float **data_out, char *err, size_t errlen)
{
    uint64_t fsize;
    FILE *fp = murk_file_open_regular(path, &fsize, err, errlen);
    if (!fp)
        return -1;
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
    int32_t enc = (int32_t)murk_rd_u32(h + 4);
    if (enc != 1) {
        murk_err_file(err, errlen, path, "unsupported .vol encoding %d (murk reads 1 = float32)", (int)enc);
        goto fail;
    }
    int32_t rx = (int32_t)murk_rd_u32(h + 8), ry = (int32_t)murk_rd_u32(h + 12), rz = (int32_t)murk_rd_u32(h + 16);
    int32_t ch = (int32_t)murk_rd_u32(h + 20);
    uint64_t n = murk_voxel_count(rx, ry, rz);
    if (n == 0) {
        if (rx < 1 || ry < 1 || rz < 1)
            murk_err_file(err, errlen, path, "bad resolution %d x %d x %d", (int)rx, (int)ry, (int)rz);
        else
            murk_err_file(err, errlen, path, "resolution %d x %d x %d exceeds the limit of %llu voxels", (int)rx, (int)ry, (int)rz, (unsigned long long)MURK_FIELD_MAX_VOXELS);
        goto fail;
    }
    if (ch != 1 && (max_ch == 1 || ch != max_ch)) {
        if (max_ch == 1)
            murk_err_file(err, errlen, path, "%d channels; a density grid needs exactly 1 (extract one channel)", (int)ch);
        else
            murk_err_file(err, errlen, path, "%d channels; an RGB grid has 1 (grey) or %d", (int)ch, max_ch);
        goto fail;
    }
    murk_vec3 lo = murk_v3(rd_f32(h + 24), rd_f32(h + 28), rd_f32(h + 32));
    murk_vec3 hi = murk_v3(rd_f32(h + 36), rd_f32(h + 40), rd_f32(h + 44));
    if (!murk_box_ok(lo, hi)) {
        murk_err_file(err, errlen, path, "bad bounding box (%g %g %g)-(%g %g %g); need finite min < max, at least 1e-20 apart, on every axis", (double)lo.x, (double)lo.y, (double)lo.z, (double)hi.x, (double)hi.y, (double)hi.z);
        goto fail;
    }
    uint64_t want = n * 4u * (uint64_t)ch, have = fsize - VOL_HEADER;
    if (have < want) {
        murk_err_file(err, errlen, path, "truncated data: %d x %d x %d voxels need %llu bytes, the file holds %llu", (int)rx, (int)ry, (int)rz, (unsigned long long)want, (unsigned long long)have);
        goto fail;
    }
    if (have > want) {
        murk_err_file(err, errlen, path, "%llu bytes after the data (does the header's resolution %d x %d x %d match?)", (unsigned long long)(have - want), (int)rx, (int)ry, (int)rz);
        goto fail;
    }
    size_t nv = (size_t)n * (size_t)ch;
    float *data = malloc(nv * sizeof *data);
    if (!data) {
        murk_err_file(err, errlen, path, "out of memory for %llu voxels", (unsigned long long)n);
        goto fail;
    }
    if (fread(data, 4, nv, fp) != nv) {
        murk_err_file(err, errlen, path, "read error: %s", ferror(fp) ? strerror(errno) : "unexpected end of file");
        free(data);
        goto fail;
    }
    fclose(fp);
    if (!host_is_little_endian())
        for (size_t i = 0; i < nv; i++)
            data[i] = rd_f32((const unsigned char *)&data[i]);
    *ch_out = ch;
    res[0] = rx, res[1] = ry, res[2] = rz;
    *lo_out = lo;
    *hi_out = hi;
    *data_out = data;
    return 0;
fail:
    fclose(fp);
    return -1;
}

murk_field *murk_field_vol_load(const char *path, char *err, size_t errlen)
{
    int ch, res[3], org[3] = {0, 0, 0};
    murk_vec3 lo, hi;
    float *data;
    if (vol_read(path, 1, &ch, res, &lo, &hi, &data, err, errlen))
        return NULL;
    return murk_field_adopt(path, res, org, lo, hi, data, err, errlen);
}

int murk_field_vol_load3(const char *path, murk_field *out[3], char *err, size_t errlen)
{
    int ch, res[3], org[3] = {0, 0, 0};
    murk_vec3 lo, hi;
    float *data;
    out[0] = out[1] = out[2] = NULL;
    if (vol_read(path, 3, &ch, res, &lo, &hi, &data, err, errlen))
        return -1;
    if (ch == 1) {
        out[0] = out[1] = out[2] = murk_field_adopt(path, res, org, lo, hi, data, err, errlen);
        return out[0] ? 1 : -1;
    }
    size_t n = (size_t)res[0] * (size_t)res[1] * (size_t)res[2];
    for (int c = 0; c < 3; c++) { /* the channels apart: each a field of its own, checked and wrapped */
        float *plane = malloc(n * sizeof *plane);
        if (!plane) {
            murk_err_file(err, errlen, path, "out of memory");
        } else {
            for (size_t i = 0; i < n; i++)
                plane[i] = data[3 * i + (size_t)c];
            out[c] = murk_field_adopt(path, res, org, lo, hi, plane, err, errlen);
        }
        if (!out[c]) {
            for (int k = 0; k < c; k++)
                murk_field_free(out[k]);
            out[0] = out[1] = out[2] = NULL;
            free(data);
            return -1;
        }
    }
    free(data);
    return 3;
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
        wr_f32(h + 24 + 4 * a, murk_v3_get(f->lo, a));
        wr_f32(h + 36 + 4 * a, murk_v3_get(f->hi, a));
    }
    int ok = fwrite(h, 1, sizeof h, fp) == sizeof h;
    size_t n = (size_t)f->res[0] * (size_t)f->res[1] * (size_t)f->res[2];
    unsigned char buf[4096];
    int x = 0, y = 0, z = 0; /* voxel i of a sparse grid */
    for (size_t i = 0; ok && i < n;) {
        size_t k = 0;
        for (; k < sizeof buf / 4 && i < n; k++, i++) {
            wr_f32(buf + 4 * k, f->data ? f->data[i] : murk_field_voxel(f, x, y, z));
            if (++x == f->res[0] && (x = 0, ++y == f->res[1]))
                y = 0, z++;
        }
        ok = fwrite(buf, 4, k, fp) == k;
    }
    if (!ok)
        return murk_err_file(err, errlen, o->path, "write error: %s", errno ? strerror(errno) : "I/O error");
    return 0;
}

MURK_API int murk_field_vol_save(const char *path, const murk_field *f, char *err, size_t errlen)
{
    if (!f || f->kind == FIELD_CONSTANT)
        return murk_err_file(err, errlen, path, "only grid fields can be saved as .vol (this one is constant)");
    if (f->affine)
        return murk_err_file(err, errlen, path, "a grid whose map rotates, shears or mirrors cannot be saved as .vol "
                             "(a .vol box is axis-aligned)");
    if (!murk_voxel_count(f->res[0], f->res[1], f->res[2]))
        return murk_err_file(err, errlen, path, "the grid's box of %d x %d x %d voxels exceeds the limit of %llu voxels "
                             "of a .vol", f->res[0], f->res[1], f->res[2], (unsigned long long)MURK_FIELD_MAX_VOXELS);
    vol_out o = {path, f};
    return murk_write_atomic(path, vol_fill, &o, err, errlen);
}
