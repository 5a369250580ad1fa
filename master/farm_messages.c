/*
 * farm_messages.c: the master's side of each message (docs/protocol.md,
 * "The master's state machine"), and the messages it sends.
 *
 *   Hello      version check (Reject VERSION_MISMATCH), register, Welcome
 *   Ask        credits += n; granting happens in farm_grant_all()
 *   Result     stale (unknown lease, other job) / duplicate (tile DONE) /
 *              taken: the EXR is validated, its chunk appended to the
 *              journal and copied into the output; an invalid EXR counts
 *              as a retryable failure of the worker (--retries of them:
 *              the worker is blocklisted for the job), a write error of the
 *              journal or the output fails the render (the master's fault)
 *   Failure    retried elsewhere up to max_attempts, then the job fails
 *              when two workers agree; a tile one worker alone gave up on
 *              waits --lease for another (scheduler.h, docs/farm.md
 *              "Failures": no single peer ends a render)
 *   NeedJob    the Job again
 *   NeedFile   the chunk of the job's file, read from disk (FileChunk +
 *              bulk); a file changed since job_load fails the render
 *   FilesReady the worker's store statistics for the summary
 *   Heartbeat  liveness only (any message counts)
 *   Shutdown   the worker leaves: its tiles go back to the queue
 * Anything but Hello from a peer the master does not know gets Reject
 * HELLO_FIRST, at most once per heartbeat interval per peer.
 */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "farm_internal.h"
#include "util/err.h"
#include "util/xalloc.h"
#include "version.h"

/* ---- sending ---- */

static int send_to(farm *f, const uint8_t *id, size_t id_len, const proto_msg *msg,
                   const void *bulk, size_t bulk_len, char *err, size_t errsz)
{
    return wire_send_limited(f->router, &f->send_limits, id, id_len, msg, bulk, bulk_len, err,
                             errsz);
}

/* Sends to a registered worker; a worker that cannot be reached any more
 * (connection gone, or its queue full because it stopped reading) is
 * lost. bulk: a FileChunk's bytes (NULL otherwise). */
static int send_msg_bulk(farm *f, farm_worker *w, const proto_msg *msg, const void *bulk,
                         size_t bulk_len, int64_t now)
{
    size_t n = proto_msg_packed_size(msg);
    char err[ERR_LEN];
    if (send_to(f, w->id, w->id_len, msg, bulk, bulk_len, err, sizeof err) != 0) {
        int e = errno;
        const char *what = proto_message_name(msg->kind);
        if (e == EHOSTUNREACH) {
            farm_lose_worker(f, w, "disconnected", now);
        } else if (e == EAGAIN) {
            farm_lose_worker(f, w, "stopped reading its messages", now);
        } else {
            console_log(f->con, CONSOLE_ERROR, "cannot send %s to worker %s: %s", what,
                        w->name, err);
        }
        return -1;
    }
    w->last_sent_ms = now;
    w->bytes_out += n + bulk_len;
    f->sent_bytes += n + bulk_len;
    return (int)n;
}

static int send_msg(farm *f, farm_worker *w, const proto_msg *msg, int64_t now)
{
    return send_msg_bulk(f, w, msg, NULL, 0, now);
}

static void send_reject(farm *f, const uint8_t *id, size_t id_len, proto_reject_code code,
                        const char *reason)
{
    proto_msg msg = {.kind = PROTO_REJECT,
                     .reject = {code, reason, AAFARM_PROTOCOL_VERSION}};
    if (send_to(f, id, id_len, &msg, NULL, 0, NULL, 0) == 0) f->rejects_sent++;
}

static void send_welcome(farm *f, farm_worker *w, int64_t now)
{
    proto_msg msg = {.kind = PROTO_WELCOME,
                     .welcome = {.protocol_version = AAFARM_PROTOCOL_VERSION,
                                 .master_name = f->host,
                                 .master_session = f->session,
                                 .heartbeat_ms = (uint32_t)f->opt->heartbeat_ms,
                                 .heartbeat_liveness = (uint32_t)f->opt->liveness}};
    send_msg(f, w, &msg, now);
}

/* Does the worker hold the frame's job (as far as the master knows: a
 * worker that dropped it asks again with NeedJob)? A serving master's
 * run may hold the same job twice (one scene submitted twice, to two
 * outputs): the worker holds it by its hash. */
static bool holds_frame(const farm *f, const farm_worker *w, int frame)
{
    for (int i = 0; i < w->nheld; i++)
        if (w->held[i] == frame ||
            strcmp(f->frames[w->held[i]].jb->hash, f->frames[frame].jb->hash) == 0)
            return true;
    return false;
}

static void mark_held(farm_worker *w, int frame)
{
    int n = (int)(sizeof w->held / sizeof w->held[0]);
    int keep = 0;
    for (int i = 0; i < w->nheld; i++)
        if (w->held[i] != frame) w->held[keep++] = w->held[i];
    if (keep == n) {
        memmove(&w->held[0], &w->held[1], sizeof w->held[0] * (size_t)(n - 1));
        keep--;
    }
    w->held[keep++] = frame;
    w->nheld = keep;
    w->has_job = true;
}

static int send_job(farm *f, farm_worker *w, farm_frame *fr, int64_t now)
{
    proto_msg msg = {.kind = PROTO_JOB, .job = *job_message_job(fr->jobmsg)};
    int n = send_msg(f, w, &msg, now);
    if (n < 0) return -1;
    mark_held(w, (int)(fr - f->frames));
    if (fr->jb->nfiles > 0 && !w->files_ready)   /* its leases wait for the files */
        scheduler_worker_waiting(f->sched, w->slot, true, now);
    w->job_bytes += (uint64_t)n;
    f->jobs_sent++;
    if (f->nframes > 1)
        console_log(f->con, CONSOLE_DETAIL, "sent the job of frame %d (%d bytes) to %s",
                    fr->jb->frame_number, n, w->name);
    else
        console_log(f->con, CONSOLE_DETAIL, "sent the job (%d bytes) to %s", n, w->name);
    return 0;
}

static int send_grant(farm *f, farm_worker *w, const scheduler_lease *l, int64_t now)
{
    int local;
    farm_frame *fr = farm_frame_of(f, l->tile, &local);
    image_rect r = image_format_tile_rect(&fr->fmt, local % fr->tiles_x, local / fr->tiles_x);
    proto_msg msg = {.kind = PROTO_GRANT,
                     .grant = {.job_hash = fr->jb->hash,
                               .lease_id = l->id,
                               .tile_index = (uint32_t)local,
                               .tile = {(uint32_t)r.x0, (uint32_t)r.y0, (uint32_t)r.w,
                                        (uint32_t)r.h},
                               .deadline_ms = (uint32_t)(l->deadline_ms - l->granted_ms)}};
    int n = send_msg(f, w, &msg, now);
    if (n < 0) return -1;
    f->grant_bytes += (uint64_t)n;
    if (f->nframes > 1)
        console_log(f->con, CONSOLE_DETAIL, "granted frame %d tile %d to %s (lease %llu%s)",
                    fr->jb->frame_number, local, w->name, (unsigned long long)l->id,
                    l->duplicate ? ", duplicate" : "");
    else
        console_log(f->con, CONSOLE_DETAIL, "granted tile %d to %s (lease %llu%s)", l->tile,
                    w->name, (unsigned long long)l->id, l->duplicate ? ", duplicate" : "");
    return 0;
}

void farm_send_heartbeat(farm *f, farm_worker *w, int64_t now)
{
    proto_msg msg = {.kind = PROTO_HEARTBEAT};
    send_msg(f, w, &msg, now);
}

/* JobDone for each frame whose job the worker holds. */
void farm_send_job_done(farm *f, farm_worker *w, int64_t now)
{
    for (int i = 0; i < w->nheld; i++) {
        proto_msg msg = {.kind = PROTO_JOB_DONE};
        proto_job_done *d = &msg.job_done;
        const farm_frame *fr = &f->frames[w->held[i]];
        farm_state st = fr->end != FARM_RUNNING ? fr->end : f->state;   /* its job's end */
        d->job_hash = fr->jb->hash;
        d->status = st == FARM_DONE     ? PROTO_JOB_STATUS_DONE
                    : st == FARM_FAILED ? PROTO_JOB_STATUS_FAILED
                                        : PROTO_JOB_STATUS_CANCELLED;
        d->message = st == FARM_DONE         ? ""
                     : st == FARM_FAILED     ? f->failure
                     : st == FARM_CANCELLED  ? "cancelled"
                     : st == FARM_NO_WORKERS ? "the master gave up waiting for workers"
                                             : "interrupted";
        send_msg(f, w, &msg, now);
    }
}

void farm_send_shutdown(farm *f, farm_worker *w, const char *reason, int64_t now)
{
    proto_msg msg = {.kind = PROTO_SHUTDOWN, .shutdown = {reason}};
    send_msg(f, w, &msg, now);
}

/* ---- bookkeeping ---- */

static void fail_v(farm *f, int tile, const char *fmt, va_list ap)
{
    if (f->state != FARM_RUNNING) return;
    vsnprintf(f->failure, sizeof f->failure, fmt, ap);
    f->failed_tile = tile;
    f->state = FARM_FAILED;
}

void farm_fail(farm *f, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fail_v(f, -1, fmt, ap);
    va_end(ap);
}

void farm_fail_tile(farm *f, int tile, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fail_v(f, tile, fmt, ap);
    va_end(ap);
}

void farm_lose_worker(farm *f, farm_worker *w, const char *why, int64_t now)
{
    if (!w->alive) return;
    int requeued = scheduler_worker_remove(f->sched, w->slot);
    registry_retire(f->reg, w, why, now);
    console_log(f->con, CONSOLE_INFO, "worker %s %s; %d tile%s back in the queue", w->name, why,
                requeued, requeued == 1 ? "" : "s");
}

static bool holds_job(const proto_hello *h, const char *hash)
{
    for (size_t i = 0; i < h->n_jobs_held; i++)
        if (strcmp(h->jobs_held[i], hash) == 0) return true;
    return false;
}

static void copy_name(char *dst, size_t n, const char *src)
{
    snprintf(dst, n, "%s", src && *src ? src : "?");
}

/* ---- incoming messages ---- */

static void on_hello(farm *f, const proto_hello *h, const uint8_t *id, size_t id_len,
                     int64_t now)
{
    char why[ERR_LEN], hex[24];
    if (proto_version_check(AAFARM_PROTOCOL_VERSION, h->protocol_version, why, sizeof why) != 0) {
        f->version_mismatches++;
        console_log(f->con, CONSOLE_INFO, "refused worker %s on %s (peer %s): %s",
                    h->worker_name && *h->worker_name ? h->worker_name : "?",
                    h->host && *h->host ? h->host : "?", registry_id_hex(id, id_len, hex, sizeof hex),
                    why);
        send_reject(f, id, id_len, PROTO_REJECT_VERSION_MISMATCH, why);
        return;
    }
    farm_worker *w = registry_find(f->reg, id, id_len);
    if (w) farm_lose_worker(f, w, "said Hello again", now);
    if (registry_alive(f->reg) >= f->opt->max_workers) {
        snprintf(why, sizeof why, "the master serves at most %d workers at a time "
                 "(--max-workers)", f->opt->max_workers);
        console_log(f->con, CONSOLE_INFO, "refused worker %s on %s (peer %s): %s",
                    h->worker_name && *h->worker_name ? h->worker_name : "?",
                    h->host && *h->host ? h->host : "?", registry_id_hex(id, id_len, hex, sizeof hex),
                    why);
        send_reject(f, id, id_len, PROTO_REJECT_REFUSED, why);
        return;
    }
    w = registry_add(f->reg, id, id_len, now);
    if (!w) return;
    copy_name(w->name, sizeof w->name, h->worker_name);
    copy_name(w->host, sizeof w->host, h->host);
    w->pid = h->pid;
    /* its credits are capped by its threads: a claim of more than a worker
     * can have (aafarm-worker --threads 1..1024) buys a peer no more tiles */
    w->threads = h->threads ? (h->threads > 1024 ? 1024 : h->threads) : 1;
    snprintf(w->pool, sizeof w->pool, "%s", h->pool ? h->pool : "");
    w->slot = scheduler_worker_add(f->sched);
    scheduler_worker_threads(f->sched, w->slot, (int)w->threads);
    farm_worker_fit(f, w);
    for (int i = 0; i < f->nframes; i++)
        if (holds_job(h, f->frames[i].jb->hash)) mark_held(w, i);
    w->local = f->locals && strcmp(w->host, f->host) == 0 &&
               local_workers_has_pid(f->locals, (pid_t)w->pid);
    f->joined++;
    console_log(f->con, CONSOLE_INFO, "worker %s joined (%s, pid %u, %u thread%s%s%s%s)", w->name,
                w->host, w->pid, w->threads, w->threads == 1 ? "" : "s",
                w->pool[0] ? ", pool " : "", w->pool,
                !w->nheld ? "" : f->nframes == 1 ? ", holds the job" : ", holds frames' jobs");
    send_welcome(f, w, now);
}

void farm_worker_fit(farm *f, farm_worker *w)
{
    w->other_pool = f->pool && *f->pool && strcmp(w->pool, f->pool) != 0;
    if (w->other_pool) scheduler_worker_remove(f->sched, w->slot);
}

/* No more tiles of this job for a worker whose failed tiles others
 * finish; it stays connected (the next job gives it tiles again). */
static void bench(farm *f, farm_worker *w, int local)
{
    w->benched = true;
    int requeued = scheduler_worker_remove(f->sched, w->slot);
    console_log(f->con, CONSOLE_INFO, "worker %s benched for this job: %d tiles it failed were "
                "finished by other workers (the last: tile %d; its error: %s); %d tile%s back in "
                "the queue", w->name, w->strikes, local, w->last_error, requeued,
                requeued == 1 ? "" : "s");
}

/* Tile `tile` was taken from w: a strike for each other worker that failed it. */
static void strike_failers(farm *f, const farm_worker *w, int tile, int local)
{
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        farm_worker *x = registry_at(f->reg, i);
        if (x == w || !x->alive || x->benched || x->blocked) continue;
        for (int k = 0; k < x->nfailed; k++) {
            if (x->failed_tiles[k] != tile) continue;
            x->failed_tiles[k] = x->failed_tiles[--x->nfailed];
            if (++x->strikes >= FARM_BENCH_AFTER) bench(f, x, local);
            break;
        }
    }
}

/* w failed the tile: remembered (the last REGISTRY_FAILED) for its strikes. */
static void remember_failed(farm_worker *w, int tile)
{
    for (int k = 0; k < w->nfailed; k++)
        if (w->failed_tiles[k] == tile) return;
    if (w->nfailed == REGISTRY_FAILED) {
        memmove(w->failed_tiles, w->failed_tiles + 1, sizeof w->failed_tiles[0] * (REGISTRY_FAILED - 1));
        w->nfailed--;
    }
    w->failed_tiles[w->nfailed++] = tile;
}

static void on_ask(farm *f, farm_worker *w, const proto_ask *a)
{
    (void)f;
    /* a worker asks for about two tiles per thread; more is a broken peer */
    uint64_t cap = 4u * (uint64_t)w->threads + 8u;
    uint64_t c = (uint64_t)w->credits + a->credits;
    w->credits = (uint32_t)(c > cap ? cap : c);
}

static void tile_failed(farm *f, farm_worker *w, uint64_t lease, int tile, const char *text,
                        bool retryable)
{
    /* the message without trailing line breaks, for one log line (a worker's
     * Failure text may be longer: it is cut here) */
    char msg[2 * ERR_LEN];
    snprintf(msg, sizeof msg, "%s", text);
    for (size_t n = strlen(msg); n > 0 && (msg[n - 1] == '\n' || msg[n - 1] == ' ');)
        msg[--n] = '\0';
    scheduler_failure r = scheduler_fail(f->sched, w->slot, lease, retryable);
    if (r == SCHEDULER_FAIL_IGNORED) return;
    w->failures++;
    remember_failed(w, tile);
    snprintf(w->last_error, sizeof w->last_error, "%s", msg);
    int local;
    farm_frame *fr = farm_frame_of(f, tile, &local);
    image_rect rect = image_format_tile_rect(&fr->fmt, local % fr->tiles_x, local / fr->tiles_x);
    int attempts = scheduler_tile_attempts(f->sched, tile);
    char frame[40] = "";
    if (f->nframes > 1) snprintf(frame, sizeof frame, "frame %d ", fr->jb->frame_number);
    if (r == SCHEDULER_RETRY) {
        console_log(f->con, CONSOLE_INFO,
                    "%stile %d at (%d,%d) failed on %s (attempt %d of %d): %s; trying again",
                    frame, local, rect.x0, rect.y0, w->name, attempts, f->opt->max_attempts, msg);
        return;
    }
    if (r == SCHEDULER_AWAIT_OTHER) {
        /* one worker alone: the words are kept for the render's failure,
         * should no other worker come within the window */
        f->given_up = xreallocarray(f->given_up, f->ngiven_up + 1, sizeof *f->given_up);
        farm_given_up *g = &f->given_up[f->ngiven_up++];
        g->tile = tile;
        snprintf(g->failure, sizeof g->failure, "%stile %d at (%d,%d) failed on worker %s only "
                 "(attempts exhausted): %s", frame, local, rect.x0, rect.y0, w->name, msg);
        console_log(f->con, CONSOLE_INFO, "%stile %d at (%d,%d) failed on %s (attempt %d of %d): "
                    "%s; no other worker has tried it: waiting up to %.0f s for one (--lease)",
                    frame, local, rect.x0, rect.y0, w->name, attempts, f->opt->max_attempts, msg,
                    (double)f->opt->lease_ms / 1000.0);
        return;
    }
    farm_fail_tile(f, tile, "%stile %d at (%d,%d) failed on worker %s (%s): %s", frame, local, rect.x0,
              rect.y0, w->name, retryable ? "attempts exhausted" : "not retryable, confirmed "
              "by a second worker", msg);
}

void farm_fail_given_up(farm *f, int tile)
{
    for (size_t i = 0; i < f->ngiven_up; i++)
        if (f->given_up[i].tile == tile) {
            farm_fail_tile(f, tile, "%s; no other worker could try it within %.0f s (--lease)",
                      f->given_up[i].failure, (double)f->opt->lease_ms / 1000.0);
            return;
        }
    farm_fail_tile(f, tile, "tile %d: every worker gave it up", tile);   /* not reached */
}

/* A worker whose results were refused --retries times gets no more tiles
 * of this job (its leases go back to the queue); it stays connected. */
static void blocklist(farm *f, farm_worker *w)
{
    if (w->blocked) return;
    w->blocked = true;
    int requeued = scheduler_worker_remove(f->sched, w->slot);
    console_log(f->con, CONSOLE_INFO, "worker %s blocklisted for this job: %llu of its results "
                "refused; %d tile%s back in the queue", w->name,
                (unsigned long long)w->invalid_tiles, requeued, requeued == 1 ? "" : "s");
}

static void add_stats(farm_worker *w, const proto_tile_stats *s)
{
    w->rays += s->rays;
    w->boxes += s->boxes;
    w->shader_evals += s->shader_evals;
    w->cache_hits += s->cache_hits;
    w->cache_misses += s->cache_misses;
    w->cache_evictions += s->cache_evictions;
    if (s->peak_cache_bytes > w->peak_cache_bytes) w->peak_cache_bytes = s->peak_cache_bytes;
    w->render_seconds += s->wall_seconds;
    w->nonfinite_samples += s->nonfinite_samples;
    w->cpu_seconds += s->cpu_seconds;
}

static void on_result(farm *f, farm_worker *w, const proto_result *r, const wire_msg *m,
                      int64_t now)
{
    size_t len = 0;
    const uint8_t *bulk = wire_msg_bulk(m, &len);
    w->bytes_in += len;
    f->result_bytes += len;
    const scheduler_lease *held = scheduler_lease_find(f->sched, w->slot, r->lease_id);
    int local = 0;
    farm_frame *fr = held ? farm_frame_of(f, held->tile, &local) : NULL;
    bool ours = fr && strcmp(r->job_hash, fr->jb->hash) == 0;
    scheduler_verdict v = ours ? scheduler_check_result(f->sched, w->slot, r->lease_id)
                               : SCHEDULER_STALE;
    if (v != SCHEDULER_TAKEN) {
        scheduler_complete(f->sched, w->slot, ours ? r->lease_id : 0, now);   /* counts it */
        if (v == SCHEDULER_DUPLICATE) w->duplicates++;
        console_log(f->con, CONSOLE_DETAIL, "%s result from %s (lease %llu) dropped",
                    v == SCHEDULER_DUPLICATE ? "duplicate" : "stale", w->name,
                    (unsigned long long)r->lease_id);
        return;
    }
    int tile = held->tile;
    char err[ERR_LEN];
    if (r->tile_index != (uint32_t)local) {
        err_set(err, sizeof err, "its result names tile %u, the lease was for tile %d",
                r->tile_index, local);
    } else {
        image_rect rect = image_format_tile_rect(&fr->fmt, local % fr->tiles_x,
                                                 local / fr->tiles_x);
        const void *chunk = NULL;
        size_t chunk_len = 0;
        if (image_tile_exr_chunk(bulk, len, &fr->fmt, rect, &chunk, &chunk_len, err, sizeof err)) {
            /* journal first: a tile in the journal survives the master */
            char ioerr[ERR_LEN];
            if (!journal_append(fr->jnl, local, chunk, chunk_len, now, ioerr, sizeof ioerr) ||
                !image_writer_put_chunk(fr->writer, local % fr->tiles_x, local / fr->tiles_x,
                                        chunk, chunk_len, ioerr, sizeof ioerr)) {
                /* the master's own output failed (disk full): not the
                 * worker's fault, and no other worker can do better */
                farm_fail_tile(f, tile, "%s", ioerr);
                return;
            }
            scheduler_complete(f->sched, w->slot, r->lease_id, now);
            farm_monitor_tile(f, fr, local, chunk, chunk_len, w);
            w->tiles++;
            add_stats(w, &r->stats);
            strike_failers(f, w, tile, local);
            if (r->stats.nonfinite_samples) {
                if (f->nonfinite_tiles++ == 0)
                    console_log(f->con, CONSOLE_INFO, "warning: tile %d at (%d,%d) from %s had %llu "
                                "NaN/Inf samples, written as 0 (further ones are counted at the "
                                "end)", local, rect.x0, rect.y0, w->name,
                                (unsigned long long)r->stats.nonfinite_samples);
                f->nonfinite_samples += r->stats.nonfinite_samples;
            }
            char frame[40] = "";
            if (f->nframes > 1) snprintf(frame, sizeof frame, "frame %d ", fr->jb->frame_number);
            console_log(f->con, CONSOLE_DETAIL, "took %stile %d from %s (lease %llu, %zu bytes)",
                        frame, local, w->name, (unsigned long long)r->lease_id, len);
            if (++fr->done == fr->ntiles) farm_frame_complete(f, fr);
            return;
        }
    }
    f->invalid_tiles++;
    w->invalid_tiles++;
    err_prefix(err, sizeof err, "invalid tile from the worker");
    tile_failed(f, w, r->lease_id, tile, err, true);
    if (w->invalid_tiles >= (uint64_t)f->opt->max_attempts) blocklist(f, w);
}

static void on_failure(farm *f, farm_worker *w, const proto_failure *x)
{
    const scheduler_lease *l = scheduler_lease_find(f->sched, w->slot, x->lease_id);
    int local;
    if (l && strcmp(x->job_hash, farm_frame_of(f, l->tile, &local)->jb->hash) != 0) return;
    if (!l) {
        console_log(f->con, CONSOLE_DETAIL, "stale failure from %s (lease %llu) dropped",
                    w->name, (unsigned long long)x->lease_id);
        return;
    }
    tile_failed(f, w, x->lease_id, l->tile, x->message, x->retryable);
}

/* the frame whose job has this hash, or NULL */
static farm_frame *frame_of_job(farm *f, const char *hash)
{
    for (int i = 0; i < f->nframes; i++)
        if (strcmp(hash, f->frames[i].jb->hash) == 0) return &f->frames[i];
    return NULL;
}

static void on_need_job(farm *f, farm_worker *w, const proto_need_job *n, int64_t now)
{
    farm_frame *fr = frame_of_job(f, n->job_hash);
    if (fr) {
        send_job(f, w, fr, now);
        return;
    }
    console_log(f->con, CONSOLE_DETAIL, "%s asked for job %.12s..., not this master's",
                w->name, n->job_hash);
}

static void on_need_file(farm *f, farm_worker *w, const proto_need_file *n, int64_t now)
{
    farm_frame *fr = frame_of_job(f, n->job_hash);
    if (!fr) {
        console_log(f->con, CONSOLE_DETAIL, "%s asked for a file of job %.12s..., not this "
                    "master's", w->name, n->job_hash);
        return;
    }
    /* what was sent to it and it has not received yet is bounded */
    uint64_t received = n->received < w->file_bytes ? n->received : w->file_bytes;
    if (w->file_bytes - received + n->length > PROTO_MAX_FILE_INFLIGHT) {
        if (!w->file_overrun++)
            console_log(f->con, CONSOLE_INFO, "%s asks for more file bytes than it has received "
                        "plus %u MiB: dropped (a broken or hostile peer)", w->name,
                        PROTO_MAX_FILE_INFLIGHT >> 20);
        return;
    }
    const uint8_t *data = NULL;
    const job_file *file = NULL;
    char err[2 * ERR_LEN];   /* names the file and its path on the master's disk */
    file_read r = file_server_read(fr->files, n->sha256, n->offset, n->length, &data, &file, err,
                                   sizeof err);
    if (r == FILE_READ_UNKNOWN || r == FILE_READ_RANGE) {
        console_log(f->con, CONSOLE_INFO, "%s asked for %s (bytes %llu..+%u of %.12s...): "
                    "dropped", w->name, r == FILE_READ_UNKNOWN ? "a file the job does not have"
                    : "bytes outside the file", (unsigned long long)n->offset, n->length,
                    n->sha256);
        return;
    }
    if (r == FILE_READ_CHANGED || r == FILE_READ_NO_MEMORY) {
        farm_fail_tile(f, fr->first, "%s", err);
        return;
    }
    proto_msg msg = {.kind = PROTO_FILE_CHUNK,
                     .file_chunk = {file->sha256, n->offset, file->size, n->length}};
    if (send_msg_bulk(f, w, &msg, data, n->length, now) < 0) return;
    if (w->file_chunks == 0) w->file_first_ms = now;
    if (!w->files_ready)   /* progress: its leases' clocks start again */
        scheduler_worker_waiting(f->sched, w->slot, true, now);
    w->file_bytes += n->length;
    w->file_chunks++;
    f->file_bytes_sent += n->length;
    f->file_chunks_sent++;
}

static void on_files_ready(farm *f, farm_worker *w, const proto_files_ready *r, int64_t now)
{
    if (!frame_of_job(f, r->job_hash) || w->files_ready) return;
    w->files_ready = true;
    w->file_ready_ms = now;
    scheduler_worker_waiting(f->sched, w->slot, false, now);   /* rendering from now */
    w->file_hits += r->hits;
    w->file_misses += r->misses;
    console_log(f->con, CONSOLE_DETAIL, "%s has the job's files (%u in its host's store, %u "
                "fetched; %llu bytes received)", w->name, r->hits, r->misses,
                (unsigned long long)r->fetched_bytes);
}

static void on_unknown_peer(farm *f, proto_kind kind, const uint8_t *id, size_t id_len,
                            int64_t now)
{
    if (kind == PROTO_SHUTDOWN) return;
    if (!registry_reject_due(f->reg, id, id_len, now, f->opt->heartbeat_ms)) return;
    char hex[24];
    console_log(f->con, CONSOLE_DETAIL, "%s from unknown peer %s: asking it to say Hello",
                proto_message_name(kind), registry_id_hex(id, id_len, hex, sizeof hex));
    send_reject(f, id, id_len, PROTO_REJECT_HELLO_FIRST,
                "the master does not know this connection (it restarted, or the "
                "connection was renewed): say Hello again");
}

void farm_handle(farm *f, wire_msg *m, int64_t now)
{
    size_t id_len = 0;
    const uint8_t *id = wire_msg_identity(m, &id_len);
    const proto_msg *msg = wire_msg_body(m);
    proto_kind kind = msg->kind;
    if (kind == PROTO_HELLO) {
        on_hello(f, &msg->hello, id, id_len, now);
        return;
    }
    farm_worker *w = registry_find(f->reg, id, id_len);
    if (!w) {
        on_unknown_peer(f, kind, id, id_len, now);
        return;
    }
    w->last_seen_ms = now;
    switch (kind) {
    case PROTO_ASK: on_ask(f, w, &msg->ask); break;
    case PROTO_RESULT: on_result(f, w, &msg->result, m, now); break;
    case PROTO_FAILURE: on_failure(f, w, &msg->failure); break;
    case PROTO_NEED_JOB: on_need_job(f, w, &msg->need_job, now); break;
    case PROTO_NEED_FILE: on_need_file(f, w, &msg->need_file, now); break;
    case PROTO_FILES_READY: on_files_ready(f, w, &msg->files_ready, now); break;
    case PROTO_SHUTDOWN: {
        char why[ERR_LEN];
        snprintf(why, sizeof why, "left (%s)",
                 msg->shutdown.reason && *msg->shutdown.reason ? msg->shutdown.reason
                                                               : "no reason given");
        farm_lose_worker(f, w, why, now);
        break;
    }
    default: break;   /* Heartbeat: liveness only */
    }
}

/* ---- granting ---- */

/* One tile to one worker: the Job first if it does not hold it. */
static bool grant_one(farm *f, farm_worker *w, int64_t now)
{
    scheduler_lease l;
    if (!scheduler_grant(f->sched, w->slot, now, &l)) return false;
    int local;
    farm_frame *fr = farm_frame_of(f, l.tile, &local);
    if (!holds_frame(f, w, (int)(fr - f->frames)) && send_job(f, w, fr, now) != 0) return false;
    if (send_grant(f, w, &l, now) != 0) return false;
    w->credits--;
    return true;
}

void farm_grant_all(farm *f, int64_t now)
{
    if (!f->gate_open) return;   /* --min-workers: not yet */
    bool granted = true;
    while (granted && f->state == FARM_RUNNING) {
        granted = false;
        for (size_t i = 0; i < registry_count(f->reg); i++) {
            farm_worker *w = registry_at(f->reg, i);
            if (w->alive && w->credits > 0 && grant_one(f, w, now)) granted = true;
        }
    }
}
