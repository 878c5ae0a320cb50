/* pathtracer.c — the path tracer shared by the path, volpath and volpath_nee plugins (see
 * pathtracer.h for what it computes). One function per kind of event along a path:
 *
 *   medium_vertex()    a free flight through the current medium (the tracker's sample()) and, if it
 *                      scatters, next-event estimation and phase-function sampling there;
 *   surface_vertex()   emission found at a surface (MIS-weighted against light sampling), then
 *                      next-event estimation and BSDF sampling;
 *   cross_boundary()   an index-matched boundary: change medium, go straight on;
 *   sample_light()     next-event estimation from any scattering vertex, through murk_pt_shadow();
 *   roulette()         Russian roulette.
 *
 * The functions with external linkage are hidden in the plugin (only the entry symbols are exported). */
#include "pathtracer.h"
#ifdef MURK_PT_TAP
#include "pathtracer_tap.h"
#endif

#include <math.h>
#include <stdio.h>

#include "murk/material.h"
#include "murk/tracking.h"

/* Each parameter's only description (murk plugins NAME prints it; docs/plugins.md is generated from it). */
#define PT_SHARED_PARAMS \
    [MURK_PT_MAX_DEPTH] = {"max_depth", MURK_PARAM_INT, 0, {64, 0, 0}, NULL, NULL, 1, 100000, \
                           "the most scattering events (surface bounces and, in volpath and volpath_nee, medium " \
                           "scattering) a path may take; light found after the last one still counts, so 1 is " \
                           "direct light only"}, \
    [MURK_PT_RR_DEPTH] = {"rr_depth", MURK_PARAM_INT, 0, {3, 0, 0}, NULL, NULL, 0, 100000, \
                          "scattering events before Russian roulette may end a path; survivors are divided by " \
                          "their survival probability, so roulette adds noise but no bias"}, \
    [MURK_PT_LIGHT_SAMPLING] = {"light_sampling", MURK_PARAM_ENUM, 0, {0, 0, 0}, "area", "area|solid_angle", 0, 0, \
                                "how next-event estimation picks a point on a light: area, every emitting " \
                                "triangle uniformly by area (a rectangular quad or box face as its whole " \
                                "rectangle); solid_angle, a rectangular quad or box face uniformly in the solid " \
                                "angle it subtends (Urena et al. 2013; tiny ones and other shapes by area). " \
                                "solid_angle is far less noisy for points close to a light but costs more per " \
                                "sample, and at equal time it was at best even with area (docs/results.md, " \
                                "\"Light sampling\"), so area is the default. Both render the same image " \
                                "(tests/test_lights.c)"}, \
    [MURK_PT_RR_THRESHOLD] = {"rr_threshold", MURK_PARAM_FLOAT, 0, {0.3, 0, 0}, NULL, NULL, 0.001, 1, \
                              "Russian roulette keeps a path with probability min(1, weight / rr_threshold), at " \
                              "least 0.05: 1 plays with every path whose weight fell below 1, 0.1 (Tungsten's " \
                              "rule) only with the paths below a tenth: longer paths and less noise per sample. " \
                              "0.3 gave the best efficiency of the three on the Cornell box, a constant " \
                              "chromatic medium and a cloud (docs/results.md, \"Russian roulette's threshold\")"},

const murk_param murk_pt_params[MURK_PT_NPARAMS] = {PT_SHARED_PARAMS};
const murk_param murk_pt_nee_params[MURK_PT_NEE_NPARAMS] = {
    PT_SHARED_PARAMS
    [MURK_PT_EQUIANGULAR] = {"equiangular", MURK_PARAM_BOOL, 0, {0, 0, 0}, NULL, NULL, 0, 1,
                             "also sample each medium segment equiangularly (Kulla and Fajardo 2012) towards a "
                             "reference point on a light (a point or spot light's position; a reference light at "
                             "infinity, a distant light or the environment, has no point: that segment has free "
                             "flights alone), and combine that vertex's NEE with the free flight's "
                             "by MIS (the balance heuristic; a per-segment exponential stands in for the free "
                             "flight's pdf, exact in a grey homogeneous medium and an approximation elsewhere, "
                             "which changes the noise, never the image). Free flights are untouched. It pays off "
                             "where single scattering of a light dominates and free flights rarely scatter near "
                             "it (a lamp in or beside thin fog: scenes/fog_lamp.yaml); it costs more per sample, "
                             "is about even in an optically thin-to-moderate medium and loses in a dense cloud "
                             "(docs/results.md, \"Equiangular sampling\"), so it is off by default"},
    [MURK_PT_NEE_MIS] = {"nee_mis", MURK_PARAM_ENUM, 0, {0, 0, 0}, "solid_angle", "solid_angle|null_scattering", 0, 0,
                         "how a light sample and the emission that phase or BSDF sampling finds are weighted against "
                         "each other: solid_angle, the power heuristic on the two directions' solid-angle pdfs "
                         "(transmittance ignored); null_scattering, the path-level MIS of Miller, Georgiev and "
                         "Jarosz 2019 (sec. 5): the balance heuristic over both strategies and the three channels' "
                         "techniques, each pdf including the probability that free flights pass the null "
                         "collisions between the vertex and the light (shadow rays ratio-track at the free flights' "
                         "majorant to know it), so that light sampling takes over where a medium is dense and "
                         "chromatic. null_scattering needs trackers that report null probabilities (spectral_mis; "
                         "without closed_form) and excludes equiangular"},
};

/* The plugin's name, for the watchdog's reports. */
static const char *pt_name(const murk_pt *pt)
{
    return pt->media ? (pt->nee ? "volpath_nee" : "volpath") : "path";
}

/* The watchdog (murk/plugin.h): every loop of li() is bounded — depth by max_depth, boundary crossings
 * by 1000 per path, shadow-ray segments by 256 — and a path that reaches a bound is ended and reported. */
static int stuck(const murk_pt *pt)
{
    pt->host->warn_once("integrator '%s': a path crossed more than 1000 surfaces or boundaries without "
                        "scattering (stuck?); it was ended (biased)", pt_name(pt));
    return 0;
}

int murk_pt_create(const murk_host *host, const murk_value *params, int nee, int media, void **self, char *err,
                   size_t errlen)
{
    if (host->size < sizeof(murk_host)) {
        snprintf(err, errlen, "this murk's host table lacks the media services");
        return -1;
    }
    murk_pt *pt = host->alloc(sizeof *pt);
    if (!pt) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    pt->host = host;
    pt->max_depth = (int)params[MURK_PT_MAX_DEPTH].f[0];
    pt->rr_depth = (int)params[MURK_PT_RR_DEPTH].f[0];
    pt->light_strategy = params[MURK_PT_LIGHT_SAMPLING].choice == 1 ? MURK_LIGHT_SOLID_ANGLE : MURK_LIGHT_AREA;
    pt->rr_threshold = (float)params[MURK_PT_RR_THRESHOLD].f[0];
    pt->nee = nee;
    pt->media = media;
    pt->equiangular = nee && media && params[MURK_PT_EQUIANGULAR].f[0] != 0.0;
    pt->nee_mis = nee && media && params[MURK_PT_NEE_MIS].choice == 1;
    if (pt->nee_mis && pt->equiangular) {
        snprintf(err, errlen, "nee_mis: null_scattering and equiangular cannot be combined (equiangular's "
                 "vertices have no null-collision pdf)");
        host->free(pt);
        return -1;
    }
    *self = pt;
    return 0;
}

void murk_pt_destroy(void *self)
{
    murk_pt *pt = self;
    if (pt)
        pt->host->free(pt);
}

/* The sampler's slots (murk/math.h), in this order in every sample: 0 the camera jitter (the core),
 * 1 the hero channel, then per scattering event d = 0, 1, ... (a surface or a medium vertex) five
 * slots from PT_SLOT(d, 0): the light choice (1-D) and the point on the light of NEE, the
 * BSDF / phase direction (2-D), the BSDF's lobe choice (1-D, u[2] of a material's sample()) and the
 * Russian roulette after the event (1-D). The point on the light takes its slot's place but is drawn as
 * the partner (murk_sample_2d_with: Sobol dimensions 2 and 3) of the draw that placed the vertex: the
 * camera jitter or the last event's direction for a surface, the free flight's slot for a medium vertex,
 * the distance for an equiangular one. Trackers and transmittance estimators take their numbers
 * from the PCG stream (murk_rng_float), outside the slots. */
enum { PT_SLOT_HERO = 1 };
/* With equiangular sampling, each medium segment's own slots, apart from the events' (slots are hashed:
 * any unique number will do): k = 0 the light choice and 1 the point (2-D) of its reference point, 2 the
 * distance, 3 the light choice and 4 the point (2-D) of the NEE at the equiangular vertex. */
#define PT_SLOT_EQUIANGULAR(depth, crossings, k) \
    (0x40000000u + ((uint32_t)(depth) * 1024u + ((uint32_t)(crossings) & 1023u)) * 8u + (uint32_t)(k))
enum { PT_SLOT_LIGHT_CHOICE, PT_SLOT_LIGHT_POINT, PT_SLOT_DIRECTION, PT_SLOT_LOBE, PT_SLOT_ROULETTE,
       PT_SLOTS_PER_EVENT };
#define PT_SLOT(depth, which) (2u + (uint32_t)(depth) * PT_SLOTS_PER_EVENT + (uint32_t)(which))
/* A free flight's own slot, sought before the tracker's sample(): a medium with stratify_flights takes the
 * flight's first numbers there (a 2-D point: the first distance and choice; murk/tracking.h); trackers
 * draw the rest, and transmittance estimators all, from the PCG stream. depth scattering events and `crossings` boundary
 * crossings so far name the path's segment; padding slots are hashed, so any unused number serves. */
#define PT_SLOT_FLIGHT(depth, crossings) (0x20000000u + (uint32_t)(depth) * 1024u + ((uint32_t)(crossings) & 1023u))

/* ---- small helpers ------------------------------------------------------------------------- */

/* p moved off its surface (normal n) to the side dir points to, by 1e-4 of its magnitude (at least). */
static murk_vec3 offset(murk_vec3 p, murk_vec3 n, murk_vec3 dir)
{
    float eps = 1e-4f * murk_maxf(1.0f, murk_maxabs(p));
    return murk_madd(p, n, murk_dot(n, dir) >= 0.0f ? eps : -eps);
}

static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

static float mean3(murk_rgb r) { return (r.c[0] + r.c[1] + r.c[2]) * (1.0f / 3.0f); }

static int finite3(murk_rgb c) { return isfinite(c.c[0]) && isfinite(c.c[1]) && isfinite(c.c[2]); }

/* A plugin returned NaN or infinity: say which (once per message; repeats are counted) and end the
 * path, so that one broken call costs its path, not the image. */
static int broken(const murk_host *h, const char *kind, const char *name, const char *what)
{
    h->warn_once("%s '%s' returned a non-finite %s: the path was ended there", kind, name, what);
    return 0;
}

static murk_ray ray_from(murk_vec3 o, murk_vec3 d)
{
    murk_ray r;
    r.o = o;
    r.d = d;
    r.tmin = 0.0f;
    r.tmax = INFINITY;
    return r;
}

/* ---- shadow rays --------------------------------------------------------------------------- */

/* An origin offset along a boundary's normal is off the original line from p to q: a leg that kept
 * the first direction, with a length measured along it, reaches a light parallel to the boundary
 * early and counts the light itself as an occluder. So every leg is re-aimed at q. With pnull (nee_mis:
 * null_scattering) every medium leg is ratio-tracked at the free flights' majorant and *pnull (1 on entry)
 * gathers the null-collision probabilities of its tentative collisions (murk_ratio_tracking_null). */
/* A light at infinity (inf = 1) is reached along wi itself: every leg keeps that direction and runs to
 * infinity (a medium's majorant walk ends at its density's box; a constant medium is bounded by its
 * boundary shapes). */
static murk_rgb shadow(const murk_pt *pt, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 q,
                       murk_vec3 wi, int inf, const murk_medium *m, const murk_path_ctx *ctx, murk_rng *rng,
                       murk_rgb *pnull)
{
    const murk_host *h = pt->host;
    const float end_eps = inf ? 0.0f : 1e-4f * murk_maxf(1.0f, murk_maxabs(q));
    murk_rgb T = murk_rgb1(1.0f);
    if (pnull)
        *pnull = T;
    if (!pt->media)
        m = NULL;
    murk_vec3 o = murk_dot(offset_n, offset_n) > 0.0f ? offset(p, offset_n, inf ? wi : murk_sub(q, p)) : p;
    for (int crossings = 0; crossings < 256; crossings++) {
        murk_ray r = ray_from(o, wi);
        if (!inf) {
            murk_vec3 d = murk_sub(q, o);
            float len = murk_length(d);
            if (!(len > end_eps))
                return T;
            r = ray_from(o, murk_mul(d, 1.0f / len));
            r.tmax = len - end_eps;
        }
        /* nothing at all in the way: the common case, cheaply. Except on a first leg through vacuum in a
         * scene with boundaries, where an occluder is often a boundary that intersect() below must find
         * anyway: that leg asks intersect() alone (no hit there is the occluded() answer no; one call
         * instead of two when something is in the way, a slightly dearer one when nothing is) */
        if (!m && (crossings > 0 || !h->boundaries(scene)) && !h->occluded(scene, &r))
            return T;
        if (!m && !h->boundaries(scene)) /* in the way, and without boundaries it is an occluder */
            return murk_rgb1(0.0f);
        murk_hit hit;
        int found = h->intersect(scene, &r, &hit);
        if (found && hit.material)
            return murk_rgb1(0.0f);
        if (m) {
            murk_ray seg = r;
            seg.tmax = found ? hit.t : r.tmax;
            murk_rgb Tm, Pm;
            if (pnull) {
                Tm = murk_ratio_tracking_null(h, m->data, &seg, rng, &Pm);
                *pnull = murk_rgb_mul(*pnull, Pm);
            } else {
                Tm = murk_medium_transmittance(m, &seg, ctx, rng);
            }
            if (!finite3(Tm))
                return murk_rgb1((float)broken(h, "medium", m->name, "transmittance"));
            T = murk_rgb_mul(T, Tm);
            if (murk_rgb_is_black(T))
                return T;
        }
        if (!found)
            return T;
        if (pt->media)
            m = murk_dot(r.d, hit.ng) < 0.0f ? hit.interior : hit.exterior;
        o = offset(hit.p, hit.ng, r.d);
    }
    /* a maze of boundaries: give up (never seen in a real scene); the watchdog says so (murk/plugin.h) */
    h->warn_once("integrator '%s': a shadow ray crossed more than 256 boundaries; its light was dropped (biased)",
                 pt_name(pt));
    return murk_rgb1(0.0f);
}

murk_rgb murk_pt_shadow(const murk_pt *pt, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 q,
                        const murk_medium *m, const murk_path_ctx *ctx, murk_rng *rng)
{
    return shadow(pt, scene, p, offset_n, q, murk_v3(0, 0, 0), 0, m, ctx, rng, NULL);
}

murk_rgb murk_pt_shadow_inf(const murk_pt *pt, const murk_scene *scene, murk_vec3 p, murk_vec3 offset_n, murk_vec3 wi,
                            const murk_medium *m, const murk_path_ctx *ctx, murk_rng *rng)
{
    return shadow(pt, scene, p, offset_n, p, wi, 1, m, ctx, rng, NULL);
}

/* ---- path state ---------------------------------------------------------------------------- */

typedef struct path {
    murk_rgb L, beta, R;
    murk_path_ctx ctx;
    const murk_medium *medium; /* where the ray's origin lies (NULL: vacuum) */
    murk_ray ray;
    /* the last scattering vertex, for the MIS weight of emission that BSDF / phase sampling finds */
    murk_vec3 prev_p;
    float prev_pdf;
    int prev_delta; /* 1 at the camera and after a delta lobe: no light sample competed */
    int prev_phase; /* the last scattering vertex was in a medium (for the tap: phase-found emission) */
    /* nee_mis null_scattering: R at the last scattering vertex, and the product of the hero's null-collision
     * probabilities over the free flights since it */
    murk_rgb R_vertex;
    float null_hero;
    int depth, crossings;
    float eta_scale; /* product of eta^2 over transmissions: beta * eta_scale is free of the 1 / eta^2 that
                      * radiance picks up entering a denser medium (for Russian roulette only) */
} path;

/* The slot whose draw placed the path's next surface vertex: the camera's jitter (slot 0) for the first,
 * else the direction sampled at the last scattering event (sample_light's partner for that vertex). */
static uint32_t placed_by(const path *st) { return st->depth ? PT_SLOT(st->depth - 1, PT_SLOT_DIRECTION) : 0u; }

/* L += beta * le * w / mean(R), a contribution of technique `term` (MURK_PT_TERM_*: pathtracer.h), which
 * a build with the tap reports (pathtracer_tap.h). */
static void add_light(path *st, murk_rgb le, float w, int term)
{
    murk_rgb c = murk_rgb_scale(murk_rgb_mul(st->beta, le), w / mean3(st->R));
    st->L = murk_rgb_add(st->L, c);
#ifdef MURK_PT_TAP
    murk_pt_tap(st->depth, term, c);
#else
    (void)term;
#endif
}

/* How a path ended, for the tap (nothing without it). */
#ifdef MURK_PT_TAP
#define PT_TAP_END(st, why) murk_pt_tap_end((st)->depth, (why))
#else
#define PT_TAP_END(st, why) ((void)0)
#endif

/* What a scattering vertex scatters with: a material in its shading frame (flipped to wo's side; the
 * hit the material gets has n flipped with it, so n . ng < 0 tells it wo is inside), prepared once for
 * the vertex (its textures read once for light sampling and BSDF sampling alike), or the medium's
 * phase function (mat == NULL). */
typedef struct vertex {
    murk_vec3 p, offset_n, wo; /* offset_n: the geometric normal at a surface flipped to wo's side, zero in a medium */
    const murk_material *mat;
    const murk_shading *sp; /* the material's shading point at the vertex */
    murk_vec3 t, b, n, wo_local;
    const murk_medium *medium; /* the medium whose phase function scatters (mat == NULL) */
    const murk_medium *behind; /* the medium on the far side of the surface from wo */
} vertex;

/* A scattering vertex in medium m at p: only what a medium's vertex uses is set (a surface's frame and
 * shading point stay unset; the phase function needs none of them), so no memset per scattering event. */
static void medium_point(vertex *v, murk_vec3 p, murk_vec3 wo, const murk_medium *m)
{
    v->p = p;
    v->offset_n = murk_v3(0, 0, 0);
    v->wo = wo;
    v->mat = NULL;
    v->sp = NULL;
    v->medium = m;
    v->behind = NULL;
}

/* 1 if the shading frame and the geometry agree on the side of the surface wi lies on (wo's side:
 * reflection; the other: transmission), so no light leaks through a surface because its shading normal
 * says so. */
static int vertex_side_ok(const vertex *v, murk_vec3 wi, murk_vec3 wl)
{
    float gs = murk_dot(wi, v->offset_n);
    return gs != 0.0f && (gs > 0.0f) == (wl.z > 0.0f);
}

/* f |cos| towards the world direction wi (the phase function in a medium). */
static murk_rgb vertex_f(const murk_host *h, const vertex *v, murk_vec3 wi)
{
    if (!v->mat)
        return murk_rgb1(h->medium_phase_eval(v->medium, v->wo, wi));
    murk_vec3 wl = murk_to_local(wi, v->t, v->b, v->n);
    if (!vertex_side_ok(v, wi, wl))
        return murk_rgb1(0.0f);
    return murk_rgb_scale(murk_material_eval(v->mat, v->sp, v->wo_local, wl), fabsf(wl.z));
}

/* The solid-angle pdf with which the vertex samples wi. */
static float vertex_pdf(const murk_host *h, const vertex *v, murk_vec3 wi)
{
    if (!v->mat)
        return h->medium_phase_eval(v->medium, v->wo, wi);
    return murk_material_pdf(v->mat, v->sp, v->wo_local, murk_to_local(wi, v->t, v->b, v->n));
}

static murk_rgb light_sample_value(const murk_pt *pt, const murk_scene *scene, path *st, const vertex *v,
                                   const murk_light_sample *ls, murk_rng *rng);

/* Next-event estimation from v with the numbers of slot `slot` (the light choice), the point as the
 * partner (murk_sample_2d_with) of slot `with`, the draw that placed v: so that over a pixel's samples
 * the light points stratify jointly with the vertices' positions. Its value times w is added to the
 * path as technique `term`: a light point, the transmittance to it, the power heuristic against the
 * vertex's own sampling. */
static void sample_light(const murk_pt *pt, const murk_scene *scene, path *st, const vertex *v, uint32_t slot,
                         uint32_t with, float w, int term, murk_rng *rng)
{
    float u[3];
    murk_sample_seek(rng, slot);
    u[0] = murk_sample_1d(rng);
    murk_sample_2d_with(rng, with, u + 1);
    murk_light_sample ls;
    ls.flags = 0;
    if (w > 0.0f && pt->host->sample_light_with(scene, v->p, u, pt->light_strategy, &ls))
        add_light(st, light_sample_value(pt, scene, st, v, &ls, rng), w, term);
}

/* f T Le / pdf of the light sample ls at v, weighted by the power heuristic against the vertex's own
 * sampling (zero when the light is blocked or behind). */
static murk_rgb light_sample_value(const murk_pt *pt, const murk_scene *scene, path *st, const vertex *v,
                                   const murk_light_sample *ls, murk_rng *rng)
{
    const murk_host *h = pt->host;
    murk_rgb f = vertex_f(h, v, ls->wi);
    if (!finite3(f)) {
        broken(h, "material", v->mat ? v->mat->name : "(phase)", "BSDF value");
        return murk_rgb1(0.0f);
    }
    if (murk_rgb_is_black(f))
        return f;
    /* a light behind a transmitting surface is reached through the medium on that side */
    const murk_medium *m = v->mat && murk_dot(ls->wi, v->offset_n) < 0.0f ? v->behind : st->medium;
    murk_rgb P; /* nee_mis: the shadow ray's null-collision probabilities (shadow() sets them) */
    int inf = isinf(ls->dist);
    murk_rgb T = shadow(pt, scene, v->p, v->offset_n, inf ? v->p : murk_madd(v->p, ls->wi, ls->dist),
                        inf ? ls->wi : murk_v3(0, 0, 0), inf, m, &st->ctx, rng, pt->nee_mis ? &P : NULL);
    if (murk_rgb_is_black(T))
        return T;
    if (ls->flags & MURK_LIGHT_SAMPLE_DELTA) /* no BSDF or phase sample can hit a delta light: weight 1 */
        return murk_rgb_scale(murk_rgb_mul(murk_rgb_mul(f, T), ls->le), 1.0f / ls->pdf);
    /* in a medium the pdf is the phase function's value, which f already holds: one plugin call, not two */
    float pdf = v->mat ? vertex_pdf(h, v, ls->wi) : f.c[0];
    if (!isfinite(pdf)) {
        broken(h, "material", v->mat ? v->mat->name : "(phase)", "pdf");
        return murk_rgb1(0.0f);
    }
    murk_rgb c = murk_rgb_mul(murk_rgb_mul(f, T), ls->le);
    if (pt->nee_mis) { /* the balance heuristic over {light, free flight} x channels, R and P per channel */
        murk_rgb R = st->R;
        float d = 0.0f;
        for (int k = 0; k < 3; k++)
            d += R.c[k] * (ls->pdf + pdf * P.c[k]);
        return murk_rgb_scale(c, d > 0.0f ? (R.c[0] + R.c[1] + R.c[2]) / d : 0.0f);
    }
    return murk_rgb_scale(c, power_heuristic(ls->pdf, pdf) / ls->pdf);
}

/* ---- equiangular sampling along a medium segment (Kulla and Fajardo 2012) ----------------------
 * Before a free flight over [0, tmax) through the path's medium, volpath_nee with `equiangular` draws a
 * reference point q on a light (a light sample from the segment's start, its own slots). Two strategies
 * then estimate the light scattered into the ray along the segment:
 *   free flight  the tracker's own flight; if it scatters at t, NEE there as always, weighted w_ff(t);
 *   equiangular  a distance t ~ p_eq(t) = D / ((th_b - th_a) (D^2 + (t - delta)^2)) on the part of the
 *                segment the majorant grid says can scatter, [a, b] (delta: q's foot on the ray, D its
 *                distance from the ray); there the density's sigma_s, the transmittance from the
 *                segment's start (the medium's estimator) and an NEE of its own, weighted w_eq(t) / p_eq.
 * w_eq = p_eq / (p_ff + p_eq), w_ff = 1 - w_eq, with p_ff(t) = s exp(-s (t - a)) for one extinction s per
 * segment (the mean over channels of sigma_t times the mean of the majorant grid's max and min over
 * [a, b]): the free flight's own pdf only in a grey homogeneous medium, an approximation elsewhere.
 * Unbiased all the same: given q the weights are a deterministic function of t that sums to one wherever
 * either strategy samples (all MIS needs), and both NEEs are independent of q, each an unbiased estimate
 * of the direct light at its vertex. (So q only steers where the equiangular vertex goes; the NEEs keep
 * their bounded light sampling, and a ray that passes close to q does not meet the 1 / D^2 of a light
 * point used for both.) Within each NEE the light sample is weighted against phase sampling as
 * everywhere, so free flight x light, free flight x phase and equiangular x light sum to one at every
 * distance and direction. */
typedef struct eq_segment {
    float a, b; /* where equiangular sampling samples: b > a, else nowhere (w_ff = 1) */
    float delta, D, th_a, th_b, s;
} eq_segment;

static float eq_pdf(const eq_segment *sg, float t)
{
    if (!(sg->b > sg->a) || t < sg->a || t > sg->b)
        return 0.0f;
    float x = t - sg->delta;
    return sg->D / ((sg->th_b - sg->th_a) * (sg->D * sg->D + x * x));
}

/* w_ff(t): the free flight's share of a scattering vertex at t. */
static float eq_w_ff(const eq_segment *sg, float t)
{
    float pe = eq_pdf(sg, t);
    if (!(pe > 0.0f))
        return 1.0f;
    float pf = sg->s * expf(-sg->s * (t - sg->a));
    return pf / (pf + pe);
}

/* Sets up the segment [0, tmax) of st->ray in st->medium (q, [a, b], s) and adds the equiangular
 * estimate. */
static void equiangular(const murk_pt *pt, const murk_scene *scene, path *st, float tmax, murk_rng *rng,
                        eq_segment *sg)
{
    const murk_host *h = pt->host;
    const murk_medium *m = st->medium;
    sg->a = sg->b = 0.0f;
    float u[3];
    murk_sample_seek(rng, PT_SLOT_EQUIANGULAR(st->depth, st->crossings, 0));
    u[0] = murk_sample_1d(rng);
    murk_sample_2d(rng, u + 1);
    murk_light_sample ls;
    ls.flags = 0;
    if (!h->sample_light_with(scene, st->ray.o, u, pt->light_strategy, &ls) || isinf(ls.dist))
        return; /* a light at infinity has no point to aim at: this segment has free flights alone */
    murk_vec3 q = murk_madd(st->ray.o, ls.wi, ls.dist);
    /* where the medium can scatter along the segment, and its mean density there */
    murk_majorant_walk w;
    h->walk_init(m->data->density, &st->ray, st->ray.tmin, tmax, &w);
    float ta, tb, dmax, dmin, a = INFINITY, b = 0.0f;
    double sum = 0.0, len = 0.0;
    for (long i = 0; i < MURK_WATCHDOG_ITERATIONS && h->walk_next(&w, &ta, &tb, &dmax, &dmin); i++) {
        if (!(dmax > 0.0f))
            continue;
        a = murk_minf(a, ta);
        b = murk_maxf(b, tb);
        if (isfinite(tb)) {
            sum += 0.5 * ((double)dmax + (double)dmin) * ((double)tb - (double)ta);
            len += (double)tb - (double)ta;
        } else if (len == 0.0) { /* an unbounded medium: its first cell's density */
            sum = 0.5 * ((double)dmax + (double)dmin);
            len = 1.0;
        }
    }
    if (!(b > a) || !(len > 0.0))
        return;
    murk_vec3 oq = murk_sub(q, st->ray.o);
    float delta = murk_dot(oq, st->ray.d);
    float D = murk_length(murk_sub(oq, murk_mul(st->ray.d, delta)));
    if (!(D > 1e-6f * murk_maxf(1.0f, murk_maxabs(q))))
        return; /* q on the ray's line: free flights alone */
    float th_a = atan2f(a - delta, D), th_b = isfinite(b) ? atan2f(b - delta, D) : 0.5f * MURK_PI;
    if (!(th_b > th_a))
        return;
    *sg = (eq_segment){a, b, delta, D, th_a, th_b, (float)(sum / len) * mean3(murk_rgb_add(m->data->sigma_a, m->data->sigma_s))};
    /* the equiangular vertex */
    murk_sample_seek(rng, PT_SLOT_EQUIANGULAR(st->depth, st->crossings, 2));
    float t = delta + D * tanf(th_a + murk_sample_1d(rng) * (th_b - th_a));
    float pe = eq_pdf(sg, t);
    if (!(pe > 0.0f) || !(t < tmax))
        return;
    murk_vec3 x = murk_madd(st->ray.o, st->ray.d, t);
    float dens = h->density(m->data->density, x);
    if (!(dens > 0.0f))
        return;
    murk_ray seg = st->ray;
    seg.tmax = t;
    st->ctx.beta = st->beta;
    murk_rgb T = murk_medium_transmittance(m, &seg, &st->ctx, rng);
    if (!finite3(T)) {
        broken(h, "medium", m->name, "transmittance");
        return;
    }
    if (murk_rgb_is_black(T))
        return;
    vertex v;
    medium_point(&v, x, murk_neg(st->ray.d), m);
    path at = *st; /* the path as if it had scattered at x: beta sigma_s T / p_eq, the equiangular share */
    at.beta = murk_rgb_mul(st->beta, murk_rgb_scale(murk_rgb_mul(m->data->sigma_s, T), dens));
    at.L = murk_rgb1(0.0f);
    sample_light(pt, scene, &at, &v, PT_SLOT_EQUIANGULAR(st->depth, st->crossings, 3),
                 PT_SLOT_EQUIANGULAR(st->depth, st->crossings, 2), (1.0f - eq_w_ff(sg, t)) / pe,
                 MURK_PT_TERM_EQUIANGULAR_NEE, rng);
    st->L = murk_rgb_add(st->L, at.L);
}

/* ---- events ---------------------------------------------------------------------------------- */

enum { PT_END, PT_PASSED, PT_SCATTERED };

/* A free flight through st->medium up to tmax (the next surface, or INFINITY). */
static int medium_vertex(const murk_pt *pt, const murk_scene *scene, path *st, float tmax, const eq_segment *sg,
                         murk_rng *rng)
{
    const murk_host *h = pt->host;
    const murk_medium *m = st->medium;
    murk_ray seg = st->ray;
    seg.tmax = tmax;
    murk_medium_event ev;
    ev.emitted = murk_rgb1(0.0f); /* a tracker adds an emitting medium's radiance (murk/medium.h) */
    ev.null_prob = -1.0f;
    st->ctx.beta = st->beta;
    st->ctx.pdf_ratio = st->R;
    murk_sample_seek(rng, PT_SLOT_FLIGHT(st->depth, st->crossings));
    m->vt->sample(m->self, &seg, &st->ctx, rng, &ev);
    if (!finite3(ev.weight) || !finite3(ev.pdf_ratio) || (ev.scattered && !isfinite(ev.t))) {
        broken(h, "medium", m->name, "free-flight weight");
        return PT_END;
    }
    if (!murk_rgb_is_black(ev.emitted)) { /* credited with beta and R before the flight */
        if (!finite3(ev.emitted))
            return broken(h, "medium", m->name, "emitted radiance"), PT_END;
        add_light(st, ev.emitted, 1.0f, MURK_PT_TERM_MEDIUM_EMISSION);
    }
    st->beta = murk_rgb_mul(st->beta, ev.weight);
    st->R = murk_rgb_mul(st->R, ev.pdf_ratio);
    if (murk_rgb_is_black(st->beta) || !(mean3(st->R) > 0.0f))
        return PT_TAP_END(st, MURK_PT_END_ABSORBED), PT_END;
    if (!ev.scattered) {
        if (pt->nee_mis && !(ev.null_prob >= 0.0f)) {
            h->warn_once("integrator 'volpath_nee' with nee_mis: null_scattering: the tracker of medium '%s' does not "
                         "report null-collision probabilities (use spectral_mis without closed_form); its paths were "
                         "ended (biased)", m->name);
            return PT_END;
        }
        if (pt->nee_mis)
            st->null_hero *= ev.null_prob;
        return PT_PASSED;
    }
    if (st->depth >= pt->max_depth)
        return PT_TAP_END(st, MURK_PT_END_MAX_DEPTH), PT_END;
    vertex v;
    medium_point(&v, murk_madd(st->ray.o, st->ray.d, ev.t), murk_neg(st->ray.d), m);
    if (pt->nee) /* with equiangular sampling, the free flight's share (1 without: sg->b = sg->a) */
        sample_light(pt, scene, st, &v, PT_SLOT(st->depth, PT_SLOT_LIGHT_CHOICE),
                     PT_SLOT_FLIGHT(st->depth, st->crossings), eq_w_ff(sg, ev.t), MURK_PT_TERM_MEDIUM_NEE, rng);
    float u[2], pdf;
    murk_sample_seek(rng, PT_SLOT(st->depth, PT_SLOT_DIRECTION));
    murk_sample_2d(rng, u);
    murk_vec3 wi;
    float p = h->medium_phase_sample(m, v.wo, u, &wi, &pdf);
    if (!(pdf > 0.0f))
        return PT_END;
    if (p != pdf) { /* murk's phase functions sample exactly (p / pdf = 1): beta stays */
        if (!isfinite(p) || !isfinite(pdf))
            return broken(h, "phase function of medium", m->name, "sample"), PT_END;
        st->beta = murk_rgb_scale(st->beta, p / pdf);
    }
    st->prev_p = v.p;
    st->prev_pdf = pdf;
    st->prev_delta = 0;
    st->prev_phase = 1;
    if (pt->nee_mis) {
        st->R_vertex = st->R;
        st->null_hero = 1.0f;
    }
    st->ray = ray_from(v.p, wi);
    st->depth++;
    return PT_SCATTERED;
}

/* The MIS weight of emission that phase or BSDF sampling found — an emitter's hit, or the environment
 * (light sampling's pdf of it: pl) — against light sampling from the last vertex: the power heuristic
 * on solid-angle pdfs, or (nee_mis: null_scattering) the balance
 * heuristic over both strategies and the channels' techniques, relative to the path's own: the found path's
 * pdf for channel k is R_k p_dir P_k and light sampling's R_vertex,k p_light (its null collisions ratio-
 * tracked, at probability 1), with R_k / R_vertex,k = P_k / P_hero, so the weight times 1 / mean(R) that
 * add_light applies is 1 / (mean(R) + mean(R_vertex) p_light / (p_dir P_hero)). */
static float found_weight(const murk_pt *pt, const path *st, float pl)
{
    if (!pt->nee_mis)
        return power_heuristic(st->prev_pdf, pl);
    if (!(st->null_hero > 0.0f) || !(st->prev_pdf > 0.0f))
        return 0.0f;
    float m = mean3(st->R), d = m + mean3(st->R_vertex) * pl / (st->prev_pdf * st->null_hero);
    return d > 0.0f ? m / d : 0.0f;
}

static float found_light_weight(const murk_pt *pt, const murk_scene *scene, const path *st, const murk_hit *hit)
{
    return found_weight(pt, st, pt->host->light_pdf_with(scene, st->prev_p, hit, pt->light_strategy));
}

/* Emission at a surface hit, then (below max_depth) light sampling and BSDF sampling. Returns 0 when
 * the path ends. */
static int surface_vertex(const murk_pt *pt, const murk_scene *scene, path *st, const murk_hit *hit, murk_rng *rng)
{
    const murk_host *h = pt->host;
    murk_vec3 wo = murk_neg(st->ray.d);
    murk_rgb le = murk_hit_le(hit, wo);
    if (!murk_rgb_is_black(le))
        add_light(st, le, pt->nee && !st->prev_delta ? found_light_weight(pt, scene, st, hit) : 1.0f,
                  st->depth == 0 ? MURK_PT_TERM_CAMERA_EMISSION : st->prev_phase ? MURK_PT_TERM_PHASE_EMISSION
                                                                                 : MURK_PT_TERM_BSDF_EMISSION);
    if (st->depth >= pt->max_depth)
        return PT_TAP_END(st, MURK_PT_END_MAX_DEPTH), 0;
    vertex v; /* every field is set below */
    v.p = hit->p;
    v.wo = wo;
    v.mat = hit->material;
    v.medium = NULL;
    murk_hit mh = *hit; /* the material's copy: n on wo's side */
    murk_shading sp;
    v.sp = &sp;
    v.offset_n = hit->ng;
    v.n = hit->n;
    v.behind = murk_dot(hit->ng, wo) >= 0.0f ? hit->interior : hit->exterior; /* the medium beyond the surface */
    if (murk_dot(v.offset_n, wo) < 0.0f) { /* the frame on wo's side: two-sided materials */
        v.offset_n = murk_neg(v.offset_n);
        v.n = murk_neg(v.n);
    }
    mh.n = v.n;
    murk_material_prepare(v.mat, &mh, &sp);
    murk_basis(v.n, &v.t, &v.b);
    v.wo_local = murk_to_local(wo, v.t, v.b, v.n);
    if (v.wo_local.z <= 0.0f) /* shading normal past wo: keep the material's wo.z >= 0 promise */
        v.wo_local.z = 1e-6f;
    if (pt->nee)
        sample_light(pt, scene, st, &v, PT_SLOT(st->depth, PT_SLOT_LIGHT_CHOICE), placed_by(st), 1.0f,
                     MURK_PT_TERM_SURFACE_NEE, rng);
    float u[3];
    murk_sample_seek(rng, PT_SLOT(st->depth, PT_SLOT_DIRECTION));
    murk_sample_2d(rng, u);
    u[2] = murk_sample_1d(rng); /* PT_SLOT_LOBE */
    murk_bsdf_sample bs;
    bs.eta = 1.0f; /* a material built before ABI 1.3 does not write it */
    if (!murk_material_sample(v.mat, &sp, v.wo_local, u, &bs) || !(bs.pdf > 0.0f))
        return 0;
    if (!finite3(bs.f) || !isfinite(bs.pdf) || !isfinite(bs.wi.x + bs.wi.y + bs.wi.z))
        return broken(h, "material", v.mat->name, "sample");
    murk_vec3 wi = murk_from_local(bs.wi, v.t, v.b, v.n);
    if (!vertex_side_ok(&v, wi, bs.wi))
        return 0;
    if (murk_dot(wi, v.offset_n) < 0.0f) { /* transmitted: into the medium behind the surface */
        if (++st->crossings > 1000)
            return stuck(pt);
        if (pt->media)
            st->medium = v.behind;
        if (bs.eta > 0.0f && isfinite(bs.eta))
            st->eta_scale *= bs.eta * bs.eta;
    }
    st->beta = murk_rgb_mul(st->beta, murk_rgb_scale(bs.f, fabsf(bs.wi.z) / bs.pdf));
    st->prev_p = hit->p;
    st->prev_pdf = bs.pdf;
    st->prev_delta = bs.delta;
    st->prev_phase = 0;
    if (pt->nee_mis) {
        st->R_vertex = st->R;
        st->null_hero = 1.0f;
    }
    st->ray = ray_from(offset(hit->p, v.offset_n, wi), wi);
    st->depth++;
    return 1;
}

/* The MIS weight of the environment that a BSDF / phase sample of pdf st->prev_pdf found, against the
 * light sampling that could have picked that direction (1 where none could: a constant background). */
static float escaped_weight(const murk_pt *pt, const murk_scene *scene, const path *st)
{
    if (!pt->nee || st->prev_delta)
        return 1.0f;
    float pe = pt->host->environment_pdf(scene, st->ray.d);
    return pe > 0.0f ? found_weight(pt, st, pe) : 1.0f;
}

/* An index-matched boundary: the medium on the far side, the same direction. */
static int cross_boundary(const murk_pt *pt, path *st, const murk_hit *hit)
{
    if (++st->crossings > 1000)
        return stuck(pt);
    if (pt->media)
        st->medium = murk_dot(st->ray.d, hit->ng) < 0.0f ? hit->interior : hit->exterior;
    st->ray = ray_from(offset(hit->p, hit->ng, st->ray.d), st->ray.d);
    return 1;
}

/* After rr_depth events a path survives with probability q = max_c |beta_c| eta_scale / mean(R) /
 * rr_threshold (at least 0.05, at most 1) and is divided by it (eta_scale: a path inside glass is not
 * culled for the 1 / eta^2 its radiance weight carries there). rr_threshold 1 plays roulette with every
 * path whose weight fell below 1; 0.1 (Tungsten's rule) only with the paths below a tenth; the default, 0.3,
 * with those below 0.3. Returns 0 when the path ends. */
static int roulette(const murk_pt *pt, path *st, murk_rng *rng)
{
    if (st->depth > pt->rr_depth) {
        murk_rgb b = st->beta;
        float q = murk_maxf(fabsf(b.c[0]), murk_maxf(fabsf(b.c[1]), fabsf(b.c[2]))) * st->eta_scale / mean3(st->R);
        if (pt->rr_threshold > 0.0f)
            q /= pt->rr_threshold;
        q = murk_maxf(0.05f, murk_minf(1.0f, q));
        murk_sample_seek(rng, PT_SLOT(st->depth - 1, PT_SLOT_ROULETTE)); /* depth was counted up at the vertex */
        if (murk_sample_1d(rng) >= q)
            return PT_TAP_END(st, MURK_PT_END_ROULETTE), 0;
        st->beta = murk_rgb_scale(st->beta, 1.0f / q);
    }
    return !murk_rgb_is_black(st->beta);
}

murk_rgb murk_pt_li(const void *self, const murk_scene *scene, const murk_ray *ray, murk_rng *rng)
{
    const murk_pt *pt = self;
    const murk_host *h = pt->host;
    path st = {0};
    st.beta = st.R = murk_rgb1(1.0f);
    st.eta_scale = 1.0f;
    murk_sample_seek(rng, PT_SLOT_HERO);
    st.ctx.hero = (int)(murk_sample_1d(rng) * 3.0f);
    if (st.ctx.hero > 2)
        st.ctx.hero = 2;
    st.medium = pt->media ? h->camera_medium(scene) : NULL;
    st.ray = *ray;
    st.prev_p = ray->o;
    st.prev_delta = 1;
    st.R_vertex = st.R;
    st.null_hero = 1.0f;
    st.ctx.flags = pt->nee_mis ? MURK_CTX_NULL_PROB : 0u;
    for (;;) {
        murk_hit hit;
        int found = h->intersect(scene, &st.ray, &hit);
        if (st.medium) {
            eq_segment sg = {0};
            if (pt->equiangular && st.depth < pt->max_depth)
                equiangular(pt, scene, &st, found ? hit.t : INFINITY, rng, &sg);
            int ev = medium_vertex(pt, scene, &st, found ? hit.t : INFINITY, &sg, rng);
            if (ev == PT_END)
                break;
            if (ev == PT_SCATTERED) {
                if (!roulette(pt, &st, rng))
                    break;
                continue;
            }
        }
        if (!found) {
            add_light(&st, h->background(scene, st.ray.d), escaped_weight(pt, scene, &st), MURK_PT_TERM_BACKGROUND);
            PT_TAP_END(&st, MURK_PT_END_ESCAPED);
            break;
        }
        if (!hit.material) {
            if (!cross_boundary(pt, &st, &hit))
                break;
            continue;
        }
        if (!surface_vertex(pt, scene, &st, &hit, rng) || !roulette(pt, &st, rng))
            break;
    }
    return st.L;
}
