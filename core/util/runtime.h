/* runtime.h — the run-time state every layer of libmurk shares, at the bottom so that media, scene and
 * render all reach it without reaching each other: logging (murk_log, quiet), once-only warnings, and the
 * calling thread's cost counters (murk/counters.h). */
#ifndef MURK_RUNTIME_H
#define MURK_RUNTIME_H

#include <stddef.h>
#include <stdint.h>
#include "murk/counters.h"
#include "murk/plugin.h"

/* "murk: MESSAGE" (MURK_LOG_INFO, silent when quiet) or "murk: warning: MESSAGE" on stderr, the message
 * made printable (murk_printable). */
void murk_log(int level, const char *fmt, ...) MURK_PRINTF(2, 3);
void murk_set_quiet(int quiet);
/* A warning logged the first time its text is seen, counted afterwards. */
void murk_warn_once(const char *fmt, ...) MURK_PRINTF(1, 2);
/* Prints how often each once-only warning repeated, and forgets them. */
void murk_warn_summary(void);
/* Names a scene's instance for the warnings: a once-only warning whose text holds `who` ("material
 * 'red'", "medium 'smoke'", "integrator 'path'") gets " [what]" after it ("plugin diffuse,
 * /usr/lib/murk/plugins/diffuse.so"), so that a message an integrator writes about the scene's instance
 * also names the plugin and the file behind it. owner: the scene (the last one named wins). */
void murk_warn_name(const void *owner, const char *who, const char *what);
/* Forgets the names an owner gave (murk_scene_free). */
void murk_warn_forget(const void *owner);

/* The calling thread's tally: the rays it traced and its cost counters, one block per counter slot (a
 * medium's slot is its index in the scene; the last slot is shared by the media beyond it). Plain
 * thread-local memory: the hot paths (every ray, density lookup and majorant cell) add to it without
 * atomics or locks. The tally is allocated on a thread's first use (murk_tally_first, freed when the
 * thread exits) and reached through one pointer in initial-exec TLS: a fixed offset from the thread pointer,
 * where the default TLS model of a shared library calls __tls_get_addr on every access. That pointer is
 * all of libmurk's TLS (8 bytes), which fits glibc's reserve for libraries dlopen()ed after the program
 * started (Python's ctypes); the 2.5 kB tally itself in initial-exec TLS did not ("cannot allocate memory
 * in static TLS block"), and a module's TLS is allocated as a whole. */
typedef struct murk_thread_tally {
    uint64_t rays;
    murk_counters media[MURK_COUNTER_SLOTS];
} murk_thread_tally;
#if defined(__GNUC__)
extern _Thread_local murk_thread_tally *murk_tally_cache __attribute__((tls_model("initial-exec")));
#else
extern _Thread_local murk_thread_tally *murk_tally_cache;
#endif
murk_thread_tally *murk_tally_first(void); /* sets murk_tally_cache; out of line, called once per thread */
static inline murk_thread_tally *murk_tally(void)
{
    murk_thread_tally *t = murk_tally_cache;
    return t ? t : murk_tally_first();
}
/* The calling thread's cost counters (MURK_COUNTER_SLOTS blocks). */
static inline murk_counters *murk_thread_counters(void) { return murk_tally()->media; }
/* Zeroes the calling thread's tally (rays and cost counters). */
void murk_thread_counters_reset(void);
/* Adds the calling thread's first n blocks into sum[0..n) (once per thread when its work ends). */
void murk_thread_counters_add(murk_counters *sum, size_t n);
/* The slot for the scene's i-th medium. */
static inline unsigned murk_counter_slot(size_t i)
{
    return i < MURK_COUNTER_SLOTS - 1 ? (unsigned)i : MURK_COUNTER_SLOTS - 1;
}

#endif
