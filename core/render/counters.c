/* counters.c — the text forms of a render's cost counters (murk/counters.h): the JSON the murk command
 * stores in an EXR's murk:counters and the lines of its end-of-render summary; `murk render` and
 * `murk bench` both print through them. */
#include "render/counters.h"
#include "scene/scene.h"
#include "util/util.h"

#include <stdio.h>

static const char *const counter_names[MURK_NCOUNTERS] = MURK_COUNTER_NAMES;

MURK_API uint64_t murk_counters_get(const murk_counters *c, int k)
{
    const uint64_t v[MURK_NCOUNTERS] = {c->lookups, c->cells, c->collisions, c->scatters, c->shadow};
    return v[k];
}

MURK_API murk_counters murk_counters_total(const murk_render_result *r)
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
                              (unsigned long long)murk_counters_get(c, i));
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, "}");
    return k;
}

MURK_API void murk_counters_json(const murk_scene *s, const murk_render_result *r, char *buf, size_t n)
{
    murk_counters t = murk_counters_total(r);
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

MURK_API void murk_counters_print(FILE *f, const murk_scene *s, const murk_render_result *r)
{
    fprintf(f, "counters: %llu rays traced", (unsigned long long)r->rays);
    for (int i = 0; i <= r->nmedia; i++) {
        if (i == r->nmedia && r->nmedia < 2)
            break;
        murk_counters t = i < r->nmedia ? r->media[i] : murk_counters_total(r);
        char name[1024];
        if (i < r->nmedia)
            fprintf(f, "\n  medium '%s':", murk_printable(name, sizeof name, slot_name(s, i)));
        else
            fprintf(f, "\n  all media:");
        for (int k = 0; k < MURK_NCOUNTERS; k++)
            fprintf(f, " %llu %s%s", (unsigned long long)murk_counters_get(&t, k), counter_names[k],
                    k + 1 < MURK_NCOUNTERS ? "," : "");
    }
    fputc('\n', f);
}
