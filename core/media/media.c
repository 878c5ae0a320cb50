/* media.c — the scene's media: parsing `media:`, density fields and their majorant/minorant grids,
 * instantiating tracker plugins, and the host services trackers call (density, majorant walk,
 * once-only warnings, Henyey-Greenstein phase function).
 *
 *   media:
 *     NAME:
 *       type: delta                 # the tracker plugin
 *       density: { constant: 1 }    # or { grid: file.vol } / { grid: file.nvdb } /
 *                                   #    { cloud: { min, max, seed, frequency, octaves, coverage, resolution } }
 *       sigma_a: [r, g, b]          # absorption per unit density (default 0)
 *       sigma_s: [r, g, b]          # scattering per unit density (default 1)
 *       scale: 1                    # multiplies sigma_a and sigma_s
 *       g: 0                        # Henyey-Greenstein asymmetry
 *       majorant_factor: 1          # multiplies the majorant grid; < 1 no longer bounds (repaired, warned)
 *       majorant_resolution: 16     # majorant grid cells along the field's longest axis
 *       majorant_repair: true       # cells a factor < 1 left below the density get their exact bound back
 *       stratify_flights: true      # a free flight's first numbers from the sampler (murk/tracking.h)
 *       transmittance: ratio        # shadow rays' estimator plugin, or { type: NAME, its keys ... };
 *                                   # none: the tracker's own transmittance() (murk/transmittance.h)
 *       ...                         # the tracker's own parameters */
#include "media/media.h"
#include "media/density.h"
#include "media/fields.h"
#include "media/source.h"
#include "scene/params.h"
#include "scene/scene.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"
#include "yaml/yread.h"

#include "murk/phase.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct murk_density {
    murk_field *field;
    murk_bound_grid grid;
    float factor;
    unsigned slot;             /* its medium's cost counters (runtime.h) */
    int transformed;           /* the field's map rotates, shears or mirrors (murk_field_local_ray) */
    murk_phase phase;          /* the `phase:` plugin; vt NULL: Henyey-Greenstein of the medium's g */
    murk_medium_fields fields; /* albedo, emission, temperature (fields.h) */
};

MURK_API void murk_density_parts(const murk_density *d, const murk_field **field, const murk_bound_grid **grid,
                                 float *factor)
{
    *field = d->field;
    *grid = &d->grid;
    *factor = d->factor;
}

typedef struct walk {
    murk_dda dda;
    float factor;
    murk_counters *count; /* this thread's block for the medium (runtime.h), taken once per walk */
} walk;

_Static_assert(sizeof(walk) <= sizeof(murk_majorant_walk), "murk_majorant_walk too small for the DDA state");

/* ---- host services ------------------------------------------------------------------------- */

/* The lookups being recorded (murk_media_record_lookups), or NULL: one predictable branch per call. */
static murk_lookup_record *lookup_record;

void murk_media_record_lookups(murk_lookup_record *rec) { lookup_record = rec; }

static void record_lookup(int kind, const murk_density *d, const void *w, const murk_ray *r, float t0, float t1)
{
    murk_lookup_record *rec = lookup_record;
    if (rec->n < rec->cap)
        rec->ev[rec->n] = (murk_lookup_event){d, w, *r, t0, t1, kind};
    rec->n++;
}

float murk_media_density(const murk_density *d, murk_vec3 p)
{
    murk_thread_counters()[d->slot].lookups++;
    float v = murk_field_eval(d->field, p);
    if (lookup_record) {
        murk_ray r = {p, p, 0.0f, 0.0f};
        record_lookup(MURK_LOOKUP_DENSITY, d, NULL, &r, 0.0f, 0.0f);
        lookup_record->sum += (double)v;
    }
    return v;
}

murk_counters *murk_media_counters(const murk_density *d) { return &murk_thread_counters()[d->slot]; }

void murk_media_walk_init(const murk_density *d, const murk_ray *ray, float t0, float t1, murk_majorant_walk *w)
{
    walk *k = (walk *)(void *)w;
    if (d->transformed) { /* the bound grid is in the grid's index space: walk the ray mapped there */
        murk_ray l = murk_field_local_ray(d->field, ray);
        murk_dda_init(&k->dda, &d->grid, &l, t0, t1);
    } else {
        murk_dda_init(&k->dda, &d->grid, ray, t0, t1);
    }
    k->factor = d->factor;
    k->count = &murk_thread_counters()[d->slot];
    if (lookup_record)
        record_lookup(MURK_LOOKUP_WALK_INIT, d, w, ray, t0, t1);
}

int murk_media_walk_next(murk_majorant_walk *w, float *ta, float *tb, float *dmax, float *dmin)
{
    walk *k = (walk *)(void *)w;
    float mx = 0.0f, mn = 0.0f;
    int r = murk_dda_next(&k->dda, ta, tb, &mx, &mn);
    k->count->cells += (unsigned)r;
    if (lookup_record) {
        murk_ray none = {{0, 0, 0}, {0, 0, 0}, 0.0f, 0.0f};
        record_lookup(MURK_LOOKUP_WALK_NEXT, NULL, w, &none, 0.0f, 0.0f);
    }
    if (dmax)
        *dmax = mx * k->factor;
    if (dmin)
        *dmin = mn;
    return r;
}

float murk_phase_hg_eval(float g, murk_vec3 wo, murk_vec3 wi) { return murk_hg_eval(g, wo, wi); }

murk_vec3 murk_phase_hg_sample(float g, murk_vec3 wo, const float u[2], float *pdf)
{
    return murk_hg_sample(g, wo, u, pdf);
}

/* A medium's phase function: its plugin, else Henyey-Greenstein of its g (the same bits as above). */
float murk_media_phase_eval(const murk_medium *m, murk_vec3 wo, murk_vec3 wi)
{
    const murk_phase *ph = &m->data->density->phase;
    return ph->vt ? ph->vt->eval(ph->self, wo, wi) : murk_hg_eval(m->data->g, wo, wi);
}

float murk_media_phase_sample(const murk_medium *m, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    const murk_phase *ph = &m->data->density->phase;
    if (ph->vt)
        return ph->vt->sample(ph->self, wo, u, wi, pdf);
    *wi = murk_hg_sample(m->data->g, wo, u, pdf);
    return *pdf;
}

/* Exported for libmurklab: murk check calls a phase plugin through it (lab/check/check.c). */
MURK_API const murk_phase *murk_media_phase(const murk_medium *m) { return &m->data->density->phase; }

murk_rgb murk_media_albedo(const murk_density *d, murk_vec3 p)
{
    murk_thread_counters()[d->slot].lookups++;
    return murk_fields_albedo(&d->fields, p);
}

murk_rgb murk_media_emission(const murk_density *d, murk_vec3 p)
{
    murk_thread_counters()[d->slot].lookups++;
    return murk_fields_emission(&d->fields, p);
}

/* ---- scene loading ------------------------------------------------------------------------- */

murk_field *murk_media_scalar_field(const murk_scene *s, const murk_ynode *d, const char *what, char *err,
                                    size_t errlen)
{
    return murk_field_from_node(s->doc.file, d, what, err, errlen);
}

/* The keys every medium has, whatever its tracker: read by the core with the same schema reader as a
 * plugin's parameters, and listed with them by `murk plugins TRACKER`. `density` and `transmittance`
 * (maps or names) are read separately (murk_medium_special_keys). */
enum { K_SIGMA_A, K_SIGMA_S, K_SCALE, K_G, K_MAJORANT_FACTOR, K_MAJORANT_RESOLUTION, K_MAJORANT_REPAIR,
       K_STRATIFY_FLIGHTS, K_TEMPERATURE_SCALE, K_TEMPERATURE_OFFSET, K_COUNT };
MURK_API const murk_param murk_medium_core_params[MURK_MEDIUM_NCORE] = {
    [K_SIGMA_A] = {"sigma_a", MURK_PARAM_RGB, 0, {0, 0, 0}, NULL, NULL, 0, 1e8, "absorption per unit density"},
    [K_SIGMA_S] = {"sigma_s", MURK_PARAM_RGB, 0, {1, 1, 1}, NULL, NULL, 0, 1e8, "scattering per unit density"},
    [K_SCALE] = {"scale", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 1e8, "multiplies sigma_a and sigma_s"},
    [K_G] = {"g", MURK_PARAM_FLOAT, 0, {0, 0, 0}, NULL, NULL, -0.99, 0.99,
             "Henyey-Greenstein asymmetry of the default phase function; an error beside a phase: block (give hg's g "
             "there)"},
    [K_MAJORANT_FACTOR] = {"majorant_factor", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 1e-3, 1e3,
                           "multiplies the majorant grid; < 1 no longer bounds (repaired, see majorant_repair)"},
    [K_MAJORANT_RESOLUTION] = {"majorant_resolution", MURK_PARAM_INT, 0, {16, 0, 0}, NULL, NULL, 1, 256,
                               "majorant/minorant grid cells along the field box's longest axis"},
    [K_MAJORANT_REPAIR] = {"majorant_repair", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                           "raise majorant cells that majorant_factor < 1 left below the density to their exact bound "
                           "before rendering; false: trackers repair per flight (unbiased, noisier)"},
    [K_STRATIFY_FLIGHTS] = {"stratify_flights", MURK_PARAM_BOOL, 0, {1, 0, 0}, NULL, NULL, 0, 1,
                            "a free flight's first distance and collision choice from the sampler (stratified over "
                            "a pixel's samples with render.sampler: sobol); false: all from the PCG stream"},
    [K_TEMPERATURE_SCALE] = {"temperature_scale", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 1e6,
                             "kelvin per unit of the temperature field: T = (value - temperature_offset) x "
                             "temperature_scale"},
    [K_TEMPERATURE_OFFSET] = {"temperature_offset", MURK_PARAM_FLOAT, 0, {0, 0, 0}, NULL, NULL, -1e6, 1e6,
                              "subtracted from the temperature field's values before temperature_scale; "
                              "temperatures at or below 0 K emit nothing"},
};
MURK_API const char *const murk_medium_special_keys[MURK_MEDIUM_NSPECIAL] = {"density", "transmittance", "phase",
                                                                            "albedo", "emission", "temperature"};

/* Keys of the block that the core's schema does not read: "type", the special keys and the tracker's
 * own parameters. */
static size_t skip_keys(const murk_plugin_desc *d, const char **out, size_t cap)
{
    size_t n = 0;
    out[n++] = "type";
    for (size_t i = 0; i < MURK_MEDIUM_NSPECIAL; i++)
        out[n++] = murk_medium_special_keys[i];
    for (uint32_t i = 0; d && i < d->nparams && n < cap; i++)
        out[n++] = d->params[i].name;
    return n;
}

/* `transmittance: NAME` or `transmittance: { type: NAME, key: value, ... }`: the medium's estimator plugin,
 * its parameters checked against its schema like a tracker's, created on the medium's data. */
static int load_estimator(murk_scene *s, const murk_host *host, const char *name, const murk_ynode *n,
                          murk_named_medium *nm, char *err, size_t errlen)
{
    static const char *const skip[] = {"type"};
    const murk_ynode *t = n->kind == MURK_Y_MAP ? murk_ymap_get(n, "type") : n;
    if (!t || t->kind != MURK_Y_SCALAR || !*t->str)
        return murk_yerr(err, errlen, t ? t : n, "medium '%s': transmittance must be an estimator's name or "
                         "{ type: NAME, ... } (murk plugins lists the transmittance kind)", name);
    char block[256], who[256];
    snprintf(block, sizeof block, "medium '%s': transmittance", name);
    snprintf(who, sizeof who, "medium '%s' transmittance (%s)", name, t->str);
    const murk_plugin *p;
    if (murk_scene_instantiate(s, host, MURK_KIND_TRANSMITTANCE, t, t->str, n, block, who, skip, n->kind == MURK_Y_MAP,
                               &nm->data, &p, &nm->m.tr_self, err, errlen))
        return -1;
    nm->m.tr_vt = p->desc->vtable;
    nm->tr_plugin = p;
    return 0;
}

/* `phase: NAME` or `phase: { type: NAME, key: value, ... }`: the medium's phase-function plugin (murk/phase.h),
 * its parameters checked against its schema. */
static int load_phase(murk_scene *s, const murk_host *host, const char *name, const murk_ynode *n, murk_phase *ph,
                      char *err, size_t errlen)
{
    static const char *const skip[] = {"type"};
    const murk_ynode *t = n->kind == MURK_Y_MAP ? murk_ymap_get(n, "type") : n;
    if (!t || t->kind != MURK_Y_SCALAR || !*t->str)
        return murk_yerr(err, errlen, t ? t : n, "medium '%s': phase must be a phase function's name or "
                         "{ type: NAME, ... } (murk plugins lists the phase kind: hg, isotropic, draine, hg_draine, "
                         "rayleigh)", name);
    char block[256], who[256];
    snprintf(block, sizeof block, "medium '%s': phase", name);
    snprintf(who, sizeof who, "medium '%s' phase (%s)", name, t->str);
    const murk_plugin *p;
    if (murk_scene_instantiate(s, host, MURK_KIND_PHASE, t, t->str, n, block, who, skip, n->kind == MURK_Y_MAP, NULL,
                               &p, &ph->self, err, errlen))
        return -1;
    ph->vt = p->desc->vtable;
    return 0;
}

/* The medium's phase function and fields beside density, after its core keys (core[]). */
static int load_extras(murk_scene *s, const murk_host *host, const char *name, const char *who, const murk_ynode *m,
                       const murk_value *core, murk_named_medium *nm, char *err, size_t errlen)
{
    const murk_ynode *pn = murk_ymap_get(m, "phase");
    if (pn && core[K_G].set) {
        const murk_ynode *gn = murk_ymap_get(m, "g");
        return murk_yerr(err, errlen, gn ? gn : pn, "%s: 'g' beside a phase: block (the phase function's own "
                         "parameters say it: phase: { type: hg, g: ... })", who);
    }
    if (pn && load_phase(s, host, name, pn, &nm->density->phase, err, errlen))
        return -1;
    int t_set = core[K_TEMPERATURE_SCALE].set || core[K_TEMPERATURE_OFFSET].set;
    return murk_fields_load(s, m, who, core[K_TEMPERATURE_SCALE].f[0], core[K_TEMPERATURE_OFFSET].f[0], t_set,
                            &nm->density->fields, &nm->data, err, errlen);
}

/* A tracker built before ABI 1.9 knows nothing of albedo or emission fields: it would render the medium
 * without them. */
static int check_tracker_fields(const murk_plugin *p, const murk_medium_data *md, const murk_ynode *m,
                                const char *who, char *err, size_t errlen)
{
    if (!md->fields || p->abi.minor >= MURK_ABI_MINOR_FIELDS)
        return 0;
    const murk_ynode *at = murk_ymap_get(m, md->fields & MURK_FIELD_ALBEDO ? "albedo" : "emission");
    if (!at)
        at = murk_ymap_get(m, "temperature");
    return murk_yerr(err, errlen, at ? at : m, "%s: tracker '%s' was built for plugin ABI %u.%u, before albedo and "
                     "emission fields (1.%d), and would ignore them; rebuild it, or use one of murk's trackers", who,
                     p->desc->name, p->abi.major, p->abi.minor, MURK_ABI_MINOR_FIELDS);
}

static int load_medium(murk_scene *s, const murk_host *host, const char *name, const murk_ynode *m,
                       murk_named_medium *nm, char *err, size_t errlen)
{
    char block[256], who[256];
    snprintf(block, sizeof block, "medium '%s'", name);
    if (m->kind != MURK_Y_MAP)
        return murk_yerr(err, errlen, m, "%s must be a map of keys", block);
    const murk_ynode *t = murk_ymap_get(m, "type");
    if (!t)
        return murk_yerr(err, errlen, m, "%s is missing the required key 'type' (a tracker: delta, decomposition, "
                                         "spectral, spectral_mis, naive_spectral)", block);
    if (t->kind != MURK_Y_SCALAR)
        return murk_yerr(err, errlen, t, "%s: type must be a plugin name", block);
    snprintf(who, sizeof who, "medium '%s' (%s)", name, t->str);
    /* the core's keys first (the tracker's own keys are skipped here and read by murk_scene_instantiate) */
    char lerr[1024];
    const murk_plugin *tp = murk_registry_load(&s->reg, MURK_KIND_MEDIUM, t->str, lerr, sizeof lerr);
    if (!tp)
        return murk_yerr(err, errlen, t, "%s: %s", block, lerr);
    const char *skip[128];
    size_t nskip = skip_keys(tp->desc, skip, 128);
    /* the core's schema under the tracker's name, so that messages point to `murk plugins TRACKER` */
    const murk_plugin_desc core_desc = {sizeof(murk_plugin_desc), MURK_KIND_MEDIUM, tp->desc->name, "the core's keys",
                                        murk_medium_core_params, MURK_MEDIUM_NCORE, NULL, NULL};
    murk_value core[MURK_MEDIUM_NCORE];
    if (murk_scene_read_plugin_params(s, &core_desc, m, who, skip, nskip, 0, core, err, errlen))
        return -1;
    murk_medium_data *md = &nm->data;
    md->size = sizeof *md;
    float scale = (float)core[K_SCALE].f[0];
    md->sigma_a = murk_rgb_scale(murk_rgb3((float)core[K_SIGMA_A].f[0], (float)core[K_SIGMA_A].f[1],
                                           (float)core[K_SIGMA_A].f[2]), scale);
    md->sigma_s = murk_rgb_scale(murk_rgb3((float)core[K_SIGMA_S].f[0], (float)core[K_SIGMA_S].f[1],
                                           (float)core[K_SIGMA_S].f[2]), scale);
    md->g = (float)core[K_G].f[0];
    md->stratify_flights = core[K_STRATIFY_FLIGHTS].f[0] != 0.0;
    double mf = core[K_MAJORANT_FACTOR].f[0];
    const murk_ynode *dn = murk_ymap_get(m, "density");
    nm->density = murk_xmalloc(sizeof *nm->density);
    nm->density->slot = murk_counter_slot(s->nmedia);
    nm->density->field = dn ? murk_media_scalar_field(s, dn, "density", err, errlen) : murk_field_constant(1.0f);
    if (!nm->density->field)
        return -1;
    murk_field_info fi;
    murk_field_describe(nm->density->field, &fi);
    nm->density->transformed = fi.transformed;
    if (murk_bound_grid_build(nm->density->field, (int)core[K_MAJORANT_RESOLUTION].f[0], &nm->density->grid) != 0)
        return murk_yerr(err, errlen, dn ? dn : m, "%s: cannot build the majorant grid (out of memory)", who);
    /* The deterministic majorant repair (docs/stability.md). Each bound-grid cell holds the exact maximum of
     * the interpolated field over it (density.h), attained at a voxel, so a factor < 1 leaves every cell
     * with density below it somewhere: the repair gives each such cell its exact bound back, which is
     * the factor 1. It happens before rendering and depends on the scene only, so the image stays a pure
     * function of (scene, seed, spp). Without it the trackers repair per flight (murk/tracking.h). */
    int repair = core[K_MAJORANT_REPAIR].f[0] != 0.0;
    nm->density->factor = (float)(repair && mf < 1.0 ? 1.0 : mf);
    md->density = nm->density;
    md->name = nm->name = murk_strdup(name);
    if (load_extras(s, host, name, who, m, core, nm, err, errlen))
        return -1;
    if (mf < 1.0) {
        const murk_bound_grid *g = &nm->density->grid;
        size_t n = (size_t)g->res[0] * (size_t)g->res[1] * (size_t)g->res[2], bad = 0;
        for (size_t i = 0; i < n; i++)
            bad += g->maj[i] > 0.0f;
        if (repair)
            murk_log(MURK_LOG_WARN,
                     "%s: majorant_factor %g < 1 leaves %zu of %zu majorant cells below the density; murk raised "
                     "them to their exact bound before rendering (as majorant_factor 1: no bias, no extra noise, "
                     "the time of a bounding majorant; majorant_repair: false keeps the factor)", who, mf, bad, n);
        else
            murk_log(MURK_LOG_WARN,
                     "%s: majorant_factor %g < 1 with majorant_repair: false: %zu of %zu majorant cells do not bound "
                     "the density; trackers weight each violating collision and raise that flight's majorant "
                     "(unbiased; noisier than majorant_repair: true)", who, mf, bad, n);
    }
    float st = murk_rgb_max(murk_rgb_add(md->sigma_a, md->sigma_s)), sm = fmaxf(1e-30f, st);
    float mn = fminf(md->sigma_a.c[0] + md->sigma_s.c[0], fminf(md->sigma_a.c[1] + md->sigma_s.c[1], md->sigma_a.c[2] + md->sigma_s.c[2]));
    if (st > 0 && mn / sm < 1e-2f)
        murk_log(MURK_LOG_INFO, "%s: extinction varies %.0f:1 across channels (strongly chromatic)", who,
                 mn > 0 ? sm / mn : INFINITY);

    /* then the tracker, with the core's keys skipped */
    nskip = 0;
    skip[nskip++] = "type";
    for (size_t i = 0; i < MURK_MEDIUM_NSPECIAL; i++)
        skip[nskip++] = murk_medium_special_keys[i];
    for (size_t i = 0; i < MURK_MEDIUM_NCORE; i++)
        skip[nskip++] = murk_medium_core_params[i].name;
    const murk_plugin *p;
    if (murk_scene_instantiate(s, host, MURK_KIND_MEDIUM, t, t->str, m, block, who, skip, nskip, md, &p, &nm->m.self,
                               err, errlen) ||
        check_tracker_fields(p, md, m, who, err, errlen))
        return -1;
    nm->m.vt = p->desc->vtable;
    nm->m.name = nm->name;
    nm->m.data = md;
    nm->plugin = p;
    const murk_ynode *tn = murk_ymap_get(m, "transmittance");
    return tn ? load_estimator(s, host, name, tn, nm, err, errlen) : 0;
}

static void medium_free(murk_named_medium *nm)
{
    if (nm->m.vt && nm->m.self)
        nm->m.vt->destroy(nm->m.self);
    if (nm->m.tr_vt && nm->m.tr_self)
        nm->m.tr_vt->destroy(nm->m.tr_self);
    if (nm->density) {
        if (nm->density->phase.vt)
            nm->density->phase.vt->destroy(nm->density->phase.self);
        murk_fields_free(&nm->density->fields);
        murk_field_free(nm->density->field);
        murk_bound_grid_free(&nm->density->grid);
        free(nm->density);
    }
    free(nm->name);
}

int murk_media_load(murk_scene *s, const murk_host *host, const murk_ynode *n, char *err, size_t errlen)
{
    if (n->kind != MURK_Y_MAP)
        return murk_yerr(err, errlen, n, "media must be a map of NAME: { type: TRACKER, ... }");
    s->media = murk_xmalloc((n->n ? n->n : 1) * sizeof *s->media);
    for (size_t i = 0; i < n->n; i++) {
        murk_named_medium *nm = &s->media[i];
        if (load_medium(s, host, n->keys[i], n->items[i], nm, err, errlen) != 0) {
            medium_free(nm);
            memset(nm, 0, sizeof *nm);
            return -1;
        }
        murk_media_count_medium(&nm->m, nm->density->slot);
        s->nmedia++;
    }
    return 0;
}

int murk_media_bind_integrator(murk_scene *s, const murk_ynode *media_node, const char *integrator, uint32_t minor,
                               char *err, size_t errlen)
{
    for (size_t i = 0; i < s->nmedia; i++) {
        murk_medium_data *md = &s->media[i].data;
        md->integrator_minor = minor;
        if (!(md->fields & MURK_FIELD_EMISSION) || minor >= MURK_ABI_MINOR_FIELDS)
            continue;
        const murk_ynode *m = media_node ? murk_ymap_get(media_node, s->media[i].name) : NULL, *at = NULL;
        if (m && !(at = murk_ymap_get(m, "emission")))
            at = murk_ymap_get(m, "temperature");
        murk_ynode here = {.file = s->doc.file, .line = 0, .col = 0};
        return murk_yerr(err, errlen, at ? at : m ? m : &here, "medium '%s' emits, and integrator '%s' was built for "
                         "plugin ABI 1.%u, before volume emission (1.%d): it would not collect it; rebuild it, or use "
                         "volpath or volpath_nee", s->media[i].name, integrator, minor, MURK_ABI_MINOR_FIELDS);
    }
    return 0;
}

void murk_media_free(murk_scene *s)
{
    for (size_t i = 0; i < s->nmedia; i++)
        medium_free(&s->media[i]);
    free(s->media);
    s->media = NULL;
    s->nmedia = 0;
}

/* ---- what float arithmetic can carry ------------------------------------------------------- */

int murk_media_check_depth(const murk_scene *s, const murk_ynode *media_node, murk_vec3 scene_lo, murk_vec3 scene_hi,
                           char *err, size_t errlen)
{
    for (size_t i = 0; i < s->nmedia; i++) {
        const murk_named_medium *nm = &s->media[i];
        if (!nm->density || !nm->density->field)
            continue;
        murk_vec3 lo, hi;
        int inf = 0;
        murk_field_bounds(nm->density->field, &lo, &hi, &inf);
        const char *over = "its density box";
        if (inf) { /* a constant density reaches as far as the scene does */
            lo = scene_lo;
            hi = scene_hi;
            over = "the scene";
        }
        double ext = 0.0;
        for (int a = 0; a < 3; a++) {
            double e = (double)murk_v3_get(hi, a) - (double)murk_v3_get(lo, a);
            ext += e > 0.0 ? e * e : 0.0;
        }
        ext = sqrt(ext);
        double st = 0.0;
        for (int k = 0; k < 3; k++)
            st = fmax(st, (double)nm->data.sigma_a.c[k] + (double)nm->data.sigma_s.c[k]);
        double dmax = (double)murk_field_max(nm->density->field) * (double)nm->density->factor;
        double depth = st * dmax * ext;
        if (!(depth <= MURK_MAX_OPTICAL_DEPTH)) {
            const murk_ynode *m = media_node ? murk_ymap_get(media_node, nm->name) : NULL, *at = NULL;
            static const char *const keys[] = {"scale", "sigma_s", "sigma_a", "density"};
            for (int k = 0; m && !at && k < 4; k++)
                at = murk_ymap_get(m, keys[k]);
            murk_ynode here = {.file = s->doc.file, .line = 0, .col = 0};
            return murk_yerr(err, errlen, at ? at : m ? m : &here,
                             "medium '%s': optical depth %.3g across %s (extinction %.3g per unit density x max "
                             "density %.3g x extent %.3g) exceeds %g, the most float arithmetic can track "
                             "(free flights would fall below the spacing of floats and stop advancing); lower "
                             "sigma_a, sigma_s or scale", nm->name, depth, over, st, dmax, ext, MURK_MAX_OPTICAL_DEPTH);
        }
    }
    return 0;
}
