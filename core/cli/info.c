/* info.c — `murk info SCENE.yaml [--set KEY.PATH=VALUE ...]`: loads a scene as `murk render` does (same
 * checks, same messages) and lists what it holds: render settings, camera, integrator, media (tracker,
 * transmittance estimator, density, majorant grid), materials, shapes (material, interior, exterior), the
 * lights (the `lights:` block's and assets', each with where it came from) and every plugin loaded, with its file. Renders nothing. Given an image instead (IMAGE.png, IMAGE.exr): its
 * size and text keys, murk:commit among them. Part of the murk executable, not of libmurk. */
#include "cli/cli.h"
#include "image/image.h"
#include "load/load.h"
#include "media/density.h"
#include "media/media.h"
#include "render/envmap.h"
#include "scene/scene.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* A scene node inline, as YAML flow ("[0.5, 0.5, 0.5]", "{ seed: 7, coverage: 0.7 }"), made printable;
 * keys in skip[] are left out of a map. */
static void put_node(const murk_ynode *n, const char *const *skip, size_t nskip)
{
    char buf[1024];
    if (!n) {
        fputs("~", stdout);
        return;
    }
    if (n->kind == MURK_Y_SCALAR) {
        fputs(murk_printable(buf, sizeof buf, n->str), stdout);
        return;
    }
    int map = n->kind == MURK_Y_MAP, first = 1;
    fputs(map ? "{ " : "[", stdout);
    for (size_t i = 0; i < n->n; i++) {
        int skipped = 0;
        for (size_t k = 0; map && k < nskip; k++)
            skipped |= !strcmp(n->keys[i], skip[k]);
        if (skipped)
            continue;
        fputs(first ? "" : ", ", stdout);
        first = 0;
        if (map)
            printf("%s: ", murk_printable(buf, sizeof buf, n->keys[i]));
        put_node(n->items[i], NULL, 0);
    }
    fputs(map ? (first ? "}" : " }") : "]", stdout);
}

/* A plugin block's own keys after its name: "diffuse { albedo: 0.5 }", or the name alone. */
static void put_block(const murk_plugin *p, const murk_ynode *block, const char *const *skip, size_t nskip)
{
    printf("%s", p->desc->name);
    size_t shown = 0;
    for (size_t i = 0; block && block->kind == MURK_Y_MAP && i < block->n; i++) {
        int skipped = 0;
        for (size_t k = 0; k < nskip; k++)
            skipped |= !strcmp(block->keys[i], skip[k]);
        shown += !skipped;
    }
    if (shown) {
        putchar(' ');
        put_node(block, skip, nskip);
    }
}

static void put_vec(const char *label, murk_vec3 v) { printf("%s [%g, %g, %g]", label, v.x, v.y, v.z); }
static void put_rgb(const char *label, murk_rgb c) { printf("%s [%g, %g, %g]", label, c.c[0], c.c[1], c.c[2]); }

static const char *bytes_text(char *buf, size_t n, uint64_t b);

static void info_medium(const murk_named_medium *nm, const murk_ynode *block)
{
    /* the keys the core reads (shown below), not the tracker's own: "type", the special keys, the schema */
    const char *own[3 + MURK_MEDIUM_NCORE] = {"type", murk_medium_special_keys[0], murk_medium_special_keys[1]};
    for (int i = 0; i < MURK_MEDIUM_NCORE; i++)
        own[3 + i] = murk_medium_core_params[i].name;
    char buf[256];
    printf("  %s\n    tracker        ", murk_printable(buf, sizeof buf, nm->name));
    put_block(nm->plugin, block, own, sizeof own / sizeof own[0]);
    printf("\n    transmittance  ");
    const murk_plugin *tp = nm->tr_plugin;
    const murk_ynode *tn = murk_ymap_get(block, "transmittance");
    static const char *const type_only[] = {"type"};
    if (tp)
        put_block(tp, tn, type_only, 1);
    else
        printf("the tracker's own (%s)", nm->plugin->desc->name);
    const murk_medium_data *md = &nm->data;
    printf("\n    coefficients  ");
    put_rgb(" sigma_a", md->sigma_a);
    put_rgb(", sigma_s", md->sigma_s);
    printf(" (per unit density, scale applied), g %g\n", md->g);
    const murk_ynode *dn = murk_ymap_get(block, "density");
    const murk_field *f;
    const murk_bound_grid *g;
    float factor;
    murk_density_parts(nm->density, &f, &g, &factor);
    int res[3];
    murk_field_grid(f, res, NULL);
    murk_field_info fi;
    murk_field_describe(f, &fi);
    murk_vec3 lo, hi;
    murk_field_bounds(f, &lo, &hi, NULL);
    printf("    density        ");
    if (dn)
        put_node(dn, NULL, 0);
    else
        printf("{ constant: 1 } (default)");
    char b1[32], b2[32];
    if (fi.grid)
        printf(": %s grid %dx%dx%d voxels over [%g, %g, %g]-[%g, %g, %g]%s, max %g", fi.sparse ? "sparse" : "dense",
               res[0], res[1], res[2], lo.x, lo.y, lo.z, hi.x, hi.y, hi.z,
               fi.transformed ? " (a rotated box: its bound grid is in index space)" : "", murk_field_max(f));
    else
        printf(": constant %g, everywhere", murk_field_max(f));
    if (fi.sparse)
        printf("\n                   %llu active voxels in %zu bricks of 8^3, %s held (dense it would be %s)",
               (unsigned long long)fi.active, fi.bricks, bytes_text(b1, sizeof b1, fi.bytes),
               bytes_text(b2, sizeof b2, (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2] * sizeof(float)));
    else if (fi.held_dense) /* sparse.c's rule: held dense when that is no larger */
        printf("\n                   %llu active voxels, held dense: %s (sparse it would be %s)",
               (unsigned long long)fi.active, bytes_text(b1, sizeof b1, fi.bytes),
               bytes_text(b2, sizeof b2, fi.sparse_bytes));
    float st = murk_rgb_max(murk_rgb_add(md->sigma_a, md->sigma_s));
    printf("\n    majorant       %dx%dx%d cells, majorant_factor %g; largest majorant %g (extinction %g x density "
           "%g x factor)\n", g->res[0], g->res[1], g->res[2], factor,
           (double)(st * murk_field_max(f) * factor), st, murk_field_max(f));
    printf("    flights        stratify_flights %s\n", md->stratify_flights ? "true" : "false");
}

static const char *medium_name(const murk_medium *m) { return m ? m->name : "vacuum"; }

/* The lights of the `lights:` block and of assets (KHR_lights_punctual), each with where it came from
 * (emissive shapes are listed with the shapes). */
static void info_lights(const murk_scene *s)
{
    char buf[600];
    printf("lights (%zu)\n", s->nadded);
    for (size_t i = 0; i < s->nadded; i++) {
        const murk_light *l = &s->added[i];
        const char *where = "added from C";
        for (size_t k = 0; k < s->nlight_origins; k++)
            if (i >= s->light_origins[k].first && i < s->light_origins[k].first + s->light_origins[k].n)
                where = s->light_origins[k].where;
        switch (l->kind) {
        case MURK_LK_POINT:
            printf("  %-3zu point  ", i);
            put_vec(" position", l->center);
            put_rgb(", intensity", l->le);
            printf(" W/sr");
            break;
        case MURK_LK_SPOT:
            printf("  %-3zu spot   ", i);
            put_vec(" position", l->center);
            put_vec(", direction", l->n);
            put_rgb(", intensity", l->le);
            printf(" W/sr, cone_angle %g, falloff_angle %g", acos(fmin(1.0, fmax(-1.0, l->cos_cone))) * 180.0 / M_PI,
                   acos(fmin(1.0, fmax(-1.0, l->cos_falloff))) * 180.0 / M_PI);
            break;
        case MURK_LK_DISTANT:
            printf("  %-3zu distant", i);
            put_vec(" direction", l->n);
            put_rgb(", irradiance", l->le);
            printf(" W/m^2, angular_diameter %g", l->omc > 0.0f ? 2.0 * acos(1.0 - l->omc) * 180.0 / M_PI : 0.0);
            break;
        default:
            printf("  %-3zu envmap ", i);
            if (l->env)
                printf(" %dx%d texels (scale applied)", l->env->w, l->env->h);
            else
                put_rgb(" constant radiance", l->le);
        }
        printf(", from %s\n", murk_printable(buf, sizeof buf, where));
    }
}

static void info_scene(const murk_scene *s, const char *path, const char *const *sets, size_t nsets)
{
    char buf[1024];
    const murk_ynode *root = s->doc.root;
    printf("scene       %s\n", murk_printable(buf, sizeof buf, path));
    for (size_t i = 0; i < nsets; i++)
        printf("%s%s\n", i ? "            --set " : "overrides   --set ", murk_printable(buf, sizeof buf, sets[i]));
    printf("render      %dx%d, %d spp, seed %llu, exposure %g\n", s->width, s->height, s->spp,
           (unsigned long long)s->seed, s->exposure);
    printf("camera     ");
    put_vec(" from", s->cam_from);
    put_vec(" at", s->cam_at);
    put_vec(" up", s->cam_up);
    printf(", fov %g, starts in %s\n", s->fov, medium_name(s->camera_medium));
    put_rgb("background ", s->background);
    printf("\nintegrator  ");
    static const char *const type_only[] = {"type"};
    put_block(s->integrator_plugin, murk_ymap_get(root, "integrator"), type_only, 1);
    const murk_ynode *media = murk_ymap_get(root, "media");
    printf("\nmedia (%zu)\n", s->nmedia);
    for (size_t i = 0; i < s->nmedia; i++)
        info_medium(&s->media[i], murk_ymap_get(media, s->media[i].name));
    const murk_ynode *mats = murk_ymap_get(root, "materials");
    printf("materials (%zu)\n", s->nmaterials + s->nasset_materials);
    for (size_t i = 0; i < s->nmaterials; i++) {
        printf("  %-14s ", murk_printable(buf, sizeof buf, s->materials[i].name));
        put_block(s->materials[i].plugin, murk_ymap_get(mats, s->materials[i].name), type_only, 1);
        putchar('\n');
    }
    for (size_t i = 0; i < s->nasset_materials; i++) { /* made from assets' own (material: from_file) */
        printf("  %-14s ", murk_printable(buf, sizeof buf, s->asset_materials[i]->name));
        put_block(s->asset_materials[i]->plugin, s->asset_docs[i]->root, type_only, 1);
        putchar('\n');
    }
    static const char *const shape_type[] = {"quad", "sphere", "box", "mesh"};
    printf("shapes (%zu)\n", s->nshapes);
    for (size_t i = 0; i < s->nshapes; i++) {
        const murk_shape *sh = &s->shapes[i];
        printf("  %-3zu %-6s material %s, interior %s, exterior %s", i, shape_type[sh->type],
               sh->material ? sh->material->name : "none (index-matched boundary)", medium_name(sh->interior),
               medium_name(sh->exterior));
        if (!murk_rgb_is_black(sh->emission))
            put_rgb(", emission", sh->emission);
        if (sh->type == MURK_SHAPE_MESH && sh->name) /* a mesh's file, or an asset's file#mesh */
            printf(", file %s (%u triangles)", murk_printable(buf, sizeof buf, sh->name), sh->ntris);
        putchar('\n');
    }
    info_lights(s);
    printf("plugins (%zu)\n", s->reg.nloaded);
    for (size_t i = 0; i < s->reg.nloaded; i++) {
        const murk_plugin *p = s->reg.loaded[i];
        printf("  %-13s %-16s %s (version %s, ABI %u.%u)\n", murk_kind_name((int)p->desc->kind), p->desc->name,
               murk_printable(buf, sizeof buf, p->path), p->version ? p->version : "none", p->abi.major, p->abi.minor);
    }
}

/* Bytes in binary units: "512 B", "3.4 KiB", "139.8 MiB". */
static const char *bytes_text(char *buf, size_t n, uint64_t b)
{
    static const char *const unit[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    double v = (double)b;
    int u = 0;
    while (v >= 1024.0 && u < 4)
        v /= 1024.0, u++;
    snprintf(buf, n, u ? "%.1f %s" : "%.0f %s", v, unit[u]);
    return buf;
}

void murk_cli_memory_print(FILE *f, const murk_scene *s, int detail)
{
    size_t n = murk_scene_memory(s, NULL, 0);
    murk_mem_item *it = murk_xmalloc((n ? n : 1) * sizeof *it);
    murk_scene_memory(s, it, n);
    static const char *const kinds[] = {"grid", "mesh", "texture", "embree"};
    static const char *const plural[] = {"grids", "meshes", "textures", "Embree"};
    uint64_t total[4] = {0}, all = 0, dense = 0, held = 0;
    char b1[32], b2[32];
    if (detail)
        fprintf(f, "memory (bytes held as allocated; README, Limits)\n");
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 4; k++)
            if (!strcmp(it[i].kind, kinds[k]))
                total[k] += it[i].bytes;
        all += it[i].bytes;
        dense += it[i].dense_bytes;
        held += it[i].sparse_bytes != 0;
        if (detail)
            fprintf(f, "  %-8s %-24s %10s  %s\n", it[i].kind, murk_cli_q(it[i].name), bytes_text(b1, sizeof b1, it[i].bytes),
                    murk_cli_q(it[i].detail));
    }
    long peak = murk_peak_rss_kb();
    if (detail) {
        fprintf(f, "  %-33s %10s\n", "total", bytes_text(b1, sizeof b1, all));
        if (peak >= 0)
            fprintf(f, "  peak resident memory of this process (VmHWM) %s\n", bytes_text(b2, sizeof b2, (uint64_t)peak * 1024));
    } else {
        fprintf(f, "memory:");
        for (int k = 0; k < 4; k++) {
            fprintf(f, "%s %s %s", k ? "," : "", plural[k], bytes_text(b1, sizeof b1, total[k]));
            if (k == 0 && (dense || held)) {
                fputs(" (", f);
                if (dense) /* sparse grids: what their voxels would take dense */
                    fprintf(f, "sparse; dense %s", bytes_text(b2, sizeof b2, dense));
                if (held) /* .vdb / .nvdb grids held dense by sparse.c's rule: counted dense above */
                    fprintf(f, "%s%llu sparse grid%s held dense, at most 1/16 larger", dense ? "; " : "",
                            (unsigned long long)held, held > 1 ? "s" : "");
                fputc(')', f);
            }
        }
        if (peak >= 0)
            fprintf(f, "; peak resident %s", bytes_text(b2, sizeof b2, (uint64_t)peak * 1024));
        fputc('\n', f);
    }
    free(it);
}

murk_scene *murk_cli_load(const char *path, const char *const *sets, size_t nsets)
{
    char err[2048];
    murk_scene *s = murk_scene_load(path, sets, nsets, err, sizeof err);
    if (s && murk_scene_check_unused(s, err, sizeof err)) {
        murk_scene_free(s);
        s = NULL;
    }
    if (!s)
        fprintf(stderr, "%s\n", err);
    return s;
}

/* 1 if path names an image murk info reads instead of a scene (by its extension, any case). */
static int image_path(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && (!strcasecmp(path + n - 4, ".png") || !strcasecmp(path + n - 4, ".exr"));
}

/* `murk info IMAGE`: its size and its text keys (PNG tEXt/zTXt/iTXt, EXR string attributes), one a line. */
static int info_image(const char *path)
{
    murk_image img;
    char err[1024], k[256], v[4096];
    size_t n = strlen(path);
    int rc = !strcasecmp(path + n - 4, ".png") ? murk_png_read(path, 1, &img, err, sizeof err)
                                                : murk_exr_read(path, &img, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    printf("%s: %dx%d\n", murk_printable(v, sizeof v, path), img.w, img.h);
    for (int i = 0; i < img.nmeta; i++)
        printf("%s: %s\n", murk_printable(k, sizeof k, img.meta[i].key), murk_printable(v, sizeof v, img.meta[i].value));
    murk_image_free(&img);
    return 0;
}

int murk_cli_info(int argc, char **argv)
{
    const char *scene_path = NULL;
    const char **sets = murk_xmalloc(((size_t)argc + 1) * sizeof *sets);
    size_t nsets = 0;
    char buf[1024], buf2[1024];
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--set")) {
            if (i + 1 >= argc) {
                free(sets);
                fprintf(stderr, "murk: --set needs KEY.PATH=VALUE\n");
                return 2;
            }
            sets[nsets++] = argv[++i];
        } else if (!strncmp(a, "--set=", 6)) {
            sets[nsets++] = a + 6;
        } else if (a[0] == '-' && a[1]) {
            free(sets);
            fprintf(stderr, "murk: unknown info option '%s'\nusage: murk info SCENE.yaml [--set KEY.PATH=VALUE ...]\n",
                    murk_printable(buf, sizeof buf, a));
            return 2;
        } else if (!scene_path) {
            scene_path = a;
        } else {
            free(sets);
            fprintf(stderr, "murk: more than one scene given ('%s' and '%s')\n",
                    murk_printable(buf, sizeof buf, scene_path), murk_printable(buf2, sizeof buf2, a));
            return 2;
        }
    }
    if (scene_path && image_path(scene_path)) {
        free(sets);
        if (nsets) {
            fprintf(stderr, "murk: --set applies to a scene, not to the image '%s'\n", murk_printable(buf, sizeof buf, scene_path));
            return 2;
        }
        return info_image(scene_path);
    }
    if (!scene_path) {
        free(sets);
        fprintf(stderr, "murk: info needs a scene file\nusage: murk info SCENE.yaml [--set KEY.PATH=VALUE ...]\n");
        return 2;
    }
    murk_scene *s = murk_cli_load(scene_path, sets, nsets);
    if (!s) {
        free(sets);
        return 1;
    }
    info_scene(s, scene_path, sets, nsets);
    murk_cli_memory_print(stdout, s, 1);
    murk_scene_free(s);
    free(sets);
    return 0;
}
