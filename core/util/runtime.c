/* runtime.c — the run-time state libmurk's layers share (runtime.h): the log and its quiet switch, the
 * once-only warnings, and every thread's cost counters. */
#include "util/runtime.h"
#include "util/util.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int quiet;

MURK_API void murk_set_quiet(int q) { quiet = q; }

MURK_API void murk_log(int level, const char *fmt, ...)
{
    if (quiet && level == MURK_LOG_INFO)
        return;
    char raw[2048], safe[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    fprintf(stderr, "%s%s\n", level == MURK_LOG_WARN ? "murk: warning: " : "murk: ", murk_printable(safe, sizeof safe, raw));
}

static pthread_mutex_t warn_lock = PTHREAD_MUTEX_INITIALIZER;
static struct { char *msg; unsigned long count; } warned[128];
static int nwarned;

static struct { const void *owner; char *who, *what; } named[256];
static int nnamed;

void murk_warn_name(const void *owner, const char *who, const char *what)
{
    pthread_mutex_lock(&warn_lock);
    if (nnamed < (int)(sizeof named / sizeof named[0])) {
        named[nnamed].owner = owner;
        named[nnamed].who = murk_strdup(who);
        named[nnamed].what = murk_strdup(what);
        nnamed++;
    }
    pthread_mutex_unlock(&warn_lock);
}

void murk_warn_forget(const void *owner)
{
    pthread_mutex_lock(&warn_lock);
    int k = 0;
    for (int i = 0; i < nnamed; i++) {
        if (named[i].owner == owner) {
            free(named[i].who);
            free(named[i].what);
        } else {
            named[k++] = named[i];
        }
    }
    nnamed = k;
    pthread_mutex_unlock(&warn_lock);
}

/* buf with " [what]" after the first instance it names (the latest naming of it), in place; under the lock. */
static void annotate(char *buf, size_t size)
{
    for (int i = nnamed - 1; i >= 0; i--) {
        char *at = strstr(buf, named[i].who);
        if (!at)
            continue;
        at += strlen(named[i].who);
        char rest[512];
        snprintf(rest, sizeof rest, "%s", at);
        snprintf(at, size - (size_t)(at - buf), " [%s]%s", named[i].what, rest);
        return;
    }
}

void murk_warn_once(const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, 512, fmt, ap);
    va_end(ap);
    pthread_mutex_lock(&warn_lock);
    annotate(buf, sizeof buf);
    int i = 0;
    while (i < nwarned && strcmp(warned[i].msg, buf) != 0)
        i++;
    if (i < nwarned) {
        warned[i].count++;
    } else if (nwarned < (int)(sizeof warned / sizeof warned[0])) {
        warned[nwarned].msg = murk_strdup(buf);
        warned[nwarned].count = 1;
        nwarned++;
        murk_log(MURK_LOG_WARN, "%s", buf);
    }
    pthread_mutex_unlock(&warn_lock);
}

MURK_API void murk_warn_summary(void)
{
    pthread_mutex_lock(&warn_lock);
    for (int i = 0; i < nwarned; i++) {
        if (warned[i].count > 1)
            murk_log(MURK_LOG_WARN, "(%lu times in all) %s", warned[i].count, warned[i].msg);
        free(warned[i].msg);
    }
    nwarned = 0;
    pthread_mutex_unlock(&warn_lock);
}

_Thread_local murk_thread_tally *murk_tally_cache;

/* Each thread's tally is allocated on its first use and freed when the thread exits (the key's
 * destructor): libmurk's own TLS is the cache pointer alone (runtime.h). */
static pthread_key_t tally_key;
static pthread_once_t tally_once = PTHREAD_ONCE_INIT;

static void tally_free(void *t)
{
    free(t);
    murk_tally_cache = NULL;
}

static int tally_key_ok;

static void tally_key_create(void) { tally_key_ok = pthread_key_create(&tally_key, tally_free) == 0; }

murk_thread_tally *murk_tally_first(void)
{
    pthread_once(&tally_once, tally_key_create);
    murk_thread_tally *t = murk_xmalloc(sizeof *t); /* zeroed */
    if (tally_key_ok) /* else (no key left) the tally outlives its thread: a leak, never a wrong count */
        pthread_setspecific(tally_key, t);
    return murk_tally_cache = t;
}

void murk_thread_counters_reset(void) { memset(murk_tally(), 0, sizeof(murk_thread_tally)); }

void murk_thread_counters_add(murk_counters *sum, size_t n)
{
    const murk_thread_tally *t = murk_tally();
    for (size_t i = 0; i < n && i < MURK_COUNTER_SLOTS; i++) {
        const murk_counters *c = &t->media[i];
        sum[i].lookups += c->lookups;
        sum[i].cells += c->cells;
        sum[i].collisions += c->collisions;
        sum[i].scatters += c->scatters;
        sum[i].shadow += c->shadow;
    }
}
