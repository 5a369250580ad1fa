/*
 * exitcodes.h: the exit statuses of every aafarm program (documented in
 * README.md "Exit codes" and docs/farm.md), so scripts can tell what went
 * wrong without parsing messages.
 */
#ifndef UTIL_EXITCODES_H
#define UTIL_EXITCODES_H

enum {
    AAFARM_EXIT_OK = 0,           /* the image (or check) is complete */
    AAFARM_EXIT_FAILURE = 1,      /* the render failed (a shader over its budget,
                                     a disk error, no workers left ...) */
    AAFARM_EXIT_USAGE = 2,        /* bad command line */
    AAFARM_EXIT_INPUT = 3,        /* bad scene or shader (diagnostics printed) */
    AAFARM_EXIT_NO_WORKERS = 4,   /* aafarm-master --wait-timeout: too few workers
                                     joined in time (the journal is kept) */
    AAFARM_EXIT_INTERRUPTED = 130 /* SIGINT / SIGTERM: nothing written */
};

#endif
