/* test_plugin_abi.c — the plugin loader (core/plugin/plugin.c) against the fixture plugins in
 * tests/fixtures (built into the build's tests/fixtures folder, reached only through MURK_PLUGIN_PATH):
 * every refusal is rc -1 with one precise line naming the file; plugin code is never run before the
 * ABI check (abi_major/abi_minor/no_abi abort() if their entry is called); only the plugins a scene
 * names are loaded; `murk render` / `murk plugins` report the same; an empty MURK_PLUGIN_PATH entry
 * never means the current folder. */
#include "testutil.h"
#include "image/image.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plugin/plugin_loader.h"
#include "scene/scene.h"

/* The host's ABI minor as text (and the next one, which the abi_minor fixture asks for). */
#define STR_(x) #x
#define STR(x) STR_(x)
#define MINOR STR(MURK_ABI_MINOR)
_Static_assert(MURK_ABI_MINOR == 9, "update MINOR_PLUS_1 with the ABI minor");
#define MINOR_PLUS_1 "10"

static char err[2048];

static const char *fixture_dir(void) { return build_path("tests/fixtures"); }

static const char *fixture(const char *name)
{
    static char bufs[4][1024];
    static int next;
    char *b = bufs[next++ & 3];
    snprintf(b, sizeof bufs[0], "%s/%s.so", fixture_dir(), name);
    return b;
}

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

/* A line of `text` that contains both a and b. */
static int has_line_with(const char *text, const char *a, const char *b)
{
    const char *p = text;
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), p);
        if (strstr(line, a) && strstr(line, b))
            return 1;
        if (!e)
            break;
        p = e + 1;
    }
    return 0;
}

static void copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    assert_non_null(a);
    assert_non_null(b);
    char buf[8192];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, a)) > 0)
        assert_int_equal(fwrite(buf, 1, n, b), n);
    fclose(a);
    fclose(b);
}

/* ---- murk_plugin_open on each fixture -------------------------------------------------------- */

typedef struct bad_case {
    const char *fixture;
    int kind;
    const char *msg; /* substring of the error after "plugin PATH: " */
} bad_case;

static const bad_case bad_cases[] = {
    {"abi_major", MURK_KIND_MATERIAL, "built for plugin ABI 2.0, this murk has ABI 1." MINOR},
    {"abi_minor", MURK_KIND_MATERIAL, "needs plugin ABI 1." MINOR_PLUS_1 ", this murk has ABI 1." MINOR},
    {"no_entry", MURK_KIND_MATERIAL, "no 'murk_plugin_entry' function"},
    {"no_abi", MURK_KIND_MATERIAL, "no 'murk_plugin_abi' symbol: not a murk plugin"},
    {"bad_size", MURK_KIND_MATERIAL, "descriptor struct_size is"},
    {"name_mismatch", MURK_KIND_MATERIAL, "declares the name 'diffuse' but its file is named 'name_mismatch.so'"},
    {"wrong_kind", MURK_KIND_MATERIAL, "integrator plugin, not a material"},
    {"bad_vtable", MURK_KIND_MATERIAL, "material vtable is"},
    {"bad_param", MURK_KIND_MATERIAL, "enum parameter 'mode' needs choices and a default"},
    {"kind_mismatch", 0, "declares a medium plugin but its vtable is marked kind 1 (material)"},
};
#define NBAD (sizeof bad_cases / sizeof bad_cases[0])

static void test_open_bad_fixtures(void **state)
{
    (void)state;
    for (size_t i = 0; i < NBAD; i++) {
        const bad_case *c = &bad_cases[i];
        const char *path = fixture(c->fixture);
        assert_int_equal(access(path, R_OK), 0);
        murk_plugin p;
        memset(err, 0, sizeof err);
        int rc = murk_plugin_open(path, c->kind, &p, err, sizeof err);
        if (rc != -1)
            fail_msg("%s: expected rc -1, got %d", c->fixture, rc);
        char prefix[1200];
        snprintf(prefix, sizeof prefix, "plugin %s: ", path);
        if (strncmp(err, prefix, strlen(prefix)) != 0)
            fail_msg("%s: message does not start with \"%s\": %s", c->fixture, prefix, err);
        assert_contains(err, c->msg);
        assert_null(strchr(err, '\n')); /* one line */
        assert_null(p.handle);
        assert_null(p.desc);
    }
}

/* Exact numbers in the messages that carry them. */
static void test_open_bad_details(void **state)
{
    (void)state;
    murk_plugin p;
    char want[256];
    assert_int_equal(murk_plugin_open(fixture("bad_size"), 0, &p, err, sizeof err), -1);
    snprintf(want, sizeof want, "descriptor struct_size is %zu bytes, expected at least %zu for ABI 1." MINOR,
             MURK_PLUGIN_DESC_SIZE_1_0 - sizeof(void *), MURK_PLUGIN_DESC_SIZE_1_0);
    assert_contains(err, want);

    assert_int_equal(murk_plugin_open(fixture("bad_vtable"), 0, &p, err, sizeof err), -1);
    snprintf(want, sizeof want, "material vtable is %zu bytes, expected at least %zu", 3 * sizeof(void *),
             MURK_MATERIAL_VT_SIZE_1_0);
    assert_contains(err, want);

    assert_int_equal(murk_plugin_open(fixture("abi_major"), 0, &p, err, sizeof err), -1);
    assert_contains(err, "rebuild the plugin");
    assert_int_equal(murk_plugin_open(fixture("abi_minor"), 0, &p, err, sizeof err), -1);
    assert_contains(err, "upgrade murk");
}

static void test_open_good_fixture(void **state)
{
    (void)state;
    murk_plugin p;
    int rc = murk_plugin_open(fixture("good_fixture"), MURK_KIND_MATERIAL, &p, err, sizeof err);
    if (rc != 0)
        fail_msg("good_fixture: %s", err);
    assert_non_null(p.handle);
    assert_non_null(p.desc);
    assert_string_equal(p.desc->name, "good_fixture");
    assert_int_equal(p.desc->kind, MURK_KIND_MATERIAL);
    assert_int_equal(p.desc->nparams, 1);
    assert_string_equal(p.desc->params[0].name, "grey");
    assert_int_equal(p.abi.major, MURK_ABI_MAJOR);
    assert_int_equal(p.abi.minor, MURK_ABI_MINOR);
    assert_string_equal(p.path, fixture("good_fixture"));
    murk_plugin_close(&p);
    assert_null(p.handle);

    /* kind 0 accepts any kind; the right kind is accepted too */
    assert_int_equal(murk_plugin_open(fixture("wrong_kind"), 0, &p, err, sizeof err), 0);
    assert_int_equal(p.desc->kind, MURK_KIND_INTEGRATOR);
    murk_plugin_close(&p);
    assert_int_equal(murk_plugin_open(fixture("wrong_kind"), MURK_KIND_INTEGRATOR, &p, err, sizeof err), 0);
    murk_plugin_close(&p);
    /* ... but not as a medium */
    assert_int_equal(murk_plugin_open(fixture("wrong_kind"), MURK_KIND_MEDIUM, &p, err, sizeof err), -1);
    assert_contains(err, "integrator plugin, not a medium");
}

static void test_open_not_a_library(void **state)
{
    (void)state;
    murk_plugin p;
    const char *missing = fixture("no_such_fixture");
    assert_int_equal(murk_plugin_open(missing, 0, &p, err, sizeof err), -1);
    assert_contains(err, missing);
    assert_contains(err, "cannot read: No such file");
    /* a text file named .so */
    const char *txt = write_tmp("text.so", "this is not an ELF file\n");
    assert_int_equal(murk_plugin_open(txt, 0, &p, err, sizeof err), -1);
    assert_contains(err, "not an ELF shared object");
    /* another major ABI with an aborting constructor: refused from the symbol table, never loaded */
    const char *ctor = fixture("abi_ctor");
    assert_int_equal(murk_plugin_open(ctor, 0, &p, err, sizeof err), -1);
    assert_contains(err, "built for plugin ABI 2.0, this murk has ABI 1." MINOR);
    assert_null(strchr(err, '\n'));
}

/* ---- the registry ------------------------------------------------------------------------------ */

static void test_registry_fixtures(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    murk_registry r;
    murk_registry_init(&r);
    assert_true(r.ndirs >= 2);
    assert_string_equal(r.dirs[0], fixture_dir()); /* MURK_PLUGIN_PATH comes first */

    for (size_t i = 0; i < NBAD; i++) {
        const bad_case *c = &bad_cases[i];
        memset(err, 0, sizeof err);
        const murk_plugin *p = murk_registry_load(&r, c->kind, c->fixture, err, sizeof err);
        if (p)
            fail_msg("%s: loaded through the registry", c->fixture);
        assert_contains(err, fixture(c->fixture)); /* names the file */
        assert_contains(err, c->msg);
        assert_int_equal(r.nloaded, 0);
    }

    const murk_plugin *g = murk_registry_load(&r, MURK_KIND_MATERIAL, "good_fixture", err, sizeof err);
    if (!g)
        fail_msg("good_fixture: %s", err);
    assert_int_equal(r.nloaded, 1);
    assert_ptr_equal(murk_registry_load(&r, MURK_KIND_MATERIAL, "good_fixture", err, sizeof err), g); /* cached */
    assert_ptr_equal(murk_registry_load(&r, 0, "good_fixture", err, sizeof err), g);
    assert_int_equal(r.nloaded, 1);
    /* a cached plugin asked for as another kind */
    assert_null(murk_registry_load(&r, MURK_KIND_INTEGRATOR, "good_fixture", err, sizeof err));
    assert_contains(err, "material plugin, not a");
    assert_contains(err, "integrator");

    /* names that could leave the search folders are refused before any file is touched */
    static const char *const bad_names[] = {"../evil", "a/b", "", ".hidden", "x.so", "name with space",
                                            "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"};
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; i++) {
        assert_null(murk_registry_load(&r, MURK_KIND_MATERIAL, bad_names[i], err, sizeof err));
        assert_contains(err, "is not a plugin name");
    }
    assert_null(murk_registry_load(&r, MURK_KIND_MATERIAL, "nonexistent", err, sizeof err));
    assert_contains(err, "no material plugin 'nonexistent' (searched");
    assert_contains(err, fixture_dir());
    assert_int_equal(r.nloaded, 1);
    murk_registry_free(&r);
    assert_int_equal(r.nloaded, 0);
    unsetenv("MURK_PLUGIN_PATH");
}

/* The file a name resolves to is the first on the search path; a broken one there is an error, not a
 * reason to look further (which would let an earlier folder shadow silently). */
static void test_registry_search_order(void **state)
{
    (void)state;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/shadow", tmp_dir());
    mkdir(dir, 0755);
    char to[1200];
    snprintf(to, sizeof to, "%s/diffuse.so", dir);
    copy_file(fixture("good_fixture"), to);
    setenv("MURK_PLUGIN_PATH", dir, 1);
    murk_registry r;
    murk_registry_init(&r);
    assert_null(murk_registry_load(&r, MURK_KIND_MATERIAL, "diffuse", err, sizeof err));
    assert_contains(err, to);
    assert_contains(err, "declares the name 'good_fixture' but its file is named 'diffuse.so'");
    murk_registry_free(&r);
    unsetenv("MURK_PLUGIN_PATH");
    /* without it the built-in diffuse loads */
    murk_registry_init(&r);
    const murk_plugin *p = murk_registry_load(&r, MURK_KIND_MATERIAL, "diffuse", err, sizeof err);
    if (!p)
        fail_msg("diffuse: %s", err);
    assert_string_equal(p->desc->name, "diffuse");
    murk_registry_free(&r);
    unlink(to);
    rmdir(dir);
}

/* An empty MURK_PLUGIN_PATH entry (or an empty variable) never means the current folder. */
static void test_empty_path_entry_not_cwd(void **state)
{
    (void)state;
    char old[4096];
    assert_non_null(getcwd(old, sizeof old));
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/cwd", tmp_dir());
    mkdir(dir, 0755);
    char to[1200];
    snprintf(to, sizeof to, "%s/cwdplug.so", dir);
    copy_file(fixture("good_fixture"), to);
    assert_int_equal(chdir(dir), 0);

    /* positive control: naming the folder explicitly finds the file (which then fails on its name) */
    setenv("MURK_PLUGIN_PATH", ".", 1);
    murk_registry r;
    murk_registry_init(&r);
    assert_null(murk_registry_load(&r, 0, "cwdplug", err, sizeof err));
    assert_contains(err, "./cwdplug.so");
    assert_contains(err, "declares the name 'good_fixture'");
    murk_registry_free(&r);

    static const char *const values[] = {":", "", "::", ":/nonexistent-murk-dir:", NULL};
    for (int i = 0; i < 5; i++) {
        if (values[i])
            setenv("MURK_PLUGIN_PATH", values[i], 1);
        else
            unsetenv("MURK_PLUGIN_PATH");
        murk_registry_init(&r);
        for (size_t k = 0; k < r.ndirs; k++) {
            assert_true(r.dirs[k][0] != 0);
            assert_string_not_equal(r.dirs[k], ".");
        }
        assert_null(murk_registry_load(&r, 0, "cwdplug", err, sizeof err));
        assert_contains(err, "no plugin 'cwdplug' (searched");
        assert_not_contains(err, "cwdplug.so");
        murk_registry_free(&r);
    }

    /* and the same through the command line, which inherits cwd and environment */
    setenv("MURK_PLUGIN_PATH", ":", 1);
    char *out = NULL;
    int st = run_murk(&out, "plugins", "cwdplug", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "no plugin 'cwdplug'");
    free(out);
    char scene[1400];
    snprintf(scene, sizeof scene, "%s/s.yaml", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fputs("murk: 1\nmaterials:\n  m: { type: cwdplug }\nshapes: []\n", f);
    fclose(f);
    st = run_murk(&out, "render", "s.yaml", "-o", "out.exr", "--spp", "1", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "s.yaml:3:14: material 'm': no material plugin 'cwdplug'");
    assert_int_equal(access("out.exr", F_OK), -1);
    free(out);

    unsetenv("MURK_PLUGIN_PATH");
    assert_int_equal(chdir(old), 0);
    unlink(scene);
    unlink(to);
    rmdir(dir);
}

/* ---- only the plugins a scene names are loaded ------------------------------------------------ */

static int mapped(const char *path)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_NOLOAD);
    if (h)
        dlclose(h);
    return h != NULL;
}

static void test_scene_loads_only_named(void **state)
{
    (void)state;
    unsetenv("MURK_PLUGIN_PATH");
    const char *cornell = src_path("scenes/cornell.yaml");
    murk_scene *s = murk_scene_load(cornell, NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("cornell: %s", err);
    assert_int_equal(s->reg.nloaded, 2);
    int have_diffuse = 0, have_path = 0;
    for (size_t i = 0; i < s->reg.nloaded; i++) {
        const char *n = s->reg.loaded[i]->desc->name;
        have_diffuse += !strcmp(n, "diffuse");
        have_path += !strcmp(n, "path");
    }
    assert_int_equal(have_diffuse, 1);
    assert_int_equal(have_path, 1);
    /* the other built plugins are not even mapped */
    assert_true(mapped(build_path("plugins/diffuse.so")));
    static const char *const others[] = {"plugins/ggx.so", "plugins/volpath.so", "plugins/volpath_nee.so",
                                         "plugins/delta.so", "plugins/spectral.so"};
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++)
        if (access(build_path(others[i]), F_OK) == 0 && mapped(build_path(others[i])))
            fail_msg("%s is loaded although the scene does not name it", others[i]);
    murk_scene_free(s);
    assert_false(mapped(build_path("plugins/diffuse.so"))); /* dlclosed with the scene */

    /* no materials and no integrator block: only the default integrator */
    const char *p = write_tmp("bare.yaml", "murk: 1\nshapes: []\n");
    s = murk_scene_load(p, NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("bare: %s", err);
    assert_int_equal(s->reg.nloaded, 1);
    assert_string_equal(s->reg.loaded[0]->desc->name, "path");
    murk_scene_free(s);

    /* a plugin named twice is loaded once */
    p = write_tmp("twice.yaml", "murk: 1\nmaterials:\n  a: { type: diffuse }\n  b: { type: diffuse, albedo: 0.2 }\n"
                                "shapes: []\n");
    s = murk_scene_load(p, NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("twice: %s", err);
    assert_int_equal(s->reg.nloaded, 2);
    assert_int_equal(s->nmaterials, 2);
    murk_scene_free(s);
}

/* ---- through the command line ------------------------------------------------------------------ */

static const char *scene_using(const char *name, const char *type, const char *extra)
{
    char text[1024], file[128];
    snprintf(text, sizeof text,
             "murk: 1\n"
             "render: { resolution: [8, 8], spp: 1 }\n"
             "materials:\n"
             "  grey: { type: %s%s }\n"
             "shapes:\n"
             "  - { type: sphere, center: [0, 0, 0], radius: 1, material: grey }\n"
             "  - { type: quad, center: [0, 3, 0], u: [1, 0, 0], v: [0, 0, 1], material: grey, emission: 5 }\n",
             type, extra);
    snprintf(file, sizeof file, "%s.yaml", name);
    return write_tmp(file, text);
}

/* A plugin that crashes: one line naming it, death by the signal, no output file. */
static void test_cli_crash(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    char exr[1100], want[1400];
    snprintf(exr, sizeof exr, "%s/crash.exr", tmp_dir());
    const char *scene = scene_using("cli_crasher", "crasher", "");
    char *out = NULL;
    int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", "--threads", "2", NULL);
    if (st != 128 + 11)
        fail_msg("crasher: exit status %d, expected death by SIGSEGV (139):\n%s", st, out);
    snprintf(want, sizeof want, "murk: crashed (SIGSEGV) in plugin 'crasher' (%s)\n", fixture("crasher"));
    assert_contains(out, want);
    assert_int_equal(access(exr, F_OK), -1);
    free(out);
}

/* NaN from a plugin: the material or the integrator that produced it is named. */
static void test_cli_nan_culprit(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    char exr[1100];
    snprintf(exr, sizeof exr, "%s/nan.exr", tmp_dir());
    const char *scene = scene_using("cli_nan_material", "nan_material", "");
    char *out = NULL;
    int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "4", NULL);
    assert_int_equal(st, 0);
    /* the scene's instance, and beside it the plugin and its file */
    char want[1400];
    snprintf(want, sizeof want, "material 'grey' [plugin nan_material, %s/nan_material.so] returned a non-finite sample: "
             "the path was ended there", fixture_dir());
    assert_contains(out, want);
    free(out);
    murk_image img;
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    assert_string_equal(murk_image_meta(&img, "murk:nonfinite_samples"), "0");
    murk_image_free(&img);
    scene = scene_using("cli_nan_integrator", "good_fixture", " }\nintegrator: { type: nan_integrator");
    st = run_murk(&out, "render", scene, "-o", exr, "--spp", "2", NULL);
    if (st != 0)
        fail_msg("nan_integrator render: status %d:\n%s", st, out);
    snprintf(want, sizeof want, "integrator 'nan_integrator' [%s/nan_integrator.so] returned 128 NaN or infinite samples",
             fixture_dir());
    assert_contains(out, want);
    free(out);
}

/* A plugin built against the ABI 1.0 headers (a smaller descriptor) loads in this 1.4 host and
 * renders; murk's own plugins carry their version (1.1's appended field). */
static void test_old_minor(void **state)
{
    (void)state;
    murk_plugin p;
    assert_int_equal(murk_plugin_open(fixture("old_minor"), MURK_KIND_MATERIAL, &p, err, sizeof err), 0);
    assert_int_equal(p.abi.major, 1);
    assert_int_equal(p.abi.minor, 0);
    assert_int_equal(p.desc->struct_size, MURK_PLUGIN_DESC_SIZE_1_0);
    assert_null(p.version);
    murk_plugin_close(&p);
    assert_int_equal(murk_plugin_open(build_path("plugins/diffuse.so"), MURK_KIND_MATERIAL, &p, err, sizeof err), 0);
    assert_non_null(p.version);
    assert_string_equal(p.version, MURK_VERSION_FOR_TESTS);
    murk_plugin_close(&p);

    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    char exr[1100];
    snprintf(exr, sizeof exr, "%s/old_minor.exr", tmp_dir());
    const char *scene = scene_using("cli_old_minor", "old_minor", "");
    char *out = NULL;
    int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", "--quiet", NULL);
    if (st != 0)
        fail_msg("old_minor render: status %d:\n%s", st, out);
    free(out);
    murk_image img;
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    char rec[1300];
    snprintf(rec, sizeof rec, "old_minor=%s (version none, ABI 1.0)", fixture("old_minor"));
    assert_contains(murk_image_meta(&img, "murk:plugins"), rec);
    murk_image_free(&img);
}

/* A material without the prepared methods of ABI 1.7 (good_fixture: a grey Lambertian whose vtable leaves
 * them NULL) goes through the hit-based methods and renders the same pixels, bit for bit, as the
 * built-in diffuse of the same albedo through prepare(): the integrators' fallback changes nothing. */
static void test_unprepared_material_renders_like_prepared(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    const char *scenes[2] = {scene_using("cli_unprepared", "good_fixture", ", grey: 0.5"),
                             scene_using("cli_prepared", "diffuse", ", albedo: 0.5")};
    murk_image img[2];
    for (int k = 0; k < 2; k++) {
        char exr[1100];
        snprintf(exr, sizeof exr, "%s/prepared%d.exr", tmp_dir(), k);
        char *out = NULL;
        int st = run_murk(&out, "render", scenes[k], "-o", exr, "--spp", "16", "--quiet", NULL);
        if (st != 0)
            fail_msg("%s: status %d:\n%s", scenes[k], st, out);
        free(out);
        assert_int_equal(murk_exr_read(exr, &img[k], err, sizeof err), 0);
    }
    assert_int_equal(img[0].w, img[1].w);
    assert_int_equal(img[0].h, img[1].h);
    assert_memory_equal(img[0].rgb, img[1].rgb, sizeof(float) * 3 * (size_t)img[0].w * (size_t)img[0].h);
    murk_image_free(&img[0]);
    murk_image_free(&img[1]);
}

static void test_cli_render_fixtures(void **state)
{
    (void)state;
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    char outdir[1024], exr[1100], png[1100];
    snprintf(outdir, sizeof outdir, "%s/cli-out", tmp_dir());
    mkdir(outdir, 0755);
    snprintf(exr, sizeof exr, "%s/out.exr", outdir);
    snprintf(png, sizeof png, "%s/out.png", outdir);

    for (size_t i = 0; i < NBAD; i++) {
        const bad_case *c = &bad_cases[i];
        if (!c->kind) /* kind-agnostic cases: named as a material they fail the kind check first */
            continue;
        char name[64];
        snprintf(name, sizeof name, "cli_%s", c->fixture);
        const char *scene = scene_using(name, c->fixture, "");
        char *out = NULL;
        int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
        if (st != 1)
            fail_msg("%s: exit status %d (want 1; >= 128 is a signal):\n%s", c->fixture, st, out);
        char want[1200];
        snprintf(want, sizeof want, "%s:4:17: material 'grey': plugin %s: ", scene, fixture(c->fixture));
        if (strncmp(out, want, strlen(want)) != 0)
            fail_msg("%s: expected the message to start with\n%s\ngot\n%s", c->fixture, want, out);
        assert_contains(out, c->msg);
        assert_int_equal(count_lines(out), 1);
        assert_int_equal(access(exr, F_OK), -1);
        assert_int_equal(access(png, F_OK), -1);
        free(out);
    }

    /* create() fails: its message behind the block's file:line:col, with the parameter it got */
    const char *scene = scene_using("cli_create_fails", "create_fails", ", level: 0.75");
    char *out = NULL;
    int st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    char want[1200];
    snprintf(want, sizeof want, "%s:4:9: material 'grey' (create_fails): this fixture always refuses (level 0.75)\n",
             scene);
    assert_string_equal(out, want);
    assert_int_equal(access(exr, F_OK), -1);
    free(out);

    /* the good fixture renders */
    scene = scene_using("cli_good", "good_fixture", ", grey: 0.3");
    st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", "--quiet", NULL);
    if (st != 0)
        fail_msg("good_fixture render: status %d:\n%s", st, out);
    assert_int_equal(access(exr, F_OK), 0);
    assert_int_equal(access(png, F_OK), 0);
    free(out);
    /* the EXR records every plugin it loaded, with its file and ABI version */
    murk_image img;
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    const char *plugins = murk_image_meta(&img, "murk:plugins");
    assert_non_null(plugins);
    char rec[1300];
    snprintf(rec, sizeof rec, "good_fixture=%s (version none, ABI 1." MINOR ")", fixture("good_fixture"));
    assert_contains(plugins, rec);
    assert_contains(plugins, "path=");
    murk_image_free(&img);
    unlink(exr);
    unlink(png);
    /* a plugin earlier on the search path hides one of the same name later on it: said once, naming both */
    char later[1100], copy[1200];
    snprintf(later, sizeof later, "%s/later", tmp_dir());
    mkdir(later, 0755);
    snprintf(copy, sizeof copy, "%s/good_fixture.so", later);
    copy_file(fixture("good_fixture"), copy);
    char path2[2400];
    snprintf(path2, sizeof path2, "%s:%s", fixture_dir(), later);
    setenv("MURK_PLUGIN_PATH", path2, 1);
    scene = scene_using("cli_good_hidden", "good_fixture", ", grey: 0.3");
    st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", "--quiet", NULL);
    assert_int_equal(st, 0);
    snprintf(rec, sizeof rec, "plugin 'good_fixture': %s hides %s", fixture("good_fixture"), copy);
    assert_contains(out, rec);
    free(out);
    unlink(exr);
    unlink(png);
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    /* its parameters are checked against its schema like a built-in's */
    scene = scene_using("cli_good_typo", "good_fixture", ", gray: 0.3");
    st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "unknown parameter 'gray' for material 'grey' (good_fixture) (did you mean 'grey'?)");
    free(out);
    scene = scene_using("cli_good_range", "good_fixture", ", grey: 2");
    st = run_murk(&out, "render", scene, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "parameter 'grey' must be in [0, 1], got 2");
    free(out);

    /* an integrator plugin named where a material is expected, and the reverse */
    const char *p = write_tmp("cli_kind.yaml", "murk: 1\nintegrator: { type: good_fixture }\nshapes: []\n");
    st = run_murk(&out, "render", p, "-o", exr, "--spp", "1", NULL);
    assert_int_equal(st, 1);
    snprintf(want, sizeof want, "%s:2:21: integrator: plugin %s: 'good_fixture' is a material plugin, not a", p,
             fixture("good_fixture"));
    assert_contains(out, want);
    free(out);
    unsetenv("MURK_PLUGIN_PATH");
    rmdir(outdir);
}

static void test_cli_plugins(void **state)
{
    (void)state;
    unsetenv("MURK_PLUGIN_PATH");
    char *out = NULL;
    int st = run_murk(&out, "plugins", NULL);
    assert_int_equal(st, 0);
    if (!has_line_with(out, "material", " diffuse "))
        fail_msg("no 'material diffuse' line in:\n%s", out);
    if (!has_line_with(out, "integrator", " path "))
        fail_msg("no 'integrator path' line in:\n%s", out);
    assert_not_contains(out, "(broken)");
    assert_not_contains(out, "good_fixture"); /* fixtures are not on the default path */
    free(out);

    st = run_murk(&out, "plugins", "diffuse", NULL);
    assert_int_equal(st, 0);
    assert_contains(out, "material diffuse");
    if (!has_line_with(out, "albedo", "[0.5, 0.5, 0.5]") || !has_line_with(out, "albedo", "[0, 1]"))
        fail_msg("albedo's default [0.5, 0.5, 0.5] and range [0, 1] not shown:\n%s", out);
    assert_true(has_line_with(out, "albedo", "rgb"));
    assert_true(has_line_with(out, "albedo", "(texturable)"));
    free(out);

    st = run_murk(&out, "plugins", "path", NULL);
    assert_int_equal(st, 0);
    assert_true(has_line_with(out, "max_depth", "64"));
    free(out);

    st = run_murk(&out, "plugins", "nonexistent", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "no plugin 'nonexistent'");
    assert_int_equal(count_lines(out), 1);
    free(out);

    st = run_murk(&out, "plugins", "../evil", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "is not a plugin name");
    free(out);

    /* listing a folder of broken plugins: each is one "(broken)" line, nothing runs or crashes */
    setenv("MURK_PLUGIN_PATH", fixture_dir(), 1);
    st = run_murk(&out, "plugins", NULL);
    if (st != 0)
        fail_msg("murk plugins with the fixtures: status %d:\n%s", st, out);
    assert_true(has_line_with(out, "material", "good_fixture"));
    assert_true(has_line_with(out, "(broken)", "abi_major"));
    assert_true(has_line_with(out, "(broken)", "no_abi"));
    assert_true(has_line_with(out, "(broken)", "name_mismatch"));
    assert_true(has_line_with(out, "material", " diffuse ")); /* the built-ins are still listed */
    free(out);
    st = run_murk(&out, "plugins", "abi_major", NULL);
    assert_int_equal(st, 1);
    assert_contains(out, "built for plugin ABI 2.0, this murk has ABI 1." MINOR);
    assert_contains(out, fixture("abi_major"));
    free(out);
    st = run_murk(&out, "plugins", "good_fixture", NULL);
    assert_int_equal(st, 0);
    assert_true(has_line_with(out, "grey", "[0, 1]"));
    free(out);
    unsetenv("MURK_PLUGIN_PATH");
}

int main(void)
{
    unsetenv("MURK_PLUGIN_PATH");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_bad_fixtures),
        cmocka_unit_test(test_open_bad_details),
        cmocka_unit_test(test_open_good_fixture),
        cmocka_unit_test(test_open_not_a_library),
        cmocka_unit_test(test_registry_fixtures),
        cmocka_unit_test(test_registry_search_order),
        cmocka_unit_test(test_empty_path_entry_not_cwd),
        cmocka_unit_test(test_scene_loads_only_named),
        cmocka_unit_test(test_cli_render_fixtures),
        cmocka_unit_test(test_cli_crash),
        cmocka_unit_test(test_old_minor),
        cmocka_unit_test(test_unprepared_material_renders_like_prepared),
        cmocka_unit_test(test_cli_nan_culprit),
        cmocka_unit_test(test_cli_plugins),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
