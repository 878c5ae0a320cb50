/* image.c — what the EXR (exr.c) and PNG (png.c) readers and writers share: size checks, opening an
 * input, the image returned by the readers and its string attributes. */
#include "image.h"
#include "error.h"
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return murk_err_file(err, errlen, path, "cannot open: %s", strerror(errno));
    return fd;
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
