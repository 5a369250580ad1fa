/*
 * farm_monitor.c: what one farm render shows on the live monitor (--http;
 * docs/farm.md "Watching a render"): the loop's side of monitor.h.
 *
 * Everything here runs on the master's loop thread. The image: every tile
 * taken (or replayed from the journal by --resume) is decoded once more
 * (image_tile_decode_rgba: about 0.05 ms for 32x32) and put into the
 * monitor. The documents: at most every FARM_MONITOR_MS, and at the end,
 * the status and the worker list are written as JSON (open_memstream)
 * from the scheduler, the registry and the console, and published whole;
 * the HTTP thread only ever serves copies of them.
 *
 *   /api/status   {"job": {...}, "tiles": {...}, "rate_tiles_per_s",
 *                  "eta_s", "frames": [{..., "tile_state": "ddlq...",
 *                  "tile_worker": [slot, ...]}], "warnings": [{"text",
 *                  "count"}], "log": [...]}
 *   /api/workers  {"workers": [{"slot", "name", "host", "threads", "tiles",
 *                  "rate_tiles_per_s", "cpu_seconds", "state", "last_error",
 *                  ...}]}
 *
 * tile_state has one letter a tile, row-major: d done, l leased (a worker
 * renders it), q queued; tile_worker the slot of the worker that rendered
 * it or holds its newest lease (-1: none; slots name the workers of
 * /api/workers).
 */
#include <assert.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "farm_internal.h"
#include "http_server.h"
#include "image/tile.h"
#include "json_out.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/xalloc.h"

enum { FARM_MONITOR_MS = 250 };

void farm_monitor_open(farm *f, int from)
{
    if (!f->opt->http) return;
    if (!f->mon) f->mon = monitor_new();   /* a serving master's: one for all its jobs */
    for (int i = from; i < f->nframes; i++) {
        int index = monitor_add_frame(f->mon, f->frames[i].fmt.width, f->frames[i].fmt.height);
        if (i == 0) f->mon_base = index;
        assert(index == f->mon_base + i);   /* the frames' monitor indices follow each other */
    }
    int kept = from > 0 && from < f->nframes ? f->frames[from].first : 0;
    if (from == 0) {   /* a new render (a serving master's next job on its own) */
        free(f->tile_slot);
        f->tile_slot = NULL;
    }
    f->tile_slot = xreallocarray(f->tile_slot, (size_t)f->ntiles + 1, sizeof *f->tile_slot);
    for (int i = kept; i < f->ntiles; i++) f->tile_slot[i] = -1;
}

int farm_monitor_serve(farm *f, const http_jobs *jobs, char *err, size_t errsz)
{
    if (!f->mon) return AAFARM_EXIT_OK;
    http_addr addr;
    if (!http_addr_parse(f->opt->http, &addr, err, errsz)) return AAFARM_EXIT_USAGE;
    f->http = http_server_start(&addr, f->opt->http_token, f->mon, jobs, err, errsz);
    if (!f->http) return AAFARM_EXIT_FAILURE;
    farm_monitor_publish(f, farm_now_ms(), true);
    console_log(f->con, CONSOLE_INFO, "monitor on http://%s:%d/%s", addr.host,
                http_server_port(f->http), f->opt->http_token ? " (token required)" : "");
    return AAFARM_EXIT_OK;
}

void farm_monitor_tile(farm *f, farm_frame *fr, int local, const void *chunk, size_t len,
                       const farm_worker *w)
{
    if (!f->mon) return;
    f->tile_slot[fr->first + local] = w ? w->slot : -1;
    image_rect r = image_format_tile_rect(&fr->fmt, local % fr->tiles_x, local / fr->tiles_x);
    float *rgba = xmalloc((size_t)r.w * (size_t)r.h * 4 * sizeof *rgba);
    char err[ERR_LEN];
    int index = f->mon_base + (int)(fr - f->frames);
    if (image_tile_decode_rgba(&fr->fmt, r, chunk, len, rgba, err, sizeof err))
        monitor_put_tile(f->mon, index, r, rgba);
    else   /* the chunk was validated: not expected */
        console_log(f->con, CONSOLE_ERROR, "monitor: tile %d not shown: %s", local, err);
    free(rgba);
}

void farm_monitor_frame_complete(farm *f, const farm_frame *fr)
{
    if (f->mon) monitor_frame_complete(f->mon, f->mon_base + (int)(fr - f->frames));
}

/* ---- the documents ---- */

static const char *state_name(const farm *f)
{
    if (f->serving && f->nframes == 0) return "idle";   /* a serving master between jobs */
    switch (f->state) {
    case FARM_CANCELLED: return "cancelled";
    case FARM_DONE: return "done";
    case FARM_FAILED: return "failed";
    case FARM_INTERRUPTED: return "interrupted";
    case FARM_REQUEUED: return "requeued";
    case FARM_NO_WORKERS: return "no workers";
    default: return "running";
    }
}

/* Tiles leased now: 'l' and the newest lease's worker slot. */
typedef struct lease_marks {
    char *state;
    int *slot;
} lease_marks;

static void mark_lease(void *arg, const scheduler_lease *l)
{
    lease_marks *m = arg;
    if (m->state[l->tile] != 'd') {
        m->state[l->tile] = 'l';
        m->slot[l->tile] = l->worker;
    }
}

static void json_frames(FILE *out, const farm *f)
{
    char *state = xmalloc((size_t)f->ntiles + 1);
    int *slot = xmalloc(((size_t)f->ntiles + 1) * sizeof *slot);
    for (int t = 0; t < f->ntiles; t++) {
        bool done = scheduler_tile_done(f->sched, t);
        state[t] = done ? 'd' : 'q';
        slot[t] = done ? f->tile_slot[t] : -1;
    }
    lease_marks m = {state, slot};
    scheduler_each_lease(f->sched, mark_lease, &m);
    fputs("\"frames\": [", out);
    for (int i = 0; i < f->nframes; i++) {
        const farm_frame *fr = &f->frames[i];
        fprintf(out, "%s\n  {\"index\": %d, \"number\": %d, \"output\": ", i ? "," : "",
                f->mon_base + i, fr->jb->frame_number);
        json_out_string(out, fr->output);
        fprintf(out, ", \"width\": %d, \"height\": %d, \"tile_size\": %d, \"tiles_x\": %d, "
                "\"tiles_y\": %d, \"tiles\": %d, \"done\": %d, \"written\": %s, "
                "\"tile_state\": \"%.*s\", \"tile_worker\": [", fr->fmt.width, fr->fmt.height,
                fr->fmt.tile_size, fr->tiles_x, image_format_tiles_y(&fr->fmt), fr->ntiles,
                fr->done, fr->written ? "true" : "false", fr->ntiles, state + fr->first);
        for (int t = 0; t < fr->ntiles; t++) fprintf(out, "%s%d", t ? "," : "", slot[fr->first + t]);
        fputs("]}", out);
    }
    fputs("]", out);
    free(state);
    free(slot);
}

static void warning(FILE *out, bool *first, uint64_t count, const char *text)
{
    if (!count) return;
    fprintf(out, "%s\n  {\"count\": %llu, \"text\": ", *first ? "" : ",",
            (unsigned long long)count);
    json_out_string(out, text);
    fputc('}', out);
    *first = false;
}

/* Repeated warnings, one entry a kind with its count over the render. */
static void json_warnings(FILE *out, const farm *f)
{
    scheduler_counts c;
    scheduler_counts_get(f->sched, &c);
    bool first = true;
    char text[300];
    fputs("\"warnings\": [", out);
    warning(out, &first, c.expired, "leases passed their deadline (the tile went back to the "
            "queue)");
    warning(out, &first, c.failures, "tile failures (see the log and the workers' last error)");
    warning(out, &first, f->invalid_tiles, "results refused as invalid tiles");
    snprintf(text, sizeof text, "NaN/Inf samples written as 0 (in %d tiles): a shader divides "
             "by zero or overflows", f->nonfinite_tiles);
    warning(out, &first, f->nonfinite_samples, text);
    warning(out, &first, c.duplicate_results, "duplicate results dropped (end-game duplicates)");
    warning(out, &first, f->wstats.dropped, "malformed messages dropped");
    warning(out, &first, f->wstats.handshake_failures, "connections failed the handshake");
    warning(out, &first, zap_refused(f->zap), "workers refused by the key check (CURVE)");
    warning(out, &first, f->rejects_sent, "rejects sent to workers");
    fputs("]", out);
}

static char *build_status(const farm *f, int64_t now, size_t *len)
{
    char *text = NULL;
    FILE *out = open_memstream(&text, len);
    if (!out) return NULL;
    int64_t end = f->end_ms ? f->end_ms : now;
    double secs = (double)(end - f->start_ms) / 1000.0;
    int done = scheduler_tiles_done(f->sched);
    double rate = secs > 0 ? (done - f->resumed_tiles) / secs : 0;
    scheduler_counts c;
    scheduler_counts_get(f->sched, &c);
    fputs("{\"job\": {\"scene\": ", out);
    json_out_string(out, f->opt->scene_path ? f->opt->scene_path : "");
    fprintf(out, ", \"state\": \"%s\", \"error\": ", state_name(f));
    json_out_string(out, f->state == FARM_FAILED || f->state == FARM_NO_WORKERS ? f->failure : "");
    fprintf(out, ", \"job_hash\": \"%.64s\", \"frames\": %d, \"frames_written\": %d, "
            "\"elapsed_s\": %.3f, \"host\": ", f->nframes ? f->frames[0].jb->hash : "", f->nframes,
            f->frames_written, secs);
    json_out_string(out, f->host);
    fprintf(out, "},\n\"tiles\": {\"total\": %d, \"done\": %d, \"leased\": %d, \"queued\": %d, "
            "\"resumed\": %d},\n\"rate_tiles_per_s\": %.3f, \"eta_s\": ", f->ntiles, done,
            c.leased, c.queued, f->resumed_tiles, rate);
    if (done == f->ntiles) fputs("0", out);
    else if (rate > 0 && f->state == FARM_RUNNING) fprintf(out, "%.1f", (f->ntiles - done) / rate);
    else fputs("null", out);
    fprintf(out, ", \"workers_alive\": %d,\n", registry_alive(f->reg));
    json_frames(out, f);
    fputs(",\n", out);
    json_warnings(out, f);
    fputs(",\n\"log\": [", out);
    for (int i = 0; i < console_tail_count(f->con); i++) {
        fputs(i ? ",\n  " : "\n  ", out);
        json_out_string(out, console_tail_line(f->con, i));
    }
    fputs("]}\n", out);
    if (fclose(out) != 0) {
        free(text);
        return NULL;
    }
    return text;
}

static const char *worker_state(const farm_worker *w)
{
    return !w->alive       ? w->gone
           : w->blocked    ? "blocklisted"
           : w->benched    ? "benched"
           : w->other_pool ? "not in the job's pool"
                           : "connected";
}

static char *build_workers(const farm *f, int64_t now, size_t *len)
{
    char *text = NULL;
    FILE *out = open_memstream(&text, len);
    if (!out) return NULL;
    fputs("{\"workers\": [", out);
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        int64_t until = w->alive ? (f->end_ms ? f->end_ms : now) : w->left_ms;
        double secs = (double)(until - w->joined_ms) / 1000.0;
        fprintf(out, "%s\n  {\"slot\": %d, \"name\": ", i ? "," : "", w->slot);
        json_out_string(out, w->name);
        fputs(", \"host\": ", out);
        json_out_string(out, w->host);
        fputs(", \"pool\": ", out);
        json_out_string(out, w->pool);
        fprintf(out, ", \"benched\": %s, \"strikes\": %d", w->benched ? "true" : "false",
                w->strikes);
        fprintf(out, ", \"pid\": %u, \"threads\": %u, \"local\": %s, \"alive\": %s, "
                "\"tiles\": %llu, \"leases\": %d, \"rate_tiles_per_s\": %.3f, "
                "\"render_seconds\": %.3f, \"cpu_seconds\": %.3f, \"failures\": %llu, "
                "\"duplicates\": %llu, \"invalid_tiles\": %llu, \"bytes_in\": %llu, "
                "\"seconds\": %.1f, \"state\": ", w->pid, w->threads,
                w->local ? "true" : "false", w->alive ? "true" : "false",
                (unsigned long long)w->tiles, w->alive ? scheduler_worker_leases(f->sched, w->slot) : 0,
                secs > 0 ? (double)w->tiles / secs : 0.0, w->render_seconds, w->cpu_seconds,
                (unsigned long long)w->failures, (unsigned long long)w->duplicates,
                (unsigned long long)w->invalid_tiles, (unsigned long long)w->bytes_in,
                secs > 0 ? secs : 0.0);
        json_out_string(out, worker_state(w));
        fputs(", \"last_error\": ", out);
        json_out_string(out, w->last_error);
        fputc('}', out);
    }
    fputs("]}\n", out);
    if (fclose(out) != 0) {
        free(text);
        return NULL;
    }
    return text;
}

void farm_monitor_publish(farm *f, int64_t now, bool force)
{
    if (!f->mon || !f->sched || (!force && now - f->published_ms < FARM_MONITOR_MS)) return;
    f->published_ms = now;
    size_t len = 0;
    char *text = build_status(f, now, &len);
    if (text) monitor_publish(f->mon, MONITOR_STATUS, text, len);
    text = build_workers(f, now, &len);
    if (text) monitor_publish(f->mon, MONITOR_WORKERS, text, len);
}

void farm_monitor_linger(farm *f, const atomic_int *interrupted)
{
    if (!f->http || f->opt->http_linger_ms <= 0) return;
    farm_monitor_publish(f, farm_now_ms(), true);
    console_log(f->con, CONSOLE_INFO, "monitor stays up for %.0f s (--http-linger; Ctrl-C ends "
                "it)", (double)f->opt->http_linger_ms / 1000.0);
    int64_t until = farm_now_ms() + f->opt->http_linger_ms;
    while (!atomic_load(interrupted) && farm_now_ms() < until) {
        struct timespec ts = {0, 50 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
}

void farm_monitor_close(farm *f)
{
    http_server_stop(&f->http);   /* its thread ends before the monitor goes */
    monitor_destroy(&f->mon);
    free(f->tile_slot);
    f->tile_slot = NULL;
}
