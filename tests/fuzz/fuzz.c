/* fuzz.c — libFuzzer harnesses for murk's input readers (issue 10, item 5). One source, one harness per
 * FUZZ_<TARGET> macro (tests/fuzz/meson.build builds each):
 *   scene  the YAML scene loader with every plugin's schema; leading lines "#set KEY.PATH=VALUE" of the
 *          input are --set overrides, the rest is the scene (paths are relative to a scratch folder)
 *   obj    the Wavefront OBJ loader          vol   the Mitsuba .vol reader
 *   nvdb   the NanoVDB reader                png   PNG textures (sRGB decode)
 *   exr    EXR reading, as `murk compare` does it
 *   vdb    the OpenVDB reader (C++ shim and sparse builder): the only grid, then the grid "density"
 *   asset  `type: asset` shapes through Assimp: the first byte picks the file's kind (glTF, binary glTF, PLY,
 *          FBX, OBJ), the rest is the file, loaded by a scene that takes its materials, lights and camera
 * The readers take paths, so each input is written to a scratch file first. Plugins are built with the
 * same instrumentation (meson's -Dfuzz=enabled applies it project-wide). */
#include "media/density.h"
#include "image/image.h"
#include "murk/murk.h"
#include "scene/obj.h"
#include "util/runtime.h"
#include "util/util.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char scratch_dir[4096], scratch[4200];

static const char *scratch_file(const uint8_t *data, size_t size, const char *name)
{
    if (!scratch_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(scratch_dir, sizeof scratch_dir, "%s/murk-fuzz-XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(scratch_dir))
            abort();
    }
    snprintf(scratch, sizeof scratch, "%s/%s", scratch_dir, name);
    FILE *f = fopen(scratch, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        abort();
    return scratch;
}

#if defined(FUZZ_SCENE)
/* Plugins stay loaded: libFuzzer keeps reading an instrumented module's coverage counters, which a
 * dlclose() would unmap. This definition takes the place of libc's for the loader in this harness. */
int dlclose(void *handle)
{
    (void)handle;
    return 0;
}

/* The files seed scenes refer to (mesh.obj, grid.vol, tex.png) are made once in the scratch folder. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    murk_set_quiet(1);
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n";
    scratch_file((const uint8_t *)obj, sizeof obj - 1, "mesh.obj");
    char err[1024], path[4200];
    murk_field *f = murk_field_cloud(murk_v3(-0.5f, 0, -0.5f), murk_v3(0.5f, 1, 0.5f), 4, 7, 3, 2, 0.5f);
    snprintf(path, sizeof path, "%s/grid.vol", scratch_dir);
    if (!f || murk_field_vol_save(path, f, err, sizeof err) != 0)
        abort();
    murk_field_free(f);
    static const float rgb[12] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1, 0, 0.5f};
    snprintf(path, sizeof path, "%s/tex.png", scratch_dir);
    if (murk_png_write(path, rgb, 2, 2, 0, err, sizeof err) != 0)
        abort();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 65536)
        return 0;
    /* leading "#set ..." lines are overrides (at most 8) */
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = 0;
    const char *sets[8];
    size_t nsets = 0, off = 0;
    while (nsets < 8 && off < size && strncmp(text + off, "#set ", 5) == 0) {
        char *nl = memchr(text + off, '\n', size - off);
        if (!nl)
            break;
        *nl = 0;
        sets[nsets++] = text + off + 5;
        off = (size_t)(nl - text) + 1;
    }
    const char *path = scratch_file((const uint8_t *)text + off, size - off, "scene.yaml");
    char err[2048];
    murk_scene *s = murk_scene_load(path, sets, nsets, err, sizeof err);
    if (s)
        murk_scene_free(s);
    free(text);
    return 0;
}
#elif defined(FUZZ_OBJ)
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    murk_mesh m;
    char err[1024];
    if (murk_obj_load(scratch_file(data, size, "mesh.obj"), &m, err, sizeof err) == 0)
        murk_mesh_free(&m);
    return 0;
}
#elif defined(FUZZ_VOL) || defined(FUZZ_NVDB)
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[1024];
#ifdef FUZZ_VOL
    murk_field *f = murk_field_vol_load(scratch_file(data, size, "grid.vol"), err, sizeof err);
#else
    murk_field *f = murk_field_nvdb_load(scratch_file(data, size, "grid.nvdb"), err, sizeof err);
#endif
    if (f) {
        murk_vec3 lo, hi;
        murk_field_bounds(f, &lo, &hi, NULL);
        (void)murk_field_eval(f, murk_v3(0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y), 0.5f * (lo.z + hi.z)));
        murk_field_free(f);
    }
    return 0;
}
#elif defined(FUZZ_VDB)
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[2048];
    const char *path = scratch_file(data, size, "grid.vdb");
    for (int k = 0; k < 2; k++) {
        murk_field *f = murk_field_vdb_load(path, k ? "density" : NULL, NULL, err, sizeof err);
        if (f) {
            murk_vec3 lo, hi;
            murk_field_bounds(f, &lo, &hi, NULL);
            (void)murk_field_eval(f, murk_v3(0.5f * (lo.x + hi.x), 0.5f * (lo.y + hi.y), 0.5f * (lo.z + hi.z)));
            murk_bound_grid g;
            if (murk_bound_grid_build(f, 8, &g) == 0)
                murk_bound_grid_free(&g);
            murk_field_free(f);
        }
    }
    return 0;
}
#elif defined(FUZZ_ASSET)
int dlclose(void *handle) /* as for the scene harness: plugins stay loaded */
{
    (void)handle;
    return 0;
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    murk_set_quiet(1);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const ext[] = {"gltf", "glb", "ply", "fbx", "obj"};
    if (size < 1 || size > 65536)
        return 0;
    char name[32], scene[512];
    snprintf(name, sizeof name, "asset.%s", ext[data[0] % 5]);
    scratch_file(data + 1, size - 1, name);
    snprintf(scene, sizeof scene, "murk: 1\nrender: { resolution: [8, 8] }\ncamera: { from_asset: 0 }\n"
             "shapes:\n  - { type: asset, file: %s, material: from_file }\n", name);
    const char *path = scratch_file((const uint8_t *)scene, strlen(scene), "scene.yaml");
    char err[2048];
    murk_scene *s = murk_scene_load(path, NULL, 0, err, sizeof err);
    if (s)
        murk_scene_free(s);
    return 0;
}
#elif defined(FUZZ_PNG) || defined(FUZZ_EXR)
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    murk_image img = {0};
    char err[1024];
#ifdef FUZZ_PNG
    int rc = murk_png_read(scratch_file(data, size, "tex.png"), 1, &img, err, sizeof err);
#else
    int rc = murk_exr_read(scratch_file(data, size, "img.exr"), &img, err, sizeof err);
#endif
    if (rc == 0 && img.w > 0) { /* touch every pixel as compare does */
        volatile float acc = 0;
        for (size_t i = 0; i < 3 * (size_t)img.w * (size_t)img.h; i++)
            acc += img.rgb[i];
        (void)acc;
    }
    murk_image_free(&img);
    return 0;
}
#else
#error "define one FUZZ_<TARGET>"
#endif
