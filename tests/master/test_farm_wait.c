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
 *     master renders the image equal to standalone;
 *   - --min-workers 2: with one worker joined the master says "1 of 2
 *     joined" and grants nothing (the worker renders no tile); once a
 *     second joins it renders, equal to standalone;
 *   - --wait-timeout 2 with no worker: exit 4 with the reason, within a
 *     bounded time, no output; with --min-workers 2 and one worker: the
 *     same, naming "1 of 2 workers joined"; more --min-workers than
 *     local workers: exit 2;
 *   - --wait-timeout 2 and the only worker killed mid-render: exit 4, the
 *     journal kept; --resume completes the image, equal to standalone.
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
#include <unistd.h>

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

static void test_min_workers_waits_for_the_second(void **state)
{
    (void)state;
    setenv("AAFARM_WAIT_REPORT_MS", "500", 1);
    char log[1024];
    snprintf(log, sizeof log, "%s", ft_path(dir, "min.log"));
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "min.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "16", "--min-workers", "2",
                          "-v", NULL};
    pid_t m = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 20));
    char line[1200];
    snprintf(line, sizeof line, "waiting for workers on %s (start one with: aafarm-worker "
             "--connect %s); 0 of 2 joined (--min-workers)\n", ep, ep);
    assert_true(ft_wait_for(log, line, 1, 10));
    const char *w1argv[] = {ft_worker, "--connect", ep, "--name", "first", "--threads", "1", NULL};
    pid_t w1 = ft_spawn(ft_path(dir, "min-w1.log"), w1argv);
    assert_true(ft_wait_for(log, "worker first joined", 1, 20));
    snprintf(line, sizeof line, "waiting for workers on %s: 1 of 2 joined (--min-workers)\n", ep);
    assert_true(ft_wait_for(log, line, 2, 20));   /* at the join, then again every 0.5 s */
    assert_true(ft_running(m));
    assert_int_equal(ft_count(log, "granted tile"), 0);   /* -v: no grant yet */
    assert_int_equal(ft_count(log, "took tile"), 0);
    const char *w2argv[] = {ft_worker, "--connect", ep, "--name", "second", "--threads", "1", NULL};
    pid_t w2 = ft_spawn(ft_path(dir, "min-w2.log"), w2argv);
    assert_int_equal(ft_wait(m, 120), 0);
    assert_int_equal(ft_count(log, "2 of 2 workers joined (--min-workers): rendering"), 1);
    char *text = ft_read(log);   /* the first grant comes after the second worker joined */
    const char *joined = strstr(text, "worker second joined");
    const char *grant = strstr(text, "granted tile");
    assert_non_null(joined);
    assert_non_null(grant);
    assert_true(joined < grant);
    free(text);
    assert_int_equal(ft_exr_diff(ft_path(dir, "min.exr"), ft_path(dir, "ref.exr")), 0);
    kill(w1, SIGTERM);
    kill(w2, SIGTERM);
    assert_int_equal(ft_wait(w1, 10), 130);
    assert_int_equal(ft_wait(w2, 10), 130);
    unsetenv("AAFARM_WAIT_REPORT_MS");
}

static void test_wait_timeout_gives_up(void **state)
{
    (void)state;
    /* no worker at all */
    char log[1024];
    snprintf(log, sizeof log, "%s", ft_path(dir, "timeout.log"));
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "to.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "16", "--wait-timeout", "2",
                          NULL};
    double t0 = ft_now();
    pid_t m = ft_spawn(log, argv);
    assert_int_equal(ft_wait(m, 30), 4);
    double took = ft_now() - t0;
    assert_true(took >= 1.9 && took < 30);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 1));
    char line[1200];
    snprintf(line, sizeof line, "gave up after --wait-timeout 2 s: no worker joined on %s "
             "(start workers with: aafarm-worker --connect %s)\n", ep, ep);
    assert_int_equal(ft_count(log, line), 1);
    assert_int_equal(ft_count_files(dir, "to.exr"), 0);   /* no output, no journal (no tile) */

    /* --min-workers 2, one worker joined */
    snprintf(log, sizeof log, "%s", ft_path(dir, "timeout-2.log"));
    const char *argv2[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "to.exr"),
                           "--bind", "tcp://127.0.0.1:*", "--tile", "16", "--wait-timeout", "3",
                           "--min-workers", "2", NULL};
    m = ft_spawn(log, argv2);
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 20));
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "alone", "--threads", "1", NULL};
    pid_t w = ft_spawn(ft_path(dir, "timeout-w.log"), wargv);
    assert_int_equal(ft_wait(m, 30), 4);
    assert_int_equal(ft_count(log, "worker alone joined"), 1);
    assert_int_equal(ft_count(log, "gave up after --wait-timeout 3 s: 1 of 2 workers joined on "), 1);
    assert_int_equal(ft_count(log, "to.exr not written"), 1);
    assert_int_equal(ft_count_files(dir, "to.exr"), 0);
    kill(w, SIGTERM);
    assert_int_equal(ft_wait(w, 10), 130);

    /* more than the local workers can ever be: a usage error, nothing started */
    snprintf(log, sizeof log, "%s", ft_path(dir, "timeout-usage.log"));
    const char *argv3[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "to.exr"),
                           "--local-workers", "2", "--min-workers", "3", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, argv3), 30), 2);
    assert_int_equal(ft_count(log, "--min-workers 3 without --bind: only the 2 local workers can "
                                   "join"), 1);
}

/* Every worker lost mid-render: --wait-timeout later the master gives up
 * (exit 4) and keeps its journal; --resume with a worker completes it. */
static void test_wait_timeout_after_every_worker_is_lost(void **state)
{
    (void)state;
    char log[1024];
    snprintf(log, sizeof log, "%s", ft_path(dir, "lost.log"));
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "lost.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "16", "--wait-timeout", "2",
                          "--heartbeat", "200", "-v", NULL};
    pid_t m = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 20));
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "doomed", "--threads", "1",
                           "--tile-delay", "200", NULL};
    pid_t w = ft_spawn(ft_path(dir, "lost-w.log"), wargv);
    assert_true(ft_wait_for(log, "took tile", 2, 30));
    kill(w, SIGKILL);
    assert_int_equal(ft_wait(w, 10), 128 + SIGKILL);
    assert_int_equal(ft_wait(m, 30), 4);
    assert_int_equal(ft_count(log, " tiles back in the queue"), 1);   /* doomed lost */
    assert_int_equal(ft_count(log, "gave up after --wait-timeout 2 s: no worker alive (1 joined, "
                                   "none alive now) on "), 1);
    assert_int_equal(ft_count(log, "the same command with --resume renders only the others"), 1);
    assert_int_equal(ft_count_files(dir, "lost.exr.journal"), 1);
    assert_int_equal(access(ft_path(dir, "lost.exr"), F_OK), -1);

    /* resumed with a worker: equal to standalone */
    snprintf(log, sizeof log, "%s", ft_path(dir, "lost-2.log"));
    const char *argv2[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "lost.exr"),
                           "--tile", "16", "--local-workers", "1", "--resume", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, argv2), 120), 0);
    assert_int_equal(ft_count(log, "resuming: "), 1);
    assert_int_equal(ft_exr_diff(ft_path(dir, "lost.exr"), ft_path(dir, "ref.exr")), 0);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_master_without_workers_says_so, ft_teardown),
        cmocka_unit_test_teardown(test_worker_without_master_says_so, ft_teardown),
        cmocka_unit_test_teardown(test_min_workers_waits_for_the_second, ft_teardown),
        cmocka_unit_test_teardown(test_wait_timeout_gives_up, ft_teardown),
        cmocka_unit_test_teardown(test_wait_timeout_after_every_worker_is_lost, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
