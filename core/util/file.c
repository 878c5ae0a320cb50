/* file.c — reading input files whole (the density grid readers), and the folder libmurk was loaded from. */
#define _GNU_SOURCE /* dladdr() */
#include "util/file.h"
#include "util/error.h"
#include "util/limit.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *file_kind(mode_t m)
{
    return S_ISDIR(m) ? "a directory" : S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" :
           S_ISBLK(m) ? "a block device" : S_ISSOCK(m) ? "a socket" : "not a regular file";
}

int murk_file_open_regular_fd(const char *path, uint64_t *size, char *err, size_t errlen)
{
    /* O_NONBLOCK: opening a FIFO must not wait for a writer; cleared again for the reads. */
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0)
        return murk_err_file(err, errlen, path, "cannot open: %s", strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        murk_err_file(err, errlen, path, "%s, not a regular file", file_kind(st.st_mode));
        close(fd);
        return -1;
    }
    uint64_t max = murk_limit(MURK_LIMIT_FILE_BYTES);
    if ((uint64_t)st.st_size > max) {
        murk_err_file(err, errlen, path, "%llu bytes exceeds the limit of %llu bytes per input file (%s)",
                      (unsigned long long)st.st_size, (unsigned long long)max, murk_limit_name(MURK_LIMIT_FILE_BYTES));
        close(fd);
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl != -1)
        fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    *size = (uint64_t)st.st_size;
    return fd;
}

FILE *murk_file_open_regular(const char *path, uint64_t *size, char *err, size_t errlen)
{
    int fd = murk_file_open_regular_fd(path, size, err, errlen);
    if (fd < 0)
        return NULL;
    FILE *fp = fdopen(fd, "rb");
    if (!fp) {
        murk_err_file(err, errlen, path, "cannot open: %s", strerror(errno));
        close(fd);
    }
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


int murk_library_dir(char *out, size_t n)
{
    static const char anchor = 0; /* an address inside the file that holds this code */
    Dl_info info;
    char lib[PATH_MAX];
    if (!dladdr(&anchor, &info) || !info.dli_fname || !realpath(info.dli_fname, lib))
        return -1;
    char *slash = strrchr(lib, '/');
    if (!slash)
        return -1;
    *slash = 0;
    size_t k = strlen(lib);
    if (k >= n)
        return -1;
    memcpy(out, lib, k + 1);
    return 0;
}
