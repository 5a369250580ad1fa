/*
 * test_slurm.c: deploy/slurm/aafarm.sbatch through a REAL Slurm (Debian
 * 12's slurmctld, slurmd, slurm-client and munge; issue 26). The test
 * builds a one-node cluster of its own in a private temporary folder:
 *   - munged -F on a private socket with a key made by mungekey (the
 *     system's munge and /etc/munge are never used);
 *   - a slurm.conf of its own (SLURM_CONF, so /etc/slurm is never read):
 *     node "localhost" at 127.0.0.1 with this machine's CPUs, free
 *     loopback ports, state, spool, pid files and logs in the folder,
 *     proctrack/linuxproc, task/none, no cgroups, no accounting,
 *     AuthType=auth/munge with AuthInfo=socket= the private socket;
 *   - slurmctld -D and slurmd -D as children, each bounded by timeout -k,
 *     stopped by PID at the end (the daemon's own pid file too, should its
 *     timeout wrapper be gone), the folder removed.
 * Once sinfo shows the node idle, sbatch --wait submits aafarm.sbatch on
 * one node with the wave scene: the job must exit 0, its log must show
 * the master and one worker started by srun inside the job, the image
 * must equal --standalone's, and the job's keys must be removed.
 *
 * Where Slurm cannot run here (a package missing, a daemon that exits or
 * never brings the node up), the test prints why, with the daemon's own
 * error line and the end of its log, and exits 77, which CTest reports as
 * skipped (SKIP_RETURN_CODE): never a pass without a real Slurm.
 *
 * Arguments: MASTER WORKER SOURCE_DIR (the repository root).
 */
#define _GNU_SOURCE   /* strcasestr */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pwd.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "farm_testutil.h"

enum { SKIP = 77, DAEMON_LIMIT_S = 280 };

static char *dir;
static const char *src;
static char bindir[4096];

/* a daemon the test started: its timeout -k wrapper and its pid file */
typedef struct {
    const char *name;
    pid_t pid;
    char log[4400];
    char pidfile[4400];
} daemon_t;

static daemon_t munged = {.name = "munged"};
static daemon_t slurmctld = {.name = "slurmctld"};
static daemon_t slurmd = {.name = "slurmd"};

static bool have(const char *tool)
{
    return ft_sh(dir, "which.log", "command -v %s", tool) == 0;
}

/* Starts argv (after "timeout -k 5 LIMIT") with its output to d->log. */
static void start(daemon_t *d, const char *const *args)
{
    char limit[16];
    snprintf(limit, sizeof limit, "%d", DAEMON_LIMIT_S);
    const char *argv[24] = {"/usr/bin/timeout", "-k", "5", limit};
    size_t n = 4;
    for (size_t i = 0; args[i] && n < 23; i++) argv[n++] = args[i];
    argv[n] = NULL;
    d->pid = ft_spawn(d->log, argv);
}

/* SIGTERM (timeout passes it on), then SIGKILL; then the pid in the
 * daemon's own pid file, should it have outlived its wrapper. */
static void stop(daemon_t *d)
{
    if (d->pid > 0) {
        kill(d->pid, SIGTERM);
        if (ft_wait(d->pid, 15) == -1) {
            kill(d->pid, SIGKILL);
            ft_wait(d->pid, 5);
        }
        d->pid = 0;
    }
    if (d->pidfile[0]) {
        char *text = ft_read(d->pidfile);
        long pid = atol(text);
        free(text);
        if (pid > 1 && kill((pid_t)pid, 0) == 0) {
            kill((pid_t)pid, SIGTERM);
            for (int i = 0; i < 100 && kill((pid_t)pid, 0) == 0; i++) ft_sleep_ms(50);
            kill((pid_t)pid, SIGKILL);
        }
    }
}

/* A job left running (a failed or timed-out sbatch) is cancelled first:
 * its slurmstepd would outlive slurmd. */
static void cancel_jobs(void)
{
    if (slurmctld.pid <= 0 || !ft_running(slurmctld.pid)) return;
    struct passwd *pw = getpwuid(getuid());
    if (!pw || ft_sh(dir, "cancel.log", "scancel --user=%s", pw->pw_name) != 0) return;
    const char *q = ft_path(dir, "squeue.log");
    for (double until = ft_now() + 20; ft_now() < until; ft_sleep_ms(250)) {
        unlink(q);
        char *text = NULL;
        if (ft_sh(dir, "squeue.log", "squeue --noheader --format=%%i") == 0) text = ft_read(q);
        bool none = text && !text[0];
        free(text);
        if (none) return;
    }
    fprintf(stderr, "test_slurm: jobs still in the queue after scancel (see %s)\n", q);
}

static void stop_all(void)
{
    cancel_jobs();
    stop(&slurmd);
    stop(&slurmctld);
    stop(&munged);
    ft_stop_all();
}

/* Why a daemon did not come up, in its own words: its first "fatal" line,
 * else its first "error" line (not MPI's: Debian's Slurm says PMIx is
 * missing on every start), then the end of its log. */
static void explain(const daemon_t *d, const char *what, char *why, size_t whysz)
{
    char *text = ft_read(d->log);
    const char *best = NULL;
    for (const char *key = "fatal"; !best && key; key = strcmp(key, "fatal") == 0 ? "error" : NULL) {
        for (const char *line = text; *line;) {
            size_t len = strcspn(line, "\n");
            const char *hit = strcasestr(line, key);
            if (hit && hit < line + len && !strstr(line, "pmix") && !strstr(line, "MPI") &&
                !strstr(line, "MailProg") && !strstr(line, "state file"))
                if (!best) best = line;   /* the first: the cause, not the summary */
            line += len + (line[len] == '\n');
        }
    }
    int len = best ? (int)strcspn(best, "\n") : 0;
    snprintf(why, whysz, "%s %s: %.*s", d->name, what, len, best ? best : "(no error line in its log)");
    size_t n = strlen(text);
    fprintf(stderr, "the end of %s's log (%s):\n%s\n", d->name, d->log, text + (n > 1500 ? n - 1500 : 0));
    free(text);
}

/* munged on a private socket with a fresh key; false with why. */
static bool start_munge(char *why, size_t whysz)
{
    /* munged wants its socket's folder and those above searchable by all */
    assert_int_equal(chmod(dir, 0711), 0);
    assert_int_equal(mkdir(ft_path(dir, "munge"), 0711), 0);
    char md[4200];
    snprintf(md, sizeof md, "%s/munge", dir);
    if (ft_sh(dir, "mungekey.log", "/usr/sbin/mungekey --create --keyfile %s/key", md) != 0) {
        char *text = ft_read(ft_path(dir, "mungekey.log"));
        snprintf(why, whysz, "mungekey cannot make a key: %.300s", text);
        free(text);
        return false;
    }
    char sock[4300], key[4300], pidf[4300], seed[4300], logf[4300];
    snprintf(sock, sizeof sock, "--socket=%s/sock", md);
    snprintf(key, sizeof key, "--key-file=%s/key", md);
    snprintf(pidf, sizeof pidf, "--pid-file=%s/pid", md);
    snprintf(seed, sizeof seed, "--seed-file=%s/seed", md);
    snprintf(logf, sizeof logf, "--log-file=%s/log", md);
    snprintf(munged.log, sizeof munged.log, "%s/munged.out", dir);
    snprintf(munged.pidfile, sizeof munged.pidfile, "%s/pid", md);
    const char *args[] = {"/usr/sbin/munged", "--foreground", sock, key, pidf, seed, logf, NULL};
    start(&munged, args);
    /* ready once a credential made on the socket decodes on it */
    for (double until = ft_now() + 15; ft_now() < until; ft_sleep_ms(100)) {
        if (!ft_running(munged.pid)) {
            explain(&munged, "exited at start", why, whysz);
            return false;
        }
        if (access(ft_path(md, "sock"), F_OK) == 0 &&
            ft_sh(dir, "munge-probe.log", "munge -n -S %s/sock | unmunge -S %s/sock >/dev/null", md, md) == 0)
            return true;
    }
    explain(&munged, "never answered on its socket in 15 s", why, whysz);
    return false;
}

/* Writes dir/slurm.conf (free loopback ports, everything in dir). */
static void write_slurm_conf(void)
{
    struct passwd *pw = getpwuid(getuid());
    assert_non_null(pw);
    int ctld_port = ft_free_port(), d_port = ft_free_port();
    while (d_port == ctld_port) d_port = ft_free_port();
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    assert_int_equal(mkdir(ft_path(dir, "state"), 0700), 0);
    assert_int_equal(mkdir(ft_path(dir, "spool"), 0700), 0);
    FILE *f = fopen(ft_path(dir, "slurm.conf"), "w");
    assert_non_null(f);
    fprintf(f,
            "# a one-node cluster of test_slurm: nothing outside %s\n"
            "ClusterName=aafarmtest\n"
            "SlurmctldHost=localhost(127.0.0.1)\n"
            "SlurmctldPort=%d\nSlurmdPort=%d\n"
            "SlurmUser=%s\nSlurmdUser=%s\n"
            "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=%s/munge/sock\n"
            "StateSaveLocation=%s/state\nSlurmdSpoolDir=%s/spool\n"
            "SlurmctldPidFile=%s/slurmctld.pid\nSlurmdPidFile=%s/slurmd.pid\n"
            "SlurmctldLogFile=%s/slurmctld.log\nSlurmdLogFile=%s/slurmd.log\n"
            "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n"
            "JobAcctGatherType=jobacct_gather/none\n"
            "AccountingStorageType=accounting_storage/none\nJobCompType=jobcomp/none\n"
            "SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\n"
            "MpiDefault=none\nMailProg=/bin/true\nReturnToService=2\n"
            "PlugStackConfig=%s/plugstack.conf\n"   /* empty: not /etc/slurm's */
            "NodeName=localhost NodeAddr=127.0.0.1 CPUs=%ld State=UNKNOWN\n"
            "PartitionName=aafarm Nodes=localhost Default=YES MaxTime=5 State=UP\n",
            dir, ctld_port, d_port, pw->pw_name, pw->pw_name, dir, dir, dir, dir, dir, dir, dir, dir,
            cpus > 0 ? cpus : 1);
    fclose(f);
    f = fopen(ft_path(dir, "plugstack.conf"), "w");
    assert_non_null(f);
    fclose(f);
}

/* slurmctld and slurmd; true once sinfo shows the node idle. */
static bool start_slurm(char *why, size_t whysz)
{
    write_slurm_conf();
    char conf[4200];
    snprintf(conf, sizeof conf, "%s/slurm.conf", dir);
    assert_int_equal(setenv("SLURM_CONF", conf, 1), 0);   /* every Slurm program below */
    snprintf(slurmctld.log, sizeof slurmctld.log, "%s/slurmctld.out", dir);
    snprintf(slurmctld.pidfile, sizeof slurmctld.pidfile, "%s/slurmctld.pid", dir);
    snprintf(slurmd.log, sizeof slurmd.log, "%s/slurmd.out", dir);
    snprintf(slurmd.pidfile, sizeof slurmd.pidfile, "%s/slurmd.pid", dir);
    const char *ctld[] = {"/usr/sbin/slurmctld", "-D", "-c", "-f", conf, NULL};   /* -c: no old state */
    start(&slurmctld, ctld);
    const char *d[] = {"/usr/sbin/slurmd", "-D", "-N", "localhost", "-f", conf, NULL};
    start(&slurmd, d);
    const char *info = ft_path(dir, "sinfo.log");
    for (double until = ft_now() + 40; ft_now() < until; ft_sleep_ms(250)) {
        if (!ft_running(slurmctld.pid)) {
            explain(&slurmctld, "exited at start", why, whysz);
            return false;
        }
        if (!ft_running(slurmd.pid)) {
            explain(&slurmd, "exited at start", why, whysz);
            return false;
        }
        unlink(info);
        if (ft_sh(dir, "sinfo.log", "sinfo --noheader --nodes=localhost --format=%%T") == 0 &&
            ft_count(info, "idle") == 1)
            return true;
    }
    char *state = ft_read(info);
    state[strcspn(state, "\n")] = '\0';
    fprintf(stderr, "sinfo says: %s\n", state);
    free(state);
    explain(&slurmd, "did not bring node localhost to idle in 40 s", why, whysz);
    explain(&slurmctld, "(the controller)", why + strlen(why), whysz - strlen(why));
    return false;
}

static void test_sbatch_renders_on_a_real_slurm(void **state)
{
    (void)state;
    int port = ft_free_port();
    int rc = ft_sh(dir, "sbatch.log",
                   "cd %s && AAFARM_BIN=%s AAFARM_PORT=%d AAFARM_BIND_HOST=127.0.0.1 "
                   "AAFARM_WORKER_OPTS=\"--threads 1\" "
                   "sbatch --wait --nodes=1 --time=2 --output=%s/job.log "
                   "%s/deploy/slurm/aafarm.sbatch scene.rib slurm.exr --tile 16",
                   dir, bindir, port, dir, src);
    const char *job = ft_path(dir, "job.log");
    char *sb = ft_read(ft_path(dir, "sbatch.log"));
    char *jl = ft_read(job);
    fprintf(stderr, "sbatch: %s--- the job's log:\n%s", sb, jl);
    free(sb);
    free(jl);
    assert_int_equal(rc, 0);
    assert_int_equal(ft_count(ft_path(dir, "sbatch.log"), "Submitted batch job "), 1);
    /* run by Slurm: its job id, its node list, srun's steps */
    assert_int_equal(ft_count(job, "aafarm.sbatch: job "), 1);
    char needle[64];
    snprintf(needle, sizeof needle, "master on localhost:%d, 1 worker node(s)", port);
    assert_int_equal(ft_count(job, needle), 1);
    assert_int_equal(ft_count(job, "connected to master"), 1);
    assert_int_equal(ft_count(job, "master exited with status 0"), 1);
    /* the worker ended by SIGTERM and said so (srun itself, sent SIGTERM,
     * would SIGKILL its tasks: "forcing job termination") */
    assert_int_equal(ft_count(job, "stopped ("), 1);
    assert_int_equal(ft_count(job, "forcing job termination"), 0);
    assert_int_equal(ft_count(job, "Killed"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "slurm.exr")), 0);
    assert_int_equal(ft_count_files(dir, ".aafarm-keys-"), 0);
}

int main(int argc, char **argv)
{
    if (argc < 4 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_slurm MASTER WORKER SOURCE_DIR\n");
        return 2;
    }
    src = argv[3];
    if (!ft_program_dir(bindir, sizeof bindir)) return 2;

    dir = ft_tempdir();
    char why[4096] = "";
    const char *tools[] = {"munge", "unmunge", "sbatch", "sinfo", "scontrol", "srun", NULL};
    for (size_t i = 0; tools[i] && !why[0]; i++)
        if (!have(tools[i]))
            snprintf(why, sizeof why, "no %s on PATH (Debian packages slurm-client, munge; "
                     "deploy/install-deps.sh installs them)", tools[i]);
    const char *daemons[] = {"/usr/sbin/munged", "/usr/sbin/mungekey", "/usr/sbin/slurmctld",
                             "/usr/sbin/slurmd", NULL};
    for (size_t i = 0; daemons[i] && !why[0]; i++)
        if (access(daemons[i], X_OK) != 0)
            snprintf(why, sizeof why, "no %s (Debian packages slurmctld, slurmd, munge; "
                     "deploy/install-deps.sh installs them)", daemons[i]);
    ft_write_scene(dir, FT_SCENE_WAVE);
    if (ft_standalone(dir, 16) != 0) {   /* the reference image, before any daemon */
        fprintf(stderr, "test_slurm: the standalone render failed\n");
        ft_rmtree(dir);
        free(dir);
        return 1;
    }
    int rc = SKIP;
    if (!why[0] && start_munge(why, sizeof why) && start_slurm(why, sizeof why)) {
        const struct CMUnitTest tests[] = {
            cmocka_unit_test(test_sbatch_renders_on_a_real_slurm),
        };
        rc = cmocka_run_group_tests(tests, NULL, NULL);
    } else {
        fprintf(stderr, "test_slurm: SKIPPED: Slurm cannot run here: %s\n", why);
    }
    stop_all();
    ft_rmtree(dir);
    free(dir);
    return rc;
}
