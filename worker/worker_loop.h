/*
 * worker_loop.h: `aafarm-worker --connect`: the farm side of a worker
 * (docs/protocol.md has the state machine).
 */
#ifndef WORKER_LOOP_H
#define WORKER_LOOP_H

#include <stddef.h>

typedef struct worker_loop_options {
    const char *endpoint;
    const char *name;
    int threads;
    size_t cache_bytes;
    int verbosity;
} worker_loop_options;

int worker_loop_run(const worker_loop_options *opt);

#endif
