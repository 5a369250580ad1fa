/*
 * queue.h: the jobs of a serving master (aafarm-master --serve; docs/farm.md
 * "A job queue"), held in SQLite so that they outlive the master: each
 * job's state (queued, running, done, failed, cancelled), priority,
 * scene and outputs, submit/start/end times, progress, exit status and
 * error, and its submission (bundle.h) as the bytes to render it from.
 *
 * Two threads use it, each through its own queue object (its own SQLite
 * connection; WAL, a busy timeout): the HTTP thread submits, cancels and
 * lists; the master's loop takes the next job, says it started, its
 * progress and its end, and looks for cancellations. The order of work:
 * a running job first (a master restarted mid-job resumes it from its
 * journal), then the queued ones by priority (higher first), then by
 * submission.
 */
#ifndef MASTER_QUEUE_H
#define MASTER_QUEUE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct queue queue;

/* Opens (creating) the database at path. NULL with the reason. */
queue *queue_open(const char *path, char *err, size_t errsz);
void queue_destroy(queue **self_p);

/* A new queued job; its id, or -1 with the reason. outputs: one line each. */
long queue_submit(queue *self, int priority, const char *pool, const char *scene,
                  const char *outputs, int frames, const void *bundle, size_t len, char *err,
                  size_t errsz);

typedef enum queue_cancel_result {
    QUEUE_CANCELLED,     /* it was queued: cancelled now */
    QUEUE_CANCEL_ASKED,  /* it runs: the master's loop ends it */
    QUEUE_NO_SUCH_JOB,
    QUEUE_ALREADY_ENDED, /* err says how it ended */
    QUEUE_ERROR
} queue_cancel_result;
queue_cancel_result queue_cancel(queue *self, long id, char *err, size_t errsz);

/* {"jobs": [...]} (id < 0), or one job's object (NULL and *missing when
 * there is no such job), malloc'd; NULL with the reason. */
char *queue_json(queue *self, long id, size_t *len, bool *missing, char *err, size_t errsz);

/* ---- the master's loop ---- */

/* The job to run next (-1: none); *resume: it was running already. */
long queue_next(queue *self, bool *resume, char *err, size_t errsz);
/* The same, but none of the nskip jobs in skip (those running already). */
long queue_next_except(queue *self, const long *skip, int nskip, bool *resume, char *err,
                       size_t errsz);
/* Its submission (malloc'd). */
bool queue_bundle(queue *self, long id, uint8_t **data, size_t *len, char *err, size_t errsz);
/* Running from now (false: it was cancelled meanwhile, or an error). */
bool queue_start(queue *self, long id, int tiles, char *err, size_t errsz);
/* Back to 'queued' (it ran and lost every worker): run again later,
 * from its journal. */
bool queue_requeue(queue *self, long id, char *err, size_t errsz);
bool queue_progress(queue *self, long id, int done, char *err, size_t errsz);
/* Was its cancellation asked for? */
bool queue_cancel_asked(queue *self, long id);
/* Its end: state "done", "failed" or "cancelled", the exit status, the error. */
bool queue_end(queue *self, long id, const char *state, int exit_status, const char *error,
               char *err, size_t errsz);

#endif
