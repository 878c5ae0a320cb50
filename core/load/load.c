/* load.c — the scene loader: a YAML scene (with --set overrides) to a validated murk_scene, loading and
 * instantiating only the plugins it names.
 *
 * Every key is checked: the core's own blocks against the tables below, plugin blocks against the
 * plugin's parameter schema (params.c); the `media:` block is media.c's. Every error is one line
 * "file:line:col: what is wrong". */
#include "load/load.h"
#include "media/media.h"
#include "media/source.h"
#include "render/accel.h"
#include "render/checkpoint.h"
#include "render/host.h"
#include "render/lights.h"
#include "scene/obj.h"
#include "scene/params.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"
#include "yaml/yread.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERR(node, ...) murk_yerr(err, errlen, (node), __VA_ARGS__)

static murk_rgb to_rgb(const double d[3]) { return murk_rgb3((float)d[0], (float)d[1], (float)d[2]); }

#define NKEYS(a) (sizeof(a) / sizeof((a)[0]))

/* Prefixes an error that create() returned with the block's location. */
/* ---- Blocks ------------------------------------------------------------------------------------ */

/* A string that must be one of names[0..n): its index in *out, or a located error listing them. */
static int read_choice(const murk_ynode *c, const char *what, const char *const *names, size_t n, uint32_t *out,
                       char *err, size_t errlen)
{
    const char *v;
    if (murk_yread_string(c, what, &v, err, errlen))
        return -1;
    for (size_t i = 0; i < n; i++)
        if (strcmp(v, names[i]) == 0) {
            *out = (uint32_t)i;
            return 0;
        }
    char list[256] = "";
    for (size_t i = 0; i < n; i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? "|" : "", names[i]);
    return ERR(c, "%s must be one of %s, got '%s'", what, list, v);
}

static int load_render(murk_scene *s, const murk_ynode *n, char *err, size_t errlen)
{
    static const char *const keys[] = {"resolution", "spp", "seed", "exposure", "sampler", "traversal"};
    s->width = s->height = 512;
    s->spp = 64;
    s->seed = 0;
    s->exposure = 0.0f;
    s->sampler = MURK_SAMPLER_SOBOL;
    s->traversal = MURK_TRAVERSAL_FAST;
    if (!n)
        return 0;
    if (murk_yexpect_map(n, "render", err, errlen) || murk_ycheck_keys(n, "render", keys, NKEYS(keys), err, errlen))
        return -1;
    const murk_ynode *c;
    long long v;
    if ((c = murk_ymap_get(n, "resolution"))) {
        double r[2];
        if (murk_yread_list(c, "render.resolution", 2, 1, 16384, r, err, errlen))
            return -1;
        if (r[0] != floor(r[0]) || r[1] != floor(r[1]))
            return ERR(c, "render.resolution must be whole numbers");
        s->width = (int)r[0];
        s->height = (int)r[1];
        if (r[0] * r[1] > (double)murk_limit(MURK_LIMIT_IMAGE_PIXELS)) /* the render's buffers: ~40 bytes a pixel */
            return ERR(c, "render.resolution %dx%d exceeds the limit of %llu pixels (%s)", s->width, s->height,
                       (unsigned long long)murk_limit(MURK_LIMIT_IMAGE_PIXELS), murk_limit_name(MURK_LIMIT_IMAGE_PIXELS));
    }
    if ((c = murk_ymap_get(n, "spp"))) {
        if (murk_yread_int(c, "render.spp", 1, 1 << 24, &v, err, errlen))
            return -1;
        s->spp = (int)v;
    }
    if ((c = murk_ymap_get(n, "seed"))) {
        if (murk_yread_int(c, "render.seed", 0, 9007199254740992.0, &v, err, errlen))
            return -1;
        s->seed = (uint64_t)v;
    }
    if ((c = murk_ymap_get(n, "exposure"))) {
        double e;
        if (murk_yread_range(c, "render.exposure", -30, 30, &e, err, errlen))
            return -1;
        s->exposure = (float)e;
    }
    if ((c = murk_ymap_get(n, "sampler"))) {
        static const char *const samplers[] = {"independent", "sobol"}; /* indexed by MURK_SAMPLER_* */
        if (read_choice(c, "render.sampler", samplers, NKEYS(samplers), &s->sampler, err, errlen))
            return -1;
    }
    if ((c = murk_ymap_get(n, "traversal"))) {
        static const char *const modes[] = {"fast", "robust"}; /* indexed by MURK_TRAVERSAL_* */
        if (read_choice(c, "render.traversal", modes, NKEYS(modes), &s->traversal, err, errlen))
            return -1;
    }
    return 0;
}

/* The index of name among names[0..n), or -1 with a located "undefined KIND 'name'" error that
 * suggests the closest of the first 256 names. */
static long find_named(const murk_ynode *n, const char *kind, const char *name, const char *const *names, size_t count,
                       char *err, size_t errlen)
{
    for (size_t i = 0; i < count; i++)
        if (strcmp(names[i], name) == 0)
            return (long)i;
    const char *sug = murk_did_you_mean(name, names, count < 256 ? count : 256);
    if (sug)
        return ERR(n, "undefined %s '%s' (did you mean '%s'?)", kind, name, sug);
    return ERR(n, "undefined %s '%s'", kind, name);
}

int murk_load_lookup_medium(const murk_scene *s, const murk_ynode *n, const murk_medium **out, char *err, size_t errlen)
{
    const char *name = NULL;
    if (murk_yread_string(n, "a medium reference", &name, err, errlen))
        return -1;
    const char **names = murk_xmalloc((s->nmedia ? s->nmedia : 1) * sizeof *names);
    for (size_t i = 0; i < s->nmedia; i++)
        names[i] = s->media[i].name;
    long i = find_named(n, "medium", name, names, s->nmedia, err, errlen);
    free(names);
    if (i < 0)
        return -1;
    *out = &s->media[i].m;
    return 0;
}

int murk_load_lookup_material(const murk_scene *s, const murk_ynode *n, const murk_material **out, char *err,
                              size_t errlen)
{
    const char *name = NULL;
    if (murk_yread_string(n, "material", &name, err, errlen))
        return -1;
    const char **names = murk_xmalloc((s->nmaterials ? s->nmaterials : 1) * sizeof *names);
    for (size_t i = 0; i < s->nmaterials; i++)
        names[i] = s->materials[i].name;
    long i = find_named(n, "material", name, names, s->nmaterials, err, errlen);
    free(names);
    if (i < 0)
        return -1;
    *out = &s->materials[i].m;
    return 0;
}

/* camera: { from_asset: N, asset_camera: NAME }: the camera of the asset shape N (shapes[N]), taken while
 * that shape loads (load/asset.c); its frame is set once the shapes are loaded (camera_frame). */
typedef struct camera_request {
    long long shape;      /* -1: the camera block's own from/at/up/fov */
    const char *name;     /* asset_camera, or NULL: the first */
    const murk_ynode *at; /* the from_asset key, for errors */
    murk_asset_camera cam;
} camera_request;

static int camera_frame(murk_scene *s, const murk_ynode *n, char *err, size_t errlen);

static int load_camera(murk_scene *s, const murk_ynode *n, camera_request *req, char *err, size_t errlen)
{
    static const char *const keys[] = {"from", "at", "up", "fov", "medium", "from_asset", "asset_camera"};
    s->cam_from = murk_v3(0, 0, 5);
    s->cam_at = murk_v3(0, 0, 0);
    s->cam_up = murk_v3(0, 1, 0);
    s->fov = 40.0f;
    req->shape = -1;
    if (n) {
        if (murk_yexpect_map(n, "camera", err, errlen) || murk_ycheck_keys(n, "camera", keys, NKEYS(keys), err, errlen))
            return -1;
        const murk_ynode *c;
        if ((c = murk_ymap_get(n, "from_asset"))) {
            static const char *const own[] = {"from", "at", "up"};
            for (size_t i = 0; i < NKEYS(own); i++)
                if (murk_ymap_get(n, own[i]))
                    return ERR(murk_ymap_get(n, own[i]), "camera: '%s' and from_asset exclude each other (the asset's "
                               "camera sets from, at and up; fov overrides its field of view)", own[i]);
            if (murk_yread_int(c, "camera.from_asset (a shape's index)", 0, 1e9, &req->shape, err, errlen))
                return -1;
            req->at = c;
            if ((c = murk_ymap_get(n, "asset_camera")) && murk_yread_string(c, "camera.asset_camera", &req->name, err, errlen))
                return -1;
        } else if ((c = murk_ymap_get(n, "asset_camera"))) {
            return ERR(c, "camera: asset_camera needs from_asset: N (the asset shape whose camera it names)");
        }
        if ((c = murk_ymap_get(n, "from")) && murk_yread_vec3(c, "camera.from", &s->cam_from, err, errlen))
            return -1;
        if ((c = murk_ymap_get(n, "at")) && murk_yread_vec3(c, "camera.at", &s->cam_at, err, errlen))
            return -1;
        if ((c = murk_ymap_get(n, "up")) && murk_yread_vec3(c, "camera.up", &s->cam_up, err, errlen))
            return -1;
        double fov;
        if ((c = murk_ymap_get(n, "fov"))) {
            if (murk_yread_range(c, "camera.fov", 0.01, 179.0, &fov, err, errlen))
                return -1;
            s->fov = (float)fov;
        }
        if ((c = murk_ymap_get(n, "medium")) && murk_load_lookup_medium(s, c, &s->camera_medium, err, errlen))
            return -1;
    }
    return req->shape >= 0 ? 0 : camera_frame(s, n, err, errlen);
}

/* The camera's frame from from, at, up and fov. */
static int camera_frame(murk_scene *s, const murk_ynode *n, char *err, size_t errlen)
{
    murk_vec3 w = murk_sub(s->cam_at, s->cam_from);
    if (murk_length(w) <= 0.0f)
        return ERR(n, "camera: 'from' and 'at' are the same point");
    s->cam_w = murk_normalize(w);
    murk_vec3 u = murk_cross(s->cam_w, s->cam_up);
    if (murk_length(u) < 1e-6f * murk_length(s->cam_up) || murk_length(s->cam_up) <= 0.0f)
        return ERR(n, "camera: 'up' is parallel to the viewing direction");
    s->cam_u = murk_normalize(u);
    s->cam_v = murk_cross(s->cam_u, s->cam_w);
    s->cam_tan = tanf(0.5f * s->fov * MURK_PI / 180.0f);
    return 0;
}

static int load_materials(murk_scene *s, const murk_host *host, const murk_ynode *n, char *err, size_t errlen)
{
    if (!n)
        return 0;
    if (murk_yexpect_map(n, "materials", err, errlen))
        return -1;
    s->materials = murk_xmalloc((n->n ? n->n : 1) * sizeof *s->materials);
    for (size_t i = 0; i < n->n; i++) {
        const murk_ynode *m = n->items[i];
        char who[256];
        snprintf(who, sizeof who, "material '%s'", n->keys[i]);
        if (murk_yexpect_map(m, who, err, errlen))
            return -1;
        const murk_ynode *t = murk_yrequire(m, "type", who, err, errlen);
        const char *type = NULL;
        if (!t || murk_yread_string(t, "type", &type, err, errlen))
            return -1;
        static const char *const skip[] = {"type"};
        murk_named_material *nm = &s->materials[s->nmaterials];
        const murk_plugin *p;
        void *self;
        char who_type[512];
        snprintf(who_type, sizeof who_type, "%s (%s)", who, type);
        if (murk_scene_instantiate(s, host, MURK_KIND_MATERIAL, t, type, m, who, who_type, skip, 1, NULL, &p, &self,
                                   err, errlen))
            return -1;
        nm->name = murk_strdup(n->keys[i]);
        nm->m.vt = p->desc->vtable;
        nm->m.self = self;
        nm->m.name = nm->name;
        nm->plugin = p;
        s->nmaterials++;
    }
    return 0;
}

static int load_integrator(murk_scene *s, const murk_host *host, const murk_ynode *n, char *err, size_t errlen)
{
    static const char *const skip[] = {"type"};
    static const murk_ynode empty = {.kind = MURK_Y_MAP, .file = "(default)", .line = 1, .col = 1};
    const char *type = "path";
    if (n) {
        if (murk_yexpect_map(n, "integrator", err, errlen))
            return -1;
        const murk_ynode *t = murk_yrequire(n, "type", "integrator", err, errlen);
        if (!t || murk_yread_string(t, "integrator.type", &type, err, errlen))
            return -1;
    } else {
        n = &empty;
    }
    const murk_plugin *p;
    const murk_ynode *t = murk_ymap_get(n, "type");
    char who[256];
    snprintf(who, sizeof who, "integrator '%s'", type);
    if (murk_scene_instantiate(s, host, MURK_KIND_INTEGRATOR, t ? t : n, type, n, "integrator", who, skip, 1, NULL,
                               &p, &s->integrator, err, errlen))
        return -1;
    const murk_integrator_vt *vt = p->desc->vtable;
    s->integrator_plugin = p;
    s->integrator_vt = vt;
    return 0;
}

/* ---- Shapes ---------------------------------------------------------------------------------- */

static void shape_alloc(murk_shape *sh, uint32_t nverts, uint32_t ntris, int with_uv)
{
    sh->nverts = nverts;
    sh->ntris = ntris;
    sh->pos = murk_xmalloc(3u * nverts * sizeof(float));
    sh->uv = with_uv ? murk_xmalloc(2u * nverts * sizeof(float)) : NULL;
    sh->idx = murk_xmalloc(3u * ntris * sizeof(uint32_t));
}

/* Appends quad center +- u +- v as two triangles whose normal is u x v, with uv in [0,1]^2. */
static void put_quad(murk_shape *sh, uint32_t q, murk_vec3 c, murk_vec3 u, murk_vec3 v)
{
    murk_vec3 p[4] = {murk_sub(murk_sub(c, u), v), murk_sub(murk_add(c, u), v), murk_add(murk_add(c, u), v),
                      murk_add(murk_sub(c, u), v)};
    static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    for (int i = 0; i < 4; i++) {
        float *dst = &sh->pos[3u * (4u * q + (uint32_t)i)];
        dst[0] = p[i].x;
        dst[1] = p[i].y;
        dst[2] = p[i].z;
        sh->uv[2u * (4u * q + (uint32_t)i)] = uv[2 * i];
        sh->uv[2u * (4u * q + (uint32_t)i) + 1] = uv[2 * i + 1];
    }
    uint32_t b = 4u * q, *t = &sh->idx[6u * q];
    t[0] = b, t[1] = b + 1, t[2] = b + 2;
    t[3] = b, t[4] = b + 2, t[5] = b + 3;
}

int murk_read_transform(const murk_ynode *n, float m[12], char *err, size_t errlen)
{
    static const char *const keys[] = {"scale", "rotate", "translate"};
    if (murk_yexpect_map(n, "transform", err, errlen) || murk_ycheck_keys(n, "transform", keys, NKEYS(keys), err, errlen))
        return -1;
    double sc[3] = {1, 1, 1}, rot[3] = {0, 0, 0}, tr[3] = {0, 0, 0};
    const murk_ynode *c;
    if ((c = murk_ymap_get(n, "scale")) && murk_yread_rgb(c, "transform.scale", -1e30, 1e30, sc, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "rotate")) && murk_yread_list(c, "transform.rotate", 3, -1e6, 1e6, rot, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "translate")) && murk_yread_list(c, "transform.translate", 3, -MURK_MAX_COORD, MURK_MAX_COORD, tr, err, errlen))
        return -1;
    if (sc[0] == 0 || sc[1] == 0 || sc[2] == 0)
        return ERR(murk_ymap_get(n, "scale"), "transform.scale must not be 0");
    /* M = T * Rz * Ry * Rx * S (rotate: degrees about x, then y, then z) */
    double a = rot[0] * M_PI / 180, b = rot[1] * M_PI / 180, g = rot[2] * M_PI / 180;
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cg = cos(g), sg = sin(g);
    double R[3][3] = {{cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa},
                      {sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa},
                      {-sb, cb * sa, cb * ca}};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            m[4 * r + k] = (float)(R[r][k] * sc[k]);
        m[4 * r + 3] = (float)tr[r];
    }
    return 0;
}

static int load_mesh(murk_scene *s, murk_shape *sh, const murk_ynode *n, char *err, size_t errlen)
{
    const murk_ynode *f = murk_yrequire(n, "file", "mesh shape", err, errlen);
    const char *file = NULL;
    if (!f || murk_yread_string(f, "mesh.file", &file, err, errlen))
        return -1;
    float m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const murk_ynode *t = murk_ymap_get(n, "transform");
    if (t && murk_read_transform(t, m, err, errlen))
        return -1;
    char *path = murk_path_relative_to(s->doc.file, file);
    murk_mesh mesh;
    char merr[768];
    int rc = murk_obj_load(path, &mesh, merr, sizeof merr);
    free(path);
    if (rc != 0)
        return ERR(f, "mesh: %s", merr);
    sh->name = murk_strdup(file);
    sh->nverts = mesh.nverts;
    sh->ntris = mesh.ntris;
    sh->pos = mesh.pos;
    sh->uv = mesh.uv;
    sh->nrm = mesh.nrm;
    sh->idx = mesh.idx;
    for (uint32_t i = 0; i < mesh.nverts; i++) {
        float *p = &sh->pos[3 * i], x = p[0], y = p[1], z = p[2];
        for (int r = 0; r < 3; r++) {
            p[r] = m[4 * r] * x + m[4 * r + 1] * y + m[4 * r + 2] * z + m[4 * r + 3];
            if (!(fabsf(p[r]) <= (float)MURK_MAX_COORD)) /* the transformed mesh must fit Embree and float */
                return ERR(t ? t : f, "mesh: vertex %u lies at %g after the transform, beyond %g, the largest "
                           "coordinate murk accepts", i + 1, (double)p[r], MURK_MAX_COORD);
        }
        if (sh->nrm) { /* normals transform by the inverse transpose: R S^-1 for M = R S */
            float *q = &sh->nrm[3 * i], nx = q[0], ny = q[1], nz = q[2];
            murk_vec3 c0 = murk_v3(m[0], m[4], m[8]), c1 = murk_v3(m[1], m[5], m[9]), c2 = murk_v3(m[2], m[6], m[10]);
            float l0 = murk_dot(c0, c0), l1 = murk_dot(c1, c1), l2 = murk_dot(c2, c2);
            murk_vec3 o = murk_add(murk_add(murk_mul(c0, nx / l0), murk_mul(c1, ny / l1)), murk_mul(c2, nz / l2));
            o = murk_normalize(o);
            q[0] = o.x, q[1] = o.y, q[2] = o.z;
        }
    }
    /* a mirroring transform flips the winding: keep normals pointing the way the file meant */
    float det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                m[2] * (m[4] * m[9] - m[5] * m[8]);
    if (det < 0)
        for (uint32_t i = 0; i < sh->ntris; i++) {
            uint32_t tmp = sh->idx[3 * i + 1];
            sh->idx[3 * i + 1] = sh->idx[3 * i + 2];
            sh->idx[3 * i + 2] = tmp;
        }
    return 0;
}

static int load_shape(murk_scene *s, const murk_ynode *n, murk_shape *sh, char *err, size_t errlen)
{
    static const char *const quad_keys[] = {"type", "material", "emission", "interior", "exterior", "center", "u", "v"};
    static const char *const sphere_keys[] = {"type", "material", "emission", "interior", "exterior", "center", "radius"};
    static const char *const box_keys[] = {"type", "material", "emission", "interior", "exterior", "min", "max"};
    static const char *const mesh_keys[] = {"type", "material", "emission", "interior", "exterior", "file", "transform"};
    static const char *const types[] = {"quad", "sphere", "box", "mesh", "asset"};
    if (murk_yexpect_map(n, "a shape", err, errlen))
        return -1;
    const murk_ynode *t = murk_yrequire(n, "type", "shape", err, errlen);
    const char *type = NULL;
    if (!t || murk_yread_string(t, "shape type", &type, err, errlen))
        return -1;
    const murk_ynode *c;
    if (!strcmp(type, "quad")) {
        sh->type = MURK_SHAPE_QUAD;
        if (murk_ycheck_keys(n, "quad", quad_keys, NKEYS(quad_keys), err, errlen))
            return -1;
        murk_vec3 ce, u, v;
        if (!(c = murk_yrequire(n, "center", "quad", err, errlen)) || murk_yread_vec3(c, "quad.center", &ce, err, errlen))
            return -1;
        if (!(c = murk_yrequire(n, "u", "quad", err, errlen)) || murk_yread_vec3(c, "quad.u", &u, err, errlen))
            return -1;
        if (!(c = murk_yrequire(n, "v", "quad", err, errlen)) || murk_yread_vec3(c, "quad.v", &v, err, errlen))
            return -1;
        if (murk_length(murk_cross(u, v)) <= 0.0f)
            return ERR(n, "quad: u and v must span a non-degenerate parallelogram");
        shape_alloc(sh, 4, 2, 1);
        put_quad(sh, 0, ce, u, v);
    } else if (!strcmp(type, "sphere")) {
        sh->type = MURK_SHAPE_SPHERE;
        if (murk_ycheck_keys(n, "sphere", sphere_keys, NKEYS(sphere_keys), err, errlen))
            return -1;
        double r;
        if (!(c = murk_yrequire(n, "center", "sphere", err, errlen)) || murk_yread_vec3(c, "sphere.center", &sh->center, err, errlen))
            return -1;
        if (!(c = murk_yrequire(n, "radius", "sphere", err, errlen)) || murk_yread_range(c, "sphere.radius", 1e-6, MURK_MAX_COORD, &r, err, errlen))
            return -1;
        sh->radius = (float)r;
    } else if (!strcmp(type, "box")) {
        sh->type = MURK_SHAPE_BOX;
        if (murk_ycheck_keys(n, "box", box_keys, NKEYS(box_keys), err, errlen))
            return -1;
        murk_vec3 lo, hi;
        if (!(c = murk_yrequire(n, "min", "box", err, errlen)) || murk_yread_vec3(c, "box.min", &lo, err, errlen))
            return -1;
        if (!(c = murk_yrequire(n, "max", "box", err, errlen)) || murk_yread_vec3(c, "box.max", &hi, err, errlen))
            return -1;
        if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
            return ERR(c, "box: max must exceed min on every axis");
        murk_vec3 ce = murk_mul(murk_add(lo, hi), 0.5f), h = murk_mul(murk_sub(hi, lo), 0.5f);
        murk_vec3 X = murk_v3(h.x, 0, 0), Y = murk_v3(0, h.y, 0), Z = murk_v3(0, 0, h.z);
        shape_alloc(sh, 24, 12, 1);
        /* six faces, normals outwards: (u x v) along the face's outward axis */
        put_quad(sh, 0, murk_add(ce, X), Y, Z);
        put_quad(sh, 1, murk_sub(ce, X), Z, Y);
        put_quad(sh, 2, murk_add(ce, Y), Z, X);
        put_quad(sh, 3, murk_sub(ce, Y), X, Z);
        put_quad(sh, 4, murk_add(ce, Z), X, Y);
        put_quad(sh, 5, murk_sub(ce, Z), Y, X);
    } else if (!strcmp(type, "mesh")) {
        sh->type = MURK_SHAPE_MESH;
        if (murk_ycheck_keys(n, "mesh", mesh_keys, NKEYS(mesh_keys), err, errlen) || load_mesh(s, sh, n, err, errlen))
            return -1;
    } else {
        const char *sug = murk_did_you_mean(type, types, NKEYS(types));
        if (sug)
            return ERR(t, "unknown shape type '%s' (did you mean '%s'?)", type, sug);
        return ERR(t, "unknown shape type '%s'; expected quad, sphere, box, mesh or asset", type);
    }
    if ((c = murk_ymap_get(n, "material")) && murk_load_lookup_material(s, c, &sh->material, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "interior")) && murk_load_lookup_medium(s, c, &sh->interior, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "exterior")) && murk_load_lookup_medium(s, c, &sh->exterior, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "emission"))) {
        double e[3];
        if (murk_yread_rgb(c, "emission", 0, 1e30, e, err, errlen))
            return -1;
        sh->emission = to_rgb(e);
    }
    if (!sh->material && !murk_ymap_get(n, "interior"))
        return ERR(n, "%s has no material (give one, or interior: MEDIUM for an index-matched medium boundary)", type);
    if (!sh->material && !murk_rgb_is_black(sh->emission))
        return ERR(murk_ymap_get(n, "emission"), "an emissive %s needs a material", type);
    return 0;
}


static int load_shapes(murk_scene *s, const murk_host *host, const murk_ynode *n, camera_request *req, char *err,
                       size_t errlen)
{
    if (!n)
        return 0;
    if (n->kind != MURK_Y_SEQ)
        return ERR(n, "shapes must be a list");
    size_t cap = n->n ? n->n : 1; /* an asset adds a shape per mesh: the array grows */
    s->shapes = murk_xmalloc(cap * sizeof *s->shapes);
    for (size_t i = 0; i < n->n; i++) {
        const murk_ynode *t = murk_ymap_get(n->items[i], "type");
        if (t && t->kind == MURK_Y_SCALAR && !strcmp(t->str, "asset")) {
            int mine = req->shape == (long long)i;
            if (murk_load_asset(s, host, n->items[i], &cap, mine ? req->name : NULL, mine ? &req->cam : NULL, err, errlen))
                return -1;
            continue;
        }
        if (s->nshapes == cap)
            s->shapes = murk_xrealloc(s->shapes, (cap *= 2) * sizeof *s->shapes);
        murk_shape *sh = &s->shapes[s->nshapes];
        memset(sh, 0, sizeof *sh);
        sh->light_base = -1;
        if (load_shape(s, n->items[i], sh, err, errlen)) {
            murk_shape_free(sh);
            memset(sh, 0, sizeof *sh);
            return -1;
        }
        s->nshapes++;
    }
    return 0;
}

/* camera: { from_asset: N }: the asset's camera, once its shape has loaded. */
static int finish_camera(murk_scene *s, const murk_ynode *camera, camera_request *req, char *err, size_t errlen)
{
    if (req->shape < 0)
        return 0;
    const murk_ynode *shapes = murk_ymap_get(s->doc.root, "shapes"), *t;
    if (!shapes || shapes->kind != MURK_Y_SEQ || req->shape >= (long long)shapes->n ||
        !(t = murk_ymap_get(shapes->items[req->shape], "type")) || t->kind != MURK_Y_SCALAR || strcmp(t->str, "asset"))
        return ERR(req->at, "camera.from_asset: shapes[%lld] is not an asset shape", req->shape);
    s->cam_from = req->cam.from;
    s->cam_at = req->cam.at;
    s->cam_up = req->cam.up;
    if (!murk_ymap_get(camera, "fov"))
        s->fov = req->cam.fov;
    return camera_frame(s, req->at, err, errlen);
}

/* The box around the camera and every shape: how far a constant-density medium can reach. */
static void scene_bounds(const murk_scene *s, murk_vec3 *lo, murk_vec3 *hi)
{
    *lo = *hi = s->cam_from;
    for (size_t i = 0; i < s->nshapes; i++) {
        murk_vec3 a, b;
        murk_shape_bounds(&s->shapes[i], &a, &b);
        *lo = murk_vmin(*lo, a);
        *hi = murk_vmax(*hi, b);
    }
}

/* ---- Unused media and materials -------------------------------------------------------------- */

/* 1 if `name` is the string value of key `key` in map m. */
static int names(const murk_ynode *m, const char *key, const char *name)
{
    const murk_ynode *v = murk_ymap_get(m, key);
    return v && v->kind == MURK_Y_SCALAR && strcmp(v->str, name) == 0;
}

/* Is the medium (media = 1) or material `name` referenced: by a shape's interior/exterior or the
 * camera's medium; by a shape's material? */
static int referenced(const murk_ynode *root, int media, const char *name)
{
    const murk_ynode *shapes = murk_ymap_get(root, "shapes");
    if (media && names(murk_ymap_get(root, "camera"), "medium", name))
        return 1;
    for (size_t i = 0; shapes && shapes->kind == MURK_Y_SEQ && i < shapes->n; i++) {
        const murk_ynode *sh = shapes->items[i];
        if (media ? names(sh, "interior", name) || names(sh, "exterior", name) : names(sh, "material", name))
            return 1;
    }
    return 0;
}

/* A medium or material that nothing references is an error (usually a typo in a --set's name, which
 * would otherwise add a block and leave the scene as it was): located at its name, with the closest
 * other name. only_set: only blocks a --set created (murk_scene_load checks them before anything
 * loads, so that such a typo is named first); else all (murk_scene_check_unused, once the scene has
 * loaded, so that a file's other errors come first). */
static int check_unused(const murk_ynode *root, int only_set, char *err, size_t errlen)
{
    for (int media = 1; media >= 0; media--) {
        const char *block = media ? "media" : "materials";
        const murk_ynode *b = murk_ymap_get(root, block);
        if (!b || b->kind != MURK_Y_MAP)
            continue;
        for (size_t i = 0; i < b->n; i++) {
            if ((only_set && !murk_yfrom_set(b->key_file[i])) || referenced(root, media, b->keys[i]))
                continue;
            const char *others[256];
            size_t no = 0;
            for (size_t j = 0; j < b->n && no < 256; j++)
                if (j != i)
                    others[no++] = b->keys[j];
            const char *sug = murk_did_you_mean(b->keys[i], others, no);
            const char *by = media ? "by any shape or by the camera" : "by any shape";
            if (sug)
                return murk_yerr_key(err, errlen, b, i, "%s.%s is not used %s; did you mean %s.%s?", block, b->keys[i],
                                     by, block, sug);
            return murk_yerr_key(err, errlen, b, i, "%s.%s is not used %s; reference it (%s) or remove it", block,
                                 b->keys[i], by, media ? "a shape's interior or exterior, camera.medium" :
                                 "a shape's material");
        }
    }
    return 0;
}

static int load_document(murk_scene *s, char *err, size_t errlen)
{
    static const char *const keys[] = {"murk", "render", "camera", "integrator", "background",
                                       "materials", "media", "shapes", "lights"};
    const murk_ynode *root = s->doc.root;
    if (!root)
        return murk_yerr(err, errlen, &(murk_ynode){.file = s->doc.file, .line = 1, .col = 1},
                         "empty scene (expected a map with at least 'murk: 1' and 'shapes')");
    if (murk_yexpect_map(root, "a scene", err, errlen) || murk_ycheck_keys(root, "the scene", keys, NKEYS(keys), err, errlen))
        return -1;
    const murk_ynode *v = murk_yrequire(root, "murk", "the scene", err, errlen);
    long long ver;
    if (!v || murk_yread_int(v, "murk (the format version)", 0, 1e9, &ver, err, errlen))
        return -1;
    if (ver != 1)
        return ERR(v, "scene format version %lld is not supported (this murk reads version 1)", ver);
    if (check_unused(root, 1, err, errlen))
        return -1;
    /* the services table every plugin's create() receives, handed down to the blocks that create them */
    const murk_host *host = murk_host_table();
    const murk_ynode *c;
    if (load_render(s, murk_ymap_get(root, "render"), err, errlen))
        return -1;
    double bg[3] = {0, 0, 0};
    if ((c = murk_ymap_get(root, "background")) && murk_yread_rgb(c, "background", 0, 1e30, bg, err, errlen))
        return -1;
    s->background = to_rgb(bg);
    if ((c = murk_ymap_get(root, "media"))) {
        if (murk_media_load(s, host, c, err, errlen))
            return -1;
    }
    camera_request req;
    memset(&req, 0, sizeof req);
    if (load_camera(s, murk_ymap_get(root, "camera"), &req, err, errlen))
        return -1;
    if (load_materials(s, host, murk_ymap_get(root, "materials"), err, errlen))
        return -1;
    if (load_integrator(s, host, murk_ymap_get(root, "integrator"), err, errlen) ||
        murk_media_bind_integrator(s, murk_ymap_get(root, "media"), s->integrator_plugin->desc->name,
                                   s->integrator_plugin->abi.minor, err, errlen))
        return -1;
    /* an integrator built before the lights' ABI gets only emissive shapes to sample (render/lights.h) */
    s->legacy_lights = s->integrator_plugin->abi.minor < MURK_ABI_MINOR_LIGHTS;
    if (load_shapes(s, host, murk_ymap_get(root, "shapes"), &req, err, errlen) ||
        finish_camera(s, murk_ymap_get(root, "camera"), &req, err, errlen) ||
        murk_load_lights(s, murk_ymap_get(root, "lights"), err, errlen))
        return -1;
    murk_vec3 lo, hi;
    scene_bounds(s, &lo, &hi);
    return murk_media_check_depth(s, murk_ymap_get(root, "media"), lo, hi, err, errlen);
}

/* ---- The scene's content hash ---------------------------------------------------------------- */

/* Folds one input file into h: its path as the scene names it and its content. -1 with err if it
 * cannot be read (the loader read it a moment ago: it changed under us). */
static int hash_input(const murk_scene *s, const murk_ynode *file, uint64_t *h, char *err, size_t errlen)
{
    if (!file || file->kind != MURK_Y_SCALAR || !*file->str)
        return 0;
    char *path = murk_path_relative_to(s->doc.file, file->str);
    uint64_t fh = murk_file_hash(path, err, errlen);
    *h = murk_fnv1a(*h, path, strlen(path) + 1);
    *h = murk_fnv1a(*h, &fh, sizeof fh);
    free(path);
    return fh ? 0 : -1;
}

/* Every image texture's file under n ({ texture: image, file: F, ... } anywhere in a block). */
static int hash_textures(const murk_scene *s, const murk_ynode *n, uint64_t *h, char *err, size_t errlen)
{
    if (!n || n->kind == MURK_Y_SCALAR)
        return 0;
    const murk_ynode *t = murk_ymap_get(n, "texture");
    if (t && t->kind == MURK_Y_SCALAR && !strcmp(t->str, "image") && hash_input(s, murk_ymap_get(n, "file"), h, err, errlen))
        return -1;
    for (size_t i = 0; i < n->n; i++)
        if (hash_textures(s, n->items[i], h, err, errlen))
            return -1;
    return 0;
}

MURK_API uint64_t murk_scene_hash(const murk_scene *s, char *err, size_t errlen)
{
    uint64_t h = murk_file_hash(s->doc.file, err, errlen);
    if (!h)
        return 0;
    const murk_ynode *root = s->doc.root, *shapes = murk_ymap_get(root, "shapes"), *media = murk_ymap_get(root, "media");
    for (size_t i = 0; shapes && shapes->kind == MURK_Y_SEQ && i < shapes->n; i++) /* meshes */
        if ((names(shapes->items[i], "type", "mesh") || names(shapes->items[i], "type", "asset")) &&
            hash_input(s, murk_ymap_get(shapes->items[i], "file"), &h, err, errlen))
            return 0;
    static const char *const grids[] = {"density", "albedo", "emission", "temperature"};
    for (size_t i = 0; media && i < media->n; i++) /* density, albedo, emission and temperature grids */
        for (size_t g = 0; g < NKEYS(grids); g++)
            if (hash_input(s, murk_field_node_file(murk_ymap_get(media->items[i], grids[g])), &h, err, errlen))
                return 0;
    if (hash_textures(s, root, &h, err, errlen))
        return 0;
    for (size_t i = 0; i < s->nasset_inputs; i++) { /* assets' buffers and textures, by their paths */
        uint64_t fh = murk_file_hash(s->asset_inputs[i], err, errlen);
        h = murk_fnv1a(h, s->asset_inputs[i], strlen(s->asset_inputs[i]) + 1);
        h = murk_fnv1a(h, &fh, sizeof fh);
        if (!fh)
            return 0;
    }
    const murk_ynode *lights = murk_ymap_get(root, "lights");
    for (size_t i = 0; lights && lights->kind == MURK_Y_SEQ && i < lights->n; i++) /* environment maps */
        if (names(lights->items[i], "type", "envmap") && hash_input(s, murk_ymap_get(lights->items[i], "file"), &h, err, errlen))
            return 0;
    return h ? h : 1;
}

MURK_API int murk_scene_check_unused(const murk_scene *s, char *err, size_t errlen)
{
    return s->doc.root ? check_unused(s->doc.root, 0, err, errlen) : 0;
}

/* Each instance's plugin and file, for the render's warnings (murk_warn_name): an integrator's message
 * about `material 'red'` then says which plugin and which .so it is. */
static void name_instances(const murk_scene *s)
{
    char who[300], what[5000];
    for (size_t i = 0; i < s->nmaterials; i++) {
        snprintf(who, sizeof who, "material '%s'", s->materials[i].name);
        snprintf(what, sizeof what, "plugin %s, %s", s->materials[i].plugin->desc->name, s->materials[i].plugin->path);
        murk_warn_name(s, who, what);
    }
    for (size_t i = 0; i < s->nmedia; i++) {
        const murk_named_medium *m = &s->media[i];
        snprintf(who, sizeof who, "medium '%s'", m->name);
        int k = snprintf(what, sizeof what, "tracker %s, %s", m->plugin->desc->name, m->plugin->path);
        if (m->tr_plugin && k > 0 && (size_t)k < sizeof what)
            snprintf(what + k, sizeof what - (size_t)k, "; transmittance %s, %s", m->tr_plugin->desc->name,
                     m->tr_plugin->path);
        murk_warn_name(s, who, what);
    }
    snprintf(who, sizeof who, "integrator '%s'", s->integrator_plugin->desc->name);
    murk_warn_name(s, who, s->integrator_plugin->path);
}

/* The scene of doc (read, or -1 with err already set), with the --set overrides. */
static murk_scene *load_scene(murk_scene *s, int read, const char *const *sets, size_t nsets, char *err,
                              size_t errlen)
{
    if (read != 0) {
        murk_scene_free(s);
        return NULL;
    }
    for (size_t i = 0; i < nsets; i++)
        if (murk_ydoc_set(&s->doc, sets[i], err, errlen) != 0) {
            murk_scene_free(s);
            return NULL;
        }
    if (load_document(s, err, errlen) != 0 || murk_accel_build(s, err, errlen) != 0 ||
        murk_lights_build(s, err, errlen) != 0) {
        murk_scene_free(s);
        return NULL;
    }
    name_instances(s);
    return s;
}

static murk_scene *scene_new(void)
{
    murk_scene *s = murk_xmalloc(sizeof *s);
    murk_registry_init(&s->reg);
    return s;
}

MURK_API murk_scene *murk_scene_load(const char *path, const char *const *sets, size_t nsets, char *err, size_t errlen)
{
    murk_scene *s = scene_new();
    return load_scene(s, murk_ydoc_load_file(&s->doc, path, err, errlen), sets, nsets, err, errlen);
}

MURK_API murk_scene *murk_scene_load_text(const char *text, const char *name, const char *const *sets, size_t nsets,
                                          char *err, size_t errlen)
{
    murk_scene *s = scene_new();
    return load_scene(s, murk_ydoc_load_string(&s->doc, text, name, err, errlen), sets, nsets, err, errlen);
}
