/* test_session.c — the render session of murk/murk.h (murk_session_begin, run_pass, end) as an embedder,
 * a ctypes binding for one, drives it: its passes give murk_render's image bit for bit and the progress
 * callback sees the share done grow to 1; a stop from another thread or from the callback, or the caller
 * ending the session early, ends the render after whole passes (interrupted), with the image of an
 * uninterrupted render of the spp reached; begin refuses, before the first sample, a checkpoint it could
 * not write or resume; run_pass after the end does nothing. */
#include "murk/murk.h"
#include "testutil.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { W = 32, H = 32 };

static murk_scene *load(void)
{
    static const char *const sets[] = {"render.resolution=[32,32]", "render.seed=5"};
    char err[2048];
    murk_scene *s = murk_scene_load(src_path("scenes/cornell_smoke.yaml"), sets, 2, err, sizeof err);
    if (!s)
        fail_msg("%s", err);
    return s;
}

/* murk_render's image of spp samples: one pass. */
static float *render_once(murk_scene *s, int spp)
{
    murk_render_opts o = {.spp = spp, .threads = 2};
    murk_render_result r;
    assert_int_equal(murk_render(s, &o, &r), 0);
    assert_int_equal(r.spp, spp);
    return r.rgb;
}

typedef struct progress {
    murk_session *ss;
    int calls, finals, backwards;
    double fraction, stop_after; /* stop_after > 0: murk_session_stop once that many seconds have passed */
} progress;

static void on_progress(void *user, double fraction, double seconds, int last)
{
    progress *p = user;
    p->calls++;
    p->finals += last;
    p->backwards += fraction < p->fraction - 1e-12;
    p->fraction = fraction;
    if (p->stop_after > 0 && seconds > p->stop_after)
        murk_session_stop(p->ss);
}

static void test_passes_same_image(void **state)
{
    (void)state;
    murk_scene *s = load();
    murk_render_opts o = {.spp = 24, .threads = 2};
    char err[1024];
    murk_session *ss = murk_session_begin(s, &o, err, sizeof err);
    assert_non_null(ss);
    progress p = {.ss = ss};
    murk_session_set_progress(ss, on_progress, &p);
    int passes = 0, rc;
    while ((rc = murk_session_run_pass(ss, err, sizeof err)) > 0)
        passes++;
    assert_int_equal(rc, 0);
    assert_int_equal(murk_session_run_pass(ss, err, sizeof err), 0); /* over: nothing more */
    murk_render_result r;
    assert_int_equal(murk_session_end(ss, &r, err, sizeof err), 0);
    print_message("24 spp in %d passes, %d progress calls\n", passes + 1, p.calls);
    assert_true(passes >= 1); /* passes grow from 1 spp: more than one */
    assert_int_equal(r.spp, 24);
    assert_false(r.interrupted);
    assert_int_equal(p.finals, 1);
    assert_int_equal(p.backwards, 0);
    assert_true(p.fraction == 1.0);
    float *ref = render_once(s, 24);
    assert_memory_equal(r.rgb, ref, 3 * sizeof(float) * W * H);
    free(ref);
    free(r.rgb);
    murk_scene_free(s);
}

static void *stop_later(void *arg)
{
    struct timespec ts = {0, 300 * 1000 * 1000};
    nanosleep(&ts, NULL);
    murk_session_stop(arg);
    return NULL;
}

/* k = 0: murk_session_stop from another thread; k = 1: from the progress callback; k = 2: the caller ends
 * the session after two passes (a binding's Ctrl-C between passes). */
static void test_stop_keeps_whole_passes(void **state)
{
    (void)state;
    static const char *const how[] = {"from a thread", "from the callback", "by ending early"};
    murk_scene *s = load();
    for (int k = 0; k < 3; k++) {
        murk_render_opts o = {.spp = 1 << 20, .threads = 2};
        char err[1024];
        murk_session *ss = murk_session_begin(s, &o, err, sizeof err);
        assert_non_null(ss);
        progress p = {.ss = ss, .stop_after = k == 1 ? 0.3 : 0};
        murk_session_set_progress(ss, on_progress, &p);
        pthread_t th;
        if (k == 0)
            assert_int_equal(pthread_create(&th, NULL, stop_later, ss), 0);
        int rc, passes = 0;
        while ((rc = murk_session_run_pass(ss, err, sizeof err)) > 0 && !(k == 2 && ++passes == 2))
            ;
        assert_int_equal(rc, k == 2 ? 1 : 0);
        if (k == 0)
            pthread_join(th, NULL);
        murk_render_result r;
        assert_int_equal(murk_session_end(ss, &r, err, sizeof err), 0);
        print_message("stopped %s after %d spp\n", how[k], r.spp);
        assert_true(r.interrupted);
        assert_true(r.spp >= 1 && r.spp < o.spp);
        float *ref = render_once(s, r.spp);
        assert_memory_equal(r.rgb, ref, 3 * sizeof(float) * W * H);
        free(ref);
        free(r.rgb);
    }
    murk_scene_free(s);
}

static void test_begin_refuses(void **state)
{
    (void)state;
    murk_scene *s = load();
    char err[1024];
    murk_render_opts o = {.spp = 4, .threads = 2, .checkpoint = tmp_path("missing/ck")};
    assert_null(murk_session_begin(s, &o, err, sizeof err));
    assert_contains(err, "missing/ck: cannot write the checkpoint: No such file or directory");
    murk_render_opts r = {.spp = 4, .threads = 2, .resume = write_tmp("bad.ck", "not one")};
    assert_null(murk_session_begin(s, &r, err, sizeof err));
    assert_contains(err, "bad.ck: not a murk checkpoint");
    murk_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_passes_same_image),
        cmocka_unit_test(test_stop_keeps_whole_passes),
        cmocka_unit_test(test_begin_refuses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
