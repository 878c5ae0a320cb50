/* params.c — plugin parameter blocks: reading a plugin's keys from the scene against the plugin's
 * schema (types, ranges, choices, textures, required keys), for the scene loader (load.c) and the
 * media loader (media.c). */
#include "scene/params.h"
#include "scene/scene.h"
#include "scene/texture.h"
#include "util/runtime.h"
#include "util/util.h"
#include "yaml/yread.h"

#include "murk/integrator.h"
#include "murk/material.h"
#include "murk/phase.h"
#include "murk/transmittance.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERR(node, ...) murk_yerr(err, errlen, (node), __VA_ARGS__)

murk_value *murk_scene_keep_params(murk_scene *s, size_t n)
{
    murk_value *v = murk_xmalloc((n ? n : 1) * sizeof *v);
    s->param_store = murk_xrealloc(s->param_store, (s->nparam_store + 1) * sizeof *s->param_store);
    s->param_store[s->nparam_store++] = v;
    return v;
}

static int choice_index(const char *choices, const char *word)
{
    int idx = 0;
    size_t wl = strlen(word);
    for (const char *c = choices;; idx++) {
        const char *bar = strchr(c, '|');
        size_t len = bar ? (size_t)(bar - c) : strlen(c);
        if (len == wl && strncmp(c, word, len) == 0)
            return idx;
        if (!bar)
            return -1;
        c = bar + 1;
    }
}

/* The length of the "file:line:col: " or "--set KEY=VALUE: " (with its space) that starts a located message err (a
 * label of the document's), or 0. */
static size_t location_length(const murk_ydoc *doc, const char *err)
{
    for (size_t i = 0; i <= doc->nsets; i++) {
        const char *f = i < doc->nsets ? doc->sets[i] : doc->file;
        size_t fl = f ? strlen(f) : 0;
        if (!fl || strncmp(err, f, fl) != 0 || err[fl] != ':')
            continue;
        int used = 0, line, col;
        size_t at = fl + 1;
        if (sscanf(err + fl, ":%d:%d:%n", &line, &col, &used) == 2 && used > 0)
            at = fl + (size_t)used;
        return at + (err[at] == ' ');
    }
    return 0;
}

/* A key of the file in a block whose `type` a --set swapped (map->swapped_type) that the file's plugin
 * takes and the new one does not: dropped with a note, so that `--set media.X.type=delta` works on a
 * block written for decomposition (`control`). A key the old plugin does not take either stays an
 * error, and so does a key a --set gave. note: say so (once per key: not for the media's core keys'
 * read, which meets the same key before the tracker's). */
static int dropped_by_swap(const murk_ynode *map, size_t k, uint32_t kind, const char *who, int note)
{
    if (!map->swapped_type || murk_yfrom_set(map->key_file[k]) || murk_yfrom_set(map->items[k]->file))
        return 0;
    murk_registry reg;
    murk_registry_init(&reg);
    char lerr[1024];
    const murk_plugin *old = murk_registry_load(&reg, (int)kind, map->swapped_type, lerr, sizeof lerr);
    int took = 0;
    for (uint32_t i = 0; old && i < old->desc->nparams && !took; i++)
        took = strcmp(old->desc->params[i].name, map->keys[k]) == 0;
    if (took && note)
        murk_log(MURK_LOG_INFO, "%s: dropped '%s' (%s:%d), a parameter of '%s' that the --set of its type replaced",
                 who, map->keys[k], map->key_file[k], map->key_line[k], map->swapped_type);
    murk_registry_free(&reg);
    return took;
}

/* The message for map's key k, which d does not take: a suggestion, or where to look. Returns -1. */
static int unknown_key(const murk_plugin_desc *d, const murk_ynode *map, size_t k, const char *who,
                       const char *const *skip, size_t nskip, char *err, size_t errlen)
{
    const char *key = map->keys[k], *cand[96];
    size_t nc = 0;
    for (uint32_t i = 0; i < d->nparams && nc < 96; i++)
        cand[nc++] = d->params[i].name;
    for (size_t j = 0; j < nskip && nc < 96; j++)
        cand[nc++] = skip[j];
    const char *sug = murk_did_you_mean(key, cand, nc);
    char hint[160];
    if (sug)
        snprintf(hint, sizeof hint, "did you mean '%s'?", sug);
    else
        snprintf(hint, sizeof hint, "see: murk plugins %s", d->name);
    if (murk_yfrom_set(map->items[k]->file) && !murk_yfrom_set(map->key_file[k])) /* a --set's value */
        return murk_yerr(err, errlen, map->items[k], "unknown parameter '%s' for %s (%s)", key, who, hint);
    return murk_yerr_key(err, errlen, map, k, "unknown parameter '%s' for %s (%s)", key, who, hint);
}

murk_texture *murk_scene_keep_texture(murk_scene *s, murk_texture *t)
{
    s->textures = murk_xrealloc(s->textures, (s->ntextures + 1) * sizeof *s->textures);
    s->textures[s->ntextures++] = t;
    return t;
}

/* A float or colour parameter given as a texture (a map): parsed, kept by the scene, its average as the
 * plain value. 0, or -1 with "LOCATION: WHAT: message" in err. */
static int read_texture(murk_scene *s, const murk_param *p, murk_value *v, const murk_ynode *n, const char *what,
                        char *err, size_t errlen)
{
    murk_texture *t = murk_texture_parse(n, s->doc.file, p->min, p->max, err, errlen);
    if (!t) { /* name the parameter after the location: "LOCATION: WHO: message" */
        char msg[2048];
        size_t at = location_length(&s->doc, err);
        snprintf(msg, sizeof msg, "%.*s%s: %s", (int)at, err, what, err + at);
        snprintf(err, errlen, "%s", msg);
        return -1;
    }
    v->tex = murk_scene_keep_texture(s, t);
    murk_texture_average(t, v->f);
    return 0;
}

/* Node n as the value of parameter p (its schema entry) into v; `what` names it in messages. 0, or -1. */
static int read_value(murk_scene *s, const murk_param *p, murk_value *v, const murk_ynode *n, const char *what,
                      char *err, size_t errlen)
{
    long long iv = 0;
    int bv = 0;
    v->set = 1;
    switch (p->type) {
    case MURK_PARAM_FLOAT:
    case MURK_PARAM_RGB:
        if (n->kind == MURK_Y_MAP && (p->flags & MURK_PARAM_TEXTURABLE))
            return read_texture(s, p, v, n, what, err, errlen);
        if (n->kind == MURK_Y_MAP)
            return ERR(n, "%s does not take a texture", what);
        if (p->type == MURK_PARAM_RGB)
            return murk_yread_rgb(n, what, p->min, p->max, v->f, err, errlen) ? -1 : 0;
        if (murk_yread_range(n, what, p->min, p->max, &v->f[0], err, errlen))
            return -1;
        v->f[1] = v->f[2] = v->f[0];
        return 0;
    case MURK_PARAM_INT:
        if (murk_yread_int(n, what, p->min, p->max, &iv, err, errlen))
            return -1;
        v->f[0] = (double)iv;
        return 0;
    case MURK_PARAM_BOOL:
        if (murk_yread_bool(n, what, &bv, err, errlen))
            return -1;
        v->f[0] = bv;
        return 0;
    case MURK_PARAM_STRING:
        return murk_yread_string(n, what, &v->s, err, errlen) ? -1 : 0;
    case MURK_PARAM_ENUM:
        if (n->kind != MURK_Y_SCALAR || (v->choice = choice_index(p->choices, n->str)) < 0)
            return ERR(n, "%s must be one of %s, got '%s'", what, p->choices, n->kind == MURK_Y_SCALAR ? n->str : "a list");
        v->s = n->str;
        return 0;
    default:
        return ERR(n, "%s has an unknown type", what);
    }
}

/* Parameter i (MURK_PARAM_ALT_SCALE) and the one before it are one parameter on two scales, and the map
 * gives both: the error, located at whichever of the two keys comes second. */
static int both_scales(const murk_plugin_desc *d, const murk_ynode *map, uint32_t i, const char *who, char *err,
                       size_t errlen)
{
    size_t at = 0;
    for (size_t k = 0; k < map->n; k++)
        if (!strcmp(map->keys[k], d->params[i].name) || !strcmp(map->keys[k], d->params[i - 1].name))
            at = k;
    return murk_yerr_key(err, errlen, map, at, "%s: '%s' and '%s' are two scales of one parameter: give one", who,
                         d->params[i - 1].name, d->params[i].name);
}

/* Fills values[] in schema order from the map's keys (all keys but those in skip[]). `who` names the
 * block in messages, e.g. "material 'metal' (ggx)". */
int murk_scene_read_plugin_params(murk_scene *s, const murk_plugin_desc *d, const murk_ynode *map, const char *who,
                                  const char *const *skip, size_t nskip, int note_drops, murk_value *values, char *err,
                                  size_t errlen)
{
    for (uint32_t i = 0; i < d->nparams; i++) { /* the defaults */
        const murk_param *p = &d->params[i];
        murk_value *v = &values[i];
        memset(v, 0, sizeof *v);
        memcpy(v->f, p->def, sizeof v->f);
        v->s = p->def_str;
        if (p->type == MURK_PARAM_ENUM)
            v->choice = choice_index(p->choices, p->def_str);
    }
    for (size_t k = 0; k < map->n; k++) {
        const char *key = map->keys[k];
        int skipped = 0;
        for (size_t j = 0; j < nskip && !skipped; j++)
            skipped = strcmp(skip[j], key) == 0;
        if (skipped)
            continue;
        int idx = -1;
        for (uint32_t i = 0; i < d->nparams; i++)
            if (strcmp(d->params[i].name, key) == 0)
                idx = (int)i;
        if (idx < 0 && dropped_by_swap(map, k, d->kind, who, note_drops))
            continue;
        if (idx < 0)
            return unknown_key(d, map, k, who, skip, nskip, err, errlen);
        char what[256];
        snprintf(what, sizeof what, "%s: parameter '%s'", who, key);
        if (read_value(s, &d->params[idx], &values[idx], map->items[k], what, err, errlen))
            return -1;
    }
    for (uint32_t i = 1; i < d->nparams; i++)
        if ((d->params[i].flags & MURK_PARAM_ALT_SCALE) && values[i].set && values[i - 1].set)
            return both_scales(d, map, i, who, err, errlen);
    for (uint32_t i = 0; i < d->nparams; i++)
        if ((d->params[i].flags & MURK_PARAM_REQUIRED) && !values[i].set)
            return murk_yerr(err, errlen, map, "%s is missing the required parameter '%s'", who, d->params[i].name);
    return 0;
}

/* murk_scene_instantiate (params.h), with the textures tex[] in place of their parameters' values. */
static int instantiate(murk_scene *s, const murk_host *host, int kind, const murk_ynode *type_node, const char *type,
                       const murk_ynode *map, const char *block, const char *who, const char *const *skip,
                       size_t nskip, const murk_medium_data *data, const murk_param_texture *tex, size_t ntex,
                       const murk_plugin **plugin, void **self, char *err, size_t errlen)
{
    char lerr[1024];
    const murk_plugin *p = murk_registry_load(&s->reg, kind, type, lerr, sizeof lerr);
    if (!p)
        return ERR(type_node, "%s: %s", block, lerr);
    murk_value *vals = murk_scene_keep_params(s, p->desc->nparams);
    if (murk_scene_read_plugin_params(s, p->desc, map, who, skip, nskip, 1, vals, err, errlen))
        return -1;
    for (size_t k = 0; k < ntex; k++) {
        uint32_t i = 0;
        while (i < p->desc->nparams && strcmp(p->desc->params[i].name, tex[k].name))
            i++;
        if (i == p->desc->nparams || !(p->desc->params[i].flags & MURK_PARAM_TEXTURABLE))
            return ERR(map, "%s: no texturable parameter '%s'", who, tex[k].name);
        vals[i].set = 1;
        vals[i].tex = tex[k].tex;
        murk_texture_average(tex[k].tex, vals[i].f);
    }
    char cerr[512] = "";
    int rc;
    switch (kind) {
    case MURK_KIND_MATERIAL: rc = ((const murk_material_vt *)p->desc->vtable)->create(host, vals, self, cerr, sizeof cerr); break;
    case MURK_KIND_INTEGRATOR: rc = ((const murk_integrator_vt *)p->desc->vtable)->create(host, vals, self, cerr, sizeof cerr); break;
    case MURK_KIND_MEDIUM: rc = ((const murk_medium_vt *)p->desc->vtable)->create(host, data, vals, self, cerr, sizeof cerr); break;
    case MURK_KIND_TRANSMITTANCE:
        rc = ((const murk_transmittance_vt *)p->desc->vtable)->create(host, data, vals, self, cerr, sizeof cerr);
        break;
    case MURK_KIND_PHASE: rc = ((const murk_phase_vt *)p->desc->vtable)->create(host, vals, self, cerr, sizeof cerr); break;
    default: rc = -1; snprintf(cerr, sizeof cerr, "unknown plugin kind %d", kind);
    }
    if (rc != 0) { /* a refusal of values a --set gave is the --set's: quote the last one */
        const murk_ynode *at = map;
        for (size_t i = 0; map->kind == MURK_Y_MAP && i < map->n; i++)
            if (murk_yfrom_set(map->items[i]->file))
                at = map->items[i];
        *self = NULL;
        return ERR(at, "%s: %s", who, cerr[0] ? cerr : "create() failed");
    }
    *plugin = p;
    return 0;
}

int murk_scene_instantiate(murk_scene *s, const murk_host *host, int kind, const murk_ynode *type_node,
                           const char *type, const murk_ynode *map, const char *block, const char *who,
                           const char *const *skip, size_t nskip, const murk_medium_data *data,
                           const murk_plugin **plugin, void **self, char *err, size_t errlen)
{
    return instantiate(s, host, kind, type_node, type, map, block, who, skip, nskip, data, NULL, 0, plugin, self, err,
                       errlen);
}

int murk_scene_instantiate_textured(murk_scene *s, const murk_host *host, int kind, const murk_ynode *type_node,
                                    const char *type, const murk_ynode *map, const char *who,
                                    const murk_param_texture *tex, size_t ntex, const murk_plugin **plugin, void **self,
                                    char *err, size_t errlen)
{
    static const char *const skip[] = {"type"};
    return instantiate(s, host, kind, type_node, type, map, who, who, skip, 1, NULL, tex, ntex, plugin, self, err, errlen);
}
