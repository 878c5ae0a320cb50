/* memory.c — what a loaded scene holds in memory, item by item (scene.h, murk_scene_memory): for `murk info`
 * and the end-of-render summary, so that a scene's memory can be read off what it names. Bytes are counted
 * as allocated (element counts times sizes), without the allocator's overhead; the process's peak resident
 * memory (VmHWM, murk_peak_rss_kb) is given beside them for what they leave out (libraries, the render's
 * buffers). */
#include "load/load.h"
#include "media/density.h"
#include "media/media.h"
#include "scene/texture.h"
#include "util/util.h"

#include <stdio.h>
#include <string.h>

static murk_mem_item *next_item(murk_mem_item *items, size_t cap, size_t *n, const char *kind)
{
    static murk_mem_item sink;
    murk_mem_item *it = *n < cap ? &items[*n] : &sink;
    (*n)++;
    memset(it, 0, sizeof *it);
    it->kind = kind;
    return it;
}

static void grid_item(const murk_named_medium *nm, murk_mem_item *it)
{
    const struct murk_field *f;
    const struct murk_bound_grid *g;
    float factor;
    murk_density_parts(nm->density, &f, &g, &factor);
    murk_field_info fi;
    murk_field_describe(f, &fi);
    int res[3];
    murk_field_grid(f, res, NULL);
    size_t cells = (size_t)g->res[0] * (size_t)g->res[1] * (size_t)g->res[2];
    snprintf(it->name, sizeof it->name, "%s", nm->name);
    it->bytes = fi.bytes + 2 * cells * sizeof(float);
    if (fi.sparse) {
        it->dense_bytes = (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2] * sizeof(float);
        snprintf(it->detail, sizeof it->detail, "sparse %dx%dx%d (dense: %.1f MiB), %llu active voxels in %zu bricks; "
                 "bound grid %zu cells", res[0], res[1], res[2], (double)it->dense_bytes / 1048576.0,
                 (unsigned long long)fi.active, fi.bricks, cells);
    }
    else if (fi.held_dense) {
        it->sparse_bytes = fi.sparse_bytes;
        snprintf(it->detail, sizeof it->detail, "dense %dx%dx%d, a sparse grid held dense (sparse: %.1f MiB), %llu "
                 "active voxels; bound grid %zu cells", res[0], res[1], res[2], (double)fi.sparse_bytes / 1048576.0,
                 (unsigned long long)fi.active, cells);
    } else if (fi.grid)
        snprintf(it->detail, sizeof it->detail, "dense %dx%dx%d; bound grid %zu cells", res[0], res[1], res[2], cells);
    else
        snprintf(it->detail, sizeof it->detail, "constant");
}

MURK_API size_t murk_scene_memory(const murk_scene *s, murk_mem_item *items, size_t cap)
{
    size_t n = 0;
    for (size_t i = 0; i < s->nmedia; i++)
        if (s->media[i].density)
            grid_item(&s->media[i], next_item(items, cap, &n, "grid"));
    for (size_t i = 0; i < s->nshapes; i++) {
        const murk_shape *sh = &s->shapes[i];
        if (sh->type != MURK_SHAPE_MESH)
            continue;
        murk_mem_item *it = next_item(items, cap, &n, "mesh");
        snprintf(it->name, sizeof it->name, "%s", sh->name ? sh->name : "(mesh)");
        snprintf(it->detail, sizeof it->detail, "shape %zu: %u vertices, %u triangles", i, sh->nverts, sh->ntris);
        it->bytes = (uint64_t)sh->nverts * (3 + (sh->uv ? 2 : 0) + (sh->nrm ? 3 : 0)) * sizeof(float) +
                    (uint64_t)sh->ntris * (3 * sizeof(uint32_t) + (sh->ng ? 3 * sizeof(float) : 0));
    }
    for (size_t i = 0; i < s->ntextures; i++) {
        murk_mem_item *it = next_item(items, cap, &n, "texture");
        const char *name;
        it->bytes = murk_texture_bytes(s->textures[i], &name);
        snprintf(it->name, sizeof it->name, "%s", name);
    }
    murk_mem_item *it = next_item(items, cap, &n, "embree");
    snprintf(it->name, sizeof it->name, "scene");
    snprintf(it->detail, sizeof it->detail, "BVH and Embree's copies of the vertex and index buffers");
    long long eb = __atomic_load_n(&s->embree_bytes, __ATOMIC_RELAXED);
    it->bytes = eb > 0 ? (uint64_t)eb : 0;
    return n;
}
