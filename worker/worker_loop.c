/*
 * worker_loop.c: the worker's connection loop, the state machine of
 * docs/protocol.md ("The worker's state machine"), Paranoid Pirate style
 * (ZeroMQ Guide, ch. 4):
 *
 *   CONNECTING  new DEALER, connect, Hello
 *   READY       Welcome: Ask(credits = pipeline target - leases held)
 *   WORKING     Grant -> task on the pool (or NeedJob and wait for the
 *               Job, and for its files: NeedFile -> FileChunk until the
 *               host's store has them all, then FilesReady); each
 *               finished tile -> Result + EXR, or Failure;
 *               Ask again as threads free up; Heartbeat when quiet
 *   BACKOFF     master silent for liveness x interval (or no Welcome):
 *               close, drop leases, wait 1, 2, 4 ... 32 s, reconnect
 *   FATAL       Reject VERSION_MISMATCH / REFUSED, or a Welcome of another
 *               protocol version: print the reason, exit 2
 *
 * Only this thread touches the socket; render threads report through the
 * pool's pipe, which sits in the same zmq_poll set.
 *
 * Preparing a Job (parse, compile, build the scene) can take seconds for a
 * large scene. It runs on a helper thread while this thread goes on
 * heartbeating and sending finished tiles, so the master does not take a
 * slow preparation for a dead worker (issue 12). Messages that arrive
 * meanwhile wait in the socket's queue (their arrival counts as a sign of
 * the master's life) and are handled when the job is ready. SIGINT or
 * SIGTERM meanwhile: Shutdown to the master, then exit 130 at once.
 */
#include "worker_loop.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <zmq.h>

#include "curve_cert.h"
#include "file_fetch.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "version.h"
#include "wire.h"
#include "worker_jobs.h"
#include "worker_pool.h"
#include "util/xalloc.h"

enum { MAX_JOBS_HELD = 4, BACKOFF_FIRST_MS = 1000, BACKOFF_MAX_MS = 32000,
       UNREACHABLE_REPORT_MS = 30000 };

typedef enum session_end {
    SESSION_LOST,          /* the master went silent: back off, reconnect */
    SESSION_FATAL,         /* refused: exit */
    SESSION_SHUTDOWN,      /* the master said so */
    SESSION_INTERRUPTED    /* SIGINT / SIGTERM */
} session_end;

/* A grant whose job has not arrived yet. */
typedef struct pending_grant {
    uint64_t lease_id;
    uint32_t tile_index;
    image_rect rect;
    char hash[HASH_HEX_SIZE];
    struct pending_grant *next;
} pending_grant;

typedef struct worker_loop {
    const worker_loop_options *opt;
    char name[128], host[128];
    int threads, target;           /* target: leases wanted (2 per thread) */
    void *ctx, *dealer;
    worker_pool *pool;
    worker_jobs *jobs;
    file_fetch *files;             /* jobs waiting for their files */
    proto_limits limits;
    wire_stats wstats;
    /* the current session */
    bool welcomed, ever_welcomed;
    uint64_t master_session;
    int heartbeat_ms, liveness;
    int64_t last_heard_ms, last_sent_ms;
    uint32_t asked;                /* credits the master still owes us */
    pending_grant *pending;
    worker_task *outbox;           /* finished tiles the socket could not take yet */
    session_end end;
    char fatal[ERR_LEN];
    int64_t drop_logged_ms;
    uint64_t tiles_sent, failures_sent;
    /* CURVE (opt->curve_secret): this worker's keys and the master's */
    bool curve;
    curve_cert own, master;
    wire_monitor *monitor;         /* handshake failures: refused keys */
    uint64_t file_received;        /* FileChunk bytes since the last Welcome */
    bool handshake_said;           /* a failed handshake was reported since the last Welcome */
    /* no master: said once, then every report interval, not at each retry */
    bool trying;                   /* no Welcome since trying_since_ms */
    bool unreachable_said;         /* "cannot reach" was said for this stretch */
    int64_t trying_since_ms, unreachable_said_ms;
    int report_ms;                 /* opt->unreachable_report_ms or UNREACHABLE_REPORT_MS */
} worker_loop;

/* Set by SIGINT/SIGTERM (a lock-free atomic: safe in a handler); the loop
 * and a job's preparation (worker_jobs_new's cancel) look at it. */
static atomic_int interrupted;

static void on_signal(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
}

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void wlog(const worker_loop *w, int level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void wlog(const worker_loop *w, int level, const char *fmt, ...)
{
    if (level > w->opt->verbosity) return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "aafarm-worker %s: ", w->name);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* ---- sending ---- */

static int send_msg(worker_loop *w, const proto_msg *msg, const void *bulk, size_t len,
                    char *err, size_t errsz)
{
    if (wire_send_limited(w->dealer, &w->limits, NULL, 0, msg, bulk, len, err, errsz) != 0)
        return -1;
    w->last_sent_ms = now_ms();
    return 0;
}

static void send_hello(worker_loop *w)
{
    char *held[MAX_JOBS_HELD];
    proto_msg msg = {.kind = PROTO_HELLO};
    proto_hello *h = &msg.hello;
    h->protocol_version = AAFARM_PROTOCOL_VERSION;
    h->worker_name = w->name;
    h->host = w->host;
    h->pid = (uint32_t)getpid();
    h->threads = (uint32_t)w->threads;
    h->n_jobs_held = worker_jobs_hashes(w->jobs, held, MAX_JOBS_HELD);
    h->jobs_held = (const char *const *)held;
    h->software = "aafarm 0.1.0";
    h->pool = w->opt->pool;
    char err[ERR_LEN];
    if (send_msg(w, &msg, NULL, 0, err, sizeof err) != 0)
        wlog(w, -1, "cannot send Hello: %s", err);
}

static void send_ask(worker_loop *w, uint32_t credits)
{
    proto_msg msg = {.kind = PROTO_ASK, .ask = {credits}};
    if (send_msg(w, &msg, NULL, 0, NULL, 0) == 0) w->asked += credits;
}

static void send_need_job(worker_loop *w, const char *hash, uint64_t lease)
{
    proto_msg msg = {.kind = PROTO_NEED_JOB, .need_job = {hash, lease}};
    send_msg(w, &msg, NULL, 0, NULL, 0);
}

/* file_fetch's way out: one NeedFile. */
static bool send_need_file(void *arg, const char *job_hash, const char *file_hash, uint64_t offset,
                           uint32_t length)
{
    worker_loop *w = arg;
    proto_msg msg = {.kind = PROTO_NEED_FILE,
                     .need_file = {job_hash, file_hash, offset, length, w->file_received}};
    return send_msg(w, &msg, NULL, 0, NULL, 0) == 0;
}

static void send_files_ready(worker_loop *w, const fetch_job *j)
{
    proto_msg msg = {.kind = PROTO_FILES_READY,
                     .files_ready = {j->hash, j->hits, j->misses, j->fetched}};
    send_msg(w, &msg, NULL, 0, NULL, 0);
}

static void send_failure(worker_loop *w, const char *hash, uint64_t lease, uint32_t tile,
                         const char *message, bool retryable)
{
    const char *text = message && *message ? message : "unknown error";
    proto_msg msg = {.kind = PROTO_FAILURE,
                     .failure = {hash, lease, tile, text, retryable}};
    if (send_msg(w, &msg, NULL, 0, NULL, 0) == 0) w->failures_sent++;
    wlog(w, 0, "tile %u failed: %s", tile, text);
}

static void send_heartbeat(worker_loop *w)
{
    uint64_t leases[4096];
    size_t n = worker_pool_leases(w->pool, leases, 4096);
    for (pending_grant *p = w->pending; p && n < 4096; p = p->next) leases[n++] = p->lease_id;
    proto_msg msg = {.kind = PROTO_HEARTBEAT, .heartbeat = {n, leases}};
    send_msg(w, &msg, NULL, 0, NULL, 0);
}

static void send_shutdown(worker_loop *w, const char *reason)
{
    proto_msg msg = {.kind = PROTO_SHUTDOWN, .shutdown = {reason}};
    send_msg(w, &msg, NULL, 0, NULL, 0);
}

/* A finished task: Result + EXR, or Failure. False when the socket's queue
 * is full (try again later). */
static bool send_task(worker_loop *w, worker_task *t)
{
    if (!t->ok) {
        send_failure(w, t->job->hash, t->lease_id, t->tile_index, t->error, true);
        return true;
    }
    proto_msg msg = {.kind = PROTO_RESULT};
    proto_result *r = &msg.result;
    r->stats = (proto_tile_stats){
        .rays = t->stats.rays,
        .boxes = t->stats.boxes,
        .shader_evals = t->stats.shader_evals,
        .cache_hits = t->stats.cache_hits,
        .cache_misses = t->stats.cache_misses,
        .cache_evictions = t->stats.cache_evictions,
        .peak_cache_bytes = t->stats.peak_cache_bytes,
        .cpu_seconds = t->stats.cpu_seconds,
        .wall_seconds = t->stats.wall_seconds,
        .nonfinite_samples = t->stats.nonfinite_samples,
    };
    r->job_hash = t->job->hash;
    r->lease_id = t->lease_id;
    r->tile_index = t->tile_index;
    r->exr_bytes = t->exr_len;
    char err[ERR_LEN];
    if (send_msg(w, &msg, t->exr, t->exr_len, err, sizeof err) != 0) {
        if (errno == EAGAIN) return false;
        wlog(w, -1, "cannot send tile %u: %s", t->tile_index, err);
        return true;
    }
    w->tiles_sent++;
    wlog(w, 1, "tile %u sent (lease %llu, %zu bytes, %.3f s, %llu blocks by idle threads)",
         t->tile_index, (unsigned long long)t->lease_id, t->exr_len, t->stats.wall_seconds,
         (unsigned long long)t->stats.helped_blocks);
    return true;
}

/* ---- leases ---- */

static int pending_count(const worker_loop *w)
{
    int n = 0;
    for (const pending_grant *p = w->pending; p; p = p->next) n++;
    return n;
}

static void drop_pending(worker_loop *w, const char *hash)
{
    for (pending_grant **at = &w->pending; *at;) {
        pending_grant *p = *at;
        if (hash && strcmp(p->hash, hash) != 0) {
            at = &p->next;
            continue;
        }
        *at = p->next;
        free(p);
    }
}

static void free_outbox(worker_loop *w)
{
    while (w->outbox) {
        worker_task *t = w->outbox;
        w->outbox = t->next;
        worker_task_destroy(&t);
    }
}

/* Forgets every lease: the master that granted them is gone or has
 * forgotten this connection. Running tiles finish and are dropped. */
static void drop_all_leases(worker_loop *w)
{
    worker_pool_cancel(w->pool, NULL);
    drop_pending(w, NULL);
    free_outbox(w);
    w->asked = 0;
}

/* Checks the grant's rectangle against the job's tile grid, then queues
 * it on the pool. */
static void start_tile(worker_loop *w, held_job *h, uint64_t lease, uint32_t tile,
                       image_rect rect)
{
    if (h->broken) {
        send_failure(w, h->hash, lease, tile, h->error, true);
        return;
    }
    int tx, ty;
    char err[ERR_LEN];
    if (!image_format_tile_index(&h->fmt, rect, &tx, &ty, err, sizeof err) ||
        (uint32_t)(ty * image_format_tiles_x(&h->fmt) + tx) != tile) {
        char msg[ERR_LEN];
        snprintf(msg, sizeof msg, "Grant for tile %u: the rectangle (%d,%d) %dx%d is not that "
                 "tile of the job's image", tile, rect.x0, rect.y0, rect.w, rect.h);
        send_failure(w, h->hash, lease, tile, msg, false);
        return;
    }
    if (w->opt->fail_tiles) {
        send_failure(w, h->hash, lease, tile, "failing on purpose (--fail-tiles)", true);
        return;
    }
    worker_pool_submit(w->pool, worker_task_new(lease, tile, rect, h));
}

/* ---- messages from the master ---- */

static void on_welcome(worker_loop *w, const proto_welcome *m)
{
    if (proto_version_check(m->protocol_version, AAFARM_PROTOCOL_VERSION, w->fatal,
                            sizeof w->fatal) != 0) {
        err_prefix(w->fatal, sizeof w->fatal, "the master at %s cannot serve this worker",
                   w->opt->endpoint);
        w->end = SESSION_FATAL;
        return;
    }
    drop_all_leases(w);   /* a new registration at the master: old leases are void */
    /* and the jobs waiting for files: the master sends the Job again with
     * its next Grant, and the transfers resume from the chunks written */
    file_fetch_drop(w->files, NULL);
    w->file_received = 0;
    if (w->master_session && w->master_session != m->master_session)
        wlog(w, 0, "a new master at %s", w->opt->endpoint);
    w->master_session = m->master_session;
    w->heartbeat_ms = (int)m->heartbeat_ms;
    w->liveness = (int)m->heartbeat_liveness;
    w->welcomed = w->ever_welcomed = true;
    char after[64] = "";
    if (w->unreachable_said)   /* it said it could not: how long it took */
        snprintf(after, sizeof after, " after %.0f s",
                 (double)(now_ms() - w->trying_since_ms) / 1000.0);
    w->trying = w->unreachable_said = false;
    w->handshake_said = false;   /* a refusal after this one is news again */
    wlog(w, 0, "connected to master %s at %s%s (heartbeat %d ms x %d)",
         m->master_name && *m->master_name ? m->master_name : "?", w->opt->endpoint, after,
         w->heartbeat_ms, w->liveness);
}

static void on_reject(worker_loop *w, const proto_reject *m)
{
    if (m->code == PROTO_REJECT_HELLO_FIRST) {
        wlog(w, 0, "the master does not know this connection: saying Hello again");
        drop_all_leases(w);
        w->welcomed = false;
        send_hello(w);
        return;
    }
    snprintf(w->fatal, sizeof w->fatal, "the master at %s refused this worker: %s",
             w->opt->endpoint, m->reason);
    w->end = SESSION_FATAL;
}

static void send_finished(worker_loop *w);

/* Work that may take seconds (compiling a job, hashing a large file) runs
 * on a helper thread while this one goes on heartbeating and sending
 * finished tiles (only the helper touches the job list and the file store
 * meanwhile; only this thread touches the socket). */
typedef struct beside {
    void (*fn)(void *arg);
    void *arg;
    atomic_bool done;
} beside;

static void *beside_thread(void *arg)
{
    beside *b = arg;
    b->fn(b->arg);
    atomic_store(&b->done, true);
    return NULL;
}

static void run_beside(worker_loop *w, void (*fn)(void *arg), void *arg, const char *what)
{
    beside b = {fn, arg, false};
    pthread_t tid;
    if (pthread_create(&tid, NULL, beside_thread, &b) != 0) {
        fn(arg);   /* no thread: here, without heartbeats */
        return;
    }
    long step = w->heartbeat_ms / 4 < 50 ? (w->heartbeat_ms / 4 > 0 ? w->heartbeat_ms / 4 : 1) : 50;
    for (;;) {
        /* done is read before the flag: a helper the flag stopped (its job
         * broken with "interrupted") is never taken for a finished one */
        bool finished = atomic_load(&b.done);
        if (atomic_load(&interrupted)) {
            /* the helper stops at the flag too (job_scene_new's cancel)
             * but holds the job list: tell the master (it requeues our
             * tiles at once) and leave without tearing anything down */
            wlog(w, 0, "interrupted while %s; leaving", what);
            send_shutdown(w, "the worker was stopped (SIGINT/SIGTERM) while preparing a job");
            int linger = 500;
            wire_monitor_destroy(&w->monitor);   /* its socket would hold up zmq_ctx_term */
            zmq_setsockopt(w->dealer, ZMQ_LINGER, &linger, sizeof linger);
            zmq_close(w->dealer);
            zmq_ctx_term(w->ctx);   /* sends what is queued, for at most 500 ms */
            _exit(AAFARM_EXIT_INTERRUPTED);
        }
        if (finished) break;
        zmq_pollitem_t item = {NULL, worker_pool_wake_fd(w->pool), ZMQ_POLLIN, 0};
        zmq_poll(&item, 1, step);
        int events = 0;
        size_t len = sizeof events;
        if (zmq_getsockopt(w->dealer, ZMQ_EVENTS, &events, &len) == 0 && (events & ZMQ_POLLIN))
            w->last_heard_ms = now_ms();   /* the master is there; read it later */
        send_finished(w);
        if (w->welcomed && now_ms() - w->last_sent_ms >= w->heartbeat_ms) send_heartbeat(w);
    }
    pthread_join(tid, NULL);
}

typedef struct preparation {
    worker_jobs *jobs;
    const proto_job *msg;
    const fetch_job *files;        /* its files' paths and descriptors, or NULL */
    int delay_ms;
    held_job *result;
} preparation;

static void prepare(void *arg)
{
    preparation *p = arg;
    if (p->delay_ms > 0) {
        struct timespec ts = {p->delay_ms / 1000, (long)(p->delay_ms % 1000) * 1000000L};
        while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
    }
    p->result = worker_jobs_add(p->jobs, p->msg, p->files ? p->files->paths : NULL,
                                p->files ? p->files->fds : NULL);
}

/* worker_jobs_add beside the loop. */
static held_job *prepare_job(worker_loop *w, const proto_job *m, const fetch_job *files)
{
    preparation p = {w->jobs, m, files, w->opt->prepare_delay_ms, NULL};
    if (worker_jobs_find(w->jobs, m->job_hash)) {
        p.delay_ms = 0;
        prepare(&p);   /* held already: nothing to compile */
        return p.result;
    }
    char what[80];
    snprintf(what, sizeof what, "preparing job %.12s", m->job_hash);
    run_beside(w, prepare, &p, what);
    return p.result;
}

/* The grants that waited for the job (or its files) start. */
static void start_pending(worker_loop *w, held_job *h)
{
    for (pending_grant **at = &w->pending; *at;) {
        pending_grant *p = *at;
        if (strcmp(p->hash, h->hash) != 0) {
            at = &p->next;
            continue;
        }
        *at = p->next;
        start_tile(w, h, p->lease_id, p->tile_index, p->rect);
        free(p);
    }
}

static void job_ready(worker_loop *w, held_job *h)
{
    if (h->broken) wlog(w, -1, "%s", h->error);
    else wlog(w, 0, "job %.12s (%s, %dx%d) ready", h->hash, h->jb->scene_file, h->fmt.width,
              h->fmt.height);
    /* where the texture module will open each file (through the resolver) */
    for (int i = 0; !h->broken && w->opt->verbosity > 0 && i < h->jb->nfiles; i++) {
        char path[4096], why[ERR_LEN];
        if (job_file_resolve(h->jb, h->jb->files[i].name, path, sizeof path, why, sizeof why))
            wlog(w, 1, "file '%s' resolves to %s", h->jb->files[i].name, path);
        else
            wlog(w, 1, "file '%s' does not resolve: %s", h->jb->files[i].name, why);
    }
    start_pending(w, h);
}

/* Jobs whose files are all here now: compiled, announced, started. */
static void take_ready_jobs(worker_loop *w)
{
    fetch_job *j;
    while ((j = file_fetch_take_ready(w->files))) {
        held_job *h;
        if (j->error[0]) {
            h = worker_jobs_add_broken(w->jobs, j->hash, j->error);
        } else {
            const proto_job *m = proto_saved_job_get(j->msg);
            if (j->misses)
                wlog(w, 0, "job %.12s: its files are here (%d in all, %u fetched, %llu bytes "
                     "received)", j->hash, j->nfiles, j->misses, (unsigned long long)j->fetched);
            h = prepare_job(w, m, j);
            for (int i = 0; i < j->nfiles; i++) j->fds[i] = -1;   /* the held job has them */
            send_files_ready(w, j);
            h->files_said = w->master_session;
        }
        fetch_job_destroy(&j);
        job_ready(w, h);
    }
}

typedef struct file_call {
    file_fetch *files;
    const proto_job *msg;          /* add this Job; NULL: poll */
} file_call;

static void file_work(void *arg)
{
    file_call *c = arg;
    if (c->msg) file_fetch_add(c->files, c->msg, now_ms());
    else file_fetch_poll(c->files, now_ms());
}

/* The file work that may hash whole files, beside the loop. */
static void poll_files(worker_loop *w)
{
    if (!file_fetch_poll_due(w->files, now_ms())) return;
    file_call c = {w->files, NULL};
    run_beside(w, file_work, &c, "checking job files");
}

static void on_job(worker_loop *w, const proto_job *m)
{
    if (m->n_files == 0 || worker_jobs_find(w->jobs, m->job_hash)) {
        job_ready(w, prepare_job(w, m, NULL));
        return;
    }
    file_call c = {w->files, m};
    run_beside(w, file_work, &c, "looking up job files");
    take_ready_jobs(w);   /* all in the store already: at once */
}

static void on_file_chunk(worker_loop *w, const proto_file_chunk *c, const wire_msg *m)
{
    size_t len = 0;
    const uint8_t *data = wire_msg_bulk(m, &len);
    w->file_received += len;
    uint64_t n = file_fetch_chunk(w->files, c, data, len, now_ms());
    wlog(w, 1, "file %.12s: bytes %llu..+%zu %s", c->sha256, (unsigned long long)c->offset, len,
         n ? "written" : "not wanted (dropped)");
    poll_files(w);   /* the last chunk: the file is checked and stored */
    take_ready_jobs(w);
}

static void on_grant(worker_loop *w, const proto_grant *g)
{
    if (w->asked) w->asked--;
    image_rect rect = {(int)g->tile.x, (int)g->tile.y, (int)g->tile.width, (int)g->tile.height};
    held_job *h = worker_jobs_find(w->jobs, g->job_hash);
    if (h) {
        if (!h->broken && h->jb->nfiles > 0 && h->files_said != w->master_session) {
            /* held from an earlier session: every file is here */
            fetch_job said = {.nfiles = h->jb->nfiles, .hits = (uint32_t)h->jb->nfiles};
            snprintf(said.hash, sizeof said.hash, "%s", h->hash);
            send_files_ready(w, &said);
            h->files_said = w->master_session;
        }
        start_tile(w, h, g->lease_id, g->tile_index, rect);
        return;
    }
    bool asked_already = file_fetch_waiting(w->files, g->job_hash);   /* files on the way */
    for (pending_grant *p = w->pending; p; p = p->next)
        if (strcmp(p->hash, g->job_hash) == 0) asked_already = true;
    pending_grant *p = xcalloc(1, sizeof *p);
    *p = (pending_grant){g->lease_id, g->tile_index, rect, "", w->pending};
    snprintf(p->hash, sizeof p->hash, "%s", g->job_hash);
    w->pending = p;
    if (!asked_already) send_need_job(w, g->job_hash, g->lease_id);
}

static void on_job_done(worker_loop *w, const proto_job_done *d)
{
    worker_pool_cancel(w->pool, d->job_hash);
    drop_pending(w, d->job_hash);
    file_fetch_drop(w->files, d->job_hash);   /* chunks written stay in the store */
    const char *how = d->status == PROTO_JOB_STATUS_DONE     ? "done"
                      : d->status == PROTO_JOB_STATUS_FAILED ? "failed"
                                                              : "cancelled";
    wlog(w, 0, "job %.12s %s%s%s", d->job_hash, how, d->message && *d->message ? ": " : "",
         d->message ? d->message : "");
}

static void handle(worker_loop *w, const wire_msg *m)
{
    const proto_msg *msg = wire_msg_body(m);
    proto_kind kind = msg->kind;
    if (!w->welcomed && kind != PROTO_WELCOME && kind != PROTO_REJECT && kind != PROTO_SHUTDOWN)
        return;   /* from before our Hello was answered: ignore */
    switch (kind) {
    case PROTO_WELCOME: on_welcome(w, &msg->welcome); break;
    case PROTO_REJECT: on_reject(w, &msg->reject); break;
    case PROTO_JOB: on_job(w, &msg->job); break;
    case PROTO_GRANT: on_grant(w, &msg->grant); break;
    case PROTO_JOB_DONE: on_job_done(w, &msg->job_done); break;
    case PROTO_FILE_CHUNK: on_file_chunk(w, &msg->file_chunk, m); break;
    case PROTO_SHUTDOWN:
        wlog(w, 0, "the master says shut down%s%s",
             msg->shutdown.reason && *msg->shutdown.reason ? ": " : "",
             msg->shutdown.reason ? msg->shutdown.reason : "");
        w->end = SESSION_SHUTDOWN;
        break;
    default: break;   /* Heartbeat: liveness only */
    }
}

/* ---- one session ---- */

static void read_master(worker_loop *w)
{
    for (int i = 0; i < 1000 && w->end == SESSION_LOST; i++) {
        wire_msg *m = wire_recv(w->dealer, &w->limits, &w->wstats, ZMQ_DONTWAIT, NULL, 0);
        if (!m) {
            if (errno != EPROTO) return;
            int64_t now = now_ms();
            if (now - w->drop_logged_ms >= 1000) {
                wlog(w, 0, "%s (%llu dropped so far)", w->wstats.last_error,
                     (unsigned long long)w->wstats.dropped);
                w->drop_logged_ms = now;
            }
            w->last_heard_ms = now;   /* something came from the master's side */
            continue;
        }
        w->last_heard_ms = now_ms();
        handle(w, m);
        wire_msg_destroy(&m);
    }
}

/* Sends finished tiles (the outbox first, in order). */
static void send_finished(worker_loop *w)
{
    worker_task *t;
    while ((t = worker_pool_take_done(w->pool))) {
        worker_task **tail = &w->outbox;
        while (*tail) tail = &(*tail)->next;
        *tail = t;
    }
    while ((t = w->outbox)) {
        if (!t->cancelled && w->welcomed && !send_task(w, t)) return;   /* queue full */
        w->outbox = t->next;
        worker_task_destroy(&t);
    }
}

static void ask_for_more(worker_loop *w)
{
    if (!w->welcomed) return;
    int held = worker_pool_busy(w->pool) + pending_count(w);
    long deficit = (long)w->target - held - (long)w->asked;
    if (deficit > 0) send_ask(w, (uint32_t)deficit);
}

static bool open_socket(worker_loop *w)
{
    w->dealer = zmq_socket(w->ctx, ZMQ_DEALER);
    if (!w->dealer || wire_socket_setup(w->dealer, &w->limits, NULL, 0) != 0) {
        snprintf(w->fatal, sizeof w->fatal, "cannot create a socket: %s", zmq_strerror(errno));
        return false;
    }
    if (w->curve &&
        (zmq_setsockopt(w->dealer, ZMQ_CURVE_SERVERKEY, w->master.public_key, CURVE_Z85_LEN) != 0 ||
         zmq_setsockopt(w->dealer, ZMQ_CURVE_PUBLICKEY, w->own.public_key, CURVE_Z85_LEN) != 0 ||
         zmq_setsockopt(w->dealer, ZMQ_CURVE_SECRETKEY, w->own.secret_key, CURVE_Z85_LEN) != 0)) {
        snprintf(w->fatal, sizeof w->fatal, "cannot turn CURVE on: %s", zmq_strerror(errno));
        return false;
    }
    w->monitor = wire_monitor_new(w->ctx, w->dealer, NULL, 0);
    if (zmq_connect(w->dealer, w->opt->endpoint) != 0) {
        snprintf(w->fatal, sizeof w->fatal, "cannot connect to '%s': %s", w->opt->endpoint,
                 zmq_strerror(errno));
        return false;
    }
    return true;
}

static void close_socket(worker_loop *w, int linger_ms)
{
    wire_monitor_destroy(&w->monitor);
    if (!w->dealer) return;
    zmq_setsockopt(w->dealer, ZMQ_LINGER, &linger_ms, sizeof linger_ms);
    zmq_close(w->dealer);
    w->dealer = NULL;
}

/* A failed handshake means the master refused this worker's key, or one
 * side speaks CURVE and the other not: said once until a master welcomes
 * this worker (not at every retry). */
static void check_handshakes(worker_loop *w)
{
    if (!w->monitor) return;
    wire_monitor_poll(w->monitor, &w->wstats, NULL, 0);
    if (w->wstats.handshake_failures == 0 || w->handshake_said || w->welcomed) return;
    w->handshake_said = true;
    if (w->wstats.auth_failures)
        wlog(w, -1, "the master at %s refused this worker's key: its public key (%s) is not "
             "in the master's --allow-keys folder; retrying with backoff", w->opt->endpoint,
             w->own.public_key);
    else
        wlog(w, -1, "the handshake with the master at %s failed (%s): %s; retrying with "
             "backoff", w->opt->endpoint, w->wstats.last_handshake,
             w->curve ? "does the master speak CURVE, and is --master-key its public key?"
                      : "the master may require CURVE (give --curve-secret and --master-key)");
}

/* No master yet: "cannot reach" once, when the first try ends without a
 * Welcome; then every report interval how long it has tried. */
static void say_unreachable(worker_loop *w, int64_t now, bool try_ended)
{
    if (!w->trying || w->welcomed) return;
    if (!w->unreachable_said) {
        if (!try_ended) return;
        w->unreachable_said = true;
        w->unreachable_said_ms = now;
        char every[32];
        if (w->report_ms % 1000) snprintf(every, sizeof every, "%.1f s", w->report_ms / 1000.0);
        else snprintf(every, sizeof every, "%d s", w->report_ms / 1000);
        wlog(w, 0, "cannot reach the master at %s: no answer for %.1f s; retrying (said again "
             "every %s until it answers)", w->opt->endpoint,
             (double)(now - w->trying_since_ms) / 1000.0, every);
        return;
    }
    if (now - w->unreachable_said_ms < w->report_ms) return;
    w->unreachable_said_ms = now;
    wlog(w, 0, "still no master at %s after %.0f s of trying", w->opt->endpoint,
         (double)(now - w->trying_since_ms) / 1000.0);
}

static session_end session(worker_loop *w)
{
    w->end = SESSION_LOST;
    w->welcomed = false;
    w->heartbeat_ms = 1000;   /* until the first Welcome */
    w->liveness = 3;
    if (!open_socket(w)) {
        close_socket(w, 0);
        return SESSION_FATAL;
    }
    send_hello(w);
    w->last_heard_ms = now_ms();
    w->wstats.handshake_failures = w->wstats.auth_failures = 0;
    while (w->end == SESSION_LOST) {
        zmq_pollitem_t items[2] = {{w->dealer, 0, ZMQ_POLLIN, 0},
                                   {NULL, worker_pool_wake_fd(w->pool), ZMQ_POLLIN, 0}};
        long timeout = w->heartbeat_ms / 2 < 100 ? w->heartbeat_ms / 2 : 100;
        if (zmq_poll(items, 2, timeout) < 0 && errno != EINTR) break;
        if (atomic_load(&interrupted)) {
            send_shutdown(w, "the worker was stopped (SIGINT/SIGTERM)");
            w->end = SESSION_INTERRUPTED;
            break;
        }
        read_master(w);
        if (w->welcomed) {
            poll_files(w);
            file_fetch_pump(w->files, now_ms(), send_need_file, w);
            take_ready_jobs(w);
        }
        send_finished(w);
        ask_for_more(w);
        check_handshakes(w);
        int64_t now = now_ms();
        if (now - w->last_heard_ms > (int64_t)w->heartbeat_ms * w->liveness) {
            if (w->welcomed) {   /* the master went away: from now on, it is tried again */
                wlog(w, 0, "master at %s: no answer for %.1f s", w->opt->endpoint,
                     (double)(now - w->last_heard_ms) / 1000.0);
                w->trying = true;
                w->trying_since_ms = now;
            } else {
                wlog(w, 1, "no master at %s: no answer for %.1f s", w->opt->endpoint,
                     (double)(now - w->last_heard_ms) / 1000.0);
                say_unreachable(w, now, true);
            }
            break;
        }
        say_unreachable(w, now, false);
        if (w->welcomed && now - w->last_sent_ms >= w->heartbeat_ms) send_heartbeat(w);
    }
    drop_all_leases(w);
    close_socket(w, w->end == SESSION_LOST ? 0 : 200);
    return w->end;
}

/* Waits ms before reconnecting; finished tiles of dropped leases are
 * freed meanwhile. False when interrupted. */
static bool backoff_wait(worker_loop *w, int ms)
{
    for (int64_t until = now_ms() + ms; now_ms() < until;) {
        zmq_pollitem_t item = {NULL, worker_pool_wake_fd(w->pool), ZMQ_POLLIN, 0};
        zmq_poll(&item, 1, 100);
        if (atomic_load(&interrupted)) return false;
        send_finished(w);
        say_unreachable(w, now_ms(), false);
    }
    return true;
}

static int serve(worker_loop *w)
{
    int backoff = BACKOFF_FIRST_MS;
    w->trying = true;
    w->trying_since_ms = now_ms();
    for (;;) {
        w->ever_welcomed = false;
        session_end end = session(w);
        switch (end) {
        case SESSION_FATAL:
            wlog(w, -1, "%s", w->fatal);
            return AAFARM_EXIT_USAGE;
        case SESSION_SHUTDOWN: return AAFARM_EXIT_OK;
        case SESSION_INTERRUPTED:
            wlog(w, 0, "stopped (%llu tiles sent)", (unsigned long long)w->tiles_sent);
            return AAFARM_EXIT_INTERRUPTED;
        default: break;
        }
        if (w->ever_welcomed) backoff = BACKOFF_FIRST_MS;
        /* after a lost master once; while none answers, only with -v */
        wlog(w, w->ever_welcomed ? 0 : 1, "reconnecting in %d s", backoff / 1000);
        if (!backoff_wait(w, backoff)) return AAFARM_EXIT_INTERRUPTED;
        backoff = backoff * 2 > BACKOFF_MAX_MS ? BACKOFF_MAX_MS : backoff * 2;
    }
}

static int default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

int worker_loop_run(const worker_loop_options *opt)
{
    worker_loop w;
    memset(&w, 0, sizeof w);
    w.opt = opt;
    w.limits = proto_limits_default();
    w.threads = opt->threads > 0 ? opt->threads : default_threads();
    w.target = 2 * w.threads;
    w.report_ms = opt->unreachable_report_ms > 0 ? opt->unreachable_report_ms
                                                 : UNREACHABLE_REPORT_MS;
    if (gethostname(w.host, 100) != 0 || !w.host[0]) snprintf(w.host, sizeof w.host, "localhost");
    w.host[100] = '\0';
    if (opt->name) snprintf(w.name, sizeof w.name, "%s", opt->name);
    else snprintf(w.name, sizeof w.name, "%.100s:%d", w.host, (int)getpid());

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;   /* no SA_RESTART: zmq_poll returns EINTR */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    if (opt->curve_secret) {
        char err[ERR_LEN];
        if (!curve_cert_read(opt->curve_secret, true, &w.own, err, sizeof err) ||
            !curve_cert_read(opt->master_key, false, &w.master, err, sizeof err)) {
            wlog(&w, -1, "%s", err);
            return AAFARM_EXIT_USAGE;
        }
        w.curve = true;
    }
    w.ctx = zmq_ctx_new();
    w.pool = worker_pool_new(w.threads, opt->tile_delay_ms);
    w.jobs = worker_jobs_new(MAX_JOBS_HELD, opt->cache_bytes, &interrupted);
    worker_jobs_set_threads(w.jobs, w.threads);
    file_fetch_options fo = {opt->file_cache, opt->file_cache_bytes, opt->file_chunk,
                             opt->file_inflight, opt->file_delay_ms};
    w.files = file_fetch_new(&fo);
    int rc = AAFARM_EXIT_FAILURE;
    if (!w.ctx || !w.pool) {
        wlog(&w, -1, "cannot start: %s", strerror(errno));
    } else {
        wlog(&w, 1, "%d render thread%s, serving %s", w.threads, w.threads == 1 ? "" : "s",
             opt->endpoint);
        rc = serve(&w);
    }
    worker_pool_destroy(&w.pool);   /* before the jobs: threads hold references */
    free_outbox(&w);
    drop_pending(&w, NULL);
    file_fetch_destroy(&w.files);
    worker_jobs_destroy(&w.jobs);
    if (w.ctx) zmq_ctx_term(w.ctx);
    memset(&w.own, 0, sizeof w.own);
    return rc;
}
