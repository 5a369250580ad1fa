/*
 * test_farm_frames.c: frame sequences on the farm (issue 14), with real
 * processes: scenes/ripples.rib (three frames, the wave's phase moving)
 *   - rendered by the embedded master with 2 local workers: one EXR per
 *     frame (the frame number put into -o), each equal to the standalone
 *     render of that frame, the three frames different from each other,
 *     the tiles of all frames in one queue (both workers take tiles);
 *   - --frames 3 renders frame 3 only; --frames errors (a backwards range,
 *     a frame the file does not have) are usage errors naming the problem;
 *   - kill -9 mid-sequence and --resume: each frame's journal gives back
 *     its tiles (the frames already written too), every frame equals its
 *     standalone render, no journal is left.
 *
 * argv: aafarm-master aafarm-worker scenes-folder
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;
static char scene[1024];
static char wrapper[1024];

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_NONE, 0) != 0) return -1;
    snprintf(wrapper, sizeof wrapper, "%s", ft_slow_worker(dir, 40));
    /* the reference: every frame, standalone, named by a pattern */
    const char *argv[] = {ft_worker, "--standalone", scene, "-o", ft_path(dir, "ref.%04d.exr"),
                          "--threads", "2", "-q", NULL};
    int rc = ft_wait(ft_spawn(ft_path(dir, "standalone.log"), argv), 120);
    if (rc != 0)
        fprintf(stderr, "the standalone reference render failed:\n%s\n",
                ft_read(ft_path(dir, "standalone.log")));
    return rc == 0 ? 0 : -1;
}

/* The embedded master with 2 local workers (private ipc folder in the
 * test's folder); extra: NULL-terminated options added at the end. */
static pid_t start_master(const char *log, const char *out, bool slow, const char *const *extra)
{
    const char *argv[32] = {ft_master, scene, "-o", out, "--local-workers", "2",
                            "--duplicates", "0", "-v"};
    int n = 9;
    if (slow) {
        argv[n++] = "--worker-binary";
        argv[n++] = wrapper;
    }
    for (int i = 0; extra && extra[i] && n < 31; i++) argv[n++] = extra[i];
    argv[n] = NULL;
    setenv("TMPDIR", dir, 1);
    pid_t pid = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    return pid;
}

/* dir/name in a buffer of the caller's (ft_path's buffers are reused) */
#define PATH(var, name) char var[1024]; snprintf(var, sizeof var, "%s", ft_path(dir, name))

static void assert_frame_equal(const char *name, int frame)
{
    char a[64], b[64];
    snprintf(a, sizeof a, "ref.%04d.exr", frame);
    snprintf(b, sizeof b, "%s.%04d.exr", name, frame);
    char pa[1024];
    snprintf(pa, sizeof pa, "%s", ft_path(dir, a));
    assert_int_equal(ft_exr_diff(pa, ft_path(dir, b)), 0);
}

static void test_sequence_equals_standalone(void **state)
{
    (void)state;
    /* the frames differ: each one rendered its own scene */
    char r1[1024];
    snprintf(r1, sizeof r1, "%s", ft_path(dir, "ref.0001.exr"));
    assert_true(ft_exr_diff(r1, ft_path(dir, "ref.0002.exr")) > 0);
    assert_true(ft_exr_diff(r1, ft_path(dir, "ref.0003.exr")) > 0);
    snprintf(r1, sizeof r1, "%s", ft_path(dir, "ref.0002.exr"));
    assert_true(ft_exr_diff(r1, ft_path(dir, "ref.0003.exr")) > 0);

    PATH(log, "seq-run.log");
    char jsonp[1024];
    snprintf(jsonp, sizeof jsonp, "%s", ft_path(dir, "seq-stats.json"));
    const char *json[] = {"--stats-json", jsonp, NULL};
    assert_int_equal(ft_wait(start_master(log, ft_path(dir, "seq.exr"), false, json), 120), 0);
    for (int k = 1; k <= 3; k++) assert_frame_equal("seq", k);
    /* three outputs, no temporary file, no journal */
    assert_int_equal(ft_count_files(dir, "seq."), 3);
    assert_int_equal(ft_count_files(dir, "seq.exr"), 0);
    assert_int_equal(ft_count(log, "3 frames (1 ... 3), 45 tiles of 32 in one queue"), 1);
    assert_int_equal(ft_count(log, "has 3 frames: each one's number goes before the extension "
                                   "of "), 1);
    assert_int_equal(ft_count(log, "frame 2: wrote "), 1);
    assert_int_equal(ft_count(log, "of 3 frames done"), 3);
    assert_int_equal(ft_count(log, "took frame "), 45);
    assert_int_equal(ft_json_number(jsonp, "frames_written"), 3);
    /* one queue: both workers rendered, and the job of each frame went out */
    assert_true(ft_count(log, "from local-1 (lease") >= 1);
    assert_true(ft_count(log, "from local-2 (lease") >= 1);
    assert_true(ft_count(log, "sent the job of frame 3") >= 1);
}

static void test_frames_choice_and_errors(void **state)
{
    (void)state;
    PATH(log, "three.log");
    const char *only3[] = {"--frames", "3", NULL};
    assert_int_equal(ft_wait(start_master(log, ft_path(dir, "only.exr"), false, only3), 120), 0);
    /* the name keeps the frame number: the file has several frames */
    assert_int_equal(ft_count_files(dir, "only."), 1);
    assert_frame_equal("only", 3);

    PATH(elog, "frames-err.log");
    const char *backwards[] = {"--frames", "1,3-2", NULL};
    assert_int_equal(ft_wait(start_master(elog, ft_path(dir, "bad.exr"), false, backwards), 30), 2);
    assert_int_equal(ft_count(elog, "--frames: the range 3-2 runs backwards (write 2-3)"), 1);
    const char *missing[] = {"--frames", "2,7", NULL};
    assert_int_equal(ft_wait(start_master(elog, ft_path(dir, "bad.exr"), false, missing), 30), 2);
    assert_int_equal(ft_count(elog, "--frames: the scene has no frame 7 (its frames: 1-3)"), 1);
    const char *garbage[] = {"--frames", "two", NULL};
    assert_int_equal(ft_wait(start_master(elog, ft_path(dir, "bad.exr"), false, garbage), 30), 2);
    assert_int_equal(ft_count(elog, "--frames: 'two' (at character 1 of 'two') is not a frame "
                                    "number"), 1);
    const char *pattern[] = {"--frames", "1", NULL};
    assert_int_equal(ft_wait(start_master(elog, ft_path(dir, "bad%s.exr"), false, pattern), 30),
                     2);
    assert_int_equal(ft_count(elog, "only %d, %4d, %04d (the frame number) and %% may follow "
                                    "a % sign"), 1);
    assert_int_equal(ft_count_files(dir, "bad"), 0);
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
}

static void test_resume_sequence_after_kill9(void **state)
{
    (void)state;
    PATH(log, "kill.log");
    pid_t master = start_master(log, ft_path(dir, "res.exr"), true, NULL);
    assert_true(ft_wait_for(log, "took frame ", 20, 60));
    kill(master, SIGKILL);
    assert_int_equal(ft_wait(master, 20), 128 + SIGKILL);
    int took = ft_count(log, "took frame ");
    assert_true(took < 45);   /* it really died mid-sequence */
    /* a journal per frame that took a tile */
    assert_true(ft_count_files(dir, "res.0001.exr.journal") == 1);

    PATH(log2, "resume.log");
    const char *resume[] = {"--resume", NULL};
    assert_int_equal(ft_wait(start_master(log2, ft_path(dir, "res.exr"), true, resume), 120), 0);
    for (int k = 1; k <= 3; k++) assert_frame_equal("res", k);
    /* what came back from the journals was not rendered again */
    int resumed = 0;
    char *text = ft_read(log2);
    for (const char *p = text; (p = strstr(p, "resuming: ")); p++)
        resumed += atoi(p + strlen("resuming: "));
    free(text);
    assert_true(resumed >= took);
    assert_int_equal(ft_count(log2, "took frame "), 45 - resumed);
    assert_int_equal(ft_count_files(dir, "res."), 3);   /* no journal, no temporary */
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
}

int main(int argc, char **argv)
{
    if (argc < 4 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: %s AAFARM_MASTER AAFARM_WORKER SCENES_DIR\n", argv[0]);
        return 2;
    }
    snprintf(scene, sizeof scene, "%s/ripples.rib", argv[3]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_sequence_equals_standalone, ft_teardown),
        cmocka_unit_test_teardown(test_frames_choice_and_errors, ft_teardown),
        cmocka_unit_test_teardown(test_resume_sequence_after_kill9, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
