/*
 * test_farm_render.c: the farm renders what the standalone renderer
 * renders, pixel for pixel, with real processes over real sockets:
 *   - the local two-process test: one master, one worker, tcp://127.0.0.1;
 *   - three workers: one started before the master, one joining mid-render;
 *   - the embedded default (no --bind): local workers started and stopped
 *     by the master, preview and statistics written, nothing left behind;
 *     the preview PNG is byte for byte the standalone renderer's;
 *   - the master killed with SIGKILL mid-render: its local workers end at
 *     once (issue 27; the test is their subreaper and reaps them by PID).
 * The reference is `aafarm-worker --standalone` of the same scene.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_WAVE, 8);
}

static pid_t start_worker(const char *endpoint, const char *name, const char *threads,
                          const char *delay_ms)
{
    char log[64];
    snprintf(log, sizeof log, "%s.log", name);
    const char *argv[] = {ft_worker, "--connect", endpoint, "--name", name, "--threads", threads,
                          "--tile-delay", delay_ms, NULL};
    return ft_spawn(ft_path(dir, log), argv);
}

/* A worker that served a master keeps waiting for the next one; SIGTERM
 * ends it with status 130. */
static void stop_worker(pid_t pid)
{
    assert_true(ft_running(pid));
    kill(pid, SIGTERM);
    assert_int_equal(ft_wait(pid, 20), 130);
}

static void test_farm_two_processes_equal_standalone(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = ft_start_master(dir, "two", "8", ep, sizeof ep);
    assert_true(master > 0);
    const char *log = ft_path(dir, "two.log");
    assert_non_null(strstr(ep, "tcp://127.0.0.1:"));
    pid_t worker = start_worker(ep, "solo", "2", "0");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "two.exr")), 0);
    assert_int_equal(ft_count_files(dir, "two.exr.tmp"), 0);
    /* the summary names the worker and its 48 tiles */
    assert_int_equal(ft_count(log, "worker solo joined"), 1);
    char *text = ft_read(log);
    const char *row = strstr(text, "  solo ");
    assert_non_null(row);
    long tiles = -1;
    sscanf(row, " solo %*s %ld", &tiles);
    assert_int_equal(tiles, 48);
    free(text);
    stop_worker(worker);
}

/* A worker's idle threads help its last tile (worker/worker_pool.c,
 * tile_share.h): the whole image is one tile, leased to one worker of 4
 * threads; 3 threads have nothing else to do, so they trace blocks of it.
 * The image equals the standalone one, and the worker says (-v) that
 * blocks were traced by idle threads. */
static void test_idle_threads_help_the_last_tile(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = ft_start_master(dir, "one", "64", ep, sizeof ep);
    assert_true(master > 0);
    const char *wlog = ft_path(dir, "helped.log");
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "helped", "--threads", "4",
                           "-v", NULL};
    pid_t worker = ft_spawn(wlog, wargv);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "one.exr")), 0);
    char *text = ft_read(wlog);
    const char *sent = strstr(text, "tile 0 sent");
    assert_non_null(sent);
    const char *by = strstr(sent, " blocks by idle threads");
    assert_non_null(by);
    while (by > sent && by[-1] >= '0' && by[-1] <= '9') by--;
    long helped = strtol(by, NULL, 10);
    printf("one tile, 4 threads: %ld blocks of 8x8 pixels traced by the idle threads\n", helped);
    assert_true(helped > 0);
    free(text);
    stop_worker(worker);
}

static void test_farm_three_workers_early_and_late(void **state)
{
    (void)state;
    int port = ft_free_port();
    assert_true(port > 0);
    char bind[64];
    snprintf(bind, sizeof bind, "tcp://127.0.0.1:%d", port);
    /* early: connects (and keeps trying) before the master exists */
    pid_t early = start_worker(bind, "early", "1", "60");
    ft_sleep_ms(300);
    const char *log = ft_path(dir, "three.log");
    const char *json = ft_path(dir, "three.json");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "three.exr"),
                          "--bind", bind, "--tile", "8", "--stats-json", json, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    assert_true(ft_wait_for(log, "worker early joined", 1, 30));
    pid_t second = start_worker(bind, "second", "1", "60");
    /* late: joins once tiles are coming back */
    assert_true(ft_wait_for(log, "took tile ", 4, 60));
    assert_true(ft_count(log, "wrote ") == 0);
    pid_t late = start_worker(bind, "late", "1", "60");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "three.exr")), 0);
    assert_int_equal(ft_count(log, "worker second joined"), 1);
    assert_int_equal(ft_count(log, "worker late joined"), 1);
    /* the late worker took part: some tile came from it */
    assert_true(ft_count(log, " from late (lease") >= 1);
    assert_true(ft_count(json, "\"tiles_done\": 48") == 1);
    stop_worker(early);
    stop_worker(second);
    stop_worker(late);
}

/* The pids of "worker local-K joined (host, pid P" lines. */
static int local_pids(const char *log, pid_t *pids, int max)
{
    char *text = ft_read(log);
    int n = 0;
    for (const char *p = text; n < max && (p = strstr(p, "joined (")); p++) {
        const char *q = strstr(p, ", pid ");
        if (q) pids[n++] = (pid_t)atoi(q + 6);
    }
    free(text);
    return n;
}

/* Bytes that differ between two files (the longer one's tail counts); -1
 * when one cannot be read. */
static long file_diff(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    long diff = -1;
    if (fa && fb) {
        diff = 0;
        int ca, cb;
        do {
            ca = fgetc(fa);
            cb = fgetc(fb);
            if (ca != cb) diff++;
        } while (ca != EOF || cb != EOF);
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return diff;
}

static void test_farm_embedded_default(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "embedded.log");
    const char *json = ft_path(dir, "embedded.json");
    const char *png = ft_path(dir, "embedded.png");
    setenv("TMPDIR", dir, 1);   /* the master's private socket folder goes here */
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "embedded.exr"),
                          "--local-workers", "2", "--tile", "8", "--preview", png,
                          "--stats-json", json, NULL};
    pid_t master = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "embedded.exr")), 0);
    /* the preview is a PNG (byte for byte the standalone one's: below) */
    char *head = ft_read(png);
    assert_memory_equal(head, "\x89PNG", 4);
    free(head);
    /* statistics: done, every tile, two local workers */
    assert_int_equal(ft_count(json, "\"status\": \"done\""), 1);
    assert_int_equal(ft_count(json, "\"tiles_done\": 48"), 1);
    assert_int_equal(ft_count(json, "\"local\": true"), 2);
    /* the local workers are gone and the private socket folder removed */
    pid_t pids[2];
    assert_int_equal(local_pids(log, pids, 2), 2);
    for (int i = 0; i < 2; i++) {
        errno = 0;
        assert_int_equal(kill(pids[i], 0), -1);
        assert_int_equal(errno, ESRCH);
    }
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
    assert_int_equal(ft_count_files(dir, "embedded.exr.tmp"), 0);
    /* the preview is byte for byte the standalone renderer's (issue 27:
     * both are made from the finished EXR by one function); last, as
     * ft_path's buffers above are reused by now */
    char sa_png[4096], farm_png[4096];   /* ft_path's buffers are reused */
    snprintf(sa_png, sizeof sa_png, "%s", ft_path(dir, "standalone.png"));
    snprintf(farm_png, sizeof farm_png, "%s", ft_path(dir, "embedded.png"));
    const char *sargv[] = {ft_worker, "--standalone", ft_path(dir, "scene.rib"), "-o",
                           ft_path(dir, "sa.exr"), "--tile", "8", "--threads", "2", "-q",
                           "--preview", sa_png, NULL};
    assert_int_equal(ft_wait(ft_spawn(ft_path(dir, "sa.log"), sargv), 120), 0);
    assert_int_equal(file_diff(sa_png, farm_png), 0);
}

/* Issue 27: local workers end at once when their master dies (SIGKILL: it
 * cannot stop them itself), even in the middle of a tile. The test becomes
 * the orphans' subreaper, so it reaps them by PID; "at once" is bounded
 * generously (2 s, less than what is left of the tile they are in) and the
 * time measured is printed. */
static void test_local_workers_end_with_their_master(void **state)
{
    (void)state;
    assert_int_equal(prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0), 0);
    /* each tile starts with 3 s the worker cannot be interrupted in (as a
     * long shader evaluation): an orderly exit on SIGTERM would wait it out */
    const char *wrapper = ft_slow_worker(dir, 3000);
    const char *log = ft_path(dir, "orphans.log");
    setenv("TMPDIR", dir, 1);
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "orphans.exr"),
                          "--tile", "8", "--local-workers", "2", "--threads-per-worker", "2",
                          "--worker-binary", wrapper, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    assert_true(ft_wait_for(log, "granted tile ", 4, 60));
    ft_sleep_ms(300);   /* both are inside their first tiles now */
    pid_t pids[2];
    assert_int_equal(local_pids(log, pids, 2), 2);
    double t0 = ft_now();
    kill(master, SIGKILL);
    assert_int_equal(ft_wait(master, 10), 128 + SIGKILL);
    bool gone[2] = {false, false};
    double took[2] = {-1, -1};
    while (ft_now() - t0 < 2.0 && !(gone[0] && gone[1])) {
        for (int i = 0; i < 2; i++) {
            if (gone[i]) continue;
            pid_t r = waitpid(pids[i], NULL, WNOHANG);
            if (r == pids[i] || (r < 0 && errno == ECHILD && kill(pids[i], 0) != 0)) {
                gone[i] = true;
                took[i] = ft_now() - t0;
            }
        }
        ft_sleep_ms(1);
    }
    for (int i = 0; i < 2; i++) {
        if (!gone[i]) {   /* bounded: never leave one behind */
            kill(pids[i], SIGKILL);
            waitpid(pids[i], NULL, 0);
        }
        if (gone[i])
            fprintf(stderr, "local worker %d (pid %d) ended %.0f ms after its master's "
                    "SIGKILL\n", i + 1, (int)pids[i], took[i] * 1000.0);
        else
            fprintf(stderr, "local worker %d (pid %d) still ran 2 s after its master's "
                    "SIGKILL\n", i + 1, (int)pids[i]);
    }
    assert_true(gone[0] && gone[1]);
    prctl(PR_SET_CHILD_SUBREAPER, 0, 0, 0, 0);
    /* the next master cleans what this one left (its private folder) */
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_farm_two_processes_equal_standalone, ft_teardown),
        cmocka_unit_test_teardown(test_idle_threads_help_the_last_tile, ft_teardown),
        cmocka_unit_test_teardown(test_farm_three_workers_early_and_late, ft_teardown),
        cmocka_unit_test_teardown(test_farm_embedded_default, ft_teardown),
        cmocka_unit_test_teardown(test_local_workers_end_with_their_master, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
