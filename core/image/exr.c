/* exr.c — linear float EXR files through OpenEXRCore, OpenEXR's C library (nothing of the C++ one).
 *
 * The writer produces a single scanline part with FLOAT channels B, G, R (EXR keeps channels sorted by
 * name), ZIP compression and one string attribute per murk_kv, into a temporary that murk_write_atomic
 * (atomic.h) renames over PATH only when all of it was written and read back identically. The reader
 * accepts part 0 of any scanline or tiled file with R, G, B (or Y) channels in HALF or FLOAT, converts
 * it to interleaved float RGB (Y is replicated, alpha and other channels are dropped) and copies every
 * string attribute.
 *
 * Errors: OpenEXRCore reports details through a callback. Reads route its first message into the
 * caller's buffer (the file is read through our own pread callbacks, so open/read failures carry
 * errno). Writes do not call back into the library from that callback: OpenEXRCore 3.1 holds a
 * non-recursive lock on write contexts while reporting, so the callback stays silent and the
 * message names the failing step plus the library's text for the result code. */
#include "image/image.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/util.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

typedef struct exr_io {
    int fd;
    int err;       /* errno of the first failed read or write, 0 if none */
    char msg[256]; /* first message OpenEXRCore reported (reads only) */
} exr_io;

/* Moves sz bytes at offset off between the file and dst (reads) or src (writes) with pread/pwrite.
 * Returns the bytes moved — fewer only for a read reaching the end of the file, which the library
 * reports — or -1 with io->err set. */
static int64_t exr_transfer(exr_io *io, char *dst, const char *src, uint64_t sz, uint64_t off)
{
    uint64_t done = 0;
    if (off > (uint64_t)INT64_MAX - sz)
        return -1;
    while (done < sz) {
        size_t want = sz - done > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)(sz - done);
        ssize_t n = src ? pwrite(io->fd, src + done, want, (off_t)(off + done))
                        : pread(io->fd, dst + done, want, (off_t)(off + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 || (n == 0 && src)) {
            if (!io->err)
                io->err = n < 0 ? errno : EIO;
            return -1;
        }
        if (n == 0)
            break; /* end of file: a short read */
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t exr_read_cb(exr_const_context_t ctxt, void *user, void *buf, uint64_t sz, uint64_t off,
                           exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    return exr_transfer(user, buf, NULL, sz, off);
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
    (void)ctxt;
    (void)error_cb;
    return exr_transfer(user, NULL, buf, sz, off);
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
    if (!path || !rgb || !murk_image_size_ok(w, h) || nmeta < 0 || (nmeta > 0 && !meta))
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
    /* the header's size against the limit and the file's real size, before any buffer is sized by it
     * (at least 2 bytes, a HALF channel, per pixel) */
    if (murk_image_declared_ok(path, "EXR", w, h, 2.0, murk_image_fd_size(io->fd), err, errlen) != 0)
        return -1;

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
    exr_io io;
    memset(&io, 0, sizeof io);
    io.fd = murk_image_open_input(path, img, err, errlen);
    if (io.fd < 0)
        return -1;

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
