/*
 * registry.h: the workers the master knows (docs/protocol.md, "The
 * master's state machine"), keyed by their ZeroMQ routing id, and what
 * each one did (the summary printed at the end and written to the
 * statistics file). A worker that leaves or dies is retired, not freed:
 * it stays in the list for the summary, but lookups by routing id no
 * longer find it, so its next message is answered with Reject
 * HELLO_FIRST. At most 4096 retired workers are kept (the oldest go
 * first), so a peer saying Hello over and over cannot grow the master
 * without bound.
 *
 * Also here: the rate limit for those HELLO_FIRST answers (at most one per
 * unknown peer per heartbeat interval, over a small table of peers).
 *
 * No sockets, no clocks: times are milliseconds passed in by the caller.
 */
#ifndef MASTER_REGISTRY_H
#define MASTER_REGISTRY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum { REGISTRY_MAX_ID = 255, REGISTRY_NAME = 128, REGISTRY_POOL = 64, REGISTRY_FAILED = 16 };

typedef struct farm_worker {
    uint8_t id[REGISTRY_MAX_ID];   /* ZeroMQ routing id */
    size_t id_len;
    char name[REGISTRY_NAME];      /* from Hello */
    char host[REGISTRY_NAME];
    char pool[REGISTRY_POOL];      /* its --pool ("" none) */
    uint32_t pid, threads;
    int slot;                      /* scheduler worker slot */
    uint32_t credits;              /* tiles it asked for and was not granted yet */
    bool has_job;                  /* it holds a job of this render (sent, or in Hello) */
    int held[8];                   /* frames whose job it holds, newest last
                                      (farm_messages.c; a worker keeps 4) */
    int nheld;
    bool local;                    /* a process this master started */
    bool alive;
    bool blocked;                  /* blocklisted for the job: its results were
                                      refused --retries times; it gets no tile */
    bool other_pool;               /* the job has a pool it is not in: it gets no tile */
    bool benched;                  /* it failed tiles that others finished
                                      (FARM_BENCH_AFTER): no more tiles of the job */
    int failed_tiles[REGISTRY_FAILED];   /* the job's tiles it failed, newest last */
    int nfailed;
    int strikes;                   /* tiles it failed that another worker finished */
    char gone[160];                /* why it was retired */
    char last_error[200];          /* its last tile failure or refused result ("" none) */
    int64_t joined_ms, last_seen_ms, last_sent_ms, left_ms;
    /* what it did */
    uint64_t tiles, duplicates, failures, invalid_tiles;
    uint64_t bytes_in, bytes_out, job_bytes;
    double render_seconds, cpu_seconds;
    uint64_t rays, boxes, shader_evals, cache_hits, cache_misses, cache_evictions;
    uint64_t peak_cache_bytes;
    uint64_t nonfinite_samples;    /* NaN/Inf samples its tiles had (written as 0) */
    /* job files (docs/textures.md): bytes sent to it, and from its FilesReady
     * the files its host's store had (hits) and lacked (misses) */
    uint64_t file_bytes, file_chunks, file_hits, file_misses;
    uint64_t file_overrun;         /* NeedFiles dropped: beyond the in-flight cap */
    int64_t file_first_ms, file_ready_ms;   /* its first NeedFile served, its FilesReady */
    bool files_ready;              /* it has every file of the job */
} farm_worker;

typedef struct registry registry;

registry *registry_new(void);
void registry_destroy(registry **self_p);

/* A new live worker with this routing id (1..REGISTRY_MAX_ID bytes). A
 * live worker with the same id must have been retired first. */
farm_worker *registry_add(registry *self, const uint8_t *id, size_t id_len, int64_t now_ms);

/* The live worker with this routing id, or NULL. */
farm_worker *registry_find(const registry *self, const uint8_t *id, size_t id_len);

/* Marks the worker gone (why: a short phrase for logs and the summary). */
void registry_retire(registry *self, farm_worker *w, const char *why, int64_t now_ms);

/* All workers ever registered, live or retired, in order of arrival. */
size_t registry_count(const registry *self);
farm_worker *registry_at(const registry *self, size_t i);
int registry_alive(const registry *self);

/* Should an unknown peer get a Reject HELLO_FIRST now? True at most once
 * per interval_ms per peer (the table remembers the most recent peers). */
bool registry_reject_due(registry *self, const uint8_t *id, size_t id_len, int64_t now_ms,
                         int64_t interval_ms);

/* The routing id as hex for logs ("0080000001"; long ids are cut with
 * "..."); buf must hold at least 24 bytes. */
const char *registry_id_hex(const uint8_t *id, size_t id_len, char *buf, size_t bufsz);

#endif
