/* atomic.c — the one way murk writes an output file: a temporary beside the target, flushed to disk,
 * then renamed over it (see atomic.h). */
#include "atomic.h"
#include "error.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* PATH.tmp-PID, malloc'd; NULL when out of memory. */
static char *tmp_name(const char *path)
{
    size_t n = strlen(path) + 32;
    char *tmp = malloc(n);
    if (tmp)
        snprintf(tmp, n, "%s.tmp-%ld", path, (long)getpid());
    return tmp;
}

/* Flushes the completely written temporary to disk and closes it (fp is closed in any case). */
static int finish(FILE *fp, const char *tmp, const char *path, int rc, char *err, size_t errlen)
{
    if (rc == 0 && (fflush(fp) != 0 || ferror(fp)))
        rc = murk_err_file(err, errlen, path, "cannot write %s: %s", tmp, strerror(errno));
    if (rc == 0 && fsync(fileno(fp)) != 0 && errno != EINVAL && errno != EROFS)
        rc = murk_err_file(err, errlen, path, "cannot sync %s: %s", tmp, strerror(errno));
    if (fclose(fp) != 0 && rc == 0)
        rc = murk_err_file(err, errlen, path, "cannot close %s: %s", tmp, strerror(errno));
    return rc;
}

int murk_write_atomic(const char *path, murk_write_fn fill, void *user, char *err, size_t errlen)
{
    char *tmp = tmp_name(path);
    if (!tmp)
        return murk_err_file(err, errlen, path, "out of memory");
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
        murk_err_file(err, errlen, path, "cannot create the temporary file %s: %s", tmp, strerror(errno));
        free(tmp);
        return -1;
    }
    int rc = 0;
    FILE *fp = fdopen(fd, "wb");
    if (!fp) {
        rc = murk_err_file(err, errlen, path, "out of memory");
        close(fd);
    } else {
        rc = finish(fp, tmp, path, fill(fp, tmp, user, err, errlen), err, errlen);
    }
    if (rc == 0 && rename(tmp, path) != 0)
        rc = murk_err_file(err, errlen, path, "cannot rename %s: %s", tmp, strerror(errno));
    if (rc != 0)
        unlink(tmp);
    free(tmp);
    return rc;
}
