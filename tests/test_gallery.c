/* test_gallery.c — the gallery's final scene, scenes/axe_room.yaml, and its generated assets, and the
 * gallery's three scenes of lights (envmap_spheres, spot_fog, cloud_sun) and their environment map:
 *  - each scene loads and renders a few spp at a tiny resolution with every pixel finite and >= 0 and
 *    no NaN/inf sample dropped (the EXR records how many were);
 *  - tools/make_envmap.py is deterministic and writes the committed scenes/env/studio.exr;
 *  - tools/make_axe.py and tools/make_textures.py are deterministic: two runs write the same bytes,
 *    and those are the bytes committed in scenes/axe/;
 *  - the axe head is a closed, outward-wound mesh (every directed edge once, its reverse once, positive
 *    signed volume); the handle is closed too; every face corner of both has a uv in [0, 1]^2, and the
 *    handle has its texture seam (one position used with u = 0 and with u = 1);
 *  - the textures load with their expected sizes, and murk's sRGB decoding of them is the sRGB
 *    transfer function of the raw 8-bit values. */
#include "testutil.h"
#include "image/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define PYTHON "/usr/bin/python3"

static const char *const OBJS[] = {"axe_head.obj", "axe_handle.obj"};
static const struct { const char *name; int w, h; } TEXTURES[] = {
    {"bricks.png", 256, 256}, {"planks.png", 256, 256}, {"plaster.png", 128, 128}, {"wood.png", 64, 256}};
enum { NTEX = sizeof TEXTURES / sizeof TEXTURES[0] };

/* ---- helpers ---------------------------------------------------------------------------------- */

/* Runs /usr/bin/python3 SCRIPT OUTDIR with its output discarded; returns the exit status. */
static int run_python(const char *script, const char *outdir)
{
    pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout))
            _exit(127);
        execl(PYTHON, PYTHON, script, outdir, (char *)NULL);
        _exit(127);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap + 1);
    size_t got;
    while (b && (got = fread(b + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            char *nb = realloc(b, 2 * cap + 1);
            if (!nb) {
                free(b);
                b = NULL;
                break;
            }
            b = nb;
            cap *= 2;
        }
    }
    fclose(f);
    if (b)
        b[n] = '\0';
    *len = n;
    return b;
}

static void assert_same_file(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    char *da = slurp(a, &na), *db = slurp(b, &nb);
    if (!da || !db || na != nb || memcmp(da, db, na) != 0)
        fprintf(stderr, "%s and %s differ (%zu and %zu bytes)\n", a, b, na, nb);
    assert_non_null(da);
    assert_non_null(db);
    assert_int_equal(na, nb);
    assert_memory_equal(da, db, na);
    free(da);
    free(db);
}

static const char *path_in(const char *dir, const char *name)
{
    static char bufs[4][2200];
    static int next;
    char *b = bufs[next++ & 3];
    snprintf(b, sizeof bufs[0], "%s/%s", dir, name);
    return b;
}

/* A minimal OBJ: positions, texture coordinates, triangles of (v, vt) indices (0-based, vt -1 if none). */
typedef struct obj {
    int nv, nvt, nf;
    double *v, *vt;
    int (*f)[3][2];
} obj;

static void obj_read(const char *path, obj *o)
{
    size_t len = 0;
    char *text = slurp(path, &len);
    assert_non_null(text);
    memset(o, 0, sizeof *o);
    size_t lines = 1;
    for (size_t i = 0; i < len; i++)
        lines += text[i] == '\n';
    o->v = malloc(3 * lines * sizeof *o->v);
    o->vt = malloc(2 * lines * sizeof *o->vt);
    o->f = malloc(lines * sizeof *o->f);
    assert_true(o->v && o->vt && o->f);
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (!strncmp(line, "v ", 2)) {
            double *p = &o->v[3 * o->nv++];
            assert_int_equal(sscanf(line + 2, "%lf %lf %lf", &p[0], &p[1], &p[2]), 3);
        } else if (!strncmp(line, "vt ", 3)) {
            double *t = &o->vt[2 * o->nvt++];
            assert_int_equal(sscanf(line + 3, "%lf %lf", &t[0], &t[1]), 2);
        } else if (!strncmp(line, "f ", 2)) {
            int (*face)[2] = o->f[o->nf++];
            char *s = line + 2;
            for (int k = 0; k < 3; k++) {
                char *end;
                face[k][0] = (int)strtol(s, &end, 10) - 1;
                face[k][1] = *end == '/' && end[1] != '/' ? (int)strtol(end + 1, &end, 10) - 1 : -1;
                while (*end && *end != ' ')
                    end++;
                s = end;
            }
            assert_true(*s == '\0' || strspn(s, " \r") == strlen(s)); /* triangles only */
        }
    }
    free(text);
}

static void obj_free(obj *o)
{
    free(o->v);
    free(o->vt);
    free(o->f);
}

/* Closed and outward: every directed edge (a, b) occurs once and (b, a) once; signed volume > 0. */
static void assert_closed(const char *name, const obj *o)
{
    int n = 3 * o->nf;
    long long *edge = malloc((size_t)n * sizeof *edge);
    assert_non_null(edge);
    for (int i = 0; i < o->nf; i++)
        for (int k = 0; k < 3; k++) {
            int a = o->f[i][k][0], b = o->f[i][(k + 1) % 3][0];
            assert_true(a >= 0 && a < o->nv && b >= 0 && b < o->nv);
            assert_int_not_equal(a, b);
            edge[3 * i + k] = (long long)a * o->nv + b;
        }
    int bad = 0;
    for (int i = 0; i < n; i++) {
        long long a = edge[i] / o->nv, b = edge[i] % o->nv, rev = b * o->nv + a;
        int same = 0, opposite = 0;
        for (int j = 0; j < n; j++) {
            same += edge[j] == edge[i];
            opposite += edge[j] == rev;
        }
        bad += same != 1 || opposite != 1;
    }
    double vol = 0.0;
    for (int i = 0; i < o->nf; i++) {
        const double *a = &o->v[3 * o->f[i][0][0]], *b = &o->v[3 * o->f[i][1][0]], *c = &o->v[3 * o->f[i][2][0]];
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
    }
    printf("%s: %d vertices, %d triangles, %d unpaired edges, volume %.3g m^3\n", name, o->nv, o->nf, bad, vol);
    free(edge);
    assert_int_equal(bad, 0);
    assert_true(vol > 0.0);
}

/* ---- tests ------------------------------------------------------------------------------------ */

/* Renders scenes/NAME.yaml at w x h and 4 spp: every pixel finite and >= 0, some light, no NaN/inf sample
 * dropped, and the scene's own integrator (volpath_nee for all of the gallery's). */
static void scene_renders(const char *name, int w, int h)
{
    char scene[1024], exr[1024], res[64], *log = NULL, err[512];
    snprintf(scene, sizeof scene, "scenes/%s.yaml", name);
    snprintf(scene, sizeof scene, "%s", src_path(scene));
    snprintf(exr, sizeof exr, "%s/%s.exr", tmp_dir(), name);
    snprintf(res, sizeof res, "render.resolution=[%d,%d]", w, h);
    int rc = run_murk(&log, "render", scene, "-o", exr, "--spp", "4", "--set", res, "--quiet", (char *)NULL);
    if (rc)
        fprintf(stderr, "%s\n", log);
    assert_int_equal(rc, 0);
    free(log);
    murk_image img = {0};
    assert_int_equal(murk_exr_read(exr, &img, err, sizeof err), 0);
    assert_int_equal(img.w, w);
    assert_int_equal(img.h, h);
    double sum = 0.0;
    for (int i = 0; i < 3 * img.w * img.h; i++) {
        assert_true(isfinite(img.rgb[i]));
        assert_true(img.rgb[i] >= 0.0f);
        sum += img.rgb[i];
    }
    const char *nonfinite = murk_image_meta(&img, "murk:nonfinite_samples");
    const char *integrator = murk_image_meta(&img, "murk:integrator");
    printf("%s %dx%d, 4 spp: mean %.4f, nonfinite samples %s, integrator %s\n", name, w, h,
           sum / (3.0 * img.w * img.h), nonfinite ? nonfinite : "?", integrator ? integrator : "?");
    assert_true(sum > 0.0);
    assert_non_null(nonfinite);
    assert_string_equal(nonfinite, "0");
    assert_non_null(integrator);
    assert_string_equal(integrator, "volpath_nee");
    murk_image_free(&img);
}

static void test_axe_scene_renders(void **state)
{
    (void)state;
    scene_renders("axe_room", 40, 30);
}

/* The gallery's three scenes of the `lights:` block (an envmap, a spot in fog, a cloud under the sky),
 * and scenes/env/studio.exr: tools/make_envmap.py writes the same bytes twice, and they are the bytes
 * committed. */
static void test_lights_scenes(void **state)
{
    (void)state;
    scene_renders("envmap_spheres", 24, 14);
    scene_renders("spot_fog", 16, 16);
    scene_renders("cloud_sun", 20, 15);
    const char *out[2] = {path_in(tmp_dir(), "studio1.exr"), path_in(tmp_dir(), "studio2.exr")};
    for (int r = 0; r < 2; r++)
        assert_int_equal(run_python(src_path("tools/make_envmap.py"), out[r]), 0);
    assert_same_file(out[0], out[1]);
    char committed[1024];
    snprintf(committed, sizeof committed, "%s", src_path("scenes/env/studio.exr"));
    assert_same_file(out[0], committed);
}

static void test_generators_deterministic(void **state)
{
    (void)state;
    const char *runs[2] = {path_in(tmp_dir(), "gen1"), path_in(tmp_dir(), "gen2")};
    char dirs[2][1024];
    for (int r = 0; r < 2; r++) {
        snprintf(dirs[r], sizeof dirs[r], "%s", runs[r]);
        assert_int_equal(run_python(src_path("tools/make_axe.py"), dirs[r]), 0);
        assert_int_equal(run_python(src_path("tools/make_textures.py"), dirs[r]), 0);
    }
    char committed[1024];
    snprintf(committed, sizeof committed, "%s", src_path("scenes/axe"));
    for (size_t i = 0; i < sizeof OBJS / sizeof OBJS[0]; i++) {
        assert_same_file(path_in(dirs[0], OBJS[i]), path_in(dirs[1], OBJS[i]));
        assert_same_file(path_in(dirs[0], OBJS[i]), path_in(committed, OBJS[i]));
    }
    for (int i = 0; i < NTEX; i++) {
        assert_same_file(path_in(dirs[0], TEXTURES[i].name), path_in(dirs[1], TEXTURES[i].name));
        assert_same_file(path_in(dirs[0], TEXTURES[i].name), path_in(committed, TEXTURES[i].name));
    }
}

static void test_axe_meshes(void **state)
{
    (void)state;
    for (size_t m = 0; m < sizeof OBJS / sizeof OBJS[0]; m++) {
        char rel[256];
        snprintf(rel, sizeof rel, "scenes/axe/%s", OBJS[m]);
        obj o;
        obj_read(src_path(rel), &o);
        assert_true(o.nf > 0);
        assert_closed(OBJS[m], &o);
        int seam0 = 0, seam1 = 0; /* corners at u = 0 and u = 1 of the same position (handle seam) */
        for (int i = 0; i < o.nf; i++)
            for (int k = 0; k < 3; k++) {
                int t = o.f[i][k][1];
                assert_true(t >= 0 && t < o.nvt); /* every corner has a uv */
                double u = o.vt[2 * t], v = o.vt[2 * t + 1];
                assert_true(isfinite(u) && isfinite(v) && u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0);
                if (m == 1 && o.f[i][k][0] == 0)
                    seam0 += u == 0.0, seam1 += u == 1.0;
            }
        if (m == 1) {
            printf("handle seam at position 1: %d corners with u = 0, %d with u = 1\n", seam0, seam1);
            assert_true(seam0 > 0 && seam1 > 0);
        }
        /* each side of the handle's uv triangles must not straddle the seam (no triangle spans u 0..1) */
        for (int i = 0; m == 1 && i < o.nf; i++) {
            double umin = 1.0, umax = 0.0;
            for (int k = 0; k < 3; k++) {
                double u = o.vt[2 * o.f[i][k][1]];
                umin = fmin(umin, u);
                umax = fmax(umax, u);
            }
            assert_true(umax - umin < 0.5);
        }
        obj_free(&o);
    }
}

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static void test_textures(void **state)
{
    (void)state;
    double mean[NTEX][3];
    for (int i = 0; i < NTEX; i++) {
        char rel[256], err[512];
        snprintf(rel, sizeof rel, "scenes/axe/%s", TEXTURES[i].name);
        murk_image raw = {0}, lin = {0};
        assert_int_equal(murk_png_read(src_path(rel), 0, &raw, err, sizeof err), 0);
        assert_int_equal(murk_png_read(src_path(rel), 1, &lin, err, sizeof err), 0);
        assert_int_equal(raw.w, TEXTURES[i].w);
        assert_int_equal(raw.h, TEXTURES[i].h);
        assert_int_equal(lin.w, TEXTURES[i].w);
        assert_int_equal(lin.h, TEXTURES[i].h);
        int n = raw.w * raw.h;
        double worst = 0.0;
        mean[i][0] = mean[i][1] = mean[i][2] = 0.0;
        for (int p = 0; p < n; p++)
            for (int c = 0; c < 3; c++) {
                double r = raw.rgb[3 * p + c], l = lin.rgb[3 * p + c];
                /* raw values are 8-bit codes / 255 */
                assert_float_equal(r * 255.0, round(r * 255.0), 1e-3);
                worst = fmax(worst, fabs(l - srgb_to_linear(r)));
                mean[i][c] += l / n;
            }
        printf("%s: %dx%d, mean linear (%.3f, %.3f, %.3f), worst sRGB decode error %.2g\n", TEXTURES[i].name, raw.w,
               raw.h, mean[i][0], mean[i][1], mean[i][2], worst);
        assert_true(worst < 1e-5); /* float rounding of the transfer function, not a different curve */
        murk_image_free(&raw);
        murk_image_free(&lin);
    }
    /* at least two different textures on the room: the brick wall is redder than the plaster */
    assert_true(mean[0][0] / mean[0][2] > 1.5 * mean[2][0] / mean[2][2]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_axe_scene_renders),
        cmocka_unit_test(test_lights_scenes),
        cmocka_unit_test(test_generators_deterministic),
        cmocka_unit_test(test_axe_meshes),
        cmocka_unit_test(test_textures),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
