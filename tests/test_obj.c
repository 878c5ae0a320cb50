/* test_obj.c — the Wavefront OBJ loader (core/obj.c).
 *
 * Fan triangulation, negative indices, the v, v/vt, v//vn and v/vt/vn forms, vertex unification,
 * ignored statements, CRLF/tabs/comments, number syntax, every error with its exact line:column,
 * missing and empty files, a generated grid large enough to catch quadratic behaviour, and the
 * glmark2 bunny when it is installed. */
#include "testutil.h"

#include "scene/obj.h"

#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char err[1024];

static void load_ok(const char *name, const char *text, murk_mesh *m)
{
    const char *path = write_tmp(name, text);
    int rc = murk_obj_load(path, m, err, sizeof err);
    if (rc != 0)
        fail_msg("unexpected error: %s", err);
}

/* Loads text expecting a failure whose message is "path:" followed by want. */
static void load_fails(const char *name, const char *text, const char *want)
{
    const char *path = write_tmp(name, text);
    murk_mesh m;
    memset(&m, 0xab, sizeof m);
    assert_int_equal(murk_obj_load(path, &m, err, sizeof err), -1);
    size_t n = strlen(path);
    if (strncmp(err, path, n) != 0 || err[n] != ':' || strncmp(err + n + 1, want, strlen(want)) != 0)
        fail_msg("got \"%s\", want \"%s:%s...\"", err, path, want);
    assert_null(m.pos);
    assert_null(m.uv);
    assert_null(m.nrm);
    assert_null(m.idx);
    assert_int_equal(m.nverts, 0);
    assert_int_equal(m.ntris, 0);
}

static void assert_tri(const murk_mesh *m, uint32_t t, uint32_t a, uint32_t b, uint32_t c)
{
    assert_true(t < m->ntris);
    assert_int_equal(m->idx[3 * t], a);
    assert_int_equal(m->idx[3 * t + 1], b);
    assert_int_equal(m->idx[3 * t + 2], c);
}

static void assert_pos(const murk_mesh *m, uint32_t v, float x, float y, float z)
{
    assert_true(v < m->nverts);
    assert_true(m->pos[3 * v] == x);
    assert_true(m->pos[3 * v + 1] == y);
    assert_true(m->pos[3 * v + 2] == z);
}

static void test_cube_quads(void **state)
{
    (void)state;
    murk_mesh m;
    load_ok("cube.obj",
            "# unit cube made of quads\n"
            "o cube\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "g sides\n"
            "usemtl grey\n"
            "s off\n"
            "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
            &m);
    assert_int_equal(m.ntris, 12);
    assert_int_equal(m.nverts, 8);
    assert_null(m.uv);
    assert_null(m.nrm);
    /* Fan: quad (a b c d) -> (a b c), (a c d); unified vertices are numbered in first-use order. */
    assert_tri(&m, 0, 0, 1, 2);
    assert_tri(&m, 1, 0, 2, 3);
    assert_pos(&m, 0, 0, 0, 0);
    assert_pos(&m, 1, 0, 1, 0); /* file vertex 4 was used second */
    assert_pos(&m, 2, 1, 1, 0);
    for (uint32_t i = 0; i < 3 * m.ntris; i++)
        assert_true(m.idx[i] < m.nverts);
    murk_mesh_free(&m);
    assert_null(m.pos);
    assert_null(m.idx);
    assert_int_equal(m.ntris, 0);
    murk_mesh_free(&m); /* harmless twice */
}

static void test_polygon_fan(void **state)
{
    (void)state;
    murk_mesh m;
    load_ok("hexagon.obj",
            "v 1 0 0\nv 0.5 0.866 0\nv -0.5 0.866 0\nv -1 0 0\nv -0.5 -0.866 0\nv 0.5 -0.866 0\n"
            "f 1 2 3 4 5 6\n"
            "f 1 2 3\n",
            &m);
    assert_int_equal(m.ntris, 5);
    assert_int_equal(m.nverts, 6);
    for (uint32_t t = 0; t < 4; t++)
        assert_tri(&m, t, 0, t + 1, t + 2);
    assert_tri(&m, 4, 0, 1, 2);
    murk_mesh_free(&m);
}

static void test_negative_indices(void **state)
{
    (void)state;
    murk_mesh m;
    load_ok("neg.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\n"
            "f -3 -2 -1\n"
            "v 0 1 0\n"
            "f -4 -2 -1\n"   /* 1 3 4 */
            "vt 0 0\nvt 1 0\nvt 1 1\n"
            "vn 0 0 1\n"
            "f -4/-3/-1 -3/-2/-1 -2/-1/-1\n", /* 1/1/1 2/2/1 3/3/1 */
            &m);
    assert_int_equal(m.ntris, 3);
    /* Positions only: 1 2 3 4 -> 4 vertices; then three new (v, vt, vn) triples. */
    assert_int_equal(m.nverts, 7);
    assert_tri(&m, 0, 0, 1, 2);
    assert_tri(&m, 1, 0, 2, 3);
    assert_tri(&m, 2, 4, 5, 6);
    assert_pos(&m, 3, 0, 1, 0);
    assert_pos(&m, 5, 1, 0, 0);
    assert_non_null(m.uv);
    assert_non_null(m.nrm);
    assert_true(m.uv[2 * 5] == 1.0f && m.uv[2 * 5 + 1] == 0.0f);
    assert_true(m.uv[2 * 6] == 1.0f && m.uv[2 * 6 + 1] == 1.0f);
    assert_true(m.nrm[3 * 6 + 2] == 1.0f);
    /* Vertices referenced without vt/vn get zeros. */
    assert_true(m.uv[0] == 0.0f && m.uv[1] == 0.0f);
    assert_true(m.nrm[0] == 0.0f && m.nrm[1] == 0.0f && m.nrm[2] == 0.0f);
    murk_mesh_free(&m);
}

static void test_forms_and_unification(void **state)
{
    (void)state;
    murk_mesh m;
    load_ok("forms.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "vn 0 0 1\nvn 0 0 -1\n"
            /* two triangles sharing the edge 1-3 with identical triples: 4 vertices */
            "f 1/1/1 2/2/1 3/3/1\n"
            "f 1/1/1 3/3/1 4/4/1\n"
            /* the same positions with another normal: 3 more */
            "f 1/1/2 3/3/2 2/2/2\n"
            /* v//vn: no texture coordinate, a distinct triple */
            "f 1//1 2//1 3//1\n"
            /* v/vt: no normal */
            "f 1/1 2/2 3/3\n"
            /* repeated triple is unified again */
            "f 1/1 2/2 4/4\n",
            &m);
    assert_int_equal(m.ntris, 6);
    assert_int_equal(m.nverts, 4 + 3 + 3 + 4);
    assert_tri(&m, 0, 0, 1, 2);
    assert_tri(&m, 1, 0, 2, 3);
    assert_tri(&m, 2, 4, 5, 6);
    assert_tri(&m, 3, 7, 8, 9);
    assert_tri(&m, 4, 10, 11, 12);
    assert_tri(&m, 5, 10, 11, 13);
    assert_non_null(m.uv);
    assert_non_null(m.nrm);
    assert_true(m.uv[2 * 2] == 1.0f && m.uv[2 * 2 + 1] == 1.0f);
    assert_true(m.nrm[3 * 4 + 2] == -1.0f);
    assert_true(m.uv[2 * 7] == 0.0f && m.uv[2 * 8] == 0.0f);   /* v//vn */
    assert_true(m.nrm[3 * 8 + 2] == 1.0f);
    assert_true(m.nrm[3 * 11 + 2] == 0.0f);                    /* v/vt */
    assert_true(m.uv[2 * 11] == 1.0f);
    murk_mesh_free(&m);
}

static void test_whitespace_comments_and_ignored(void **state)
{
    (void)state;
    murk_mesh m;
    load_ok("messy.obj",
            "# header comment\r\n"
            "mtllib scene.mtl\r\n"
            "\r\n"
            "\t v\t0.5  -1e-3\t+2.5E+1 1.0 # w, then a comment\r\n"
            "v 1 2 3 0.1 0.2 0.3\r\n"            /* vertex colours are tolerated */
            "v .5 5. -0\r\n"
            "vp 0.1 0.2\r\n"
            "vt 0.25\r\n"                        /* v defaults to 0 */
            "l 1 2\r\n"
            "p 1\r\n"
            "cstype bspline\r\n"
            "somethingunknown with [weird] tokens 1/2/3\r\n"
            "   \t\r\n"
            "f 1/1 2/1 3/1   \r\n"
            "f 1/1 2/1 3/1",                     /* no newline at the end */
            &m);
    assert_int_equal(m.ntris, 2);
    assert_int_equal(m.nverts, 3);
    assert_pos(&m, 0, 0.5f, -1e-3f, 25.0f);
    assert_pos(&m, 1, 1, 2, 3);
    assert_pos(&m, 2, 0.5f, 5.0f, -0.0f);
    assert_true(signbit(m.pos[8]));
    assert_non_null(m.uv);
    assert_true(m.uv[0] == 0.25f && m.uv[1] == 0.0f);
    assert_null(m.nrm);
    murk_mesh_free(&m);
}

static void test_number_parsing(void **state)
{
    (void)state;
    static const char *const nums[] = {"0.1", "-0.907931", "3.14159265358979323846", "1e-7", "123456789",
                                       "1.17549435e-38", "3.4028234e38", "0.000001", "16777217", "-7.5e+2",
                                       "9.999999e9", "1e10", "2.5e-11", "00012.50", "1.0000000000000000000001",
                                       "4.9e-324", "+.75"};
    const size_t n = sizeof nums / sizeof nums[0];
    char text[4096];
    size_t len = 0;
    for (size_t i = 0; i < n; i++)
        len += (size_t)snprintf(text + len, sizeof text - len, "v %s %s 0\n", nums[i], nums[i]);
    snprintf(text + len, sizeof text - len, "f 1 2 3\n");
    murk_mesh m;
    load_ok("numbers.obj", text, &m);
    assert_int_equal(m.nverts, 3);
    murk_mesh_free(&m);

    /* Each value must be exactly what strtof makes of it: load the numbers one face at a time. */
    for (size_t i = 0; i < n; i++) {
        snprintf(text, sizeof text, "v %s 0 0\nv 0 %s 0\nv 0 0 %s\nf 1 2 3\n", nums[i], nums[i], nums[i]);
        load_ok("number.obj", text, &m);
        float want = strtof(nums[i], NULL);
        assert_true(memcmp(&m.pos[0], &want, 4) == 0);
        assert_true(memcmp(&m.pos[4], &want, 4) == 0);
        assert_true(memcmp(&m.pos[8], &want, 4) == 0);
        murk_mesh_free(&m);
    }

    /* Many random decimal strings against strtof, bit for bit: 99 distinct vertices in 33 faces. */
    enum { NV = 99 };
    size_t cap = 64 * 3 * NV + 32 * NV;
    char *big = malloc(cap);
    float want[3 * NV];
    uint32_t s = 2024;
    assert_non_null(big);
    len = 0;
    for (int i = 0; i < 3 * NV; i++) {
        s ^= s << 13, s ^= s >> 17, s ^= s << 5;
        int digits = 1 + (int)(s % 12), point = (int)((s >> 4) % (unsigned)(digits + 1));
        int ex = (int)((s >> 8) % 61) - 30;
        char num[64];
        int k = 0;
        if (s & (1u << 20))
            num[k++] = '-';
        for (int d = 0; d < digits; d++) {
            if (d == point && d > 0)
                num[k++] = '.';
            s ^= s << 13, s ^= s >> 17, s ^= s << 5;
            num[k++] = (char)('0' + (d == 0 ? 1 + s % 9 : s % 10)); /* distinct vertices: no all-zero values */
        }
        if (ex != 0)
            k += snprintf(num + k, sizeof num - (size_t)k, "e%d", ex);
        num[k] = 0;
        want[i] = strtof(num, NULL);
        len += (size_t)snprintf(big + len, cap - len, "%s %s", i % 3 ? "" : "v", num);
        if (i % 3 == 2)
            big[len++] = '\n';
    }
    for (int f = 0; f < NV / 3; f++)
        len += (size_t)snprintf(big + len, cap - len, "f %d %d %d\n", 3 * f + 1, 3 * f + 2, 3 * f + 3);
    load_ok("random_numbers.obj", big, &m);
    free(big);
    assert_int_equal(m.nverts, NV);
    for (int i = 0; i < 3 * NV; i++)
        if (memcmp(&m.pos[i], &want[i], 4) != 0)
            fail_msg("value %d: got %.9g want %.9g", i, (double)m.pos[i], (double)want[i]);
    murk_mesh_free(&m);
}

/* Numbers do not depend on the application's locale (skipped when no comma-decimal locale exists). */
static void test_locale_independent(void **state)
{
    (void)state;
    static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8", "nl_NL.UTF-8",
                                        "ru_RU.UTF-8"};
    const char *text = "v 0.123456789012 -1234.56789e-3 3.5\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const float want[3] = {strtof("0.123456789012", NULL), strtof("-1234.56789e-3", NULL), 3.5f};
    int found = 0;
    for (size_t i = 0; i < sizeof names / sizeof names[0] && !found; i++)
        found = setlocale(LC_NUMERIC, names[i]) != NULL && strtof("1.5", NULL) != 1.5f;
    if (!found) {
        setlocale(LC_NUMERIC, "C");
        skip();
    }
    murk_mesh m;
    const char *path = write_tmp("locale.obj", text);
    int rc = murk_obj_load(path, &m, err, sizeof err);
    setlocale(LC_NUMERIC, "C");
    assert_int_equal(rc, 0);
    assert_memory_equal(m.pos, want, sizeof want);
    murk_mesh_free(&m);
}

static void test_errors_line_col(void **state)
{
    (void)state;
    load_fails("e_num.obj", "v 0 0 0\nv 1 0 0\nv 1 2 abc\n", "3:7: bad number 'abc'");
    load_fails("e_num2.obj", "v 1 2 3.4.5\n", "1:7: bad number '3.4.5'");
    load_fails("e_num3.obj", "v 1 2 1e\n", "1:7: bad number '1e'");
    load_fails("e_num4.obj", "v 1 2 nan\n", "1:7: bad number 'nan'");
    load_fails("e_num5.obj", "v 1 2 -\n", "1:7: bad number '-'");
    load_fails("e_num6.obj", "vn 1 0x10 0\n", "1:6: bad number '0x10'");
    load_fails("e_range.obj", "v 1 2 1e39\n", "1:7: number out of range '1e39'");
    load_fails("e_tab.obj", "v 0 0 0\n\tv\t1\t2\t?\n", "2:8: bad number '?'");
    load_fails("e_crlf.obj", "v 0 0 0\r\nv 0 0 0\r\nv 1 1 x\r\n", "3:7: bad number 'x'");
    load_fails("e_few.obj", "v 0 0 0\n  v 1 2\n", "2:3: 'v' needs at least 3 values, got 2");
    load_fails("e_vn.obj", "vn 0 0 1 0\n", "1:10: too many values for 'vn'");
    load_fails("e_vt.obj", "vt\n", "1:1: 'vt' needs at least 1 values");
    load_fails("e_oor.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n", "4:7: vertex index 4 out of range");
    load_fails("e_oorneg.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 -4\n", "4:7: vertex index -4 out of range");
    load_fails("e_zero.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n", "4:3: index 0 is invalid");
    load_fails("e_negzero.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 -0\n", "4:7: index 0 is invalid");
    load_fails("e_huge.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 99999999999999999999999\n",
               "4:7: vertex index 99999999999999999999999 out of range");
    load_fails("e_vt_oor.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/1 2/1 3/1\n",
               "4:3: texture coordinate index 1 out of range");
    load_fails("e_vn_oor.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n",
               "5:13: normal index 2 out of range");
    load_fails("e_forward.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 1 1 0\n", "3:7: vertex index 3 out of range");
    load_fails("e_two.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\n\n  f 1 2\n", "5:3: face has fewer than 3 vertices");
    load_fails("e_none.obj", "v 0 0 0\nf # nothing\n", "2:1: face has fewer than 3 vertices");
    load_fails("e_idx.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3x\n", "4:7: bad index '3x'");
    load_fails("e_slash.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2/ 3\n", "4:5: bad index '2/'");
    load_fails("e_slash2.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1 2/1/1/1 3\n", "5:5: bad index '2/1/1/1'");
    load_fails("e_slash3.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 /1 3\n", "4:5: bad index '/1'");
    load_fails("e_slash4.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2// 3\n", "4:5: bad index '2//'");
    load_fails("e_float_idx.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2.0 3\n", "4:5: bad index '2.0'");
}

static void test_missing_and_empty(void **state)
{
    (void)state;
    murk_mesh m;
    char path[1024];
    snprintf(path, sizeof path, "%s/no-such-mesh.obj", tmp_dir());
    assert_int_equal(murk_obj_load(path, &m, err, sizeof err), -1);
    char want[1200];
    snprintf(want, sizeof want, "%s: cannot open: No such file or directory", path);
    assert_string_equal(err, want);
    assert_null(m.pos);

    load_fails("empty.obj", "", " no faces");
    load_fails("comments.obj", "# nothing here\n\n   \n", " no faces");
    load_fails("points.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\np 1 2 3\n", " no faces");

    /* A directory is not a mesh. */
    assert_int_equal(murk_obj_load(tmp_dir(), &m, err, sizeof err), -1);
    assert_null(m.pos);

    /* A tiny error buffer is truncated, never overrun. */
    char small[8];
    memset(small, 'x', sizeof small);
    const char *p = write_tmp("small_err.obj", "v 1 2 zzz\n");
    assert_int_equal(murk_obj_load(p, &m, small, sizeof small), -1);
    assert_int_equal(small[7], 0);
    assert_int_equal(murk_obj_load(p, &m, NULL, 0), -1);
}

/* A W x H grid of quads with uv and normals: the shape of a large scanned mesh. */
static void test_large_grid(void **state)
{
    (void)state;
    enum { N = 300 };
    char path[1024];
    snprintf(path, sizeof path, "%s/grid.obj", tmp_dir());
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    for (int y = 0; y <= N; y++)
        for (int x = 0; x <= N; x++)
            fprintf(f, "v %.6f %.6f %.6f\n", x / (double)N, y / (double)N, 0.1 * sin(x * 0.1) * cos(y * 0.1));
    for (int y = 0; y <= N; y++)
        for (int x = 0; x <= N; x++)
            fprintf(f, "vt %.6f %.6f\n", x / (double)N, y / (double)N);
    fprintf(f, "vn 0 0 1\n");
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            int a = y * (N + 1) + x + 1, b = a + 1, c = a + N + 2, d = a + N + 1;
            fprintf(f, "f %d/%d/1 %d/%d/1 %d/%d/1 %d/%d/1\n", a, a, b, b, c, c, d, d);
        }
    assert_int_equal(fclose(f), 0);

    murk_mesh m;
    assert_int_equal(murk_obj_load(path, &m, err, sizeof err), 0);
    assert_int_equal(m.ntris, 2 * N * N);
    assert_int_equal(m.nverts, (N + 1) * (N + 1));
    assert_non_null(m.uv);
    assert_non_null(m.nrm);
    for (uint32_t i = 0; i < 3 * m.ntris; i++)
        assert_true(m.idx[i] < m.nverts);
    for (uint32_t v = 0; v < m.nverts; v++) {
        /* Every vertex got its own uv, equal to its x, y. */
        assert_true(fabsf(m.uv[2 * v] - m.pos[3 * v]) < 1e-6f);
        assert_true(fabsf(m.uv[2 * v + 1] - m.pos[3 * v + 1]) < 1e-6f);
        assert_true(m.nrm[3 * v + 2] == 1.0f);
    }
    murk_mesh_free(&m);
    unlink(path);
}

static void test_bunny(void **state)
{
    (void)state;
    const char *path = "/usr/share/glmark2/models/bunny.obj";
    if (access(path, R_OK) != 0)
        skip();
    murk_mesh m;
    assert_int_equal(murk_obj_load(path, &m, err, sizeof err), 0);
    /* The Stanford bunny as shipped by glmark2: ~35k vertices, ~70k triangles, positions only. */
    assert_true(m.ntris > 60000 && m.ntris < 80000);
    assert_true(m.nverts > 30000 && m.nverts < 40000);
    assert_true(m.nverts < m.ntris);
    assert_null(m.uv);
    assert_null(m.nrm);
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t i = 0; i < 3 * m.nverts; i++) {
        assert_true(isfinite(m.pos[i]));
        lo = fminf(lo, m.pos[i]);
        hi = fmaxf(hi, m.pos[i]);
    }
    assert_true(hi > lo && hi - lo < 1e4f);
    for (uint32_t i = 0; i < 3 * m.ntris; i++)
        assert_true(m.idx[i] < m.nverts);
    murk_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube_quads),
        cmocka_unit_test(test_polygon_fan),
        cmocka_unit_test(test_negative_indices),
        cmocka_unit_test(test_forms_and_unification),
        cmocka_unit_test(test_whitespace_comments_and_ignored),
        cmocka_unit_test(test_number_parsing),
        cmocka_unit_test(test_locale_independent),
        cmocka_unit_test(test_errors_line_col),
        cmocka_unit_test(test_missing_and_empty),
        cmocka_unit_test(test_large_grid),
        cmocka_unit_test(test_bunny),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
