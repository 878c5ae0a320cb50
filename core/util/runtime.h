/* runtime.h — the run-time state every layer of libmurk shares, at the bottom so that media, scene and
 * render all reach it without reaching each other: logging (murk_log, quiet), once-only warnings, and the
 * calling thread's cost counters (murk/counters.h). */
#ifndef MURK_RUNTIME_H
#define MURK_RUNTIME_H

#include <stddef.h>
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

/* The calling thread's cost counters, one block per counter slot: a medium's slot is its index in the
 * scene (the last slot is shared by the media beyond it). Plain thread-local memory: the hot paths
 * (density lookups, majorant cells) add to it without atomics or locks. initial-exec: a fixed offset
 * from the thread pointer, where the default model for a shared library's TLS calls __tls_get_addr on
 * every access. */
#if defined(__GNUC__)
extern _Thread_local murk_counters murk_thread_counters[MURK_COUNTER_SLOTS] __attribute__((tls_model("initial-exec")));
#else
extern _Thread_local murk_counters murk_thread_counters[MURK_COUNTER_SLOTS];
#endif
/* Zeroes the calling thread's cost counters. */
void murk_thread_counters_reset(void);
/* Adds the calling thread's first n blocks into sum[0..n) (once per thread when its work ends). */
void murk_thread_counters_add(murk_counters *sum, size_t n);
/* The slot for the scene's i-th medium. */
static inline unsigned murk_counter_slot(size_t i)
{
    return i < MURK_COUNTER_SLOTS - 1 ? (unsigned)i : MURK_COUNTER_SLOTS - 1;
}

#endif
