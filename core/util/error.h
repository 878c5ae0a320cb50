/* error.h — the one formatter of the errors loaders report. Internal to libmurk.
 *
 * Every loader (scene YAML, --set, OBJ meshes, density grids, images and textures) reports one line:
 *   "file:line:col: what is wrong"   when it knows the place in the file (line and col are 1-based);
 *   "file: what is wrong"            when the whole file is at fault.
 * Both functions return -1, so a failing loader can end with `return murk_err_at(...)`. err may be
 * NULL or errlen 0 (nothing is written); a message that does not fit is cut short. */
#ifndef MURK_ERROR_H
#define MURK_ERROR_H

#include <stdarg.h>
#include <stddef.h>

#include "murk/plugin.h"

/* line < 1 leaves the place out ("file: what is wrong"). */
int murk_err_at(char *err, size_t errlen, const char *file, long line, long col, const char *fmt, ...)
    MURK_PRINTF(6, 7);
int murk_verr_at(char *err, size_t errlen, const char *file, long line, long col, const char *fmt, va_list ap)
    MURK_PRINTF(6, 0);
/* "file: what is wrong". */
int murk_err_file(char *err, size_t errlen, const char *file, const char *fmt, ...) MURK_PRINTF(4, 5);

#endif
