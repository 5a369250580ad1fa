/*
 * file_fetch.h: a worker gathering the files of the jobs it is sent
 * (docs/textures.md, "The wire and the cache"; docs/protocol.md,
 * "Files").
 *
 * A Job names its files by SHA-256. file_fetch_add looks each one up in
 * the host's store (file_store.h); the job is ready when all are there.
 * Otherwise the job waits here (a copy of its Job message kept) while the
 * missing files are fetched from the master in chunks (NeedFile ->
 * FileChunk), with at most `inflight` bytes asked for and not received at
 * any time, or while another worker process of the host fetches them
 * (polled). Chunks are written into the store as they come; after a
 * reconnect the job is sent again and the transfer resumes from the
 * chunks already written, also those a killed process wrote.
 *
 * No sockets here: file_fetch_pump hands each request to a callback.
 */
#ifndef WORKER_FILE_FETCH_H
#define WORKER_FILE_FETCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "message.h"
#include "util/err.h"
#include "util/hash.h"

typedef struct file_fetch_options {
    const char *dir;               /* the store (NULL: file_store_default_dir) */
    uint64_t budget;               /* store byte budget, 0: unlimited */
    uint32_t chunk;                /* bytes per NeedFile (default 1 MiB) */
    uint64_t inflight;             /* bytes asked and not received, at most (8 MiB) */
    int delay_ms;                  /* testing aid: at least this between two NeedFile */
} file_fetch_options;

/* A job whose files are being gathered, or are all present. */
typedef struct fetch_job {
    char hash[HASH_HEX_SIZE];
    proto_saved_job *msg;          /* the Job message */
    int nfiles;
    char **paths;                  /* per Job.files entry: its path in the store */
    int *fds;                      /* ... and its "in use" descriptor (-1: absent) */
    uint32_t hits, misses;         /* present at arrival / fetched */
    uint64_t fetched;              /* file bytes this process received for it */
    char error[ERR_LEN];           /* non-empty: its files cannot be had */
    struct fetch_job *next;
} fetch_job;

typedef struct file_fetch file_fetch;

file_fetch *file_fetch_new(const file_fetch_options *opt);
void file_fetch_destroy(file_fetch **self_p);

/* Takes a Job: looks its files up (hashing each the first time this
 * process uses it: run it beside the loop) and keeps it until they are
 * all present (file_fetch_take_ready hands it back then, possibly at
 * once). A job already waiting is not added twice. */
void file_fetch_add(file_fetch *self, const proto_job *m, int64_t now_ms);

/* Is a job with this hash waiting for its files? */
bool file_fetch_waiting(const file_fetch *self, const char *hash);

/* The slow part, which may hash whole files (run it beside the loop):
 * checks and stores the transfers whose chunks are all written, starts
 * transfers, and looks again at the files another process fetches.
 * file_fetch_poll_due says whether there is anything to do now. */
bool file_fetch_poll_due(const file_fetch *self, int64_t now_ms);
void file_fetch_poll(file_fetch *self, int64_t now_ms);

/* Sends what may be sent now (cheap): send(arg, job_hash, sha256, offset,
 * length) for each chunk to ask for (false: the socket cannot take it
 * now). */
typedef bool (*file_fetch_send_fn)(void *arg, const char *job_hash, const char *file_hash,
                                   uint64_t offset, uint32_t length);
void file_fetch_pump(file_fetch *self, int64_t now_ms, file_fetch_send_fn send, void *arg);

/* A FileChunk arrived: its bytes are written (cheap; the hash of a
 * complete file is checked by file_fetch_poll). Returns the bytes it
 * added (0: not wanted). */
uint64_t file_fetch_chunk(file_fetch *self, const proto_file_chunk *c, const uint8_t *data,
                          size_t len, int64_t now_ms);

/* A job whose files are all present (or that failed: ->error), removed
 * from the waiting list; NULL when none. The caller owns it: it passes
 * the descriptors on (or releases them) and frees it with
 * fetch_job_destroy. */
fetch_job *file_fetch_take_ready(file_fetch *self);
void fetch_job_destroy(fetch_job **self_p);

/* Drops the waiting job with this hash (NULL: all of them, as after a
 * reconnect); transfers stop, their chunks stay in the store. */
void file_fetch_drop(file_fetch *self, const char *hash);

/* Chunks asked for and not yet received are asked again (a new session). */
void file_fetch_rewind(file_fetch *self);

#endif
