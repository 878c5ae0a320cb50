/* accel.c — the Embree 3 scene: triangle geometry for quads, boxes and meshes; Embree's analytic
 * point-spheres for spheres. Geometry ids equal shape indices. */
#include "render/accel.h"
#include "util/error.h"
#include "util/runtime.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void embree_error(void *user, enum RTCError code, const char *str)
{
    (void)user;
    murk_log(MURK_LOG_WARN, "embree error %d: %s", (int)code, str ? str : "");
}

/* Embree's memory monitor: what it allocates and frees for the scene (called from its build threads). */
static bool embree_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;
    __atomic_fetch_add(&((murk_scene *)user)->embree_bytes, (long long)bytes, __ATOMIC_RELAXED);
    return true;
}

/* The bounds of triangle t of shape sh, or of a sphere (t ignored). */
static void prim_bounds(const murk_shape *sh, uint32_t t, murk_vec3 *lo, murk_vec3 *hi)
{
    if (sh->type == MURK_SHAPE_SPHERE) {
        murk_shape_bounds(sh, lo, hi);
        return;
    }
    const uint32_t *tv = &sh->idx[3 * t];
    *lo = *hi = murk_shape_vertex(sh, tv[0]);
    for (int k = 1; k < 3; k++) {
        *lo = murk_vmin(*lo, murk_shape_vertex(sh, tv[k]));
        *hi = murk_vmax(*hi, murk_shape_vertex(sh, tv[k]));
    }
}

static int boxes_meet(murk_vec3 alo, murk_vec3 ahi, murk_vec3 blo, murk_vec3 bhi)
{
    return alo.x <= bhi.x && blo.x <= ahi.x && alo.y <= bhi.y && blo.y <= ahi.y && alo.z <= bhi.z && blo.z <= ahi.z;
}

/* Shape i as an empty medium shape (accel.h), or 0: not a box or a sphere, it holds no medium, something
 * else meets it, or (a box) its faces are not two triangles each with axis-aligned normals, or it lacks
 * the loader's uv or has shading normals or an emission texture (never so for a loaded box). "Meets" uses
 * its bounds grown by 1e-4 of their coordinates' magnitude (the integrators' offset off a surface): a
 * shape on or within rounding of its surface could tie with it or beat it in Embree's arithmetic, so such
 * a shape is left to Embree. */
static int empty_shape(const murk_scene *s, size_t i, murk_empty_shape *b)
{
    const murk_shape *sh = &s->shapes[i];
    b->sphere = sh->type == MURK_SHAPE_SPHERE;
    if (!sh->interior || !(b->sphere || (sh->type == MURK_SHAPE_BOX && sh->ntris == 12)))
        return 0;
    if (!b->sphere && (!sh->uv || sh->nrm || sh->emission_tex)) /* host.c fills a face's hit from tri alone */
        return 0;
    b->center = sh->center;
    b->radius = sh->radius;
    murk_shape_bounds(sh, &b->lo, &b->hi);
    float m = 1e-4f * murk_maxf(1.0f, murk_maxf(murk_maxabs(b->lo), murk_maxabs(b->hi)));
    murk_vec3 glo = murk_sub(b->lo, murk_v3(m, m, m)), ghi = murk_add(b->hi, murk_v3(m, m, m));
    for (size_t j = 0; j < s->nshapes; j++) {
        const murk_shape *o = &s->shapes[j];
        for (uint32_t t = 0; j != i && t < (o->type == MURK_SHAPE_SPHERE ? 1u : o->ntris); t++) {
            murk_vec3 lo, hi;
            prim_bounds(o, t, &lo, &hi);
            if (boxes_meet(lo, hi, glo, ghi))
                return 0;
        }
    }
    int n[6] = {0};
    b->geom = (uint32_t)i;
    for (uint32_t t = 0; !b->sphere && t < 12; t++) {
        const float *g = &sh->ng[3 * t];
        int a = fabsf(g[0]) > 0.5f ? 0 : (fabsf(g[1]) > 0.5f ? 1 : 2);
        int f = 2 * a + (g[a] > 0.0f ? 0 : 1);
        if (g[(a + 1) % 3] != 0.0f || g[(a + 2) % 3] != 0.0f || n[f] == 2) /* not axis-aligned */
            return 0;
        /* the dual basis of the edges e1, e2: p - a = b1 e1 + b2 e2 gives b1 = (p - a).g1, b2 = (p - a).g2 */
        const uint32_t *tv = &sh->idx[3 * t];
        murk_box_tri *bt = &b->tri[f][n[f]++];
        bt->prim = t;
        bt->a = murk_shape_vertex(sh, tv[0]);
        bt->b = murk_shape_vertex(sh, tv[1]);
        bt->c = murk_shape_vertex(sh, tv[2]);
        bt->ng = murk_v3(g[0], g[1], g[2]);
        for (int k = 0; k < 6 && sh->uv; k++)
            bt->uv[k] = sh->uv[2 * tv[k / 2] + (uint32_t)(k % 2)];
        murk_vec3 e1 = murk_sub(bt->b, bt->a), e2 = murk_sub(bt->c, bt->a);
        float d11 = murk_dot(e1, e1), d12 = murk_dot(e1, e2), d22 = murk_dot(e2, e2), det = d11 * d22 - d12 * d12;
        if (!(det > 0.0f))
            return 0;
        bt->g1 = murk_mul(murk_sub(murk_mul(e1, d22), murk_mul(e2, d12)), 1.0f / det);
        bt->g2 = murk_mul(murk_sub(murk_mul(e2, d11), murk_mul(e1, d12)), 1.0f / det);
    }
    return 1;
}

static int is_empty_shape(const murk_scene *s, size_t i)
{
    for (size_t k = 0; k < s->nempty_shapes; k++)
        if (s->empty_shapes[k].geom == i)
            return 1;
    return 0;
}

int murk_accel_build(murk_scene *s, char *err, size_t errlen)
{
    s->device = rtcNewDevice(NULL);
    if (!s->device) {
        murk_err_file(err, errlen, s->doc.file, "cannot create an Embree device (error %d)", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    rtcSetDeviceErrorFunction(s->device, embree_error, NULL);
    s->embree_bytes = 0;
    rtcSetDeviceMemoryMonitorFunction(s->device, embree_memory, s);
    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    /* render.traversal: Embree's default unless the scene asks for its robust mode (README.md, "Scene format") */
    rtcSetSceneFlags(s->rtc, s->traversal == MURK_TRAVERSAL_ROBUST ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    s->nboundaries = 0;
    for (size_t i = 0; i < s->nshapes; i++) {
        murk_shape *sh = &s->shapes[i];
        s->nboundaries += !sh->material;
        RTCGeometry g;
        if (sh->type == MURK_SHAPE_SPHERE) {
            g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1);
            v[0] = sh->center.x, v[1] = sh->center.y, v[2] = sh->center.z, v[3] = sh->radius;
        } else {
            g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
            /* Embree reads 16 bytes past the last vertex: shared buffers need that padding. */
            float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                               sh->nverts);
            uint32_t *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                                   sh->ntris);
            if (!v || !ix) {
                rtcReleaseGeometry(g);
                murk_err_file(err, errlen, s->doc.file, "Embree could not allocate geometry for shape %zu", i);
                return -1;
            }
            memcpy(v, sh->pos, 3u * sh->nverts * sizeof(float));
            memcpy(ix, sh->idx, 3u * sh->ntris * sizeof(uint32_t));
            /* each triangle's unit normal as host.c's fill_hit() computed it per hit (same operations,
             * so the same floats): one load there instead of a cross product and a normalisation */
            free(sh->ng);
            sh->ng = murk_xmalloc(3u * sh->ntris * sizeof(float));
            for (uint32_t t = 0; t < sh->ntris; t++) {
                const uint32_t *tv = &sh->idx[3 * t];
                murk_vec3 n = murk_triangle_normal(murk_shape_vertex(sh, tv[0]), murk_shape_vertex(sh, tv[1]),
                                                   murk_shape_vertex(sh, tv[2]));
                sh->ng[3 * t] = n.x, sh->ng[3 * t + 1] = n.y, sh->ng[3 * t + 2] = n.z;
            }
        }
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(s->rtc, g);
        rtcReleaseGeometry(g);
        if (id != i) {
            murk_err_file(err, errlen, s->doc.file, "internal error: Embree geometry id %u for shape %zu", id, i);
            return -1;
        }
    }
    free(s->empty_shapes);
    s->empty_shapes = NULL;
    s->nempty_shapes = 0;
    murk_empty_shape b;
    /* each candidate is checked against every primitive of the scene: at most 2 x MURK_EMPTY_SHAPE_MAX of
     * them, so that a scene of many medium shapes and a large mesh does not pay shapes x triangles at load */
    int tried = 0;
    for (size_t i = 0; i < s->nshapes && s->nempty_shapes < MURK_EMPTY_SHAPE_MAX && tried < 2 * MURK_EMPTY_SHAPE_MAX; i++) {
        const murk_shape *sh = &s->shapes[i];
        tried += (sh->type == MURK_SHAPE_BOX || sh->type == MURK_SHAPE_SPHERE) && sh->interior;
        if (!empty_shape(s, i, &b))
            continue;
        if (!s->empty_shapes)
            s->empty_shapes = murk_xmalloc(MURK_EMPTY_SHAPE_MAX * sizeof *s->empty_shapes);
        s->empty_shapes[s->nempty_shapes++] = b;
        /* host.c answers every ray's meeting with it: Embree's tree leaves it out, so that the rays
         * that pass it or cross it do not traverse it */
        rtcDisableGeometry(rtcGetGeometry(s->rtc, b.geom));
    }
    free(s->few_spheres);
    s->few_spheres = NULL;
    s->nfew_spheres = 0;
    size_t nspheres = 0;
    for (size_t i = 0; i < s->nshapes; i++)
        nspheres += s->shapes[i].type == MURK_SHAPE_SPHERE && !is_empty_shape(s, i);
    for (size_t i = 0; nspheres <= MURK_FEW_SPHERES && i < s->nshapes; i++) {
        if (s->shapes[i].type != MURK_SHAPE_SPHERE || is_empty_shape(s, i))
            continue;
        if (!s->few_spheres)
            s->few_spheres = murk_xmalloc(nspheres * sizeof *s->few_spheres);
        s->few_spheres[s->nfew_spheres++] = (uint32_t)i;
        rtcDisableGeometry(rtcGetGeometry(s->rtc, (unsigned)i)); /* host.c intersects it (accel.h) */
    }
    rtcCommitScene(s->rtc);
    if (rtcGetDeviceError(s->device) != RTC_ERROR_NONE) {
        murk_err_file(err, errlen, s->doc.file, "Embree failed to build the scene");
        return -1;
    }
    return 0;
}

void murk_accel_bounds(const murk_scene *s, murk_vec3 *lo, murk_vec3 *hi)
{
    struct RTCBounds b;
    rtcGetSceneBounds(s->rtc, &b);
    *lo = murk_v3(b.lower_x, b.lower_y, b.lower_z);
    *hi = murk_v3(b.upper_x, b.upper_y, b.upper_z);
    for (size_t i = 0; i < s->nempty_shapes; i++) {
        *lo = murk_vmin(*lo, s->empty_shapes[i].lo);
        *hi = murk_vmax(*hi, s->empty_shapes[i].hi);
    }
    for (size_t i = 0; i < s->nfew_spheres; i++) {
        murk_vec3 slo, shi;
        murk_shape_bounds(&s->shapes[s->few_spheres[i]], &slo, &shi);
        *lo = murk_vmin(*lo, slo);
        *hi = murk_vmax(*hi, shi);
    }
}
