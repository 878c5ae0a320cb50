/* test_assets.c — `type: asset` shapes read through Assimp (core/load/asset.c), against the same things said in
 * murk's own terms. Every file is written here: OBJ, PLY and glTF (JSON with an embedded buffer, and binary
 * .glb) by hand, FBX by Assimp's own exporter (its ASCII form: Debian's Assimp 5.2.5 cannot read back its
 * binary FBX). The mesh's coordinates are multiples of 1/64, exact in every format (FBX ASCII prints 6
 * decimals), so each file holds the same floats.
 *
 *   formats      the mesh as .obj (murk's reader, type: mesh), and as .obj, .ply, .gltf, .glb, .fbx through
 *                Assimp: bitwise the same image; one vertex moved by 1/64 must differ.
 *   material     a glTF metallic-roughness material (base colour, metallic 0.25, roughness 0.6, an emissive
 *                factor) with material: from_file renders bitwise as the
 *                OBJ with the documented ggx (albedo = base (1 - m), specular = 0.04 (1 - m) + base m) and the
 *                emission; the ggx without the metallic mix (albedo = base) must differ.
 *   camera       a glTF camera node (translated, rotated, yfov) taken with camera: { from_asset: N } renders as
 *                the YAML camera at its place; a yfov 5 % wider must differ.
 *   lights       KHR_lights_punctual point and directional lights render as the `lights:` block's.
 *   scene        tools/make_gem.py writes the bytes committed in scenes/gem/ (twice the same), and
 *                scenes/gem_asset.yaml (a PLY and a glTF with its materials, camera and spot lamp) renders a few
 *                spp with every pixel finite and >= 0.
 *   textures     a glTF quad with a base colour texture (external PNG; embedded in a .glb) renders bitwise as the
 *                YAML quad with the same PNG as its ggx albedo (upside down in v must differ); a uniform
 *                metallicRoughness texture times the factors as the mapped ggx (the mix left out must differ);
 *                KHR_materials_emissive_strength 4 as the YAML emission x 4 (without it must differ).
 *   uv origin    an emissive texture of four coloured quadrants seen straight down: each quadrant where glTF's
 *                convention (texture coordinate (0, 0) at the image's top-left) puts it.
 *   emission     an emissive texture half white, half black lights the room as its white half as an emissive
 *                OBJ mesh (block-wise z over independent seeds, stat.h); the other half emitting must differ.
 *   info lights  murk info lists the lights: block's spot and the glTF's point light, each with its origin.
 *   bad texture  a glTF whose texture file is missing: a located error naming it, no image.
 *   resume       a checkpoint of a scene whose .gltf reads an external .bin buffer and an external PNG texture:
 *                resumed while neither changed, refused after the .bin changed, and after the PNG changed.
 *   bad input    no mesh, a NaN vertex, a missing buffer, random bytes, truncated JSON, a PLY header without
 *                end_header (Assimp 5.2 hangs on it), a face of no vertices (Assimp 5.2 aborts), an unknown
 *                extension, a directory, from_asset naming a quad or an asset without a camera: `murk render`
 *                exits 1 with "scene.yaml:LINE:COL:" and writes no image. */
#include "testutil.h"
#include "image/image.h"
#include "stat.h"

#ifdef MURK_HAVE_ASSIMP
#include <assimp/cexport.h>
#include <assimp/cimport.h>
#include <assimp/scene.h>
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* A gem: 6 vertices, 8 triangles, outward winding; coordinates in 1/64 steps. */
static const float V[6][3] = {{0, 0.125f, 0}, {0.375f, 0.5f, 0.0625f}, {-0.0625f, 0.5f, 0.375f},
                              {-0.34375f, 0.5f, -0.125f}, {0.0625f, 0.5f, -0.3125f}, {0, 0.90625f, 0}};
static const unsigned F[8][3] = {{0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {0, 1, 4}, {5, 1, 2}, {5, 2, 3}, {5, 3, 4}, {5, 4, 1}};

static void write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_true(fwrite(data, 1, n, f) == n);
    assert_int_equal(fclose(f), 0);
}

static const char *write_obj(const char *name, float dy)
{
    char text[2048];
    size_t k = 0;
    for (int i = 0; i < 6; i++)
        k += (size_t)snprintf(text + k, sizeof text - k, "v %.9g %.9g %.9g\n", (double)V[i][0],
                              (double)(V[i][1] + (i == 5 ? dy : 0.0f)), (double)V[i][2]);
    for (int t = 0; t < 8; t++)
        k += (size_t)snprintf(text + k, sizeof text - k, "f %u %u %u\n", F[t][0] + 1, F[t][1] + 1, F[t][2] + 1);
    return write_tmp(name, text);
}

static const char *write_ply(const char *name)
{
    char text[2048];
    size_t k = (size_t)snprintf(text, sizeof text, "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 8\nproperty list uchar int vertex_indices\n"
                                "end_header\n");
    for (int i = 0; i < 6; i++)
        k += (size_t)snprintf(text + k, sizeof text - k, "%.9g %.9g %.9g\n", (double)V[i][0], (double)V[i][1], (double)V[i][2]);
    for (int t = 0; t < 8; t++)
        k += (size_t)snprintf(text + k, sizeof text - k, "3 %u %u %u\n", F[t][0], F[t][1], F[t][2]);
    return write_tmp(name, text);
}

/* The mesh's buffer: 6 float3 positions (72 bytes), then 24 uint16 indices (48 bytes). */
static size_t mesh_buffer(unsigned char *b, int nan_vertex)
{
    float p[18];
    for (int i = 0; i < 6; i++)
        for (int a = 0; a < 3; a++)
            p[3 * i + a] = V[i][a];
    if (nan_vertex)
        p[7] = NAN;
    memcpy(b, p, sizeof p);
    for (int t = 0; t < 8; t++)
        for (int k = 0; k < 3; k++) {
            uint16_t v = (uint16_t)F[t][k];
            memcpy(b + 72 + 2 * (3 * t + k), &v, 2);
        }
    return 120;
}

static void base64(const unsigned char *in, size_t n, char *out)
{
    static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t k = 0;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)in[i] << 16 | (i + 1 < n ? (unsigned)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[k++] = a[v >> 18];
        out[k++] = a[(v >> 12) & 63];
        out[k++] = i + 1 < n ? a[(v >> 6) & 63] : '=';
        out[k++] = i + 2 < n ? a[v & 63] : '=';
    }
    out[k] = 0;
}

/* A glTF document around the mesh: `uri` is the buffer's (NULL: none, for a .glb's BIN chunk), `extra_nodes`
 * and `extra` are spliced in (nodes after node 0; top-level members), `material` is material 0's JSON (NULL:
 * none). */
static void gltf_json(char *out, size_t n, const char *uri, const char *material, const char *extra_nodes,
                      const char *extra, int nodes)
{
    char list[128] = "0";
    for (int i = 1; i < nodes; i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), ", %d", i);
    snprintf(out, n,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [%s]}],\n"
             "\"nodes\": [{\"name\": \"gem\", \"mesh\": 0}%s],\n"
             "\"meshes\": [{\"name\": \"gem\", \"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1%s}]}],\n"
             "%s%s%s"
             "\"buffers\": [{\"byteLength\": 120%s%s%s}],\n"
             "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 72}, {\"buffer\": 0, \"byteOffset\": 72, "
             "\"byteLength\": 48}],\n"
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 6, \"type\": \"VEC3\", "
             "\"min\": [-0.34375, 0.125, -0.3125], \"max\": [0.375, 0.90625, 0.375]},\n"
             "  {\"bufferView\": 1, \"componentType\": 5123, \"count\": 24, \"type\": \"SCALAR\"}]}\n",
             list, extra_nodes ? extra_nodes : "", material ? ", \"material\": 0" : "", material ? "\"materials\": [" : "",
             material ? material : "", material ? "],\n" : "", uri ? ", \"uri\": \"" : "", uri ? uri : "", uri ? "\"" : "");
    if (extra && *extra) { /* before the closing brace */
        size_t l = strlen(out);
        while (l && out[l - 1] != '}')
            l--;
        snprintf(out + l - 1, n - (l - 1), ",\n%s}\n", extra);
    }
}

static const char *write_gltf(const char *name, const char *material, const char *extra_nodes, const char *extra,
                              int nodes, int nan_vertex)
{
    unsigned char b[128];
    char uri[300], text[8192];
    size_t n = mesh_buffer(b, nan_vertex);
    strcpy(uri, "data:application/octet-stream;base64,");
    base64(b, n, uri + strlen(uri));
    gltf_json(text, sizeof text, uri, material, extra_nodes, extra, nodes);
    return write_tmp(name, text);
}

/* A binary glTF of the JSON text (room for 3 pad bytes after it) and the BIN chunk's nb bytes. */
static const char *write_glb_chunks(const char *name, char *json, const unsigned char *bin, size_t nb)
{
    size_t nj = strlen(json);
    while (nj % 4)
        json[nj++] = ' ';
    size_t total = 12 + 8 + nj + 8 + nb;
    unsigned char *out = malloc(total);
    assert_non_null(out);
    uint32_t h[3] = {0x46546C67u, 2, (uint32_t)total}, cj[2] = {(uint32_t)nj, 0x4E4F534Au}, cb[2] = {(uint32_t)nb, 0x004E4942u};
    memcpy(out, h, 12);
    memcpy(out + 12, cj, 8);
    memcpy(out + 20, json, nj);
    memcpy(out + 20 + nj, cb, 8);
    memcpy(out + 28 + nj, bin, nb);
    static char p[512];
    snprintf(p, sizeof p, "%s", tmp_path(name));
    write_file(p, out, total);
    free(out);
    return p;
}

static const char *write_glb(const char *name)
{
    unsigned char bin[128];
    char json[4096];
    size_t nb = mesh_buffer(bin, 0);
    gltf_json(json, sizeof json, NULL, NULL, NULL, NULL, 1);
    return write_glb_chunks(name, json, bin, nb);
}

#ifdef MURK_HAVE_ASSIMP
/* The OBJ written again as ASCII FBX by Assimp's exporter. */
static const char *write_fbx(const char *name, const char *obj)
{
    const struct aiScene *s = aiImportFile(obj, 0);
    if (!s)
        fail_msg("Assimp cannot read %s: %s", obj, aiGetErrorString());
    static char p[512];
    snprintf(p, sizeof p, "%s", tmp_path(name));
    if (aiExportScene(s, "fbxa", p, 0) != AI_SUCCESS)
        fail_msg("Assimp cannot write %s: %s", p, aiGetErrorString());
    aiReleaseImport(s);
    return p;
}
#endif

/* A small lit room around the mesh shape `shape` (a YAML flow map), with `camera` and `extra` (more top-level
 * YAML) if given; rendered at 32x32, 16 spp, seed 3 into tmp_dir()/out. */
static int small_renders; /* 1: 16x16 at 4 spp (the bitwise comparisons of textures need no more) */

static const char *render_scene(const char *shape, const char *materials, const char *camera, const char *extra,
                                const char *out)
{
    char text[4096];
    snprintf(text, sizeof text,
             "murk: 1\nrender: { resolution: %s, seed: 3 }\n"
             "camera: %s\n"
             "materials:\n  white: { type: diffuse, albedo: 0.7 }\n  shiny: { type: ggx, albedo: 0.5, specular: 0.3, roughness: 0.4 }\n%s"
             "%s"
             "shapes:\n  - { type: quad, center: [0, 0, 0], u: [2, 0, 0], v: [0, 0, -2], material: white }\n"
             "  - { type: quad, center: [0, 2, 0], u: [0.3, 0, 0], v: [0, 0, 0.3], material: shiny, emission: [12, 12, 12] }\n"
             "  - %s\n",
             small_renders ? "[16, 16], spp: 4" : "[32, 32], spp: 16",
             camera ? camera : "{ from: [0.3, 0.8, 2.2], at: [0, 0.5, 0], fov: 40 }", materials ? materials : "",
             extra ? extra : "", shape);
    const char *scene = write_tmp("asset_scene.yaml", text), *path = tmp_path(out);
    const char *args[] = {"render", scene, "-o", path, "--threads", "2", "--quiet", NULL};
    run_murk_ok(args, NULL);
    static char keep[8][512];
    static int next;
    char *k = keep[next++ & 7];
    snprintf(k, sizeof keep[0], "%s", path);
    return k;
}

static void need_assimp(void)
{
#ifndef MURK_HAVE_ASSIMP
    skip();
#endif
}

static int nfail;

static void expect(int same, int want, const char *what)
{
    printf("  %-60s %s%s\n", what, same ? "bitwise the same" : "DIFFER", same == want ? "" : "  <-- FAIL");
    nfail += same != want;
}

static void test_formats(void **state)
{
    (void)state;
    need_assimp();
    nfail = 0;
    char shape[1200], obj[512];
    snprintf(obj, sizeof obj, "%s", write_obj("gem.obj", 0.0f));
    snprintf(shape, sizeof shape, "{ type: mesh, file: %s, material: shiny }", obj);
    const char *ref = render_scene(shape, NULL, NULL, NULL, "ref.exr");
    char files[5][512]; /* copies: the helpers' paths are rotating buffers */
    snprintf(files[0], sizeof files[0], "%s", obj);
    snprintf(files[1], sizeof files[1], "%s", write_ply("gem.ply"));
    snprintf(files[2], sizeof files[2], "%s", write_gltf("gem.gltf", NULL, NULL, NULL, 1, 0));
    snprintf(files[3], sizeof files[3], "%s", write_glb("gem.glb"));
    snprintf(files[4], sizeof files[4], "%s", "none.fbx");
#ifdef MURK_HAVE_ASSIMP
    snprintf(files[4], sizeof files[4], "%s", write_fbx("gem.fbx", obj));
#endif
    static const char *const labels[5] = {"OBJ through Assimp", "PLY", "glTF (JSON, embedded buffer)", "glTF binary (.glb)",
                                          "FBX (ASCII, written by Assimp)"};
    for (int i = 0; i < 5; i++) {
        snprintf(shape, sizeof shape, "{ type: asset, file: %.511s, material: shiny }", files[i]);
        expect(same_pixels(render_scene(shape, NULL, NULL, NULL, "asset.exr"), ref), 1, labels[i]);
    }
    const char *moved = write_obj("gem_moved.obj", 0.015625f); /* must-fail: the apex 1/64 higher */
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: shiny }", moved);
    expect(same_pixels(render_scene(shape, NULL, NULL, NULL, "moved.exr"), ref), 0, "the apex 1/64 higher (must DIFFER)");
    assert_int_equal(nfail, 0);
}

static void test_material(void **state)
{
    (void)state;
    need_assimp();
    nfail = 0;
    const char *mat = "{\"name\": \"copper\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.3, 0.2, 1], "
                      "\"metallicFactor\": 0.25, \"roughnessFactor\": 0.6}, \"emissiveFactor\": [1, 0.5, 0.25]}";
    const char *g = write_gltf("mat.gltf", mat, NULL, NULL, 1, 0);
    char shape[600], mats[600];
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }", g);
    const char *a = render_scene(shape, NULL, NULL, NULL, "mat_gltf.exr");
    /* the documented mapping, in float as asset.c computes it */
    float base[3] = {0.8f, 0.3f, 0.2f}, m = 0.25f, al[3], sp[3];
    for (int c = 0; c < 3; c++) {
        al[c] = base[c] * (1.0f - m);
        sp[c] = 0.04f * (1.0f - m) + base[c] * m;
    }
    for (int k = 0; k < 2; k++) {
        snprintf(mats, sizeof mats, "  mapped: { type: ggx, albedo: [%.9g, %.9g, %.9g], specular: [%.9g, %.9g, %.9g], "
                 "roughness: %.9g }\n", (double)(k ? base[0] : al[0]), (double)(k ? base[1] : al[1]),
                 (double)(k ? base[2] : al[2]), (double)sp[0], (double)sp[1], (double)sp[2], (double)0.6f);
        snprintf(shape, sizeof shape, "{ type: mesh, file: %s, material: mapped, emission: [1, 0.5, 0.25] }",
                 write_obj("gem.obj", 0.0f));
        const char *b = render_scene(shape, mats, NULL, NULL, k ? "mat_unmixed.exr" : "mat_obj.exr");
        expect(same_pixels(a, b), !k, k ? "albedo = base colour, no metallic mix (must DIFFER)"
                                        : "glTF material from_file = OBJ with the mapped ggx and emission");
    }
    assert_int_equal(nfail, 0);
}

/* The rotation matrix of a quaternion (x, y, z, w as glTF writes it) in float, as Assimp's aiQuaternion::GetMatrix
 * computes it (the node transforms asset.c reads are Assimp's float matrices). */
static void qmat(const float q[4], float m[9])
{
    float x = q[0], y = q[1], z = q[2], w = q[3];
    m[0] = 1.0f - 2.0f * (y * y + z * z), m[1] = 2.0f * (x * y - z * w), m[2] = 2.0f * (x * z + y * w);
    m[3] = 2.0f * (x * y + z * w), m[4] = 1.0f - 2.0f * (x * x + z * z), m[5] = 2.0f * (y * z - x * w);
    m[6] = 2.0f * (x * z - y * w), m[7] = 2.0f * (y * z + x * w), m[8] = 1.0f - 2.0f * (x * x + y * y);
}

static void test_camera(void **state)
{
    (void)state;
    need_assimp();
    nfail = 0;
    /* the camera turned 0.4 rad about y, then tilted 0.3 rad down about its x: q = qy qx */
    double a = 0.2, b = -0.15, qy[4] = {0, sin(a), 0, cos(a)}, qx[4] = {sin(b), 0, 0, cos(b)};
    float q[4] = {(float)(qy[3] * qx[0] + qy[0] * qx[3] + qy[1] * qx[2] - qy[2] * qx[1]),
                  (float)(qy[3] * qx[1] - qy[0] * qx[2] + qy[1] * qx[3] + qy[2] * qx[0]),
                  (float)(qy[3] * qx[2] + qy[0] * qx[1] - qy[1] * qx[0] + qy[2] * qx[3]),
                  (float)(qy[3] * qx[3] - qy[0] * qx[0] - qy[1] * qx[1] - qy[2] * qx[2])};
    float t[3] = {0.875f, 1.125f, 2.0f}, yfov = 0.75f;
    char nodes[600], extra[300], shape[600], cam[600];
    snprintf(nodes, sizeof nodes, ", {\"name\": \"view\", \"camera\": 0, \"translation\": [%.9g, %.9g, %.9g], "
             "\"rotation\": [%.9g, %.9g, %.9g, %.9g]}", (double)t[0], (double)t[1], (double)t[2], (double)q[0],
             (double)q[1], (double)q[2], (double)q[3]);
    snprintf(extra, sizeof extra, "\"cameras\": [{\"name\": \"view\", \"type\": \"perspective\", \"perspective\": "
             "{\"yfov\": %.9g, \"aspectRatio\": 1.0, \"znear\": 0.01}}]", (double)yfov);
    const char *g = write_gltf("cam.gltf", NULL, nodes, extra, 2, 0);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: shiny }", g);
    const char *img = render_scene(shape, NULL, "{ from_asset: 2 }", NULL, "cam_gltf.exr");
    /* the same camera written out: from = t, at = t + R (0, 0, -1), up = R (0, 1, 0), fov = yfov in degrees */
    float m[9];
    qmat(q, m);
    for (int k = 0; k < 2; k++) {
        double fov = (double)yfov * (k ? 1.05 : 1.0) * 180.0 / M_PI;
        snprintf(cam, sizeof cam, "{ from: [%.9g, %.9g, %.9g], at: [%.9g, %.9g, %.9g], up: [%.9g, %.9g, %.9g], fov: %.9g }",
                 (double)t[0], (double)t[1], (double)t[2], (double)(float)((double)t[0] - m[2]),
                 (double)(float)((double)t[1] - m[5]), (double)(float)((double)t[2] - m[8]), (double)m[1], (double)m[4],
                 (double)m[7], (double)(float)fov);
        expect(same_pixels(img, render_scene(shape, NULL, cam, NULL, "cam_yaml.exr")), !k,
               k ? "the yfov 5 % wider (must DIFFER)" : "glTF camera (from_asset) = the YAML camera at its place");
    }
    assert_int_equal(nfail, 0);
}

static void test_lights(void **state)
{
    (void)state;
    need_assimp();
    nfail = 0;
    const float q[4] = {-0.382683432f, 0, 0, 0.923879533f}; /* -45 degrees about x */
    char nodes[600], lights[600], shape[600];
    snprintf(nodes, sizeof nodes, ", {\"name\": \"bulb\", \"translation\": [0.5, 1.25, 0.75], \"extensions\": "
             "{\"KHR_lights_punctual\": {\"light\": 0}}}, {\"name\": \"sun\", \"rotation\": [%.9g, 0, 0, %.9g], "
             "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}", (double)q[0], (double)q[3]);
    const char *extra = "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": "
                        "{\"lights\": [{\"type\": \"point\", \"color\": [1, 0.5, 0.25], \"intensity\": 2}, "
                        "{\"type\": \"directional\", \"color\": [1, 1, 1], \"intensity\": 0.5}]}}";
    const char *g = write_gltf("lights.gltf", NULL, nodes, extra, 3, 0);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: shiny }", g);
    const char *img = render_scene(shape, NULL, NULL, NULL, "lights_gltf.exr");
    float m[9]; /* the sun shines along R (0, 0, -1): its direction towards the light is R (0, 0, 1) */
    qmat(q, m);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: shiny, lights: false }", g); /* its lights left out */
    for (int k = 0; k < 2; k++) {
        snprintf(lights, sizeof lights, "lights:\n  - { type: point, position: [0.5, 1.25, 0.75], intensity: [2, 1, 0.5] }\n"
                 "  - { type: distant, direction: [%.9g, %.9g, %.9g], irradiance: %s, angular_diameter: 0 }\n",
                 (double)m[2], (double)m[5], (double)m[8], k ? "0.6" : "0.5");
        expect(same_pixels(img, render_scene(shape, NULL, NULL, lights, "lights_yaml.exr")), !k,
               k ? "the sun 20 % brighter (must DIFFER)" : "glTF point + directional = the lights: block's");
    }
    assert_int_equal(nfail, 0);
}

/* `murk render` of the room with shape: exit 1, "scene:LINE:COL: ... needle", no image. */
static void expect_error(const char *shape, const char *camera, const char *needle)
{
    char text[2048];
    snprintf(text, sizeof text, "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\n%s%s%s"
             "materials:\n  white: { type: diffuse }\nshapes:\n  - { type: quad, center: [0, 0, 0], u: [1, 0, 0], "
             "v: [0, 0, -1], material: white }\n  - %s\n", camera ? "camera: " : "", camera ? camera : "",
             camera ? "\n" : "", shape);
    const char *scene = write_tmp("bad_asset.yaml", text), *out = tmp_path("bad_asset.exr");
    remove(out);
    char *log = NULL;
    const char *args[] = {"render", scene, "-o", out, NULL};
    int rc = run_murk_argv(&log, args);
    char where[600];
    snprintf(where, sizeof where, "%s:", scene);
    assert_refused(log, rc, where, needle, out);
}

static void test_bad_input(void **state)
{
    (void)state;
    need_assimp();
    char shape[700], text[8192];
    /* no mesh: a document with a camera only */
    const char *nomesh = write_tmp("nomesh.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], "
                                   "\"nodes\": [{\"name\": \"c\", \"camera\": 0}], \"cameras\": [{\"type\": \"perspective\", "
                                   "\"perspective\": {\"yfov\": 0.7, \"znear\": 0.1}}]}");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", nomesh);
    expect_error(shape, NULL, "holds no triangle mesh");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", write_gltf("nan.gltf", NULL, NULL, NULL, 1, 1));
    expect_error(shape, NULL, "vertex 2 is not finite");
    gltf_json(text, sizeof text, "missing.bin", NULL, NULL, NULL, 1);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", write_tmp("nobuffer.gltf", text));
    expect_error(shape, NULL, "Assimp cannot read it");
    unsigned char junk[3000];
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (unsigned char)(i * 7919u >> 3);
    write_file(tmp_path("junk.glb"), junk, sizeof junk);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", tmp_path("junk.glb"));
    expect_error(shape, NULL, "Assimp cannot read it");
    gltf_json(text, sizeof text, "x", NULL, NULL, NULL, 1);
    text[strlen(text) / 2] = 0;
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", write_tmp("cut.gltf", text));
    expect_error(shape, NULL, "Assimp cannot read it");
    /* a PLY header without end_header, on which Assimp 5.2 reads forever (found by fuzz_asset) */
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }",
             write_tmp("noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nengd_header\n0\n1\n2\n"));
    expect_error(shape, NULL, "its PLY header has no 'end_header' line");
    /* a face of no vertices, on which Assimp 5.2's Triangulate step aborts (found by fuzz_asset) */
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }",
             write_tmp("emptyface.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n"));
    expect_error(shape, NULL, "mesh 0 face 1 has no vertices");
    expect_error("{ type: asset, file: model.stl, material: white }", NULL, "not a file murk reads as an asset");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s/, material: white }", tmp_dir());
    expect_error(shape, NULL, "not a file murk reads as an asset");
    mkdir(tmp_path("dir.gltf"), 0700);
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", tmp_path("dir.gltf"));
    expect_error(shape, NULL, "not a regular file");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s }", write_gltf("g.gltf", NULL, NULL, NULL, 1, 0));
    expect_error(shape, NULL, "asset has no material");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: white }", write_gltf("g.gltf", NULL, NULL, NULL, 1, 0));
    expect_error(shape, "{ from_asset: 0 }", "shapes[0] is not an asset shape");
    expect_error(shape, "{ from_asset: 1 }", "the file has no camera");
    expect_error(shape, "{ from_asset: 1, asset_camera: main }", "no camera 'main'");
    expect_error(shape, "{ from_asset: 1, from: [0, 0, 1] }", "'from' and from_asset exclude each other");
}

/* ---- textures, emission, lights in murk info ------------------------------------------------------------ */

/* A w x h texture of four quadrants (top-left red, top-right green, bottom-left blue, bottom-right white; row 0
 * at the top; flip: upside down), or of one colour c everywhere, written as an 8-bit PNG by murk's writer. */
static const char *write_png(const char *name, int w, int h, const float *c, int flip)
{
    static const float q[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    float *rgb = malloc(3u * (size_t)w * (size_t)h * sizeof(float));
    assert_non_null(rgb);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++)
                rgb[3 * (y * w + x) + k] = c ? c[k] : q[((y >= h / 2) != flip) * 2 + (x >= w / 2)][k];
    static char p[4][512];
    static int next;
    char *path = p[next++ & 3], err[512];
    snprintf(path, sizeof p[0], "%s", tmp_path(name));
    if (murk_png_write(path, rgb, w, h, 0.0f, err, sizeof err))
        fail_msg("%s", err);
    free(rgb);
    return path;
}

/* The quad center [0, 0.25, 0] +- [0.5, 0, 0] +- [0, 0, -0.5] as murk's `type: quad` makes it (load.c's put_quad:
 * its vertices, triangles and uv), as a glTF buffer: 4 float3 positions, 4 float2 texture coordinates in glTF's
 * convention (t = 1 - v: t = 0 is the image's top row), 6 uint16 indices; 92 bytes. */
static size_t quad_buffer(unsigned char *b)
{
    const float p[12] = {-0.5f, 0.25f, 0.5f, 0.5f, 0.25f, 0.5f, 0.5f, 0.25f, -0.5f, -0.5f, 0.25f, -0.5f};
    const float st[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint16_t ix[6] = {0, 1, 2, 0, 2, 3};
    memcpy(b, p, 48);
    memcpy(b + 48, st, 32);
    memcpy(b + 80, ix, 12);
    return 92;
}

#define QUAD_YAML "type: quad, center: [0, 0.25, 0], u: [0.5, 0, 0], v: [0, 0, -0.5]"

/* The quad as a glTF with material 0 `material` and the top-level members `extra` (images, textures): a .gltf
 * with its buffer embedded as base64, or (png: the bytes of image 0) a .glb whose BIN chunk holds the buffer and
 * then the PNG, image 0 a view of it. */
static const char *write_quad(const char *name, const char *material, const char *extra, const char *png)
{
    unsigned char bin[200000];
    char json[8192], uri[300] = "";
    size_t nb = quad_buffer(bin), npng = 0;
    int glb = png != NULL;
    if (glb) {
        FILE *f = fopen(png, "rb");
        assert_non_null(f);
        npng = fread(bin + 92, 1, sizeof bin - 100, f);
        fclose(f);
        nb = 92 + npng;
        while (nb % 4)
            bin[nb++] = 0;
    } else {
        strcpy(uri, ", \"uri\": \"data:application/octet-stream;base64,");
        base64(bin, nb, uri + strlen(uri));
        strcat(uri, "\"");
    }
    snprintf(json, sizeof json,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n"
             "\"nodes\": [{\"name\": \"quad\", \"mesh\": 0}],\n"
             "\"meshes\": [{\"name\": \"quad\", \"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}, "
             "\"indices\": 2, \"material\": 0}]}],\n\"materials\": [%s],\n%s%s"
             "\"buffers\": [{\"byteLength\": %zu%s}],\n"
             "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, "
             "\"byteLength\": 32}, {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 12}%s],\n"
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", "
             "\"min\": [-0.5, 0.25, -0.5], \"max\": [0.5, 0.25, 0.5]},\n"
             "  {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},\n"
             "  {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n",
             material, extra ? extra : "", extra ? ",\n" : "", nb, uri,
             glb ? ", {\"buffer\": 0, \"byteOffset\": 92, \"byteLength\": NPNG}" : "");
    if (!glb)
        return write_tmp(name, json);
    char *at = strstr(json, "NPNG"), tail[8192];
    snprintf(tail, sizeof tail, "%s", at + 4);
    snprintf(at, sizeof json - (size_t)(at - json), "%zu%s", npng, tail);
    return write_glb_chunks(name, json, bin, nb);
}

/* glTF's textures against the YAML quad with the same texture: the base colour texture (external PNG, and
 * embedded in a .glb), the metallicRoughness texture's mix, the emissive strength. */
static void test_textures(void **state)
{
    (void)state;
    need_assimp();
    nfail = 0;
    small_renders = 1;
    char shape[1200], mats[1200], png[512];
    snprintf(png, sizeof png, "%s", write_png("quadrants.png", 16, 16, NULL, 0));
    /* 1. base colour texture, metallic 0: the YAML quad with the same image as its ggx albedo */
    const char *mat = "{\"name\": \"painted\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, "
                      "\"metallicFactor\": 0, \"roughnessFactor\": 0.5}}";
    char extra[600];
    snprintf(extra, sizeof extra, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"quadrants.png\"}]");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }", write_quad("tex.gltf", mat, extra, NULL));
    const char *a = render_scene(shape, NULL, NULL, NULL, "tex_gltf.exr");
    static char keep_a[512];
    snprintf(keep_a, sizeof keep_a, "%s", a);
    snprintf(extra, sizeof extra, "\"textures\": [{\"source\": 0}], \"images\": [{\"bufferView\": 3, \"mimeType\": "
             "\"image/png\"}]");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }", write_quad("tex.glb", mat, extra, png));
    const char *g = render_scene(shape, NULL, NULL, NULL, "tex_glb.exr");
    static char keep_g[512];
    snprintf(keep_g, sizeof keep_g, "%s", g);
    for (int k = 0; k < 2; k++) {
        snprintf(mats, sizeof mats, "  painted: { type: ggx, albedo: { texture: image, file: %s }, specular: 0.04, "
                 "roughness: 0.5 }\n", k ? write_png("flipped.png", 16, 16, NULL, 1) : png);
        snprintf(shape, sizeof shape, "{ " QUAD_YAML ", material: painted }");
        const char *b = render_scene(shape, mats, NULL, NULL, k ? "tex_flipped.exr" : "tex_yaml.exr");
        expect(same_pixels(keep_a, b), !k, k ? "the texture upside down in v (must DIFFER)"
                                            : "glTF base colour texture (.gltf, external PNG) = YAML quad");
        if (!k)
            expect(same_pixels(keep_g, b), 1, "glTF base colour texture (.glb, embedded PNG) = YAML quad");
    }
    /* 2. a uniform metallicRoughness texture (R 0, G 0 roughness, B 1 metallic: texels of 0 and 1, which the
     * bilinear lookup returns exactly) times the factors: the documented ggx, computed in float as the mix does;
     * the mix left out, and G and B swapped, must differ */
    const float mrc[3] = {0.0f, 0.0f, 1.0f}, bf[3] = {0.8f, 0.3f, 0.2f}, mf = 0.5f, rf = 0.75f;
    write_png("mr.png", 4, 4, mrc, 0);
    char mat2[600];
    snprintf(mat2, sizeof mat2, "{\"name\": \"metal\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [%.9g, %.9g, %.9g, 1], "
             "\"metallicFactor\": %.9g, \"roughnessFactor\": %.9g, \"metallicRoughnessTexture\": {\"index\": 0}}}",
             (double)bf[0], (double)bf[1], (double)bf[2], (double)mf, (double)rf);
    snprintf(extra, sizeof extra, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"mr.png\"}]");
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }", write_quad("mr.gltf", mat2, extra, NULL));
    a = render_scene(shape, NULL, NULL, NULL, "mr_gltf.exr");
    snprintf(keep_a, sizeof keep_a, "%s", a);
    static const char *const mr_what[3] = {"metallicRoughness texture x factors = the mapped ggx",
                                           "the metallic mix left out (must DIFFER)", "G and B swapped (must DIFFER)"};
    for (int k = 0; k < 3; k++) {
        float m = (k == 2 ? mrc[1] : mrc[2]) * mf, r = (k == 2 ? mrc[2] : mrc[1]) * rf, al[3], sp[3];
        for (int c = 0; c < 3; c++)
            al[c] = k == 1 ? bf[c] : bf[c] * (1.0f - m), sp[c] = 0.04f * (1.0f - m) + bf[c] * m;
        snprintf(mats, sizeof mats, "  metal: { type: ggx, albedo: [%.9g, %.9g, %.9g], specular: [%.9g, %.9g, %.9g], "
                 "roughness: %.9g }\n", (double)al[0], (double)al[1], (double)al[2], (double)sp[0], (double)sp[1],
                 (double)sp[2], (double)r);
        snprintf(shape, sizeof shape, "{ " QUAD_YAML ", material: metal }");
        expect(same_pixels(keep_a, render_scene(shape, mats, NULL, NULL, "mr_yaml.exr")), !k, mr_what[k]);
    }
    /* 3. KHR_materials_emissive_strength, which murk reads from the JSON (Assimp 5.2 drops it), against the
     * quad as an OBJ mesh (a YAML quad's light is sampled as a rectangle, a mesh's by triangles) */
    char quad_obj[512];
    snprintf(quad_obj, sizeof quad_obj, "%s", write_tmp("quad.obj", "v -0.5 0.25 0.5\nv 0.5 0.25 0.5\nv 0.5 0.25 -0.5\n"
                                                        "v -0.5 0.25 -0.5\nf 1 2 3\nf 1 3 4\n"));
    const char *em = "{\"name\": \"lamp\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, 1], "
                     "\"metallicFactor\": 0, \"roughnessFactor\": 1}, \"emissiveFactor\": [1, 0.5, 0.25], \"extensions\": "
                     "{\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 4}}}";
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }",
             write_quad("strength.gltf", em, "\"extensionsUsed\": [\"KHR_materials_emissive_strength\"]", NULL));
    a = render_scene(shape, NULL, NULL, NULL, "strength_gltf.exr");
    snprintf(keep_a, sizeof keep_a, "%s", a);
    for (int k = 0; k < 2; k++) {
        snprintf(mats, sizeof mats, "  lamp: { type: ggx, albedo: [0.8, 0.8, 0.8], specular: 0.04, roughness: 1 }\n");
        snprintf(shape, sizeof shape, "{ type: mesh, file: %s, material: lamp, emission: %s }", quad_obj,
                 k ? "[1, 0.5, 0.25]" : "[4, 2, 1]");
        expect(same_pixels(keep_a, render_scene(shape, mats, NULL, NULL, "strength_yaml.exr")), !k,
               k ? "the strength left out (must DIFFER)" : "emissiveStrength 4 = the YAML quad's emission x 4");
    }
    small_renders = 0;
    assert_int_equal(nfail, 0);
}

/* glTF's UV origin: the emissive texture's top-left quadrant (red) lies at texture coordinate (0, 0), which
 * the file puts at the quad's corner nearest the camera's top-left; seen straight down, each quadrant of the
 * image shows its colour (an upside-down reading shows blue and white on top). */
static void test_uv_origin(void **state)
{
    (void)state;
    need_assimp();
    write_png("quadrants.png", 16, 16, NULL, 0);
    const char *em = "{\"name\": \"screen\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]}, "
                     "\"emissiveFactor\": [1, 1, 1], \"emissiveTexture\": {\"index\": 0}}";
    const char *g = write_quad("uv.gltf", em, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"quadrants.png\"}]",
                               NULL);
    char text[2048];
    /* looking down -y with up = -z: image right is +x, image top is -z; the quad's texcoord (0, 0) vertex is
     * (-0.5, 0.25, -0.5), the top-left */
    snprintf(text, sizeof text, "murk: 1\nrender: { resolution: [16, 16], spp: 4, seed: 1 }\n"
             "camera: { from: [0, 3, 0], at: [0, 0, 0], up: [0, 0, -1], fov: 20 }\n"
             "shapes:\n  - { type: asset, file: %s, material: from_file }\n", g);
    const char *scene = write_tmp("uv.yaml", text), *out = tmp_path("uv.exr");
    const char *args[] = {"render", scene, "-o", out, "--quiet", NULL};
    run_murk_ok(args, NULL);
    murk_image img = {0};
    char err[512];
    assert_int_equal(murk_exr_read(out, &img, err, sizeof err), 0);
    static const float want[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    static const char *const names[4] = {"top-left red", "top-right green", "bottom-left blue", "bottom-right white"};
    for (int q = 0; q < 4; q++) {
        int x = (q & 1) ? 10 : 5, y = (q & 2) ? 10 : 5; /* well inside each quadrant of the quad's image */
        const float *px = &img.rgb[3 * (y * img.w + x)];
        printf("  pixel (%d, %d): [%.3f, %.3f, %.3f], want %s\n", x, y, (double)px[0], (double)px[1], (double)px[2], names[q]);
        for (int c = 0; c < 3; c++)
            assert_true(fabsf(px[c] - want[q][c]) < 0.02f);
    }
    murk_image_free(&img);
}

/* An emissive texture lights the room as the part of the mesh it lights: the glTF quad (facing down) whose
 * emissive texture is white in its top half and black below, against the YAML scene with that half as an
 * emissive OBJ mesh and the other half as a plain one. Light samples land on the texture (render/lights.c's
 * textured_le) and BSDF-sampled hits see it (host.c): independent seeds, block-wise z (stat.h); must-fail:
 * the other half emitting. 1024 texture rows, so the bilinear blur at the two edges of the white half
 * (half a row each) moves the lamp's power by 0.1 %, below the comparison's resolution. */
#define EM_SEEDS 4
static void test_emission_texture(void **state)
{
    (void)state;
    need_assimp();
    float *rgb = malloc(3 * 1024 * sizeof(float));
    assert_non_null(rgb);
    for (int y = 0; y < 1024; y++)
        for (int k = 0; k < 3; k++)
            rgb[3 * y + k] = y < 512 ? 1.0f : 0.0f;
    char err[512];
    if (murk_png_write(tmp_path("halves.png"), rgb, 1, 1024, 0.0f, err, sizeof err))
        fail_msg("%s", err);
    free(rgb);
    const char *em = "{\"name\": \"panel\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1], "
                     "\"metallicFactor\": 0, \"roughnessFactor\": 1}, \"emissiveFactor\": [1, 1, 1], "
                     "\"emissiveTexture\": {\"index\": 0}}";
    char g[512], lit[2][512], text[3][4096];
    snprintf(g, sizeof g, "%s", write_quad("halves.gltf", em, "\"textures\": [{\"source\": 0}], \"images\": "
                                           "[{\"uri\": \"halves.png\"}]", NULL));
    /* murk's v = 1 (glTF t = 0, the white rows) is the quad's z = -0.5 edge: the white half is z in [-0.5, 0] */
    snprintf(lit[0], sizeof lit[0], "%s", write_tmp("half_white.obj", "v -0.5 0.25 0\nv 0.5 0.25 0\nv 0.5 0.25 -0.5\n"
                                                    "v -0.5 0.25 -0.5\nf 1 2 3\nf 1 3 4\n"));
    snprintf(lit[1], sizeof lit[1], "%s", write_tmp("half_black.obj", "v -0.5 0.25 0.5\nv 0.5 0.25 0.5\nv 0.5 0.25 0\n"
                                                    "v -0.5 0.25 0\nf 1 2 3\nf 1 3 4\n"));
    const char *head = "murk: 1\nrender: { resolution: [24, 24], spp: 16 }\n"
                       "camera: { from: [0, 0.2, 2.4], at: [0, -0.9, 0], fov: 55 }\n"
                       "materials:\n  white: { type: diffuse, albedo: 0.8 }\n%s"
                       "shapes:\n  - { type: quad, center: [0, -1, 0], u: [1.5, 0, 0], v: [0, 0, -1.5], material: white }\n";
    const char *flip = "transform: { rotate: [180, 0, 0] }"; /* the quad faces down, at y = -0.25 */
    const char *panel = "  panel: { type: ggx, albedo: [0.5, 0.5, 0.5], specular: 0.04, roughness: 1 }\n";
    char h0[1024], h1[1024];
    snprintf(h0, sizeof h0, head, "");
    snprintf(h1, sizeof h1, head, panel);
    snprintf(text[0], sizeof text[0], "%s  - { type: asset, file: %s, material: from_file, %s }\n", h0, g, flip);
    for (int k = 0; k < 2; k++)
        snprintf(text[1 + k], sizeof text[1], "%s  - { type: mesh, file: %s, material: panel, emission: 1, %s }\n"
                 "  - { type: mesh, file: %s, material: panel, %s }\n", h1, lit[k], flip, lit[!k], flip);
    img_stack a, r, wrong;
    img_stack_render(&a, write_tmp("em_gltf.yaml", text[0]), "em_gltf.exr", EM_SEEDS, 10, NULL);
    img_stack_render(&r, write_tmp("em_yaml.yaml", text[1]), "em_yaml.exr", EM_SEEDS, 1000, NULL);
    img_stack_render(&wrong, write_tmp("em_wrong.yaml", text[2]), "em_wrong.exr", EM_SEEDS, 2000, NULL);
    int ok = img_stack_agree("emissive texture = its white half as an emissive mesh", &a, &r, 4);
    ok &= img_stack_must_differ("the other half emitting (must DIFFER)", &wrong, &r, 4);
    img_stack_free(&a);
    img_stack_free(&r);
    img_stack_free(&wrong);
    assert_true(ok);
}

/* murk info lists the lights: the lights: block's and the glTF's KHR_lights_punctual ones, with where each
 * came from. */
static void test_info_lights(void **state)
{
    (void)state;
    need_assimp();
    const char *extra = "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": "
                        "{\"lights\": [{\"name\": \"bulb\", \"type\": \"point\", \"color\": [1, 0.5, 0.25], \"intensity\": 2}]}}";
    const char *nodes = ", {\"name\": \"bulb\", \"translation\": [0.5, 1.25, 0.75], \"extensions\": "
                        "{\"KHR_lights_punctual\": {\"light\": 0}}}";
    const char *g = write_gltf("info_lights.gltf", NULL, nodes, extra, 2, 0);
    char text[2048];
    snprintf(text, sizeof text, "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\n"
             "materials:\n  white: { type: diffuse }\n"
             "shapes:\n  - { type: asset, file: %s, material: white }\n"
             "lights:\n  - { type: spot, position: [0, 2, 0], direction: [0, -1, 0], intensity: 3, cone_angle: 40 }\n", g);
    const char *scene = write_tmp("info_lights.yaml", text);
    char *log = NULL;
    const char *args[] = {"info", scene, NULL};
    assert_int_equal(run_murk_argv(&log, args), 0);
    char want[3][700];
    snprintf(want[0], sizeof want[0], "lights (2)");
    snprintf(want[1], sizeof want[1], "spot    position [0, 2, 0], direction [0, -1, 0], intensity [3, 3, 3] W/sr, "
             "cone_angle 40, falloff_angle 35, from %s:8:5 lights[0]", scene);
    snprintf(want[2], sizeof want[2], "point   position [0.5, 1.25, 0.75], intensity [2, 1, 0.5] W/sr, from %s light "
             "'bulb' (%s:6:", g, scene);
    for (int i = 0; i < 3; i++)
        if (!strstr(log, want[i]))
            fail_msg("murk info lacks \"%s\":\n%s", want[i], log);
    free(log);
}

/* A glTF whose base colour texture is missing: a located error naming it, no image. */
static void test_bad_texture(void **state)
{
    (void)state;
    need_assimp();
    const char *mat = "{\"name\": \"lost\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}";
    const char *g = write_quad("lost.gltf", mat, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"nothere.png\"}]",
                               NULL);
    char shape[700];
    snprintf(shape, sizeof shape, "{ type: asset, file: %s, material: from_file }", g);
    expect_error(shape, NULL, "material 0 'lost': base colour texture 'nothere.png'");
}

static void test_scene(void **state)
{
    (void)state;
    need_assimp();
    static const char *const files[] = {"gem.gltf", "gem.ply"};
    for (int run = 0; run < 2; run++) {
        char dir[600], a[700], b[700];
        snprintf(dir, sizeof dir, "%s/gem%d", tmp_dir(), run);
        pid_t pid = fork();
        if (pid == 0) {
            if (!freopen("/dev/null", "w", stdout))
                _exit(127);
            execl("/usr/bin/python3", "/usr/bin/python3", src_path("tools/make_gem.py"), dir, (char *)NULL);
            _exit(127);
        }
        int st = 0;
        assert_true(pid > 0 && waitpid(pid, &st, 0) == pid && WIFEXITED(st) && WEXITSTATUS(st) == 0);
        for (int i = 0; i < 2; i++) {
            snprintf(a, sizeof a, "%s/%s", dir, files[i]);
            snprintf(b, sizeof b, "scenes/gem/%s", files[i]);
            if (!files_equal(a, src_path(b)))
                fail_msg("%s differs from the committed %s: run tools/make_gem.py", a, b);
        }
    }
    const char *exr = tmp_path("gem_asset.exr");
    const char *args[] = {"render", src_path("scenes/gem_asset.yaml"), "-o", exr, "--spp", "4", "--set",
                          "render.resolution=[40,30]", "--quiet", NULL};
    run_murk_ok(args, NULL);
    murk_image img = {0};
    char err[512];
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    double sum = 0.0;
    for (int i = 0; i < 3 * img.w * img.h; i++) {
        assert_true(isfinite(img.rgb[i]) && img.rgb[i] >= 0.0f);
        sum += img.rgb[i];
    }
    printf("  gem_asset 40x30, 4 spp: mean %.4f\n", sum / (3.0 * img.w * img.h));
    assert_true(sum > 0.0);
    murk_image_free(&img);
}

/* ---- resume -------------------------------------------------------------------------------------------- */

/* The checkpoint's content hash covers what an asset reads beside itself (load.c, asset.c): a scene of the gem
 * as a .gltf with an external .bin buffer and the quad as a .gltf with an external PNG texture. Each step makes
 * a fresh 2-spp checkpoint and resumes it: unchanged, it resumes; after the .bin changed (one vertex moved by
 * 1/64, the same size), or the PNG (upside down), --resume is refused. */
static void test_resume_inputs(void **state)
{
    (void)state;
    need_assimp();
    unsigned char b[128];
    size_t nb = mesh_buffer(b, 0);
    char text[8192], bin[600], png[600], scene[600], ck[600], exr[600];
    snprintf(bin, sizeof bin, "%s", tmp_path("resume_gem.bin"));
    write_file(bin, b, nb);
    gltf_json(text, sizeof text, "resume_gem.bin", NULL, NULL, NULL, 1);
    write_tmp("resume_gem.gltf", text);
    snprintf(png, sizeof png, "%s", write_png("resume_tex.png", 8, 8, NULL, 0));
    const char *mat = "{\"name\": \"painted\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, "
                      "\"metallicFactor\": 0, \"roughnessFactor\": 0.5}}";
    write_quad("resume_quad.gltf", mat, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"resume_tex.png\"}]",
               NULL);
    snprintf(scene, sizeof scene, "%s", write_tmp("resume.yaml",
             "murk: 1\nrender: { resolution: [8, 8], spp: 4 }\n"
             "camera: { from: [0.3, 0.8, 2.2], at: [0, 0.5, 0], fov: 40 }\n"
             "materials:\n  white: { type: diffuse, albedo: 0.7 }\n"
             "shapes:\n  - { type: quad, center: [0, 2, 0], u: [0.3, 0, 0], v: [0, 0, 0.3], material: white, "
             "emission: [12, 12, 12] }\n"
             "  - { type: asset, file: resume_gem.gltf, material: white }\n"
             "  - { type: asset, file: resume_quad.gltf, material: from_file }\n"));
    snprintf(ck, sizeof ck, "%s", tmp_path("resume.ck"));
    snprintf(exr, sizeof exr, "%s", tmp_path("resume.exr"));
    static const char *const what[] = {"nothing changed", "the .bin buffer changed", "the PNG texture changed"};
    for (int step = 0; step < 3; step++) {
        char *out = NULL;
        const char *first[] = {"render", scene, "-o", exr, "--spp", "2", "--checkpoint", ck, "--quiet", NULL};
        run_murk_ok(first, NULL);
        if (step == 1) {
            float y = V[5][1] + 1.0f / 64.0f; /* vertex 5's y, at byte 4 * (3 * 5 + 1) */
            memcpy(b + 64, &y, 4);
            write_file(bin, b, nb);
        } else if (step == 2)
            write_png("resume_tex.png", 8, 8, NULL, 1);
        const char *again[] = {"render", scene, "-o", exr, "--resume", ck, "--quiet", NULL};
        int rc = run_murk_argv(&out, again);
        printf("  %-26s --resume: exit %d%s\n", what[step], rc, rc ? ", refused" : ", resumed");
        if (step == 0)
            assert_int_equal(rc, 0);
        else {
            assert_int_equal(rc, 1);
            assert_contains(out, "a file it loads (mesh, grid, texture) changed since");
        }
        free(out);
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_formats),
        cmocka_unit_test(test_material),
        cmocka_unit_test(test_camera),
        cmocka_unit_test(test_lights),
        cmocka_unit_test(test_scene),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_textures),
        cmocka_unit_test(test_uv_origin),
        cmocka_unit_test(test_emission_texture),
        cmocka_unit_test(test_info_lights),
        cmocka_unit_test(test_bad_texture),
        cmocka_unit_test(test_resume_inputs),
    };
    if (getenv("MURK_TEST_FILTER"))
        cmocka_set_test_filter(getenv("MURK_TEST_FILTER"));
    return STAT_RUN(tests, argc, argv);
}
