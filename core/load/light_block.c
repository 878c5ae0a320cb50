/* light_block.c — the scene's `lights:` list (render/lights.h holds the lights and their adders):
 *
 *   lights:
 *     - { type: point, position: [x, y, z], intensity: RGB }                       # W/sr
 *     - { type: spot, position, direction, intensity, cone_angle: 30, falloff_angle: 25 }
 *     - { type: distant, direction: [x, y, z], irradiance: RGB, angular_diameter: 0 }  # towards the light
 *     - { type: envmap, file: sky.exr, scale: 1, rotation: 0 }                     # lat-long RGB EXR
 *     - { type: sky, sun_direction: [x, y, z], turbidity: 3, sun: true }           # Preetham 1999
 *
 * Every key is checked and every error is located at its key: "scene.yaml:12:7: lights[1] (spot): ...".
 * Defaults: cone_angle 30 and falloff_angle cone_angle - 5 (pbrt-v4's coneangle and conedelta), at least
 * 0; angular_diameter 0 (a delta light); scale 1, rotation 0; turbidity 3, sun true. */
#include "load/load.h"
#include "render/lights.h"
#include "util/util.h"
#include "yaml/yread.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERR(node, ...) murk_yerr(err, errlen, (node), __VA_ARGS__)
#define NKEYS(a) (sizeof(a) / sizeof((a)[0]))

typedef struct light_ctx {
    murk_scene *s;
    const murk_ynode *n; /* the light's map */
    char who[64];        /* "lights[1] (spot)" */
} light_ctx;

/* A required or optional vec3 key: 1 if present, 0 if absent (and optional), -1 on error. A direction
 * (dir = 1) must have a length. */
static int get_vec3(const light_ctx *c, const char *key, int required, int dir, murk_vec3 *out, char *err, size_t errlen)
{
    const murk_ynode *k = required ? murk_yrequire(c->n, key, c->who, err, errlen) : murk_ymap_get(c->n, key);
    if (!k)
        return required ? -1 : 0;
    char what[128];
    snprintf(what, sizeof what, "%s: %s", c->who, key);
    if (murk_yread_vec3(k, what, out, err, errlen))
        return -1;
    if (dir && !(murk_length(*out) > 0.0f))
        return ERR(k, "%s has no length: give the direction it points in", what);
    return 1;
}

static int get_rgb(const light_ctx *c, const char *key, int required, double def, murk_rgb *out, char *err,
                   size_t errlen)
{
    const murk_ynode *k = required ? murk_yrequire(c->n, key, c->who, err, errlen) : murk_ymap_get(c->n, key);
    double v[3] = {def, def, def};
    char what[128];
    snprintf(what, sizeof what, "%s: %s", c->who, key);
    if (required && !k)
        return -1;
    if (k && murk_yread_rgb(k, what, 0, 1e30, v, err, errlen))
        return -1;
    *out = murk_rgb3((float)v[0], (float)v[1], (float)v[2]);
    return 0;
}

static int get_num(const light_ctx *c, const char *key, double lo, double hi, double def, double *out, char *err,
                   size_t errlen)
{
    const murk_ynode *k = murk_ymap_get(c->n, key);
    char what[128];
    snprintf(what, sizeof what, "%s: %s", c->who, key);
    *out = def;
    return k ? murk_yread_range(k, what, lo, hi, out, err, errlen) : 0;
}

/* An adder's error, located at `key` (or the light's map) and named. */
static int added(const light_ctx *c, int rc, const char *key, const char *why, char *err, size_t errlen)
{
    if (rc == 0)
        return 0;
    const murk_ynode *k = key ? murk_ymap_get(c->n, key) : NULL;
    return ERR(k ? k : c->n, "%s: %s", c->who, why);
}

static int load_punctual(const light_ctx *c, int spot, char *err, size_t errlen)
{
    murk_vec3 pos, dir = murk_v3(0, -1, 0);
    murk_rgb I;
    if (get_vec3(c, "position", 1, 0, &pos, err, errlen) < 0 || get_rgb(c, "intensity", 1, 0, &I, err, errlen))
        return -1;
    char why[512];
    if (!spot)
        return added(c, murk_lights_add_point(c->s, pos, I, why, sizeof why), "position", why, err, errlen);
    double cone, fall;
    if (get_vec3(c, "direction", 1, 1, &dir, err, errlen) < 0 ||
        get_num(c, "cone_angle", 0, 180, 30, &cone, err, errlen) ||
        get_num(c, "falloff_angle", 0, 180, fmax(0.0, cone - 5.0), &fall, err, errlen))
        return -1;
    if (!(cone > 0.0))
        return ERR(murk_ymap_get(c->n, "cone_angle"), "%s: cone_angle must be above 0 degrees", c->who);
    return added(c, murk_lights_add_spot(c->s, pos, dir, I, cone, fall, why, sizeof why), "cone_angle", why, err,
                 errlen);
}

static int load_distant(const light_ctx *c, char *err, size_t errlen)
{
    murk_vec3 dir;
    murk_rgb E;
    double diam;
    if (get_vec3(c, "direction", 1, 1, &dir, err, errlen) < 0 || get_rgb(c, "irradiance", 1, 0, &E, err, errlen) ||
        get_num(c, "angular_diameter", 0, 180, 0, &diam, err, errlen))
        return -1;
    if (!(diam < 180.0))
        return ERR(murk_ymap_get(c->n, "angular_diameter"), "%s: angular_diameter must be below 180 degrees (a cone "
                   "of half-angle 90 or more is no distant light)", c->who);
    char why[512];
    return added(c, murk_lights_add_distant(c->s, dir, E, diam, why, sizeof why), "direction", why, err, errlen);
}

static int load_envmap(const light_ctx *c, char *err, size_t errlen)
{
    const murk_ynode *f = murk_yrequire(c->n, "file", c->who, err, errlen);
    const char *file = NULL;
    murk_rgb scale;
    double rot;
    char what[128];
    snprintf(what, sizeof what, "%s: file", c->who);
    if (!f || murk_yread_string(f, what, &file, err, errlen) || get_rgb(c, "scale", 0, 1, &scale, err, errlen) ||
        get_num(c, "rotation", -1e6, 1e6, 0, &rot, err, errlen))
        return -1;
    char *path = murk_path_relative_to(c->s->doc.file, file), why[768];
    int rc = murk_lights_add_envmap(c->s, path, scale, rot, why, sizeof why);
    free(path);
    return added(c, rc, "file", why, err, errlen);
}

static int load_sky(const light_ctx *c, char *err, size_t errlen)
{
    murk_vec3 dir;
    double T;
    int sun = 1;
    const murk_ynode *k;
    if (get_vec3(c, "sun_direction", 1, 1, &dir, err, errlen) < 0 || get_num(c, "turbidity", 1.7, 10, 3, &T, err, errlen))
        return -1;
    char what[128];
    snprintf(what, sizeof what, "%s: sun", c->who);
    if ((k = murk_ymap_get(c->n, "sun")) && murk_yread_bool(k, what, &sun, err, errlen))
        return -1;
    char why[512];
    return added(c, murk_lights_add_sky(c->s, dir, T, sun, why, sizeof why), "sun_direction", why, err, errlen);
}

/* One light of the list. */
static int load_light(murk_scene *s, const murk_ynode *n, size_t i, char *err, size_t errlen)
{
    static const char *const types[] = {"point", "spot", "distant", "envmap", "sky"};
    static const char *const keys[][7] = {
        {"type", "position", "intensity"},
        {"type", "position", "direction", "intensity", "cone_angle", "falloff_angle"},
        {"type", "direction", "irradiance", "angular_diameter"},
        {"type", "file", "scale", "rotation"},
        {"type", "sun_direction", "turbidity", "sun"},
    };
    static const size_t nkeys[] = {3, 6, 4, 4, 4};
    light_ctx c = {s, n, ""};
    snprintf(c.who, sizeof c.who, "lights[%zu]", i);
    if (murk_yexpect_map(n, c.who, err, errlen))
        return -1;
    const murk_ynode *t = murk_yrequire(n, "type", c.who, err, errlen);
    const char *type = NULL;
    if (!t || murk_yread_string(t, "light type", &type, err, errlen))
        return -1;
    size_t k = 0;
    while (k < NKEYS(types) && strcmp(type, types[k]) != 0)
        k++;
    if (k == NKEYS(types)) {
        const char *sug = murk_did_you_mean(type, types, NKEYS(types));
        if (sug)
            return ERR(t, "%s: unknown light type '%s' (did you mean '%s'?)", c.who, type, sug);
        return ERR(t, "%s: unknown light type '%s'; expected point, spot, distant, envmap or sky", c.who, type);
    }
    snprintf(c.who, sizeof c.who, "lights[%zu] (%s)", i, type);
    if (murk_ycheck_keys(n, c.who, keys[k], nkeys[k], err, errlen))
        return -1;
    size_t before = s->nadded;
    int rc = k <= 1 ? load_punctual(&c, k == 1, err, errlen) : k == 2 ? load_distant(&c, err, errlen)
             : k == 3 ? load_envmap(&c, err, errlen) : load_sky(&c, err, errlen);
    if (rc == 0)
        murk_load_note_lights(s, before, "%s:%d:%d lights[%zu]", n->file, n->line, n->col, i);
    for (size_t j = before; rc == 0 && s->legacy_lights && j < s->nadded; j++)
        if (!murk_light_is_env(&s->added[j]))
            return ERR(t, "%s: the integrator predates plugin ABI 1.%d and cannot sample a delta light (point, spot, "
                       "distant with angular_diameter 0), which nothing else can reach: rebuild it against this murk",
                       c.who, MURK_ABI_MINOR_LIGHTS);
    return rc;
}

void murk_load_note_lights(murk_scene *s, size_t before, const char *fmt, ...)
{
    if (s->nadded <= before)
        return;
    char where[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(where, sizeof where, fmt, ap);
    va_end(ap);
    s->light_origins = murk_xrealloc(s->light_origins, (s->nlight_origins + 1) * sizeof *s->light_origins);
    s->light_origins[s->nlight_origins++] = (struct murk_light_origin){before, s->nadded - before, murk_strdup(where)};
}

int murk_load_lights(murk_scene *s, const murk_ynode *n, char *err, size_t errlen)
{
    if (!n)
        return 0;
    if (n->kind != MURK_Y_SEQ)
        return ERR(n, "lights must be a list");
    for (size_t i = 0; i < n->n; i++)
        if (load_light(s, n->items[i], i, err, errlen))
            return -1;
    return 0;
}
