/* lights.c — emissive shapes as lights: one light per emitting triangle or sphere, chosen in
 * proportion to its power (luminance x area), sampled uniformly by area (triangles; the two triangles
 * of a rectangular quad or box face as the whole rectangle, p0 + u1 ex + u2 ey, the same density, so
 * the sampler's 2-D point stays stratified over the lamp) or uniformly in the cone of directions the
 * sphere subtends (spheres). Triangles and quads emit on the side of their
 * normal only; spheres emit outwards. With MURK_LIGHT_SOLID_ANGLE (murk/plugin.h) the two triangles of
 * a rectangular quad or box face are sampled together, uniformly in the solid angle of the rectangle
 * (Urena, Fajardo and King 2013, "An Area-Preserving Parametrization for Spherical Rectangles"), except
 * from points that see the rectangle under less than MIN_RECT_OMEGA or lie on its plane up to PLANE_EPS
 * (a hit on the light itself): those sample it by area, and murk_lights_pdf() follows the same rule. */
#include "render/lights.h"
#include "render/accel.h"
#include "scene/texture.h"
#include "util/error.h"
#include "util/util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void add_light(murk_scene *s, size_t *cap, const murk_light *l)
{
    if (s->nlights == *cap) {
        *cap = *cap ? 2 * *cap : 16;
        s->lights = murk_xrealloc(s->lights, *cap * sizeof *s->lights);
    }
    s->lights[s->nlights++] = *l;
}

/* The radius of the scene's bounding sphere: the shapes' box, murk_accel_bounds (1 when
 * the scene has no shapes). */
static double scene_radius(const murk_scene *s)
{
    murk_vec3 lo, hi;
    murk_accel_bounds(s, &lo, &hi);
    if (!(hi.x >= lo.x && hi.y >= lo.y && hi.z >= lo.z))
        return 1.0;
    double dx = (double)hi.x - lo.x, dy = (double)hi.y - lo.y, dz = (double)hi.z - lo.z;
    double r = 0.5 * sqrt(dx * dx + dy * dy + dz * dz);
    return r > 0.0 ? r : 1.0;
}

static void shape_lights(murk_scene *s, size_t *cap);
static void add_scene_lights(murk_scene *s, size_t *cap);
static double light_weight(const murk_scene *s, const murk_light *l, double R);
static void rect_lights(murk_scene *s);

int murk_lights_build(murk_scene *s, char *err, size_t errlen)
{
    size_t cap = 0;
    for (size_t i = 0; s->legacy_lights && i < s->nadded; i++)
        if (!murk_light_is_env(&s->added[i]))
            return murk_err_file(err, errlen, s->doc.file, "the integrator predates plugin ABI 1.%d and cannot sample "
                                 "point, spot or delta distant lights, which nothing else can reach: rebuild it "
                                 "against this murk", MURK_ABI_MINOR_LIGHTS);
    shape_lights(s, &cap);
    add_scene_lights(s, &cap);
    s->light_cdf = murk_xmalloc((s->nlights + 1) * sizeof(float));
    double total = 0.0, run = 0.0, R = scene_radius(s);
    for (size_t i = 0; i < s->nlights; i++)
        total += light_weight(s, &s->lights[i], R);
    for (size_t i = 0; i < s->nlights; i++) {
        double w = light_weight(s, &s->lights[i], R);
        s->light_cdf[i] = total > 0 ? (float)(run / total) : 0.0f;
        s->lights[i].pmf = total > 0 ? (float)(w / total) : 0.0f;
        run += w;
    }
    s->light_cdf[s->nlights] = 1.0f;
    s->light_power = (float)total;
    rect_lights(s);
    return 0;
}

/* One light per emitting triangle or sphere of the shapes. */
static void shape_lights(murk_scene *s, size_t *cap)
{
    for (size_t i = 0; i < s->nshapes; i++) {
        murk_shape *sh = &s->shapes[i];
        if (murk_rgb_max(sh->emission) <= 0.0f)
            continue;
        sh->light_base = (int32_t)s->nlights;
        murk_light l = {0};
        l.geom = (uint32_t)i;
        l.le = sh->emission;
        if (sh->emission_tex) { /* its mean for the choice by power; its value where a sample lands */
            double m[3];
            murk_texture_average(sh->emission_tex, m);
            l.le = murk_rgb3(sh->emission.c[0] * (float)m[0], sh->emission.c[1] * (float)m[1], sh->emission.c[2] * (float)m[2]);
            l.textured = 1;
        }
        if (sh->type == MURK_SHAPE_SPHERE) {
            l.kind = MURK_LK_SPHERE;
            l.center = sh->center;
            l.radius = sh->radius;
            l.area = 4.0f * MURK_PI * sh->radius * sh->radius;
            add_light(s, cap, &l);
            continue;
        }
        for (uint32_t t = 0; t < sh->ntris; t++) {
            const uint32_t *ix = &sh->idx[3 * t];
            murk_vec3 a = murk_shape_vertex(sh, ix[0]);
            murk_vec3 b = murk_shape_vertex(sh, ix[1]);
            murk_vec3 c = murk_shape_vertex(sh, ix[2]);
            l.prim = t;
            l.p0 = a;
            l.e1 = murk_sub(b, a);
            l.e2 = murk_sub(c, a);
            murk_vec3 cr = murk_cross(l.e1, l.e2);
            l.area = 0.5f * murk_length(cr);
            l.n = murk_normalize(cr);
            add_light(s, cap, &l); /* degenerate triangles get area 0 and are never picked */
        }
    }
}

/* The added lights after the shapes' (an environment with parts: the constant background as one more,
 * so that every direction of it is sampled), and the environment's list. */
static void add_scene_lights(murk_scene *s, size_t *cap)
{
    size_t first = s->nlights, nenv = 0;
    for (size_t i = 0; i < s->nadded; i++)
        nenv += murk_light_is_env(&s->added[i]);
    for (size_t i = 0; i < s->nadded; i++)
        add_light(s, cap, &s->added[i]);
    if (nenv > 0 && !murk_rgb_is_black(s->background)) {
        murk_light l = {0};
        l.kind = MURK_LK_ENVMAP;
        l.le = s->background;
        add_light(s, cap, &l);
        nenv++;
    }
    s->env = murk_xmalloc((nenv ? nenv : 1) * sizeof *s->env);
    s->nenv = 0;
    for (size_t i = first; i < s->nlights; i++)
        if (murk_light_is_env(&s->lights[i]))
            s->env[s->nenv++] = i;
}

/* The selection weight of a light: its power over pi (lights.h). Emitting triangles and spheres keep the
 * product murk always computed (luminance x area), so scenes without added lights choose bit for bit as
 * before; a legacy integrator never gets an added light. */
static double light_weight(const murk_scene *s, const murk_light *l, double R)
{
    if (l->kind == MURK_LK_TRIANGLE || l->kind == MURK_LK_SPHERE)
        return (double)murk_luminance(l->le) * l->area;
    return s->legacy_lights ? 0.0 : murk_light_added_weight(l, R);
}

/* quads and box faces: triangles 2q (p0 p1 p2) and 2q + 1 (p0 p2 p3) of a rectangle (load.c's put_quad) */
static void rect_lights(murk_scene *s)
{
    for (size_t i = 0; i < s->nshapes; i++) {
        const murk_shape *sh = &s->shapes[i];
        if (sh->light_base < 0 || (sh->type != MURK_SHAPE_QUAD && sh->type != MURK_SHAPE_BOX))
            continue;
        for (uint32_t t = 0; t + 1 < sh->ntris; t += 2) {
            murk_light *a = &s->lights[sh->light_base + (int32_t)t], *b = a + 1;
            murk_vec3 ex = a->e1, ey = b->e2; /* p1 - p0, p3 - p0 */
            float lx = murk_length(ex), ly = murk_length(ey);
            if (!(lx > 0.0f && ly > 0.0f) || fabsf(murk_dot(ex, ey)) > 1e-5f * lx * ly)
                continue; /* a parallelogram: by area */
            a->rect = b->rect = 1;
            a->rp0 = b->rp0 = a->p0;
            a->rex = b->rex = ex;
            a->rey = b->rey = ey;
            a->rect_pmf = b->rect_pmf = a->pmf + b->pmf;
        }
    }
}

/* ---- spherical rectangles -------------------------------------------------------------------------- */

/* The rectangle seen from p in its own frame: x along ex, y along ey, z towards p's side flipped so that
 * the rectangle lies at z0 < 0 from p; the four corner-plane normals' angles give the solid angle. */
typedef struct srect {
    double x0, y0, x1, y1, z0;
    double n0z, n2z, g0, g1, g2, g3, omega;
    murk_vec3 ax, ay, az; /* unit frame */
} srect;

/* Closer to a rectangle's plane than this (relative to the coordinates' magnitude, as the integrators'
 * ray offsets are) a point is taken to be on it: not on the emitting side, sampled by area. */
#define PLANE_EPS 1e-4f

/* Fills r for the rectangle of l seen from p; returns 0 if p is not clearly on its emitting side. */
static int srect_setup(const murk_light *l, murk_vec3 p, srect *r)
{
    float lx = murk_length(l->rex), ly = murk_length(l->rey);
    r->ax = murk_mul(l->rex, 1.0f / lx);
    r->ay = murk_mul(l->rey, 1.0f / ly);
    r->az = murk_cross(r->ax, r->ay); /* the emitting side (n = normalize(ex x ey)) */
    murk_vec3 d = murk_sub(l->rp0, p);
    r->x0 = murk_dot(d, r->ax);
    r->y0 = murk_dot(d, r->ay);
    r->z0 = murk_dot(d, r->az);
    /* p behind the emitting side, or on the plane up to rounding: a point on the light itself (a hit on
     * its back, rounded to the front) would see the rectangle fill a hemisphere and be lit by it */
    if (!(r->z0 < -PLANE_EPS * murk_maxf(1.0f, murk_maxf(murk_maxabs(p), murk_maxabs(l->rp0)))))
        return 0;
    r->x1 = r->x0 + lx;
    r->y1 = r->y0 + ly;
    /* The corner planes' normals in this frame are n0 ~ (0, z0, -y0), n1 ~ (-z0, 0, x1), n2 ~ (0, -z0, y1),
     * n3 ~ (z0, 0, -x0) (Urena et al.), and the angle between -n_i and n_(i+1) is the atan2 of |z0| |v|
     * (v the corner they share) over their dot product: g0 at v10, g1 at v11, g2 at v01, g3 at v00. */
    double x0 = r->x0, y0 = r->y0, x1 = r->x1, y1 = r->y1, z0 = r->z0, az0 = fabs(z0), zz = z0 * z0;
    r->g0 = atan2(az0 * sqrt(x1 * x1 + y0 * y0 + zz), y0 * x1);
    r->g1 = atan2(az0 * sqrt(x1 * x1 + y1 * y1 + zz), -x1 * y1);
    r->g2 = atan2(az0 * sqrt(x0 * x0 + y1 * y1 + zz), x0 * y1);
    r->g3 = atan2(az0 * sqrt(x0 * x0 + y0 * y0 + zz), -x0 * y0);
    r->n0z = -y0 / sqrt(y0 * y0 + zz);
    r->n2z = y1 / sqrt(y1 * y1 + zz);
    r->omega = r->g0 + r->g1 + r->g2 + r->g3 - 2.0 * M_PI;
    return 1;
}

/* Below this solid angle (sr) the spherical-rectangle formulas lose their precision: sampled by area. */
#define MIN_RECT_OMEGA 1e-4

/* A point uniformly in the solid angle of r (u in [0, 1)^2), in world space. */
static murk_vec3 srect_sample(const srect *r, murk_vec3 p, float su, float sv)
{
    double au = su * (r->g0 + r->g1 - 2.0 * M_PI) + (su - 1.0) * (r->g2 + r->g3);
    double fu = (cos(au) * r->n0z - r->n2z) / sin(au);
    double cu = copysign(1.0 / sqrt(fu * fu + r->n0z * r->n0z), fu);
    cu = fmin(fmax(cu, -0.999999999), 0.999999999);
    double xu = -(cu * r->z0) / sqrt(1.0 - cu * cu);
    xu = fmin(fmax(xu, r->x0), r->x1);
    double dd = sqrt(xu * xu + r->z0 * r->z0);
    double h0 = r->y0 / sqrt(dd * dd + r->y0 * r->y0), h1 = r->y1 / sqrt(dd * dd + r->y1 * r->y1);
    double hv = h0 + sv * (h1 - h0), hv2 = hv * hv;
    double yv = hv2 < 1.0 - 1e-12 ? hv * dd / sqrt(1.0 - hv2) : r->y1;
    yv = fmin(fmax(yv, r->y0), r->y1);
    return murk_add(p, murk_add(murk_add(murk_mul(r->ax, (float)xu), murk_mul(r->ay, (float)yv)),
                                murk_mul(r->az, (float)r->z0)));
}

/* ---- sampling -------------------------------------------------------------------------------------- */

/* 1 - cos(theta_max) of the cone a sphere subtends from distance d > r, accurate when tiny. */
static float cone_one_minus_cos(float r, float d)
{
    float sin2 = (r * r) / (d * d);
    float cosm = sqrtf(murk_maxf(0.0f, 1.0f - sin2));
    return sin2 / (1.0f + cosm);
}

/* Kept out of murk_lights_sample() so that its common path (a triangle by area) does not pay for their
 * stack frames (srect: 14 doubles) in its prologue. */
#if defined(__GNUC__)
#define MURK_NOINLINE __attribute__((noinline))
#else
#define MURK_NOINLINE
#endif

/* A direction uniformly in the cone sphere light l subtends from p. */
static MURK_NOINLINE int sample_sphere(const murk_light *l, murk_vec3 p, const float u[3], murk_light_sample *ls)
{
    murk_vec3 dc = murk_sub(l->center, p);
    float d = murk_length(dc);
    if (d <= l->radius * 1.0001f)
        return 0; /* inside (or on) an outward-emitting sphere: it sends nothing this way */
    murk_vec3 w = murk_mul(dc, 1.0f / d), t, b;
    murk_basis(w, &t, &b);
    float omc = cone_one_minus_cos(l->radius, d);
    float one_minus_cos = u[1] * omc;
    float cost = 1.0f - one_minus_cos;
    float sint = sqrtf(murk_maxf(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
    float phi = 2.0f * MURK_PI * u[2];
    murk_vec3 dir = murk_from_local(murk_v3(sint * cosf(phi), sint * sinf(phi), cost), t, b, w);
    /* distance to the near intersection along dir */
    float bq = murk_dot(dir, dc);
    float disc = l->radius * l->radius - (d * d - bq * bq);
    float dist = bq - sqrtf(murk_maxf(0.0f, disc));
    ls->wi = dir;
    ls->dist = murk_maxf(dist, 0.0f);
    ls->le = l->le;
    ls->pdf = l->pmf / (2.0f * MURK_PI * omc);
    return ls->pdf > 0.0f && isfinite(ls->pdf);
}

/* A point uniformly in the solid angle of rectangle light l seen from p; -1 where it is sampled by area
 * instead (MIN_RECT_OMEGA, PLANE_EPS). */
static MURK_NOINLINE int sample_rect(const murk_light *l, murk_vec3 p, const float u[3], murk_light_sample *ls)
{
    srect r;
    if (!srect_setup(l, p, &r) || !(r.omega >= MIN_RECT_OMEGA))
        return -1;
    murk_vec3 q = srect_sample(&r, p, u[1], u[2]);
    murk_vec3 d = murk_sub(q, p);
    float dist = murk_length(d);
    if (!(dist > 0.0f))
        return 0;
    ls->wi = murk_mul(d, 1.0f / dist);
    ls->dist = dist;
    ls->le = l->le;
    ls->pdf = (float)(l->rect_pmf / r.omega);
    return isfinite(ls->pdf) && ls->pdf > 0.0f;
}

/* The emission of a textured triangle light at barycentrics (b1, b2): its shape's emission times the
 * texture at the point's (u, v), as host.c's fill_hit gives a hit there. Only meshes are textured, and a
 * mesh's triangles are never sampled as rectangles. */
static MURK_NOINLINE murk_rgb textured_le(const murk_scene *s, const murk_light *l, float b1, float b2)
{
    const murk_shape *sh = &s->shapes[l->geom];
    murk_hit h;
    memset(&h, 0, sizeof h);
    const uint32_t *ix = &sh->idx[3 * l->prim];
    float b0 = 1.0f - b1 - b2;
    if (sh->uv) {
        const float *t0 = &sh->uv[2 * ix[0]], *t1 = &sh->uv[2 * ix[1]], *t2 = &sh->uv[2 * ix[2]];
        h.u = b0 * t0[0] + b1 * t1[0] + b2 * t2[0];
        h.v = b0 * t0[1] + b1 * t1[1] + b2 * t2[1];
    } else {
        h.u = b1;
        h.v = b2;
    }
    float t[3];
    murk_texture_eval(sh->emission_tex, &h, t);
    return murk_rgb3(sh->emission.c[0] * t[0], sh->emission.c[1] * t[1], sh->emission.c[2] * t[2]);
}

int murk_lights_sample(const murk_scene *s, murk_vec3 p, const float u[3], int strategy, murk_light_sample *ls)
{
    memset(ls, 0, sizeof *ls);
    if (s->nlights == 0 || s->light_power <= 0.0f)
        return 0;
    /* the last i with cdf[i] <= u0 (cdf[0] = 0; a NaN u0 gives 0): a binary search whose steps are
     * conditional moves, not branches (u0 is random, so a branch is mispredicted every other time) */
    size_t lo = 0, len = s->nlights;
    while (len > 1) {
        size_t half = len / 2;
        lo = s->light_cdf[lo + half] <= u[0] ? lo + half : lo;
        len -= half;
    }
    while (lo > 0 && s->lights[lo].pmf <= 0.0f) /* never land on a zero-power light */
        lo--;
    const murk_light *l = &s->lights[lo];
    if (l->pmf <= 0.0f)
        return 0;
    if (l->kind != MURK_LK_TRIANGLE)
        return l->kind == MURK_LK_SPHERE ? sample_sphere(l, p, u, ls) : murk_lights_sample_added(s, l, p, u, ls);
    if (strategy == MURK_LIGHT_SOLID_ANGLE && l->rect) {
        int ok = sample_rect(l, p, u, ls);
        if (ok >= 0)
            return ok;
    }
    murk_vec3 q;
    float b1 = 0.0f, b2 = 0.0f; /* q's barycentrics in the triangle (not for a rectangle) */
    if (l->rect) { /* the whole rectangle, uniformly: the same density as its triangle's (both carry
                    * pmf / area), but the 2-D point keeps the sampler's stratification over the lamp */
        q = murk_add(l->rp0, murk_add(murk_mul(l->rex, u[1]), murk_mul(l->rey, u[2])));
    } else {
        float su = sqrtf(u[1]);
        b1 = su * (1.0f - u[2]), b2 = su * u[2];
        q = murk_add(l->p0, murk_add(murk_mul(l->e1, b1), murk_mul(l->e2, b2)));
    }
    murk_vec3 d = murk_sub(q, p);
    float dist2 = murk_dot(d, d), dist = sqrtf(dist2);
    if (dist <= 0.0f)
        return 0;
    murk_vec3 wi = murk_mul(d, 1.0f / dist);
    float cosl = -murk_dot(l->n, wi);
    if (cosl <= 0.0f)
        return 0;
    ls->wi = wi;
    ls->dist = dist;
    ls->le = l->textured ? textured_le(s, l, b1, b2) : l->le;
    ls->pdf = l->pmf * dist2 / (cosl * l->area);
    return isfinite(ls->pdf) && ls->pdf > 0.0f;
}

float murk_lights_pdf(const murk_scene *s, murk_vec3 p, const murk_hit *h, int strategy)
{
    if (h->light < 0 || (size_t)h->light >= s->nlights)
        return 0.0f;
    const murk_light *l = &s->lights[h->light];
    if (l->kind == MURK_LK_SPHERE) {
        float d = murk_length(murk_sub(l->center, p));
        if (d <= l->radius * 1.0001f)
            return 0.0f;
        return l->pmf / (2.0f * MURK_PI * cone_one_minus_cos(l->radius, d));
    }
    srect r;
    if (strategy == MURK_LIGHT_SOLID_ANGLE && l->rect && srect_setup(l, p, &r) && r.omega >= MIN_RECT_OMEGA)
        return (float)(l->rect_pmf / r.omega);
    murk_vec3 dv = murk_sub(h->p, p);
    float dist2 = murk_dot(dv, dv);
    if (dist2 <= 0.0f)
        return 0.0f;
    float cosl = -murk_dot(l->n, dv) / sqrtf(dist2);
    if (cosl <= 0.0f)
        return 0.0f;
    return l->pmf * dist2 / (cosl * l->area);
}

/* ---- the environment ------------------------------------------------------------------------------- */

murk_rgb murk_lights_background(const murk_scene *s, murk_vec3 dir)
{
    if (s->nenv == 0)
        return s->background;
    murk_rgb L = murk_rgb1(0.0f);
    for (size_t i = 0; i < s->nenv; i++)
        L = murk_rgb_add(L, murk_light_env_radiance(&s->lights[s->env[i]], dir));
    return L;
}

float murk_lights_environment_pdf(const murk_scene *s, murk_vec3 dir)
{
    float pdf = 0.0f;
    for (size_t i = 0; i < s->nenv; i++) {
        const murk_light *l = &s->lights[s->env[i]];
        if (l->pmf > 0.0f)
            pdf += l->pmf * murk_light_env_pdf(l, dir);
    }
    return pdf;
}
