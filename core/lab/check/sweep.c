/* sweep.c — the parameter sets of `murk check` (sweep.h). A plugin's bug may live at one value only: a
 * mode nobody runs by default, an albedo of 1 where 20 % too much energy first shows. So besides the
 * defaults and two sets with every numeric range at 25 % / 75 % (the RGB channels spread apart), each
 * parameter is set in turn, the others at their defaults, to both ends of its range and to every value of
 * an enum or bool that is not its default. Part of libmurklab. */
#include "lab/check/sweep.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Appends ", name: value" for the value v (numbers: its type's text; RGB grey) to set s and to its
 * description. 0, or -1 if it does not fit. */
static int put_value(ck_set *s, const murk_param *p, double v, const char *text)
{
    char val[160];
    if (text)
        snprintf(val, sizeof val, "%s", text);
    else if (p->type == MURK_PARAM_INT)
        snprintf(val, sizeof val, "%.0f", floor(v + 0.5));
    else if (p->type == MURK_PARAM_RGB)
        snprintf(val, sizeof val, "[%.9g, %.9g, %.9g]", v, v, v);
    else
        snprintf(val, sizeof val, "%.9g", v);
    size_t k = strlen(s->keys);
    int n = snprintf(s->keys + k, sizeof s->keys - k, ", %s: %s", p->name, val);
    return n > 0 && (size_t)n < sizeof s->keys - k ? 0 : -1;
}

/* The set with every numeric parameter of a range no wider than 1e3 at 25 % (which 1) or 75 % (2) of it,
 * an RGB's channels spread apart. 0 if d has no such parameter. */
static int spread_set(const murk_plugin_desc *d, int which, ck_set *s)
{
    memset(s, 0, sizeof *s);
    s->full = 1;
    int any = 0;
    for (uint32_t i = 0; i < d->nparams; i++) {
        const murk_param *p = &d->params[i];
        if (!(p->max > p->min) || !(p->max - p->min <= 1e3) || (p->flags & MURK_PARAM_NO_SWEEP) ||
            (p->type != MURK_PARAM_FLOAT && p->type != MURK_PARAM_INT && p->type != MURK_PARAM_RGB))
            continue;
        /* two scales of one parameter (MURK_PARAM_ALT_SCALE, never given together): the 25 % set takes the
         * first, the 75 % set the other */
        if ((which == 1 && (p->flags & MURK_PARAM_ALT_SCALE)) ||
            (which == 2 && i + 1 < d->nparams && (d->params[i + 1].flags & MURK_PARAM_ALT_SCALE)))
            continue;
        double f[3] = {which == 1 ? 0.25 : 0.75, which == 1 ? 0.5 : 0.6, which == 1 ? 0.75 : 0.3};
        double v[3];
        for (int ch = 0; ch < 3; ch++)
            v[ch] = p->min + f[ch] * (p->max - p->min);
        char rgb[160];
        snprintf(rgb, sizeof rgb, "[%.9g, %.9g, %.9g]", v[0], v[1], v[2]);
        if (put_value(s, p, v[0], p->type == MURK_PARAM_RGB ? rgb : NULL))
            return 0;
        any = 1;
    }
    snprintf(s->what, sizeof s->what, "every numeric range at %s (%s)", which == 1 ? "25 %" : "75 %", s->keys + 2);
    return any;
}

/* One parameter at value v (or text), the others at their defaults; counted in *dropped if out is full. */
static int one_param(ck_set *out, int n, int max, int *dropped, const murk_param *p, double v, const char *text,
                     const char *why)
{
    if (n >= max) {
        ++*dropped;
        return n;
    }
    ck_set *s = &out[n];
    memset(s, 0, sizeof *s);
    if (put_value(s, p, v, text))
        return n;
    snprintf(s->what, sizeof s->what, "%s%s (the others at their defaults)", s->keys + 2, why);
    return n + 1;
}

/* Every value of p worth a set of its own: the ends of its range, each choice of an enum, the other bool. */
static int sweep_param(const murk_plugin_desc *d, const murk_param *p, ck_set *out, int n, int max, int *dropped)
{
    if (p->flags & MURK_PARAM_NO_SWEEP) /* its other values are for study (murk/plugin.h) */
        return n;
    if (p->type == MURK_PARAM_BOOL)
        return one_param(out, n, max, dropped, p, 0.0, p->def[0] != 0.0 ? "false" : "true", "");
    if (p->type == MURK_PARAM_ENUM) {
        for (const char *c = p->choices; c && *c;) {
            const char *bar = strchr(c, '|');
            char v[128];
            snprintf(v, sizeof v, "%.*s", bar ? (int)(bar - c) : (int)strlen(c), c);
            if (!p->def_str || strcmp(v, p->def_str))
                n = one_param(out, n, max, dropped, p, 0.0, v, "");
            c = bar ? bar + 1 : c + strlen(c);
        }
        return n;
    }
    if (p->type != MURK_PARAM_FLOAT && p->type != MURK_PARAM_INT && p->type != MURK_PARAM_RGB)
        return n;
    if (!(p->max >= p->min) || !(fabs(p->min) <= 1e6) || !(fabs(p->max) <= 1e6))
        return n; /* no finite ends to test */
    int depth = d->kind == MURK_KIND_INTEGRATOR && !strcmp(p->name, "max_depth");
    for (int end = depth ? 1 : 0; end < 2; end++) {
        double v = end ? p->max : p->min;
        int is_def = p->def[0] == v && (p->type != MURK_PARAM_RGB || (p->def[1] == v && p->def[2] == v));
        if (!is_def)
            n = one_param(out, n, max, dropped, p, v, NULL, end ? ", its maximum" : ", its minimum");
    }
    return n;
}

static int from_assignments(const murk_plugin_desc *d, const char *const *assign, int nassign, ck_set *s, char *err,
                            size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->full = 1;
    for (int i = 0; i < nassign; i++) {
        const char *eq = strchr(assign[i], '=');
        const murk_param *p = NULL;
        for (uint32_t k = 0; eq && k < d->nparams && !p; k++)
            if (strlen(d->params[k].name) == (size_t)(eq - assign[i]) && !strncmp(d->params[k].name, assign[i], (size_t)(eq - assign[i])))
                p = &d->params[k];
        if (!p) {
            snprintf(err, errlen, "--set %s: %s has no parameter '%.*s' (see: murk plugins %s)", assign[i], d->name,
                     eq ? (int)(eq - assign[i]) : (int)strlen(assign[i]), assign[i], d->name);
            return -1;
        }
        if (put_value(s, p, 0.0, eq + 1)) {
            snprintf(err, errlen, "--set %s: too long", assign[i]);
            return -1;
        }
    }
    snprintf(s->what, sizeof s->what, "%s (--set; the others at their defaults)", s->keys + 2);
    return 1;
}

int ck_param_sets(const murk_plugin_desc *d, const char *const *assign, int nassign, ck_set *out, int max, char *err,
                  size_t errlen)
{
    if (errlen)
        err[0] = '\0';
    if (nassign > 0)
        return max > 0 ? from_assignments(d, assign, nassign, out, err, errlen) : 0;
    int n = 0, dropped = 0;
    if (max < 3)
        return 0;
    memset(&out[n], 0, sizeof out[n]);
    out[n].full = 1;
    snprintf(out[n++].what, sizeof out[0].what, "defaults");
    for (int which = 1; which <= 2; which++)
        n += spread_set(d, which, &out[n]);
    for (uint32_t i = 0; i < d->nparams; i++)
        n = sweep_param(d, &d->params[i], out, n, max, &dropped);
    if (dropped) /* said, never silently left out */
        snprintf(err, errlen, "%d sweep point%s beyond the first %d parameter sets not run (check them with --set)",
                 dropped, dropped == 1 ? "" : "s", max);
    return n;
}
