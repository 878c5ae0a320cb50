/* test_scene_errors.c — bad scenes through `murk render SCENE -o OUT.exr --spp 1`: each must exit with
 * status 1 (never a signal), print exactly one line starting with the exact "file:LINE:COL: " of the
 * fault (or "--set KEY.PATH=VALUE: " quoting the override that caused it), say what is wrong, and leave no out.exr, out.png or
 * temporary file behind. The corpus is tests/fixtures/scenes/ plus scenes written here. Then a fuzz-ish
 * pass runs the loader in-process over every 37th truncation / byte mutation of scenes/cornell.yaml
 * and over odd --set strings: it must load or fail with a located message, never crash. */
#include "testutil.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "murk/murk.h"
#include "util/util.h"

typedef struct bad_scene {
    const char *name;
    const char *file; /* under tests/fixtures/scenes/, or NULL: `text` written to the temp folder */
    const char *text;
    const char *set;  /* a --set argument (the scene is then scenes/cornell.yaml unless file/text say) */
    int line, col;    /* expected location (unused when set_loc) */
    int set_loc;      /* the message starts "--set SET: " */
    const char *msg;  /* substring of the message */
} bad_scene;

#define HEAD "murk: 1\nmaterials:\n  white: { type: diffuse }\n"

static const bad_scene corpus[] = {
    /* the required cases, as files under tests/fixtures/scenes/ */
    {"unclosed bracket", "unclosed_bracket.yaml", NULL, NULL, 3, 43, 0, "did not find expected ',' or ']'"},
    {"tab indentation", "tab_indent.yaml", NULL, NULL, 4, 1, 0, "tab character: YAML indentation must use spaces"},
    {"unknown top-level key", "unknown_top_key.yaml", NULL, NULL, 5, 1, 0,
     "unknown key 'volumes' in the scene; expected one of: murk, render, camera"},
    {"parameter typo", "param_typo.yaml", NULL, NULL, 4, 27, 0,
     "unknown parameter 'albdo' for material 'white' (diffuse) (did you mean 'albedo'?)"},
    {"string for a number", "wrong_type.yaml", NULL, NULL, 3, 65, 0, "camera.fov must be a number, got 'wide'"},
    {"albedo out of range", "albedo_range.yaml", NULL, NULL, 4, 41, 0,
     "material 'white' (diffuse): parameter 'albedo' must be in [0, 1], got 1.5"},
    {"undefined material", "undefined_material.yaml", NULL, NULL, 7, 61, 0,
     "undefined material 'whte' (did you mean 'white'?)"},
    {"missing mesh file", "missing_mesh.yaml", NULL, NULL, 6, 25, 0,
     "no_such_mesh.obj: cannot open: No such file or directory"},
    {"empty file", "empty.yaml", NULL, NULL, 1, 1, 0, "empty scene"},
    {"no version key", "no_version.yaml", NULL, NULL, 2, 1, 0, "the scene is missing the required key 'murk'"},
    {"wrong version", "wrong_version.yaml", NULL, NULL, 2, 7, 0, "scene format version 2 is not supported (this murk reads version 1)"},
    {"duplicate key", "duplicate_key.yaml", NULL, NULL, 5, 3, 0, "duplicate key 'white'"},
    {"unknown shape type", "unknown_shape.yaml", NULL, NULL, 6, 13, 0,
     "unknown shape type 'spere' (did you mean 'sphere'?)"},
    {"degenerate quad", "degenerate_quad.yaml", NULL, NULL, 6, 5, 0,
     "quad: u and v must span a non-degenerate parallelogram"},
    {"camera up parallel", "camera_up_parallel.yaml", NULL, NULL, 3, 9, 0,
     "camera: 'up' is parallel to the viewing direction"},
    {"resolution 0", "resolution_zero.yaml", NULL, NULL, 3, 24, 0, "render.resolution must be in [1, 16384], got 0"},
    {"plugin type '../evil'", "plugin_path_escape.yaml", NULL, NULL, 4, 18, 0,
     "material 'white': '../evil' is not a plugin name"},
    {"nonexistent plugin", "plugin_missing.yaml", NULL, NULL, 4, 18, 0,
     "material 'white': no material plugin 'velvet_dream' (searched"},
    {"binary garbage with NUL", "garbage.bin.yaml", NULL, NULL, 1, 1, 0, "not a text file (contains NUL bytes)"},
    {"200 nested lists", "deep_nesting.yaml", NULL, NULL, 3, 76, 0, "nesting deeper than 64 levels"},
    {"1e400", "huge_number.yaml", NULL, NULL, 6, 48, 0, "sphere.radius is too large, got '1e400'"},

    /* --set errors (on scenes/cornell.yaml): the message quotes the --set */
    {"--set bad value type", NULL, NULL, "render.spp=abc", 1, 12, 1, "render.spp must be a number, got 'abc'"},
    {"--set index out of range", NULL, NULL, "shapes.12.material=red", 1, 8, 1,
     "'12' is not an index of the list shapes (it has 8 items)"},
    {"--set non-numeric index", NULL, NULL, "shapes.x.material=red", 1, 8, 1, "'x' is not an index of the list shapes"},
    {"--set path through a scalar", NULL, NULL, "camera.fov.x=3", 1, 12, 1, "cannot descend into a scalar at 'x'"},
    {"--set unknown traversal", NULL, NULL, "render.traversal=exact", 1, 18, 1,
     "render.traversal must be one of fast|robust, got 'exact'"},
    {"--set no key", NULL, NULL, "=3", 1, 1, 1, "expected KEY.PATH=VALUE"},
    {"--set no value", NULL, NULL, "render.spp", 1, 1, 1, "expected KEY.PATH=VALUE"},
    {"--set empty path segment", NULL, NULL, "render..spp=3", 1, 8, 1, "empty key in 'render..spp'"},
    {"--set malformed YAML value", NULL, NULL, "render.spp=[1", 1, 12, 1,
     "the value after '=' is not valid YAML: did not find expected ',' or ']'"},
    {"--set out of range", NULL, NULL, "materials.white.albedo=2", 1, 24, 1,
     "material 'white' (diffuse): parameter 'albedo' must be in [0, 1], got 2"},
    {"--set undefined material", NULL, NULL, "shapes.0.material=whte", 1, 19, 1,
     "undefined material 'whte' (did you mean 'white'?)"},
    {"--set list item out of range", NULL, NULL, "render.resolution=[0, 8]", 1, 20, 1,
     "render.resolution must be in [1, 16384], got 0"},
    {"--set wrong node kind", NULL, NULL, "shapes=5", 1, 8, 1, "shapes must be a list"},
    {"--set bad plugin name", NULL, NULL, "integrator.type=../x", 1, 17, 1, "'../x' is not a plugin name"},

    /* more, written to the temp folder */
    {"scene is a list", NULL, "- murk\n- 1\n", NULL, 1, 1, 0, "a scene must be a map of keys"},
    {"scene is a scalar", NULL, "~\n", NULL, 1, 1, 0, "a scene must be a map of keys"},
    {"material not a map", NULL, HEAD "  red: diffuse\nshapes: []\n", NULL, 4, 8, 0, "material 'red' must be a map of keys"},
    {"material without type", NULL, HEAD "  red: { albedo: 0.5 }\nshapes: []\n", NULL, 4, 8, 0,
     "material 'red' is missing the required key 'type'"},
    {"ggx: alpha and roughness", NULL, HEAD "  metal: { type: ggx, roughness: 0.3, alpha: 0.09 }\nshapes:\n  - { type: sphere, center: [0, 0, 0], radius: 1, material: metal }\n", NULL, 4, 39, 0,
     "material 'metal' (ggx): 'roughness' and 'alpha' are two scales of one parameter: give one"},
    {"dielectric: alpha and roughness", NULL, HEAD "  glass: { type: dielectric, alpha: 0.09, roughness: 0.3 }\nshapes:\n  - { type: sphere, center: [0, 0, 0], radius: 1, material: glass }\n", NULL, 4, 43, 0,
     "material 'glass' (dielectric): 'roughness' and 'alpha' are two scales"},
    {"shapes not a list", NULL, HEAD "shapes: { a: 1 }\n", NULL, 4, 9, 0, "shapes must be a list"},
    {"shape not a map", NULL, HEAD "shapes: [1]\n", NULL, 4, 10, 0, "a shape must be a map of keys"},
    {"sphere without radius", NULL, HEAD "shapes:\n  - { type: sphere, center: [0, 0, 0], material: white }\n", NULL,
     5, 5, 0, "sphere is missing the required key 'radius'"},
    {"shape without material", NULL, HEAD "shapes:\n  - { type: sphere, center: [0, 0, 0], radius: 1 }\n", NULL, 5, 5,
     0, "sphere has no material"},
    {"box inside out", NULL,
     HEAD "shapes:\n  - { type: box, min: [0, 0, 0], max: [1, -1, 1], material: white }\n", NULL, 5, 39, 0,
     "box: max must exceed min on every axis"},
    {"negative emission", NULL,
     HEAD "shapes:\n  - { type: sphere, center: [0, 0, 0], radius: 1, material: white, emission: -1 }\n", NULL, 5, 78,
     0, "emission must be in [0, 1e+30], got -1"},
    {"camera from == at", NULL, HEAD "camera: { from: [1, 2, 3], at: [1, 2, 3] }\nshapes: []\n", NULL, 4, 9, 0,
     "camera: 'from' and 'at' are the same point"},
    {"fov out of range", NULL, HEAD "camera: { fov: 180 }\nshapes: []\n", NULL, 4, 16, 0,
     "camera.fov must be in [0.01, 179], got 180"},
    {"spp not whole", NULL, HEAD "render: { spp: 1.5 }\nshapes: []\n", NULL, 4, 16, 0,
     "render.spp must be a whole number, got '1.5'"},
    {"render key typo", NULL, HEAD "render: { sp: 4 }\nshapes: []\n", NULL, 4, 11, 0,
     "unknown key 'sp' in render (did you mean 'spp'?)"},
    {"integrator parameter typo", NULL, HEAD "integrator: { type: path, max_dept: 5 }\nshapes: []\n", NULL, 4, 27, 0,
     "unknown parameter 'max_dept' for integrator 'path' (did you mean 'max_depth'?)"},
    {"integrator is a material", NULL, HEAD "integrator: { type: diffuse }\nshapes: []\n", NULL, 4, 21, 0,
     "'diffuse' is a material plugin, not a"},
    {"material is an integrator", NULL, HEAD "  p: { type: path }\nshapes: []\n", NULL, 4, 14, 0,
     "integrator plugin, not a material"},
    {"unknown texture", NULL, "murk: 1\nmaterials:\n  t: { type: diffuse, albedo: { texture: marble } }\nshapes: []\n",
     NULL, 3, 42, 0, "unknown texture 'marble' (expected checker or image)"},
    {"texture on a plain number", NULL, HEAD "integrator: { type: path, max_depth: { texture: checker } }\nshapes: []\n",
     NULL, 4, 38, 0, "max_depth' must be a number"},
    {"YAML alias", NULL, HEAD "background: &bg [1, 1, 1]\nshapes: *bg\n", NULL, 5, 9, 0,
     "YAML aliases are not supported in scenes"},
    {"two documents", NULL, HEAD "shapes: []\n---\nmurk: 1\n", NULL, 5, 1, 0, "a scene file holds one YAML document"},
    {"complex key", NULL, HEAD "? [a, b]\n: 1\n", NULL, 4, 3, 0, "a map key must be a plain name"},
    {"mesh file is a folder", NULL, HEAD "shapes:\n  - { type: mesh, file: ., material: white }\n", NULL, 5, 25, 0,
     "a directory, not a regular file"},
    {"NaN background", NULL, HEAD "background: .nan\nshapes: []\n", NULL, 4, 13, 0, "background must be a number"},
};
#define NCORPUS (sizeof corpus / sizeof corpus[0])

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

/* Number of entries in a folder, . and .. aside. */
static int dir_entries(const char *dir, char *first, size_t n)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int k = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            if (k++ == 0 && first)
                snprintf(first, n, "%s", e->d_name);
        }
    closedir(d);
    return k;
}

/* Runs one bad scene through the command line and checks status, location, message and leftovers. */
static void check_bad(const char *name, const char *scene, const char *set, const char *loc_file, int line, int col,
                      const char *msg)
{
    static int serial;
    static char *out; /* kept until the next call so that a failed assertion does not leak it */
    free(out);
    out = NULL;
    char outdir[1024], exr[1100];
    snprintf(outdir, sizeof outdir, "%s/out-%d", tmp_dir(), serial++);
    assert_int_equal(mkdir(outdir, 0755), 0);
    snprintf(exr, sizeof exr, "%s/out.exr", outdir);
    int st = set ? run_murk(&out, "render", scene, "-o", exr, "--spp", "1", "--set", set, NULL)
                 : run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
    if (st != 1)
        fail_msg("[%s] exit status %d (want 1; 128+N is signal N):\n%s", name, st, out);
    char prefix[1200];
    if (set && !strcmp(loc_file, "--set"))
        snprintf(prefix, sizeof prefix, "--set %s: ", set);
    else
        snprintf(prefix, sizeof prefix, "%s:%d:%d: ", loc_file, line, col);
    if (strncmp(out, prefix, strlen(prefix)) != 0)
        fail_msg("[%s] expected the message to start with\n  %s\ngot\n  %s", name, prefix, out);
    if (!strstr(out, msg))
        fail_msg("[%s] expected \"%s\" in\n  %s", name, msg, out);
    if (count_lines(out) != 1 || out[strlen(out) - 1] != '\n')
        fail_msg("[%s] expected exactly one line, got:\n%s", name, out);
    char left[256] = "";
    if (dir_entries(outdir, left, sizeof left) != 0)
        fail_msg("[%s] left '%s' in the output folder", name, left);
    assert_int_equal(rmdir(outdir), 0);
}

static void test_corpus(void **state)
{
    (void)state;
    char cornell[1024]; /* src_path's buffers rotate */
    snprintf(cornell, sizeof cornell, "%s", src_path("scenes/cornell.yaml"));
    for (size_t i = 0; i < NCORPUS; i++) {
        const bad_scene *c = &corpus[i];
        char scene[1024];
        if (c->file) {
            snprintf(scene, sizeof scene, "%s", src_path("tests/fixtures/scenes/"));
            strncat(scene, c->file, sizeof scene - strlen(scene) - 1);
            assert_int_equal(access(scene, R_OK), 0);
        } else if (c->text) {
            char fname[64];
            snprintf(fname, sizeof fname, "corpus-%zu.yaml", i);
            snprintf(scene, sizeof scene, "%s", write_tmp(fname, c->text));
        } else {
            snprintf(scene, sizeof scene, "%s", cornell);
        }
        check_bad(c->name, scene, c->set, c->set_loc ? "--set" : scene, c->line, c->col, c->msg);
    }
}

/* Files that cannot be written with write_tmp (bytes) or are long (generated). */
static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void test_generated(void **state)
{
    (void)state;
    char path[1024];
    /* 200 levels of block maps */
    size_t cap = 200 * 210 + 256, n = 0;
    char *text = malloc(cap);
    n += (size_t)snprintf(text + n, cap - n, "murk: 1\nshapes: []\nbackground:\n");
    for (int d = 1; d <= 200; d++)
        n += (size_t)snprintf(text + n, cap - n, "%*sa%d:\n", 2 * d, "", d);
    n += (size_t)snprintf(text + n, cap - n, "%*s1\n", 2 * 201, "");
    snprintf(path, sizeof path, "%s/deep_maps.yaml", tmp_dir());
    write_bytes(path, text, n);
    /* the root map is level 1, the map holding key aK (line 3 + K, column 2K + 1) is level K + 1 */
    check_bad("200 nested maps", path, NULL, path, 3 + 64, 2 * 64 + 1, "nesting deeper than 64 levels");
    free(text);

    /* 200 levels mixing lists and maps, flow style */
    char flow[2048];
    n = (size_t)snprintf(flow, sizeof flow, "murk: 1\nbackground: ");
    for (int d = 0; d < 100; d++)
        n += (size_t)snprintf(flow + n, sizeof flow - n, "[{a: ");
    n += (size_t)snprintf(flow + n, sizeof flow - n, "1");
    for (int d = 0; d < 100; d++)
        n += (size_t)snprintf(flow + n, sizeof flow - n, "}]");
    n += (size_t)snprintf(flow + n, sizeof flow - n, "\n");
    snprintf(path, sizeof path, "%s/deep_flow.yaml", tmp_dir());
    write_bytes(path, flow, n);
    /* "[{a: " per two levels from column 13; level 65 is the '{' of the 32nd pair */
    check_bad("200 nested flow maps and lists", path, NULL, path, 2, 13 + 5 * 31 + 1, "nesting deeper than 64 levels");

    /* random bytes without NUL: not UTF-8 */
    unsigned char junk[600];
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (size_t i = 0; i < sizeof junk; i++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        junk[i] = (unsigned char)(1 + x % 255);
    }
    junk[0] = 0xff; /* never valid UTF-8 */
    snprintf(path, sizeof path, "%s/junk.yaml", tmp_dir());
    write_bytes(path, junk, sizeof junk);
    check_bad("random non-UTF-8 bytes", path, NULL, path, 1, 1, "invalid leading UTF-8 octet");

    /* a scene file that is a folder */
    snprintf(path, sizeof path, "%s/folder.yaml", tmp_dir());
    assert_int_equal(mkdir(path, 0755), 0);
    char outdir[1100], exr[1200];
    snprintf(outdir, sizeof outdir, "%s/out-folder", tmp_dir());
    mkdir(outdir, 0755);
    snprintf(exr, sizeof exr, "%s/out.exr", outdir);
    char *out = NULL;
    int st = run_murk(&out, "render", path, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    assert_int_equal(strncmp(out, path, strlen(path)), 0);
    assert_int_equal(count_lines(out), 1);
    assert_int_equal(dir_entries(outdir, NULL, 0), 0);
    free(out);
    rmdir(path);

    /* a scene that does not exist */
    snprintf(path, sizeof path, "%s/no-such-scene.yaml", tmp_dir());
    st = run_murk(&out, "render", path, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    char want[1200];
    snprintf(want, sizeof want, "%s: cannot open: No such file or directory\n", path);
    assert_string_equal(out, want);
    assert_int_equal(dir_entries(outdir, NULL, 0), 0);
    free(out);
    rmdir(outdir);
}

/* An error about a key that a --set added to a map of the scene file quotes the --set, not the scene
 * file. */
static void test_set_new_key_location(void **state)
{
    (void)state;
    const char *cornell = src_path("scenes/cornell.yaml");
    check_bad("--set unknown top-level key", cornell, "rendr.spp=4", "--set", 1, 1,
              "unknown key 'rendr' in the scene (did you mean 'render'?)");
    check_bad("--set unknown key in a block", cornell, "render.spq=4", "--set", 1, 8,
              "unknown key 'spq' in render (did you mean 'spp'?)");
    check_bad("--set parameter typo", cornell, "materials.white.albdo=0.5", "--set", 1, 17,
              "unknown parameter 'albdo' for material 'white' (diffuse) (did you mean 'albedo'?)");
}

/* ---- A/B safety: --set typos, tracker swaps, quoted --set errors -------------------------------- */

/* A small scene whose medium `m` is written for decomposition tracking (its own key `control`), with a
 * transmittance estimator of its own keys, a GGX material with `roughness`, and a spare medium or
 * material when `extra` says so. */
static const char *ab_scene(const char *name, const char *extra)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "murk: 1\n"
             "render: { resolution: [8, 8], spp: 1 }\n"
             "camera: { from: [0, 0, 3], at: [0, 0, 0] }\n"
             "integrator: { type: volpath_nee, max_depth: 4 }\n"
             "materials:\n"
             "  shiny: { type: ggx, roughness: 0.3 }\n"
             "  lamp: { type: diffuse, albedo: 0 }\n"
             "media:\n"
             "  m:\n"
             "    type: decomposition\n"
             "    control: 0.5\n"
             "    density: { constant: 1 }\n"
             "    sigma_s: 0.5\n"
             "    transmittance: { type: unbiased_raymarch, depth_step: 0.5 }\n"
             "%s"
             "shapes:\n"
             "  - { type: sphere, center: [0, 0, 0], radius: 0.5, material: shiny }\n"
             "  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: m }\n"
             "  - { type: quad, center: [0, 2, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: lamp, emission: 5 }\n",
             extra ? extra : "");
    return write_tmp(name, text);
}

/* Errors a --set causes, on a scene of scenes/: each message starts "--set SET: ". */
static const struct { const char *name, *scene, *set, *msg; } set_corpus[] = {
    /* a misspelt medium or material name is refused with the name it was meant to be */
    {"--set typo in a medium's name", "cornell_smoke", "media.smok.type=spectral",
     "media.smok is not used by any shape or by the camera; did you mean media.smoke?"},
    {"--set typo in a material's name", "cornell", "materials.whte.type=ggx",
     "materials.whte is not used by any shape; did you mean materials.white?"},
    /* named as the typo it is before what else is wrong with the block (no type) */
    {"--set typo before any other error", "cornell_smoke", "media.smok.sigma_s=3",
     "media.smok is not used by any shape or by the camera; did you mean media.smoke?"},
    /* whatever reports the error: a reader, the plugin loader, a file the value names, a texture */
    {"--set medium key not a number", "cornell_smoke", "media.smoke.sigma_a=abc",
     "medium 'smoke' (delta): parameter 'sigma_a' must be a number, got 'abc'"},
    {"--set unknown tracker", "cornell_smoke", "media.smoke.type=dleta", "medium 'smoke': no medium plugin 'dleta'"},
    {"--set missing grid file", "cornell_smoke", "media.smoke.density={grid: nope.vol}", "density grid:"},
    {"--set texture error", "cornell", "materials.white.albedo={texture: marble}",
     "material 'white' (diffuse): parameter 'albedo': unknown texture 'marble'"},
    {"--set tracker key out of range", "cornell_smoke", "media.smoke.g=2",
     "medium 'smoke' (delta): parameter 'g' must be in [-0.99, 0.99], got 2"},
};

static void test_set_errors_are_quoted(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof set_corpus / sizeof set_corpus[0]; i++) {
        char scene[1024];
        snprintf(scene, sizeof scene, "%s", src_path("scenes/"));
        strncat(scene, set_corpus[i].scene, sizeof scene - strlen(scene) - 6);
        strcat(scene, ".yaml");
        check_bad(set_corpus[i].name, scene, set_corpus[i].set, "--set", 0, 0, set_corpus[i].msg);
    }
}

/* A medium or material the scene file defines and nothing uses is refused by murk render and murk
 * info, located at its name; murk_scene_load leaves it to the command. */
static void test_unused_is_refused(void **state)
{
    (void)state;
    /* the scene file's own: located at the name */
    const char *p = ab_scene("unused_medium.yaml", "  fog: { type: delta }\n");
    check_bad("unused medium in the file", p, NULL, p, 15, 3,
              "media.fog is not used by any shape or by the camera; reference it (a shape's interior or exterior, "
              "camera.medium) or remove it");
    char *out = NULL;
    assert_int_equal(run_murk(&out, "info", p, NULL), 1);
    assert_contains(out, "media.fog is not used");
    free(out);
    /* referenced by a --set instead: fine */
    assert_int_equal(run_murk(&out, "info", p, "--set", "camera.medium=fog", NULL), 0);
    free(out);
    /* the embedding API loads the file's unused blocks (embedders call trackers directly) ... */
    char err[2048];
    murk_scene *s = murk_scene_load(p, NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    murk_scene_free(s);
    /* ... but not one a --set made */
    const char *typo = "media.mm.type=delta";
    assert_null(murk_scene_load(p, &typo, 1, err, sizeof err));
    assert_contains(err, "--set media.mm.type=delta: media.mm is not used by any shape or by the camera; did you mean "
                         "media.m?");
}

/* A --set of a plugin's type drops the file's keys of the previous plugin that the new one does not
 * take: a tracker (decomposition's control), an estimator (unbiased_raymarch's depth_step), a material
 * (ggx's roughness). Keys the old plugin did not take either, or that a --set gave, stay errors. */
static void test_type_swap(void **state)
{
    (void)state;
    const char *p = ab_scene("swap.yaml", NULL);
    char exr[1200], *out = NULL;
    snprintf(exr, sizeof exr, "%s/swap.exr", tmp_dir());
    int st = run_murk(&out, "render", p, "-o", exr, "--set", "media.m.type=delta", "--set",
                      "media.m.transmittance.type=ratio", "--set", "materials.shiny.type=diffuse", NULL);
    if (st != 0)
        fail_msg("swapping the tracker, the estimator and the material failed (%d):\n%s", st, out);
    assert_contains(out, "medium 'm' (delta): dropped 'control'");
    assert_contains(out, "a parameter of 'decomposition' that the --set of its type replaced");
    assert_contains(out, "dropped 'depth_step'");
    assert_contains(out, "dropped 'roughness'");
    assert_int_equal(access(exr, R_OK), 0);
    free(out);
    /* murk info shows the new plugins */
    assert_int_equal(run_murk(&out, "info", p, "--set", "media.m.type=delta", NULL), 0);
    assert_contains(out, "tracker        delta");
    assert_not_contains(out, "decomposition.so");
    free(out);
    /* without the swap, the same keys under delta are refused: the drop is what makes it work */
    const char *q = write_tmp("delta_control.yaml",
                              "murk: 1\nmedia:\n  m: { type: delta, control: 0.5 }\n"
                              "shapes: [ { type: box, min: [0, 0, 0], max: [1, 1, 1], interior: m } ]\n");
    check_bad("control under delta", q, NULL, q, 3, 21, "unknown parameter 'control' for medium 'm' (delta)");
    /* a key given by a --set is the user's: still refused, quoting that --set */
    st = run_murk(&out, "render", p, "-o", exr, "--set", "media.m.type=delta", "--set", "media.m.control=0.3", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "--set media.m.control=0.3: unknown parameter 'control' for medium 'm' (delta)");
    free(out);
    /* a key of the file that the old tracker did not take either stays the file's error */
    const char *r = write_tmp("contrl.yaml", "murk: 1\nmedia:\n  m: { type: decomposition, contrl: 0.5 }\n"
                                             "shapes: [ { type: box, min: [0, 0, 0], max: [1, 1, 1], interior: m } ]\n");
    check_bad("file typo survives a swap", r, "media.m.type=delta", r, 3, 29,
              "unknown parameter 'contrl' for medium 'm' (delta)");
}

/* Encoding errors (libyaml reader errors) are located where the bad byte is, not at 1:1. */
static void test_encoding_error_location(void **state)
{
    (void)state;
    const char *p = write_tmp("bad_utf8.yaml", "murk: 1\nshapes: []\nbackground: \xff\xfe\n");
    check_bad("invalid UTF-8 on line 3", p, NULL, p, 3, 13, "invalid leading UTF-8 octet");
    p = write_tmp("control.yaml", "murk: 1\nshapes: []\nbackground: [0, \x01, 0]\n");
    check_bad("control character on line 3", p, NULL, p, 3, 17, "control characters are not allowed");
}

/* ---- in-process fuzzing ----------------------------------------------------------------------- */

static char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)len + 1);
    assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
    b[len] = 0;
    fclose(f);
    *n = (size_t)len;
    return b;
}

/* Loads `path` in-process: either a scene, or an error "PATH:LINE:COL: message" on one line (or
 * "--set SET: message" when a set is given). Returns 1 if it loaded. */
static int load_or_located_error(const char *path, const char *set, const char *what)
{
    char err[2048];
    memset(err, 0, sizeof err);
    murk_scene *s = murk_scene_load(path, set ? &set : NULL, set ? 1 : 0, err, sizeof err);
    if (s) {
        murk_scene_free(s);
        return 1;
    }
    size_t pl = strlen(path);
    const char *rest = NULL;
    char quoted[512];
    if (set) { /* the set as the message quotes it: printable */
        char raw[512];
        snprintf(raw, sizeof raw, "--set %s: ", set);
        murk_printable(quoted, sizeof quoted, raw);
    }
    if (set && strncmp(err, quoted, strlen(quoted)) == 0) {
        if (strchr(err, '\n'))
            fail_msg("[%s] error of more than one line: \"%s\"", what, err);
        if (!err[strlen(quoted)])
            fail_msg("[%s] error with no message: \"%s\"", what, err);
        return 0;
    }
    if (strncmp(err, path, pl) == 0 && err[pl] == ':')
        rest = err + pl + 1;
    int line = 0, col = 0, used = 0;
    if (!rest || sscanf(rest, "%d:%d: %n", &line, &col, &used) != 2 || used == 0 || line < 1 || col < 1)
        fail_msg("[%s] error without a file:line:col prefix: \"%s\"", what, err);
    if (strchr(err, '\n'))
        fail_msg("[%s] error of more than one line: \"%s\"", what, err);
    if (!rest[used])
        fail_msg("[%s] error with no message: \"%s\"", what, err);
    return 0;
}

static void test_truncations(void **state)
{
    (void)state;
    size_t n;
    char *text = read_all(src_path("scenes/cornell.yaml"), &n);
    char path[1024];
    snprintf(path, sizeof path, "%s/trunc.yaml", tmp_dir());
    int loaded = 0, failed = 0;
    for (size_t cut = 0;; cut += 37) {
        if (cut > n)
            cut = n;
        write_bytes(path, text, cut);
        char what[64];
        snprintf(what, sizeof what, "cornell.yaml cut at byte %zu", cut);
        if (load_or_located_error(path, NULL, what))
            loaded++;
        else
            failed++;
        if (cut == n)
            break;
    }
    print_message("cornell.yaml truncations: %d loaded, %d refused with a located error\n", loaded, failed);
    assert_true(failed > 10); /* most cuts break it */
    assert_true(loaded >= 1); /* the whole file loads */
    free(text);
}

static void test_mutations(void **state)
{
    (void)state;
    size_t n;
    char *text = read_all(src_path("scenes/cornell.yaml"), &n);
    char *buf = malloc(n + 1);
    char path[1024];
    snprintf(path, sizeof path, "%s/mut.yaml", tmp_dir());
    static const char repl[] = "\t:[]{},&*!|>'\"#-?%@`\n9 \x01\xc3";
    int loaded = 0, failed = 0;
    for (size_t off = 18; off < n; off += 37)
        for (size_t r = 0; r < sizeof repl - 1; r++) {
            memcpy(buf, text, n);
            buf[off] = repl[r];
            write_bytes(path, buf, n);
            char what[96];
            snprintf(what, sizeof what, "cornell.yaml with byte %zu set to 0x%02x", off, (unsigned char)repl[r]);
            if (load_or_located_error(path, NULL, what))
                loaded++;
            else
                failed++;
        }
    print_message("cornell.yaml mutations: %d loaded, %d refused with a located error\n", loaded, failed);
    assert_true(failed > 0);
    assert_true(loaded > 0);
    free(buf);
    free(text);
}

static void test_odd_sets(void **state)
{
    (void)state;
    static const char *const sets[] = {
        "a.=1", ".a=1", "a..b=1", ".=1", "=", "==", "a==1", "shapes.99999999999999999999.x=1", "shapes.-1=1",
        "shapes.0=", "shapes.0={}", "shapes.0=[]", "shapes.0.type=sphere", "shapes.0.center.0.x=1",
        "render=[[[[[[", "render={", "murk=", "murk=1.0", "murk=0x1", "camera.up=[0, 0, 0]", "camera.fov=1e400",
        "camera.fov=-1e-400", "materials.white=", "materials.white.type=", "materials.white.type=path",
        "materials.new.type=diffuse", "integrator={type: path, max_depth: 0}", "background=&a [1, 1, 1]",
        "background=*a", "background=[1, 1, 1]\n---\nx", "shapes.0.material=\"\"", "a.b.c.d.e.f.g.h=1",
        "render.resolution=[100000, 1]", "render.seed=-1", "shapes=[]", "shapes.8=x", "materials.white.albedo=\t1",
    };
    const char *cornell = src_path("scenes/cornell.yaml");
    for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
        char what[128];
        snprintf(what, sizeof what, "--set '%s'", sets[i]);
        load_or_located_error(cornell, sets[i], what);
    }
    /* and a few that must load (murk_scene_load leaves the file's unused materials to the command) */
    assert_int_equal(load_or_located_error(cornell, "shapes=[]", "--set shapes=[]"), 1);
    /* a material a --set adds and nothing uses is refused, quoting the --set */
    assert_int_equal(load_or_located_error(cornell, "materials.new.type=diffuse", "--set new material"), 0);
    assert_int_equal(load_or_located_error(cornell, "shapes.0.type=sphere", "--set quad to sphere"), 0);
}

int main(void)
{
    unsetenv("MURK_PLUGIN_PATH");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corpus),
        cmocka_unit_test(test_generated),
        cmocka_unit_test(test_set_new_key_location),
        cmocka_unit_test(test_encoding_error_location),
        cmocka_unit_test(test_unused_is_refused),
        cmocka_unit_test(test_type_swap),
        cmocka_unit_test(test_set_errors_are_quoted),
        cmocka_unit_test(test_truncations),
        cmocka_unit_test(test_mutations),
        cmocka_unit_test(test_odd_sets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
