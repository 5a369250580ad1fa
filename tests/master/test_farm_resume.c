/*
 * test_farm_resume.c: kill -9 the master and resume, with real processes
 * (an embedded master with two slowed-down local workers):
 *   - killed after 1, 20 and 36 of 48 tiles: the journal and the dead
 *     master's temporary file and ipc folder are left; `--resume` removes
 *     the leftovers, takes at least the tiles the dead master took from
 *     the journal, grants only the others (no tile rendered twice), and
 *     the image equals the standalone render sample for sample; the
 *     journal is gone afterwards;
 *   - the journal's tail torn (garbage appended) and its last record
 *     corrupted (a flipped byte): the resume drops them, says so, and the
 *     image is still equal;
 *   - --resume of another job (another tile size) is refused with exit 2
 *     and leaves the journal as it was; --resume without a journal renders
 *     everything.
 * Moments are counted in tiles the master logged, never in seconds.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;
static char wrapper[4096];

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_WAVE, 8) != 0) return -1;
    snprintf(wrapper, sizeof wrapper, "%s", ft_slow_worker(dir, 60));
    return 0;
}

/* The embedded master on out (private ipc folder in the test's folder);
 * extra options after the fixed ones. */
static pid_t start_master(const char *log, const char *out, const char *json, bool resume,
                          const char *tile)
{
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--tile", tile,
                          "--local-workers", "2", "--worker-binary", wrapper, "--duplicates", "0",
                          "--stats-json", json, "-v", resume ? "--resume" : NULL, NULL};
    setenv("TMPDIR", dir, 1);
    pid_t pid = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    return pid;
}

static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

/* The number after "resuming: " in the log, -1 when absent. */
static int resumed_count(const char *log)
{
    char *text = ft_read(log);
    const char *p = strstr(text, "resuming: ");
    int n = p ? atoi(p + strlen("resuming: ")) : -1;
    free(text);
    return n;
}

/* Starts a render, kills the master with SIGKILL once it took `after`
 * tiles; returns how many it had logged. */
static int render_and_kill(const char *name, int after)
{
    char log[64], out[64], json[64];
    snprintf(log, sizeof log, "%s-1.log", name);
    snprintf(out, sizeof out, "%s.exr", name);
    snprintf(json, sizeof json, "%s-1.json", name);
    const char *logp = ft_path(dir, log);
    pid_t master = start_master(logp, ft_path(dir, out), ft_path(dir, json), false, "8");
    assert_true(ft_wait_for(logp, "took tile ", after, 60));
    kill(master, SIGKILL);
    assert_int_equal(ft_wait(master, 20), 128 + SIGKILL);
    int took = ft_count(logp, "took tile ");
    assert_true(took < 48);   /* it really died mid-render */
    /* what a dead master leaves: its temporary file, its journal, its
     * ipc folder (the local workers exit on their own: PR_SET_PDEATHSIG) */
    char prefix[80];
    snprintf(prefix, sizeof prefix, "%s.exr.tmp-", name);
    assert_int_equal(ft_count_files(dir, prefix), 1);
    snprintf(prefix, sizeof prefix, "%s.exr.journal", name);
    assert_int_equal(ft_count_files(dir, prefix), 1);
    assert_int_equal(access(ft_path(dir, out), F_OK), -1);
    return took;
}

/* Resumes `name` and checks the result; returns the tiles resumed. */
static int resume_and_check(const char *name, int took, const char *log_name, int leftovers)
{
    char out[64], json[64], prefix[80];
    snprintf(out, sizeof out, "%s.exr", name);
    snprintf(json, sizeof json, "%s-2.json", name);
    const char *log = ft_path(dir, log_name);
    pid_t master = start_master(log, ft_path(dir, out), ft_path(dir, json), true, "8");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, out)), 0);
    int resumed = resumed_count(log);
    assert_true(resumed >= took);
    assert_true(resumed <= 48);
    assert_int_equal(ft_json_number(ft_path(dir, json), "resumed_tiles"), resumed);
    /* only the missing tiles were rendered (no duplicates, nobody lost) */
    assert_int_equal(ft_json_number(ft_path(dir, json), "grants"), 48 - resumed);
    assert_int_equal(ft_count(log, "left behind by a master that died"), leftovers);
    snprintf(prefix, sizeof prefix, "%s.exr.", name);   /* no .tmp-, no .journal */
    assert_int_equal(ft_count_files(dir, prefix), 0);
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
    return resumed;
}

static void test_resume_after_kill9_at_three_moments(void **state)
{
    (void)state;
    const int moments[] = {1, 20, 36};
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "kill%d", moments[i]);
        int took = render_and_kill(name, moments[i]);
        char log[64];
        snprintf(log, sizeof log, "%s-2.log", name);
        resume_and_check(name, took, log, 2);
        fprintf(stderr, "killed after %d tiles taken, resumed with %d\n", took,
                resumed_count(ft_path(dir, log)));
    }
}

static void test_resume_drops_torn_and_corrupt_tail(void **state)
{
    (void)state;
    int took = render_and_kill("torn", 12);
    const char *jpath = ft_path(dir, "torn.exr.journal");
    /* a flipped byte near the end of the last whole record ... */
    long size = file_size(jpath);
    int fd = open(jpath, O_RDWR);
    assert_true(fd >= 0);
    unsigned char b;
    assert_int_equal(pread(fd, &b, 1, size - 3), 1);
    b ^= 0x41;
    assert_int_equal(pwrite(fd, &b, 1, size - 3), 1);
    /* ... and a torn record after it */
    const char torn[] = "TILE\x05\x00\x00\x00\xff\x0f\x00\x00garbage";
    assert_int_equal(pwrite(fd, torn, sizeof torn - 1, size), (ssize_t)(sizeof torn - 1));
    close(fd);
    const char *log = ft_path(dir, "torn-2.log");
    char json[] = "torn-2.json";
    pid_t master = start_master(log, ft_path(dir, "torn.exr"), ft_path(dir, json), true, "8");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_count(log, "the journal ended in a record with a bad checksum"), 1);
    int resumed = resumed_count(log);
    assert_true(resumed >= took - 1);   /* the corrupted record is rendered again */
    assert_true(resumed < 48);
    assert_int_equal(ft_json_number(ft_path(dir, json), "grants"), 48 - resumed);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "torn.exr")), 0);
    assert_int_equal(ft_count_files(dir, "torn.exr."), 0);
}

static void test_resume_other_job_refused(void **state)
{
    (void)state;
    render_and_kill("other", 5);
    const char *jpath = ft_path(dir, "other.exr.journal");
    long size = file_size(jpath);
    const char *log = ft_path(dir, "other-2.log");
    pid_t master = start_master(log, ft_path(dir, "other.exr"), ft_path(dir, "other-2.json"),
                                true, "16");
    assert_int_equal(ft_wait(master, 60), 2);
    assert_int_equal(ft_count(log, "cannot resume: "), 1);
    assert_int_equal(ft_count(log, "(the scene, a shader or an option changed; remove the "
                                   "journal or render without --resume)"), 1);
    assert_int_equal(file_size(jpath), size);
    assert_int_equal(ft_count(log, "worker local-"), 0);   /* nothing started */
    /* the right options resume it (the refused run already removed the
     * dead master's temporary file; its ipc folder is left for this one) */
    resume_and_check("other", 5, "other-3.log", 1);
}

static void test_resume_without_journal_renders_all(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "fresh.log");
    pid_t master = start_master(log, ft_path(dir, "fresh.exr"), ft_path(dir, "fresh.json"), true,
                                "8");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_count(log, "--resume: no journal "), 1);
    assert_int_equal(ft_json_number(ft_path(dir, "fresh.json"), "grants"), 48);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "fresh.exr")), 0);
    assert_int_equal(ft_count_files(dir, "fresh.exr."), 0);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_resume_after_kill9_at_three_moments, ft_teardown),
        cmocka_unit_test_teardown(test_resume_drops_torn_and_corrupt_tail, ft_teardown),
        cmocka_unit_test_teardown(test_resume_other_job_refused, ft_teardown),
        cmocka_unit_test_teardown(test_resume_without_journal_renders_all, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
