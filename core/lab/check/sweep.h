/* sweep.h — the parameter sets `murk check` runs a plugin with (sweep.c): the defaults, each parameter's
 * range endpoints and every value of its enums and bools, one parameter at a time, and two sets with
 * every numeric range at 25 % / 75 %; or exactly the values the user gave (--set KEY=VALUE). Internal to
 * libmurklab. */
#ifndef MURK_CHECK_SWEEP_H
#define MURK_CHECK_SWEEP_H

#include <stddef.h>
#include "murk/plugin.h"

enum { CK_MAX_SETS = 48 };

/* One set: the keys to add to the plugin's block in a scene (", k: v, ..."; "" for the defaults), what it
 * is for the output, and whether it is one of the sets every check runs on in full (the defaults, the two
 * 25 % / 75 % sets and a --set combination) or a sweep point (`murk check --quick` thins those). */
typedef struct ck_set {
    char keys[1024];
    char what[512];
    int full;
} ck_set;

/* The sets for plugin d into out (at most max): with nassign > 0 the one set of those KEY=VALUE
 * assignments (every KEY a parameter of d, else -1 with err); else the sweep. An integrator's
 * `max_depth` is swept to its maximum only (the furnace's closed form needs unlimited bounces). Returns
 * the count; a sweep that did not fit into max sets returns max and says so in err (err is "" otherwise). */
int ck_param_sets(const murk_plugin_desc *d, const char *const *assign, int nassign, ck_set *out, int max, char *err,
                  size_t errlen);

#endif
