/* counters.h — the text forms of a render's cost counters (murk/counters.h), for the murk command's
 * render and bench alike. Internal to libmurk (exported for the murk command). */
#ifndef MURK_RENDER_COUNTERS_H
#define MURK_RENDER_COUNTERS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "murk/murk.h"

/* The k-th counter of c, in MURK_COUNTER_NAMES' order. */
uint64_t murk_counters_get(const murk_counters *c, int k);
/* The media's counters of r summed. */
murk_counters murk_counters_total(const murk_render_result *r);
/* The media's counters as JSON, for the EXR's murk:counters: {"rays": N, "total": {...}, "media":
 * {"NAME": {...}, ...}}; when the names do not fit in buf, the rays and totals only. */
void murk_counters_json(const murk_scene *s, const murk_render_result *r, char *buf, size_t n);
/* The end-of-render summary's counters: rays, then one line per medium (and their sum when several). */
void murk_counters_print(FILE *f, const murk_scene *s, const murk_render_result *r);

#endif
