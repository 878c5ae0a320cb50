/* image.c — image files: linear float EXR through OpenEXRCore, 8-bit sRGB PNG through libpng.
 *
 * EXR uses OpenEXRCore, OpenEXR's C library, and nothing of the C++ one. The writer produces a
 * single scanline part with FLOAT channels B, G, R (EXR keeps channels sorted by name), ZIP
 * compression and one string attribute per murk_kv. The reader accepts part 0 of any scanline or
 * tiled file with R, G, B (or Y) channels in HALF or FLOAT, converts it to interleaved float RGB
 * (Y is replicated, alpha and other channels are dropped) and copies every string attribute.
 *
 * PNG uses libpng. The writer makes an 8-bit sRGB preview of linear data; the reader lets libpng
 * reduce every 8/16-bit grey, grey+alpha, RGB, RGBA or palette image to 8-bit RGB, then maps it to
 * linear floats (the exact sRGB EOTF, or v/255).
 *
 * Both writers fill a temporary through murk_write_atomic (atomic.h), which renames it over PATH only
 * when all of it was written; on any failure PATH is left as it was.
 *
 * Errors: OpenEXRCore reports details through a callback. Reads route its first message into the
 * caller's buffer (the file is read through our own pread callbacks, so open/read failures carry
 * errno). Writes do not call back into the library from that callback: OpenEXRCore 3.1 holds a
 * non-recursive lock on write contexts while reporting, so the callback stays silent and the
 * message names the failing step plus the library's text for the result code. libpng errors
 * longjmp back into small functions whose caller owns every resource, so nothing leaks. */
#include "image.h"
#include "atomic.h"
#include "error.h"
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>
#include <png.h>

/* ---------------------------------------------------------------------------------------------- */
/* Shared helpers                                                                                   */

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

/* Checks w, h and that 3*w*h floats (and 12*w bytes per row) can be addressed. */
static int size_ok(long long w, long long h)
{
    return w > 0 && h > 0 && w <= INT_MAX / 12 && h <= INT_MAX &&
           (unsigned long long)w * (unsigned long long)h <= SIZE_MAX / 12;
}

const char *murk_image_meta(const murk_image *img, const char *key)
{
    for (int i = 0; img && key && i < img->nmeta; i++)
        if (img->meta[i].key && strcmp(img->meta[i].key, key) == 0)
            return img->meta[i].value;
    return NULL;
}

MURK_API void murk_image_free(murk_image *img)
{
    if (!img)
        return;
    free(img->rgb);
    for (int i = 0; img->meta && i < img->nmeta; i++) {
        free((char *)img->meta[i].key);
        free((char *)img->meta[i].value);
    }
    free(img->meta);
    memset(img, 0, sizeof *img);
}

/* ---------------------------------------------------------------------------------------------- */
/* EXR                                                                                              */

typedef struct exr_io {
    int fd;
    int err;       /* errno of the first failed read or write, 0 if none */
    char msg[256]; /* first message OpenEXRCore reported (reads only) */
} exr_io;

static int64_t exr_read_cb(exr_const_context_t ctxt, void *user, void *buf, uint64_t sz, uint64_t off,
                           exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = user;
    char *p = buf;
    uint64_t done = 0;
    (void)ctxt;
    (void)error_cb;
    if (off > (uint64_t)INT64_MAX - sz)
        return -1;
    while (done < sz) {
        size_t want = sz - done > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)(sz - done);
        ssize_t n = pread(io->fd, p + done, want, (off_t)(off + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            if (!io->err)
                io->err = errno;
            return -1;
        }
        if (n == 0)
            break; /* end of file: a short read, which the library reports */
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t exr_size_cb(exr_const_context_t ctxt, void *user)
{
    exr_io *io = user;
    struct stat st;
    (void)ctxt;
    return fstat(io->fd, &st) == 0 ? (int64_t)st.st_size : -1;
}

static int64_t exr_write_cb(exr_const_context_t ctxt, void *user, const void *buf, uint64_t sz, uint64_t off,
                            exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = user;
    const char *p = buf;
    uint64_t done = 0;
    (void)ctxt;
    (void)error_cb;
    if (off > (uint64_t)INT64_MAX - sz)
        return -1;
    while (done < sz) {
        size_t want = sz - done > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)(sz - done);
        ssize_t n = pwrite(io->fd, p + done, want, (off_t)(off + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            if (!io->err)
                io->err = n < 0 ? errno : EIO;
            return -1;
        }
        done += (uint64_t)n;
    }
    return (int64_t)sz;
}

/* Read contexts: keep the first message. exr_get_user_data takes no lock on read contexts. */
static void exr_read_error_cb(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *user = NULL;
    (void)code;
    if (!ctxt || exr_get_user_data(ctxt, &user) != EXR_ERR_SUCCESS || !user)
        return;
    exr_io *io = user;
    if (!io->msg[0] && msg)
        snprintf(io->msg, sizeof io->msg, "%s", msg);
}

/* Write contexts: silent (see the note at the top of the file). */
static void exr_quiet_error_cb(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    (void)msg;
}

/* Offset of a channel inside an interleaved RGB pixel, or -1 for channels murk does not use. */
static int rgb_slot(const char *name)
{
    if (!name || !name[0] || name[1])
        return -1;
    switch (name[0]) {
    case 'R': return 0;
    case 'G': return 1;
    case 'B': return 2;
    default: return -1;
    }
}

/* Encodes every scanline chunk of part 0; *step names what was being done when it fails. */
static exr_result_t exr_write_pixels(exr_context_t ctx, int part, const float *rgb, int w, int h,
                                     const char **step)
{
    int32_t lines = 1;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    exr_encode_pipeline_t enc;
    int started = 0;
    memset(&enc, 0, sizeof enc);
    if (rv == EXR_ERR_SUCCESS && lines < 1)
        rv = EXR_ERR_INVALID_ARGUMENT;
    *step = "writing pixels";
    for (int y = 0; rv == EXR_ERR_SUCCESS && y < h; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (rv != EXR_ERR_SUCCESS)
            break;
        if (started) {
            rv = exr_encoding_update(ctx, part, &ci, &enc);
        } else {
            rv = exr_encoding_initialize(ctx, part, &ci, &enc);
            started = rv == EXR_ERR_SUCCESS;
        }
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int slot = rgb_slot(ch->channel_name);
            if (slot < 0) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            ch->encode_from_ptr = (const uint8_t *)(rgb + (size_t)y * (size_t)w * 3 + (size_t)slot);
            ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
            ch->user_line_stride = 3 * (int32_t)sizeof(float) * w;
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
        }
        if (rv == EXR_ERR_SUCCESS && !enc.convert_and_pack_fn)
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (started)
        exr_encoding_destroy(ctx, &enc);
    return rv;
}

/* Everything between opening the temporary and closing it. *step and *what describe a failure. */
static exr_result_t exr_write_file(exr_io *io, const char *tmp, const float *rgb, int w, int h,
                                   const murk_kv *meta, int nmeta, exr_compression_t comp, const char **step,
                                   const char **what)
{
    static const char *const names[3] = {"B", "G", "R"};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL;
    int part = 0;
    exr_result_t rv, frv;

    init.error_handler_fn = exr_quiet_error_cb;
    init.user_data = io;
    init.write_fn = exr_write_cb;
    *step = "starting the file";
    rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS)
        return rv;

    *step = "defining the image";
    rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, w, h, comp);
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    for (int i = 0; i < nmeta && rv == EXR_ERR_SUCCESS; i++) {
        *step = "setting attribute";
        *what = meta[i].key ? meta[i].key : "(null)";
        if (!meta[i].key || !meta[i].key[0]) {
            rv = EXR_ERR_INVALID_ARGUMENT;
            break;
        }
        if (strlen(meta[i].key) > 31)
            rv = exr_set_longname_support(ctx, 1);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_attr_set_string(ctx, part, meta[i].key, meta[i].value ? meta[i].value : "");
    }
    if (rv == EXR_ERR_SUCCESS) {
        *what = NULL;
        *step = "writing the header";
        rv = exr_write_header(ctx);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_pixels(ctx, part, rgb, w, h, step);
    if (rv == EXR_ERR_SUCCESS)
        *step = "finishing the file";
    frv = exr_finish(&ctx);
    return rv != EXR_ERR_SUCCESS ? rv : frv;
}

/* Writes the whole file through fd (the temporary tmp) with the given compression; 0, or -1 with err. */
static int exr_write_tmp(const char *path, int fd, const char *tmp, const float *rgb, int w, int h,
                         const murk_kv *meta, int nmeta, exr_compression_t comp, char *err, size_t errlen)
{
    exr_io io;
    memset(&io, 0, sizeof io);
    io.fd = fd;
    if (ftruncate(fd, 0) != 0)
        return murk_err_file(err, errlen, path, "cannot write %s: %s", tmp, strerror(errno));
    const char *step = "", *what = NULL;
    exr_result_t rv = exr_write_file(&io, tmp, rgb, w, h, meta, nmeta, comp, &step, &what);
    if (rv == EXR_ERR_SUCCESS)
        return 0;
    const char *why = io.err ? strerror(io.err) : exr_get_default_error_message(rv);
    if (what)
        return murk_err_file(err, errlen, path, "EXR error %s '%.64s': %s", step, what, why);
    return murk_err_file(err, errlen, path, "EXR error %s: %s", step, why);
}

/* 1 if the file at tmp holds exactly these pixels. */
static int exr_verify(const char *tmp, const float *rgb, int w, int h)
{
    murk_image img;
    char err[256];
    if (murk_exr_read(tmp, &img, err, sizeof err) != 0)
        return 0;
    int same = img.w == w && img.h == h && memcmp(img.rgb, rgb, 3 * sizeof(float) * (size_t)w * (size_t)h) == 0;
    murk_image_free(&img);
    return same;
}

typedef struct exr_job {
    const char *path;
    const float *rgb;
    int w, h, nmeta;
    const murk_kv *meta;
} exr_job;

/* Fills the temporary: ZIP, read back and checked bit for bit. OpenEXRCore 3.1's ZIP encoder can
 * store a chunk whose zlib output is as large as its input in a form its decoder misreads (openexr
 * issue 2306). If the check fails, the file is written again uncompressed. */
static int exr_fill(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    const exr_job *j = user;
    int fd = fileno(fp);
    int rc = exr_write_tmp(j->path, fd, tmp, j->rgb, j->w, j->h, j->meta, j->nmeta, EXR_COMPRESSION_ZIP, err, errlen);
    if (rc == 0 && !exr_verify(tmp, j->rgb, j->w, j->h))
        rc = exr_write_tmp(j->path, fd, tmp, j->rgb, j->w, j->h, j->meta, j->nmeta, EXR_COMPRESSION_NONE, err,
                           errlen);
    if (rc == 0 && !exr_verify(tmp, j->rgb, j->w, j->h))
        rc = murk_err_file(err, errlen, j->path, "the EXR written does not read back identically");
    return rc;
}

MURK_API int murk_exr_write(const char *path, const float *rgb, int w, int h, const murk_kv *meta, int nmeta,
                            char *err, size_t errlen)
{
    if (!path || !rgb || !size_ok(w, h) || nmeta < 0 || (nmeta > 0 && !meta))
        return murk_err_file(err, errlen, path ? path : "(null)", "invalid image (%dx%d)", w, h);
    exr_job j = {path, rgb, w, h, nmeta, meta};
    return murk_write_atomic(path, exr_fill, &j, err, errlen);
}

/* Decodes one chunk whose top-left pixel is (x0, y0) of the data window into img->rgb. slots[c] is
 * the RGB offset receiving file channel c, or -1 to skip it. */
static exr_result_t exr_decode_chunk(exr_context_t ctx, exr_decode_pipeline_t *dec, int *started,
                                     const exr_chunk_info_t *ci, const int *slots, float *rgb, int w, int h,
                                     int64_t x0, int64_t y0)
{
    exr_result_t rv;
    if (x0 < 0 || y0 < 0 || ci->width <= 0 || ci->height <= 0 || x0 + ci->width > w || y0 + ci->height > h)
        return EXR_ERR_CORRUPT_CHUNK;
    if (*started) {
        rv = exr_decoding_update(ctx, 0, ci, dec);
    } else {
        rv = exr_decoding_initialize(ctx, 0, ci, dec);
        *started = rv == EXR_ERR_SUCCESS;
    }
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        if (slots[c] < 0) {
            ch->decode_to_ptr = NULL;
            continue;
        }
        if (ch->width != ci->width || ch->height != ci->height)
            return EXR_ERR_CORRUPT_CHUNK;
        ch->decode_to_ptr = (uint8_t *)(rgb + ((size_t)y0 * (size_t)w + (size_t)x0) * 3 + (size_t)slots[c]);
        ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
        ch->user_line_stride = 3 * (int32_t)sizeof(float) * w;
        ch->user_bytes_per_element = (int16_t)sizeof(float);
        ch->user_data_type = EXR_PIXEL_FLOAT;
    }
    if (!dec->unpack_and_convert_fn) {
        rv = exr_decoding_choose_default_routines(ctx, 0, dec);
        if (rv != EXR_ERR_SUCCESS)
            return rv;
    }
    return exr_decoding_run(ctx, 0, dec);
}

static exr_result_t exr_read_pixels(exr_context_t ctx, exr_storage_t storage, const exr_attr_box2i_t *dw,
                                    const int *slots, float *rgb, int w, int h)
{
    exr_decode_pipeline_t dec;
    int started = 0;
    exr_result_t rv = EXR_ERR_SUCCESS;
    memset(&dec, 0, sizeof dec);
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        if (rv == EXR_ERR_SUCCESS && lines < 1)
            rv = EXR_ERR_FILE_BAD_HEADER;
        for (int64_t y = dw->min.y; rv == EXR_ERR_SUCCESS && y <= dw->max.y; y += lines) {
            exr_chunk_info_t ci;
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci);
            if (rv == EXR_ERR_SUCCESS && ci.width != w)
                rv = EXR_ERR_CORRUPT_CHUNK;
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_decode_chunk(ctx, &dec, &started, &ci, slots, rgb, w, h, 0,
                                      (int64_t)ci.start_y - dw->min.y);
        }
    } else {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t lmode;
        exr_tile_round_mode_t rmode;
        rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, &lmode, &rmode);
        if (rv == EXR_ERR_SUCCESS && (tw == 0 || th == 0))
            rv = EXR_ERR_FILE_BAD_HEADER;
        int64_t ntx = rv == EXR_ERR_SUCCESS ? ((int64_t)w + tw - 1) / tw : 0;
        int64_t nty = rv == EXR_ERR_SUCCESS ? ((int64_t)h + th - 1) / th : 0;
        for (int64_t ty = 0; rv == EXR_ERR_SUCCESS && ty < nty; ty++) {
            for (int64_t tx = 0; rv == EXR_ERR_SUCCESS && tx < ntx; tx++) {
                exr_chunk_info_t ci;
                rv = exr_read_tile_chunk_info(ctx, 0, (int)tx, (int)ty, 0, 0, &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = exr_decode_chunk(ctx, &dec, &started, &ci, slots, rgb, w, h, tx * tw, ty * th);
            }
        }
    }
    if (started)
        exr_decoding_destroy(ctx, &dec);
    return rv;
}

/* Copies every string attribute of part 0 into img->meta. */
static int exr_read_meta(exr_context_t ctx, murk_image *img)
{
    int32_t n = 0;
    if (exr_get_attribute_count(ctx, 0, &n) != EXR_ERR_SUCCESS || n <= 0)
        return 0;
    img->meta = calloc((size_t)n, sizeof *img->meta);
    if (!img->meta)
        return -1;
    for (int32_t i = 0; i < n; i++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(ctx, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) != EXR_ERR_SUCCESS || !a ||
            a->type != EXR_ATTR_STRING || !a->name || !a->string)
            continue;
        const exr_attr_string_t *s = a->string;
        size_t len = s->str && s->length > 0 ? (size_t)s->length : 0;
        murk_kv *kv = &img->meta[img->nmeta];
        kv->key = dup_n(a->name, strlen(a->name));
        kv->value = dup_n(len ? s->str : "", len);
        img->nmeta++; /* counted before checking, so murk_image_free releases a half-made pair */
        if (!kv->key || !kv->value)
            return -1;
    }
    return 0;
}

/* Reads part 0 of an open file; on failure returns -1 with err set (img is freed by the caller). */
static int exr_read_image(exr_context_t ctx, exr_io *io, const char *path, murk_image *img, char *err,
                          size_t errlen)
{
    int nparts = 0;
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    exr_result_t rv;

    if (exr_get_count(ctx, &nparts) != EXR_ERR_SUCCESS || nparts < 1)
        return murk_err_file(err, errlen, path, "EXR file has no parts");
    if (exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS ||
        (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED))
        return murk_err_file(err, errlen, path, "deep EXR images are not supported");
    if (exr_get_data_window(ctx, 0, &dw) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctx, 0, &chl) != EXR_ERR_SUCCESS || !chl)
        return murk_err_file(err, errlen, path, "EXR header lacks a data window or channel list");
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (!size_ok(w, h))
        return murk_err_file(err, errlen, path, "unsupported EXR size %lldx%lld", (long long)w, (long long)h);

    /* Map file channels to RGB slots: R, G, B if all three exist, else Y into slot 0. */
    int nch = chl->num_channels, found = 0, y_ch = -1;
    int *slots = malloc(sizeof *slots * (size_t)(nch > 0 ? nch : 1));
    if (!slots)
        return murk_err_file(err, errlen, path, "out of memory");
    for (int c = 0; c < nch; c++) {
        slots[c] = rgb_slot(chl->entries[c].name.str);
        if (slots[c] >= 0)
            found |= 1 << slots[c];
        else if (chl->entries[c].name.str && strcmp(chl->entries[c].name.str, "Y") == 0)
            y_ch = c;
    }
    if (found != 7) {
        for (int c = 0; c < nch; c++)
            slots[c] = c == y_ch ? 0 : -1;
    }
    int rc = 0;
    if (found != 7 && y_ch < 0)
        rc = murk_err_file(err, errlen, path, "EXR has neither R, G, B nor Y channels");
    for (int c = 0; c < nch && rc == 0; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        if (slots[c] < 0)
            continue;
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT)
            rc = murk_err_file(err, errlen, path, "EXR channel %s is not half or float", e->name.str);
        else if (e->x_sampling != 1 || e->y_sampling != 1)
            rc = murk_err_file(err, errlen, path, "EXR channel %s is subsampled", e->name.str);
    }
    if (rc == 0) {
        img->w = (int)w;
        img->h = (int)h;
        img->rgb = calloc((size_t)w * (size_t)h * 3, sizeof(float));
        if (!img->rgb)
            rc = murk_err_file(err, errlen, path, "out of memory");
    }
    if (rc == 0) {
        rv = exr_read_pixels(ctx, storage, &dw, slots, img->rgb, (int)w, (int)h);
        if (rv != EXR_ERR_SUCCESS) {
            const char *why = io->err     ? strerror(io->err)
                              : io->msg[0] ? io->msg
                                           : exr_get_default_error_message(rv);
            rc = murk_err_file(err, errlen, path, "cannot decode EXR pixels: %s", why);
        }
    }
    if (rc == 0 && found != 7) {
        size_t n = (size_t)w * (size_t)h;
        for (size_t i = 0; i < n; i++)
            img->rgb[3 * i + 1] = img->rgb[3 * i + 2] = img->rgb[3 * i];
    }
    if (rc == 0 && exr_read_meta(ctx, img) != 0)
        rc = murk_err_file(err, errlen, path, "out of memory");
    free(slots);
    return rc;
}

MURK_API int murk_exr_read(const char *path, murk_image *img, char *err, size_t errlen)
{
    if (!img)
        return murk_err_file(err, errlen, path ? path : "(null)", "no image to read into");
    memset(img, 0, sizeof *img);
    if (!path)
        return murk_err_file(err, errlen, "(null)", "no path");
    exr_io io;
    memset(&io, 0, sizeof io);
    io.fd = open(path, O_RDONLY | O_CLOEXEC);
    if (io.fd < 0)
        return murk_err_file(err, errlen, path, "cannot open: %s", strerror(errno));

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_read_error_cb;
    init.user_data = &io;
    init.read_fn = exr_read_cb;
    init.size_fn = exr_size_cb;
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    exr_context_t ctx = NULL;
    int rc;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        const char *why = io.err ? strerror(io.err) : io.msg[0] ? io.msg : exr_get_default_error_message(rv);
        rc = murk_err_file(err, errlen, path, "not a readable EXR file: %s", why);
    } else {
        rc = exr_read_image(ctx, &io, path, img, err, errlen);
    }
    if (ctx)
        exr_finish(&ctx);
    close(io.fd);
    if (rc != 0)
        murk_image_free(img);
    return rc;
}

/* ---------------------------------------------------------------------------------------------- */
/* PNG                                                                                              */

typedef struct png_job {
    FILE *fp;
    png_structp png;
    png_infop info;
    unsigned char *pix; /* write: one 8-bit RGB row; read: the whole 8-bit RGB image */
    png_bytep *rows;    /* read: row pointers into pix */
    png_uint_32 w, h;
    char msg[200];
} png_job;

static void png_error_cb(png_structp png, png_const_charp msg)
{
    png_job *j = png_get_error_ptr(png);
    if (j && !j->msg[0])
        snprintf(j->msg, sizeof j->msg, "%s", msg ? msg : "libpng error");
    png_longjmp(png, 1);
}

static void png_warning_cb(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static unsigned char srgb_encode8(float v, double scale)
{
    double x = (double)v * scale;
    if (!(x > 0.0)) /* also NaN */
        x = 0.0;
    if (x > 1.0)
        x = 1.0;
    x = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    return (unsigned char)(x * 255.0 + 0.5);
}

/* The libpng calls of a write; errors longjmp back here and the caller cleans up. */
static int png_encode(png_job *j, const float *rgb, int w, int h, double scale)
{
    if (setjmp(png_jmpbuf(j->png)))
        return -1;
    png_init_io(j->png, j->fp);
    png_set_IHDR(j->png, j->info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(j->png, j->info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(j->png, j->info);
    for (int y = 0; y < h; y++) {
        const float *src = rgb + (size_t)y * (size_t)w * 3;
        for (size_t i = 0; i < (size_t)w * 3; i++)
            j->pix[i] = srgb_encode8(src[i], scale);
        png_write_row(j->png, j->pix);
    }
    png_write_end(j->png, NULL);
    return 0;
}

typedef struct png_out {
    const float *rgb;
    int w, h;
    float exposure;
    const char *path;
} png_out;

/* Fills the temporary with the encoded preview. */
static int png_fill(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    const png_out *o = user;
    png_job j;
    int rc = 0;
    (void)tmp;
    memset(&j, 0, sizeof j);
    j.fp = fp;
    j.pix = malloc((size_t)o->w * 3);
    j.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &j, png_error_cb, png_warning_cb);
    if (j.png)
        j.info = png_create_info_struct(j.png);
    if (!j.pix || !j.png || !j.info)
        rc = murk_err_file(err, errlen, o->path, "out of memory");
    else if (png_encode(&j, o->rgb, o->w, o->h, exp2((double)o->exposure)) != 0)
        rc = murk_err_file(err, errlen, o->path, "cannot write PNG: %s", j.msg[0] ? j.msg : "libpng error");
    if (j.png)
        png_destroy_write_struct(&j.png, j.info ? &j.info : NULL);
    free(j.pix);
    return rc;
}

MURK_API int murk_png_write(const char *path, const float *rgb, int w, int h, float exposure, char *err,
                            size_t errlen)
{
    if (!path || !rgb || !size_ok(w, h))
        return murk_err_file(err, errlen, path ? path : "(null)", "invalid image (%dx%d)", w, h);
    png_out o = {rgb, w, h, exposure, path};
    return murk_write_atomic(path, png_fill, &o, err, errlen);
}

/* The libpng calls of a read into j->pix (allocated here, freed by the caller). */
static int png_decode(png_job *j)
{
    if (setjmp(png_jmpbuf(j->png)))
        return -1;
    png_init_io(j->png, j->fp);
    png_set_sig_bytes(j->png, 8);
    png_read_info(j->png, j->info);
    j->w = png_get_image_width(j->png, j->info);
    j->h = png_get_image_height(j->png, j->info);
    if (!size_ok(j->w, j->h)) {
        snprintf(j->msg, sizeof j->msg, "unsupported PNG size %lux%lu", (unsigned long)j->w, (unsigned long)j->h);
        return -1;
    }
    png_set_expand(j->png); /* palette -> RGB, grey < 8 bits -> 8 bits, tRNS -> alpha */
#ifdef PNG_READ_SCALE_16_TO_8_SUPPORTED
    png_set_scale_16(j->png);
#else
    png_set_strip_16(j->png);
#endif
    png_set_gray_to_rgb(j->png);
    png_set_strip_alpha(j->png);
    png_set_interlace_handling(j->png);
    png_read_update_info(j->png, j->info);
    if (png_get_channels(j->png, j->info) != 3 || png_get_bit_depth(j->png, j->info) != 8 ||
        png_get_rowbytes(j->png, j->info) != (size_t)j->w * 3) {
        snprintf(j->msg, sizeof j->msg, "unsupported PNG pixel format");
        return -1;
    }
    j->pix = malloc((size_t)j->w * (size_t)j->h * 3);
    j->rows = malloc(sizeof *j->rows * (size_t)j->h);
    if (!j->pix || !j->rows) {
        snprintf(j->msg, sizeof j->msg, "out of memory");
        return -1;
    }
    for (size_t y = 0; y < j->h; y++)
        j->rows[y] = j->pix + y * (size_t)j->w * 3;
    png_read_image(j->png, j->rows);
    png_read_end(j->png, NULL);
    return 0;
}

int murk_png_read(const char *path, int srgb, murk_image *img, char *err, size_t errlen)
{
    if (!img)
        return murk_err_file(err, errlen, path ? path : "(null)", "no image to read into");
    memset(img, 0, sizeof *img);
    if (!path)
        return murk_err_file(err, errlen, "(null)", "no path");
    png_job j;
    memset(&j, 0, sizeof j);
    int rc = 0, fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return murk_err_file(err, errlen, path, "cannot open: %s", strerror(errno));
    j.fp = fdopen(fd, "rb");
    if (!j.fp) {
        close(fd);
        return murk_err_file(err, errlen, path, "out of memory");
    }
    unsigned char sig[8];
    if (fread(sig, 1, sizeof sig, j.fp) != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0) {
        fclose(j.fp);
        return murk_err_file(err, errlen, path, "not a PNG file");
    }
    j.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &j, png_error_cb, png_warning_cb);
    if (j.png)
        j.info = png_create_info_struct(j.png);
    if (!j.png || !j.info)
        rc = murk_err_file(err, errlen, path, "out of memory");
    else if (png_decode(&j) != 0)
        rc = murk_err_file(err, errlen, path, "cannot read PNG: %s", j.msg[0] ? j.msg : "libpng error");
    if (j.png)
        png_destroy_read_struct(&j.png, j.info ? &j.info : NULL, NULL);
    fclose(j.fp);
    free(j.rows);
    if (rc == 0) {
        size_t n = (size_t)j.w * (size_t)j.h * 3;
        img->rgb = malloc(n * sizeof(float));
        if (!img->rgb) {
            rc = murk_err_file(err, errlen, path, "out of memory");
        } else {
            float lut[256];
            for (int v = 0; v < 256; v++) {
                double c = v / 255.0;
                if (srgb)
                    c = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
                lut[v] = (float)c;
            }
            for (size_t i = 0; i < n; i++)
                img->rgb[i] = lut[j.pix[i]];
            img->w = (int)j.w;
            img->h = (int)j.h;
        }
    }
    free(j.pix);
    return rc;
}
