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
#include "util/err.h"
#include "util/xalloc.h"

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

/* Set by SIGINT/SIGTERM (a lock-free atomic: safe in a handler); job
 * loading (main.c), the run loop and the preview look at it. */
static atomic_int interrupted;

static void on_signal(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
}

const atomic_int *farm_catch_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;   /* no SA_RESTART: zmq_poll returns EINTR */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    return &interrupted;
}

void farm_options_default(farm_options *opt)
{
    memset(opt, 0, sizeof *opt);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    opt->local_workers = cores > 0 ? (int)cores : 1;
    opt->threads_per_worker = 1;
    opt->heartbeat_ms = 1000;
    opt->liveness = 3;
    /* the scheduler's own defaults, which these options pass on to it */
    scheduler_options so;
    scheduler_options_default(&so);
    opt->max_attempts = so.max_attempts;
    opt->max_duplicates = so.max_duplicates;
    opt->lease_ms = so.lease_ms;
    opt->lease_factor = so.lease_factor;
    opt->max_workers = 1024;
    opt->wait_report_ms = 30000;
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
        err_set(err, errsz, "cannot create a private folder in %s for the local workers' "
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
    err_set(err, errsz, "cannot bind %s: %s", ep, zmq_strerror(e));
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
        err_set(err, errsz, "cannot turn CURVE on: %s (does this libzmq have CURVE?)",
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
    if (!f->router || wire_socket_setup(f->router, &f->limits, NULL, 0) != 0 ||
        zmq_setsockopt(f->router, ZMQ_RCVHWM, &rcvhwm, sizeof rcvhwm) != 0 ||
        zmq_setsockopt(f->router, ZMQ_SNDHWM, &sndhwm, sizeof sndhwm) != 0) {
        err_set(err, errsz, "cannot create the master's socket: %s", zmq_strerror(errno));
        return AAFARM_EXIT_FAILURE;
    }
    f->monitor = wire_monitor_new(f->ctx, f->router, NULL, 0);
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
        snprintf(f->bound, sizeof f->bound, "%s", last[0] ? last : f->opt->bind);
        console_log(f->con, CONSOLE_INFO, "listening on %s%s", f->bound, f->zap ? " (CURVE)" : "");
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
static int check_job_message(farm *f, farm_frame *fr, char *err, size_t errsz)
{
    proto_msg msg = {.kind = PROTO_JOB, .job = *job_message_job(fr->jobmsg)};
    char why[ERR_LEN];
    if (!proto_msg_check(&msg, false, 0, &f->send_limits, why, sizeof why)) {
        err_set(err, errsz, "the job cannot be sent to workers: %s", why);
        return AAFARM_EXIT_INPUT;
    }
    fr->job_bytes = job_message_packed_size(fr->jobmsg);
    if (fr->job_bytes > f->send_limits.max_header_bytes) {
        err_set(err, errsz, "the job is %zu bytes, more than the %zu a message may carry",
                fr->job_bytes, f->send_limits.max_header_bytes);
        return AAFARM_EXIT_INPUT;
    }
    f->job_bytes += fr->job_bytes;
    return AAFARM_EXIT_OK;
}

farm_frame *farm_frame_of(farm *f, int tile, int *local)
{
    int lo = 0, hi = f->nframes - 1;
    while (lo < hi) {   /* the last frame whose first tile is <= tile */
        int mid = (lo + hi + 1) / 2;
        if (f->frames[mid].first <= tile) lo = mid;
        else hi = mid - 1;
    }
    *local = tile - f->frames[lo].first;
    return &f->frames[lo];
}

/* "frame 3: " in a sequence, "" for a single image (for messages). */
static const char *frame_label(const farm *f, const farm_frame *fr, char *buf, size_t n)
{
    if (f->nframes > 1) snprintf(buf, n, "frame %d: ", fr->jb->frame_number);
    else buf[0] = '\0';
    return buf;
}

static void write_preview(farm *f, farm_frame *fr)
{
    char err[ERR_LEN];
    if (image_preview_write_png_exr_cancel(fr->preview, fr->output, &interrupted, err,
                                           sizeof err))
        return;
    if (atomic_load(&interrupted)) {   /* the signal ends the render, not only the preview */
        console_log(f->con, CONSOLE_ERROR, "preview %s not written: interrupted", fr->preview);
        f->state = FARM_INTERRUPTED;
        return;
    }
    console_log(f->con, CONSOLE_ERROR, "preview %s not written: %s", fr->preview, err);
}

void farm_frame_complete(farm *f, farm_frame *fr)
{
    char err[ERR_LEN], label[40];
    if (!image_writer_finish(&fr->writer, err, sizeof err)) {
        farm_fail_tile(f, fr->first, "%s%s", frame_label(f, fr, label, sizeof label), err);
        return;
    }
    fr->written = true;
    f->frames_written++;
    farm_monitor_frame_complete(f, fr);
    int written = 0;   /* of its job's frames (a serving master's run holds several jobs) */
    for (int i = 0; i < fr->job_frames; i++) written += f->frames[fr->job_first + i].written;
    if (fr->job_frames > 1)
        console_log(f->con, CONSOLE_INFO, "frame %d: wrote %s (%dx%d, %d tiles; %d of %d "
                    "frames done)", fr->jb->frame_number, fr->output, fr->fmt.width,
                    fr->fmt.height, fr->ntiles, written, fr->job_frames);
    if (f->nframes > 1 && !f->serving) {
        char line[64];
        snprintf(line, sizeof line, "%d/%d frames, ", f->frames_written, f->nframes);
        console_set_prefix(f->con, line);
    }
    if (fr->preview) write_preview(f, fr);
}

/* What replay_tile works on: the farm and the frame whose journal it is. */
typedef struct replay_ctx {
    farm *f;
    farm_frame *fr;
} replay_ctx;

/* A journaled tile goes into the frame's new output file and is DONE. */
static bool replay_tile(void *arg, int tile, const void *chunk, size_t len, char *err,
                        size_t errsz)
{
    farm *f = ((replay_ctx *)arg)->f;
    farm_frame *fr = ((replay_ctx *)arg)->fr;
    if (!image_writer_put_chunk(fr->writer, tile % fr->tiles_x, tile / fr->tiles_x, chunk, len,
                                err, errsz))
        return false;
    if (scheduler_mark_done(f->sched, fr->first + tile)) {
        farm_monitor_tile(f, fr, tile, chunk, len, NULL);
        f->resumed_tiles++;
        fr->done++;
    }
    return true;
}

/* --resume: the journal's tiles are in; otherwise a new, empty journal. */
static int open_journal(farm *f, farm_frame *fr, char *err, size_t errsz)
{
    char *path = journal_path_for(fr->output);
    journal_id id;
    memset(&id, 0, sizeof id);
    snprintf(id.job_hash, sizeof id.job_hash, "%s", fr->jb->hash);
    id.width = (uint32_t)fr->fmt.width;
    id.height = (uint32_t)fr->fmt.height;
    id.tile_size = (uint32_t)fr->fmt.tile_size;
    id.layers = (uint32_t)fr->fmt.layers;
    id.tiles = (uint32_t)fr->ntiles;
    int rc = AAFARM_EXIT_OK;
    bool missing = !f->opt->resume;
    if (f->opt->resume) {
        journal_replay info;
        replay_ctx ctx = {f, fr};
        fr->jnl = journal_resume(path, &id, replay_tile, &ctx, &info, &missing, err, errsz);
        if (fr->jnl) {
            console_log(f->con, CONSOLE_INFO, "resuming: %d of %d tiles taken from %s", info.tiles,
                        fr->ntiles, path);
            if (info.dropped_bytes)
                console_log(f->con, CONSOLE_INFO, "the journal ended in %s: dropped its last "
                            "%llu bytes (those tiles are rendered again)", info.dropped_why,
                            (unsigned long long)info.dropped_bytes);
        } else if (missing) {
            if (!f->serving)   /* a queue's new job has none */
                console_log(f->con, CONSOLE_INFO, "--resume: no journal %s, rendering every tile",
                            path);
        } else {
            rc = image_writer_failed(fr->writer) ? AAFARM_EXIT_FAILURE : AAFARM_EXIT_USAGE;
        }
    }
    if (missing) {
        bool replaced = false;
        fr->jnl = journal_create(path, &id, &replaced, err, errsz);
        if (!fr->jnl) rc = AAFARM_EXIT_FAILURE;
        else if (replaced)
            console_log(f->con, CONSOLE_INFO, "replaced the journal of an unfinished render "
                        "(%s): --resume would have continued it", path);
    }
    free(path);
    return rc;
}

/* Each frame's job message, output file and journal. */
static int setup_frame(farm *f, farm_frame *fr, char *err, size_t errsz)
{
    fr->jobmsg = job_message_new(fr->jb, &fr->fmt);
    fr->files = file_server_new(fr->jb);
    int rc = check_job_message(f, fr, err, errsz);
    if (rc != AAFARM_EXIT_OK) return rc;
    stale_clean_outputs(fr->output, report_leftover, f);
    if (fr->preview) stale_clean_outputs(fr->preview, report_leftover, f);
    fr->writer = image_writer_new(fr->output, &fr->fmt, err, errsz);
    if (!fr->writer) return AAFARM_EXIT_FAILURE;
    rc = open_journal(f, fr, err, errsz);
    if (rc == AAFARM_EXIT_OK && fr->done == fr->ntiles) farm_frame_complete(f, fr);
    return f->state == FARM_FAILED ? AAFARM_EXIT_FAILURE : rc;
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

/* What every render of this master shares: limits, session, host name. */
static void setup_common(farm *f)
{
    bound_limits(f);
    f->failed_tile = -1;
    f->gate_open = f->opt->min_workers <= 1 && f->opt->wait_timeout_ms <= 0;
    f->gate_since_ms = f->gate_said_ms = farm_now_ms();
    f->gate_said = -1;
    f->session = random_session();
    if (gethostname(f->host, sizeof f->host - 1) != 0) snprintf(f->host, sizeof f->host, "master");
}

/* The tiles of frames from .. nframes - 1 after those before them; the
 * scheduler (with a slot for every live worker: a serving master's next
 * job) made, or extended (a serving master's job that joins the queue
 * while the previous one's last tiles are out); the registry the first
 * time; the monitor's frames; and each frame's output and journal. */
static int add_frames(farm *f, int from, char *err, size_t errsz)
{
    int added = 0;
    for (int i = from; i < f->nframes; i++) {
        farm_frame *fr = &f->frames[i];
        fr->tiles_x = image_format_tiles_x(&fr->fmt);
        fr->ntiles = image_format_tile_count(&fr->fmt);
        fr->first = f->ntiles + added;
        if (fr->ntiles > INT_MAX / 4 - fr->first) {
            err_set(err, errsz, "the %d frames have too many tiles to count", f->nframes);
            return AAFARM_EXIT_INPUT;
        }
        added += fr->ntiles;
    }
    if (f->sched) {
        if (added > 0 && !scheduler_extend(f->sched, added)) {
            err_set(err, errsz, "the %d frames have too many tiles to count", f->nframes);
            return AAFARM_EXIT_INPUT;
        }
        f->ntiles += added;
    } else {
        f->ntiles = added;
        scheduler_options so;
        scheduler_options_default(&so);
        so.max_attempts = f->opt->max_attempts;
        so.max_duplicates = f->opt->max_duplicates;
        so.lease_ms = f->opt->lease_ms;
        so.lease_factor = f->opt->lease_factor;
        /* a tile one worker alone gave up on waits for another one while one
         * can join (--bind): as long as the longest lease */
        so.join_window_ms = f->opt->bind ? f->opt->lease_ms : 0;
        /* every frame's tiles in one row-major queue: a worker's run goes on
         * into the next frame, and new runs start in the longest queued run */
        f->sched = scheduler_new(f->ntiles ? f->ntiles : 1, 1, &so);
        if (!f->sched) {
            err_set(err, errsz, "the %d frames have too many tiles to count", f->nframes);
            return AAFARM_EXIT_INPUT;
        }
        if (f->ntiles == 0) scheduler_mark_done(f->sched, 0);   /* a serving master, idle */
        if (!f->reg) f->reg = registry_new();
        for (size_t i = 0; i < registry_count(f->reg); i++) {
            farm_worker *w = registry_at(f->reg, i);
            if (!w->alive) continue;
            w->slot = scheduler_worker_add(f->sched);
            scheduler_worker_threads(f->sched, w->slot, (int)w->threads);
            farm_worker_fit(f, w);
        }
    }
    farm_monitor_open(f, from);
    for (int i = from; i < f->nframes; i++) {
        int rc = setup_frame(f, &f->frames[i], err, errsz);
        if (rc != AAFARM_EXIT_OK) return rc;
    }
    return AAFARM_EXIT_OK;
}

static int setup_job(farm *f, char *err, size_t errsz)
{
    return add_frames(f, 0, err, errsz);
}

static int setup(farm *f, char *err, size_t errsz)
{
    setup_common(f);
    int rc = setup_job(f, err, errsz);
    if (rc != AAFARM_EXIT_OK) return rc;
    rc = open_socket(f, err, errsz);
    if (rc == AAFARM_EXIT_OK) rc = farm_monitor_serve(f, NULL, err, errsz);
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
                    f->wstats.last_error, (unsigned long long)f->drops_unlogged);
    else
        console_log(f->con, CONSOLE_INFO, "%s", f->wstats.last_error);
    f->drops_unlogged = 0;
    f->drop_logged_ms = now;
}

/* Reads what is queued (at most a batch, so timers still run). */
static void drain(farm *f, int64_t now)
{
    for (int i = 0; i < 1000 && f->state == FARM_RUNNING; i++) {
        wire_msg *m = wire_recv(f->router, &f->limits, &f->wstats, ZMQ_DONTWAIT, NULL, 0);
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
        if (f->state == FARM_RUNNING && f->ntiles > 0 && scheduler_finished(f->sched))
            f->state = FARM_DONE;
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
            char why[ERR_LEN];
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

/* Embedded mode: every local worker started joined and is blocklisted, so
 * no one is left to render (none can join). */
static bool all_blocked(const farm *f)
{
    int blocked = 0;
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        if (w->alive && !w->blocked) return false;
        if (w->alive) blocked++;
    }
    return blocked > 0 && local_workers_running(f->locals) <= blocked;
}

/* The command a worker host runs: the bound endpoint, with this host's
 * name for a wildcard address (tcp://0.0.0.0:5555 -> tcp://HOST:5555). */
static void worker_command(const farm *f, char *buf, size_t n)
{
    const char *ep = f->bound;
    const char *wild[] = {"tcp://0.0.0.0:", "tcp://[::]:", "tcp://*:"};
    char host_ep[700];
    for (size_t i = 0; i < sizeof wild / sizeof *wild; i++)
        if (strncmp(ep, wild[i], strlen(wild[i])) == 0) {
            snprintf(host_ep, sizeof host_ep, "tcp://%s:%s", f->host, ep + strlen(wild[i]));
            ep = host_ep;
            break;
        }
    snprintf(buf, n, "aafarm-worker --connect %s%s", ep,
             f->zap ? " --curve-secret NAME.key_secret --master-key MASTER.key" : "");
}

/* Where workers join: the bound endpoint, else the private one. */
static const char *join_endpoint(const farm *f)
{
    return f->bound[0] ? f->bound : f->endpoint;
}

/* --wait-timeout passed: the master gives up (AAFARM_EXIT_NO_WORKERS). */
static void give_up_waiting(farm *f, const char *what)
{
    char cmd[800] = "";
    if (f->bound[0]) worker_command(f, cmd, sizeof cmd);
    snprintf(f->failure, sizeof f->failure, "gave up after --wait-timeout %.0f s: %.120s on %.600s%s%.800s%s",
             (double)f->opt->wait_timeout_ms / 1000.0, what, join_endpoint(f),
             cmd[0] ? " (start workers with: " : "", cmd, cmd[0] ? ")" : "");
    console_log(f->con, CONSOLE_ERROR, "%s", f->failure);
    f->state = FARM_NO_WORKERS;
}

/* --min-workers N: no tile is granted before N workers are alive at once
 * (the gate opens once; workers lost later do not close it). While it is
 * closed the master says how many joined: when that changes, and every
 * FARM_GATE_SAY_MS (or the shorter --wait-report interval). --wait-timeout:
 * closed that long, the master gives up. */
enum { FARM_GATE_SAY_MS = 5000 };

static void check_gate(farm *f, int64_t now)
{
    if (f->gate_open || f->state != FARM_RUNNING) return;
    int need = f->opt->min_workers > 1 ? f->opt->min_workers : 1;
    int alive = registry_alive(f->reg);
    if (alive >= need) {
        f->gate_open = true;
        if (need > 1)
            console_log(f->con, CONSOLE_INFO, "%d of %d workers joined (--min-workers): "
                        "rendering", alive, need);
        return;
    }
    if (f->opt->wait_timeout_ms > 0 && now - f->gate_since_ms >= f->opt->wait_timeout_ms) {
        char what[120];
        if (need == 1) snprintf(what, sizeof what, "no worker joined");
        else snprintf(what, sizeof what, "%d of %d workers joined", alive, need);
        give_up_waiting(f, what);
        return;
    }
    if (need <= 1) return;   /* no worker at all: say_waiting says so */
    int64_t every = f->opt->wait_report_ms < FARM_GATE_SAY_MS ? f->opt->wait_report_ms
                                                              : FARM_GATE_SAY_MS;
    if (alive == f->gate_said && now - f->gate_said_ms < every) return;
    f->gate_said = alive;
    f->gate_said_ms = now;
    console_log(f->con, CONSOLE_INFO, "waiting for workers on %s: %d of %d joined (--min-workers)",
                join_endpoint(f), alive, need);
}

/* --bind and no worker alive: said when the render starts, then again
 * every --wait-report interval with how long it has waited. A farm waits
 * for its workers unless --wait-timeout says how long. */
static void say_waiting(farm *f, int64_t now)
{
    if (!f->opt->bind || !f->bound[0]) return;
    if (registry_alive(f->reg) > 0 || (f->locals && local_workers_running(f->locals) > 0)) {
        f->waiting = false;
        return;
    }
    if (!f->waiting) {   /* the last worker was lost: from now on */
        f->waiting = true;
        f->waiting_since_ms = f->wait_said_ms = now;
        return;
    }
    if (f->gate_open && f->opt->wait_timeout_ms > 0 && f->ntiles > 0 &&
        !scheduler_finished(f->sched) && now - f->waiting_since_ms >= f->opt->wait_timeout_ms) {
        char what[120];
        snprintf(what, sizeof what, "no worker alive (%d joined, none alive now)", f->joined);
        give_up_waiting(f, what);
        return;
    }
    if (!f->gate_open && f->opt->min_workers > 1) return;   /* check_gate says it */
    if (now - f->wait_said_ms < f->opt->wait_report_ms) return;
    f->wait_said_ms = now;
    char cmd[800], joined[64];
    worker_command(f, cmd, sizeof cmd);
    if (f->joined) snprintf(joined, sizeof joined, "%d joined, none alive now", f->joined);
    else snprintf(joined, sizeof joined, "0 joined");
    double secs = (double)(now - f->waiting_since_ms) / 1000.0;
    console_log(f->con, CONSOLE_INFO, "still waiting for workers on %s after %.*f s: %s (start "
                "one with: %s)", f->bound, secs < 10 ? 1 : 0, secs, joined, cmd);
}

/* A serving master whose local workers all exited starts them again,
 * after 1 s, then 2, 4 ... 30 s while they keep exiting (reset when a
 * job is done). */
static void restart_local_workers(farm *f, int64_t now)
{
    if (!f->restart_backoff_ms) f->restart_backoff_ms = 1000;
    if (!f->restart_at_ms) {
        f->restart_at_ms = now + f->restart_backoff_ms;
        console_log(f->con, CONSOLE_INFO, "all %d local workers exited: starting them again in "
                    "%.0f s", f->opt->local_workers, (double)f->restart_backoff_ms / 1000.0);
        return;
    }
    if (now < f->restart_at_ms) return;
    f->restart_at_ms = 0;
    f->restart_backoff_ms = f->restart_backoff_ms * 2 > 30000 ? 30000 : f->restart_backoff_ms * 2;
    local_workers_destroy(&f->locals);
    char err[ERR_LEN];
    if (start_local_workers(f, err, sizeof err) != AAFARM_EXIT_OK) {
        console_log(f->con, CONSOLE_ERROR, "cannot start the local workers again: %s", err);
        return;
    }
    f->restarts++;
    console_log(f->con, CONSOLE_INFO, "started the %d local workers again (restart %d)",
                f->opt->local_workers, f->restarts);
}

static void timers(farm *f, int64_t now)
{
    check_workers(f, now);
    check_gate(f, now);
    if (f->state != FARM_RUNNING) return;
    int tiles[CONSOLE_TALLY_TILES];
    int n = scheduler_expire_list(f->sched, now, tiles, CONSOLE_TALLY_TILES);
    for (int i = 0; i < n; i++) {
        int local = 0;   /* the tiles after the first few are only counted */
        if (i < CONSOLE_TALLY_TILES) farm_frame_of(f, tiles[i], &local);
        console_tally_add(&f->expired, local, NULL);
    }
    console_tally_flush(&f->expired, f->con, now, false);
    say_waiting(f, now);
    if (f->monitor) {
        wire_monitor_poll(f->monitor, &f->wstats, NULL, 0);
        log_handshakes(f, now);
    }
    int given_up = scheduler_check_given_up(f->sched, now);
    if (given_up >= 0) farm_fail_given_up(f, given_up);
    if (f->locals) {
        local_workers_reap(f->locals, on_child_exit, f);
        bool none = local_workers_running(f->locals) == 0 && registry_alive(f->reg) == 0;
        if (f->serving && none) {   /* the job waits in the queue; the workers start again */
            if (!f->opt->bind && f->ntiles > 0) f->state = FARM_REQUEUED;
            restart_local_workers(f, now);
        } else if (!f->opt->bind && none)
            farm_fail(f, "no workers left: all %d local workers exited", f->opt->local_workers);
        else if (!f->opt->bind && all_blocked(f))
            farm_fail(f, "no workers left: every local worker is blocklisted (its results "
                      "were refused)");
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
        if (atomic_load(&interrupted)) {
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
        if (f->ntiles > 0)
            console_progress(f->con, scheduler_tiles_done(f->sched), f->ntiles,
                             registry_alive(f->reg), f->start_ms, now, false);
        farm_monitor_publish(f, now, false);
        if (f->tick) f->tick(f, now);   /* a serving master's queue (serve.c) */
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

/* Every frame's journal: deleted when the whole sequence is in place (so
 * that --resume after a failure replays the frames already written too),
 * or when it holds nothing; otherwise synced and kept. */
static void close_journals(farm *f)
{
    bool told = false;   /* the --resume hint is given once */
    for (int i = 0; i < f->nframes; i++) {
        farm_frame *fr = &f->frames[i];
        if (!fr->jnl) continue;
        if (f->state == FARM_DONE || fr->done == 0 ||
            (f->serving && !fr->keep_journal)) {   /* failed, cancelled: no resume */
            journal_remove(&fr->jnl);   /* the image is in place, or nothing to resume */
            continue;
        }
        char jerr[ERR_LEN];
        if (!journal_sync(fr->jnl, jerr, sizeof jerr))
            console_log(f->con, CONSOLE_ERROR, "%s", jerr);
        else if (!told && !f->serving)
            console_log(f->con, CONSOLE_ERROR, "%d of %d tiles kept in %s%s: the same command "
                        "with --resume renders only the others", scheduler_tiles_done(f->sched),
                        f->ntiles, journal_file(fr->jnl),
                        f->nframes > 1 ? " and the other frames' journals" : "");
        told = true;
        journal_close(&fr->jnl);
    }
}

static int finish(farm *f)
{
    char err[ERR_LEN];
    close_journals(f);
    f->end_ms = farm_now_ms();
    console_tally_flush(&f->expired, f->con, f->end_ms, true);   /* none left unsaid */
    if (f->state == FARM_DONE)
        console_progress(f->con, f->ntiles, f->ntiles, registry_alive(f->reg), f->start_ms,
                         f->end_ms, true);
    tell_workers(f, f->end_ms);
    if (f->locals) local_workers_stop(f->locals, 2000);
    int rc = AAFARM_EXIT_OK;
    const farm_frame *last = &f->frames[f->nframes - 1];
    switch (f->state) {
    case FARM_DONE:
        if (f->nonfinite_samples)
            console_log(f->con, CONSOLE_ERROR, "warning: %llu NaN/Inf samples in %d tiles were "
                        "written as 0 (Z: as no hit); a shader divides by zero or overflows "
                        "there", (unsigned long long)f->nonfinite_samples, f->nonfinite_tiles);
        if (f->nframes == 1)
            console_log(f->con, CONSOLE_INFO, "wrote %s (%dx%d, %d tiles, %.2f s)", last->output,
                        last->fmt.width, last->fmt.height, f->ntiles,
                        (double)(f->end_ms - f->start_ms) / 1000.0);
        else
            console_log(f->con, CONSOLE_INFO, "wrote %d frames (%s ... %s, %d tiles, %.2f s)",
                        f->nframes, f->frames[0].output, last->output, f->ntiles,
                        (double)(f->end_ms - f->start_ms) / 1000.0);
        break;
    case FARM_INTERRUPTED:
        if (f->nframes == 1)
            console_log(f->con, CONSOLE_ERROR, "interrupted; %s %s", last->output,
                        last->written ? "written, its preview not" : "not written");
        else
            console_log(f->con, CONSOLE_ERROR, "interrupted; %d of %d frames written",
                        f->frames_written, f->nframes);
        rc = AAFARM_EXIT_INTERRUPTED;
        break;
    case FARM_NO_WORKERS:   /* the reason was said when it gave up */
        if (f->nframes == 1)
            console_log(f->con, CONSOLE_ERROR, "%s not written", last->output);
        else
            console_log(f->con, CONSOLE_ERROR, "%d of %d frames written", f->frames_written,
                        f->nframes);
        rc = AAFARM_EXIT_NO_WORKERS;
        break;
    default:
        console_log(f->con, CONSOLE_ERROR, "render failed: %s", f->failure);
        if (f->nframes == 1)
            console_log(f->con, CONSOLE_ERROR, "%s not written", last->output);
        else
            console_log(f->con, CONSOLE_ERROR, "%d of %d frames written", f->frames_written,
                        f->nframes);
        rc = AAFARM_EXIT_FAILURE;
        break;
    }
    farm_report_summary(f);
    farm_monitor_publish(f, f->end_ms, true);
    if (f->opt->stats_json && !farm_report_json(f, f->opt->stats_json, err, sizeof err)) {
        console_log(f->con, CONSOLE_ERROR, "%s", err);
        if (rc == AAFARM_EXIT_OK) rc = AAFARM_EXIT_FAILURE;
    }
    return rc;
}

static void teardown(farm *f)
{
    farm_monitor_close(f);   /* the HTTP thread ends first */
    for (int i = 0; i < f->nframes; i++) {
        farm_frame *fr = &f->frames[i];
        image_writer_destroy(&fr->writer);   /* unfinished: removes the temporary file */
        if (fr->jnl && fr->done == 0) journal_remove(&fr->jnl);
        journal_close(&fr->jnl);             /* kept for --resume */
        job_message_destroy(&fr->jobmsg);
        file_server_destroy(&fr->files);
    }
    local_workers_destroy(&f->locals);
    wire_monitor_destroy(&f->monitor);
    if (f->router) zmq_close(f->router);
    zap_destroy(&f->zap);
    if (f->ctx) zmq_ctx_term(f->ctx);
    remove_private_endpoint(f);
    registry_destroy(&f->reg);
    scheduler_destroy(&f->sched);
    free(f->given_up);
    f->given_up = NULL;
    console_destroy(&f->con);
    free(f->frames);
}

void farm_console_open(farm *f, const farm_options *opt)
{
    f->con = console_new(opt->verbosity, isatty(STDERR_FILENO));
    char detail[200];
    snprintf(detail, sizeof detail, "without a result (%d x the measured time per tile, at most "
             "%.0f s): back in the queue", opt->lease_factor, (double)opt->lease_ms / 1000.0);
    console_tally_init(&f->expired, "lease passed its deadline", "leases passed their deadlines",
                       detail, FARM_WARN_INTERVAL_MS);
}

int farm_run(const farm_options *opt, const farm_frame_in *frames, int nframes)
{
    farm f;
    memset(&f, 0, sizeof f);
    f.opt = opt;
    f.pool = opt->pool;
    f.nframes = nframes;
    f.frames = xcalloc((size_t)nframes, sizeof *f.frames);
    for (int i = 0; i < nframes; i++) {
        f.frames[i].jb = frames[i].jb;
        f.frames[i].fmt = frames[i].fmt;
        f.frames[i].output = frames[i].output;
        f.frames[i].preview = frames[i].preview;
        f.frames[i].job_frames = nframes;
    }
    f.fmt = frames[0].fmt;   /* the tile size (the same in every frame): limits */
    farm_console_open(&f, opt);

    farm_catch_signals();

    char err[2 * ERR_LEN];   /* setup's messages: a prefix and a callee's ERR_LEN message */
    int rc = setup(&f, err, sizeof err);
    if (rc != AAFARM_EXIT_OK) {
        console_log(f.con, CONSOLE_ERROR, "%s", err);
        teardown(&f);
        return rc;
    }
    f.start_ms = farm_now_ms();
    console_set_resumed(f.con, f.resumed_tiles);
    if (nframes == 1)
        console_log(f.con, CONSOLE_INFO, "%s: %dx%d, %d tiles of %d, job %.12s (%zu bytes%s)",
                    opt->scene_path, f.fmt.width, f.fmt.height, f.ntiles, f.fmt.tile_size,
                    frames[0].jb->hash, f.job_bytes, frames[0].jb->nfiles ? ", files below" : "");
    else
        console_log(f.con, CONSOLE_INFO, "%s: %d frames (%d ... %d), %d tiles of %d in one "
                    "queue, %zu job bytes", opt->scene_path, nframes,
                    frames[0].jb->frame_number, frames[nframes - 1].jb->frame_number, f.ntiles,
                    f.fmt.tile_size, f.job_bytes);
    if (frames[0].jb->nfiles)   /* the files go once per host, not with every Job */
        console_log(f.con, CONSOLE_INFO, "%d file%s of %llu bytes, sent once per host",
                    frames[0].jb->nfiles, frames[0].jb->nfiles == 1 ? "" : "s",
                    (unsigned long long)job_files_bytes(frames[0].jb));
    if (scheduler_finished(f.sched)) f.state = FARM_DONE;   /* all resumed */
    if (opt->bind && !f.locals && f.state == FARM_RUNNING) {
        char cmd[800], joined[64] = "0 joined";
        worker_command(&f, cmd, sizeof cmd);
        if (opt->min_workers > 1) {
            snprintf(joined, sizeof joined, "0 of %d joined (--min-workers)", opt->min_workers);
            f.gate_said = 0;
            f.gate_said_ms = farm_now_ms();
        }
        console_log(f.con, CONSOLE_INFO, "waiting for workers on %s (start one with: %s); %s",
                    f.bound, cmd, joined);
        f.waiting = true;
        f.waiting_since_ms = f.wait_said_ms = farm_now_ms();
    }
    run_loop(&f);
    rc = finish(&f);
    farm_monitor_linger(&f, &interrupted);
    teardown(&f);
    return rc;
}

/* ---- a serving master (serve.c; see farm_internal.h) ---- */

const atomic_int *farm_interrupted(void)
{
    return &interrupted;
}

int farm_serve_open(farm *f, char *err, size_t errsz)
{
    f->serving = true;
    f->fmt.tile_size = 1024;   /* limits for a tile of any job (--tile at most 1024) */
    setup_common(f);
    f->reg = registry_new();
    f->sched = NULL;
    int rc = open_socket(f, err, errsz);
    if (rc == AAFARM_EXIT_OK) rc = start_local_workers(f, err, errsz);
    return rc;
}

int farm_serve_job(farm *f, const farm_frame_in *frames, int nframes, char *err, size_t errsz)
{
    f->frames = xcalloc((size_t)(nframes ? nframes : 1), sizeof *f->frames);
    f->nframes = nframes;
    for (int i = 0; i < nframes; i++) {
        f->frames[i].jb = frames[i].jb;
        f->frames[i].fmt = frames[i].fmt;
        f->frames[i].output = frames[i].output;
        f->frames[i].preview = frames[i].preview;
        f->frames[i].job_frames = nframes;
    }
    f->ntiles = 0;
    f->frames_written = 0;
    f->resumed_tiles = 0;
    f->state = FARM_RUNNING;
    f->failure[0] = '\0';
    f->failed_tile = -1;
    f->end_ms = 0;
    f->nonfinite_samples = 0;
    f->nonfinite_tiles = 0;
    console_set_prefix(f->con, "");
    int rc = setup_job(f, err, errsz);
    f->start_ms = farm_now_ms();
    console_set_resumed(f->con, f->resumed_tiles);
    if (rc == AAFARM_EXIT_OK && f->ntiles > 0 && scheduler_finished(f->sched) &&
        f->state == FARM_RUNNING)
        f->state = FARM_DONE;   /* all resumed */
    return rc;
}

int farm_serve_append(farm *f, const farm_frame_in *frames, int nframes, char *err, size_t errsz)
{
    int from = f->nframes;
    f->frames = xreallocarray(f->frames, (size_t)(from + nframes), sizeof *f->frames);
    memset(&f->frames[from], 0, (size_t)nframes * sizeof *f->frames);
    for (int i = 0; i < nframes; i++) {
        farm_frame *fr = &f->frames[from + i];
        fr->jb = frames[i].jb;
        fr->fmt = frames[i].fmt;
        fr->output = frames[i].output;
        fr->preview = frames[i].preview;
        fr->first = f->ntiles;
        fr->job_first = from;
        fr->job_frames = nframes;
    }
    f->nframes += nframes;
    int resumed = f->resumed_tiles;
    int rc = add_frames(f, from, err, errsz);
    if (f->resumed_tiles != resumed) console_set_resumed(f->con, f->resumed_tiles);
    if (rc == AAFARM_EXIT_OK && f->state == FARM_RUNNING && scheduler_finished(f->sched))
        f->state = FARM_DONE;   /* every tile of every job is in (the new one's resumed) */
    return rc;
}

void farm_serve_loop(farm *f)
{
    if (f->state == FARM_RUNNING) run_loop(f);
}

void farm_serve_end_job(farm *f)
{
    int64_t now = farm_now_ms();
    close_journals(f);
    f->end_ms = now;
    if (f->state == FARM_DONE && f->ntiles > 0) f->restart_backoff_ms = 1000;
    console_tally_flush(&f->expired, f->con, now, true);
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        farm_worker *w = registry_at(f->reg, i);
        if (w->alive && w->has_job && f->nframes) farm_send_job_done(f, w, now);
        w->has_job = false;   /* the next job starts afresh; the worker stays */
        w->nheld = 0;
        w->files_ready = false;
        w->blocked = false;
        w->benched = false;
        w->other_pool = false;
        w->nfailed = 0;
        w->strikes = 0;
    }
    farm_monitor_publish(f, now, true);
    for (int i = 0; i < f->nframes; i++) {
        farm_frame *fr = &f->frames[i];
        image_writer_destroy(&fr->writer);   /* unfinished: removes the temporary file */
        journal_close(&fr->jnl);
        job_message_destroy(&fr->jobmsg);
        file_server_destroy(&fr->files);
    }
    scheduler_destroy(&f->sched);
    free(f->given_up);
    f->given_up = NULL;
    f->ngiven_up = 0;
    free(f->frames);
    f->frames = NULL;
    f->nframes = 0;
    f->ntiles = 0;
}

void farm_serve_close(farm *f)
{
    f->end_ms = farm_now_ms();
    tell_workers(f, f->end_ms);
    if (f->locals) local_workers_stop(f->locals, 2000);
    teardown(f);
}
