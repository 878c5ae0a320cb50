/* policy_pace.c — how many samples per pixel the session's next pass renders (session.h), from the time
 * the last pass took per spp. pace: passes of about `seconds` each (the loss when a pass is abandoned,
 * the granularity of checkpoints). budget (--time S): whole passes while the next fits in what is left of
 * S, each filling most of it; the render ends after the last whole pass that fits. Without either the
 * session renders every sample in one pass. The session caps each pass at twice the last plus one. */
#include "render/session.h"
#include "util/util.h"

#include <stdlib.h>

static int steady(murk_session *ss, void *self, char *err, size_t errlen)
{
    (void)err, (void)errlen;
    double per_spp = ss->pass_seconds / ss->n, seconds = *(const double *)self;
    ss->next = seconds / (per_spp > 1e-9 ? per_spp : 1e-9);
    return MURK_PASS_GO;
}

void murk_policy_pace(murk_pass_policy *p, double seconds)
{
    double *s = murk_xmalloc(sizeof *s);
    *s = seconds;
    p->name = "pace";
    p->self = s;
    p->after = steady;
    p->release = free;
}

static int budget(murk_session *ss, void *self, char *err, size_t errlen)
{
    (void)self, (void)err, (void)errlen;
    double per_spp = ss->pass_seconds / ss->n, left = ss->opts.time_limit - (ss->now - ss->t0);
    if (left <= per_spp)
        return MURK_PASS_STOP;
    ss->next = left / per_spp * 0.9; /* the next pass fills most of what is left */
    return MURK_PASS_GO;
}

void murk_policy_budget(murk_pass_policy *p)
{
    p->name = "budget";
    p->after = budget;
}
