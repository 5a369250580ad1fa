/*
 * serve.c: aafarm-master --serve (docs/farm.md "A job queue"): a master
 * that keeps its workers and renders the jobs of a queue held in SQLite
 * (queue.h), one after another, until SIGINT/SIGTERM.
 *
 * The loop is farm.c's, one job at a time (farm_serve_*): between jobs an
 * idle "job" without tiles keeps the workers (heartbeats, Hellos, their
 * credits) while the queue is looked at every SERVE_CHECK_MS. A job is
 * rebuilt from its submission (bundle.h: the Jobs as the submitter's
 * job_load made them, its files written into DB.files/ by hash), renders
 * with the journal of the one-shot master (always as with --resume), and
 * ends done, failed or cancelled in the database. A master killed mid-job
 * leaves it 'running' there with its journal: the next master on the same
 * database takes it first and renders only the tiles the journal lacks.
 *
 * The HTTP thread (http_server.c) submits, lists and cancels through its
 * own connection to the database; the loop sees a cancellation at its
 * next look and ends the job (its partial output and journal removed).
 */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bundle.h"
#include "farm_internal.h"
#include "http_server.h"
#include "json_out.h"
#include "queue.h"
#include "serve.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/xalloc.h"

enum { SERVE_CHECK_MS = 300 };
#define SERVE_MAX_BODY ((size_t)256 << 20)

typedef struct serve {
    farm_options opt;              /* the master's, scene_path the job's */
    queue *q;                      /* the loop's connection */
    queue *hq;                     /* the HTTP thread's */
    char files_dir[PATH_MAX];      /* DB.files: the jobs' files by SHA-256 */
    long job;                      /* running now, -1: idle */
    int64_t checked_ms;
} serve;

/* ---- the HTTP thread ---- */

static char *json_error(const char *message, size_t *len)
{
    char *text = NULL;
    FILE *out = open_memstream(&text, len);
    if (!out) return NULL;
    fputs("{\"error\": ", out);
    json_out_string(out, message);
    fputs("}\n", out);
    fclose(out);
    return text;
}

static unsigned on_submit(void *arg, const void *body, size_t len, char **answer, size_t *alen)
{
    serve *s = arg;
    job_bundle b;
    char err[2 * ERR_LEN];
    if (!job_bundle_decode(&b, body, len, err, sizeof err)) {
        err_prefix(err, sizeof err, "refused the submission");
        *answer = json_error(err, alen);
        return 400;
    }
    bool ok = true;
    size_t olen = 0;
    char *outputs = NULL;
    FILE *out = open_memstream(&outputs, &olen);
    for (int i = 0; i < b.nframes && ok; i++) {
        image_format fmt;
        job *jb = job_bundle_job(&b, i, &fmt, err, sizeof err);
        ok = jb && image_format_check(&fmt, err, sizeof err);
        job_destroy(&jb);
        if (out) fprintf(out, "%s%s", i ? "\n" : "", b.outputs[i]);
    }
    if (out) fclose(out);
    unsigned status = 400;
    if (!ok) {
        err_prefix(err, sizeof err, "refused the submission");
        *answer = json_error(err, alen);
    } else {
        long id = queue_submit(s->hq, b.priority, b.pool, b.scene, outputs ? outputs : "",
                               b.nframes, body, len, err, sizeof err);
        if (id < 0) {
            *answer = json_error(err, alen);
            status = 500;
        } else {
            char text[64];
            *alen = (size_t)snprintf(text, sizeof text, "{\"id\": %ld}\n", id);
            *answer = xstrdup(text);
            status = 201;
        }
    }
    free(outputs);
    job_bundle_clear(&b);
    return status;
}

static unsigned on_list(void *arg, long id, char **answer, size_t *alen)
{
    serve *s = arg;
    bool missing = false;
    char err[ERR_LEN];
    *answer = queue_json(s->hq, id, alen, &missing, err, sizeof err);
    if (*answer) return 200;
    *answer = json_error(err, alen);
    return missing ? 404 : 500;
}

static unsigned on_cancel(void *arg, long id, char **answer, size_t *alen)
{
    serve *s = arg;
    char err[ERR_LEN], text[160];
    switch (queue_cancel(s->hq, id, err, sizeof err)) {
    case QUEUE_CANCELLED:
        *alen = (size_t)snprintf(text, sizeof text, "{\"id\": %ld, \"state\": \"cancelled\"}\n", id);
        *answer = xstrdup(text);
        return 200;
    case QUEUE_CANCEL_ASKED:
        *alen = (size_t)snprintf(text, sizeof text, "{\"id\": %ld, \"state\": \"running\", "
                                 "\"cancel_asked\": true}\n", id);
        *answer = xstrdup(text);
        return 202;
    case QUEUE_NO_SUCH_JOB: *answer = json_error(err, alen); return 404;
    case QUEUE_ALREADY_ENDED: *answer = json_error(err, alen); return 409;
    default: *answer = json_error(err, alen); return 500;
    }
}

/* ---- the loop ---- */

/* Can a job start? Not while every local worker has exited and none can
 * join from elsewhere (they are started again: farm.c). */
static bool can_render(const farm *f)
{
    return f->opt->bind || !f->locals || local_workers_running(f->locals) > 0 ||
           registry_alive(f->reg) > 0;
}

/* Once a loop turn: idle, is there a job? Running, was it cancelled? */
static void tick(farm *f, int64_t now)
{
    serve *s = f->serve;
    if (now - s->checked_ms < SERVE_CHECK_MS) return;
    s->checked_ms = now;
    if (s->job < 0) {
        bool resume;
        if (can_render(f) && queue_next(s->q, &resume, NULL, 0) >= 0)
            f->state = FARM_DONE;   /* idle ends */
        return;
    }
    if (queue_cancel_asked(s->q, s->job)) {
        console_log(f->con, CONSOLE_INFO, "job %ld cancelled", s->job);
        f->state = FARM_CANCELLED;
        return;
    }
    queue_progress(s->q, s->job, scheduler_tiles_done(f->sched), NULL, 0);
}

/* The job's files in DB.files/SHA (written once, renamed into place). */
static bool store_files(serve *s, const job_bundle *b, char *err, size_t errsz)
{
    for (int i = 0; i < b->nfiles; i++) {
        char path[PATH_MAX + 80], tmp[PATH_MAX + 100];
        snprintf(path, sizeof path, "%s/%s", s->files_dir, b->files[i].sha256);
        struct stat st;
        if (stat(path, &st) == 0 && (uint64_t)st.st_size == b->files[i].size) continue;
        snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
        FILE *out = fopen(tmp, "wb");
        bool ok = out && fwrite(b->files[i].data, 1, (size_t)b->files[i].size, out) ==
                             b->files[i].size;
        if (out && fclose(out) != 0) ok = false;
        if (!ok || rename(tmp, path) != 0) {
            err_set(err, errsz, "cannot write the job's file %s: %s", path, strerror(errno));
            unlink(tmp);
            return false;
        }
    }
    return true;
}

/* A job loaded from its submission. */
typedef struct loaded_job {
    uint8_t *bytes;
    size_t len;
    job_bundle b;
    job **jobs;
    farm_frame_in *frames;
} loaded_job;

static void loaded_job_clear(loaded_job *l)
{
    for (int i = 0; l->jobs && i < l->b.nframes; i++) job_destroy(&l->jobs[i]);
    free(l->jobs);
    free(l->frames);
    job_bundle_clear(&l->b);
    free(l->bytes);
    memset(l, 0, sizeof *l);
}

static bool load_job(serve *s, long id, loaded_job *l, char *err, size_t errsz)
{
    memset(l, 0, sizeof *l);
    if (!queue_bundle(s->q, id, &l->bytes, &l->len, err, errsz)) return false;
    if (!job_bundle_decode(&l->b, l->bytes, l->len, err, errsz)) return false;
    if (!store_files(s, &l->b, err, errsz)) return false;
    int n = l->b.nframes;
    l->jobs = xcalloc((size_t)n, sizeof *l->jobs);
    l->frames = xcalloc((size_t)n, sizeof *l->frames);
    for (int i = 0; i < n; i++) {
        job *jb = job_bundle_job(&l->b, i, &l->frames[i].fmt, err, errsz);
        if (!jb) return false;
        l->jobs[i] = jb;
        for (int k = 0; k < jb->nfiles; k++) {
            char path[PATH_MAX + 80];
            snprintf(path, sizeof path, "%s/%s", s->files_dir, jb->files[k].sha256);
            job_file_set_path(jb, k, path);
        }
        if (!image_format_check(&l->frames[i].fmt, err, errsz)) return false;
        l->frames[i].jb = jb;
        l->frames[i].output = l->b.outputs[i];
    }
    return true;
}

/* Live workers of the job's pool. */
static int pool_workers(const farm *f)
{
    int n = 0;
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        n += w->alive && !w->other_pool;
    }
    return n;
}

/* Runs job id to its end (or the master's); its state into the database. */
static void run_job(serve *s, farm *f, long id, bool resume)
{
    loaded_job l;
    char err[2 * ERR_LEN];
    bool ok = load_job(s, id, &l, err, sizeof err);
    s->opt.scene_path = ok ? l.b.scene : "?";
    s->job = id;
    f->pool = ok && l.b.pool[0] ? l.b.pool : NULL;
    int rc = farm_serve_job(f, ok ? l.frames : NULL, ok ? l.b.nframes : 0, err, sizeof err);
    if (!ok || rc != AAFARM_EXIT_OK) {
        f->state = FARM_FAILED;
        snprintf(f->failure, sizeof f->failure, "%s", err);
    } else if (!queue_start(s->q, id, f->ntiles, err, sizeof err)) {
        f->state = FARM_CANCELLED;   /* cancelled between the look and now */
    } else {
        console_log(f->con, CONSOLE_INFO, "job %ld: %s, %d frame%s, %d tiles (priority %d%s%s%s%s)",
                    id, l.b.scene, l.b.nframes, l.b.nframes == 1 ? "" : "s", f->ntiles,
                    l.b.priority, f->pool ? ", pool " : "", f->pool ? f->pool : "",
                    resume ? "; resumed" : "", f->resumed_tiles ? ", tiles from its journal" : "");
        if (f->pool && !pool_workers(f))
            console_log(f->con, CONSOLE_INFO, "job %ld waits for a worker of pool %s (aafarm-worker "
                        "--connect ... --pool %s)", id, f->pool, f->pool);
        farm_serve_loop(f);
    }
    switch (f->state) {
    case FARM_DONE:
        queue_progress(s->q, id, f->ntiles, NULL, 0);
        queue_end(s->q, id, "done", AAFARM_EXIT_OK, NULL, NULL, 0);
        console_log(f->con, CONSOLE_INFO, "job %ld done: %s%s (%.2f s)", id,
                    f->nframes ? f->frames[0].output : "", f->nframes > 1 ? " ..." : "",
                    (double)(farm_now_ms() - f->start_ms) / 1000.0);
        break;
    case FARM_CANCELLED:
        queue_end(s->q, id, "cancelled", AAFARM_EXIT_INTERRUPTED, "cancelled while running",
                  NULL, 0);
        break;
    case FARM_REQUEUED:   /* back in the queue: it resumes from its journal */
        queue_progress(s->q, id, scheduler_tiles_done(f->sched), NULL, 0);
        queue_requeue(s->q, id, NULL, 0);
        console_log(f->con, CONSOLE_INFO, "job %ld requeued: every local worker exited (%d of %d "
                    "tiles in its journal); it resumes when they are back", id,
                    scheduler_tiles_done(f->sched), f->ntiles);
        break;
    case FARM_INTERRUPTED:   /* stays 'running': the next master resumes it */
        queue_progress(s->q, id, scheduler_tiles_done(f->sched), NULL, 0);
        console_log(f->con, CONSOLE_INFO, "job %ld interrupted: a master started on the same "
                    "database resumes it", id);
        break;
    default:
        queue_end(s->q, id, "failed", AAFARM_EXIT_FAILURE, f->failure, NULL, 0);
        console_log(f->con, CONSOLE_ERROR, "job %ld failed: %s", id, f->failure);
        break;
    }
    farm_serve_end_job(f);
    f->pool = NULL;
    s->job = -1;
    s->opt.scene_path = NULL;   /* it points into the job freed now */
    loaded_job_clear(&l);
}

int farm_serve(const farm_options *opt, const char *db_path)
{
    serve s;
    memset(&s, 0, sizeof s);
    s.opt = *opt;
    s.opt.resume = true;     /* every job continues from its journal */
    s.opt.preview = NULL;
    s.opt.stats_json = NULL;
    s.job = -1;
    char err[2 * ERR_LEN];
    s.q = queue_open(db_path, err, sizeof err);
    s.hq = s.q ? queue_open(db_path, err, sizeof err) : NULL;
    if (!s.hq) {
        fprintf(stderr, "aafarm-master: %s\n", err);
        queue_destroy(&s.q);
        return AAFARM_EXIT_FAILURE;
    }
    snprintf(s.files_dir, sizeof s.files_dir, "%s.files", db_path);
    if (mkdir(s.files_dir, 0700) != 0 && errno != EEXIST) {
        fprintf(stderr, "aafarm-master: cannot create %s for the jobs' files: %s\n", s.files_dir,
                strerror(errno));
        queue_destroy(&s.q);
        queue_destroy(&s.hq);
        return AAFARM_EXIT_FAILURE;
    }

    farm f;
    memset(&f, 0, sizeof f);
    f.opt = &s.opt;
    f.serve = &s;
    f.tick = tick;
    f.con = console_new(opt->verbosity, isatty(STDERR_FILENO));
    char detail[200];
    snprintf(detail, sizeof detail, "without a result (%d x the measured time per tile, at most "
             "%.0f s): back in the queue", opt->lease_factor, (double)opt->lease_ms / 1000.0);
    console_tally_init(&f.expired, "lease passed its deadline", "leases passed their deadlines",
                       detail, FARM_WARN_INTERVAL_MS);
    const atomic_int *interrupted = farm_catch_signals();

    int rc = farm_serve_open(&f, err, sizeof err);
    if (rc == AAFARM_EXIT_OK && opt->http) {
        f.mon = monitor_new();
        http_jobs jobs = {&s, SERVE_MAX_BODY, on_submit, on_list, on_cancel};
        rc = farm_monitor_serve(&f, &jobs, err, sizeof err);
    }
    if (rc != AAFARM_EXIT_OK) {
        console_log(f.con, CONSOLE_ERROR, "%s", err);
    } else {
        console_log(f.con, CONSOLE_INFO, "serving the job queue in %s%s", db_path,
                    opt->http ? "" : " (no --http: nothing can submit)");
        while (!atomic_load(interrupted)) {
            bool resume = false;
            long id = can_render(&f) ? queue_next(s.q, &resume, err, sizeof err) : -1;
            if (id >= 0) {
                run_job(&s, &f, id, resume);
            } else {   /* idle until a job comes */
                farm_serve_job(&f, NULL, 0, err, sizeof err);
                farm_serve_loop(&f);
                farm_serve_end_job(&f);
            }
            if (f.state == FARM_INTERRUPTED || atomic_load(interrupted)) {
                rc = AAFARM_EXIT_INTERRUPTED;
                break;
            }
        }
        if (atomic_load(interrupted)) rc = AAFARM_EXIT_INTERRUPTED;
    }
    farm_serve_close(&f);   /* the HTTP thread ends first */
    queue_destroy(&s.q);
    queue_destroy(&s.hq);
    return rc;
}
