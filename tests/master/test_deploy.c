/*
 * test_deploy.c: deploy/ as far as this machine allows (docs/cluster.md,
 * "What the tests exercise"):
 *   - deploy/ssh/farm.sh renders for real on two "hosts" through stand-in
 *     ssh and scp (deploy/fake-ssh, fake-scp: run here what ssh would run
 *     there), with CURVE keys it makes and copies; the image equals
 *     --standalone; every worker it started is stopped, the copied secret
 *     keys removed; Ctrl-C mid-render stops the master and every worker,
 *     exit 130, no image;
 *   - the same over a REAL OpenSSH server the test starts: /usr/sbin/sshd
 *     -D on 127.0.0.1:PORT with its own host key, client key and
 *     authorized_keys in the test's folder (ssh -F a config of its own:
 *     two host aliases for 127.0.0.1, StrictHostKeyChecking no, known_hosts
 *     in the folder), bounded by timeout -k and stopped by PID: farm.sh
 *     --master-host 127.0.0.1 renders an image equal to --standalone (so ssh
 *     returned while its worker ran), stops the very PIDs it started, and no
 *     aafarm-worker of those hosts is left (/proc scanned); an aafarm-worker
 *     missing on the hosts and a master host they cannot resolve are errors
 *     naming the host (exit 1, no master started, keys removed). Skipped with
 *     a one-line reason where sshd cannot run (not installed; not root and
 *     no /run/sshd);
 *   - deploy/slurm/aafarm.sbatch renders for real with stand-in srun,
 *     scontrol and scancel (two tasks for two nodes; scancel --signal=TERM
 *     fails as without a controller, so the script falls back to SIGTERM
 *     to srun); equal image, the job's keys removed (a real Slurm:
 *     test_slurm);
 *   - deploy/systemd: install.sh into a scratch root (run again, it keeps
 *     the host's NAME.conf and writes a differing default beside it as
 *     NAME.conf.new), the unit's store of job files in its StateDirectory,
 *     and systemd-analyze verify of the template unit;
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
#include <dirent.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

static char *dir;
static const char *src;
static char bindir[4096];

static int group_setup(void **state)
{
    (void)state;
    if (!ft_program_dir(bindir, sizeof bindir)) return -1;
    return ft_group_begin(&dir, FT_SCENE_WAVE, 16);
}

/* Runs a shell command line bounded by timeout -k; output to dir/log. */
static int sh(const char *log, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int sh(const char *log, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = ft_shv(dir, log, fmt, ap);
    va_end(ap);
    return rc;
}

static bool have(const char *tool)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "command -v %s", tool);
    return sh("which.log", "%s", cmd) == 0;
}

/* The PID farm.sh says it stopped on HOST in the log: "HOST: stopped
 * worker PID", or "HOST: killed worker PID" where the worker outlived
 * SIGTERM's grace (a sanitized worker's exit can); 0 when it says neither
 * or says it more than once. The caller then checks that PID is gone. */
static long stopped_pid(const char *log, const char *host)
{
    char stopped[64], killed[64];
    snprintf(stopped, sizeof stopped, "%s: stopped worker ", host);
    snprintf(killed, sizeof killed, "%s: killed worker ", host);
    if (ft_count(log, stopped) + ft_count(log, killed) != 1) return 0;
    char *text = ft_read(log);
    const char *at = strstr(text, stopped);
    const char *k = strstr(text, killed);
    long pid = at ? atol(at + strlen(stopped)) : k ? atol(k + strlen(killed)) : 0;
    free(text);
    return pid;
}

/* Waits up to 5 s for process pid to be gone; fails if it is not. */
static void assert_gone(long pid)
{
    for (int i = 0; i < 100 && kill((pid_t)pid, 0) == 0; i++) ft_sleep_ms(50);
    assert_int_equal(kill((pid_t)pid, 0), -1);
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
                "AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 AAFARM_MASTER_HOST=127.0.0.1 AAFARM_STOP_GRACE=10 "
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
    for (const char *h = "hostA"; h; h = strcmp(h, "hostA") == 0 ? "hostB" : NULL) {
        long pid = stopped_pid(log, h);
        assert_true(pid > 1);
        assert_gone(pid);
    }
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
             "AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 AAFARM_MASTER_HOST=127.0.0.1 AAFARM_STOP_GRACE=10 "
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
    long pid_c = stopped_pid(log, "hostC"), pid_d = stopped_pid(log, "hostD");
    assert_true(pid_c > 1);
    assert_true(pid_d > 1);
    assert_true(ft_count(log, "ctrlc.exr not written") >= 1);
    struct stat st;
    assert_int_equal(stat(ft_path(dir, "ctrlc.exr"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run2/hostC/keys"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run2/hostD/keys"), &st), -1);
    assert_gone(pid_c);
    assert_gone(pid_d);
}

/* ---- a real OpenSSH server on loopback ---- */

static pid_t sshd_pid;            /* timeout -k ... sshd -D: stopped by SIGTERM */
static bool made_privsep_dir;     /* /run/sshd made here (removed again) */
static int sshd_port;

static void stop_sshd(void)
{
    if (sshd_pid > 0) {
        kill(sshd_pid, SIGTERM);   /* timeout passes it on to sshd */
        if (ft_wait(sshd_pid, 10) == -1) kill(sshd_pid, SIGKILL);
        sshd_pid = 0;
    }
    char *text = ft_read(ft_path(dir, "sshd/sshd.pid"));
    long pid = atol(text);
    free(text);
    if (pid > 1 && kill((pid_t)pid, 0) == 0) kill((pid_t)pid, SIGKILL);
    if (made_privsep_dir) rmdir("/run/sshd");
    made_privsep_dir = false;
}

/* Starts sshd; false with a one-line reason where it cannot run here. */
static bool start_sshd(char *why, size_t whysz)
{
    if (access("/usr/sbin/sshd", X_OK) != 0 || !have("ssh-keygen") || !have("ssh") ||
        !have("scp")) {
        snprintf(why, whysz, "no /usr/sbin/sshd, ssh, scp or ssh-keygen (Debian packages "
                 "openssh-server, openssh-client: deploy/install-deps.sh)");
        return false;
    }
    struct stat st;
    if (stat("/run/sshd", &st) != 0) {   /* sshd's privilege separation directory */
        if (geteuid() != 0) {
            snprintf(why, whysz, "not root and no /run/sshd (sshd's privilege separation "
                     "directory) to run sshd with");
            return false;
        }
        assert_int_equal(mkdir("/run/sshd", 0755), 0);
        made_privsep_dir = true;
    }
    const char *d = ft_path(dir, "sshd");
    char sd[1024];
    snprintf(sd, sizeof sd, "%s", d);
    assert_int_equal(mkdir(sd, 0700), 0);
    assert_int_equal(sh("keys.log", "cd %s && ssh-keygen -q -t ed25519 -N \"\" -f host_key && "
                        "ssh-keygen -q -t ed25519 -N \"\" -f id && cp id.pub authorized_keys",
                        sd), 0);
    sshd_port = ft_free_port();
    char text[16384];
    snprintf(text, sizeof text,
             "ListenAddress 127.0.0.1:%d\nHostKey %s/host_key\n"
             "AuthorizedKeysFile %s/authorized_keys\nPidFile %s/sshd.pid\n"
             "UsePAM no\nStrictModes no\nPasswordAuthentication no\n"
             "KbdInteractiveAuthentication no\nPubkeyAuthentication yes\n"
             "PermitRootLogin prohibit-password\nSubsystem sftp internal-sftp\n"
             "LogLevel VERBOSE\n", sshd_port, sd, sd, sd);
    FILE *f = fopen(ft_path(sd, "sshd_config"), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    /* the client side: two host names for this sshd */
    struct passwd *pw = getpwuid(geteuid());
    assert_non_null(pw);
    snprintf(text, sizeof text,
             "Host realA realB\n  HostName 127.0.0.1\n  Port %d\n  User %s\n"
             "  IdentityFile %s/id\n  IdentitiesOnly yes\n  BatchMode yes\n"
             "  StrictHostKeyChecking no\n  UserKnownHostsFile %s/known_hosts\n"
             "  LogLevel ERROR\n  ConnectTimeout 10\n", sshd_port, pw->pw_name, sd, sd);
    f = fopen(ft_path(sd, "ssh_config"), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    if (sh("sshd-t.log", "/usr/sbin/sshd -t -f %s/sshd_config", sd) != 0) {
        char *msg = ft_read(ft_path(dir, "sshd-t.log"));
        char *nl = strchr(msg, '\n');
        if (nl) *nl = '\0';
        snprintf(why, whysz, "sshd -t refuses its configuration: %s", msg);
        free(msg);
        return false;
    }
    char cfg[1100];
    snprintf(cfg, sizeof cfg, "%s/sshd_config", sd);
    const char *argv[] = {"/usr/bin/timeout", "-k", "2", "240", "/usr/sbin/sshd", "-D", "-e", "-f", cfg,
                          NULL};
    sshd_pid = ft_spawn(ft_path(dir, "sshd.log"), argv);
    if (!ft_wait_for(ft_path(dir, "sshd.log"), "Server listening on 127.0.0.1", 1, 10)) {
        fprintf(stderr, "%s\n", ft_read(ft_path(dir, "sshd.log")));
        fail_msg("sshd did not start listening");
    }
    return true;
}

/* Processes whose command line has aafarm-worker and "--name NAME"; with
 * kill_them, each is sent SIGKILL (by its PID). */
static int workers_named(const char *name, bool kill_them)
{
    DIR *d = opendir("/proc");
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
        char path[300], buf[4096];
        snprintf(path, sizeof path, "/proc/%s/cmdline", e->d_name);
        FILE *f = fopen(path, "r");
        if (!f) continue;
        size_t len = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
        buf[len] = '\0';
        /* ours: a worker of this test's hosts (its run folder is in the
         * arguments), not one of another test_deploy running beside it */
        bool worker = false, named = false, ours = false;
        for (size_t i = 0; i < len; i += strlen(buf + i) + 1) {
            if (strstr(buf + i, "aafarm-worker") && !strstr(buf + i, "farm.sh")) worker = true;
            if (strstr(buf + i, dir)) ours = true;
            if (strcmp(buf + i, "--name") == 0 && i + strlen(buf + i) + 1 < len &&
                strcmp(buf + i + strlen(buf + i) + 1, name) == 0)
                named = true;
        }
        if (worker && named && ours) {
            n++;
            if (kill_them) kill((pid_t)atol(e->d_name), SIGKILL);
        }
    }
    closedir(d);
    return n;
}

/* The number after "needle" in the file; 0 if absent. */
static long number_after(const char *log, const char *needle)
{
    char *text = ft_read(log);
    const char *at = strstr(text, needle);
    long v = at ? atol(at + strlen(needle)) : 0;
    free(text);
    return v;
}

static int teardown_sshd(void **state)
{
    (void)state;
    /* a worker a failed assertion left: by the PID farm.sh recorded */
    static const char *const pids[] = {"run3/realA/worker.pid", "run3/realB/worker.pid"};
    for (int i = 0; i < 2; i++) {
        char *text = ft_read(ft_path(dir, pids[i]));
        long pid = atol(text);
        free(text);
        if (pid > 1) kill((pid_t)pid, SIGKILL);
    }
    /* and one whose recorded PID was not its own (the bug this test is for) */
    workers_named("realA", true);
    workers_named("realB", true);
    ft_stop_all();
    stop_sshd();
    return 0;
}

/* Runs farm.sh over the real sshd (hosts file hosts3, the wave scene into
 * OUT); output in dir/LOG; its exit status. */
static int real_farm(const char *log, const char *remote_bin, const char *master_host,
                     const char *worker_opts, const char *out)
{
    return sh(log,
              "cd %s && AAFARM_BIN=%s AAFARM_KEYS=%s/keys3 AAFARM_RUN=%s/run3 AAFARM_PORT=%d "
              "AAFARM_BIND_HOST=127.0.0.1 AAFARM_STOP_GRACE=10 SSH=\"ssh -F %s/sshd/ssh_config\" "
              "SCP=\"scp -q -F %s/sshd/ssh_config\" AAFARM_REMOTE_BIN=%s "
              "AAFARM_WORKER_OPTS=\"%s\" %s/deploy/ssh/farm.sh --master-host %s hosts3 "
              "scene.rib -o %s --tile 16",
              dir, bindir, dir, dir, ft_free_port(), dir, dir, remote_bin, worker_opts, src,
              master_host, out);
}

static void test_ssh_farm_over_a_real_sshd(void **state)
{
    (void)state;
    char why[512];
    if (!start_sshd(why, sizeof why)) {
        fprintf(stderr, "real sshd test skipped: %s\n", why);
        skip();
    }
    FILE *fp = fopen(ft_path(dir, "hosts3"), "w");
    assert_non_null(fp);
    fputs("realA 1\nrealB\n", fp);
    fclose(fp);
    /* --tile-delay: both workers join before the end (400 ms a tile: a
     * worker's ssh start under a loaded CI machine took over the 1.8 s
     * that one worker needed at 150 ms) */
    int rc = real_farm("real.log", bindir, "127.0.0.1", "--tile-delay 400", "real.exr");
    const char *log = ft_path(dir, "real.log");
    if (rc != 0) fprintf(stderr, "%s\n", ft_read(log));
    assert_int_equal(rc, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "real.exr")), 0);
    assert_int_equal(ft_count(log, "worker realA joined"), 1);
    assert_int_equal(ft_count(log, "worker realB joined"), 1);
    static const char *const hosts[] = {"realA", "realB"};
    for (int h = 0; h < 2; h++) {
        char started[64];
        snprintf(started, sizeof started, "%s: worker ", hosts[h]);
        long pid = number_after(log, started);
        assert_true(pid > 1);
        assert_int_equal(stopped_pid(log, hosts[h]), pid);   /* the PID it started */
        assert_gone(pid);
        assert_int_equal(workers_named(hosts[h], false), 0);   /* nothing left behind */
    }
    struct stat st;
    assert_int_equal(stat(ft_path(dir, "run3/realA/keys"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "run3/realB/worker.pid"), &st), -1);

    /* aafarm-worker missing on the hosts: named, nothing renders */
    rc = real_farm("missing.log", ft_path(dir, "nowhere"), "127.0.0.1", "", "missing.exr");
    const char *mlog = ft_path(dir, "missing.log");
    assert_int_equal(rc, 1);
    char needle[512];
    snprintf(needle, sizeof needle, "farm.sh: realA: %s/nowhere/aafarm-worker is not there or "
             "not executable", dir);
    assert_int_equal(ft_count(mlog, needle), 1);
    assert_int_equal(ft_count(mlog, "not rendering: fix realA"), 1);
    assert_int_equal(ft_count(mlog, "listening on"), 0);   /* no master started */
    assert_int_equal(stat(ft_path(dir, "run3/realA/keys"), &st), -1);
    assert_int_equal(stat(ft_path(dir, "missing.exr"), &st), -1);

    /* a master host the hosts cannot resolve: named before anything starts */
    rc = real_farm("unresolved.log", bindir, "no-such-host.invalid", "", "unresolved.exr");
    assert_int_equal(rc, 1);
    assert_int_equal(ft_count(ft_path(dir, "unresolved.log"),
                              "farm.sh: realA: cannot resolve the master host "
                              "'no-such-host.invalid' there"), 1);
    assert_int_equal(ft_count(ft_path(dir, "unresolved.log"), "worker"), 0);
}

static void test_slurm_script_with_stand_in_srun(void **state)
{
    (void)state;
    assert_int_equal(mkdir(ft_path(dir, "slurmbin"), 0755), 0);
    assert_int_equal(sh("links.log", "ln -s %s/tests/master/deploy/fake-srun %s/slurmbin/srun && "
                        "ln -s %s/tests/master/deploy/fake-scontrol %s/slurmbin/scontrol && "
                        "ln -s %s/tests/master/deploy/fake-scancel %s/slurmbin/scancel",
                        src, dir, src, dir, src, dir), 0);
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
    assert_int_equal(ft_count(ft_path(dir, "srun.log"), "scancel: --signal=TERM 4242"), 1);
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
    /* run again: the host's options are kept; a different default goes
     * beside them as .conf.new, said once; the same default adds nothing */
    FILE *fp = fopen(ft_path(dir, "root/etc/aafarm/farm1.conf"), "w");
    assert_non_null(fp);
    fputs("AAFARM_MASTER=tcp://render-master:5555\nAAFARM_WORKER_OPTS=--threads 8\n", fp);
    fclose(fp);
    assert_int_equal(sh("install2.log", "AAFARM_ROOT=%s/root %s/deploy/systemd/install.sh farm1 "
                        "tcp://render-master2:5555 %s.key %s", dir, src, key, bindir), 0);
    conf = ft_read(ft_path(dir, "root/etc/aafarm/farm1.conf"));
    assert_string_equal(conf, "AAFARM_MASTER=tcp://render-master:5555\nAAFARM_WORKER_OPTS=--threads 8\n");
    free(conf);
    conf = ft_read(ft_path(dir, "root/etc/aafarm/farm1.conf.new"));
    assert_string_equal(conf, "AAFARM_MASTER=tcp://render-master2:5555\nAAFARM_WORKER_OPTS=\n");
    free(conf);
    char said[8400];
    snprintf(said, sizeof said, "install.sh: kept your %s/root/etc/aafarm/farm1.conf; the new default "
             "(AAFARM_MASTER=tcp://render-master2:5555) is in %s/root/etc/aafarm/farm1.conf.new", dir, dir);
    assert_int_equal(ft_count(ft_path(dir, "install2.log"), said), 1);
    assert_int_equal(unlink(ft_path(dir, "root/etc/aafarm/farm1.conf.new")), 0);
    assert_int_equal(sh("install3.log", "AAFARM_ROOT=%s/root %s/deploy/systemd/install.sh farm2 "
                        "tcp://render-master:5555 %s.key %s && AAFARM_ROOT=%s/root %s/deploy/systemd/"
                        "install.sh farm2 tcp://render-master:5555 %s.key %s",
                        dir, src, key, bindir, dir, src, key, bindir), 0);
    assert_int_equal(ft_count(ft_path(dir, "install3.log"), "kept your"), 0);
    assert_int_equal(ft_count_files(ft_path(dir, "root/etc/aafarm"), "farm2.conf.new"), 0);
    /* the worker's store of job files: the unit's persistent state folder,
     * shared by its instances (one user for all), not the private /tmp */
    char *unit = ft_read(ft_path(dir, "root/etc/systemd/system/aafarm-worker@.service"));
    assert_non_null(strstr(unit, "\nStateDirectory=aafarm\n"));
    assert_non_null(strstr(unit, "\nUser=aafarm\n"));
    assert_non_null(strstr(unit, " --file-cache ${STATE_DIRECTORY}/files "));
    free(unit);
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
        cmocka_unit_test_teardown(test_ssh_farm_renders_and_stops_its_workers, ft_teardown),
        cmocka_unit_test_teardown(test_ssh_farm_ctrl_c_stops_everything, ft_teardown),
        cmocka_unit_test_teardown(test_ssh_farm_over_a_real_sshd, teardown_sshd),
        cmocka_unit_test_teardown(test_slurm_script_with_stand_in_srun, ft_teardown),
        cmocka_unit_test_teardown(test_systemd_unit_and_install, ft_teardown),
        cmocka_unit_test_teardown(test_scripts_and_manifests_checked, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
