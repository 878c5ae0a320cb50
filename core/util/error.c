/* error.c — the one formatter of loader errors: "file:line:col: what is wrong" or "file: what is wrong"
 * (see error.h). */
#include "util/error.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>

int murk_verr_at(char *err, size_t errlen, const char *file, long line, long col, const char *fmt, va_list ap)
{
    if (!err || errlen == 0)
        return -1;
    /* Formatted whole, then made printable: a message is one line whatever names, keys or values from
     * the input it quotes (a newline or a terminal escape in them is shown escaped). */
    char *raw = malloc(errlen);
    if (!raw) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int k = line >= 1 ? snprintf(raw, errlen, "%s:%ld:%ld: ", file, line, col) : snprintf(raw, errlen, "%s: ", file);
    if (k >= 0 && (size_t)k < errlen)
        vsnprintf(raw + k, errlen - (size_t)k, fmt, ap);
    murk_printable(err, errlen, raw);
    free(raw);
    return -1;
}

int murk_err_at(char *err, size_t errlen, const char *file, long line, long col, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    murk_verr_at(err, errlen, file, line, col, fmt, ap);
    va_end(ap);
    return -1;
}

int murk_err_file(char *err, size_t errlen, const char *file, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    murk_verr_at(err, errlen, file, 0, 0, fmt, ap);
    va_end(ap);
    return -1;
}
