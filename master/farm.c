/*
 * farm.c: one farm render (see farm.h): set-up, the master's poll loop and
 * its timers, and the end of the job.
 *
 * The loop is single-threaded (ZeroMQ sockets are not thread-safe, and the
 * master's work per message is small: bookkeeping and one chunk copy):
 *
 *     poll the ROUTER (and its monitor) for at most 100 ms
 *     read every queued message: farm_handle()
 *     timers: heartbeats to quiet workers, silent workers are dead, lease
 *             deadlines, local children that exited, progress
 *     grant tiles to workers with credits: farm_grant_all()
 *
 * The end: the output file is finished (renamed into place) only when
 * every tile is in; then JobDone to every worker that got the job,
 * Shutdown to the local workers, which are then stopped by PID. On
 * failure or SIGINT/SIGTERM the temporary output is removed instead.
 */
#include "farm.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <zmq.h>

#include "curve_cert.h"
#include "farm_internal.h"
#include "image/buffer.h"
#include "image/preview.h"
#include "stale.h"
#include "util/exitcodes.h"

/* What one peer can make the master hold (issue 11): a message from a
 * worker has a header of at most FARM_MAX_HEADER bytes (a Hello, a
 * Result's metadata: small; the Job the master sends may be larger, see
 * send_limits), and a Result's bulk
 * frame is at most what a tile of this job can take (every channel of
 * every layer as 32-bit floats, uncompressed, 64 bytes a pixel at most,
 * plus 64 KiB of header); ZeroMQ refuses a bigger frame before allocating
 * it and disconnects the peer. With FARM_RCVHWM messages queued per
 * connection at most, the bytes queued per connection are bounded by
 * (FARM_RCVHWM + 1) x that (the +1: the message being read). */
enum { FARM_RCVHWM = 8, FARM_SNDHWM = 256, FARM_MAX_HEADER = 256 << 10 };

static volatile sig_atomic_t interrupted;

static void on_signal(int sig)
{
    (void)sig;
    interrupted = 1;
}

void farm_options_default(farm_options *opt)
{
    memset(opt, 0, sizeof *opt);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    opt->local_workers = cores > 0 ? (int)cores : 1;
    opt->threads_per_worker = 1;
    opt->heartbeat_ms = 1000;
    opt->liveness = 3;
    opt->max_attempts = 3;
    opt->max_duplicates = 1;
    opt->lease_ms = 120000;
    opt->lease_factor = 4;
    opt->max_workers = 1024;
}

int64_t farm_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* ---- set-up ---- */

static uint64_t random_session(void)
{
    uint64_t v = 0;
    int fd = open("/dev/urandom", O_RDONLY);
    if (fd >= 0) {
        if (read(fd, &v, sizeof v) != (ssize_t)sizeof v) v = 0;
        close(fd);
    }
    if (v == 0) v = ((uint64_t)time(NULL) << 20) ^ (uint64_t)getpid() ^ (uint64_t)farm_now_ms();
    return v ? v : 1;
}

static void report_leftover(void *arg, const char *path, long pid, int removed)
{
    farm *f = arg;
    if (removed)
        console_log(f->con, CONSOLE_INFO, "removed %s, left behind by a master that died "
                    "(pid %ld)", path, pid);
    else
        console_log(f->con, CONSOLE_INFO, "left %s alone: it belongs to process %ld, which "
                    "still runs (remove it by hand if that is no master)", path, pid);
}

/* The embedded mode's private endpoint: ipc://<new temp folder>/master.sock,
 * with master.pid beside it so that the next master can tell the folder of
 * a dead master from that of a running one (stale.h). */
static bool make_private_endpoint(farm *f, char *ep, size_t n, char *err, size_t errsz)
{
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !*tmp || strlen(tmp) > 60) tmp = "/tmp";
    stale_clean_ipc_dirs(tmp, report_leftover, f);
    snprintf(f->ipc_dir, sizeof f->ipc_dir, "%s/aafarm-XXXXXX", tmp);
    if (!mkdtemp(f->ipc_dir)) {
        snprintf(err, errsz, "cannot create a private folder in %s for the local workers' "
                 "socket: %s", tmp, strerror(errno));
        f->ipc_dir[0] = '\0';
        return false;
    }
    char pidfile[PATH_MAX + 16];
    snprintf(pidfile, sizeof pidfile, "%s/%s", f->ipc_dir, STALE_PID_FILE);
    FILE *pf = fopen(pidfile, "w");
    if (pf) {
        fprintf(pf, "%ld\n", (long)getpid());
        fclose(pf);
    }
    snprintf(ep, n, "ipc://%s/master.sock", f->ipc_dir);
    return true;
}

static void remove_private_endpoint(farm *f)
{
    if (!f->ipc_dir[0]) return;
    char sock[PATH_MAX + 16];
    snprintf(sock, sizeof sock, "%s/master.sock", f->ipc_dir);
    unlink(sock);
    snprintf(sock, sizeof sock, "%s/%s", f->ipc_dir, STALE_PID_FILE);
    unlink(sock);
    rmdir(f->ipc_dir);
    f->ipc_dir[0] = '\0';
}

static int bind_endpoint(farm *f, const char *ep, char *err, size_t errsz)
{
    if (zmq_bind(f->router, ep) == 0) return AAFARM_EXIT_OK;
    int e = errno;
    snprintf(err, errsz, "cannot bind %s: %s", ep, zmq_strerror(e));
    return e == EINVAL || e == EPROTONOSUPPORT || e == ENOCOMPATPROTO ? AAFARM_EXIT_USAGE
                                                                       : AAFARM_EXIT_FAILURE;
}

/* CURVE on the network endpoint (zap.h): the master's secret key, and the
 * handler that admits only the allowed workers' keys. Options set here
 * apply to the binds that follow, not to the ipc endpoint bound before. */
static int enable_curve(farm *f, char *err, size_t errsz)
{
    curve_cert cert;
    if (!curve_cert_read(f->opt->curve_secret, true, &cert, err, errsz)) return AAFARM_EXIT_USAGE;
    f->zap = zap_new(f->ctx, f->opt->allow_keys, f->con, err, errsz);
    if (!f->zap) return AAFARM_EXIT_USAGE;
    int on = 1;
    if (zmq_setsockopt(f->router, ZMQ_CURVE_SERVER, &on, sizeof on) != 0 ||
        zmq_setsockopt(f->router, ZMQ_CURVE_SECRETKEY, cert.secret_key, CURVE_Z85_LEN) != 0 ||
        zmq_setsockopt(f->router, ZMQ_ZAP_DOMAIN, "aafarm", 6) != 0) {
        snprintf(err, errsz, "cannot turn CURVE on: %s (does this libzmq have CURVE?)",
                 zmq_strerror(errno));
        memset(&cert, 0, sizeof cert);
        return AAFARM_EXIT_FAILURE;
    }
    memset(&cert, 0, sizeof cert);
    console_log(f->con, CONSOLE_INFO, "CURVE on: %d worker key%s allowed (%s)",
                zap_key_count(f->zap), zap_key_count(f->zap) == 1 ? "" : "s", f->opt->allow_keys);
    return AAFARM_EXIT_OK;
}

static int open_socket(farm *f, char *err, size_t errsz)
{
    f->ctx = zmq_ctx_new();
    f->router = f->ctx ? zmq_socket(f->ctx, ZMQ_ROUTER) : NULL;
    int rcvhwm = FARM_RCVHWM, sndhwm = FARM_SNDHWM;
    if (!f->router || wire_socket_setup(f->router, &f->limits) != 0 ||
        zmq_setsockopt(f->router, ZMQ_RCVHWM, &rcvhwm, sizeof rcvhwm) != 0 ||
        zmq_setsockopt(f->router, ZMQ_SNDHWM, &sndhwm, sizeof sndhwm) != 0) {
        snprintf(err, errsz, "cannot create the master's socket: %s", zmq_strerror(errno));
        return AAFARM_EXIT_FAILURE;
    }
    f->monitor = wire_monitor_new(f->ctx, f->router);
    if (f->opt->local_workers > 0) {   /* private, plaintext: bound before CURVE is on */
        char ep[PATH_MAX + 32];
        if (!make_private_endpoint(f, ep, sizeof ep, err, errsz)) return AAFARM_EXIT_FAILURE;
        int rc = bind_endpoint(f, ep, err, errsz);
        if (rc != AAFARM_EXIT_OK) return AAFARM_EXIT_FAILURE;
        snprintf(f->endpoint, sizeof f->endpoint, "%s", ep);
    }
    if (f->opt->bind) {
        if (f->opt->curve_secret) {
            int rc = enable_curve(f, err, errsz);
            if (rc != AAFARM_EXIT_OK) return rc;
        } else if (!curve_endpoint_is_local(f->opt->bind)) {
            console_log(f->con, CONSOLE_ERROR, "WARNING: --insecure: %s is open to the network "
                        "without CURVE: anyone who can reach it can take the job (scene and "
                        "shaders, in clear text) and send tiles into the image", f->opt->bind);
        }
        int rc = bind_endpoint(f, f->opt->bind, err, errsz);
        if (rc != AAFARM_EXIT_OK) return rc;
        char last[600] = "";
        size_t len = sizeof last;
        zmq_getsockopt(f->router, ZMQ_LAST_ENDPOINT, last, &len);
        console_log(f->con, CONSOLE_INFO, "listening on %s%s", last[0] ? last : f->opt->bind,
                    f->zap ? " (CURVE)" : "");
        if (!f->opt->local_workers)
            snprintf(f->endpoint, sizeof f->endpoint, "%s", last[0] ? last : f->opt->bind);
    }
    return AAFARM_EXIT_OK;
}

static int start_local_workers(farm *f, char *err, size_t errsz)
{
    if (f->opt->local_workers <= 0) return AAFARM_EXIT_OK;
    char binary[PATH_MAX];
    if (f->opt->worker_binary) {
        snprintf(binary, sizeof binary, "%s", f->opt->worker_binary);
    } else if (!local_workers_find_binary(binary, sizeof binary, err, errsz)) {
        return AAFARM_EXIT_FAILURE;
    }
    f->locals = local_workers_start(binary, f->endpoint, f->opt->local_workers,
                                    f->opt->threads_per_worker,
                                    f->opt->verbosity > 0 ? 1 : -1, err, errsz);
    if (!f->locals) return AAFARM_EXIT_FAILURE;
    console_log(f->con, CONSOLE_DETAIL, "started %d local worker%s on %s",
                f->opt->local_workers, f->opt->local_workers == 1 ? "" : "s", f->endpoint);
    return AAFARM_EXIT_OK;
}

/* The Job must pass the same checks a worker applies (names, sizes, no NUL
 * bytes): fail before contacting anyone rather than at the first grant. */
static int check_job_message(farm *f, char *err, size_t errsz)
{
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_JOB;
    env.job = job_message_job(f->jobmsg);
    char why[300];
    if (proto_message_check(&env, false, 0, &f->send_limits, why, sizeof why) != 0) {
        snprintf(err, errsz, "the job cannot be sent to workers: %s", why);
        return AAFARM_EXIT_INPUT;
    }
    f->job_bytes = job_message_packed_size(f->jobmsg);
    if (f->job_bytes > f->send_limits.max_header_bytes) {
        snprintf(err, errsz, "the job is %zu bytes, more than the %zu a message may carry",
                 f->job_bytes, f->send_limits.max_header_bytes);
        return AAFARM_EXIT_INPUT;
    }
    return AAFARM_EXIT_OK;
}

/* A journaled tile goes into the new output file and is DONE. */
static bool replay_tile(void *arg, int tile, const void *chunk, size_t len, char *err,
                        size_t errsz)
{
    farm *f = arg;
    if (!image_writer_put_chunk(f->writer, tile % f->tiles_x, tile / f->tiles_x, chunk, len,
                                err, errsz))
        return false;
    if (scheduler_mark_done(f->sched, tile)) f->resumed_tiles++;
    return true;
}

/* --resume: the journal's tiles are in; otherwise a new, empty journal. */
static int open_journal(farm *f, char *err, size_t errsz)
{
    char *path = journal_path_for(f->opt->output);
    if (!path) abort();
    journal_id id;
    memset(&id, 0, sizeof id);
    snprintf(id.job_hash, sizeof id.job_hash, "%s", f->jb->hash);
    id.width = (uint32_t)f->fmt.width;
    id.height = (uint32_t)f->fmt.height;
    id.tile_size = (uint32_t)f->fmt.tile_size;
    id.layers = (uint32_t)f->fmt.layers;
    id.tiles = (uint32_t)f->ntiles;
    int rc = AAFARM_EXIT_OK;
    bool missing = !f->opt->resume;
    if (f->opt->resume) {
        journal_replay info;
        f->jnl = journal_resume(path, &id, replay_tile, f, &info, &missing, err, errsz);
        if (f->jnl) {
            console_log(f->con, CONSOLE_INFO, "resuming: %d of %d tiles taken from %s", info.tiles,
                        f->ntiles, path);
            if (info.dropped_bytes)
                console_log(f->con, CONSOLE_INFO, "the journal ended in %s: dropped its last "
                            "%llu bytes (those tiles are rendered again)", info.dropped_why,
                            (unsigned long long)info.dropped_bytes);
        } else if (missing) {
            console_log(f->con, CONSOLE_INFO, "--resume: no journal %s, rendering every tile",
                        path);
        } else {
            rc = image_writer_failed(f->writer) ? AAFARM_EXIT_FAILURE : AAFARM_EXIT_USAGE;
        }
    }
    if (missing) {
        bool replaced = false;
        f->jnl = journal_create(path, &id, &replaced, err, errsz);
        if (!f->jnl) rc = AAFARM_EXIT_FAILURE;
        else if (replaced)
            console_log(f->con, CONSOLE_INFO, "replaced the journal of an unfinished render "
                        "(%s): --resume would have continued it", path);
    }
    free(path);
    return rc;
}

static void bound_limits(farm *f)
{
    f->send_limits = proto_limits_default();
    f->limits = proto_limits_default();
    f->limits.max_header_bytes = FARM_MAX_HEADER;
    size_t px = (size_t)f->fmt.tile_size * (size_t)f->fmt.tile_size;
    size_t bound = 65536 + px * 64;
    if (bound < f->limits.max_bulk_bytes) f->limits.max_bulk_bytes = bound;
}

static int setup(farm *f, char *err, size_t errsz)
{
    bound_limits(f);
    f->session = random_session();
    if (gethostname(f->host, sizeof f->host - 1) != 0) snprintf(f->host, sizeof f->host, "master");
    f->tiles_x = image_format_tiles_x(&f->fmt);
    f->ntiles = image_format_tile_count(&f->fmt);
    scheduler_options so;
    scheduler_options_default(&so);
    so.max_attempts = f->opt->max_attempts;
    so.max_duplicates = f->opt->max_duplicates;
    so.lease_ms = f->opt->lease_ms;
    so.lease_factor = f->opt->lease_factor;
    f->sched = scheduler_new(f->tiles_x, image_format_tiles_y(&f->fmt), &so);
    f->reg = registry_new();
    f->jobmsg = job_message_new(f->jb, &f->fmt);
    f->files = file_server_new(f->jb);
    int rc = check_job_message(f, err, errsz);
    if (rc != AAFARM_EXIT_OK) return rc;
    stale_clean_outputs(f->opt->output, report_leftover, f);
    if (f->opt->preview) stale_clean_outputs(f->opt->preview, report_leftover, f);
    f->writer = image_writer_new(f->opt->output, &f->fmt, err, errsz);
    if (!f->writer) return AAFARM_EXIT_FAILURE;
    rc = open_journal(f, err, errsz);
    if (rc != AAFARM_EXIT_OK) return rc;
    rc = open_socket(f, err, errsz);
    if (rc != AAFARM_EXIT_OK) return rc;
    return start_local_workers(f, err, errsz);
}

/* ---- the loop ---- */

static void log_drop(farm *f, int64_t now)
{
    if (now - f->drop_logged_ms < 1000) {
        f->drops_unlogged++;
        return;
    }
    if (f->drops_unlogged)
        console_log(f->con, CONSOLE_INFO, "%s (and %llu more malformed messages dropped)",
                    wire_last_error(), (unsigned long long)f->drops_unlogged);
    else
        console_log(f->con, CONSOLE_INFO, "%s", wire_last_error());
    f->drops_unlogged = 0;
    f->drop_logged_ms = now;
}

/* Reads what is queued (at most a batch, so timers still run). */
static void drain(farm *f, int64_t now)
{
    for (int i = 0; i < 1000 && f->state == FARM_RUNNING; i++) {
        wire_msg *m = wire_recv(f->router, &f->limits, &f->wstats, ZMQ_DONTWAIT);
        if (!m) {
            if (errno == EPROTO) {
                log_drop(f, now);
                continue;
            }
            if (errno != EAGAIN && errno != EINTR)
                farm_fail(f, "receiving from workers: %s", zmq_strerror(errno));
            return;
        }
        farm_handle(f, m, now);
        wire_msg_destroy(&m);
        if (scheduler_finished(f->sched)) f->state = FARM_DONE;
    }
}

static void on_child_exit(void *arg, pid_t pid, int status)
{
    farm *f = arg;
    char how[64];
    if (WIFEXITED(status)) snprintf(how, sizeof how, "exited with status %d", WEXITSTATUS(status));
    else if (WIFSIGNALED(status)) snprintf(how, sizeof how, "was killed by signal %d", WTERMSIG(status));
    else snprintf(how, sizeof how, "stopped");
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        farm_worker *w = registry_at(f->reg, i);
        if (w->alive && w->local && (pid_t)w->pid == pid) {
            farm_lose_worker(f, w, how, farm_now_ms());
            return;
        }
    }
    console_log(f->con, CONSOLE_INFO, "local worker (pid %d) %s", (int)pid, how);
}

static void check_workers(farm *f, int64_t now)
{
    int64_t interval = f->opt->heartbeat_ms;
    int64_t dead_after = interval * f->opt->liveness;
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        farm_worker *w = registry_at(f->reg, i);
        if (!w->alive) continue;
        if (now - w->last_seen_ms > dead_after) {
            char why[120];
            snprintf(why, sizeof why, "missed %d heartbeats (silent for %.1f s)", f->opt->liveness,
                     (double)(now - w->last_seen_ms) / 1000.0);
            farm_lose_worker(f, w, why, now);
        } else if (now - w->last_sent_ms >= interval) {
            farm_send_heartbeat(f, w, now);
        }
    }
}

/* Failed handshakes (a plaintext peer on the CURVE endpoint, a wrong
 * master key): logged with the endpoint, at most once per 10 s. */
static void log_handshakes(farm *f, int64_t now)
{
    uint64_t n = f->wstats.handshake_failures;
    if (n == f->handshakes_logged || now - f->handshake_logged_ms < 10000) return;
    console_log(f->con, CONSOLE_INFO, "%llu connection%s failed the %s handshake (last: %s)%s",
                (unsigned long long)(n - f->handshakes_logged), n - f->handshakes_logged == 1 ? "" : "s",
                f->zap ? "CURVE" : "ZMTP", f->wstats.last_handshake,
                f->zap ? ": plaintext peers, or keys this master does not allow" : "");
    f->handshakes_logged = n;
    f->handshake_logged_ms = now;
}

static void timers(farm *f, int64_t now)
{
    check_workers(f, now);
    int n = scheduler_expire(f->sched, now);
    if (n > 0)
        console_log(f->con, CONSOLE_INFO, "%d lease%s passed %s deadline without a result "
                    "(%d x the measured time per tile, at most %.0f s): tile%s back in the "
                    "queue", n, n == 1 ? "" : "s", n == 1 ? "its" : "their",
                    f->opt->lease_factor, (double)f->opt->lease_ms / 1000.0, n == 1 ? "" : "s");
    if (f->monitor) {
        wire_monitor_poll(f->monitor, &f->wstats);
        log_handshakes(f, now);
    }
    if (f->locals) {
        local_workers_reap(f->locals, on_child_exit, f);
        if (!f->opt->bind && local_workers_running(f->locals) == 0 && registry_alive(f->reg) == 0)
            farm_fail(f, "no workers left: all %d local workers exited", f->opt->local_workers);
    }
}

static void run_loop(farm *f)
{
    long timeout = f->opt->heartbeat_ms / 2 < 100 ? f->opt->heartbeat_ms / 2 : 100;
    if (timeout < 1) timeout = 1;
    while (f->state == FARM_RUNNING) {
        zmq_pollitem_t items[3] = {{f->router, 0, ZMQ_POLLIN, 0}, {NULL, 0, ZMQ_POLLIN, 0},
                                   {NULL, 0, ZMQ_POLLIN, 0}};
        int nitems = 1;
        if (f->monitor) items[nitems++].socket = wire_monitor_socket(f->monitor);
        if (f->zap) items[nitems++].socket = zap_socket(f->zap);
        int rc = zmq_poll(items, nitems, timeout);
        zap_answer(f->zap);
        if (interrupted) {
            f->state = FARM_INTERRUPTED;
            break;
        }
        if (rc < 0 && errno != EINTR) {
            farm_fail(f, "zmq_poll: %s", zmq_strerror(errno));
            break;
        }
        int64_t now = farm_now_ms();
        drain(f, now);
        if (f->state != FARM_RUNNING) break;
        timers(f, now);
        farm_grant_all(f, now);
        console_progress(f->con, scheduler_tiles_done(f->sched), f->ntiles,
                         registry_alive(f->reg), f->start_ms, now, false);
    }
}

/* ---- the end ---- */

static void tell_workers(farm *f, int64_t now)
{
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        farm_worker *w = registry_at(f->reg, i);
        if (w->alive && w->has_job) farm_send_job_done(f, w, now);
        if (w->alive && w->local) {
            farm_send_shutdown(f, w, f->state == FARM_DONE     ? "the render is done"
                                     : f->state == FARM_FAILED ? "the render failed"
                                                               : "the render was interrupted",
                               now);
            registry_retire(f->reg, w, "shut down", now);
        }
    }
}

static void write_preview(farm *f)
{
    char err[600];
    image_buffer *buf = image_buffer_read_exr(f->opt->output, err, sizeof err);
    if (!buf || !image_preview_write_png_buffer(f->opt->preview, buf, err, sizeof err))
        console_log(f->con, CONSOLE_ERROR, "preview %s not written: %s", f->opt->preview, err);
    image_buffer_destroy(&buf);
}

static int finish(farm *f)
{
    char err[600];
    if (f->state == FARM_DONE && !image_writer_finish(&f->writer, err, sizeof err)) {
        f->state = FARM_FAILED;
        snprintf(f->failure, sizeof f->failure, "%s", err);
    }
    if (f->state == FARM_DONE || (f->jnl && scheduler_tiles_done(f->sched) == 0)) {
        journal_remove(&f->jnl);   /* the image is in place, or nothing to resume */
    } else if (f->jnl) {
        char jerr[600];
        if (journal_sync(f->jnl, jerr, sizeof jerr))
            console_log(f->con, CONSOLE_ERROR, "%d of %d tiles kept in %s: the same command with "
                        "--resume renders only the others", scheduler_tiles_done(f->sched),
                        f->ntiles, journal_file(f->jnl));
        else
            console_log(f->con, CONSOLE_ERROR, "%s", jerr);
        journal_close(&f->jnl);
    }
    f->end_ms = farm_now_ms();
    if (f->state == FARM_DONE)
        console_progress(f->con, f->ntiles, f->ntiles, registry_alive(f->reg), f->start_ms,
                         f->end_ms, true);
    tell_workers(f, f->end_ms);
    if (f->locals) local_workers_stop(f->locals, 2000);
    int rc = AAFARM_EXIT_OK;
    switch (f->state) {
    case FARM_DONE:
        if (f->nonfinite_samples)
            console_log(f->con, CONSOLE_ERROR, "warning: %llu NaN/Inf samples in %d tiles were "
                        "written as 0 (Z: as no hit); a shader divides by zero or overflows "
                        "there", (unsigned long long)f->nonfinite_samples, f->nonfinite_tiles);
        console_log(f->con, CONSOLE_INFO, "wrote %s (%dx%d, %d tiles, %.2f s)", f->opt->output,
                    f->fmt.width, f->fmt.height, f->ntiles, (double)(f->end_ms - f->start_ms) / 1000.0);
        if (f->opt->preview) write_preview(f);
        break;
    case FARM_INTERRUPTED:
        console_log(f->con, CONSOLE_ERROR, "interrupted; %s not written", f->opt->output);
        rc = AAFARM_EXIT_INTERRUPTED;
        break;
    default:
        console_log(f->con, CONSOLE_ERROR, "render failed: %s", f->failure);
        console_log(f->con, CONSOLE_ERROR, "%s not written", f->opt->output);
        rc = AAFARM_EXIT_FAILURE;
        break;
    }
    farm_report_summary(f);
    if (f->opt->stats_json && !farm_report_json(f, f->opt->stats_json, err, sizeof err)) {
        console_log(f->con, CONSOLE_ERROR, "%s", err);
        if (rc == AAFARM_EXIT_OK) rc = AAFARM_EXIT_FAILURE;
    }
    return rc;
}

static void teardown(farm *f)
{
    image_writer_destroy(&f->writer);   /* unfinished: removes the temporary file */
    if (f->jnl && scheduler_tiles_done(f->sched) == 0) journal_remove(&f->jnl);
    journal_close(&f->jnl);             /* kept for --resume */
    local_workers_destroy(&f->locals);
    wire_monitor_destroy(&f->monitor);
    if (f->router) zmq_close(f->router);
    zap_destroy(&f->zap);
    if (f->ctx) zmq_ctx_term(f->ctx);
    remove_private_endpoint(f);
    job_message_destroy(&f->jobmsg);
    file_server_destroy(&f->files);
    registry_destroy(&f->reg);
    scheduler_destroy(&f->sched);
    console_destroy(&f->con);
}

int farm_run(const farm_options *opt, const job *jb, const image_format *fmt)
{
    farm f;
    memset(&f, 0, sizeof f);
    f.opt = opt;
    f.jb = jb;
    f.fmt = *fmt;
    f.con = console_new(opt->verbosity, isatty(STDERR_FILENO));

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;   /* no SA_RESTART: zmq_poll returns EINTR */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    char err[1200];
    int rc = setup(&f, err, sizeof err);
    if (rc != AAFARM_EXIT_OK) {
        console_log(f.con, CONSOLE_ERROR, "%s", err);
        teardown(&f);
        return rc;
    }
    f.start_ms = farm_now_ms();
    console_set_resumed(f.con, f.resumed_tiles);
    if (jb->nfiles == 0)
        console_log(f.con, CONSOLE_INFO, "%s: %dx%d, %d tiles of %d, job %.12s (%zu bytes)",
                    opt->scene_path, f.fmt.width, f.fmt.height, f.ntiles, f.fmt.tile_size,
                    jb->hash, f.job_bytes);
    else   /* the files go once per host, not with every Job */
        console_log(f.con, CONSOLE_INFO, "%s: %dx%d, %d tiles of %d, job %.12s (%zu bytes + "
                    "%d file%s of %llu bytes, once per host)", opt->scene_path, f.fmt.width,
                    f.fmt.height, f.ntiles, f.fmt.tile_size, jb->hash, f.job_bytes, jb->nfiles,
                    jb->nfiles == 1 ? "" : "s", (unsigned long long)job_files_bytes(jb));
    run_loop(&f);
    rc = finish(&f);
    teardown(&f);
    return rc;
}
