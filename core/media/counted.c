/* counted.c — the core's counting wrappers around a scene's medium: every free flight that scatters
 * and every transmittance estimate is added to the medium's cost counters (murk/counters.h), whatever
 * the tracker's or estimator's code. */
#include "media/media.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdlib.h>

typedef struct counted {
    const murk_medium_vt *vt; /* the tracker's own */
    void *self;
    const murk_transmittance_vt *tr_vt; /* the estimator's own, or NULL */
    void *tr_self;
    unsigned slot;
} counted;

static void counted_destroy(void *self)
{
    counted *c = self;
    if (c->self)
        c->vt->destroy(c->self);
    if (c->tr_self)
        c->tr_vt->destroy(c->tr_self);
    free(c);
}

static void counted_sample(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng,
                           murk_medium_event *ev)
{
    const counted *c = self;
    c->vt->sample(c->self, ray, ctx, rng, ev);
    murk_thread_counters[c->slot].scatters += ev->scattered != 0;
}

static murk_rgb counted_transmittance(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    const counted *c = self;
    murk_thread_counters[c->slot].shadow++;
    return c->vt->transmittance(c->self, ray, ctx, rng);
}

static void counted_estimator_destroy(void *self) { (void)self; /* counted_destroy frees the estimator */ }

static murk_rgb counted_estimate(const void *self, const murk_ray *ray, const murk_path_ctx *ctx, murk_rng *rng)
{
    const counted *c = self;
    murk_thread_counters[c->slot].shadow++;
    return c->tr_vt->estimate(c->tr_self, ray, ctx, rng);
}

static const murk_medium_vt counted_vt = {sizeof(murk_medium_vt), MURK_KIND_MEDIUM, NULL, counted_destroy,
                                          counted_sample, counted_transmittance};

static const murk_transmittance_vt counted_est_vt = {sizeof(murk_transmittance_vt), MURK_KIND_TRANSMITTANCE, NULL,
                                                     counted_estimator_destroy, counted_estimate};

void murk_media_count_medium(murk_medium *m, unsigned slot)
{
    if (!m->vt || !m->self)
        return;
    counted *c = murk_xmalloc(sizeof *c);
    *c = (counted){m->vt, m->self, m->tr_self ? m->tr_vt : NULL, m->tr_self, slot};
    m->vt = &counted_vt;
    m->self = c;
    if (c->tr_vt) {
        m->tr_vt = &counted_est_vt;
        m->tr_self = c;
    }
}

