/*
 * local_workers.c: starting, watching and stopping the master's own
 * worker processes (see local_workers.h). Everything is done by PID:
 * fork/execv, waitpid(pid, WNOHANG), kill(pid, ...).
 */
#include "local_workers.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

struct local_workers {
    pid_t *pids;       /* 0 once reaped */
    int n;
};

bool local_workers_find_binary(char *buf, size_t bufsz, char *err, size_t errsz)
{
    char self[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) {
        err_set(err, errsz, "cannot find this program's folder (/proc/self/exe: %s)",
                strerror(errno));
        return false;
    }
    self[len] = '\0';
    char *slash = strrchr(self, '/');
    if (slash) *slash = '\0';
    if ((size_t)snprintf(buf, bufsz, "%s/aafarm-worker", self) >= bufsz) {
        err_set(err, errsz, "path of aafarm-worker too long");
        return false;
    }
    if (access(buf, X_OK) != 0) {
        err_set(err, errsz, "cannot start local workers: %s: %s (it is built next to "
                "aafarm-master)", buf, strerror(errno));
        return false;
    }
    return true;
}

/* In the child: never returns. */
static void exec_worker(const char *binary, const char *endpoint, int k, int threads,
                        int verbosity, pid_t parent)
{
#ifdef __linux__
    /* the master's death ends it at once (issue 27): SIGKILL, not SIGTERM,
     * whose orderly exit (Shutdown to a master that is gone, the socket's
     * linger, render threads finishing their tile or evaluation) took
     * seconds; nothing of a local worker outlives its master anyway. The
     * setting survives execv. */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);     /* the master died before prctl */
#else
    (void)parent;
#endif
    /* the master stops its workers itself: a terminal's ^C goes to it only */
    setpgid(0, 0);
    char name[32], nthreads[16];
    snprintf(name, sizeof name, "local-%d", k);
    snprintf(nthreads, sizeof nthreads, "%d", threads);
    const char *argv[10];
    int a = 0;
    argv[a++] = binary;
    argv[a++] = "--connect";
    argv[a++] = endpoint;
    argv[a++] = "--name";
    argv[a++] = name;
    argv[a++] = "--threads";
    argv[a++] = nthreads;
    if (verbosity < 0) argv[a++] = "-q";
    if (verbosity > 0) argv[a++] = "-v";
    argv[a] = NULL;
    execv(binary, (char *const *)argv);
    fprintf(stderr, "aafarm-master: cannot run %s: %s\n", binary, strerror(errno));
    _exit(127);
}

local_workers *local_workers_start(const char *binary, const char *endpoint, int n,
                                   int threads, int verbosity, char *err, size_t errsz)
{
    local_workers *self = xcalloc(1, sizeof *self);
    self->pids = xcalloc((size_t)(n > 0 ? n : 1), sizeof *self->pids);
    pid_t parent = getpid();
    fflush(NULL);
    for (int k = 0; k < n; k++) {
        pid_t pid = fork();
        if (pid < 0) {
            err_set(err, errsz, "cannot start local worker %d: fork: %s", k + 1, strerror(errno));
            local_workers_stop(self, 0);
            local_workers_destroy(&self);
            return NULL;
        }
        if (pid == 0) exec_worker(binary, endpoint, k + 1, threads, verbosity, parent);
        self->pids[self->n++] = pid;
    }
    return self;
}

int local_workers_reap(local_workers *self, void (*on_exit)(void *arg, pid_t pid, int status),
                       void *arg)
{
    int exited = 0;
    for (int i = 0; i < self->n; i++) {
        if (self->pids[i] <= 0) continue;
        int status;
        pid_t r = waitpid(self->pids[i], &status, WNOHANG);
        if (r == self->pids[i] || (r < 0 && errno == ECHILD)) {
            if (on_exit && r > 0) on_exit(arg, self->pids[i], status);
            self->pids[i] = 0;
            exited++;
        }
    }
    return exited;
}

int local_workers_running(const local_workers *self)
{
    int n = 0;
    for (int i = 0; i < self->n; i++) n += self->pids[i] > 0;
    return n;
}

bool local_workers_has_pid(const local_workers *self, pid_t pid)
{
    for (int i = 0; i < self->n; i++)
        if (self->pids[i] == pid && pid > 0) return true;
    return false;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
}

/* Waits up to ms for every child to exit (polling every 10 ms). */
static void wait_all(local_workers *self, int ms)
{
    for (int waited = 0;; waited += 10) {
        local_workers_reap(self, NULL, NULL);
        if (local_workers_running(self) == 0 || waited >= ms) return;
        sleep_ms(10);
    }
}

static int signal_all(local_workers *self, int sig)
{
    int n = 0;
    for (int i = 0; i < self->n; i++)
        if (self->pids[i] > 0 && kill(self->pids[i], sig) == 0) n++;
    return n;
}

int local_workers_stop(local_workers *self, int grace_ms)
{
    wait_all(self, grace_ms);
    int signalled = signal_all(self, SIGTERM);
    if (signalled) wait_all(self, grace_ms > 0 ? grace_ms : 1000);
    if (signal_all(self, SIGKILL)) {
        for (int i = 0; i < self->n; i++)
            if (self->pids[i] > 0) {
                waitpid(self->pids[i], NULL, 0);
                self->pids[i] = 0;
            }
    }
    return signalled;
}

void local_workers_destroy(local_workers **self_p)
{
    local_workers *self = *self_p;
    if (!self) return;
    if (local_workers_running(self)) local_workers_stop(self, 0);
    free(self->pids);
    free(self);
    *self_p = NULL;
}
