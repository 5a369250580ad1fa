/*
 * http_server.h: the master's live monitor over HTTP (--http; docs/farm.md
 * "Watching a render"), on GNU libmicrohttpd: its own thread answers
 * requests from the monitor (monitor.h: copies of what the master's loop
 * published, taken under the monitor's lock), never from the master's
 * state.
 *
 *   GET /                     the page (monitor_page/, embedded)
 *   GET /monitor.js, .css     its script and style
 *   GET /api/status           JSON: the job, tiles, rate, ETA, warnings, log
 *   GET /api/workers          JSON: the worker table
 *   GET /api/image.png?frame=N  the image of frame N (index, default 0) so far
 *
 * GET and HEAD only (405 otherwise). With a token (http_access.h) every
 * /api/ request must carry it (401 otherwise); the page and its script
 * carry no data. Routes are a table (http_server.c), so a job queue's
 * endpoints can be added beside these.
 */
#ifndef MASTER_HTTP_SERVER_H
#define MASTER_HTTP_SERVER_H

#include <stdbool.h>
#include <stddef.h>

#include "http_access.h"
#include "monitor.h"

typedef struct http_server http_server;

/* A serving master's job queue (serve.c), answered on the server's thread:
 *
 *   GET  /api/jobs             list(-1): {"jobs": [...]}
 *   GET  /api/jobs/ID          list(ID): the job
 *   POST /api/jobs             submit(body): {"id": N} (body: bundle.h)
 *   POST /api/jobs/ID/cancel   cancel(ID)
 *
 * Each returns the HTTP status and sets *answer to a JSON text (malloc'd). */
typedef struct http_jobs {
    void *arg;
    size_t max_body;               /* bytes a submission may have (413 beyond) */
    unsigned (*submit)(void *arg, const void *body, size_t len, char **answer, size_t *alen);
    unsigned (*list)(void *arg, long id, char **answer, size_t *alen);
    unsigned (*cancel)(void *arg, long id, char **answer, size_t *alen);
} http_jobs;

/* Listens on addr and serves mon (which must outlive the server) and,
 * when jobs is not NULL, the job queue (copied; its arg must outlive the
 * server); token NULL: none needed (loopback, main.c checks). NULL with a
 * message when the address cannot be bound. */
http_server *http_server_start(const http_addr *addr, const char *token, monitor *mon,
                               const http_jobs *jobs, char *err, size_t errsz);

/* The port listened on (the one chosen for port 0). */
int http_server_port(const http_server *self);

/* Stops the server: its thread has ended when this returns. */
void http_server_stop(http_server **self_p);

#endif
