/* pathtracer_tap.h — the path tracer's tap: the two functions a program that compiles pathtracer.c with
 * -DMURK_PT_TAP provides (bench/variance_profile.c, tests/test_variance_profile.c), through which it sees
 * every contribution to a sample and how each path ended. pathtracer.c includes this header only with
 * MURK_PT_TAP; the plugins are built without it, so nothing of the tap reaches them. */
#ifndef MURK_PATHTRACER_TAP_H
#define MURK_PATHTRACER_TAP_H

#include "pathtracer.h"

/* `value` (beta Le w / mean(R), what L gains) of technique `term` (MURK_PT_TERM_*, pathtracer.h) after
 * `depth` scattering events (an NEE's own vertex not counted). */
void murk_pt_tap(int depth, int term, murk_rgb value);
/* At most once per path, how it ended (MURK_PT_END_*) after `depth` scattering events: Russian roulette,
 * max_depth, a free flight of weight 0 (absorbed), escaped to the background. A path that ends otherwise
 * (a BSDF sample that failed or weighed 0, a non-finite value, the watchdog) reports no end. */
void murk_pt_tap_end(int depth, int why);

#endif
