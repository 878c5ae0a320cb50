/* texture.c — constant, checkerboard and PNG image textures (see texture.h for the scene syntax), and the
 * parameters of a glTF metallic-roughness material computed from its textures (load/asset.c). */
#include "scene/texture.h"
#include "image/image.h"
#include "util/util.h"
#include "yaml/yread.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum { TEX_CHECKER, TEX_IMAGE, TEX_GLTF } tex_kind;

struct murk_texture {
    tex_kind kind;
    float even[3], odd[3];
    float su, sv;     /* uv scale */
    murk_image img;   /* TEX_IMAGE */
    char file[256];   /* TEX_IMAGE: the file as the scene names it */
    double avg[3];
    /* TEX_GLTF: which parameter, the textures it reads (not owned) and the factors */
    murk_gltf_param which;
    const murk_texture *base, *mr;
    float base_factor[3], metallic, roughness;
};

static int colour(const murk_ynode *n, const char *what, double lo, double hi, float out[3], char *err, size_t errlen)
{
    double v[3];
    if (murk_yread_rgb(n, what, lo, hi, v, err, errlen))
        return -1;
    for (int i = 0; i < 3; i++)
        out[i] = (float)v[i];
    return 0;
}

static int scale2(const murk_ynode *n, float *su, float *sv, char *err, size_t errlen)
{
    double a, b;
    if (n->kind == MURK_Y_SEQ && n->n == 2) {
        if (murk_yread_range(n->items[0], "texture scale", 1e-6, 1e6, &a, err, errlen) ||
            murk_yread_range(n->items[1], "texture scale", 1e-6, 1e6, &b, err, errlen))
            return -1;
    } else {
        if (murk_yread_range(n, "texture scale", 1e-6, 1e6, &a, err, errlen))
            return -1;
        b = a;
    }
    *su = (float)a;
    *sv = (float)b;
    return 0;
}

static void image_average(murk_texture *t)
{
    size_t np = (size_t)t->img.w * (size_t)t->img.h;
    for (size_t i = 0; i < np; i++)
        for (int ch = 0; ch < 3; ch++)
            t->avg[ch] += t->img.rgb[3 * i + (size_t)ch];
    for (int ch = 0; ch < 3; ch++)
        t->avg[ch] /= (double)(np ? np : 1);
}

murk_texture *murk_texture_parse(const murk_ynode *n, const char *scene_path, double lo, double hi, char *err,
                                 size_t errlen)
{
    static const char *const checker_keys[] = {"texture", "even", "odd", "scale"};
    static const char *const image_keys[] = {"texture", "file", "srgb", "scale"};
    const murk_ynode *k = murk_ymap_get(n, "texture");
    if (!k || k->kind != MURK_Y_SCALAR) {
        murk_yerr(err, errlen, n, "a texture map needs 'texture: checker' or 'texture: image'");
        return NULL;
    }
    murk_texture *t = murk_xmalloc(sizeof *t);
    t->su = t->sv = 1.0f;
    const murk_ynode *c;
    if (!strcmp(k->str, "checker")) {
        t->kind = TEX_CHECKER;
        t->su = t->sv = 8.0f;
        for (int i = 0; i < 3; i++)
            t->even[i] = (float)fmin(hi, fmax(lo, 0.8)), t->odd[i] = (float)fmin(hi, fmax(lo, 0.2));
        if (murk_ycheck_keys(n, "a checker texture", checker_keys, 4, err, errlen) ||
            ((c = murk_ymap_get(n, "even")) && colour(c, "checker 'even'", lo, hi, t->even, err, errlen)) ||
            ((c = murk_ymap_get(n, "odd")) && colour(c, "checker 'odd'", lo, hi, t->odd, err, errlen)) ||
            ((c = murk_ymap_get(n, "scale")) && scale2(c, &t->su, &t->sv, err, errlen)))
            goto fail;
        for (int i = 0; i < 3; i++)
            t->avg[i] = 0.5 * (t->even[i] + t->odd[i]);
        return t;
    }
    if (!strcmp(k->str, "image")) {
        t->kind = TEX_IMAGE;
        int srgb = 1;
        if (murk_ycheck_keys(n, "an image texture", image_keys, 4, err, errlen))
            goto fail;
        const murk_ynode *f = murk_ymap_get(n, "file");
        if (!f || f->kind != MURK_Y_SCALAR) {
            murk_yerr(err, errlen, n, "an image texture needs 'file: NAME.png'");
            goto fail;
        }
        if ((c = murk_ymap_get(n, "srgb"))) {
            if (c->kind != MURK_Y_SCALAR || (strcmp(c->str, "true") && strcmp(c->str, "false"))) {
                murk_yerr(err, errlen, c, "srgb must be true or false");
                goto fail;
            }
            srgb = !strcmp(c->str, "true");
        }
        if ((c = murk_ymap_get(n, "scale")) && scale2(c, &t->su, &t->sv, err, errlen))
            goto fail;
        snprintf(t->file, sizeof t->file, "%s", f->str);
        char *path = murk_path_relative_to(scene_path, f->str);
        char ierr[768];
        int rc = murk_png_read(path, srgb, &t->img, ierr, sizeof ierr);
        free(path);
        if (rc != 0) {
            murk_yerr(err, errlen, f, "image texture: %s", ierr);
            goto fail;
        }
        image_average(t);
        return t;
    }
    murk_yerr(err, errlen, k, "unknown texture '%s' (expected checker or image)", k->str);
fail:
    murk_texture_free(t);
    return NULL;
}

static int wrap(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

static float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

/* A TEX_GLTF texture's value at (u, v) (texture.h): the textures are sampled first, then mixed, as the
 * glTF specification's BRDF does. */
static void gltf_eval(const murk_texture *t, const murk_hit *hit, float out[3])
{
    float b[3] = {1.0f, 1.0f, 1.0f}, mr[3] = {1.0f, 1.0f, 1.0f};
    if (t->mr)
        murk_texture_eval(t->mr, hit, mr);
    float m = clamp01(mr[2] * t->metallic);
    if (t->which == MURK_GLTF_ROUGHNESS) {
        out[0] = out[1] = out[2] = clamp01(mr[1] * t->roughness);
        return;
    }
    if (t->base)
        murk_texture_eval(t->base, hit, b);
    for (int c = 0; c < 3; c++) {
        float base = clamp01(b[c] * t->base_factor[c]);
        out[c] = clamp01(t->which == MURK_GLTF_ALBEDO ? base * (1.0f - m) : 0.04f * (1.0f - m) + base * m);
    }
}

void murk_texture_eval(const murk_texture *t, const murk_hit *hit, float out[3])
{
    if (t->kind == TEX_GLTF) {
        gltf_eval(t, hit, out);
        return;
    }
    float u = hit->u * t->su, v = hit->v * t->sv;
    if (t->kind == TEX_CHECKER) {
        long parity = ((long)floorf(u) + (long)floorf(v)) & 1;
        memcpy(out, parity ? t->odd : t->even, 3 * sizeof(float));
        return;
    }
    /* bilinear over texel centres; image row 0 is v = 1 */
    const murk_image *im = &t->img;
    float x = u * (float)im->w - 0.5f, y = (1.0f - v) * (float)im->h - 0.5f;
    if (!isfinite(x) || !isfinite(y)) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    x = fmodf(x, (float)im->w);
    y = fmodf(y, (float)im->h);
    float fx = floorf(x), fy = floorf(y), ax = x - fx, ay = y - fy;
    int x0 = wrap((int)fx, im->w), y0 = wrap((int)fy, im->h), x1 = wrap(x0 + 1, im->w), y1 = wrap(y0 + 1, im->h);
    for (int c = 0; c < 3; c++) {
        float a = im->rgb[3 * ((size_t)y0 * (size_t)im->w + (size_t)x0) + (size_t)c];
        float b = im->rgb[3 * ((size_t)y0 * (size_t)im->w + (size_t)x1) + (size_t)c];
        float d = im->rgb[3 * ((size_t)y1 * (size_t)im->w + (size_t)x0) + (size_t)c];
        float e = im->rgb[3 * ((size_t)y1 * (size_t)im->w + (size_t)x1) + (size_t)c];
        out[c] = (1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * d + ax * e);
    }
}

murk_texture *murk_texture_from_image(murk_image *img, const char *name)
{
    murk_texture *t = murk_xmalloc(sizeof *t); /* zeroed */
    t->kind = TEX_IMAGE;
    t->su = t->sv = 1.0f;
    t->img = *img;
    memset(img, 0, sizeof *img);
    snprintf(t->file, sizeof t->file, "%s", name);
    image_average(t);
    return t;
}

murk_texture *murk_texture_gltf(murk_gltf_param which, const murk_texture *base, const float base_factor[3],
                                const murk_texture *mr, float metallic, float roughness)
{
    murk_texture *t = murk_xmalloc(sizeof *t); /* zeroed */
    t->kind = TEX_GLTF;
    t->which = which;
    t->base = base;
    t->mr = mr;
    memcpy(t->base_factor, base_factor, sizeof t->base_factor);
    t->metallic = metallic;
    t->roughness = roughness;
    snprintf(t->file, sizeof t->file, "glTF %s", which == MURK_GLTF_ALBEDO ? "albedo" : which == MURK_GLTF_SPECULAR
             ? "specular" : "roughness");
    /* the plain value (murk_value.f): the mean over a grid of points in [0,1)^2, as fine as the larger image
     * (at most 512 x 512 points) */
    int n = 1;
    if (base)
        n = base->img.w > n ? base->img.w : n, n = base->img.h > n ? base->img.h : n;
    if (mr)
        n = mr->img.w > n ? mr->img.w : n, n = mr->img.h > n ? mr->img.h : n;
    n = n < 512 ? n : 512;
    murk_hit h;
    memset(&h, 0, sizeof h);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            float v[3];
            h.u = ((float)x + 0.5f) / (float)n;
            h.v = ((float)y + 0.5f) / (float)n;
            gltf_eval(t, &h, v);
            for (int c = 0; c < 3; c++)
                t->avg[c] += v[c];
        }
    for (int c = 0; c < 3; c++)
        t->avg[c] /= (double)n * n;
    return t;
}

void murk_texture_average(const murk_texture *t, double out[3]) { memcpy(out, t->avg, sizeof t->avg); }

size_t murk_texture_bytes(const murk_texture *t, const char **name)
{
    if (name)
        *name = t->kind == TEX_CHECKER ? "checker" : t->file;
    return sizeof *t + (t->kind == TEX_IMAGE ? 3 * (size_t)t->img.w * (size_t)t->img.h * sizeof(float) : 0);
}

void murk_texture_free(murk_texture *t)
{
    if (!t)
        return;
    if (t->kind == TEX_IMAGE)
        murk_image_free(&t->img);
    free(t);
}
