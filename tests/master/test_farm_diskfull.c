/*
 * test_farm_diskfull.c: the output's file system fills up, with real
 * processes on a small tmpfs the test mounts itself (in a private mount
 * namespace, so nothing outlives the test):
 *   - full before the header is written (master with local workers, and
 *     the standalone renderer): exit 1 within seconds (it used to deadlock
 *     in OpenEXR's error callback), the message names the temporary path
 *     and the cause, no output and no temporary file left;
 *   - full in the middle of the render (master and standalone): exit 1,
 *     the master reports its own write error and never blames a worker
 *     (no "invalid tile", no retry), nothing half-written left but the
 *     master's journal; once there is space again (the tmpfs remounted
 *     larger) `--resume` completes the image, equal to the standalone
 *     render;
 *   - the final rename fails (OUT.exr is a folder): exit 1, "cannot
 *     rename", no temporary file left;
 *   - --stats-json on a full disk (the image elsewhere): exit 1, the
 *     image in place, no half-written statistics file.
 * Every process runs under timeout -k and is reaped by PID. Needs root
 * (mount); skipped with a message otherwise.
 */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;
static char mnt[4096];
static bool can_mount;

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_WAVE, 8) != 0) return -1;
    snprintf(mnt, sizeof mnt, "%s/mnt", dir);
    mkdir(mnt, 0755);
    if (geteuid() != 0) {
        fprintf(stderr, "test_farm_diskfull: SKIPPED: needs root to mount a small tmpfs "
                "(run the suite as root, as CI does)\n");
    } else if (unshare(CLONE_NEWNS) != 0 ||
               mount(NULL, "/", NULL, MS_REC | MS_PRIVATE, NULL) != 0) {
        fprintf(stderr, "test_farm_diskfull: SKIPPED: cannot make a private mount namespace: "
                "%s\n", strerror(errno));
    } else {
        can_mount = true;
    }
    return 0;
}

static int group_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    if (can_mount) umount2(mnt, MNT_DETACH);
    return ft_group_teardown(state);
}

static int teardown(void **state)
{
    (void)state;
    ft_stop_all();
    if (can_mount) umount2(mnt, MNT_DETACH);
    return 0;
}

/* A fresh tmpfs of `kib` KiB on mnt, with `fill_kib` KiB of it taken. */
static void mount_small(int kib, int fill_kib)
{
    if (!can_mount) skip();
    char opt[64];
    snprintf(opt, sizeof opt, "size=%dk,mode=0755", kib);
    int rc = mount("tmpfs", mnt, "tmpfs", 0, opt);
    if (rc != 0 && (errno == EPERM || errno == EACCES)) {   /* a container without the right */
        fprintf(stderr, "test_farm_diskfull: SKIPPED: cannot mount a tmpfs here: %s\n",
                strerror(errno));
        can_mount = false;
        skip();
    }
    assert_int_equal(rc, 0);
    if (fill_kib <= 0) return;
    int fd = open(ft_path(mnt, "filler"), O_WRONLY | O_CREAT, 0644);
    assert_true(fd >= 0);
    char block[1024];
    memset(block, 'x', sizeof block);
    for (int i = 0; i < fill_kib; i++)
        if (write(fd, block, sizeof block) != (ssize_t)sizeof block) break;   /* full: fine */
    close(fd);
}

/* Exit status of the command under timeout -k 5 60 (124: it hung). */
static int run_bounded(const char *log, const char *const *args)
{
    const char *argv[40] = {"/usr/bin/timeout", "-k", "5", "60"};
    int n = 4;
    for (int i = 0; args[i] && n < 39; i++) argv[n++] = args[i];
    argv[n] = NULL;
    pid_t pid = ft_spawn(log, argv);
    return ft_wait(pid, 90);
}

static int master(const char *log, const char *out, bool resume)
{
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--tile", "8",
                          "--local-workers", "2", resume ? "--resume" : NULL, NULL};
    setenv("TMPDIR", dir, 1);   /* the private ipc folder: counted below */
    int rc = run_bounded(log, argv);
    unsetenv("TMPDIR");
    return rc;
}

static int standalone(const char *log, const char *out)
{
    const char *argv[] = {ft_worker, "--standalone", ft_path(dir, "scene.rib"), "-o", out,
                          "--tile", "8", "--threads", "2", NULL};
    return run_bounded(log, argv);
}

/* Nothing named out.exr* is left on the tmpfs, nor a private ipc folder. */
static void assert_nothing_left(void)
{
    assert_int_equal(ft_count_files(mnt, "out.exr"), 0);
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
}

static void test_diskfull_at_header_master(void **state)
{
    (void)state;
    mount_small(16, 64);
    const char *log = ft_path(dir, "hdr-master.log");
    assert_int_equal(master(log, ft_path(mnt, "out.exr"), false), 1);
    assert_int_equal(ft_count(log, "cannot write EXR header to "), 1);
    assert_int_equal(ft_count(log, "/mnt/out.exr.tmp-"), 1);
    assert_int_equal(ft_count(log, "No space left on device"), 1);
    assert_nothing_left();
}

static void test_diskfull_at_header_standalone(void **state)
{
    (void)state;
    mount_small(16, 64);
    const char *log = ft_path(dir, "hdr-sa.log");
    assert_int_equal(standalone(log, ft_path(mnt, "out.exr")), 1);
    assert_int_equal(ft_count(log, "cannot write EXR header to "), 1);
    assert_int_equal(ft_count(log, "No space left on device"), 1);
    assert_nothing_left();
}

/* The image is about 25 KB: 16 KiB fills up after some tiles. */
static void test_diskfull_mid_render_master(void **state)
{
    (void)state;
    mount_small(16, 0);
    const char *log = ft_path(dir, "mid-master.log");
    assert_int_equal(master(log, ft_path(mnt, "out.exr"), false), 1);
    assert_int_equal(ft_count(log, "render failed: cannot write tile ("), 1);
    assert_int_equal(ft_count(log, "No space left on device"), 1);
    assert_int_equal(ft_count(log, "invalid tile"), 0);
    assert_int_equal(ft_count(log, "trying again"), 0);
    assert_int_equal(ft_count(log, " tiles kept in "), 1);
    assert_int_equal(ft_count_files(mnt, "out.exr.tmp"), 0);
    assert_int_equal(ft_count_files(mnt, "out.exr"), 1);   /* the journal */
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
    /* space again: resume */
    assert_int_equal(mount("tmpfs", mnt, "tmpfs", MS_REMOUNT, "size=256k"), 0);
    const char *log2 = ft_path(dir, "mid-master-resume.log");
    assert_int_equal(master(log2, ft_path(mnt, "out.exr"), true), 0);
    assert_int_equal(ft_count(log2, "resuming: "), 1);
    assert_int_equal(ft_count(log2, "resuming: 0 of"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(mnt, "out.exr")), 0);
    assert_int_equal(ft_count_files(mnt, "out.exr"), 1);     /* no journal, no temporary */
}

static void test_diskfull_mid_render_standalone(void **state)
{
    (void)state;
    mount_small(16, 0);
    const char *log = ft_path(dir, "mid-sa.log");
    assert_int_equal(standalone(log, ft_path(mnt, "out.exr")), 1);
    assert_int_equal(ft_count(log, "cannot write tile ("), 1);
    assert_int_equal(ft_count(log, "No space left on device"), 1);
    assert_nothing_left();
}

static void test_rename_fails_master(void **state)
{
    (void)state;
    mount_small(256, 0);
    assert_int_equal(mkdir(ft_path(mnt, "out.exr"), 0755), 0);   /* in the way */
    const char *log = ft_path(dir, "rename.log");
    assert_int_equal(master(log, ft_path(mnt, "out.exr"), false), 1);
    assert_int_equal(ft_count(log, "cannot rename "), 1);
    assert_int_equal(ft_count_files(mnt, "out.exr.tmp"), 0);
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
    assert_int_equal(rmdir(ft_path(mnt, "out.exr")), 0);   /* still an empty folder */
}

static void test_stats_json_on_full_disk(void **state)
{
    (void)state;
    mount_small(16, 64);
    const char *log = ft_path(dir, "stats.log"), *out = ft_path(dir, "stats.exr");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--tile", "8",
                          "--local-workers", "2", "--stats-json", ft_path(mnt, "stats.json"),
                          NULL};
    assert_int_equal(run_bounded(log, argv), 1);
    assert_int_equal(ft_count(log, "/mnt/stats.json: No space left on device"), 1);
    assert_int_equal(ft_count_files(mnt, "stats.json"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), out), 0);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_diskfull_at_header_master, teardown),
        cmocka_unit_test_teardown(test_diskfull_at_header_standalone, teardown),
        cmocka_unit_test_teardown(test_diskfull_mid_render_master, teardown),
        cmocka_unit_test_teardown(test_diskfull_mid_render_standalone, teardown),
        cmocka_unit_test_teardown(test_rename_fails_master, teardown),
        cmocka_unit_test_teardown(test_stats_json_on_full_disk, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
