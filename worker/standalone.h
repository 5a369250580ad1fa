/*
 * standalone.h: `aafarm-worker --standalone`: the whole image rendered in
 * this one process by a pool of threads over tiles, written as the same
 * tiled EXR the farm writes. This is the reference every farm render must
 * equal pixel for pixel.
 */
#ifndef WORKER_STANDALONE_H
#define WORKER_STANDALONE_H

#include <stdbool.h>
#include <stddef.h>

#include "job/job.h"

typedef struct standalone_options {
    const char *scene_path;
    const char *output;            /* OUT.exr, a pattern (out.%04d.exr), or NULL:
                                      each frame's Display (job/frames.h) */
    const char *frames;            /* --frames "1,3,5-7", NULL: all */
    const char *preview;           /* OUT.png or NULL */
    const char *stats_json;        /* FILE or NULL */
    bool stats;                    /* print statistics */
    int threads;                   /* 0: number of cores */
    size_t cache_bytes;            /* per thread; 0: unlimited */
    int verbosity;                 /* -1 quiet, 0 normal, 1 verbose */
    job_options job;
} standalone_options;

/* Returns an AAFARM_EXIT_* code (util/exitcodes.h). */
int worker_standalone(const standalone_options *opt);

#endif
