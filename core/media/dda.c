/* dda.c — the 3-D DDA walk through a bound grid: consecutive segments that exactly tile a ray's
 * parameter range, each with its cell's majorant and minorant (see density.h for the contract). */
#include "media/density.h"

#include <math.h>

/* Parameter at which the ray leaves the current cell along axis a (INFINITY if it never does, or
 * if it cannot step further because this is the last cell: the last cell then absorbs rounding). */
static double dda_tnext(const murk_dda *it, int a)
{
    int s = it->step[a], i = it->idx[a];
    if (s == 0 || (s > 0 && i >= it->g->res[a] - 1) || (s < 0 && i <= 0))
        return INFINITY;
    double b = murk_v3_get(it->g->lo, a) + (s > 0 ? i + 1 : i) * it->g->h[a];
    return (b - it->o[a]) * it->inv_d[a];
}

enum { DDA_BEFORE, DDA_ENTER, DDA_INSIDE, DDA_AFTER, DDA_DONE };

void murk_dda_init(murk_dda *it, const murk_bound_grid *g, const murk_ray *r, float t0, float t1)
{
    if (isinf(g->lo.x) && t0 < t1) { /* infinite (constant) grid: one segment; murk_dda_next reads only
                                      * these fields of it (a homogeneous medium's every flight and shadow
                                      * ray starts here) */
        it->g = g;
        it->t = it->tin = t0;
        it->t1 = it->tout = t1;
        it->cell[0] = it->cell[1] = it->cell[2] = -1;
        it->phase = DDA_INSIDE;
        return;
    }
    it->g = g; /* every other field murk_dda_next reads is set below or in dda_enter */
    it->t = t0;
    it->t1 = t1;
    it->cell[0] = it->cell[1] = it->cell[2] = -1;
    for (int a = 0; a < 3; a++) {
        it->o[a] = murk_v3_get(r->o, a);
        it->d[a] = murk_v3_get(r->d, a);
    }
    it->tin = 1.0f;
    it->tout = 0.0f; /* missed unless proved otherwise */
    if (!(t0 < t1)) {
        it->phase = DDA_DONE;
        return;
    }
    it->phase = DDA_AFTER;
    double tin = t0, tout = t1;
    for (int a = 0; a < 3; a++) {
        double o = it->o[a], d = it->d[a], lo = murk_v3_get(g->lo, a), hi = murk_v3_get(g->hi, a);
        if (!isfinite(o) || !isfinite(d))
            return; /* a broken ray sees no density */
        it->inv_d[a] = d != 0.0 ? 1.0 / d : 0.0; /* one division per axis and walk (dda_enter's too) */
        if (d == 0.0) {
            if (o < lo || o > hi)
                return;
            continue;
        }
        double ta = (lo - o) * it->inv_d[a], tb = (hi - o) * it->inv_d[a];
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        tin = murk_fmax(tin, ta);
        tout = murk_fmin(tout, tb);
    }
    /* t0 <= tin and tout <= t1 in double, so also after rounding to float (t0, t1 are floats). */
    float fin = (float)tin, fout = (float)tout;
    if (!(fin < fout))
        return; /* missed, or only touched */
    it->tin = fin;
    it->tout = fout;
    it->phase = fin > t0 ? DDA_BEFORE : DDA_ENTER;
}

/* Enters the box at it->t: the cell holding the ray point there, and the step directions. */
static void dda_enter(murk_dda *it)
{
    const murk_bound_grid *g = it->g;
    for (int a = 0; a < 3; a++) {
        double d = it->d[a];
        it->step[a] = d > 0.0 ? 1 : (d < 0.0 ? -1 : 0);
        double u = (it->o[a] + d * it->t - murk_v3_get(g->lo, a)) * g->inv_h[a];
        it->idx[a] = u <= 0.0 ? 0 : (u >= g->res[a] - 1 ? g->res[a] - 1 : (int)floor(u));
    }
}

int murk_dda_next(murk_dda *it, float *ta, float *tb, float *maj, float *min)
{
    const murk_bound_grid *g = it->g;
    float a0, b0, mj = 0.0f, mn = 0.0f;
    it->cell[0] = it->cell[1] = it->cell[2] = -1;
    switch (it->phase) {
    case DDA_BEFORE:
        a0 = it->t;
        b0 = it->t = it->tin;
        it->phase = DDA_ENTER;
        break;
    case DDA_ENTER:
        dda_enter(it);
        it->phase = DDA_INSIDE;
        /* fall through */
    case DDA_INSIDE:
        if (isinf(g->lo.x)) {
            a0 = it->t;
            b0 = it->t = it->t1;
            mj = g->maj[0];
            mn = g->min[0];
            it->cell[0] = it->cell[1] = it->cell[2] = 0;
            it->phase = DDA_DONE;
            break;
        }
        for (;;) {
            int axis = -1;
            double tn = INFINITY;
            for (int a = 0; a < 3; a++) {
                double t = dda_tnext(it, a);
                if (t < tn) {
                    tn = t;
                    axis = a;
                }
            }
            float end = tn >= (double)it->tout ? it->tout : (float)tn;
            if (!(end > it->t)) { /* zero length (rounding, or an edge/corner crossing): step silently */
                if (axis < 0 || end >= it->tout) {
                    it->phase = DDA_AFTER;
                    return murk_dda_next(it, ta, tb, maj, min);
                }
                it->idx[axis] += it->step[axis];
                continue;
            }
            size_t k = ((size_t)it->idx[2] * (size_t)g->res[1] + (size_t)it->idx[1]) * (size_t)g->res[0] +
                       (size_t)it->idx[0];
            a0 = it->t;
            b0 = it->t = end;
            mj = g->maj[k];
            mn = g->min[k];
            for (int a = 0; a < 3; a++)
                it->cell[a] = it->idx[a];
            if (end >= it->tout)
                it->phase = DDA_AFTER;
            else
                it->idx[axis] += it->step[axis];
            break;
        }
        break;
    case DDA_AFTER: /* after the box, or the whole range for a miss */
        if (!(it->t < it->t1)) {
            it->phase = DDA_DONE;
            return 0;
        }
        a0 = it->t;
        b0 = it->t = it->t1;
        it->phase = DDA_DONE;
        break;
    default:
        return 0;
    }
    if (ta)
        *ta = a0;
    if (tb)
        *tb = b0;
    if (maj)
        *maj = mj;
    if (min)
        *min = mn;
    return 1;
}
