/*
 * http_server.c: the live monitor's HTTP server (see http_server.h) on GNU
 * libmicrohttpd: one internal polling thread, at most HTTP_MAX_CONNECTIONS
 * connections, idle ones closed after 10 s. The listening socket is made
 * here (so a taken port is reported with its errno) and handed to the
 * library. libmicrohttpd's own log is off: this runs beside the master's
 * loop, and only that loop writes to stderr.
 */
#include "http_server.h"

#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "json_out.h"
#include "monitor_page.h"
#include "util/err.h"
#include "util/xalloc.h"

enum { HTTP_MAX_CONNECTIONS = 32, HTTP_IDLE_S = 10 };

struct http_server {
    struct MHD_Daemon *daemon;
    monitor *mon;
    http_jobs jobs;
    bool has_jobs;
    char token[HTTP_TOKEN_MAX + 1];
    bool has_token;
    int port;
};

/* ---- responses ---- */

static const char *page_policy =
    "default-src 'self'; img-src 'self'; style-src 'self'; script-src 'self'; "
    "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'";

static enum MHD_Result send_bytes(struct MHD_Connection *c, unsigned status, const char *mime,
                                  void *body, size_t len, enum MHD_ResponseMemoryMode mode,
                                  bool page)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, body, mode);
    if (!r) {
        if (mode == MHD_RESPMEM_MUST_FREE) free(body);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, mime);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, page ? "no-cache" : "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
    if (page) MHD_add_response_header(r, "Content-Security-Policy", page_policy);
    if (status == MHD_HTTP_UNAUTHORIZED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"aafarm\"");
    if (status == MHD_HTTP_METHOD_NOT_ALLOWED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD, POST");
    enum MHD_Result ok = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    return ok;
}

/* {"error": "message"} */
static enum MHD_Result send_error(struct MHD_Connection *c, unsigned status, const char *message)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    if (!out) return MHD_NO;
    fputs("{\"error\": ", out);
    json_out_string(out, message);
    fputs("}\n", out);
    if (fclose(out) != 0) {
        free(text);
        return MHD_NO;
    }
    return send_bytes(c, status, "application/json", text, len, MHD_RESPMEM_MUST_FREE, false);
}

/* ---- routes ---- */

typedef enum MHD_Result (*route_fn)(http_server *self, struct MHD_Connection *c);

static enum MHD_Result serve_doc(http_server *self, struct MHD_Connection *c, monitor_doc doc)
{
    size_t len = 0;
    char *text = monitor_doc_copy(self->mon, doc, &len);
    if (!text) return send_error(c, MHD_HTTP_SERVICE_UNAVAILABLE, "the render is starting");
    return send_bytes(c, MHD_HTTP_OK, "application/json", text, len, MHD_RESPMEM_MUST_FREE,
                      false);
}

static enum MHD_Result serve_status(http_server *self, struct MHD_Connection *c)
{
    return serve_doc(self, c, MONITOR_STATUS);
}

static enum MHD_Result serve_workers(http_server *self, struct MHD_Connection *c)
{
    return serve_doc(self, c, MONITOR_WORKERS);
}

static enum MHD_Result serve_image(http_server *self, struct MHD_Connection *c)
{
    const char *arg = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "frame");
    long frame = 0;
    if (arg) {
        char *end = NULL;
        frame = strtol(arg, &end, 10);
        if (!*arg || *end || frame < 0 || frame > 1000000000L)
            return send_error(c, MHD_HTTP_BAD_REQUEST, "frame= wants a frame index: 0, 1, ...");
    }
    void *png = NULL;
    size_t len = 0;
    bool missing = false;
    char err[ERR_LEN];
    if (!monitor_png(self->mon, (int)frame, &png, &len, &missing, err, sizeof err))
        return send_error(c, missing ? MHD_HTTP_NOT_FOUND : MHD_HTTP_GONE, err);
    return send_bytes(c, MHD_HTTP_OK, "image/png", png, len, MHD_RESPMEM_MUST_FREE, false);
}

typedef struct route {
    const char *path;
    route_fn fn;
} route;

/* The API: each needs the token when there is one. */
static const route api_routes[] = {
    {"/api/status", serve_status},
    {"/api/workers", serve_workers},
    {"/api/image.png", serve_image},
};

/* ---- the job queue (--serve) ---- */

/* A POST's body, gathered over the calls libmicrohttpd makes. */
typedef struct upload {
    uint8_t *data;
    size_t len, cap;
    bool too_big;
} upload;

static enum MHD_Result send_answer(struct MHD_Connection *c, unsigned status, char *answer,
                                   size_t len)
{
    if (!answer) return send_error(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "no answer");
    return send_bytes(c, status, "application/json", answer, len, MHD_RESPMEM_MUST_FREE, false);
}

/* "/api/jobs/ID" + rest: the id (-1: not that form). */
static long job_id_of(const char *url, const char *rest)
{
    const char *p = url + strlen("/api/jobs/");
    char *end = NULL;
    if (*p < '0' || *p > '9') return -1;
    long id = strtol(p, &end, 10);
    return strcmp(end, rest) == 0 && id >= 0 ? id : -1;
}

static bool is_jobs_url(const char *url)
{
    return strcmp(url, "/api/jobs") == 0 || strncmp(url, "/api/jobs/", 10) == 0;
}

static enum MHD_Result serve_jobs(http_server *self, struct MHD_Connection *c, const char *url,
                                  bool post, const upload *up)
{
    char *answer = NULL;
    size_t len = 0;
    unsigned status;
    if (!post) {
        long id = strcmp(url, "/api/jobs") == 0 ? -1 : job_id_of(url, "");
        if (id < 0 && strcmp(url, "/api/jobs") != 0)
            return send_error(c, MHD_HTTP_NOT_FOUND, "no such job path: /api/jobs or /api/jobs/ID");
        status = self->jobs.list(self->jobs.arg, id, &answer, &len);
    } else if (strcmp(url, "/api/jobs") == 0) {
        if (up->too_big) {
            char m[160];
            snprintf(m, sizeof m, "the submission is over the %zu bytes this master takes",
                     self->jobs.max_body);
            return send_error(c, MHD_HTTP_CONTENT_TOO_LARGE, m);
        }
        status = self->jobs.submit(self->jobs.arg, up->data, up->len, &answer, &len);
    } else {
        long id = job_id_of(url, "/cancel");
        if (id < 0)
            return send_error(c, MHD_HTTP_NOT_FOUND, "POST /api/jobs (a submission) or "
                              "/api/jobs/ID/cancel");
        status = self->jobs.cancel(self->jobs.arg, id, &answer, &len);
    }
    return send_answer(c, status, answer, len);
}

/* Gathers a POST's body; true while more is to come (the answer waits). */
static bool gather(http_server *self, upload *up, const char *data, size_t *size)
{
    if (!*size) return false;
    if (!up->too_big && up->len + *size <= self->jobs.max_body) {
        if (up->len + *size > up->cap) {
            up->cap = (up->len + *size) * 2 > self->jobs.max_body ? self->jobs.max_body
                                                                   : (up->len + *size) * 2;
            up->data = xrealloc(up->data, up->cap);
        }
        memcpy(up->data + up->len, data, *size);
        up->len += *size;
    } else {
        up->too_big = true;   /* read and dropped: 413 at the end */
    }
    *size = 0;
    return true;
}

static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    (void)cls;
    (void)c;
    (void)toe;
    upload *up = *con_cls;
    if (!up) return;
    free(up->data);
    free(up);
    *con_cls = NULL;
}

static bool authorized(const http_server *self, struct MHD_Connection *c)
{
    if (!self->has_token) return true;
    const char *given = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "token");
    if (given && http_token_equal(self->token, given)) return true;
    const char *auth = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                   MHD_HTTP_HEADER_AUTHORIZATION);
    return auth && strncmp(auth, "Bearer ", 7) == 0 && http_token_equal(self->token, auth + 7);
}

/* A Content-Length over what a submission may be: refused at once. */
static bool too_long(const http_server *self, struct MHD_Connection *c)
{
    const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (!cl) return false;
    char *end = NULL;
    errno = 0;
    unsigned long long n = strtoull(cl, &end, 10);
    return end != cl && (errno == ERANGE || n > self->jobs.max_body);
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_data_size,
                                  void **con_cls)
{
    (void)version;
    http_server *self = cls;
    bool post = strcmp(method, MHD_HTTP_METHOD_POST) == 0;
    if (post && self->has_jobs && is_jobs_url(url)) {
        if (!*con_cls) {   /* the first call: the headers only */
            if (!authorized(self, c))
                return send_error(c, MHD_HTTP_UNAUTHORIZED, "this master needs its token: "
                                  "?token=TOKEN or Authorization: Bearer TOKEN (--http-token)");
            if (too_long(self, c)) {   /* said before the body is read */
                char m[160];
                snprintf(m, sizeof m, "the submission is over the %zu bytes this master takes",
                         self->jobs.max_body);
                return send_error(c, MHD_HTTP_CONTENT_TOO_LARGE, m);
            }
            *con_cls = xcalloc(1, sizeof(upload));
            return MHD_YES;
        }
        if (gather(self, *con_cls, upload_data, upload_data_size)) return MHD_YES;
        return serve_jobs(self, c, url, true, *con_cls);
    }
    if (strcmp(method, MHD_HTTP_METHOD_GET) != 0 && strcmp(method, MHD_HTTP_METHOD_HEAD) != 0)
        return send_error(c, MHD_HTTP_METHOD_NOT_ALLOWED,
                          self->has_jobs ? "the master answers GET and HEAD, and POST on "
                          "/api/jobs" : "the monitor answers GET and HEAD");
    if (*upload_data_size) *upload_data_size = 0;   /* a GET's body is ignored */
    for (size_t i = 0; i < sizeof api_routes / sizeof *api_routes; i++) {
        if (strcmp(url, api_routes[i].path) != 0) continue;
        if (!authorized(self, c))
            return send_error(c, MHD_HTTP_UNAUTHORIZED, "this monitor needs its token: "
                              "?token=TOKEN or Authorization: Bearer TOKEN (--http-token)");
        return api_routes[i].fn(self, c);
    }
    if (self->has_jobs && is_jobs_url(url)) {
        if (!authorized(self, c))
            return send_error(c, MHD_HTTP_UNAUTHORIZED, "this master needs its token: "
                              "?token=TOKEN or Authorization: Bearer TOKEN (--http-token)");
        return serve_jobs(self, c, url, false, NULL);
    }
    const char *path = strcmp(url, "/") == 0 ? "/index.html" : url;
    for (int i = 0; i < monitor_page_nfiles; i++)
        if (strcmp(path, monitor_page_files[i].path) == 0)
            return send_bytes(c, MHD_HTTP_OK, monitor_page_files[i].mime,
                              (void *)monitor_page_files[i].data, monitor_page_files[i].len,
                              MHD_RESPMEM_PERSISTENT, true);
    return send_error(c, MHD_HTTP_NOT_FOUND, "no such page: the monitor has /, /api/status, "
                      "/api/workers and /api/image.png?frame=N");
}

/* ---- the server ---- */

static int listen_on(const http_addr *addr, int *port, char *err, size_t errsz)
{
    char where[96];
    snprintf(where, sizeof where, "%s:%d", addr->host, addr->port);
    int fd = socket(addr->family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        err_set(err, errsz, "--http %s: cannot make a socket: %s", where, strerror(errno));
        return -1;
    }
    int on = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (addr->family == AF_INET6) setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &on, sizeof on);
    if (bind(fd, (const struct sockaddr *)&addr->sa, addr->len) != 0 || listen(fd, 64) != 0) {
        err_set(err, errsz, "--http %s: cannot listen there: %s%s", where, strerror(errno),
                errno == EADDRINUSE ? " (another program has that port: pick another one, or 0 "
                                      "for any free port)" : "");
        close(fd);
        return -1;
    }
    struct sockaddr_storage got;
    socklen_t len = sizeof got;
    *port = addr->port;
    if (getsockname(fd, (struct sockaddr *)&got, &len) == 0)
        *port = ntohs(got.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&got)->sin6_port
                                                : ((struct sockaddr_in *)&got)->sin_port);
    return fd;
}

http_server *http_server_start(const http_addr *addr, const char *token, monitor *mon,
                               const http_jobs *jobs, char *err, size_t errsz)
{
    int port = 0;
    int fd = listen_on(addr, &port, err, errsz);
    if (fd < 0) return NULL;
    http_server *self = xcalloc(1, sizeof *self);
    self->mon = mon;
    self->port = port;
    if (jobs) {
        self->jobs = *jobs;
        self->has_jobs = true;
    }
    if (token) {
        snprintf(self->token, sizeof self->token, "%s", token);
        self->has_token = true;
    }
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL;
    if (addr->family == AF_INET6) flags |= MHD_USE_IPv6;
    self->daemon = MHD_start_daemon(flags, 0, NULL, NULL, on_request, self,
                                    MHD_OPTION_LISTEN_SOCKET, fd,
                                    MHD_OPTION_CONNECTION_LIMIT, (unsigned)HTTP_MAX_CONNECTIONS,
                                    MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)HTTP_IDLE_S,
                                    MHD_OPTION_NOTIFY_COMPLETED, on_completed, NULL,
                                    MHD_OPTION_END);
    if (!self->daemon) {
        err_set(err, errsz, "--http %s:%d: the HTTP server (libmicrohttpd) did not start",
                addr->host, port);
        close(fd);
        free(self);
        return NULL;
    }
    return self;
}

int http_server_port(const http_server *self)
{
    return self->port;
}

void http_server_stop(http_server **self_p)
{
    http_server *self = *self_p;
    if (!self) return;
    MHD_stop_daemon(self->daemon);   /* joins its thread, closes the socket */
    memset(self->token, 0, sizeof self->token);
    free(self);
    *self_p = NULL;
}
