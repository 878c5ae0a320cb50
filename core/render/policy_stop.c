/* policy_stop.c — what a stop (a signal's flag, murk_session_stop) needs in a session (session.h): only
 * whole passes count, so the pixels' state and the NaN count are copied before each pass and put back
 * when the pass was abandoned (its tiles half advanced). The render threads see the stop (render.c);
 * the session then ends the render with the image of the whole passes done. */
#include "render/session.h"
#include "scene/scene.h"
#include "util/util.h"

#include <stdlib.h>
#include <string.h>

typedef struct keep {
    double *sum;
    uint32_t *count;
    size_t npix;
    uint64_t nonfinite;
} keep;

static int alloc_copy(murk_session *ss, void *self, char *err, size_t errlen)
{
    (void)err, (void)errlen;
    keep *k = self;
    k->npix = (size_t)ss->s->width * (size_t)ss->s->height;
    k->sum = murk_xmalloc(3 * k->npix * sizeof(double));
    k->count = murk_xmalloc(k->npix * sizeof(uint32_t));
    return 0;
}

static void copy(murk_session *ss, void *self)
{
    keep *k = self;
    memcpy(k->sum, ss->job.sum, 3 * k->npix * sizeof(double));
    memcpy(k->count, ss->job.count, k->npix * sizeof(uint32_t));
    k->nonfinite = (uint64_t)atomic_load(&ss->job.nonfinite);
}

static void roll_back(murk_session *ss, void *self)
{
    keep *k = self;
    if (!atomic_load(&ss->job.abandoned))
        return;
    memcpy(ss->job.sum, k->sum, 3 * k->npix * sizeof(double));
    memcpy(ss->job.count, k->count, k->npix * sizeof(uint32_t));
    atomic_store(&ss->job.nonfinite, k->nonfinite);
}

static void release(void *self)
{
    keep *k = self;
    free(k->sum);
    free(k->count);
    free(k);
}

void murk_policy_rollback(murk_pass_policy *p)
{
    p->name = "rollback";
    p->self = murk_xmalloc(sizeof(keep));
    p->begin = alloc_copy;
    p->before = copy;
    p->ran = roll_back;
    p->release = release;
}
