/* atomic.h — writing an output file whole or not at all. Internal to libmurk.
 *
 * Every file murk writes (the EXR and its PNG preview, a .vol from `murk grid`) goes through
 * murk_write_atomic: the content is written to PATH.tmp-PID beside the target, flushed to disk and
 * renamed over PATH only when all of it was written. On any failure the temporary is removed and PATH
 * is left as it was, so a failed or interrupted run never leaves a half-written file. */
#ifndef MURK_ATOMIC_H
#define MURK_ATOMIC_H

#include <stddef.h>
#include <stdio.h>

/* Writes the whole content into fp (opened "wb" on the temporary tmp; write(2)/pwrite(2) on
 * fileno(fp) are fine when nothing is buffered in fp). Returns 0, or -1 with err set. */
typedef int (*murk_write_fn)(FILE *fp, const char *tmp, void *user, char *err, size_t errlen);

/* Returns 0, or -1 with err = "path: what went wrong" (fill's own message when fill failed). */
int murk_write_atomic(const char *path, murk_write_fn fill, void *user, char *err, size_t errlen);

#endif
