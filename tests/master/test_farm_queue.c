/*
 * test_farm_queue.c: a master that outlives one render (aafarm-master
 * --serve --db, aafarm-submit; docs/farm.md "A job queue"), as real
 * processes over loopback: one local worker (slowed, so that jobs
 * overlap the submissions), four jobs of scenes/wave.rib at 64x48 from
 * several submitter processes with different priorities: the first runs
 * at once, of the three queued behind it the highest priority runs next
 * and one is cancelled before it starts; the master is killed with
 * SIGKILL in the middle of a job and restarted on the same database: the
 * running job is resumed from its journal, the queued one follows, the
 * submitters waiting with --wait get exit status 0 through the restart,
 * and every output equals the standalone render pixel for pixel.
 *
 * argv: aafarm-master aafarm-worker aafarm-submit scenes-folder
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
static const char *submit_bin, *scenes;
static char url[64];

static void write_scene(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/wave.rib", scenes);
    char *text = ft_read(path);
    FILE *out = fopen(ft_path(dir, "scene.rib"), "w");
    assert_non_null(out);
    /* 64x48, one sample a pixel, the shaders found from anywhere */
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "Format ", 7) == 0) fputs("Format 64 48 1\n", out);
        else if (strncmp(line, "PixelSamples ", 13) == 0) fputs("PixelSamples 1 1\n", out);
        else if (strstr(line, "\"searchpath\" \"shader\""))
            fprintf(out, "Option \"searchpath\" \"shader\" [\"%s/shaders:&\"]\n", scenes);
        else fprintf(out, "%s\n", line);
    }
    fclose(out);
    free(text);
}

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_NONE, 0) != 0) return -1;
    write_scene();
    if (ft_standalone(dir, 16) != 0) return -1;
    snprintf(url, sizeof url, "http://127.0.0.1:%d", ft_free_port());
    return 0;
}

static pid_t start_master(const char *log)
{
    const char *argv[] = {ft_master, "--serve", "--db", ft_path(dir, "queue.db"), "--http",
                          url + 7, "--local-workers", "1", "--worker-binary",
                          ft_slow_worker(dir, 200), NULL};
    return ft_spawn(log, argv);
}

/* aafarm-submit with the scene, output name and extra arguments. */
static pid_t submit(const char *log, const char *out, const char *priority, bool wait)
{
    const char *argv[] = {submit_bin, "--master", url, ft_path(dir, "scene.rib"), "-o",
                          ft_path(dir, out), "--tile", "16", "--priority", priority,
                          wait ? "--wait" : NULL, NULL};
    return ft_spawn(log, argv);
}

static void test_queue_priorities_cancel_and_restart(void **state)
{
    (void)state;
    char log1[1024], log2[1024], ll[1024];   /* ft_path's buffers are reused */
    snprintf(log1, sizeof log1, "%s", ft_path(dir, "master-1.log"));
    snprintf(log2, sizeof log2, "%s", ft_path(dir, "master-2.log"));
    snprintf(ll, sizeof ll, "%s", ft_path(dir, "list.log"));
    pid_t master = start_master(log1);
    assert_true(ft_wait_for(log1, "serving the job queue", 1, 30));
    assert_true(ft_wait_for(log1, "monitor on http://127.0.0.1:", 1, 5));

    /* job 1 runs at once; 2 (priority 1), 3 (priority 5) and 4 (priority 9)
     * queue behind it, from other submitter processes */
    pid_t first = submit(ft_path(dir, "submit-1.log"), "a.exr", "0", true);
    assert_true(ft_wait_for(log1, "job 1: ", 1, 30));
    pid_t second = submit(ft_path(dir, "submit-2.log"), "b.exr", "1", false);
    assert_int_equal(ft_wait(second, 30), 0);
    pid_t third = submit(ft_path(dir, "submit-3.log"), "c.exr", "5", true);
    assert_true(ft_wait_for(ft_path(dir, "submit-3.log"), "job 3 queued", 1, 30));
    pid_t fourth = submit(ft_path(dir, "submit-4.log"), "d.exr", "9", false);
    assert_int_equal(ft_wait(fourth, 30), 0);
    const char *cancel[] = {submit_bin, "--master", url, "--cancel", "4", NULL};
    assert_int_equal(ft_wait(ft_spawn(ft_path(dir, "cancel.log"), cancel), 30), 0);
    assert_int_equal(ft_count(ft_path(dir, "cancel.log"), "job 4 cancelled"), 1);
    /* a job that ended cannot be cancelled again */
    assert_int_equal(ft_wait(ft_spawn(ft_path(dir, "cancel-2.log"), cancel), 30), 1);
    assert_int_equal(ft_count(ft_path(dir, "cancel-2.log"), "job 4 has ended (cancelled)"), 1);

    /* job 1 ends; job 3 (priority 5) comes before job 2 (priority 1) */
    assert_int_equal(ft_wait(first, 60), 0);
    assert_true(ft_wait_for(log1, "job 3: ", 1, 30));
    assert_int_equal(ft_count(log1, "job 2: "), 0);
    /* SIGKILL in the middle of job 3, once a tile is whole in its journal
     * (the journal grew twice: the first record is complete) */
    char jpath[1024];
    snprintf(jpath, sizeof jpath, "%s", ft_path(dir, "c.exr.journal"));
    long size0 = -1;
    int grew = 0;
    for (double t0 = ft_now(); ft_now() - t0 < 30; ft_sleep_ms(20)) {
        struct stat st;
        if (stat(jpath, &st) != 0) continue;
        if (size0 < 0) size0 = (long)st.st_size;
        else if ((long)st.st_size > size0 && ++grew == 2) break;
        if ((long)st.st_size > size0) size0 = (long)st.st_size;
    }
    assert_int_equal(grew, 2);
    kill(master, SIGKILL);
    assert_int_equal(ft_wait(master, 10), 128 + SIGKILL);

    /* the master restarted on the same database resumes job 3, then job 2 */
    master = start_master(log2);
    assert_int_equal(ft_wait(third, 60), 0);   /* waited through the restart */
    assert_true(ft_wait_for(log2, "job 2 done", 1, 60));
    assert_true(ft_wait_for(log2, "job 3: ", 1, 1));
    assert_true(ft_count(log2, "; resumed, tiles from its journal") == 1);
    /* job 2 starts after job 3 (it may join job 3's last tiles: overlap) */
    assert_true(ft_position(log2, "job 3: ") < ft_position(log2, "job 2: "));
    assert_int_equal(ft_count(log1, "job 4: ") + ft_count(log2, "job 4: "), 0);

    /* the list says so */
    const char *list[] = {submit_bin, "--master", url, "--list", NULL};
    assert_int_equal(ft_wait(ft_spawn(ll, list), 30), 0);
    assert_int_equal(ft_count(ll, "  done  "), 3);
    assert_int_equal(ft_count(ll, "  cancelled  "), 1);

    /* every output is the standalone render */
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "a.exr")), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "b.exr")), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "c.exr")), 0);
    assert_int_equal(access(ft_path(dir, "d.exr"), F_OK), -1);
    assert_int_equal(ft_count_files(dir, "c.exr."), 0);   /* no journal, no temporary file */

    kill(master, SIGTERM);
    assert_int_equal(ft_wait(master, 10), 130);
}

int main(int argc, char **argv)
{
    if (argc < 5 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_farm_queue MASTER WORKER SUBMIT SCENES\n");
        return 2;
    }
    submit_bin = argv[3];
    scenes = argv[4];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_queue_priorities_cancel_and_restart),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
