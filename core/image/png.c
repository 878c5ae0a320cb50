/* png.c — 8-bit PNG files through libpng.
 *
 * The writer makes an 8-bit sRGB preview of linear data, into a temporary that murk_write_atomic
 * (atomic.h) renames over PATH only when all of it was written. The reader lets libpng reduce every
 * 8/16-bit grey, grey+alpha, RGB, RGBA or palette image to 8-bit RGB, then maps it to linear floats
 * (the exact sRGB EOTF, or v/255). libpng errors longjmp back into small functions whose caller owns
 * every resource, so nothing leaks. Every PNG written carries the text keys murk:version and murk:commit
 * (the build's, util/commit.c), so a figure says which build made it; the reader returns a file's text
 * keys (tEXt, zTXt, iTXt, before or after the image data) as the image's metadata. */
#include "image/image.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/limit.h"
#include "util/util.h"

#include <math.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <png.h>

typedef struct png_job {
    FILE *fp;
    png_structp png;
    png_infop info;
    unsigned char *pix; /* write: one 8-bit RGB row; read: the whole 8-bit RGB image */
    png_bytep *rows;    /* read: row pointers into pix */
    png_uint_32 w, h;
    char msg[200];
    const char *path;   /* read: for the size check's message */
    uint64_t file_size; /* read: the file's size */
    murk_image *img;    /* read: receives the text keys as metadata */
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
    png_text text[2];
    memset(text, 0, sizeof text);
    text[0].compression = text[1].compression = PNG_TEXT_COMPRESSION_NONE;
    text[0].key = (png_charp) "murk:version";
    text[0].text = (png_charp)murk_build_version();
    text[1].key = (png_charp) "murk:commit";
    text[1].text = (png_charp)murk_build_commit();
    png_set_text(j->png, j->info, text, 2);
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
    if (!path || !rgb || !murk_image_size_ok(w, h))
        return murk_err_file(err, errlen, path ? path : "(null)", "invalid image (%dx%d)", w, h);
    png_out o = {rgb, w, h, exposure, path};
    return murk_write_atomic(path, png_fill, &o, err, errlen);
}

/* The file's text chunks into j->img's metadata (pairs malloc'd; murk_image_free releases them). */
static int png_copy_text(png_job *j)
{
    png_textp text = NULL;
    int n = png_get_text(j->png, j->info, &text, NULL);
    if (n <= 0 || !text)
        return 0;
    j->img->meta = calloc((size_t)n, sizeof *j->img->meta);
    if (!j->img->meta) {
        snprintf(j->msg, sizeof j->msg, "out of memory");
        return -1;
    }
    for (int i = 0; i < n; i++) {
        murk_kv *kv = &j->img->meta[j->img->nmeta++]; /* counted first: murk_image_free releases a half pair */
        kv->key = strdup(text[i].key ? text[i].key : "");
        kv->value = strdup(text[i].text ? text[i].text : "");
        if (!kv->key || !kv->value) {
            snprintf(j->msg, sizeof j->msg, "out of memory");
            return -1;
        }
    }
    return 0;
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
    {
        /* before any allocation: the declared size against the limit and against what the file can hold
         * (bits per pixel as stored; deflate expands at most 1032:1) */
        char serr[512];
        double bpp = png_get_bit_depth(j->png, j->info) * png_get_channels(j->png, j->info) / 8.0;
        if (murk_image_declared_ok(j->path, "PNG", j->w, j->h, bpp, j->file_size, serr, sizeof serr) != 0) {
            const char *m = strstr(serr, ": ");
            m = m ? m + 2 : serr;
            size_t k = strlen(m) < sizeof j->msg ? strlen(m) : sizeof j->msg - 1;
            memcpy(j->msg, m, k);
            j->msg[k] = 0;
            return -1;
        }
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
    png_read_end(j->png, j->info); /* text chunks after the image data land in info too */
    return png_copy_text(j);
}

/* The chunk framing of the PNG open as fp, before libpng sees it: from byte 8 on, every chunk's 12 bytes of
 * length, type and CRC plus its declared length must fit in the file, up to IEND. libpng allocates a chunk's
 * declared length before reading it (a text chunk claiming 1.7 GB in a 240-byte file took that much memory),
 * so no allocation may be sized by a length the file cannot hold. Leaves fp at byte 8; 0 or -1 with msg. */
static int png_check_framing(FILE *fp, uint64_t size, char *msg, size_t msglen)
{
    uint64_t at = 8;
    for (;;) {
        unsigned char h[8];
        if (size - at < 12 || fseek(fp, (long)at, SEEK_SET) != 0 || fread(h, 1, sizeof h, fp) != sizeof h) {
            snprintf(msg, msglen, "the file ends at byte %llu before its IEND chunk", (unsigned long long)size);
            return -1;
        }
        uint64_t len = (uint64_t)h[0] << 24 | (uint64_t)h[1] << 16 | (uint64_t)h[2] << 8 | h[3];
        char type[5] = {0};
        for (int i = 0; i < 4; i++)
            type[i] = (h[4 + i] >= 'A' && h[4 + i] <= 'z') ? (char)h[4 + i] : '?';
        if (len > size - at - 12) {
            snprintf(msg, msglen, "chunk '%s' at byte %llu claims %llu bytes, more than the %llu left in the file",
                     type, (unsigned long long)at, (unsigned long long)len, (unsigned long long)(size - at - 12));
            return -1;
        }
        at += 12 + len;
        if (memcmp(h + 4, "IEND", 4) == 0)
            break;
    }
    if (fseek(fp, 8, SEEK_SET) != 0) {
        snprintf(msg, msglen, "cannot seek in the file");
        return -1;
    }
    return 0;
}

/* The read of a PNG open as fp (size bytes; closed here), named path in messages. */
static int png_read_fp(FILE *fp, uint64_t size, const char *path, int srgb, murk_image *img, char *err, size_t errlen)
{
    png_job j;
    memset(&j, 0, sizeof j);
    int rc = 0;
    j.path = path;
    j.img = img;
    j.file_size = size;
    j.fp = fp;
    unsigned char sig[8];
    if (fread(sig, 1, sizeof sig, j.fp) != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0) {
        fclose(j.fp);
        return murk_err_file(err, errlen, path, "not a PNG file");
    }
    if (png_check_framing(j.fp, size, j.msg, sizeof j.msg) != 0) {
        fclose(j.fp);
        return murk_err_file(err, errlen, path, "cannot read PNG: %s", j.msg);
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
    if (rc != 0)
        murk_image_free(img); /* the text keys read before the failure */
    return rc;
}

MURK_API int murk_png_read(const char *path, int srgb, murk_image *img, char *err, size_t errlen)
{
    int fd = murk_image_open_input(path, img, err, errlen);
    if (fd < 0)
        return -1;
    uint64_t size = murk_image_fd_size(fd);
    FILE *fp = fdopen(fd, "rb");
    if (!fp) {
        close(fd);
        return murk_err_file(err, errlen, path, "out of memory");
    }
    return png_read_fp(fp, size, path, srgb, img, err, errlen);
}

int murk_png_read_memory(const void *data, size_t size, const char *name, int srgb, murk_image *img, char *err,
                         size_t errlen)
{
    memset(img, 0, sizeof *img);
    if (size > murk_limit(MURK_LIMIT_FILE_BYTES))
        return murk_err_file(err, errlen, name, "more than %llu bytes, the limit (%s)",
                             (unsigned long long)murk_limit(MURK_LIMIT_FILE_BYTES), murk_limit_name(MURK_LIMIT_FILE_BYTES));
    FILE *fp = size ? fmemopen((void *)(uintptr_t)data, size, "rb") : NULL;
    if (!fp)
        return murk_err_file(err, errlen, name, size ? "out of memory" : "not a PNG file (no bytes)");
    return png_read_fp(fp, size, name, srgb, img, err, errlen);
}
