/* image.h — image files: linear float EXR through OpenEXRCore (exr.c), 8-bit sRGB PNG through libpng
 * (png.c), and what they share (image.c). Internal to libmurk. Pixels are interleaved RGB floats, row-major, row 0 at the top.
 * Writers write PATH.tmp-PID and rename it over PATH only when the whole file is written, so a failed
 * or interrupted run never leaves a half-written image. Every function returns 0 on success, or -1
 * with a one-line message in err ("path: what is wrong"). */
#ifndef MURK_IMAGE_H
#define MURK_IMAGE_H

#include <stddef.h>
#include <stdint.h>

typedef struct murk_kv { const char *key, *value; } murk_kv;

typedef struct murk_image {
    int w, h;
    float *rgb;       /* 3*w*h floats */
    int nmeta;        /* string attributes read back from an EXR (key/value pairs, malloc'd) */
    murk_kv *meta;
} murk_image;

int murk_exr_write(const char *path, const float *rgb, int w, int h, const murk_kv *meta, int nmeta,
                   char *err, size_t errlen);
int murk_exr_read(const char *path, murk_image *img, char *err, size_t errlen);
/* Tone map for preview: clamp to [0,1] after multiplying by 2^exposure, sRGB transfer, 8 bits. */
int murk_png_write(const char *path, const float *rgb, int w, int h, float exposure, char *err, size_t errlen);
/* Decodes 8/16-bit grey/RGB/RGBA/palette PNGs; sRGB-encoded values are converted to linear when srgb=1. */
int murk_png_read(const char *path, int srgb, murk_image *img, char *err, size_t errlen);
/* The same from size bytes in memory (a glTF binary's embedded image), named name in messages. */
int murk_png_read_memory(const void *data, size_t size, const char *name, int srgb, murk_image *img, char *err,
                         size_t errlen);
const char *murk_image_meta(const murk_image *img, const char *key); /* NULL if absent */
/* 1 if w x h is positive and 3*w*h floats (and 12*w bytes per row) can be addressed. */
int murk_image_size_ok(long long w, long long h);
/* What both readers do first: clears img and opens path for reading — a regular file only (a FIFO
 * or device is refused without blocking), within MURK_MAX_FILE_BYTES. The descriptor, or -1 with err set. */
int murk_image_open_input(const char *path, murk_image *img, char *err, size_t errlen);
/* What both readers check before allocating for a header's w x h: a size murk can address, at most
 * MURK_MAX_IMAGE_PIXELS pixels (limit.h), and no more decoded bytes (bytes_per_pixel each) than the
 * file's size can expand to (MURK_MAX_EXPANSION). 0, or -1 with err "path: ..." naming the problem. */
int murk_image_declared_ok(const char *path, const char *what, long long w, long long h, double bytes_per_pixel,
                           uint64_t file_size, char *err, size_t errlen);
uint64_t murk_image_fd_size(int fd); /* 0 if unknown */
void murk_image_free(murk_image *img);

#endif
