/*
 * test_deploy.c: deploy/ as far as this machine allows (docs/cluster.md,
 * "What the tests exercise"):
 *   - deploy/ssh/farm.sh renders for real on two "hosts" through stand-in
 *     ssh and scp (deploy/fake-ssh, fake-scp: run here what ssh would run
 *     there), with CURVE keys it makes and copies; the image equals
 *     --standalone; every worker it started is stopped, the copied secret
 *     keys removed; Ctrl-C mid-render stops the master and every worker,
 *     exit 130, no image;
 *   - deploy/slurm/aafarm.sbatch renders for real with stand-in srun and
 *     scontrol (two tasks for two nodes); equal image, the job's keys removed;
 *   - deploy/systemd: install.sh into a scratch root, and
 *     systemd-analyze verify of the template unit;
 *   - what cannot run here (containers, Kubernetes): shellcheck of every
 *     script, check_manifests.py (YAML parsed and cross-checked).
 * A check whose tool is missing (shellcheck, python3-yaml, systemd-analyze)
 * is skipped with a message.
 *
 * Arguments: MASTER WORKER SOURCE_DIR (the repository root).
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
static const char *src;
static char bindir[4096];

static int group_setup(void **state)
{
    (void)state;
    dir = ft_tempdir();
    ft_write_scene(dir, FT_SCENE_WAVE);
    char *real = realpath(ft_master, NULL);
    if (!real) return -1;
    snprintf(bindir, sizeof bindir, "%s", real);
    free(real);
    char *slash = strrchr(bindir, '/');
    if (!slash) return -1;
    *slash = '\0';
    return ft_standalone(dir, 16) == 0 ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    ft_rmtree(dir);
    free(dir);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ft_stop_all();
    return 0;
}

/* Runs a shell command line bounded by timeout -k; output to dir/log. */
static int sh(const char *log, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int sh(const char *log, const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    char path[4300], wrapped[8400];
    snprintf(path, sizeof path, "%s/%s", dir, log);
    snprintf(wrapped, sizeof wrapped, "exec timeout -k 2 120 /bin/sh -c '%s'", cmd);
    const char *argv[] = {"/bin/sh", "-c", wrapped, NULL};
    return ft_wait(ft_spawn(path, argv), 130);
}

static bool have(const char *tool)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "command -v %s", tool);
    return sh("which.log", "%s", cmd) == 0;
}

static void test_ssh_farm_renders_and_stops_its_workers(void **state)
{
    (void)state;
    FILE *fp = fopen(ft_path(dir, "hosts"), "w");
    assert_non_null(fp);
    fputs("# two hosts, the first with one thread\nhostA 1\nhostB\n", fp);
    fclose(fp);
    int port = ft_free_port();
    int rc = sh("ssh.log",
                "cd %s && AAFARM_BIN=%s AAFARM_REMOTE_BIN=%s AAFARM_KEYS=%s/keys AAFARM_RUN=%s/run "
                "AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 AAFARM_MASTER_HOST=127.0.0.1 "
                "AAFARM_WORKER_OPTS=\"--tile-delay 150\" "   /* both join before the end */
                "SSH=%s/tests/master/deploy/fake-ssh SCP=%s/tests/master/deploy/fake-scp "
                "%s/deploy/ssh/farm.sh hosts scene.rib -o ssh.exr --tile 16",
                dir, bindir, bindir, dir, dir, port, src, src, src);
    const char *log = ft_path(dir, "ssh.log");
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(log));
    assert_int_equal(rc, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "ssh.exr")), 0);
    assert_int_equal(ft_count(log, "CURVE on: 2 worker keys allowed"), 1);
    assert_int_equal(ft_count(log, "worker hostA joined"), 1);
    assert_int_equal(ft_count(log, "worker hostB joined"), 1);
    /* both stopped, by the pids it printed; the copied secrets are gone */
    char *text = ft_read(log);
    for (const char *h = "hostA", *p = text; h; h = strcmp(h, "hostA") == 0 ? "hostB" : NULL) {
        char needle[64];
        snprintf(needle, sizeof needle, "%s: stopped worker ", h);
        const char *at = strstr(p, needle);
        assert_non_null(at);
        long pid = atol(at + strlen(needle));
        assert_true(pid > 1);
        for (int i = 0; i < 100 && kill((pid_t)pid, 0) == 0; i++) ft_sleep_ms(50);
        assert_int_equal(kill((pid_t)pid, 0), -1);
    }
    free(text);
    struct stat st;
    assert_int_equal(stat(ft_path(dir, "run/hostA/keys"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run/hostB/worker.pid"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "keys/master.key_secret"), &st), 0);
    assert_int_equal(st.st_mode & 0777, 0600);
    /* a bad hosts file is named with its line */
    fp = fopen(ft_path(dir, "badhosts"), "w");
    fputs("hostA\nhostB many threads\n", fp);
    fclose(fp);
    assert_int_equal(sh("badhosts.log", "cd %s && %s/deploy/ssh/farm.sh badhosts scene.rib -o x.exr",
                        dir, src), 2);
    assert_int_equal(ft_count(ft_path(dir, "badhosts.log"), "badhosts:2: expected"), 1);
}

/* Ctrl-C (SIGINT to the script) mid-render: the master is stopped, every
 * worker it started is stopped, the copied secrets removed, exit 130, no
 * image. */
static void test_ssh_farm_ctrl_c_stops_everything(void **state)
{
    (void)state;
    FILE *fp = fopen(ft_path(dir, "hosts2"), "w");
    assert_non_null(fp);
    fputs("hostC 1\nhostD 1\n", fp);
    fclose(fp);
    char cmd[20000], log[4200];
    snprintf(log, sizeof log, "%s/ctrlc.log", dir);
    snprintf(cmd, sizeof cmd,
             "cd %s && AAFARM_BIN=%s AAFARM_REMOTE_BIN=%s AAFARM_KEYS=%s/keys2 AAFARM_RUN=%s/run2 "
             "AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 AAFARM_MASTER_HOST=127.0.0.1 "
             "AAFARM_WORKER_OPTS=\"--tile-delay 300\" SSH=%s/tests/master/deploy/fake-ssh "
             "SCP=%s/tests/master/deploy/fake-scp exec timeout -k 2 120 %s/deploy/ssh/farm.sh "
             "hosts2 scene.rib -o ctrlc.exr --tile 16",
             dir, bindir, bindir, dir, dir, ft_free_port(), src, src, src);
    /* timeout runs farm.sh in its own process: signal that one */
    const char *argv[] = {"/bin/sh", "-c", cmd, NULL};
    pid_t sh_pid = ft_spawn(log, argv);   /* exec: sh becomes timeout */
    assert_true(ft_wait_for(log, "worker hostD joined", 1, 60));
    assert_true(ft_wait_for(log, " tiles (", 1, 60));   /* rendering */
    assert_int_equal(sh("pgrep.log", "pgrep -P %d", (int)sh_pid), 0);
    char *kids = ft_read(ft_path(dir, "pgrep.log"));
    long script = atol(kids);
    free(kids);
    assert_true(script > 1);
    kill((pid_t)script, SIGINT);
    assert_int_equal(ft_wait(sh_pid, 60), 130);
    assert_int_equal(ft_count(log, "hostC: stopped worker "), 1);
    assert_int_equal(ft_count(log, "hostD: stopped worker "), 1);
    assert_true(ft_count(log, "ctrlc.exr not written") >= 1);
    struct stat st;
    assert_int_equal(stat(ft_path(dir, "ctrlc.exr"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run2/hostC/keys"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run2/hostD/keys"), &st), -1);
    char *text = ft_read(log);
    const char *at = strstr(text, "hostC: stopped worker ");
    long pid = at ? atol(at + strlen("hostC: stopped worker ")) : 0;
    free(text);
    assert_true(pid > 1);
    for (int i = 0; i < 100 && kill((pid_t)pid, 0) == 0; i++) ft_sleep_ms(50);
    assert_int_equal(kill((pid_t)pid, 0), -1);
}

static void test_slurm_script_with_stand_in_srun(void **state)
{
    (void)state;
    assert_int_equal(mkdir(ft_path(dir, "slurmbin"), 0755), 0);
    assert_int_equal(sh("links.log", "ln -s %s/tests/master/deploy/fake-srun %s/slurmbin/srun && "
                        "ln -s %s/tests/master/deploy/fake-scontrol %s/slurmbin/scontrol",
                        src, dir, src, dir), 0);
    int port = ft_free_port();
    int rc = sh("slurm.log",
                "cd %s && PATH=%s/slurmbin:$PATH SLURM_JOB_ID=4242 SLURM_JOB_NUM_NODES=2 "
                "SLURM_JOB_NODELIST=127.0.0.1,127.0.0.1 SLURM_SUBMIT_DIR=%s AAFARM_BIN=%s "
                "AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 "
                "AAFARM_WORKER_OPTS=\"--threads 1 --tile-delay 150\" "   /* both workers join */
                "FAKE_SRUN_LOG=%s/srun.log bash %s/deploy/slurm/aafarm.sbatch scene.rib slurm.exr "
                "--tile 16", dir, dir, dir, bindir, port, dir, src);
    const char *log = ft_path(dir, "slurm.log");
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(log));
    assert_int_equal(rc, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "slurm.exr")), 0);
    assert_int_equal(ft_count(ft_path(dir, "srun.log"), "step: 1 task(s) on 1 node(s): "), 1);
    assert_int_equal(ft_count(ft_path(dir, "srun.log"), "step: 2 task(s) on 2 node(s): "), 1);
    assert_int_equal(ft_count(log, "connected to master"), 2);
    assert_int_equal(ft_count(log, "stopped ("), 2);   /* both workers ended by SIGTERM */
    assert_int_equal(ft_count(log, "master exited with status 0"), 1);
    assert_int_equal(ft_count_files(dir, ".aafarm-keys-4242"), 0);
    /* outside a job it says so */
    assert_int_equal(sh("noslurm.log", "cd %s && env -u SLURM_JOB_ID bash %s/deploy/slurm/aafarm.sbatch "
                        "scene.rib x.exr", dir, src), 1);
    assert_true(ft_count(ft_path(dir, "noslurm.log"), "submit with sbatch") >= 1);
}

static void test_systemd_unit_and_install(void **state)
{
    (void)state;
    char key[4096];
    snprintf(key, sizeof key, "%s/m", dir);
    assert_int_equal(sh("mk.log", "%s/aafarm-keygen %s", bindir, key), 0);
    assert_int_equal(sh("install.log", "AAFARM_ROOT=%s/root %s/deploy/systemd/install.sh farm1 "
                        "tcp://render-master:5555 %s.key %s", dir, src, key, bindir), 0);
    char *conf = ft_read(ft_path(dir, "root/etc/aafarm/farm1.conf"));
    assert_non_null(strstr(conf, "AAFARM_MASTER=tcp://render-master:5555\n"));
    free(conf);
    struct stat st;
    assert_int_equal(stat(ft_path(dir, "root/etc/aafarm/keys/farm1.key_secret"), &st), 0);
    assert_int_equal(st.st_mode & 0777, 0600);
    assert_int_equal(stat(ft_path(dir, "root/etc/aafarm/keys/master.key"), &st), 0);
    assert_int_equal(stat(ft_path(dir, "root/etc/systemd/system/aafarm-worker@.service"), &st), 0);
    if (!have("systemd-analyze")) {
        fprintf(stderr, "systemd-analyze not found: the unit is not verified\n");
        return;
    }
    /* verify an instance; the one complaint allowed is that the program is
     * not installed on this machine */
    assert_int_equal(sh("links2.log", "mkdir -p %s/unit && cp %s/deploy/systemd/aafarm-worker@.service "
                        "%s/unit/ && ln -s aafarm-worker@.service %s/unit/aafarm-worker@farm1.service",
                        dir, src, dir, dir), 0);
    sh("verify.log", "cd %s/unit && systemd-analyze verify --man=no ./aafarm-worker@farm1.service 2>&1 "
       "| grep -v \"/usr/local/bin/aafarm-worker is not executable\" | grep . && exit 1; exit 0", dir);
    assert_int_equal(ft_count(ft_path(dir, "verify.log"), "aafarm-worker@farm1.service"), 0);
}

static void test_scripts_and_manifests_checked(void **state)
{
    (void)state;
    if (have("shellcheck")) {
        int rc = sh("shellcheck.log", "cd %s && shellcheck deploy/ssh/*.sh deploy/slurm/aafarm.sbatch "
                    "deploy/systemd/install.sh deploy/container/make-keys.sh "
                    "tests/master/deploy/fake-*", src);
        if (rc != 0) fprintf(stderr, "%s\n", ft_read(ft_path(dir, "shellcheck.log")));
        assert_int_equal(rc, 0);
    } else {
        fprintf(stderr, "shellcheck not found (Debian package shellcheck): scripts not linted\n");
    }
    if (sh("yaml.log", "python3 -c \"import yaml\"") != 0) {
        fprintf(stderr, "python3-yaml not found: manifests not checked\n");
        return;
    }
    int rc = sh("manifests.log", "python3 %s/tests/master/deploy/check_manifests.py %s", src, src);
    char *text = ft_read(ft_path(dir, "manifests.log"));
    fprintf(stderr, "%s", text);
    free(text);
    assert_int_equal(rc, 0);
}

int main(int argc, char **argv)
{
    if (argc < 4 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_deploy MASTER WORKER SOURCE_DIR\n");
        return 2;
    }
    src = argv[3];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_ssh_farm_renders_and_stops_its_workers, teardown),
        cmocka_unit_test_teardown(test_ssh_farm_ctrl_c_stops_everything, teardown),
        cmocka_unit_test_teardown(test_slurm_script_with_stand_in_srun, teardown),
        cmocka_unit_test_teardown(test_systemd_unit_and_install, teardown),
        cmocka_unit_test_teardown(test_scripts_and_manifests_checked, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
