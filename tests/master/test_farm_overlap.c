/*
 * test_farm_overlap.c: a serving master's jobs overlap (issue 25; docs/farm.md
 * "A job queue", "Overlap"), as real processes over loopback: a master
 * with --serve --bind --min-workers 2 and two workers of the test, one
 * fast (--tile-delay 100) and one slow (--tile-delay 1500), --duplicates 0
 * and --lease-factor 0 so that the slow worker's tiles stay its own. Each
 * job is scenes/wave.rib at 32x32 (X, 4 tiles of 16) or 48x32 (Y, 6
 * tiles), both queued before the workers join (--min-workers holds X
 * back): the slow worker takes two of X's tiles at once, the fast one
 * the two others; when the fast one asks again, nothing of X is left to
 * hand out, Y joins, and its tiles are leased while X's two are still
 * out (the master's log says so from its scheduler's leases), Y is done
 * before X, and both equal their standalone renders. Then the same pair
 * again, and the first job cancelled while the second has joined it: the
 * first ends cancelled (no output, no journal), the second goes back to
 * the queue with its journal, resumes, and equals its standalone render.
 * Then a job whose output cannot be written (a missing folder) joins a
 * run: it fails alone, the job it joined is requeued, resumes and equals
 * its standalone render.
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
#include <unistd.h>

#include "farm_testutil.h"

static char *dir_x, *dir_y, *dir;
static const char *submit_bin, *scenes;
static char url[64];

/* scenes/wave.rib at w x h, one sample a pixel, into d/scene.rib, and
 * its standalone render d/ref.exr. */
static int write_scene(const char *d, int w, int h)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/wave.rib", scenes);
    char *text = ft_read(path);
    FILE *out = fopen(ft_path(d, "scene.rib"), "w");
    if (!out || !text) return -1;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "Format ", 7) == 0) fprintf(out, "Format %d %d 1\n", w, h);
        else if (strncmp(line, "PixelSamples ", 13) == 0) fputs("PixelSamples 1 1\n", out);
        else if (strstr(line, "\"searchpath\" \"shader\""))
            fprintf(out, "Option \"searchpath\" \"shader\" [\"%s/shaders:&\"]\n", scenes);
        else fprintf(out, "%s\n", line);
    }
    fclose(out);
    free(text);
    return ft_standalone(d, 16);
}

static int group_setup(void **state)
{
    (void)state;
    dir = ft_tempdir();
    dir_x = ft_tempdir();
    dir_y = ft_tempdir();
    if (write_scene(dir_x, 32, 32) != 0 || write_scene(dir_y, 48, 32) != 0) {
        fprintf(stderr, "the standalone renders failed\n");
        return -1;
    }
    snprintf(url, sizeof url, "http://127.0.0.1:%d", ft_free_port());
    return 0;
}

static int group_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    ft_rmtree(dir);
    ft_rmtree(dir_x);
    ft_rmtree(dir_y);
    free(dir);
    free(dir_x);
    free(dir_y);
    return 0;
}

/* aafarm-submit of d/scene.rib to dir/out, waiting for its end. */
static pid_t submit(const char *log, const char *d, const char *out)
{
    char scene[1024];
    snprintf(scene, sizeof scene, "%s", ft_path(d, "scene.rib"));
    const char *argv[] = {submit_bin, "--master", url, scene, "-o", ft_path(dir, out), "--tile",
                          "16", "--wait", NULL};
    return ft_spawn(log, argv);
}

static void test_next_job_joins_the_last_tiles(void **state)
{
    (void)state;
    char log[1024], sx[1024], sy[1024];
    snprintf(log, sizeof log, "%s", ft_path(dir, "master.log"));
    snprintf(sx, sizeof sx, "%s", ft_path(dir, "submit-x.log"));
    snprintf(sy, sizeof sy, "%s", ft_path(dir, "submit-y.log"));
    const char *argv[] = {ft_master, "--serve", "--db", ft_path(dir, "queue.db"), "--http",
                          url + 7, "--bind", "tcp://127.0.0.1:*", "--min-workers", "2",
                          "--duplicates", "0", "--lease-factor", "0", NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 20));
    assert_true(ft_wait_for(log, "serving the job queue", 1, 20));

    /* X and Y queued before the workers (--min-workers 2 holds X back) */
    pid_t px = submit(sx, dir_x, "x.exr");
    assert_true(ft_wait_for(sx, "job 1 queued", 1, 30));
    pid_t py = submit(sy, dir_y, "y.exr");
    assert_true(ft_wait_for(sy, "job 2 queued", 1, 30));
    assert_true(ft_wait_for(log, "job 1: ", 1, 30));
    /* the slow one first: in the registry's order it is granted first */
    const char *slow[] = {ft_worker, "--connect", ep, "--name", "slow", "--threads", "1",
                          "--tile-delay", "1500", NULL};
    const char *fast[] = {ft_worker, "--connect", ep, "--name", "fast", "--threads", "1",
                          "--tile-delay", "100", NULL};
    pid_t ws = ft_spawn(ft_path(dir, "slow.log"), slow);
    assert_true(ft_wait_for(log, "worker slow joined", 1, 20));
    pid_t wf = ft_spawn(ft_path(dir, "fast.log"), fast);
    assert_true(ft_wait_for(log, "2 of 2 workers joined (--min-workers): rendering", 1, 20));
    assert_int_equal(ft_wait(py, 60), 0);
    assert_int_equal(ft_wait(px, 60), 0);
    assert_int_equal(ft_count(log, "job 2: "), 2);   /* it starts, and its overlap */
    /* the slow worker's two, and the fast one's second one or not */
    assert_int_equal(ft_count(log, " tiles of job 1 are out\n"), 1);
    assert_int_equal(ft_count(log, "job 2: 1 tile leased while "), 1);
    assert_int_equal(ft_count(log, " tiles of job 1 are still out (overlap)\n"), 1);
    assert_int_equal(ft_count(log, "frames done"), 0);   /* one frame a job */
    assert_true(ft_position(log, "job 2: ") < ft_position(log, "job 1 done"));
    assert_true(ft_position(log, "job 2 done") < ft_position(log, "job 1 done"));   /* Y overtook */
    assert_int_equal(ft_exr_diff(ft_path(dir_x, "ref.exr"), ft_path(dir, "x.exr")), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir_y, "ref.exr"), ft_path(dir, "y.exr")), 0);
    assert_int_equal(ft_count_files(dir, "x.exr."), 0);   /* no journal, no temporary file */
    assert_int_equal(ft_count_files(dir, "y.exr."), 0);

    /* again, and the first one cancelled while the second has joined it */
    snprintf(sx, sizeof sx, "%s", ft_path(dir, "submit-p.log"));
    snprintf(sy, sizeof sy, "%s", ft_path(dir, "submit-q.log"));
    pid_t pp = submit(sx, dir_x, "p.exr");
    assert_true(ft_wait_for(sx, "job 3 queued", 1, 30));
    pid_t pq = submit(sy, dir_y, "q.exr");
    assert_true(ft_wait_for(log, " tiles of job 3 are still out (overlap)", 1, 30));
    const char *cancel[] = {submit_bin, "--master", url, "--cancel", "3", NULL};
    assert_int_equal(ft_wait(ft_spawn(ft_path(dir, "cancel.log"), cancel), 30), 0);
    assert_int_equal(ft_wait(pp, 30), 130);
    assert_int_equal(ft_wait(pq, 60), 0);
    assert_int_equal(ft_count(log, "job 3 cancelled"), 1);
    assert_int_equal(ft_count(log, "job 4 requeued: the job beside it was cancelled"), 1);
    assert_int_equal(ft_count(log, "job 4 done"), 1);
    assert_int_equal(ft_count(log, "job 3 done"), 0);
    assert_true(ft_position(log, "job 4 requeued") < ft_position(log, "job 4 done"));
    assert_int_equal(ft_exr_diff(ft_path(dir_y, "ref.exr"), ft_path(dir, "q.exr")), 0);
    assert_int_equal(access(ft_path(dir, "p.exr"), F_OK), -1);
    assert_int_equal(ft_count_files(dir, "p.exr"), 0);   /* nor its journal */
    assert_int_equal(ft_count_files(dir, "q.exr."), 0);

    /* a job whose output cannot be written joins a run: it fails, the job
     * it joined goes back to the queue with its journal and resumes */
    snprintf(sx, sizeof sx, "%s", ft_path(dir, "submit-r.log"));
    snprintf(sy, sizeof sy, "%s", ft_path(dir, "submit-f.log"));
    pid_t pr = submit(sx, dir_x, "r.exr");
    assert_true(ft_wait_for(sx, "job 5 queued", 1, 30));
    pid_t pf = submit(sy, dir_y, "missing/f.exr");
    assert_int_equal(ft_wait(pf, 60), 1);
    assert_int_equal(ft_wait(pr, 60), 0);
    assert_int_equal(ft_count(log, "job 6: "), 0);   /* it never started */
    assert_int_equal(ft_count(log, "job 6 failed: "), 1);
    assert_int_equal(ft_count(log, "job 5 requeued: the job beside it failed"), 1);
    assert_int_equal(ft_count(log, "job 5 done"), 1);
    assert_int_equal(ft_exr_diff(ft_path(dir_x, "ref.exr"), ft_path(dir, "r.exr")), 0);
    assert_int_equal(ft_count_files(dir, "r.exr."), 0);

    kill(master, SIGTERM);
    assert_int_equal(ft_wait(master, 10), 130);
    kill(ws, SIGTERM);
    kill(wf, SIGTERM);
    assert_int_equal(ft_wait(ws, 10), 130);
    assert_int_equal(ft_wait(wf, 10), 130);
}

int main(int argc, char **argv)
{
    if (argc < 5 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_farm_overlap MASTER WORKER SUBMIT SCENES\n");
        return 2;
    }
    submit_bin = argv[3];
    scenes = argv[4];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_next_job_joins_the_last_tiles),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
