/* bench.c — the cost counters' text forms (the end-of-render summary and the EXR's murk:counters).
 * Part of the murk executable. */
#include "cli.h"
#include "scene.h"
#include "util.h"

#include <stdio.h>
#include <string.h>

static const char *const counter_names[MURK_NCOUNTERS] = MURK_COUNTER_NAMES;

static uint64_t counter_get(const murk_counters *c, int k)
{
    const uint64_t v[MURK_NCOUNTERS] = {c->lookups, c->cells, c->collisions, c->scatters, c->shadow};
    return v[k];
}

/* The media's counters summed. */
static murk_counters counters_total(const murk_render_result *r)
{
    murk_counters t = {0};
    for (int i = 0; i < r->nmedia; i++) {
        t.lookups += r->media[i].lookups;
        t.cells += r->media[i].cells;
        t.collisions += r->media[i].collisions;
        t.scatters += r->media[i].scatters;
        t.shadow += r->media[i].shadow;
    }
    return t;
}

/* A medium's name for the counters: the scene's, or "(the rest)" for the shared last slot. */
static const char *slot_name(const murk_scene *s, int i)
{
    return i == MURK_COUNTER_SLOTS - 1 && s->nmedia > MURK_COUNTER_SLOTS ? "(the rest)" : s->media[i].name;
}

static size_t json_counters(char *buf, size_t n, size_t k, const murk_counters *c)
{
    for (int i = 0; i < MURK_NCOUNTERS && k < n; i++)
        k += (size_t)snprintf(buf + k, n - k, "%s\"%s\": %llu", i ? ", " : "{", counter_names[i],
                              (unsigned long long)counter_get(c, i));
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, "}");
    return k;
}

/* The media's counters as JSON: {"rays": N, "total": {...}, "media": {"NAME": {...}, ...}}; when the
 * names do not fit in buf, the rays and totals only. */
void murk_cli_counters_json(const murk_scene *s, const murk_render_result *r, char *buf, size_t n)
{
    murk_counters t = counters_total(r);
    size_t head = (size_t)snprintf(buf, n, "{\"rays\": %llu, \"total\": ", (unsigned long long)r->rays);
    size_t k = json_counters(buf, n, head, &t);
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, ", \"media\": {");
    for (int i = 0; i < r->nmedia && k < n; i++) {
        k += (size_t)snprintf(buf + k, n - k, "%s\"", i ? ", " : "");
        for (const char *p = slot_name(s, i); *p && k < n; p++) { /* escape " \ and control characters */
            unsigned char ch = (unsigned char)*p;
            k += ch < 0x20 ? (size_t)snprintf(buf + k, n - k, "\\u%04x", ch)
                           : (size_t)snprintf(buf + k, n - k, ch == '"' || ch == '\\' ? "\\%c" : "%c", ch);
        }
        if (k < n)
            k += (size_t)snprintf(buf + k, n - k, "\": ");
        k = json_counters(buf, n, k, &r->media[i]);
    }
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, "}}");
    if (k >= n) { /* too long: the totals alone */
        k = json_counters(buf, n, head, &t);
        if (k < n)
            snprintf(buf + k, n - k, "}");
    }
}

/* The end-of-render summary's counters: rays, then one line per medium (and their sum when several). */
void murk_cli_counters_print(FILE *f, const murk_scene *s, const murk_render_result *r)
{
    fprintf(f, "counters: %llu rays traced", (unsigned long long)r->rays);
    for (int i = 0; i <= r->nmedia; i++) {
        if (i == r->nmedia && r->nmedia < 2)
            break;
        murk_counters t = i < r->nmedia ? r->media[i] : counters_total(r);
        if (i < r->nmedia)
            fprintf(f, "\n  medium '%s':", murk_cli_q(slot_name(s, i)));
        else
            fprintf(f, "\n  all media:");
        for (int k = 0; k < MURK_NCOUNTERS; k++)
            fprintf(f, " %llu %s%s", (unsigned long long)counter_get(&t, k), counter_names[k],
                    k + 1 < MURK_NCOUNTERS ? "," : "");
    }
    fputc('\n', f);
}
