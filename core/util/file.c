/* file.c — reading input files whole (the density grid readers). */
#include "file.h"
#include "error.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

FILE *murk_file_open_regular(const char *path, uint64_t *size, char *err, size_t errlen)
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


unsigned char *murk_file_read_all(const char *path, uint64_t *size, char *err, size_t errlen)
{
    FILE *fp = murk_file_open_regular(path, size, err, errlen);
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

