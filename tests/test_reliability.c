/* test_reliability.c — regressions for issue 10's classes, each a case that broke a promise before:
 *   1. values that pass validation but break float arithmetic: a medium too dense for float t (hung
 *      every tracker), a camera beyond what Embree accepts (SIGABRT) and the host's range check of every
 *      ray against its scalar statement, free-flight loops that must advance and stop at the
 *      watchdog's cap (bounded-time tests under alarm());
 *   2. allocations sized by untrusted headers or endless input: declared-size checks on PNG, EXR and
 *      grid headers, and devices/FIFOs refused without reading or blocking;
 *   3. files left behind or replaced: the EXR and PNG are written both or neither, temporaries are
 *      removed on SIGTERM/SIGINT, and a device or directory is never replaced (the folder is inspected);
 *   4. messages that mislead: exact text for escaped names, a directory as the scene, strict CLI numbers. */
#include "testutil.h"

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "util/atomic.h"
#include "render/host.h"
#include "scene/scene.h"
#include "media/density.h"
#include "image/image.h"
#include "util/limit.h"
#include "util/util.h"
#include "murk/medium.h"
#include "murk/tracking.h"

/* A fresh folder under the test's temporary folder. */
static const char *fresh_dir(const char *name)
{
    static char buf[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmp_dir(), name);
    mkdir(buf[k], 0755);
    return buf[k];
}

static const char *join(const char *dir, const char *name)
{
    static char buf[8][600];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

/* Names in dir, space-separated and sorted ("" if empty). */
static void list_dir(const char *dir, char *out, size_t n)
{
    char names[64][256];
    int count = 0;
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)) && count < 64)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            snprintf(names[count++], 256, "%s", e->d_name);
    closedir(d);
    for (int a = 0; a < count; a++)
        for (int b = a + 1; b < count; b++)
            if (strcmp(names[b], names[a]) < 0) {
                char t[256];
                memcpy(t, names[a], 256);
                memcpy(names[a], names[b], 256);
                memcpy(names[b], t, 256);
            }
    out[0] = 0;
    for (int a = 0; a < count; a++)
        snprintf(out + strlen(out), n - strlen(out), "%s%s", a ? " " : "", names[a]);
}

/* ---- 1. float arithmetic ------------------------------------------------------------------- */

/* sigma_s 1e8 x scale 1e8 (each inside its range) hung every tracker: now refused, located, naming the
 * optical depth. alarm() makes the old hang a failure rather than a stuck test. */
static void t_medium_too_dense(void **state)
{
    (void)state;
    const char *scene = write_tmp("dense.yaml",
        "murk: 1\nrender: { resolution: [8, 8], spp: 1 }\ncamera: { from: [0, 0.5, 3], at: [0, 0.5, 0] }\n"
        "integrator: { type: volpath }\nmedia:\n"
        "  c: { type: delta, density: { cloud: { min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5], resolution: 8 } }, "
        "sigma_s: 1e8, scale: 1e8 }\n"
        "shapes:\n  - { type: box, min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5], interior: c }\n");
    char *out = NULL;
    alarm(60);
    int rc = run_murk(&out, "render", scene, "-o", join(fresh_dir("dense"), "o.exr"), "--quiet", NULL);
    alarm(0);
    assert_int_equal(rc, 1);
    char want[1024];
    snprintf(want, sizeof want, "%s:6:123: medium 'c': optical depth ", scene);
    assert_contains(out, want);
    assert_contains(out, "exceeds 1e+06, the most float arithmetic can track");
    free(out);
}

/* A camera at 2e18 died on Embree's ray.valid() assertion; at 1e30 the error blamed `up`. */
static void t_camera_far(void **state)
{
    (void)state;
    static const char *const zs[] = {"2e18", "1e30"};
    for (int i = 0; i < 2; i++) {
        char text[256], name[32], want[512];
        snprintf(text, sizeof text, "murk: 1\ncamera: { from: [0, 0, %s] }\nshapes: []\n", zs[i]);
        snprintf(name, sizeof name, "far%d.yaml", i);
        const char *scene = write_tmp(name, text);
        char *out = NULL;
        int rc = run_murk(&out, "render", scene, "-o", join(fresh_dir("far"), "o.exr"), "--quiet", NULL);
        assert_int_equal(rc, 1); /* not 128 + SIGABRT */
        snprintf(want, sizeof want, "%s:2:24: camera.from: %g is beyond 1e+15, the largest coordinate murk accepts",
                 scene, atof(zs[i]));
        assert_contains(out, want);
        assert_null(strstr(out, "'up'"));
        free(out);
    }
}

/* host.c hands Embree only rays it can carry (Embree asserts, SIGABRT, on an origin or direction beyond
 * about 1.8e18 or not finite, a NaN or negative tnear, a NaN tfar). The check runs on every ray, so it is
 * one pass of SSE bound compares: here against its scalar statement on the edge values of each of the 8
 * floats, through the host's intersect() and occluded(). A refused ray is not traced (no hit, not
 * occluded) nor counted. */
static int scalar_traceable(const murk_ray *r)
{
    const float big = 1e18f;
    return fabsf(r->o.x) <= big && fabsf(r->o.y) <= big && fabsf(r->o.z) <= big && fabsf(r->d.x) <= big &&
           fabsf(r->d.y) <= big && fabsf(r->d.z) <= big && r->tmin >= 0.0f && r->tmin <= INFINITY && !isnan(r->tmax);
}

static void t_ray_range(void **state)
{
    (void)state;
    char err[1024];
    murk_scene *s = murk_scene_load(write_tmp("range.yaml", "murk: 1\nmaterials: { w: { type: diffuse } }\n"
                                              "shapes: [ { type: box, min: [-1, -1, -1], max: [1, 1, 1], material: w } ]\n"),
                                    NULL, 0, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    const murk_host *h = murk_host_table();
    const float edge[] = {0.0f, -0.0f, 1e18f, -1e18f, nextafterf(1e18f, INFINITY), -nextafterf(1e18f, INFINITY),
                          INFINITY, -INFINITY, NAN, -NAN, 1e-45f, -1e-45f};
    int n = (int)(sizeof edge / sizeof edge[0]), checked = 0;
    for (int f = 0; f < 8; f++)
        for (int e = 0; e < n; e++) {
            murk_ray r = {murk_v3(0.1f, 0.2f, 0.3f), murk_v3(0.0f, 0.6f, 0.8f), 0.0f, INFINITY};
            float *v = &r.o.x; /* o, d, tmin, tmax: 8 floats */
            v[f] = edge[e];
            int want = scalar_traceable(&r);
            murk_hit hit;
            murk_host_thread_reset();
            int found = h->intersect(s, &r, &hit);
            h->occluded(s, &r);
            assert_int_equal(murk_host_thread_rays(), want ? 2u : 0u);
            if (!want)
                assert_int_equal(found, 0);
            checked++;
        }
    murk_host_thread_reset();
    murk_scene_free(s);
    printf("ray range: %d rays, each traced exactly when the scalar test accepts it\n", checked);
}

/* A fake host for driving tracking.h: one majorant segment [t0, t1) of density dmax. */
typedef struct fake_walk { float t0, t1, dmax; int done; } fake_walk;
static float fake_t0, fake_t1, fake_dmax;
static char fake_warning[512];
static long fake_lookups;

static float fake_density(const murk_density *d, murk_vec3 p)
{
    (void)d;
    (void)p;
    fake_lookups++;
    return 0.0f; /* every collision is null: the flight must cross the whole segment */
}
static void fake_walk_init(const murk_density *d, const murk_ray *r, float t0, float t1, murk_majorant_walk *w)
{
    (void)d, (void)r, (void)t0, (void)t1;
    fake_walk *f = (fake_walk *)(void *)w;
    f->t0 = fake_t0, f->t1 = fake_t1, f->dmax = fake_dmax, f->done = 0;
}
static int fake_walk_next(murk_majorant_walk *w, float *ta, float *tb, float *dmax, float *dmin)
{
    fake_walk *f = (fake_walk *)(void *)w;
    if (f->done)
        return 0;
    f->done = 1;
    *ta = f->t0, *tb = f->t1, *dmax = f->dmax, *dmin = 0.0f;
    return 1;
}
static void fake_warn_once(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(fake_warning, sizeof fake_warning, fmt, ap);
    va_end(ap);
}
static void *fake_alloc(size_t n) { return calloc(1, n); }

/* The host services a tracker's collision loop uses, over the fake walk above. */
static void fake_host(murk_host *h)
{
    memset(h, 0, sizeof *h);
    h->size = sizeof *h;
    h->alloc = fake_alloc;
    h->free = free;
    h->density = fake_density;
    h->walk_init = fake_walk_init;
    h->walk_next = fake_walk_next;
    h->warn_once = fake_warn_once;
}

/* The collision loop had no progress guard: a step below the float spacing of t left t where it was,
 * forever. Now t advances by at least one float and the watchdog stops the flight at
 * MURK_WATCHDOG_ITERATIONS, naming the tracker and the medium. Bounded by alarm(). */
static void t_tracker_progress_and_watchdog(void **state)
{
    (void)state;
    murk_host h;
    fake_host(&h);
    murk_medium_data d = {sizeof d, murk_rgb1(0.0f), murk_rgb1(1e10f), 0.0f, NULL, "m", 0, 0, 0};
    char err[128];
    murk_tracker *t = murk_tracker_new(&h, &d, sizeof *t, err, sizeof err);
    assert_non_null(t);
    t->plugin = "delta";
    murk_ray ray = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, INFINITY};
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    alarm(60);
    /* a short segment far from 0: mean step 1e-20, float spacing of t ~1e-7 — crossed float by float */
    fake_t0 = 1.0f, fake_t1 = nextafterf(nextafterf(1.0f, 2.0f), 2.0f), fake_dmax = 1e10f;
    murk_collisions c;
    murk_collisions_init(&c, t, &ray, t->smax);
    float tt, dens;
    long n = 0;
    while (murk_collisions_next(&c, &rng, &tt, &dens))
        n++;
    assert_int_equal(c.stopped, 0);
    assert_true(n >= 1 && n <= 3);
    /* an endless segment: the watchdog ends it and reports with the plugin's name */
    fake_t0 = 1.0f, fake_t1 = INFINITY;
    fake_warning[0] = 0;
    murk_collisions_init(&c, t, &ray, t->smax);
    n = 0;
    while (murk_collisions_next(&c, &rng, &tt, &dens))
        n++;
    assert_int_equal(c.stopped, 1);
    assert_true(n < MURK_WATCHDOG_ITERATIONS);
    assert_string_equal(fake_warning, "tracker 'delta' (medium 'm'): a free flight exceeded 16777216 iterations "
                                      "(MURK_WATCHDOG_ITERATIONS); the path was ended (biased)");
    /* ratio tracking over the same endless segment: transmittance 0, reported */
    fake_warning[0] = 0;
    murk_rgb T = murk_ratio_tracking(&h, &d, &ray, 0.0f, &rng);
    assert_true(T.c[0] == 0.0f);
    alarm(0);
    free(t);
}

/* The SDK's example tracker (plugins/examples/example_delta.c, built in-tree into tests/fixtures) does
 * what docs/plugins.md asks of every tracker at the watchdog's cap: its warning names it (base.plugin),
 * not '?', and the flight ends the path (c.stopped: weight 0), never passes the segment on. */
static void t_example_tracker_watchdog(void **state)
{
    (void)state;
    void *so = dlopen(build_path("tests/fixtures/example_delta.so"), RTLD_NOW | RTLD_LOCAL);
    if (!so)
        fail_msg("dlopen example_delta.so: %s", dlerror());
    const murk_plugin_desc *(*entry)(void);
    *(void **)&entry = dlsym(so, MURK_PLUGIN_ENTRY_SYMBOL);
    assert_non_null(entry);
    const murk_medium_vt *vt = entry()->vtable;
    murk_host h;
    fake_host(&h);
    murk_medium_data d = {sizeof d, murk_rgb1(0.0f), murk_rgb1(1e10f), 0.0f, NULL, "m", 0, 0, 0};
    char err[256];
    void *self = NULL;
    assert_int_equal(vt->create(&h, &d, NULL, &self, err, sizeof err), 0);
    murk_ray ray = {murk_v3(0, 0, 0), murk_v3(0, 0, 1), 0.0f, INFINITY};
    murk_path_ctx ctx = {.hero = 0, .beta = {{1, 1, 1}}};
    murk_rng rng;
    murk_rng_seed(&rng, 1, 2, 3);
    murk_medium_event ev;
    alarm(60);
    fake_t0 = 1.0f, fake_t1 = INFINITY, fake_dmax = 1e10f;
    fake_warning[0] = 0;
    vt->sample(self, &ray, &ctx, &rng, &ev);
    alarm(0);
    printf("example_delta at the watchdog's cap: scattered %d, weight %g, '%s'\n", ev.scattered, (double)ev.weight.c[0],
           fake_warning);
    assert_string_equal(fake_warning, "tracker 'example_delta' (medium 'm'): a free flight exceeded 16777216 iterations "
                                      "(MURK_WATCHDOG_ITERATIONS); the path was ended (biased)");
    assert_int_equal(ev.scattered, 1);
    assert_true(murk_rgb_is_black(ev.weight));
    vt->destroy(self);
    dlclose(so);
}

/* ---- 2. declared sizes and endless input --------------------------------------------------- */

static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}
static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24), p[1] = (unsigned char)(v >> 16), p[2] = (unsigned char)(v >> 8), p[3] = (unsigned char)v;
}

/* A PNG whose IHDR declares w x h RGB 8-bit, followed by a tiny IDAT and IEND. */
static const char *hostile_png(const char *name, uint32_t w, uint32_t h)
{
    unsigned char b[128];
    size_t n = 0;
    memcpy(b, "\x89PNG\r\n\x1a\n", 8);
    n = 8;
    put32(b + n, 13);
    memcpy(b + n + 4, "IHDR", 4);
    put32(b + n + 8, w);
    put32(b + n + 12, h);
    b[n + 16] = 8, b[n + 17] = 2, b[n + 18] = 0, b[n + 19] = 0, b[n + 20] = 0;
    put32(b + n + 21, crc32_of(b + n + 4, 17));
    n += 25;
    static const unsigned char idat[] = {0x78, 0x9c, 0x63, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01};
    put32(b + n, sizeof idat);
    memcpy(b + n + 4, "IDAT", 4);
    memcpy(b + n + 8, idat, sizeof idat);
    put32(b + n + 8 + sizeof idat, crc32_of(b + n + 4, 4 + sizeof idat));
    n += 12 + sizeof idat;
    put32(b + n, 0);
    memcpy(b + n + 4, "IEND", 4);
    put32(b + n + 8, crc32_of(b + n + 4, 4));
    n += 12;
    const char *path = join(tmp_dir(), name);
    write_file(path, b, n);
    return path;
}

/* A 33 KB PNG declaring 16384 x 16384 took 3.9 GB: refused from the header, by the limit and by the
 * file's real size. */
static void t_png_declared_size(void **state)
{
    (void)state;
    murk_image img;
    char err[512], want[700];
    const char *p = hostile_png("huge.png", 16384, 16384);
    assert_int_equal(murk_png_read(p, 1, &img, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: cannot read PNG: PNG of 16384x16384 pixels exceeds the limit of 67108864 pixels "
             "(MURK_MAX_IMAGE_PIXELS)", p);
    assert_string_equal(err, want);
    p = hostile_png("liar.png", 4096, 4096); /* under the limit, but 48 MiB from ~70 bytes */
    assert_int_equal(murk_png_read(p, 1, &img, err, sizeof err), -1);
    assert_contains(err, "header declares 4096x4096 pixels but the file holds only");
}

/* murk compare sized buffers from EXR headers before validating them: a 4x4 EXR whose data window is
 * patched to 100000 x 100000 is refused before any pixel buffer. */
static void t_exr_declared_size(void **state)
{
    (void)state;
    float rgb[4 * 4 * 3] = {0};
    char err[512];
    const char *p = join(tmp_dir(), "small.exr");
    assert_int_equal(murk_exr_write(p, rgb, 4, 4, NULL, 0, err, sizeof err), 0);
    FILE *f = fopen(p, "r+b");
    assert_non_null(f);
    unsigned char buf[4096];
    size_t n = fread(buf, 1, sizeof buf, f);
    const unsigned char *dw = NULL;
    for (size_t i = 0; i + 30 < n && !dw; i++)
        if (memcmp(buf + i, "dataWindow\0box2i\0", 17) == 0)
            dw = buf + i + 17 + 4; /* after the name, type and size: xmin ymin xmax ymax */
    assert_non_null(dw);
    long off = (long)(dw - buf) + 8;
    unsigned char big[8] = {0x9f, 0x86, 0x01, 0, 0x9f, 0x86, 0x01, 0}; /* 99999, 99999 */
    fseek(f, off, SEEK_SET);
    fwrite(big, 1, 8, f);
    fclose(f);
    murk_image img;
    assert_int_equal(murk_exr_read(p, &img, err, sizeof err), -1);
    assert_contains(err, "EXR of 100000x100000 pixels exceeds the limit of 67108864 pixels (MURK_MAX_IMAGE_PIXELS)");
    char *out = NULL;
    assert_int_equal(run_murk(&out, "compare", p, p, NULL), 1);
    assert_contains(out, "exceeds the limit of 67108864 pixels");
    free(out);
}

/* A mesh naming /dev/zero grew memory without bound; a FIFO hung. Both refused at once. */
static void t_devices_and_fifos(void **state)
{
    (void)state;
    const char *dir = fresh_dir("fifo");
    const char *fifo = join(dir, "pipe.obj");
    assert_int_equal(mkfifo(fifo, 0644), 0);
    char text[1024], *out = NULL;
    alarm(60);
    snprintf(text, sizeof text, "murk: 1\nmaterials: { w: { type: diffuse } }\nshapes:\n  - { type: mesh, file: /dev/zero, material: w }\n");
    const char *scene = write_tmp("devzero.yaml", text);
    assert_int_equal(run_murk(&out, "render", scene, "-o", join(dir, "o.exr"), NULL), 1);
    assert_contains(out, "/dev/zero: a character device, not a regular file");
    free(out);
    snprintf(text, sizeof text, "murk: 1\nmaterials: { w: { type: diffuse } }\nshapes:\n  - { type: mesh, file: %s, material: w }\n", fifo);
    scene = write_tmp("fifo.yaml", text);
    assert_int_equal(run_murk(&out, "render", scene, "-o", join(dir, "o.exr"), NULL), 1);
    assert_contains(out, "pipe.obj: a FIFO, not a regular file");
    free(out);
    /* the scene itself, a texture, a grid */
    assert_int_equal(run_murk(&out, "render", fifo, "-o", join(dir, "o.exr"), NULL), 1);
    assert_contains(out, "pipe.obj: is a FIFO, not a scene file");
    free(out);
    murk_image img;
    char err[512];
    assert_int_equal(murk_png_read(fifo, 1, &img, err, sizeof err), -1);
    assert_contains(err, "a FIFO, not a regular file");
    assert_null(murk_field_vol_load("/dev/zero", err, sizeof err));
    assert_contains(err, "/dev/zero: a character device, not a regular file");
    alarm(0);
}

/* Grid sizes: a cloud beyond the voxel limit is named as such (it said "out of memory?"). */
static void t_grid_voxel_limit(void **state)
{
    (void)state;
    char *out = NULL;
    const char *dir = fresh_dir("gridlimit");
    assert_int_equal(run_murk(&out, "grid", join(dir, "g.vol"), "--res", "1024", NULL), 1);
    assert_string_equal(out, "murk: --res 1024 gives 1073741824 voxels, beyond the limit of 134217728 "
                             "(MURK_MAX_GRID_VOXELS)\n");
    free(out);
    char names[1024];
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "");
}

/* ---- 3. files left behind or replaced ------------------------------------------------------ */

/* When the PNG could not be written the EXR stayed: a group is committed both or neither. */
static void t_group_all_or_nothing(void **state)
{
    (void)state;
    const char *dir = fresh_dir("group");
    float rgb[2 * 2 * 3] = {0.5f};
    char err[512], names[1024];
    murk_output_begin();
    assert_int_equal(murk_exr_write(join(dir, "o.exr"), rgb, 2, 2, NULL, 0, err, sizeof err), 0);
    assert_int_equal(murk_png_write(join(dir, "missing/o.png"), rgb, 2, 2, 0.0f, err, sizeof err), -1);
    murk_output_abort();
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "");
    murk_output_begin();
    assert_int_equal(murk_exr_write(join(dir, "o.exr"), rgb, 2, 2, NULL, 0, err, sizeof err), 0);
    assert_int_equal(murk_png_write(join(dir, "o.png"), rgb, 2, 2, 0.0f, err, sizeof err), 0);
    list_dir(dir, names, sizeof names); /* nothing renamed before the commit */
    char want[256];
    snprintf(want, sizeof want, "o.exr.tmp-%ld o.png.tmp-%ld", (long)getpid(), (long)getpid());
    assert_string_equal(names, want);
    assert_int_equal(murk_output_commit(err, sizeof err), 0);
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "o.exr o.png");
}

/* The same end to end: an output PNG that cannot be replaced (a directory) leaves no EXR. */
static void t_render_no_half_output(void **state)
{
    (void)state;
    const char *dir = fresh_dir("half");
    mkdir(join(dir, "o.png"), 0755);
    char *out = NULL, names[1024];
    int rc = run_murk(&out, "render", src_path("scenes/cornell.yaml"), "-o", join(dir, "o.exr"), "--spp", "1", "--quiet",
                      NULL);
    assert_int_equal(rc, 1);
    char want[1024];
    snprintf(want, sizeof want, "murk: %s: is a directory; murk only replaces regular files\n", join(dir, "o.png"));
    assert_string_equal(out, want);
    free(out);
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "o.png");
}

/* A fill that is interrupted by sig half-way, in a child process: the child dies by the signal, the
 * folder holds neither the target nor a temporary. */
static int interrupt_fill(FILE *fp, const char *tmp, void *user, char *err, size_t errlen)
{
    (void)tmp, (void)err, (void)errlen;
    fputs("half", fp);
    fflush(fp);
    raise(*(int *)user);
    return 0;
}

static void t_signal_removes_temporaries(void **state)
{
    (void)state;
    static const int sigs[] = {SIGTERM, SIGINT};
    for (int i = 0; i < 2; i++) {
        const char *dir = fresh_dir(i ? "sigint" : "sigterm");
        pid_t pid = fork();
        if (pid == 0) {
            char err[256];
            int sig = sigs[i];
            murk_write_atomic(join(dir, "out.vol"), interrupt_fill, &sig, err, sizeof err);
            _exit(0);
        }
        int status = 0;
        waitpid(pid, &status, 0);
        assert_true(WIFSIGNALED(status) && WTERMSIG(status) == sigs[i]);
        char names[1024];
        list_dir(dir, names, sizeof names);
        assert_string_equal(names, "");
    }
}

/* murk grid renamed its output over whatever the path named (as root, /dev/full — which is why this
 * test names a FIFO of its own: run as root against a murk with the bug, /dev/full would be gone). */
static void t_never_replace_non_regular(void **state)
{
    (void)state;
    char *out = NULL, want[700];
    const char *dir = fresh_dir("nonreg");
    assert_int_equal(mkfifo(join(dir, "f.vol"), 0644), 0);
    alarm(60);
    assert_int_equal(run_murk(&out, "grid", join(dir, "f.vol"), "--res", "4", NULL), 1);
    alarm(0);
    snprintf(want, sizeof want, "murk: %s: is a FIFO; murk only replaces regular files\n", join(dir, "f.vol"));
    assert_string_equal(out, want);
    free(out);
    mkdir(join(dir, "d.vol"), 0755);
    assert_int_equal(symlink("/dev/null", join(dir, "l.vol")), 0);
    assert_int_equal(run_murk(&out, "grid", join(dir, "d.vol"), "--res", "4", NULL), 1);
    assert_contains(out, "d.vol: is a directory; murk only replaces regular files");
    free(out);
    assert_int_equal(run_murk(&out, "grid", join(dir, "l.vol"), "--res", "4", NULL), 1);
    assert_contains(out, "l.vol: is a symbolic link; murk only replaces regular files");
    free(out);
    char names[1024];
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "d.vol f.vol l.vol");
}

/* ---- 4. messages ---------------------------------------------------------------------------- */

static void t_printable(void **state)
{
    (void)state;
    char b[128];
    assert_string_equal(murk_printable(b, sizeof b, "a\nb\x1b[31mc\td\r\x7f"), "a\\nb\\e[31mc\\td\\r\\x7f");
    assert_string_equal(murk_printable(b, sizeof b, "caf\xc3\xa9 \xc2\x9b \xff"), "caf\xc3\xa9 \\u009b \\xff");
    assert_string_equal(murk_printable(b, 6, "abcdefgh"), "abcde");
    assert_string_equal(murk_printable(b, 4, "a\nb"), "a\\n");
}

/* Keys and names with newlines or escapes were echoed raw: a two-line error, an escape reaching the
 * terminal. Exact text, one line. */
static void t_escaped_names(void **state)
{
    (void)state;
    const char *scene = write_tmp("esc.yaml", "murk: 1\nshapes: []\nmaterials:\n  \"a\\nb\\e[31m\": { type: diffus }\n"
                                              "  w: { type: diffuse, \"k\\ey\": 1 }\n");
    char *out = NULL, want[1024];
    assert_int_equal(run_murk(&out, "render", scene, "-o", join(fresh_dir("esc"), "o.exr"), NULL), 1);
    snprintf(want, sizeof want, "%s:4:25: material 'a\\nb\\e[31m': no material plugin 'diffus' (did you mean 'diffuse'?;", scene);
    assert_contains(out, want);
    assert_null(strchr(out, '\x1b'));
    assert_ptr_equal(strchr(out, '\n'), out + strlen(out) - 1);
    free(out);
    assert_int_equal(run_murk(&out, "render", "\x1b[2Jx.yaml", "also\nthis", NULL), 2);
    assert_string_equal(out, "murk: more than one scene given ('\\e[2Jx.yaml' and 'also\\nthis')\n");
    free(out);
}

/* `murk render somedir/` complained about the output extension. */
static void t_scene_is_directory(void **state)
{
    (void)state;
    const char *dir = fresh_dir("scenedir");
    char arg[600], want[700], *out = NULL;
    snprintf(arg, sizeof arg, "%s/", dir);
    assert_int_equal(run_murk(&out, "render", arg, NULL), 1);
    snprintf(want, sizeof want, "%s/: is a directory, not a scene file\n", dir);
    assert_string_equal(out, want);
    free(out);
}

/* `murk grid g.vol --res 2.5` silently wrote an all-zero 2^3 grid. CLI numbers are as strict as the
 * scene's. */
static void t_cli_numbers(void **state)
{
    (void)state;
    const char *dir = fresh_dir("clinum");
    static const struct { const char *opt, *val, *msg; } cases[] = {
        {"--res", "2.5", "murk: --res must be a whole number, got '2.5'\n"},
        {"--res", " 8", "murk: --res needs a whole number, got ' 8'\n"},
        {"--res", "0x10", "murk: --res needs a whole number, got '0x10'\n"},
        {"--res", "1e9", "murk: --res must be in [2, 1024], got '1e9'\n"},
        {"--octaves", "3.5", "murk: --octaves must be a whole number, got '3.5'\n"},
        {"--seed", "-1", "murk: --seed must be in [0, 4294967295], got '-1'\n"},
        {"--coverage", "nan", "murk: --coverage needs a number, got 'nan'\n"},
        {"--frequency", "inf", "murk: --frequency needs a number, got 'inf'\n"},
        {"--min", "1,2", "murk: --min needs X,Y,Z, got '1,2'\n"},
        {"--min", "1,2,3,4", "murk: --min needs X,Y,Z, got '1,2,3,4'\n"},
        {"--max", "1,2,1e20", "murk: --max must be in [-1e+15, 1e+15], got '1e20'\n"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *out = NULL;
        assert_int_equal(run_murk(&out, "grid", join(dir, "g.vol"), cases[i].opt, cases[i].val, NULL), 2);
        assert_string_equal(out, cases[i].msg);
        free(out);
    }
    char names[256];
    list_dir(dir, names, sizeof names);
    assert_string_equal(names, "");
    char *out = NULL;
    assert_int_equal(run_murk(&out, "render", "x.yaml", "--spp", " 4", NULL), 2);
    assert_string_equal(out, "murk: --spp needs a whole number in [1, 16777216], got ' 4'\n");
    free(out);
}

/* Scene numbers that used to be truncated or to size allocations: cloud.resolution 2.5, a cloud or an
 * image beyond the limits. */
static void t_scene_numbers(void **state)
{
    (void)state;
    static const struct { const char *text, *msg; } cases[] = {
        {"murk: 1\nmedia: { c: { type: delta, density: { cloud: { resolution: 2.5 } } } }\nshapes: []\n",
         ":2:60: cloud.resolution must be a whole number, got '2.5'\n"},
        {"murk: 1\nmedia: { c: { type: delta, density: { cloud: { resolution: 1024 } } } }\nshapes: []\n",
         ":2:60: cloud.resolution 1024 gives 1073741824 voxels, beyond the limit of 134217728 (MURK_MAX_GRID_VOXELS)\n"},
        {"murk: 1\nrender: { resolution: [16384, 16384] }\nshapes: []\n",
         ":2:23: render.resolution 16384x16384 exceeds the limit of 67108864 pixels (MURK_MAX_IMAGE_PIXELS)\n"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char name[32], want[1024], *out = NULL;
        snprintf(name, sizeof name, "num%zu.yaml", i);
        const char *scene = write_tmp(name, cases[i].text);
        assert_int_equal(run_murk(&out, "render", scene, "-o", join(fresh_dir("num"), "o.exr"), NULL), 1);
        snprintf(want, sizeof want, "%s%s", scene, cases[i].msg);
        assert_string_equal(out, want);
        free(out);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(t_medium_too_dense),
        cmocka_unit_test(t_camera_far),
        cmocka_unit_test(t_ray_range),
        cmocka_unit_test(t_tracker_progress_and_watchdog),
        cmocka_unit_test(t_example_tracker_watchdog),
        cmocka_unit_test(t_png_declared_size),
        cmocka_unit_test(t_exr_declared_size),
        cmocka_unit_test(t_devices_and_fifos),
        cmocka_unit_test(t_grid_voxel_limit),
        cmocka_unit_test(t_group_all_or_nothing),
        cmocka_unit_test(t_render_no_half_output),
        cmocka_unit_test(t_signal_removes_temporaries),
        cmocka_unit_test(t_never_replace_non_regular),
        cmocka_unit_test(t_printable),
        cmocka_unit_test(t_escaped_names),
        cmocka_unit_test(t_scene_is_directory),
        cmocka_unit_test(t_cli_numbers),
        cmocka_unit_test(t_scene_numbers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
