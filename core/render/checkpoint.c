/* checkpoint.c — saving and loading a render's accumulated state (see checkpoint.h). */
#include "render/checkpoint.h"
#include "util/atomic.h"
#include "util/error.h"
#include "util/file.h"
#include "util/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CKPT_MAGIC "MURKCKPT"
enum { CKPT_VERSION = 1, CKPT_BOM = 0x01020304, CKPT_HEADER = 8 + 4 + 4 + 8 + 8 + 4 * 4 + 8 + 8 };

uint64_t murk_fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    if (h == 0)
        h = 14695981039346656037ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

MURK_API uint64_t murk_file_hash(const char *path, char *err, size_t errlen)
{
    uint64_t size;
    unsigned char *b = murk_file_read_all(path, &size, err, errlen);
    if (!b)
        return 0;
    uint64_t h = murk_fnv1a(0, b, (size_t)size);
    free(b);
    return h ? h : 1;
}

typedef struct wctx {
    const murk_ckpt *c;
    uint64_t h;
} wctx;

static int put(FILE *fp, wctx *w, const void *p, size_t n)
{
    w->h = murk_fnv1a(w->h, p, n);
    return n == 0 || fwrite(p, 1, n, fp) == n ? 0 : -1;
}

static int fill(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    wctx *w = user;
    const murk_ckpt *c = w->c;
    size_t npix = (size_t)c->width * (size_t)c->height;
    uint32_t ver = CKPT_VERSION, bom = CKPT_BOM, olen = (uint32_t)strlen(c->overrides ? c->overrides : "");
    int32_t dims[3] = {c->width, c->height, c->spp};
    int rc = put(fp, w, CKPT_MAGIC, 8) | put(fp, w, &ver, 4) | put(fp, w, &bom, 4) | put(fp, w, &c->scene_hash, 8) |
             put(fp, w, &c->seed, 8) | put(fp, w, dims, sizeof dims) | put(fp, w, &olen, 4) |
             put(fp, w, &c->nonfinite, 8) | put(fp, w, &c->rays, 8) | put(fp, w, c->overrides ? c->overrides : "", olen) |
             put(fp, w, c->sum, 3 * npix * sizeof(double)) | put(fp, w, c->count, npix * sizeof(uint32_t));
    uint64_t h = w->h;
    if (rc == 0 && fwrite(&h, 8, 1, fp) != 1)
        rc = -1;
    if (rc)
        return murk_err_file(err, errlen, tmp, "cannot write the checkpoint");
    return 0;
}

int murk_ckpt_save(const char *path, const murk_ckpt *c, char *err, size_t errlen)
{
    wctx w = {c, 0};
    return murk_write_atomic(path, fill, &w, err, errlen);
}

void murk_ckpt_free(murk_ckpt *c)
{
    free(c->sum);
    free(c->count);
    free((char *)c->overrides);
    memset(c, 0, sizeof *c);
}

int murk_ckpt_load(const char *path, const murk_ckpt *want, murk_ckpt *c, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    uint64_t size;
    unsigned char *b = murk_file_read_all(path, &size, err, errlen);
    if (!b)
        return -1;
    int rc = -1;
    uint32_t ver, bom, olen;
    int32_t dims[3];
    if (size < CKPT_HEADER + 8 || memcmp(b, CKPT_MAGIC, 8) != 0) {
        murk_err_file(err, errlen, path, "not a murk checkpoint");
        goto out;
    }
    memcpy(&ver, b + 8, 4);
    memcpy(&bom, b + 12, 4);
    if (bom != CKPT_BOM || ver != CKPT_VERSION) {
        murk_err_file(err, errlen, path, "checkpoint version %u (or byte order) is not the one this murk writes (%d)",
                      bom == CKPT_BOM ? ver : 0u, CKPT_VERSION);
        goto out;
    }
    memcpy(&c->scene_hash, b + 16, 8);
    memcpy(&c->seed, b + 24, 8);
    memcpy(dims, b + 32, 12);
    memcpy(&olen, b + 44, 4);
    memcpy(&c->nonfinite, b + 48, 8);
    memcpy(&c->rays, b + 56, 8);
    c->width = dims[0], c->height = dims[1], c->spp = dims[2];
    uint64_t npix = dims[0] > 0 && dims[1] > 0 ? (uint64_t)dims[0] * (uint64_t)dims[1] : 0;
    if (npix == 0 || npix > ((uint64_t)1 << 32) || dims[2] < 0 ||
        size != CKPT_HEADER + (uint64_t)olen + npix * (3 * sizeof(double) + sizeof(uint32_t)) + 8) {
        murk_err_file(err, errlen, path, "truncated or damaged checkpoint (size %llu)", (unsigned long long)size);
        goto out;
    }
    uint64_t h;
    memcpy(&h, b + size - 8, 8);
    if (murk_fnv1a(0, b, (size_t)size - 8) != h) {
        murk_err_file(err, errlen, path, "damaged checkpoint (checksum mismatch)");
        goto out;
    }
    const char *wo = want->overrides ? want->overrides : "";
    if (c->scene_hash != want->scene_hash) {
        murk_err_file(err, errlen, path, "checkpoint of another scene, or the scene file or a file it loads (mesh, "
                      "grid, texture) changed since (content hash %016llx, now %016llx)",
                      (unsigned long long)c->scene_hash, (unsigned long long)want->scene_hash);
        goto out;
    }
    if (olen != strlen(wo) || memcmp(b + CKPT_HEADER, wo, olen) != 0) {
        murk_err_file(err, errlen, path, "checkpoint made with other --set overrides ('%.*s', now '%s')",
                      (int)(olen < 200 ? olen : 200), (const char *)b + CKPT_HEADER, wo);
        goto out;
    }
    if (c->seed != want->seed || c->width != want->width || c->height != want->height) {
        murk_err_file(err, errlen, path, "checkpoint of seed %llu at %dx%d, this render is seed %llu at %dx%d",
                      (unsigned long long)c->seed, c->width, c->height, (unsigned long long)want->seed, want->width,
                      want->height);
        goto out;
    }
    char *ov = murk_xmalloc((size_t)olen + 1);
    memcpy(ov, b + CKPT_HEADER, olen);
    c->overrides = ov;
    c->sum = murk_xmalloc((size_t)npix * 3 * sizeof(double));
    c->count = murk_xmalloc((size_t)npix * sizeof(uint32_t));
    memcpy(c->sum, b + CKPT_HEADER + olen, (size_t)npix * 3 * sizeof(double));
    memcpy(c->count, b + CKPT_HEADER + olen + npix * 3 * sizeof(double), (size_t)npix * sizeof(uint32_t));
    for (uint64_t i = 0; i < npix; i++)
        if (c->count[i] > (uint32_t)c->spp) {
            murk_err_file(err, errlen, path, "damaged checkpoint (a pixel has more samples than its spp)");
            goto out;
        }
    rc = 0;
out:
    free(b);
    if (rc)
        murk_ckpt_free(c);
    return rc;
}
