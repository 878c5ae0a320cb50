/* atomic.h — writing output files whole or not at all. Internal to libmurk (murk_write_atomic and the
 * murk_output_* group calls are exported for the murk command: `murk bench` writes its files with them).
 *
 * Every file murk writes (the EXR and its PNG preview, a .vol from `murk grid`) goes through
 * murk_write_atomic: the content is written to PATH.tmp-PID beside the target, flushed to disk and
 * renamed over PATH only when all of it was written. On any failure the temporary is removed and PATH
 * is left as it was, so a failed or interrupted run never leaves a half-written file.
 *
 *  - Only a regular file is ever replaced: when PATH names a directory, a device (/dev/full), a FIFO,
 *    a socket or a symbolic link, nothing is written and the error says what PATH is.
 *  - While a temporary exists, SIGINT, SIGTERM and SIGHUP that would end the process (their default
 *    action) remove it first; where the program installed its own handler (`murk render` finishes
 *    its image on SIGINT/SIGTERM), that handler runs and the write goes on to its normal end.
 *  - Several files that belong together (an EXR and its PNG) are written as a group:
 *    murk_output_begin(), the writes (each leaves its finished temporary), then murk_output_commit()
 *    renames them all — or, if one write failed, murk_output_abort() removes every temporary. If a
 *    rename fails half-way, the targets already renamed are removed again: both files or neither. */
#ifndef MURK_ATOMIC_H
#define MURK_ATOMIC_H

#include <stddef.h>
#include <stdio.h>

/* Writes the whole content into fp (opened "wb" on the temporary tmp; write(2)/pwrite(2) on
 * fileno(fp) are fine when nothing is buffered in fp). Returns 0, or -1 with err set. */
typedef int (*murk_write_fn)(FILE *fp, const char *tmp, void *user, char *err, size_t errlen);

/* Returns 0, or -1 with err = "path: what went wrong" (fill's own message when fill failed). */
int murk_write_atomic(const char *path, murk_write_fn fill, void *user, char *err, size_t errlen);

/* 0 if path does not exist or is a regular file murk may replace; else -1 with err naming what it is. */
int murk_output_check(const char *path, char *err, size_t errlen);
/* murk_output_check, then whether murk_write_atomic could write path now: its temporary is created and
 * removed again (the target is not touched). 0, or -1 with err = "path: cannot write the WHAT: why" (what:
 * "image", "checkpoint", ...). For checking every output before a long render rather than after it. */
int murk_output_probe(const char *path, const char *what, char *err, size_t errlen);
/* Starts a group: until commit or abort, murk_write_atomic leaves its finished temporaries in place. */
void murk_output_begin(void);
/* Renames every temporary of the group over its target (all or none); 0, or -1 with err. Ends the group. */
int murk_output_commit(char *err, size_t errlen);
/* Removes every temporary of the group. Ends the group. */
void murk_output_abort(void);

#endif
