/*
 * worker_loop.h: `aafarm-worker --connect`: the farm side of a worker
 * (docs/protocol.md, "The worker's state machine"; docs/farm.md).
 *
 * Long-lived: connects a DEALER to the master, says Hello, asks for
 * tiles, renders them on a pool of threads (worker_pool.h) with the jobs
 * it holds compiled (worker_jobs.h) once their files are in the host's
 * store (file_fetch.h), sends the tiles back as EXR, and
 * heartbeats meanwhile. When the master goes silent it reconnects with
 * exponential backoff (1 s, 2 s, ... 32 s) and serves the next master.
 * While it cannot reach a master it says so once, then every 30 s with
 * how long it has tried, and how long it took when it connects.
 * With a CURVE key pair and the master's public key every byte is
 * encrypted and the master checks this worker's key; a refusal is said
 * in plain words (once, until a master welcomes it) and the worker keeps
 * retrying with the same backoff (the key may be allowed later).
 */
#ifndef WORKER_LOOP_H
#define WORKER_LOOP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct worker_loop_options {
    const char *endpoint;          /* e.g. tcp://render1:5555 */
    const char *name;              /* NULL: host:pid */
    const char *pool;              /* --pool NAME: jobs of this pool only (NULL: none) */
    bool fail_tiles;               /* testing aid: every tile answered with a Failure */
    int threads;                   /* 0: number of cores */
    size_t cache_bytes;            /* box cache per thread; 0: the job's (unlimited) */
    int verbosity;                 /* -1 quiet, 0 normal, 1 verbose */
    int tile_delay_ms;             /* testing aid: sleep before each tile */
    int prepare_delay_ms;          /* testing aid: sleep before compiling a Job */
    const char *curve_secret;      /* CURVE: this worker's NAME.key_secret, or NULL */
    const char *master_key;        /* CURVE: the master's NAME.key */
    /* job files (file_fetch.h, docs/textures.md) */
    const char *file_cache;        /* the host's store; NULL: the default folder */
    uint64_t file_cache_bytes;     /* its byte budget (0: unlimited) */
    uint32_t file_chunk;           /* bytes per NeedFile (0: 1 MiB) */
    uint64_t file_inflight;        /* bytes asked and not received (0: 8 MiB) */
    int file_delay_ms;             /* testing aid: at least this between NeedFiles */
    int unreachable_report_ms;     /* no master: said again this often (0: 30000;
                                    * AAFARM_WAIT_REPORT_MS, a testing aid) */
} worker_loop_options;

/* Serves masters until told to stop. Returns an AAFARM_EXIT_* code:
 * OK after Shutdown from the master, USAGE for a bad endpoint or a master
 * that refuses this worker (protocol version mismatch: the reason is
 * printed), INTERRUPTED after SIGINT/SIGTERM (a Shutdown is sent first),
 * FAILURE when the sockets or threads cannot be set up. */
int worker_loop_run(const worker_loop_options *opt);

#endif
