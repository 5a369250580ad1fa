/*
 * file_fetch.c: the files of waiting jobs, looked up in the host's store
 * and fetched from the master chunk by chunk (see file_fetch.h).
 *
 * A `want` is one file (by hash) some waiting job lacks: fetched by this
 * process (a transfer), or by another process of the host (busy: polled
 * every POLL_MS). When it is whole in the store every waiting job that
 * names it acquires it.
 */
#include "file_fetch.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "file_store.h"
#include "util/err.h"
#include "util/xalloc.h"

enum { POLL_MS = 100, MAX_ATTEMPTS = 3 };

typedef struct want {
    char sha256[HASH_HEX_SIZE];
    uint64_t size;
    char job_hash[HASH_HEX_SIZE];  /* a waiting job that names it (for NeedFile) */
    file_transfer *t;              /* ours; NULL: not started, or busy elsewhere */
    int64_t next_poll_ms;
    int attempts;                  /* transfers whose bytes did not hash right */
    bool complete;                 /* every chunk written: to be checked (poll) */
    struct want *next;
} want;

struct file_fetch {
    file_fetch_options opt;
    char dir[PATH_MAX];
    file_store *store;             /* opened with the first job that has files */
    fetch_job *jobs;               /* waiting, in arrival order */
    want *wants;
    uint64_t inflight;             /* bytes asked for and not received */
    int64_t next_send_ms;
};

file_fetch *file_fetch_new(const file_fetch_options *opt)
{
    file_fetch *self = xcalloc(1, sizeof *self);
    self->opt = *opt;
    if (!self->opt.chunk) self->opt.chunk = 1u << 20;
    if (!self->opt.inflight) self->opt.inflight = 8u << 20;
    if (opt->dir) snprintf(self->dir, sizeof self->dir, "%s", opt->dir);
    else file_store_default_dir(self->dir, sizeof self->dir);
    return self;
}

void fetch_job_destroy(fetch_job **self_p)
{
    fetch_job *j = *self_p;
    if (!j) return;
    for (int i = 0; i < j->nfiles; i++) {
        file_store_release(j->fds[i]);
        free(j->paths[i]);
    }
    free(j->paths);
    free(j->fds);
    proto_saved_job_destroy(&j->msg);
    free(j);
    *self_p = NULL;
}

static void want_free(want *w)
{
    file_transfer_abandon(&w->t);
    free(w);
}

void file_fetch_destroy(file_fetch **self_p)
{
    file_fetch *self = *self_p;
    if (!self) return;
    file_fetch_drop(self, NULL);
    file_store_close(&self->store);
    free(self);
    *self_p = NULL;
}

bool file_fetch_waiting(const file_fetch *self, const char *hash)
{
    for (const fetch_job *j = self->jobs; j; j = j->next)
        if (strcmp(j->hash, hash) == 0) return true;
    return false;
}

static want *find_want(const file_fetch *self, const char *sha)
{
    for (want *w = self->wants; w; w = w->next)
        if (strcmp(w->sha256, sha) == 0) return w;
    return NULL;
}

static void job_fail(fetch_job *j, const char *fmt, const char *a, const char *b)
{
    if (j->error[0]) return;
    int n = snprintf(j->error, sizeof j->error, fmt, a, b);
    if (n < 0) j->error[0] = '?';
}

void file_fetch_add(file_fetch *self, const proto_job *m, int64_t now_ms)
{
    (void)now_ms;
    if (file_fetch_waiting(self, m->job_hash)) return;
    fetch_job *j = xcalloc(1, sizeof *j);
    snprintf(j->hash, sizeof j->hash, "%s", m->job_hash);
    j->msg = proto_saved_job_new(m);
    j->nfiles = (int)m->n_files;
    j->paths = xcalloc((size_t)j->nfiles + 1, sizeof *j->paths);
    j->fds = xcalloc((size_t)j->nfiles + 1, sizeof *j->fds);
    for (int i = 0; i < j->nfiles; i++) j->fds[i] = -1;
    fetch_job **tail = &self->jobs;
    while (*tail) tail = &(*tail)->next;
    *tail = j;
    if (j->nfiles == 0) return;
    char err[ERR_LEN];
    if (!self->store && !(self->store = file_store_open(self->dir, self->opt.budget, err,
                                                         sizeof err))) {
        job_fail(j, "job %.12s...: %s", j->hash, err);
        return;
    }
    for (int i = 0; i < j->nfiles; i++) {
        const proto_file_ref *f = &m->files[i];
        char path[PATH_MAX + 100];
        j->fds[i] = file_store_acquire(self->store, f->sha256, f->size, path, sizeof path);
        if (j->fds[i] >= 0) {
            j->paths[i] = xstrdup(path);
            j->hits++;
            continue;
        }
        j->misses++;
        if (find_want(self, f->sha256)) continue;
        want *w = xcalloc(1, sizeof *w);
        snprintf(w->sha256, sizeof w->sha256, "%s", f->sha256);
        w->size = f->size;
        snprintf(w->job_hash, sizeof w->job_hash, "%s", j->hash);
        w->next = self->wants;
        self->wants = w;
    }
}

/* Every waiting job that names the file takes it from the store. */
static void deliver(file_fetch *self, const char *sha)
{
    for (fetch_job *j = self->jobs; j; j = j->next) {
        if (j->error[0]) continue;
        const proto_job *m = proto_saved_job_get(j->msg);
        for (int i = 0; i < j->nfiles; i++) {
            if (j->fds[i] >= 0 || strcmp(m->files[i].sha256, sha) != 0) continue;
            char path[PATH_MAX + 100];
            j->fds[i] = file_store_acquire(self->store, sha, m->files[i].size, path, sizeof path);
            if (j->fds[i] >= 0) j->paths[i] = xstrdup(path);
        }
    }
    file_store_evict(self->store);
}

/* Does a waiting job still lack the file? */
static const fetch_job *needing(const file_fetch *self, const want *w)
{
    for (const fetch_job *j = self->jobs; j; j = j->next) {
        if (j->error[0]) continue;
        const proto_job *m = proto_saved_job_get(j->msg);
        bool needs = false;
        for (int i = 0; i < j->nfiles && !needs; i++)
            needs = j->fds[i] < 0 && strcmp(m->files[i].sha256, w->sha256) == 0;
        if (needs) return j;
    }
    return NULL;
}

/* Removes the wants no waiting job needs any more (delivered, or their
 * jobs dropped); the others name a job still waiting. */
static void prune(file_fetch *self)
{
    for (want **at = &self->wants; *at;) {
        want *w = *at;
        const fetch_job *j = needing(self, w);
        if (j) {
            snprintf(w->job_hash, sizeof w->job_hash, "%s", j->hash);
            at = &w->next;
            continue;
        }
        *at = w->next;
        want_free(w);
    }
    if (!self->wants) self->inflight = 0;
}

static void fail_file(file_fetch *self, const want *w, const char *why)
{
    for (fetch_job *j = self->jobs; j; j = j->next) {
        if (j->error[0]) continue;
        const proto_job *m = proto_saved_job_get(j->msg);
        for (int i = 0; i < j->nfiles; i++)
            if (j->fds[i] < 0 && strcmp(m->files[i].sha256, w->sha256) == 0)
                job_fail(j, "a file of this job (%.12s...) cannot be had: %s", w->sha256, why);
    }
}

static void finish(file_fetch *self, want *w, int64_t now_ms);

/* Starts the transfer of a file nobody here fetches yet, or takes it from
 * the store when another process has finished it. */
static void start(file_fetch *self, want *w, int64_t now_ms)
{
    char path[PATH_MAX + 100], err[ERR_LEN];
    int fd = file_store_acquire(self->store, w->sha256, w->size, path, sizeof path);
    if (fd >= 0) {
        file_store_release(fd);
        deliver(self, w->sha256);
        return;
    }
    switch (file_store_begin(self->store, w->sha256, w->size, self->opt.chunk, &w->t, err,
                             sizeof err)) {
    case FILE_BEGIN_STARTED:
        if (file_transfer_complete(w->t)) finish(self, w, now_ms);   /* a dead process wrote all */
        break;
    case FILE_BEGIN_PRESENT: deliver(self, w->sha256); break;
    case FILE_BEGIN_BUSY: w->next_poll_ms = now_ms + POLL_MS; break;
    case FILE_BEGIN_ERROR: fail_file(self, w, err); break;
    }
}

bool file_fetch_poll_due(const file_fetch *self, int64_t now_ms)
{
    for (const want *w = self->wants; w; w = w->next)
        if (w->complete || (!w->t && now_ms >= w->next_poll_ms)) return true;
    return false;
}

/* A transfer with every chunk written: hashed, into the store. */
static void finish(file_fetch *self, want *w, int64_t now_ms)
{
    char err[ERR_LEN];
    w->complete = false;
    if (file_transfer_finish(&w->t, err, sizeof err) == 0) deliver(self, w->sha256);
    else if (++w->attempts >= MAX_ATTEMPTS) fail_file(self, w, err);
    else w->next_poll_ms = now_ms;   /* fetched again from the start */
}

void file_fetch_poll(file_fetch *self, int64_t now_ms)
{
    for (want *w = self->wants; w; w = w->next) {
        if (w->complete) finish(self, w, now_ms);
        else if (!w->t && now_ms >= w->next_poll_ms) start(self, w, now_ms);
    }
    prune(self);
}

void file_fetch_pump(file_fetch *self, int64_t now_ms, file_fetch_send_fn send, void *arg)
{
    if (!self->wants) return;
    bool sent = true;
    while (sent && now_ms >= self->next_send_ms &&
           (self->inflight == 0 || self->inflight + self->opt.chunk <= self->opt.inflight)) {
        sent = false;
        for (want *w = self->wants; w && !sent; w = w->next) {
            uint64_t off;
            uint32_t len;
            if (!w->t || w->complete || !file_transfer_next(w->t, &off, &len)) continue;
            if (!send(arg, w->job_hash, w->sha256, off, len)) {
                file_transfer_unask(w->t, off);
                return;   /* the socket is full: later */
            }
            self->inflight += len;
            sent = true;
            if (self->opt.delay_ms > 0) self->next_send_ms = now_ms + self->opt.delay_ms;
        }
    }
}

uint64_t file_fetch_chunk(file_fetch *self, const proto_file_chunk *c, const uint8_t *data,
                          size_t len, int64_t now_ms)
{
    want *w = find_want(self, c->sha256);
    if (!w || !w->t || w->complete || c->file_size != w->size) return 0;
    char err[ERR_LEN];
    long n = file_transfer_put(w->t, c->offset, data, len, err, sizeof err);
    if (n < 0) {
        file_transfer_abandon(&w->t);
        fail_file(self, w, err);
        prune(self);
        return 0;
    }
    self->inflight = self->inflight > (uint64_t)n ? self->inflight - (uint64_t)n : 0;
    if (n == 0) return 0;
    for (fetch_job *j = self->jobs; j; j = j->next)
        if (strcmp(j->hash, w->job_hash) == 0) j->fetched += (uint64_t)n;
    (void)now_ms;
    if (file_transfer_complete(w->t)) w->complete = true;   /* checked by file_fetch_poll */
    return (uint64_t)n;
}

fetch_job *file_fetch_take_ready(file_fetch *self)
{
    for (fetch_job **at = &self->jobs; *at; at = &(*at)->next) {
        fetch_job *j = *at;
        bool ready = true;
        for (int i = 0; i < j->nfiles && ready; i++) ready = j->fds[i] >= 0;
        if (!ready && !j->error[0]) continue;
        *at = j->next;
        j->next = NULL;
        prune(self);
        return j;
    }
    return NULL;
}

void file_fetch_drop(file_fetch *self, const char *hash)
{
    for (fetch_job **at = &self->jobs; *at;) {
        fetch_job *j = *at;
        if (hash && strcmp(j->hash, hash) != 0) {
            at = &j->next;
            continue;
        }
        *at = j->next;
        fetch_job_destroy(&j);
    }
    prune(self);
}

void file_fetch_rewind(file_fetch *self)
{
    for (want *w = self->wants; w; w = w->next)
        if (w->t) file_transfer_rewind(w->t);
    self->inflight = 0;
}
