/* policy_checkpoint.c — the session's checkpoints (session.h; the file: checkpoint.h). checkpoint
 * (--checkpoint FILE [--every S]): whether FILE can be written is checked before the first sample (not
 * found out after the whole render); the state of the whole passes done is saved after a pass once
 * checkpoint_every seconds have passed since the last save, and at the end — also after a stop, so the
 * render can be resumed. resume (--resume FILE): the state saved is loaded before the first pass, and the
 * render goes on from its spp. */
#include "render/checkpoint.h"
#include "render/session.h"
#include "scene/scene.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/util.h"

#include <stdlib.h>
#include <string.h>

/* Saves the state after ss->done whole samples per pixel; 0 or -1 with err set. */
static int save(murk_session *ss, char *err, size_t errlen)
{
    const murk_scene *s = ss->s;
    const murk_job *j = &ss->job;
    murk_ckpt c = {.scene_hash = ss->opts.scene_hash, .seed = s->seed, .width = s->width, .height = s->height,
                   .spp = ss->done, .overrides = ss->opts.overrides ? ss->opts.overrides : "",
                   .nonfinite = (uint64_t)atomic_load(&j->nonfinite), .rays = (uint64_t)atomic_load(&j->rays),
                   .sum = j->sum, .count = j->count};
    return murk_ckpt_save(ss->opts.checkpoint, &c, err, errlen);
}

/* After a whole pass (not the last: the end saves that one): saves when checkpoint_every has passed. */
static int save_when_due(murk_session *ss, void *self, char *err, size_t errlen)
{
    double *last = self; /* when the last save ended; < 0: none yet, count from the start */
    double since = *last >= 0 ? *last : ss->t0;
    if (ss->done >= ss->spp || ss->now - since < ss->opts.checkpoint_every || murk_job_stopped(&ss->job))
        return MURK_PASS_GO;
    if (save(ss, err, errlen) != 0) {
        if (murk_job_stopped(&ss->job)) { /* the signal cut the write short: the final save redoes it */
            err[0] = 0;
            return MURK_PASS_STOP;
        }
        return MURK_PASS_FAIL;
    }
    *last = murk_now();
    return MURK_PASS_GO;
}

static int check(murk_session *ss, void *self, char *err, size_t errlen)
{
    (void)self;
    return murk_output_probe(ss->opts.checkpoint, "checkpoint", err, errlen);
}

static int save_at_end(murk_session *ss, void *self, int rc, char *err, size_t errlen)
{
    (void)self;
    if (rc == 0 && ss->began && save(ss, err, errlen) != 0)
        rc = -1;
    return rc;
}

void murk_policy_checkpoint(murk_pass_policy *p)
{
    double *last = murk_xmalloc(sizeof *last);
    *last = -1;
    p->name = "checkpoint";
    p->self = last;
    p->begin = check;
    p->after = save_when_due;
    p->end = save_at_end;
    p->release = free;
}

/* Before the first pass: the checkpoint's state, if it belongs to this render and has no more spp than
 * asked for. */
static int load(murk_session *ss, void *self, char *err, size_t errlen)
{
    (void)self;
    const murk_scene *s = ss->s;
    murk_job *j = &ss->job;
    murk_ckpt want = {.scene_hash = ss->opts.scene_hash, .seed = s->seed, .width = s->width, .height = s->height,
                      .overrides = ss->opts.overrides}, c;
    if (murk_ckpt_load(ss->opts.resume, &want, &c, err, errlen) != 0)
        return -1;
    if (c.spp > ss->spp) {
        murk_err_file(err, errlen, ss->opts.resume, "the checkpoint has %d spp, more than the %d asked for", c.spp,
                      ss->spp);
        murk_ckpt_free(&c);
        return -1;
    }
    size_t npix = (size_t)s->width * (size_t)s->height;
    memcpy(j->sum, c.sum, 3 * npix * sizeof(double));
    memcpy(j->count, c.count, npix * sizeof(uint32_t));
    atomic_store(&j->nonfinite, c.nonfinite);
    atomic_store(&j->rays, c.rays);
    ss->rays_before = c.rays;
    ss->done = ss->resumed_spp = c.spp;
    murk_ckpt_free(&c);
    return 0;
}

void murk_policy_resume(murk_pass_policy *p)
{
    p->name = "resume";
    p->begin = load;
}
