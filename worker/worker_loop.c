/*
 * worker_loop.c: the farm side of the worker. Not written yet (issue 5):
 * says so instead of pretending.
 */
#include "worker_loop.h"

#include <stdio.h>

#include "util/exitcodes.h"

int worker_loop_run(const worker_loop_options *opt)
{
    fprintf(stderr, "aafarm-worker: --connect %s: the farm mode is not built yet "
            "(use --standalone)\n", opt->endpoint);
    return AAFARM_EXIT_USAGE;
}
