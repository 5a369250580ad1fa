/*
 * stale.h: what dead masters left behind, found and removed at the start
 * of the next render (docs/farm.md, "Journal and resume").
 *
 *   - "OUT.exr.tmp-<pid>" beside the output (image/outfile.h): removed
 *     when process <pid> no longer exists; reported and left alone when it
 *     does (another process may be writing it);
 *   - the embedded mode's private folders "$TMPDIR/aafarm-XXXXXX" holding
 *     "master.pid" (written by the master that made the folder) and its
 *     "master.sock": removed when that pid no longer exists. Folders
 *     without master.pid, or with anything else in them, are never
 *     touched.
 *
 * A pid can be reused by an unrelated process after a crash: then the
 * leftover is only reported, never removed by mistake.
 */
#ifndef MASTER_STALE_H
#define MASTER_STALE_H

#include <stddef.h>

/* Called once per leftover: what was found and whether it was removed. */
typedef void (*stale_report_fn)(void *arg, const char *path, long pid, int removed);

/* Temporary files of `output` (any directory). Returns how many were
 * removed. */
int stale_clean_outputs(const char *output, stale_report_fn report, void *arg);

/* Private ipc folders of dead masters under tmpdir (those of running
 * masters are not reported). Returns how many were removed. */
int stale_clean_ipc_dirs(const char *tmpdir, stale_report_fn report, void *arg);

/* The name of the pid file inside a private ipc folder. */
#define STALE_PID_FILE "master.pid"

#endif
