/* image.c — what the EXR (exr.c) and PNG (png.c) readers and writers share: size checks, opening an
 * input, the image returned by the readers and its string attributes. */
#include "image/image.h"
#include "util/error.h"
#include "util/file.h"
#include "util/limit.h"
#include "util/util.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Checks w, h and that 3*w*h floats (and 12*w bytes per row) can be addressed. */
int murk_image_size_ok(long long w, long long h)
{
    return w > 0 && h > 0 && w <= INT_MAX / 12 && h <= INT_MAX &&
           (unsigned long long)w * (unsigned long long)h <= SIZE_MAX / 12;
}

int murk_image_open_input(const char *path, murk_image *img, char *err, size_t errlen)
{
    if (!img)
        return murk_err_file(err, errlen, path ? path : "(null)", "no image to read into");
    memset(img, 0, sizeof *img);
    if (!path)
        return murk_err_file(err, errlen, "(null)", "no path");
    uint64_t size;
    return murk_file_open_regular_fd(path, &size, err, errlen);
}

int murk_image_declared_ok(const char *path, const char *what, long long w, long long h, double bytes_per_pixel,
                           uint64_t file_size, char *err, size_t errlen)
{
    uint64_t max = murk_limit(MURK_LIMIT_IMAGE_PIXELS);
    if (!murk_image_size_ok(w, h))
        return murk_err_file(err, errlen, path, "unsupported %s size %lldx%lld", what, w, h);
    if ((uint64_t)w * (uint64_t)h > max)
        return murk_err_file(err, errlen, path, "%s of %lldx%lld pixels exceeds the limit of %llu pixels (%s)", what, w,
                             h, (unsigned long long)max, murk_limit_name(MURK_LIMIT_IMAGE_PIXELS));
    double need = (double)w * (double)h * bytes_per_pixel;
    if (need > MURK_MAX_EXPANSION * (double)file_size + 65536.0)
        return murk_err_file(err, errlen, path, "header declares %lldx%lld pixels but the file holds only %llu bytes "
                             "(corrupt or hostile header)", w, h, (unsigned long long)file_size);
    return 0;
}

uint64_t murk_image_fd_size(int fd)
{
    struct stat st;
    return fstat(fd, &st) == 0 && st.st_size > 0 ? (uint64_t)st.st_size : 0;
}

MURK_API const char *murk_image_meta(const murk_image *img, const char *key)
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
