/* asset.c — shapes from a scene file of another tool, read with Assimp's C API (Debian's libassimp-dev):
 *
 *   - { type: asset, file: scene.glb | mesh.ply | mesh.fbx | mesh.obj, transform: {...},
 *       material: NAME | from_file, emission: [r, g, b], interior: M, exterior: M, lights: true, light_scale: 1 }
 *
 * Every mesh of the file becomes a triangle shape, placed by its node's transform in the file and then by
 * `transform` (the mesh shape's scale / rotate / translate); points and lines are dropped, polygons
 * triangulated. `material: NAME` gives every mesh the scene's material NAME; `from_file` gives each mesh
 * one made from its material in the file (below); without a material the meshes are index-matched medium
 * boundaries (interior required), as a mesh shape's. `emission` makes every mesh emissive; with from_file
 * and no emission, a material's emissive factor does (times its emissive intensity where Assimp reads one:
 * Debian's Assimp 5.2.5 drops glTF's KHR_materials_emissive_strength: murk reads it from the JSON itself,
 * emissive_strengths below, and matches it to Assimp's materials by name).
 *
 * Materials (from_file): murk's ggx (plugins/materials/ggx.c), from glTF's metallic-roughness model the
 * way the glTF specification mixes its dielectric and metal BRDFs (Appendix B, "fresnel_mix"):
 *   albedo = baseColor (1 - metallic),  specular = 0.04 (1 - metallic) + baseColor metallic,
 *   roughness = roughness (glTF's is perceptual as ggx's is: alpha = roughness^2).
 * A file without metallic-roughness (OBJ's .mtl, FBX's Phong, PLY's default) maps its diffuse colour to
 * albedo, its specular colour (averaged, clamped to [0, 1]) to specular and its Phong exponent n to
 * roughness = (2 / (n + 2))^(1/4) (Walter et al. 2007's alpha = sqrt(2 / (n + 2)) for Blinn-Phong).
 * Textures (file_texture): glTF's base colour (sRGB), metallicRoughness (linear; G roughness, B metallic) and
 * emissive textures, other formats' diffuse map, read as murk's image textures (PNG beside the file, or
 * embedded in a .glb) and mixed per hit by the formulas above (scene/texture.c's murk_texture_gltf); an
 * emissive texture is the mesh's emission_tex (render/host.c, render/lights.c). README, Assets.
 *
 * Lights (lights: true): KHR_lights_punctual's point, spot and directional lights become murk's point, spot
 * and distant lights (render/lights.h), placed by their nodes; intensity = colour x intensity x
 * light_scale (the file's candela and lux read as W/sr and W/m^2), a spot's inner and outer cone angles
 * its falloff and cone (murk's smoothstep between them, not glTF's linear one). Area and ambient lights are
 * left out with a warning.
 *
 * Cameras: `camera: { from_asset: N }` (load.c) takes the first camera of the asset shape N (or the one
 * named asset_camera): a glTF camera sits at its node's origin looking down its -z with +y up (the glTF
 * specification; Assimp's glTF importer also copies the node's translation into the camera's position,
 * which is ignored), its yfov (Assimp stores yfov x aspect) is murk's fov; other formats follow Assimp's
 * convention (position, look-at and up in the node's frame, half the horizontal angle).
 *
 * Why Assimp replaces nothing of murk's own OBJ reader (type: mesh stays): scene/obj.c parses numbers
 * correctly rounded and locale-independently (Assimp's fast_atoreal is not correctly rounded), reports
 * file:line:col for a malformed token (Assimp accepts or drops it), and is what the existing scenes'
 * bitwise images come from. type: asset reads .obj through Assimp too, for OBJ files with materials. */
#include "load/load.h"
#include "render/lights.h"
#include "image/image.h"
#include "scene/params.h"
#include "scene/texture.h"
#include "util/error.h"
#include "util/file.h"
#include "util/limit.h"
#include "util/runtime.h"
#include "util/util.h"
#include "yaml/yread.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifdef MURK_HAVE_ASSIMP
#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#endif

#define ERR(node, ...) murk_yerr(err, errlen, (node), __VA_ARGS__)

static int ends_with(const char *s, const char *suffix)
{
    size_t l = strlen(s), k = strlen(suffix);
    return l >= k && strcasecmp(s + l - k, suffix) == 0;
}

#ifdef MURK_HAVE_ASSIMP

/* A 3 x 4 affine map (row-major: out_r = m[4r..4r+2] . p + m[4r+3]), in double. */
typedef struct xform { double m[12]; } xform;

static xform compose(const xform *a, const xform *b) /* a after b */
{
    xform c;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++) {
            double v = k == 3 ? a->m[4 * r + 3] : 0.0;
            for (int j = 0; j < 3; j++)
                v += a->m[4 * r + j] * b->m[4 * j + k];
            c.m[4 * r + k] = v;
        }
    return c;
}

static xform from_ai(const struct aiMatrix4x4 *t)
{
    xform x = {{t->a1, t->a2, t->a3, t->a4, t->b1, t->b2, t->b3, t->b4, t->c1, t->c2, t->c3, t->c4}};
    return x;
}

static void apply(const xform *x, const double p[3], int point, double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = x->m[4 * r] * p[0] + x->m[4 * r + 1] * p[1] + x->m[4 * r + 2] * p[2] + (point ? x->m[4 * r + 3] : 0.0);
}

static double det3(const xform *x)
{
    const double *m = x->m;
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) + m[2] * (m[4] * m[9] - m[5] * m[8]);
}

/* Normals transform by the inverse transpose: the cofactor matrix (its scale does not matter). */
static void normal_map(const xform *x, double n[9])
{
    const double *m = x->m;
    n[0] = m[5] * m[10] - m[6] * m[9], n[1] = m[6] * m[8] - m[4] * m[10], n[2] = m[4] * m[9] - m[5] * m[8];
    n[3] = m[2] * m[9] - m[1] * m[10], n[4] = m[0] * m[10] - m[2] * m[8], n[5] = m[1] * m[8] - m[0] * m[9];
    n[6] = m[1] * m[6] - m[2] * m[5], n[7] = m[2] * m[4] - m[0] * m[6], n[8] = m[0] * m[5] - m[1] * m[4];
}

/* Adds path (taken) to the scene's asset inputs, the files beside a scene's own that its content hash
 * covers (load.c, murk_scene_hash), unless it is there already. */
static void note_input(murk_scene *s, char *path)
{
    for (size_t i = 0; i < s->nasset_inputs; i++)
        if (!strcmp(s->asset_inputs[i], path)) {
            free(path);
            return;
        }
    s->asset_inputs = murk_xrealloc(s->asset_inputs, (s->nasset_inputs + 1) * sizeof *s->asset_inputs);
    s->asset_inputs[s->nasset_inputs++] = path;
}

typedef struct asset_ctx {
    murk_scene *s;
    const murk_host *host;
    const struct aiScene *ai;
    const murk_ynode *n, *file; /* the shape's block and its file key: where errors point */
    const char *name;           /* the file as the scene names it */
    xform user;                 /* the block's transform */
    const murk_material *material; /* material: NAME */
    int from_file, have_emission;
    murk_rgb emission;
    const murk_medium *interior, *exterior;
    const murk_material **made;  /* from_file: the murk material of each of the file's materials */
    murk_rgb *made_emission;
    size_t *cap;                 /* capacity of s->shapes */
    const struct murk_texture **made_emission_tex;
    uint64_t triangles;
    int depth;
    char *path;                  /* the file's path (textures are found relative to it) */
    struct gltf_strength { char name[160]; double strength; } *strength; /* glTF: KHR_materials_emissive_strength */
    size_t nstrength;
    struct tex_cache { char key[MAXLEN]; int srgb; const struct murk_texture *t; } *cache; /* images read */
    size_t ncache;
    int noted_format, noted_unread, noted_mix, noted_uv, noted_strength;
} asset_ctx;

/* ---- materials ---------------------------------------------------------------------------------- */

static int get_colour(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, float out[3])
{
    struct aiColor4D c;
    if (aiGetMaterialColor(m, key, type, idx, &c) != AI_SUCCESS || !isfinite(c.r) || !isfinite(c.g) || !isfinite(c.b))
        return 0;
    out[0] = c.r, out[1] = c.g, out[2] = c.b;
    return 1;
}

static int get_float(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, float *out)
{
    ai_real v;
    unsigned one = 1;
    if (aiGetMaterialFloatArray(m, key, type, idx, &v, &one) != AI_SUCCESS || !isfinite(v))
        return 0;
    *out = (float)v;
    return 1;
}

static float clamp01(float v) { return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v); }

/* The ggx parameters of a file material (the mapping at the top of this file); 1 if it is a
 * metallic-roughness one, with its base colour and metallic factors in base and *metallic. */
static int ggx_of(const struct aiMaterial *m, float albedo[3], float specular[3], float *roughness, float base[3],
                  float *metallic_out)
{
    float metallic = 0.0f, ks[3];
    base[0] = base[1] = base[2] = 0.8f;
    int pbr = get_float(m, AI_MATKEY_METALLIC_FACTOR, &metallic) | get_float(m, AI_MATKEY_ROUGHNESS_FACTOR, roughness);
    if (!get_colour(m, AI_MATKEY_BASE_COLOR, base))
        get_colour(m, AI_MATKEY_COLOR_DIFFUSE, base);
    *metallic_out = metallic = clamp01(metallic);
    if (pbr) {
        for (int c = 0; c < 3; c++) {
            albedo[c] = clamp01(base[c] * (1.0f - metallic));
            specular[c] = clamp01(0.04f * (1.0f - metallic) + base[c] * metallic);
        }
        *roughness = clamp01(*roughness);
        return 1;
    }
    float ns = 0.0f, k = 0.04f;
    if (get_colour(m, AI_MATKEY_COLOR_SPECULAR, ks))
        k = clamp01((ks[0] + ks[1] + ks[2]) / 3.0f);
    get_float(m, AI_MATKEY_SHININESS, &ns);
    for (int c = 0; c < 3; c++) {
        albedo[c] = clamp01(base[c]);
        specular[c] = k;
    }
    *roughness = clamp01(powf(2.0f / (fmaxf(ns, 0.0f) + 2.0f), 0.25f));
    return 0;
}

/* ---- textures of the file's materials (material: from_file) ------------------------------------------ */

/* Where a warning about the asset points: "scene.yaml:L:C: FILE". */
#define AT(a) (a)->file->file, (a)->file->line, (a)->file->col, (a)->name

/* w x h texels of 8-bit RGB (stride bytes apart, in the channel order r, g, b at offsets ro, go, bo) as
 * linear floats (the sRGB EOTF if srgb), into img. 0, or -1 if the size is not one murk takes. */
static int texels_8bit(const unsigned char *px, unsigned w, unsigned h, size_t stride, int ro, int go, int bo, int srgb,
                       murk_image *img)
{
    memset(img, 0, sizeof *img);
    if (!murk_image_size_ok(w, h) || (uint64_t)w * h > murk_limit(MURK_LIMIT_IMAGE_PIXELS))
        return -1;
    float lut[256];
    for (int v = 0; v < 256; v++)
        lut[v] = (float)(srgb ? (v / 255.0 <= 0.04045 ? v / 255.0 / 12.92 : pow((v / 255.0 + 0.055) / 1.055, 2.4)) : v / 255.0);
    img->w = (int)w, img->h = (int)h;
    img->rgb = murk_xmalloc(3u * (size_t)w * h * sizeof(float));
    for (size_t i = 0; i < (size_t)w * h; i++) {
        img->rgb[3 * i] = lut[px[i * stride + (size_t)ro]];
        img->rgb[3 * i + 1] = lut[px[i * stride + (size_t)go]];
        img->rgb[3 * i + 2] = lut[px[i * stride + (size_t)bo]];
    }
    return 0;
}

/* Texture `type` of the file's material m (`what` names it, e.g. "baseColorTexture"; mlabel the material) as
 * an image texture the scene keeps, read once per file: an external file relative to the asset, or an image
 * embedded in the file (Assimp's "*N": compressed bytes when its mHeight is 0, else BGRA texels). *out is NULL
 * when m has none, or one murk cannot decode (not PNG: said once, the factor alone is used). 0, or -1 with a
 * located err (a file that is missing or not a readable PNG). */
static int file_texture(asset_ctx *a, const struct aiMaterial *m, enum aiTextureType type, const char *what,
                        const char *mlabel, int srgb, const murk_texture **out, char *err, size_t errlen)
{
    *out = NULL;
    struct aiString p;
    unsigned uv = 0;
    if (aiGetMaterialTextureCount(m, type) == 0 ||
        aiGetMaterialTexture(m, type, 0, &p, NULL, &uv, NULL, NULL, NULL, NULL) != AI_SUCCESS || !p.data[0])
        return 0;
    char shown[256], ierr[768];
    murk_printable(shown, sizeof shown, p.data);
    if (uv != 0 && !a->noted_uv++)
        murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: %s uses UV set %u; murk reads UV set 0 only", AT(a), mlabel,
                 what, uv);
    for (size_t i = 0; i < a->ncache; i++)
        if (a->cache[i].srgb == srgb && !strcmp(a->cache[i].key, p.data)) {
            *out = a->cache[i].t;
            return 0;
        }
    murk_image img;
    char name[300];
    if (p.data[0] == '*') { /* embedded */
        char *end;
        long k = strtol(p.data + 1, &end, 10);
        if (*end || end == p.data + 1 || k < 0 || (unsigned long)k >= a->ai->mNumTextures || !a->ai->mTextures[k])
            return ERR(a->file, "%s: material %s: %s names embedded image '%s' of %u", a->name, mlabel, what, shown,
                       a->ai->mNumTextures);
        const struct aiTexture *tx = a->ai->mTextures[k];
        snprintf(name, sizeof name, "%s#image%ld", a->name, k);
        if (!tx->pcData)
            return ERR(a->file, "%s: material %s: %s: embedded image %ld holds no data", a->name, mlabel, what, k);
        if (tx->mHeight == 0) {
            const unsigned char *bytes = (const unsigned char *)tx->pcData;
            if (tx->mWidth < 8 || memcmp(bytes, "\x89PNG\r\n\x1a\n", 8)) {
                char hint[16];
                murk_printable(hint, sizeof hint, tx->achFormatHint);
                if (!a->noted_format++)
                    murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: %s is an embedded %s image; murk decodes PNG "
                             "only, so its factor alone is used", AT(a), mlabel, what, hint[0] ? hint : "non-PNG");
                return 0;
            }
            if (murk_png_read_memory(bytes, tx->mWidth, name, srgb, &img, ierr, sizeof ierr))
                return ERR(a->file, "%s: material %s: %s: %s", a->name, mlabel, what, ierr);
        } else if (texels_8bit((const unsigned char *)tx->pcData, tx->mWidth, tx->mHeight, sizeof(struct aiTexel), 2, 1,
                               0, srgb, &img))
            return ERR(a->file, "%s: material %s: %s: embedded image %ld is %ux%u texels, a size murk does not take",
                       a->name, mlabel, what, k, tx->mWidth, tx->mHeight);
    } else { /* a file beside the asset */
        char *tp = murk_path_relative_to(a->path, p.data);
        uint64_t size;
        FILE *fp = murk_file_open_regular(tp, &size, ierr, sizeof ierr);
        if (!fp) {
            free(tp);
            return ERR(a->file, "%s: material %s: %s '%s': %s", a->name, mlabel, what, shown, ierr);
        }
        fclose(fp);
        if (!ends_with(p.data, ".png")) {
            free(tp);
            if (!a->noted_format++)
                murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: %s '%s' is not a PNG file; murk decodes PNG only, "
                         "so its factor alone is used", AT(a), mlabel, what, shown);
            return 0;
        }
        int rc = murk_png_read(tp, srgb, &img, ierr, sizeof ierr);
        if (rc) {
            free(tp);
            return ERR(a->file, "%s: material %s: %s '%s': %s", a->name, mlabel, what, shown, ierr);
        }
        note_input(a->s, tp); /* the checkpoint's content hash covers it (load.c) */
        snprintf(name, sizeof name, "%s", shown);
    }
    *out = murk_scene_keep_texture(a->s, murk_texture_from_image(&img, name));
    a->cache = murk_xrealloc(a->cache, (a->ncache + 1) * sizeof *a->cache);
    memcpy(a->cache[a->ncache].key, p.data, sizeof p.data);
    a->cache[a->ncache].srgb = srgb;
    a->cache[a->ncache++].t = *out;
    return 0;
}

/* ---- KHR_materials_emissive_strength, from the glTF's JSON ------------------------------------------- */

/* Debian's Assimp 5.2 drops this extension, so murk reads it itself: a scanner of just enough JSON to
 * find materials[i].extensions.KHR_materials_emissive_strength.emissiveStrength (RFC 8259's grammar,
 * nesting at most 64 deep; anything malformed ends the scan and leaves the strengths read so far). */
typedef struct json { const char *p, *end; int depth; } json;

static void j_ws(json *j)
{
    while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r'))
        j->p++;
}

/* A string at p: its contents' bounds (escapes left as they are); 0 if there is none. */
static int j_string(json *j, const char **s, size_t *n)
{
    j_ws(j);
    if (j->p >= j->end || *j->p != '"')
        return 0;
    const char *b = ++j->p;
    while (j->p < j->end && *j->p != '"')
        j->p += *j->p == '\\' ? 2 : 1;
    if (j->p >= j->end)
        return 0;
    *s = b, *n = (size_t)(j->p++ - b);
    return 1;
}

static int j_skip(json *j)
{
    j_ws(j);
    if (j->p >= j->end || ++j->depth > 64)
        return 0;
    int ok = 1;
    const char *s;
    size_t n;
    if (*j->p == '"')
        ok = j_string(j, &s, &n);
    else if (*j->p == '{' || *j->p == '[') {
        char close = *j->p == '{' ? '}' : ']';
        int obj = *j->p++ == '{';
        j_ws(j);
        if (j->p < j->end && *j->p == close)
            j->p++;
        else
            for (;;) {
                if (obj && !(j_string(j, &s, &n) && (j_ws(j), j->p < j->end && *j->p++ == ':')))
                    return 0;
                if (!j_skip(j))
                    return 0;
                j_ws(j);
                if (j->p >= j->end)
                    return 0;
                if (*j->p == close) {
                    j->p++;
                    break;
                }
                if (*j->p++ != ',')
                    return 0;
            }
    } else { /* a number or a literal */
        const char *b = j->p;
        while (j->p < j->end && *j->p && strchr("+-.0123456789eEtruefalsn", *j->p))
            j->p++;
        ok = j->p > b;
    }
    j->depth--;
    return ok;
}

/* In the object at p, the value of key: p left at it (1), or 0 (p past the object, or anywhere if malformed). */
static int j_find(json *j, const char *key)
{
    j_ws(j);
    if (j->p >= j->end || *j->p != '{')
        return 0;
    j->p++;
    j_ws(j);
    if (j->p < j->end && *j->p == '}')
        return 0;
    for (;;) {
        const char *s;
        size_t n;
        if (!j_string(j, &s, &n) || (j_ws(j), j->p >= j->end || *j->p++ != ':'))
            return 0;
        if (n == strlen(key) && !memcmp(s, key, n))
            return 1;
        if (!j_skip(j))
            return 0;
        j_ws(j);
        if (j->p >= j->end || *j->p++ != ',')
            return 0;
    }
}

/* Each material of the glTF or binary glTF data with KHR_materials_emissive_strength: its name (as the JSON
 * writes it, escapes and all) and strength; n of them. */
static struct gltf_strength *emissive_strengths(const unsigned char *data, size_t size, size_t *n)
{
    *n = 0;
    json j = {(const char *)data, (const char *)data + size, 0};
    if (size >= 20 && !memcmp(data, "glTF", 4)) { /* binary glTF: the JSON chunk comes first */
        uint32_t len = (uint32_t)data[12] | (uint32_t)data[13] << 8 | (uint32_t)data[14] << 16 | (uint32_t)data[15] << 24;
        if (memcmp(data + 16, "JSON", 4) || len > size - 20)
            return NULL;
        j.p = (const char *)data + 20, j.end = j.p + len;
    }
    if (!j_find(&j, "materials") || (j_ws(&j), j.p >= j.end || *j.p++ != '['))
        return NULL;
    struct gltf_strength *st = NULL;
    for (;;) {
        j_ws(&j);
        if (j.p >= j.end || *j.p == ']')
            break;
        json m = j, e;
        const char *name = "";
        size_t nl = 0;
        if (!j_find(&m, "name") || !j_string(&m, &name, &nl))
            name = "", nl = 0;
        m = j;
        if (j_find(&m, "extensions") && (e = m, j_find(&e, "KHR_materials_emissive_strength"))) {
            st = murk_xrealloc(st, (*n + 1) * sizeof *st);
            struct gltf_strength *g = &st[(*n)++];
            snprintf(g->name, sizeof g->name, "%.*s", (int)(nl < sizeof g->name ? nl : sizeof g->name - 1), name);
            g->strength = -1.0; /* unreadable */
            if (j_find(&e, "emissiveStrength")) {
                char num[64];
                size_t k = 0;
                j_ws(&e);
                while (e.p < e.end && k + 1 < sizeof num && *e.p && strchr("+-.0123456789eE", *e.p))
                    num[k++] = *e.p++;
                num[k] = 0;
                char *stop;
                double v = strtod(num, &stop);
                g->strength = k && !*stop && isfinite(v) && v >= 0.0 ? v : -1.0;
            } else {
                g->strength = 1.0; /* the extension's default */
            }
        }
        if (!j_skip(&j) || (j_ws(&j), j.p >= j.end) || *j.p == ']' || *j.p++ != ',')
            break;
    }
    return st;
}

/* The emissive strength murk read for the file's material called name (1: none); a material carrying the
 * extension that murk cannot tell apart (no name, or one that two materials share) or whose strength is not a
 * number >= 0 is named in a warning, once per file, and gets 1. */
static float strength_of(asset_ctx *a, const char *name, const char *mlabel)
{
    size_t hits = 0, at = 0;
    for (size_t k = 0; k < a->nstrength; k++)
        if (!strcmp(a->strength[k].name, name))
            hits++, at = k;
    if (!hits)
        return 1.0f;
    if (hits == 1 && name[0] && a->strength[at].strength >= 0.0)
        return (float)fmin(a->strength[at].strength, 1e30);
    if (!a->noted_strength++)
        murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: its KHR_materials_emissive_strength is left out (%s)",
                 AT(a), mlabel, a->strength[at].strength < 0.0 ? "its emissiveStrength is not a number >= 0"
                 : "murk matches it to the file's material by name, and this name is empty or not unique");
    return 1.0f;
}

/* murk's ggx for the file's material i, made once (from_file), with its emission and emission texture. */
static const murk_material *file_material(asset_ctx *a, unsigned i, murk_rgb *emission, const murk_texture **etex,
                                          char *err, size_t errlen)
{
    if (a->made[i]) {
        *emission = a->made_emission[i];
        *etex = a->made_emission_tex[i];
        return a->made[i];
    }
    const struct aiMaterial *m = a->ai->mMaterials[i];
    struct aiString nm;
    char mname[160] = "", label[400];
    if (aiGetMaterialString(m, AI_MATKEY_NAME, &nm) == AI_SUCCESS)
        murk_printable(mname, sizeof mname, nm.data);
    snprintf(label, sizeof label, "%s#%u '%s'", a->name, i, mname);
    char mlabel[200];
    snprintf(mlabel, sizeof mlabel, "%u '%s'", i, mname);
    float al[3], sp[3], r = 0.5f, e[3] = {0, 0, 0}, strength = 1.0f, base[3], metallic;
    int pbr = ggx_of(m, al, sp, &r, base, &metallic);
    if (get_colour(m, AI_MATKEY_COLOR_EMISSIVE, e) && !get_float(m, AI_MATKEY_EMISSIVE_INTENSITY, &strength))
        strength = strength_of(a, mname, mlabel); /* KHR_materials_emissive_strength, read by murk */
    for (int c = 0; c < 3; c++)
        e[c] = e[c] > 0.0f && strength > 0.0f ? fminf(e[c] * strength, 1e30f) : 0.0f;
    /* the textures: glTF's base colour (sRGB) and metallic-roughness (linear: roughness in G, metallic in B;
     * Assimp's glTF importer files it under aiTextureType_UNKNOWN), other formats' diffuse map; emission */
    const murk_texture *bt = NULL, *mrt = NULL, *et = NULL;
    if (file_texture(a, m, pbr ? aiTextureType_BASE_COLOR : aiTextureType_DIFFUSE, "base colour texture", mlabel, 1,
                     &bt, err, errlen) ||
        (pbr && !bt && file_texture(a, m, aiTextureType_DIFFUSE, "base colour texture", mlabel, 1, &bt, err, errlen)) ||
        (pbr && file_texture(a, m, aiTextureType_UNKNOWN, "metallicRoughness texture", mlabel, 0, &mrt, err, errlen)) ||
        file_texture(a, m, aiTextureType_EMISSIVE, "emissive texture", mlabel, 1, &et, err, errlen))
        return NULL;
    if (!a->noted_unread && (aiGetMaterialTextureCount(m, aiTextureType_NORMALS) ||
                             aiGetMaterialTextureCount(m, aiTextureType_LIGHTMAP))) {
        murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: normal and occlusion textures are not read", AT(a), mlabel);
        a->noted_unread = 1;
    }
    if (mrt && !a->noted_mix++)
        murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: material %s: metallic texture mapped per hit onto ggx (albedo = base "
                 "(1 - metallic), specular = mix(0.04, base, metallic)); ggx's diffuse under its coat differs from "
                 "glTF's (README, Assets)", AT(a), mlabel);
    murk_param_texture tex[3];
    size_t ntex = 0;
    float unit[3] = {1.0f, 1.0f, 1.0f};
    for (int c = 0; c < 3; c++)
        base[c] = pbr ? base[c] : al[c];
    if (bt || mrt) {
        tex[ntex++] = (murk_param_texture){"albedo", murk_scene_keep_texture(a->s, murk_texture_gltf(
                                                        MURK_GLTF_ALBEDO, bt, base, mrt, pbr ? metallic : 0.0f, r))};
        if (pbr)
            tex[ntex++] = (murk_param_texture){"specular", murk_scene_keep_texture(a->s, murk_texture_gltf(
                                                              MURK_GLTF_SPECULAR, bt, base, mrt, metallic, r))};
    }
    if (mrt)
        tex[ntex++] = (murk_param_texture){"roughness", murk_scene_keep_texture(a->s, murk_texture_gltf(
                                                           MURK_GLTF_ROUGHNESS, NULL, unit, mrt, metallic, r))};
    char text[512];
    snprintf(text, sizeof text, "{ type: ggx, albedo: [%.9g, %.9g, %.9g], specular: [%.9g, %.9g, %.9g], roughness: %.9g }",
             (double)al[0], (double)al[1], (double)al[2], (double)sp[0], (double)sp[1], (double)sp[2], (double)r);
    murk_named_material *nmat = murk_xmalloc(sizeof *nmat);
    murk_ydoc *doc = murk_xmalloc(sizeof *doc);
    const murk_plugin *p = NULL;
    void *self = NULL;
    char who[480];
    snprintf(who, sizeof who, "material %s (ggx, from the file)", label);
    if (murk_ydoc_load_string(doc, text, label, err, errlen) ||
        murk_scene_instantiate_textured(a->s, a->host, MURK_KIND_MATERIAL, murk_ymap_get(doc->root, "type"), "ggx",
                                        doc->root, who, tex, ntex, &p, &self, err, errlen)) {
        murk_ydoc_free(doc);
        free(doc);
        free(nmat);
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", err);
        ERR(a->file, "%s", msg);
        return NULL;
    }
    nmat->name = murk_strdup(label);
    nmat->m.vt = p->desc->vtable;
    nmat->m.self = self;
    nmat->m.name = nmat->name;
    nmat->plugin = p;
    murk_scene *s = a->s;
    s->asset_materials = murk_xrealloc(s->asset_materials, (s->nasset_materials + 1) * sizeof *s->asset_materials);
    s->asset_docs = murk_xrealloc(s->asset_docs, (s->nasset_materials + 1) * sizeof *s->asset_docs);
    s->asset_materials[s->nasset_materials] = nmat;
    s->asset_docs[s->nasset_materials++] = doc;
    a->made[i] = &nmat->m;
    a->made_emission[i] = *emission = murk_rgb3(e[0], e[1], e[2]);
    a->made_emission_tex[i] = *etex = murk_rgb_is_black(*emission) ? NULL : et;
    return a->made[i];
}

/* ---- meshes ------------------------------------------------------------------------------------- */

/* Mesh mi of the file under the node transform x, as a new shape. */
static int add_mesh(asset_ctx *a, unsigned mi, const xform *x, char *err, size_t errlen)
{
    const struct aiMesh *me = a->ai->mMeshes[mi];
    if (!(me->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !me->mVertices)
        return 0; /* points and lines (SortByPType split them off) */
    uint32_t ntris = 0;
    for (unsigned f = 0; f < me->mNumFaces; f++)
        ntris += me->mFaces[f].mNumIndices == 3;
    if (!ntris)
        return 0;
    a->triangles += ntris;
    if (a->triangles > murk_limit(MURK_LIMIT_MESH_TRIANGLES))
        return ERR(a->file, "%s: more than %llu triangles, the limit (%s)", a->name,
                   (unsigned long long)murk_limit(MURK_LIMIT_MESH_TRIANGLES), murk_limit_name(MURK_LIMIT_MESH_TRIANGLES));
    murk_scene *s = a->s;
    if (s->nshapes == *a->cap) {
        *a->cap *= 2;
        s->shapes = murk_xrealloc(s->shapes, *a->cap * sizeof *s->shapes);
    }
    murk_shape *sh = &s->shapes[s->nshapes];
    memset(sh, 0, sizeof *sh);
    sh->type = MURK_SHAPE_MESH;
    sh->light_base = -1;
    size_t ln = strlen(a->name) + (me->mName.length ? strlen(me->mName.data) : 4) + 2;
    sh->name = murk_xmalloc(ln);
    snprintf(sh->name, ln, "%s#%s", a->name, me->mName.length ? me->mName.data : "mesh");
    sh->nverts = me->mNumVertices;
    sh->ntris = ntris;
    sh->pos = murk_xmalloc(3u * (size_t)sh->nverts * sizeof(float));
    sh->idx = murk_xmalloc(3u * (size_t)ntris * sizeof(uint32_t));
    sh->uv = me->mTextureCoords[0] ? murk_xmalloc(2u * (size_t)sh->nverts * sizeof(float)) : NULL;
    sh->nrm = me->mNormals ? murk_xmalloc(3u * (size_t)sh->nverts * sizeof(float)) : NULL;
    s->nshapes++; /* owned by the scene from here: freed with it on any error below */
    double nm9[9], det = det3(x);
    normal_map(x, nm9);
    for (uint32_t v = 0; v < sh->nverts; v++) {
        const struct aiVector3D *p = &me->mVertices[v];
        double in[3] = {p->x, p->y, p->z}, out[3];
        apply(x, in, 1, out);
        for (int r = 0; r < 3; r++) {
            if (!(fabs(out[r]) <= MURK_MAX_COORD))
                return ERR(a->file, "%s: mesh '%s' vertex %u is %s (%g, %g, %g)", a->name, me->mName.data, v,
                           isfinite(in[0]) && isfinite(in[1]) && isfinite(in[2]) ? "beyond the largest coordinate murk "
                           "accepts after the transform" : "not finite", in[0], in[1], in[2]);
            sh->pos[3 * v + (uint32_t)r] = (float)out[r];
        }
        if (sh->uv) {
            sh->uv[2 * v] = isfinite(me->mTextureCoords[0][v].x) ? (float)me->mTextureCoords[0][v].x : 0.0f;
            sh->uv[2 * v + 1] = isfinite(me->mTextureCoords[0][v].y) ? (float)me->mTextureCoords[0][v].y : 0.0f;
        }
        if (sh->nrm) {
            const struct aiVector3D *q = &me->mNormals[v];
            double o[3];
            for (int r = 0; r < 3; r++)
                o[r] = nm9[3 * r] * q->x + nm9[3 * r + 1] * q->y + nm9[3 * r + 2] * q->z;
            double l = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
            if (!(l > 0.0) || !isfinite(l)) /* a broken normal: the geometric one stands in (host.c) */
                o[0] = o[1] = o[2] = 0.0, l = 1.0;
            for (int r = 0; r < 3; r++)
                sh->nrm[3 * v + (uint32_t)r] = (float)((det < 0.0 ? -1.0 : 1.0) * o[r] / l);
        }
    }
    uint32_t t = 0;
    for (unsigned f = 0; f < me->mNumFaces; f++) {
        const struct aiFace *fc = &me->mFaces[f];
        if (fc->mNumIndices != 3)
            continue;
        for (int k = 0; k < 3; k++) {
            unsigned i = fc->mIndices[det < 0.0 && k ? 3 - k : k]; /* a mirroring map flips the winding back */
            if (i >= sh->nverts)
                return ERR(a->file, "%s: mesh '%s' face %u names vertex %u of %u", a->name, me->mName.data, f, i, sh->nverts);
            sh->idx[3 * t + (uint32_t)k] = i;
        }
        t++;
    }
    sh->material = a->material;
    sh->emission = a->emission;
    sh->interior = a->interior;
    sh->exterior = a->exterior;
    if (a->from_file) {
        murk_rgb e;
        const murk_texture *et;
        if (me->mMaterialIndex >= a->ai->mNumMaterials)
            return ERR(a->file, "%s: mesh '%s' names material %u of %u", a->name, me->mName.data, me->mMaterialIndex,
                       a->ai->mNumMaterials);
        if (!(sh->material = file_material(a, me->mMaterialIndex, &e, &et, err, errlen)))
            return -1;
        if (!a->have_emission)
            sh->emission = e, sh->emission_tex = et;
    }
    return 0;
}

/* The node's meshes under its global transform, then its children's. */
static int walk(asset_ctx *a, const struct aiNode *node, const xform *parent, char *err, size_t errlen)
{
    if (++a->depth > 256)
        return ERR(a->file, "%s: the node hierarchy is more than 256 deep", a->name);
    xform local = from_ai(&node->mTransformation), g = compose(parent, &local);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= a->ai->mNumMeshes)
            return ERR(a->file, "%s: node '%s' names mesh %u of %u", a->name, node->mName.data, node->mMeshes[i],
                       a->ai->mNumMeshes);
        if (add_mesh(a, node->mMeshes[i], &g, err, errlen))
            return -1;
    }
    for (unsigned i = 0; i < node->mNumChildren; i++)
        if (walk(a, node->mChildren[i], &g, err, errlen))
            return -1;
    a->depth--;
    return 0;
}

/* The global transform of the node called name (the user's transform included); 0 if there is none. */
static int node_xform(const asset_ctx *a, const struct aiNode *node, const xform *parent, const char *name, int depth,
                      xform *out)
{
    if (depth > 256)
        return 0;
    xform local = from_ai(&node->mTransformation), g = compose(parent, &local);
    if (!strcmp(node->mName.data, name)) {
        *out = g;
        return 1;
    }
    for (unsigned i = 0; i < node->mNumChildren; i++)
        if (node_xform(a, node->mChildren[i], &g, name, depth + 1, out))
            return 1;
    return 0;
}

/* ---- lights and cameras ------------------------------------------------------------------------------- */

static int add_lights(asset_ctx *a, double scale, char *err, size_t errlen)
{
    for (unsigned i = 0; i < a->ai->mNumLights; i++) {
        const struct aiLight *l = a->ai->mLights[i];
        xform x;
        if (!node_xform(a, a->ai->mRootNode, &a->user, l->mName.data, 0, &x))
            x = a->user;
        double p[3] = {l->mPosition.x, l->mPosition.y, l->mPosition.z}, d[3] = {l->mDirection.x, l->mDirection.y, l->mDirection.z};
        double wp[3], wd[3];
        apply(&x, p, 1, wp);
        apply(&x, d, 0, wd);
        murk_vec3 pos = murk_v3((float)wp[0], (float)wp[1], (float)wp[2]), dir = murk_v3((float)wd[0], (float)wd[1], (float)wd[2]);
        murk_rgb I = murk_rgb3((float)(l->mColorDiffuse.r * scale), (float)(l->mColorDiffuse.g * scale),
                               (float)(l->mColorDiffuse.b * scale));
        char lerr[512] = "", lname[160];
        int rc = 0;
        size_t before = a->s->nadded;
        if (l->mType == aiLightSource_POINT)
            rc = murk_lights_add_point(a->s, pos, I, lerr, sizeof lerr);
        else if (l->mType == aiLightSource_SPOT)
            rc = murk_lights_add_spot(a->s, pos, dir, I, l->mAngleOuterCone * 180.0 / M_PI,
                                      fmin(l->mAngleInnerCone, l->mAngleOuterCone) * 180.0 / M_PI, lerr, sizeof lerr);
        else if (l->mType == aiLightSource_DIRECTIONAL)
            rc = murk_lights_add_distant(a->s, murk_mul(dir, -1.0f), I, 0.0, lerr, sizeof lerr);
        else
            murk_log(MURK_LOG_WARN, "%s:%d:%d: %s: light '%s' is of a kind murk does not take (area or ambient); left out",
                     a->file->file, a->file->line, a->file->col, a->name, l->mName.data);
        if (rc)
            return ERR(a->file, "%s: light '%s': %s", a->name, l->mName.data, lerr);
        murk_load_note_lights(a->s, before, "%s light '%s' (%s:%d:%d)", a->name, murk_printable(lname, sizeof lname,
                              l->mName.data), a->file->file, a->file->line, a->file->col);
    }
    return 0;
}

/* The camera called want (NULL: the first) into cam. */
static int take_camera(asset_ctx *a, const char *want, murk_asset_camera *cam, char *err, size_t errlen)
{
    const struct aiCamera *c = NULL;
    for (unsigned i = 0; i < a->ai->mNumCameras && !c; i++)
        if (!want || !strcmp(a->ai->mCameras[i]->mName.data, want))
            c = a->ai->mCameras[i];
    if (!c)
        return ERR(a->file, want ? "%s: no camera '%s' in the file" : "%s: the file has no camera%s", a->name,
                   want ? want : "");
    xform x;
    if (!node_xform(a, a->ai->mRootNode, &a->user, c->mName.data, 0, &x))
        x = a->user;
    int gltf = ends_with(a->name, ".gltf") || ends_with(a->name, ".glb");
    double pos[3] = {c->mPosition.x, c->mPosition.y, c->mPosition.z}, look[3] = {c->mLookAt.x, c->mLookAt.y, c->mLookAt.z};
    double up[3] = {c->mUp.x, c->mUp.y, c->mUp.z}, wp[3], wl[3], wu[3];
    if (gltf) { /* the glTF convention: the node's origin, its -z, its +y */
        pos[0] = pos[1] = pos[2] = 0.0;
        look[0] = look[1] = 0.0, look[2] = -1.0;
        up[0] = up[2] = 0.0, up[1] = 1.0;
    }
    apply(&x, pos, 1, wp);
    apply(&x, look, 0, wl);
    apply(&x, up, 0, wu);
    double aspect = c->mAspect > 0.0f ? c->mAspect : (double)a->s->width / a->s->height;
    double fov = gltf ? c->mHorizontalFOV / (c->mAspect > 0.0f ? c->mAspect : 1.0)
                      : 2.0 * atan(tan(c->mHorizontalFOV) / aspect);
    cam->found = 1;
    cam->from = murk_v3((float)wp[0], (float)wp[1], (float)wp[2]);
    cam->at = murk_v3((float)(wp[0] + wl[0]), (float)(wp[1] + wl[1]), (float)(wp[2] + wl[2]));
    cam->up = murk_v3((float)wu[0], (float)wu[1], (float)wu[2]);
    cam->fov = (float)(fov * 180.0 / M_PI);
    if (!(cam->fov > 0.01f && cam->fov < 179.0f))
        return ERR(a->file, "%s: camera '%s' has a field of view of %g degrees; murk takes (0.01, 179)", a->name,
                   c->mName.data, (double)cam->fov);
    return 0;
}

/* 1 if the PLY file at path has a line "end_header": Debian's Assimp 5.2.5 reads a header without one forever
 * (found by tests/fuzz: fuzz_asset; the seed corpus keeps the input, ply_no_end_header). */
static int ply_header_ends(const char *path)
{
    uint64_t size;
    char ferr[512];
    unsigned char *b = murk_file_read_all(path, &size, ferr, sizeof ferr);
    if (!b)
        return 1; /* Assimp's own open reports it */
    int found = 0;
    for (uint64_t i = 0; !found && i + 10 <= size; i++)
        found = (i == 0 || b[i - 1] == '\n') && !memcmp(b + i, "end_header", 10) &&
                (i + 10 == size || b[i + 10] == '\n' || b[i + 10] == '\r');
    free(b);
    return found;
}

/* ---- the files Assimp reads ------------------------------------------------------------------------------ */

/* Assimp's file system, as its default one (stdio), except that every regular file it opens beside the asset
 * (a .gltf's .bin buffers, an OBJ's .mtl, ...) is noted as an asset input: a checkpoint of the scene is then
 * refused once one of them changed, as it is for the asset file itself (load.c, the content hash). */
typedef struct io_ctx {
    murk_scene *s;
    const char *path; /* the asset file, hashed as the scene names it */
} io_ctx;

static size_t io_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    return fread(buf, size, count, (FILE *)(void *)f->UserData);
}

static size_t io_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t io_tell(struct aiFile *f)
{
    long t = ftell((FILE *)(void *)f->UserData);
    return t < 0 ? 0 : (size_t)t;
}

static size_t io_size(struct aiFile *f)
{
    struct stat st;
    return fstat(fileno((FILE *)(void *)f->UserData), &st) == 0 && st.st_size > 0 ? (size_t)st.st_size : 0;
}

static enum aiReturn io_seek(struct aiFile *f, size_t off, enum aiOrigin origin)
{
    int whence = origin == aiOrigin_CUR ? SEEK_CUR : origin == aiOrigin_END ? SEEK_END : SEEK_SET;
    if (origin != aiOrigin_SET && origin != aiOrigin_CUR && origin != aiOrigin_END)
        return aiReturn_FAILURE;
    return fseek((FILE *)(void *)f->UserData, (long)off, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
}

static void io_flush(struct aiFile *f) { fflush((FILE *)(void *)f->UserData); }

static struct aiFile *io_open(struct aiFileIO *io, const char *name, const char *mode)
{
    io_ctx *c = (io_ctx *)(void *)io->UserData;
    if (!name || !mode)
        return NULL;
    FILE *fp = fopen(name, mode);
    if (!fp)
        return NULL;
    struct aiFile *f = calloc(1, sizeof *f);
    if (!f) {
        fclose(fp);
        return NULL;
    }
    f->ReadProc = io_read;
    f->WriteProc = io_write;
    f->TellProc = io_tell;
    f->FileSizeProc = io_size;
    f->SeekProc = io_seek;
    f->FlushProc = io_flush;
    f->UserData = (aiUserData)(void *)fp;
    struct stat st;
    if (strcmp(name, c->path) != 0 && fstat(fileno(fp), &st) == 0 && S_ISREG(st.st_mode))
        note_input(c->s, murk_strdup(name));
    return f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (!f)
        return;
    fclose((FILE *)(void *)f->UserData);
    free(f);
}

/* The block's keys beside file (transform, lights, light_scale, material, interior, exterior, emission) into a,
 * *lights and *light_scale. */
static int read_keys(asset_ctx *a, int *lights, double *light_scale, char *err, size_t errlen)
{
    murk_scene *s = a->s;
    const murk_ynode *n = a->n, *c;
    float m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const murk_ynode *t = murk_ymap_get(n, "transform");
    if (t && murk_read_transform(t, m, err, errlen))
        return -1;
    for (int i = 0; i < 12; i++)
        a->user.m[i] = m[i];
    if ((c = murk_ymap_get(n, "lights")) && murk_yread_bool(c, "asset.lights", lights, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "light_scale")) && murk_yread_range(c, "asset.light_scale", 0, 1e30, light_scale, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "material"))) {
        if (c->kind == MURK_Y_SCALAR && !strcmp(c->str, "from_file"))
            a->from_file = 1;
        else if (murk_load_lookup_material(s, c, &a->material, err, errlen))
            return -1;
    }
    if ((c = murk_ymap_get(n, "interior")) && murk_load_lookup_medium(s, c, &a->interior, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "exterior")) && murk_load_lookup_medium(s, c, &a->exterior, err, errlen))
        return -1;
    if ((c = murk_ymap_get(n, "emission"))) {
        double e[3];
        if (murk_yread_rgb(c, "emission", 0, 1e30, e, err, errlen))
            return -1;
        a->emission = murk_rgb3((float)e[0], (float)e[1], (float)e[2]);
        a->have_emission = 1;
    }
    if (!a->material && !a->from_file && !murk_ymap_get(n, "interior"))
        return ERR(n, "asset has no material (give one, material: from_file, or interior: MEDIUM for an index-matched "
                   "medium boundary)");
    if (!a->material && !a->from_file && !murk_rgb_is_black(a->emission))
        return ERR(murk_ymap_get(n, "emission"), "an emissive asset needs a material");
    return 0;
}

/* The file at path (a->name as the block gives it) through Assimp into a->ai, a->path = path; first what
 * Debian's Assimp 5.2 does not survive is refused. On failure path and a->strength are freed. */
static int import_file(asset_ctx *a, char *path, char *err, size_t errlen)
{
    const murk_ynode *f = a->file;
    const char *file = a->name;
    char ferr[768];
    uint64_t size;
    FILE *fp = murk_file_open_regular(path, &size, ferr, sizeof ferr);
    if (!fp) {
        free(path);
        return ERR(f, "asset: %s", ferr);
    }
    fclose(fp);
    if (a->from_file && (ends_with(file, ".gltf") || ends_with(file, ".glb"))) {
        unsigned char *bytes = murk_file_read_all(path, &size, ferr, sizeof ferr);
        if (bytes)
            a->strength = emissive_strengths(bytes, (size_t)size, &a->nstrength);
        free(bytes);
    }
    if (ends_with(file, ".ply") && !ply_header_ends(path)) {
        free(path);
        free(a->strength);
        return ERR(f, "asset: %s: its PLY header has no 'end_header' line (Assimp 5.2 would read on without end)", file);
    }
    struct aiPropertyStore *props = aiCreatePropertyStore();
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    /* read first without post-processing, to refuse a face without vertices (a PLY face list of 0), on which
     * Debian's Assimp 5.2 aborts in its Triangulate step (an ai_assert; found by tests/fuzz, seed ply_empty_face);
     * then read again with the steps. Not aiApplyPostProcessing on the first scene: when its validation fails
     * it releases the scene twice (a crash fuzz_asset found; seed apply_postprocess_release), as it does when
     * any later step fails (SortByPType removing every mesh of a file of points or lines); and validating in the
     * first read would run before Assimp's preprocessing sets the primitive types it checks faces by, and
     * report a file's other faults before its empty face. So the second read stays; what it costs (the first
     * two imports of a process are the slow ones) is in docs/results.md, "Assets read twice". */
    io_ctx ioc = {a->s, path};
    struct aiFileIO io = {io_open, io_close, (aiUserData)(void *)&ioc};
    const struct aiScene *probe = aiImportFileExWithProperties(path, 0, &io, props);
    char bad[300] = "";
    for (unsigned m = 0; probe && m < probe->mNumMeshes && !bad[0]; m++)
        for (unsigned k = 0; probe->mMeshes[m] && probe->mMeshes[m]->mFaces && k < probe->mMeshes[m]->mNumFaces && !bad[0]; k++)
            if (probe->mMeshes[m]->mFaces[k].mNumIndices == 0 || !probe->mMeshes[m]->mFaces[k].mIndices)
                snprintf(bad, sizeof bad, "mesh %u face %u has no vertices", m, k);
    if (probe)
        aiReleaseImport(probe);
    if (bad[0]) {
        aiReleasePropertyStore(props);
        free(path);
        free(a->strength);
        return ERR(f, "asset: %s: %s", file, bad);
    }
    a->ai = probe ? aiImportFileExWithProperties(path, aiProcess_Triangulate | aiProcess_SortByPType |
                                                 aiProcess_ValidateDataStructure, &io, props) : NULL;
    aiReleasePropertyStore(props);
    a->path = path;
    if (!a->ai) {
        char msg[512];
        free(path);
        free(a->strength);
        return ERR(f, "asset: %s: Assimp cannot read it: %s", file, murk_printable(msg, sizeof msg, aiGetErrorString()));
    }
    return 0;
}
#endif

/* ---- the block ------------------------------------------------------------------------------------------ */

/* An `asset` shape block: its file read through Assimp into shapes, and its lights and camera. */
int murk_load_asset(murk_scene *s, const murk_host *host, const murk_ynode *n, size_t *cap, const char *camera,
                    murk_asset_camera *cam, char *err, size_t errlen)
{
    static const char *const keys[] = {"type", "file", "transform", "material", "emission", "interior", "exterior",
                                       "lights", "light_scale"};
    if (murk_ycheck_keys(n, "asset", keys, sizeof keys / sizeof keys[0], err, errlen))
        return -1;
    const murk_ynode *f = murk_yrequire(n, "file", "asset shape", err, errlen);
    const char *file = NULL;
    if (!f || murk_yread_string(f, "asset.file", &file, err, errlen))
        return -1;
    static const char *const exts[] = {".gltf", ".glb", ".ply", ".fbx", ".obj"};
    int known = 0;
    for (size_t i = 0; i < sizeof exts / sizeof exts[0]; i++)
        known |= ends_with(file, exts[i]);
    if (!known)
        return ERR(f, "asset: '%s' is not a file murk reads as an asset (.gltf, .glb, .ply, .fbx, .obj)", file);
#ifndef MURK_HAVE_ASSIMP
    (void)s, (void)host, (void)cap, (void)camera, (void)cam;
    return ERR(f, "asset: murk was built without Assimp, so it cannot read %s (install libassimp-dev and rebuild: "
               "tools/build.sh, or meson configure -Dassimp=enabled)", file);
#else
    asset_ctx a = {.s = s, .host = host, .n = n, .file = f, .name = file, .cap = cap};
    int lights = 1;
    double light_scale = 1.0;
    if (read_keys(&a, &lights, &light_scale, err, errlen) ||
        import_file(&a, murk_path_relative_to(s->doc.file, file), err, errlen))
        return -1;
    int rc = 0;
    a.made = murk_xmalloc((a.ai->mNumMaterials ? a.ai->mNumMaterials : 1) * sizeof *a.made);
    a.made_emission = murk_xmalloc((a.ai->mNumMaterials ? a.ai->mNumMaterials : 1) * sizeof *a.made_emission);
    a.made_emission_tex = murk_xmalloc((a.ai->mNumMaterials ? a.ai->mNumMaterials : 1) * sizeof *a.made_emission_tex);
    size_t before = s->nshapes;
    if (!a.ai->mRootNode)
        rc = ERR(f, "asset: %s has no node hierarchy", file);
    if (!rc) {
        xform root = a.user;
        rc = walk(&a, a.ai->mRootNode, &root, err, errlen);
    }
    if (!rc && s->nshapes == before)
        rc = ERR(f, "asset: %s holds no triangle mesh", file);
    if (!rc && lights)
        rc = add_lights(&a, light_scale, err, errlen);
    if (!rc && cam)
        rc = take_camera(&a, camera, cam, err, errlen);
    free(a.made);
    free(a.made_emission);
    free(a.made_emission_tex);
    free(a.strength);
    free(a.cache);
    free(a.path);
    aiReleaseImport(a.ai);
    return rc;
#endif
}
