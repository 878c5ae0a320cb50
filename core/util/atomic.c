/* atomic.c — the one way murk writes an output file: a temporary beside the target, flushed to disk,
 * then renamed over it; groups of files committed together; temporaries removed on SIGINT/SIGTERM/
 * SIGHUP; only regular files replaced (see atomic.h). */
#include "util/atomic.h"
#include "util/error.h"
#include "util/util.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- temporaries the signal handler removes ------------------------------------------------ */

enum { MAX_PENDING = 8, PATH_CAP = 4096 };
static char pending_tmp[MAX_PENDING][PATH_CAP];   /* "" = free slot */
static char pending_dst[MAX_PENDING][PATH_CAP];
static volatile sig_atomic_t npending_live;       /* slots in use */
static volatile sig_atomic_t interrupted;         /* a signal removed the temporaries */
static int group_open;
static const int caught[] = {SIGINT, SIGTERM, SIGHUP};
static struct sigaction previous[3];

/* A signal while a temporary exists. If the program handles it itself (a handler was installed before:
 * `murk render` stops and still writes its image), that handler runs and the writes go on to their
 * normal end. If the signal would end the process (the default action), the temporaries are removed
 * first and the default action follows. */
static void on_signal(int sig, siginfo_t *info, void *ctx)
{
    int k = 0;
    while (k < 2 && caught[k] != sig)
        k++;
    const struct sigaction *prev = &previous[k];
    if ((prev->sa_flags & SA_SIGINFO) && prev->sa_sigaction) {
        prev->sa_sigaction(sig, info, ctx);
        return;
    }
    if (prev->sa_handler == SIG_IGN)
        return;
    if (prev->sa_handler != SIG_DFL) {
        prev->sa_handler(sig);
        return;
    }
    int saved = errno;
    for (int i = 0; i < MAX_PENDING; i++)
        if (pending_tmp[i][0])
            unlink(pending_tmp[i]); /* async-signal-safe */
    interrupted = 1;
    sigaction(sig, prev, NULL);
    errno = saved;
    raise(sig); /* the default action, once this handler returns */
}

static void block_signals(sigset_t *old)
{
    sigset_t s;
    sigemptyset(&s);
    for (int k = 0; k < 3; k++)
        sigaddset(&s, caught[k]);
    sigprocmask(SIG_BLOCK, &s, old);
}

/* Registers tmp (to be renamed to dst); -1 if every slot is taken or the names are too long. */
static int pending_add(const char *tmp, const char *dst)
{
    if (strlen(tmp) >= PATH_CAP || strlen(dst) >= PATH_CAP)
        return -1;
    sigset_t old;
    block_signals(&old);
    int slot = -1;
    for (int i = 0; i < MAX_PENDING && slot < 0; i++)
        if (!pending_tmp[i][0])
            slot = i;
    if (slot >= 0) {
        if (npending_live == 0) {
            interrupted = 0;
            struct sigaction sa;
            memset(&sa, 0, sizeof sa);
            sa.sa_sigaction = on_signal;
            sa.sa_flags = SA_SIGINFO;
            sigemptyset(&sa.sa_mask);
            for (int k = 0; k < 3; k++)
                sigaction(caught[k], &sa, &previous[k]);
        }
        memcpy(pending_dst[slot], dst, strlen(dst) + 1);
        memcpy(pending_tmp[slot], tmp, strlen(tmp) + 1);
        npending_live++;
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    return slot < 0 ? -1 : 0;
}

/* Forgets slot i (its file is renamed or removed); the last one restores the previous handlers. */
static void pending_drop(int i)
{
    sigset_t old;
    block_signals(&old);
    if (pending_tmp[i][0]) {
        pending_tmp[i][0] = 0;
        pending_dst[i][0] = 0;
        if (--npending_live == 0)
            for (int k = 0; k < 3; k++)
                sigaction(caught[k], &previous[k], NULL);
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
}

static int pending_find(const char *tmp)
{
    for (int i = 0; i < MAX_PENDING; i++)
        if (pending_tmp[i][0] && strcmp(pending_tmp[i], tmp) == 0)
            return i;
    return -1;
}

/* ---- the target ---------------------------------------------------------------------------- */

static const char *kind_of(mode_t m)
{
    return S_ISDIR(m) ? "a directory" : S_ISLNK(m) ? "a symbolic link" : S_ISCHR(m) ? "a character device" :
           S_ISBLK(m) ? "a block device" : S_ISFIFO(m) ? "a FIFO" : S_ISSOCK(m) ? "a socket" : "not a regular file";
}

MURK_API int murk_output_check(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (!path || !*path)
        return murk_err_file(err, errlen, path ? path : "(null)", "no output file name");
    if (lstat(path, &st) != 0)
        return 0; /* nothing there (or unreachable: creating the temporary says why) */
    if (!S_ISREG(st.st_mode))
        return murk_err_file(err, errlen, path, "is %s; murk only replaces regular files", kind_of(st.st_mode));
    return 0;
}

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

MURK_API int murk_write_atomic(const char *path, murk_write_fn fill, void *user, char *err, size_t errlen)
{
    if (murk_output_check(path, err, errlen) != 0)
        return -1;
    char *tmp = tmp_name(path);
    if (!tmp)
        return murk_err_file(err, errlen, path, "out of memory");
    /* a stale temporary of an earlier run with this pid is replaced, never followed if it is a link */
    if (unlink(tmp) != 0 && errno != ENOENT) {
        murk_err_file(err, errlen, path, "cannot remove the stale temporary %s: %s", tmp, strerror(errno));
        free(tmp);
        return -1;
    }
    if (pending_add(tmp, path) != 0) {
        murk_err_file(err, errlen, path, "too many output files at once");
        free(tmp);
        return -1;
    }
    int slot = pending_find(tmp);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
        murk_err_file(err, errlen, path, "cannot create the temporary file %s: %s", tmp, strerror(errno));
        pending_drop(slot);
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
    if (rc == 0 && interrupted)
        rc = murk_err_file(err, errlen, path, "interrupted by a signal");
    if (rc == 0 && group_open) { /* murk_output_commit renames it */
        free(tmp);
        return 0;
    }
    if (rc == 0 && rename(tmp, path) != 0)
        rc = murk_err_file(err, errlen, path, "cannot rename %s: %s", tmp, strerror(errno));
    if (rc != 0)
        unlink(tmp);
    pending_drop(slot);
    free(tmp);
    return rc;
}

MURK_API int murk_output_probe(const char *path, const char *what, char *err, size_t errlen)
{
    if (murk_output_check(path, err, errlen) != 0)
        return -1;
    char *tmp = tmp_name(path);
    if (!tmp)
        return murk_err_file(err, errlen, path, "out of memory");
    if (pending_find(tmp) >= 0) { /* this process is writing it right now */
        free(tmp);
        return 0;
    }
    int rc = 0;
    if (pending_add(tmp, path) != 0) {
        free(tmp);
        return murk_err_file(err, errlen, path, "too many output files at once");
    }
    int slot = pending_find(tmp);
    /* as murk_write_atomic does: a stale temporary of this pid goes, the new one is never a link */
    int fd = -1;
    if (unlink(tmp) == 0 || errno == ENOENT)
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0)
        rc = murk_err_file(err, errlen, path, "cannot write the %s: %s", what, strerror(errno));
    else {
        close(fd);
        unlink(tmp);
    }
    pending_drop(slot);
    free(tmp);
    return rc;
}

MURK_API void murk_output_begin(void) { group_open = 1; }

MURK_API void murk_output_abort(void)
{
    for (int i = 0; i < MAX_PENDING; i++)
        if (pending_tmp[i][0]) {
            unlink(pending_tmp[i]);
            pending_drop(i);
        }
    group_open = 0;
}

MURK_API int murk_output_commit(char *err, size_t errlen)
{
    int done[MAX_PENDING], ndone = 0, rc = 0;
    for (int i = 0; i < MAX_PENDING && rc == 0; i++) {
        if (!pending_tmp[i][0])
            continue;
        if (interrupted)
            rc = murk_err_file(err, errlen, pending_dst[i], "interrupted by a signal");
        else if (murk_output_check(pending_dst[i], err, errlen) != 0)
            rc = -1;
        else if (rename(pending_tmp[i], pending_dst[i]) != 0)
            rc = murk_err_file(err, errlen, pending_dst[i], "cannot rename %s: %s", pending_tmp[i], strerror(errno));
        else
            done[ndone++] = i;
    }
    if (rc != 0) /* neither: the files already renamed go too */
        for (int k = 0; k < ndone; k++)
            unlink(pending_dst[done[k]]);
    for (int k = 0; k < ndone; k++)
        pending_drop(done[k]);
    murk_output_abort(); /* whatever is left */
    return rc;
}
