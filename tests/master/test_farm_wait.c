/*
 * test_farm_wait.c: a farm says what it waits for (issue 25), with real
 * processes on loopback (AAFARM_WAIT_REPORT_MS shortens the 30 s report
 * interval of both programs):
 *   - a master with --bind and no worker says at once where it listens
 *     and how to start a worker (the real port for '*'), then again with
 *     how long it has waited, never exits on its own for this, and ends
 *     with 130 on SIGTERM;
 *   - a worker pointed at a port where nothing listens says "cannot
 *     reach" once, then a line per interval (not one per retry), and
 *     "connected ... after N s" once a master appears on that port; that
 *     master renders the image equal to standalone.
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

#include "farm_testutil.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_WAVE, 16);
}

static void test_master_without_workers_says_so(void **state)
{
    (void)state;
    setenv("AAFARM_WAIT_REPORT_MS", "500", 1);
    const char *log = ft_path(dir, "alone.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "alone.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "16", NULL};
    pid_t m = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 20));
    assert_null(strstr(ep, "*"));   /* the port bound, not the wildcard */
    char line[600];
    snprintf(line, sizeof line, "waiting for workers on %s (start one with: aafarm-worker "
             "--connect %s); 0 joined\n", ep, ep);
    assert_true(ft_wait_for(log, line, 1, 10));
    /* then again, with how long it has waited */
    snprintf(line, sizeof line, "still waiting for workers on %s after ", ep);
    assert_true(ft_wait_for(log, line, 3, 20));
    assert_true(ft_count(log, "0 joined (start one with: aafarm-worker --connect ") >= 3);
    assert_true(ft_running(m));   /* it waits for its workers: no exit on its own */
    assert_int_equal(kill(m, SIGTERM), 0);
    assert_int_equal(ft_wait(m, 10), 130);
    assert_int_equal(ft_count_files(dir, "alone.exr"), 0);
    unsetenv("AAFARM_WAIT_REPORT_MS");
}

static void test_worker_without_master_says_so(void **state)
{
    (void)state;
    setenv("AAFARM_WAIT_REPORT_MS", "1000", 1);
    int port = ft_free_port();
    char ep[64];
    snprintf(ep, sizeof ep, "tcp://127.0.0.1:%d", port);
    const char *wlog = ft_path(dir, "lonely.log");
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "lonely", "--threads", "1", NULL};
    double t0 = ft_now();
    pid_t w = ft_spawn(wlog, wargv);
    char needle[200];
    snprintf(needle, sizeof needle, "cannot reach the master at %s: no answer for ", ep);
    assert_true(ft_wait_for(wlog, needle, 1, 20));
    snprintf(needle, sizeof needle, "still no master at %s after ", ep);
    assert_true(ft_wait_for(wlog, needle, 3, 20));
    double tried = ft_now() - t0;
    ft_sleep_ms(1500);
    tried += 1.5;
    /* once; then about a line a second, not one per retry */
    assert_int_equal(ft_count(wlog, "cannot reach"), 1);
    int still = ft_count(wlog, "still no master");
    assert_true(still >= 3 && still <= (int)tried + 1);
    assert_int_equal(ft_count(wlog, "reconnecting in"), 0);
    assert_int_equal(ft_count(wlog, "no answer for"), 1);
    assert_true(ft_running(w));

    /* a master appears on that port: the worker says how long it took */
    const char *mlog = ft_path(dir, "late.log");
    const char *margv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "late.exr"),
                           "--bind", ep, "--tile", "16", NULL};
    pid_t m = ft_spawn(mlog, margv);
    assert_true(ft_wait_for(wlog, "connected to master ", 1, 60));
    snprintf(needle, sizeof needle, " at %s after ", ep);
    char *text = ft_read(wlog);
    const char *line = strstr(text, "connected to master ");
    const char *after = strstr(line, needle);
    assert_non_null(after);
    assert_true(after < strchr(line, '\n'));   /* on the line that says it connected */
    after += strlen(needle);
    int secs = atoi(after);
    free(text);
    assert_true(secs >= (int)tried - 1);
    assert_int_equal(ft_count(wlog, "connected to master "), 1);
    assert_int_equal(ft_wait(m, 120), 0);
    assert_int_equal(ft_count(mlog, "worker lonely joined"), 1);
    assert_int_equal(ft_exr_diff(ft_path(dir, "late.exr"), ft_path(dir, "ref.exr")), 0);
    assert_int_equal(kill(w, SIGTERM), 0);
    assert_int_equal(ft_wait(w, 10), 130);
    unsetenv("AAFARM_WAIT_REPORT_MS");
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_master_without_workers_says_so, ft_teardown),
        cmocka_unit_test_teardown(test_worker_without_master_says_so, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
