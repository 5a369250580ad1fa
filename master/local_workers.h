/*
 * local_workers.h: worker processes the master starts itself (the
 * embedded default: `aafarm-master scene.rib -o out.exr` with nothing else
 * running). Each is the aafarm-worker program found next to
 * aafarm-master, started with fork + exec as
 *
 *     aafarm-worker --connect ENDPOINT --name local-K --threads T [-q|-v]
 *
 * and stopped by PID: the farm first sends it Shutdown over the socket,
 * local_workers_stop() then waits a grace period, sends SIGTERM, waits
 * again, sends SIGKILL, and reaps every child. On Linux each child also
 * gets SIGKILL the moment the master dies without stopping it
 * (PR_SET_PDEATHSIG; a getppid() check after it closes the race with a
 * master that died before), so no orphan keeps rendering or retrying a
 * vanished socket.
 */
#ifndef MASTER_LOCAL_WORKERS_H
#define MASTER_LOCAL_WORKERS_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

typedef struct local_workers local_workers;

/* The aafarm-worker next to this program (/proc/self/exe's folder), into
 * buf; false with a reason in err when it is not there. */
bool local_workers_find_binary(char *buf, size_t bufsz, char *err, size_t errsz);

/* Starts n workers. NULL with a reason in err when a fork fails (the ones
 * already started are stopped). verbosity -1/0/1 becomes -q/nothing/-v. */
local_workers *local_workers_start(const char *binary, const char *endpoint, int n,
                                   int threads, int verbosity, char *err, size_t errsz);

/* Reaps children that have exited (never blocks). Returns how many exited
 * in this call; each one's pid and wait status go to the log callback. */
int local_workers_reap(local_workers *self,
                       void (*on_exit)(void *arg, pid_t pid, int status), void *arg);

int local_workers_running(const local_workers *self);
bool local_workers_has_pid(const local_workers *self, pid_t pid);

/* Waits up to grace_ms for the children to exit, then SIGTERM, another
 * grace_ms, then SIGKILL; reaps them all. Returns how many needed a
 * signal. */
int local_workers_stop(local_workers *self, int grace_ms);

/* Stops whatever still runs (SIGKILL) and frees. */
void local_workers_destroy(local_workers **self_p);

#endif
