/* util.h — small helpers internal to libmurk: error formatting, strings, did-you-mean, paths. */
#ifndef MURK_UTIL_H
#define MURK_UTIL_H

#include <stddef.h>
#include "murk/plugin.h"

/* Visible from libmurk (the embedding API and what the murk command needs). */
#define MURK_API __attribute__((visibility("default")))

void *murk_xmalloc(size_t n);           /* zeroed; aborts with a message when out of memory */
void *murk_xrealloc(void *p, size_t n);
char *murk_strdup(const char *s);
int murk_snprintf(char *buf, size_t n, const char *fmt, ...) MURK_PRINTF(3, 4);
/* Levenshtein distance, capped at 64 for long strings. */
int murk_edit_distance(const char *a, const char *b);
/* The candidate closest to `word` when close enough to be a plausible typo, else NULL. */
const char *murk_did_you_mean(const char *word, const char *const *candidates, size_t n);
/* dir of `path` joined with rel (rel returned as-is when absolute); malloc'd. */
char *murk_path_relative_to(const char *path, const char *rel);
double murk_now(void); /* monotonic seconds */
int murk_cpus_usable(void); /* CPUs this process may run on (its affinity mask), at least 1 (cpus.c) */
long murk_peak_rss_kb(void); /* the peak resident memory of this process in kB (VmHWM), -1 where /proc does not say */
/* Untrusted text made safe to print on one line: control characters (C0, DEL, C1) and bytes that are
 * not valid UTF-8 become escapes (\n, \t, \r, \e, \\xNN, \\u00NN); printable ASCII and valid UTF-8 pass.
 * Writes at most n bytes including the NUL (cut short at a character boundary) and returns dst. The
 * error formatter, murk_log and the command line pass every echoed name, key and value through it. */
MURK_API char *murk_printable(char *dst, size_t n, const char *src);
/* The git commit murk was built from ("c7e151510217", "...-dirty" for uncommitted changes, "unknown"
 * outside a checkout) and its version: every PNG and EXR murk writes carries both (commit.c). */
MURK_API const char *murk_build_commit(void);
MURK_API const char *murk_build_version(void);

#endif
