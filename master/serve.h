/*
 * serve.h: aafarm-master --serve, a master that renders a queue of jobs
 * (serve.c; docs/farm.md "A job queue").
 */
#ifndef MASTER_SERVE_H
#define MASTER_SERVE_H

#include "farm.h"

/* Serves the queue in the SQLite database db_path until SIGINT/SIGTERM
 * (AAFARM_EXIT_INTERRUPTED), or an exit code when it cannot start or its
 * local workers are all gone. opt: as for farm_run, without a scene. */
int farm_serve(const farm_options *opt, const char *db_path);

#endif
