/*
 * worker_jobs.h: the jobs a farm worker holds (docs/protocol.md, "Job"
 * and "Job hash"). A Job message is turned back into a job (job_new,
 * job_add_source, job_add_shader, job_finish), its hash RECOMPUTED and
 * compared with the one the master sent, then compiled and prepared for
 * rendering (job_scene_new). The last few jobs stay compiled and are
 * listed in the next Hello's jobs_held, so a worker serving one master
 * after another is not sent the same job twice.
 *
 * A held_job is reference counted: the list holds one reference, each
 * render thread holds one for the job its trace_thread (and so its box
 * cache) was made for, each queued tile one. The job is freed by whoever
 * drops the last reference, so evicting an old job never pulls the world
 * out from under a thread still rendering it.
 *
 * A Job that fails to verify or compile is held too, as "broken" with the
 * reason, so that every grant of it is answered with a Failure at once.
 */
#ifndef WORKER_JOBS_H
#define WORKER_JOBS_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "image/format.h"
#include "job/job_scene.h"
#include "message.h"
#include "util/err.h"

typedef struct held_job {
    char hash[HASH_HEX_SIZE];
    job *jb;                   /* NULL when broken */
    job_scene *js;             /* NULL when broken */
    image_format fmt;          /* the image the tiles belong to */
    bool broken;
    char error[ERR_LEN];       /* why it is broken */
    int *file_fds;             /* its files' "in use" descriptors (file_store.h) */
    int nfile_fds;
    uint64_t files_said;       /* the master session told FilesReady for it */
    atomic_int refs;
} held_job;

held_job *held_job_retain(held_job *self);
void held_job_release(held_job **self_p);

typedef struct worker_jobs worker_jobs;

/* max_held: compiled jobs kept (>= 1); cache_bytes: box cache budget per
 * render thread (0: the Job's, and unlimited when the Job says 0); cancel:
 * the worker's stop flag (a signal) or NULL, handed to job_scene_new so
 * that compiling and preparing a job stop when it is set (the job is then
 * broken with "interrupted"; the caller is leaving anyway). */
worker_jobs *worker_jobs_new(int max_held, size_t cache_bytes, const atomic_int *cancel);
/* The threads a job's preparation may use (the root boxes of displaced
 * meshes: job_scene_new_threads); default 1. */
void worker_jobs_set_threads(worker_jobs *self, int threads);
void worker_jobs_destroy(worker_jobs **self_p);

/* The held job with this hash (broken or not), or NULL. No reference is
 * added: valid until the next worker_jobs_add. */
held_job *worker_jobs_find(const worker_jobs *self, const char *hash);

/* Verifies and compiles a Job. Returns the held job: ready, or broken
 * with the reason in ->error (never NULL). A job already held is
 * returned as it is. file_paths and file_fds (NULL when the Job has no
 * files): per Job.files entry, the local copy and its open "in use"
 * descriptor, which the held job takes over (a job already held: they
 * are released). */
held_job *worker_jobs_add(worker_jobs *self, const proto_job *msg,
                          char *const *file_paths, const int *file_fds);

/* Holds a job that cannot be had here (its files could not be fetched):
 * broken, with the reason. */
held_job *worker_jobs_add_broken(worker_jobs *self, const char *hash, const char *error);

/* The hashes of the good jobs held, newest first (at most max). */
size_t worker_jobs_hashes(const worker_jobs *self, char **out, size_t max);

#endif
