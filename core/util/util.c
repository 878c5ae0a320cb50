/* util.c — small helpers internal to libmurk. */
#include "util/util.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

MURK_API void *murk_xmalloc(size_t n)
{
    void *p = calloc(1, n ? n : 1);
    if (!p) {
        fprintf(stderr, "murk: out of memory (%zu bytes)\n", n);
        exit(2);
    }
    return p;
}

MURK_API void *murk_xrealloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q) {
        fprintf(stderr, "murk: out of memory (%zu bytes)\n", n);
        exit(2);
    }
    return q;
}

MURK_API char *murk_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = murk_xmalloc(n);
    memcpy(d, s, n);
    return d;
}

int murk_snprintf(char *buf, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int r = vsnprintf(buf, n, fmt, ap);
    va_end(ap);
    return r;
}

int murk_edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 63 || lb > 63)
        return 64;
    int d[64][64];
    for (size_t i = 0; i <= la; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int c = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            if (d[i - 1][j] + 1 < c)
                c = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < c)
                c = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < c)
                c = d[i - 2][j - 2] + 1; /* transposition */
            d[i][j] = c;
        }
    return d[la][lb];
}

const char *murk_did_you_mean(const char *word, const char *const *candidates, size_t n)
{
    const char *best = NULL;
    int bestd = 1 << 30;
    for (size_t i = 0; i < n; i++) {
        int dist = murk_edit_distance(word, candidates[i]);
        if (dist < bestd) {
            bestd = dist;
            best = candidates[i];
        }
    }
    size_t len = strlen(word);
    int limit = len <= 3 ? 1 : (len <= 6 ? 2 : 3);
    return best && bestd <= limit ? best : NULL;
}

char *murk_path_relative_to(const char *path, const char *rel)
{
    if (rel[0] == '/' || !path)
        return murk_strdup(rel);
    const char *slash = strrchr(path, '/');
    if (!slash)
        return murk_strdup(rel);
    size_t dl = (size_t)(slash - path) + 1, rl = strlen(rel);
    char *out = murk_xmalloc(dl + rl + 1);
    memcpy(out, path, dl);
    memcpy(out + dl, rel, rl + 1);
    return out;
}

MURK_API double murk_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Length of the valid UTF-8 sequence at s (2..4), or 0 if there is none. */
static size_t utf8_len(const unsigned char *s)
{
    size_t n = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 ? 3 : s[0] >= 0xc2 && s[0] < 0xe0 ? 2 : 0;
    for (size_t i = 1; i < n; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    if ((n == 3 && s[0] == 0xe0 && s[1] < 0xa0) || (n == 3 && s[0] == 0xed && s[1] >= 0xa0) ||
        (n == 4 && s[0] == 0xf0 && s[1] < 0x90) || (n == 4 && s[0] == 0xf4 && s[1] >= 0x90))
        return 0; /* overlong, surrogate or beyond U+10FFFF */
    if (n == 2 && s[0] == 0xc2 && s[1] < 0xa0)
        return 0; /* C1 control characters U+0080..U+009F */
    return n;
}

MURK_API char *murk_printable(char *dst, size_t n, const char *src)
{
    if (!dst || n == 0)
        return dst;
    const unsigned char *s = (const unsigned char *)(src ? src : "(null)");
    size_t k = 0;
    while (*s) {
        char esc[12];
        size_t len;
        const char *out = esc;
        if (*s >= 0x20 && *s < 0x7f) {
            out = (const char *)s;
            len = 1;
        } else if (*s >= 0x80 && (len = utf8_len(s)) > 0) {
            out = (const char *)s;
        } else {
            if (*s == '\n')
                len = (size_t)snprintf(esc, sizeof esc, "\\n");
            else if (*s == '\t')
                len = (size_t)snprintf(esc, sizeof esc, "\\t");
            else if (*s == '\r')
                len = (size_t)snprintf(esc, sizeof esc, "\\r");
            else if (*s == 0x1b)
                len = (size_t)snprintf(esc, sizeof esc, "\\e");
            else if (*s == 0xc2 && s[1] >= 0x80 && s[1] < 0xa0) { /* a C1 control in UTF-8 */
                len = (size_t)snprintf(esc, sizeof esc, "\\u%04x", s[1]);
                s++;
            } else
                len = (size_t)snprintf(esc, sizeof esc, "\\x%02x", *s);
            s++;
            if (k + len >= n)
                break;
            memcpy(dst + k, esc, len);
            k += len;
            continue;
        }
        if (k + len >= n)
            break;
        memcpy(dst + k, out, len);
        k += len;
        s += len;
    }
    dst[k] = 0;
    return dst;
}

/* The peak resident memory of this process in kB (VmHWM), -1 where /proc does not say. */
MURK_API long murk_peak_rss_kb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld", &kb) == 1)
            break;
    if (f)
        fclose(f);
    return kb;
}
