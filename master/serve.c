/*
 * serve.c: aafarm-master --serve (docs/farm.md "A job queue"): a master
 * that keeps its workers and renders the jobs of a queue held in SQLite
 * (queue.h), one after another, until SIGINT/SIGTERM.
 *
 * The loop is farm.c's (farm_serve_*): between jobs an idle "job" without
 * tiles keeps the workers (heartbeats, Hellos, their credits) while the
 * queue is looked at every SERVE_CHECK_MS. A job is rebuilt from its
 * submission (bundle.h: the Jobs as the submitter's job_load made them,
 * its files written into DB.files/ by hash), renders with the journal of
 * the one-shot master (always as with --resume), and ends done, failed or
 * cancelled in the database. A master killed mid-job leaves it 'running'
 * there with its journal: the next master on the same database takes it
 * first and renders only the tiles the journal lacks.
 *
 * Overlap: once no tile of the running job is left to hand out (every one
 * is done or leased) and a worker asks for more, the next job joins the
 * same run (farm_serve_append): its frames come after the running job's
 * in the one tile queue, as the frames of a sequence do, so idle workers
 * take its tiles while the last ones of the job before are rendered. Each
 * job of the run is said done in the database as soon as its frames are
 * written. A run holds at most SERVE_RUN_JOBS jobs and SERVE_RUN_TILES
 * tiles, all of one pool, and no worker benched or blocklisted (that is
 * per run); a job that does not fit waits for the
 * end of the run. When one job of the run fails or is cancelled, the run
 * ends: the others go back to the queue with their journals and resume
 * from them (the tiles they had out are rendered again).
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

enum { SERVE_CHECK_MS = 300, SERVE_OVERLAP_MS = 50, SERVE_RUN_JOBS = 8 };
#define SERVE_RUN_TILES (1 << 20)
#define SERVE_MAX_BODY ((size_t)256 << 20)

/* A job loaded from its submission. */
typedef struct loaded_job {
    uint8_t *bytes;
    size_t len;
    job_bundle b;
    job **jobs;
    farm_frame_in *frames;
} loaded_job;

/* A job of the run: its frames and tiles in the farm's. */
typedef struct active_job {
    long id;
    loaded_job l;
    int first_frame, nframes;
    int first_tile, ntiles;
    bool resume;
    bool ended;                    /* done, said in the database, journals removed */
    bool overlap_said;             /* its grant beside the job before it was said */
    int64_t start_ms;
} active_job;

typedef struct serve {
    farm_options opt;              /* the master's, scene_path the newest job's */
    queue *q;                      /* the loop's connection */
    queue *hq;                     /* the HTTP thread's */
    char files_dir[PATH_MAX];      /* DB.files: the jobs' files by SHA-256 */
    active_job act[SERVE_RUN_JOBS];   /* the run's jobs, in the order they joined */
    int nact;                      /* 0: idle */
    long cancelled;                /* the job whose cancellation ended the run, or -1 */
    bool no_overlap;               /* the next job waits for the end of the run */
    int64_t checked_ms, overlap_checked_ms;
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

/* ---- a run: one job, and those that join it ---- */

static int job_tiles_done(const farm *f, const active_job *a)
{
    int n = 0;
    for (int i = 0; i < a->nframes && a->first_frame + i < f->nframes; i++)
        n += f->frames[a->first_frame + i].done;
    return n;
}

static bool job_written(const farm *f, const active_job *a)
{
    for (int i = 0; i < a->nframes; i++)
        if (a->first_frame + i >= f->nframes || !f->frames[a->first_frame + i].written)
            return false;
    return a->nframes > 0;
}

static const char *job_output(const farm *f, const active_job *a)
{
    return a->first_frame < f->nframes ? f->frames[a->first_frame].output : "";
}

static void say_started(serve *s, farm *f, const active_job *a, const char *more)
{
    const job_bundle *b = &a->l.b;
    console_log(f->con, CONSOLE_INFO, "job %ld: %s, %d frame%s, %d tiles (priority %d%s%s%s%s)%s",
                a->id, b->scene, b->nframes, b->nframes == 1 ? "" : "s", a->ntiles, b->priority,
                f->pool ? ", pool " : "", f->pool ? f->pool : "", a->resume ? "; resumed" : "",
                job_tiles_done(f, a) ? ", tiles from its journal" : "", more);
    (void)s;
}

/* Every frame of the job is written: done in the database, its journals
 * removed (the run may go on with the jobs after it). */
static void record_done(serve *s, farm *f, active_job *a, int64_t now)
{
    queue_progress(s->q, a->id, a->ntiles, NULL, 0);
    queue_end(s->q, a->id, "done", AAFARM_EXIT_OK, NULL, NULL, 0);
    for (int i = 0; i < a->nframes; i++) {
        farm_frame *fr = &f->frames[a->first_frame + i];
        journal_remove(&fr->jnl);
        fr->end = FARM_DONE;
    }
    console_log(f->con, CONSOLE_INFO, "job %ld done: %s%s (%.2f s)", a->id, job_output(f, a),
                a->nframes > 1 ? " ..." : "", (double)(now - a->start_ms) / 1000.0);
    a->ended = true;
}

/* Live leases of the run's tiles first .. first + n - 1 whose tile is not in. */
typedef struct lease_tally {
    const farm *f;
    int first, n, count;
} lease_tally;

static void tally_lease(void *arg, const scheduler_lease *l)
{
    lease_tally *t = arg;
    if (l->tile >= t->first && l->tile < t->first + t->n && !l->expired &&
        !scheduler_tile_done(t->f->sched, l->tile))
        t->count++;
}

static int leases_out(const farm *f, int first, int n)
{
    lease_tally t = {f, first, n, 0};
    scheduler_each_lease(f->sched, tally_lease, &t);
    return t.count;
}

/* The newest job's first grants, said once with what the jobs before it
 * still have out: the overlap, as the log shows it. */
static void say_overlap(serve *s, farm *f)
{
    if (s->nact < 2) return;
    active_job *a = &s->act[s->nact - 1];
    if (a->overlap_said) return;
    int mine = leases_out(f, a->first_tile, a->ntiles);
    if (!mine) return;
    a->overlap_said = true;
    int before = leases_out(f, 0, a->first_tile);
    if (before)
        console_log(f->con, CONSOLE_INFO, "job %ld: %d tile%s leased while %d tile%s of job %ld "
                    "%s still out (overlap)", a->id, mine, mine == 1 ? "" : "s", before,
                    before == 1 ? "" : "s", s->act[s->nact - 2].id, before == 1 ? "is" : "are");
}

/* Should the next job join the run now? When a worker asks for tiles and
 * none of the run's is left to hand out. */
static void maybe_overlap(serve *s, farm *f, int64_t now)
{
    if (s->nact == 0 || s->no_overlap || s->nact >= SERVE_RUN_JOBS || f->state != FARM_RUNNING ||
        !f->gate_open || now - s->overlap_checked_ms < SERVE_OVERLAP_MS)
        return;
    bool asks = false;
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        if (!w->alive) continue;
        if (w->benched || w->blocked) return;   /* that holds for the whole run */
        if (w->credits > 0 && !w->other_pool) asks = true;
    }
    if (!asks) return;
    s->overlap_checked_ms = now;
    if (scheduler_failed(f->sched) || f->ngiven_up) return;
    scheduler_counts c;
    scheduler_counts_get(f->sched, &c);
    if (c.queued > 0) return;
    long skip[SERVE_RUN_JOBS];
    for (int i = 0; i < s->nact; i++) skip[i] = s->act[i].id;
    bool resume = false;
    char err[2 * ERR_LEN];
    long id = queue_next_except(s->q, skip, s->nact, &resume, err, sizeof err);
    if (id < 0) return;
    active_job *a = &s->act[s->nact];
    memset(a, 0, sizeof *a);
    if (!load_job(s, id, &a->l, err, sizeof err)) {   /* it fails alone; the run goes on */
        queue_end(s->q, id, "failed", AAFARM_EXIT_FAILURE, err, NULL, 0);
        console_log(f->con, CONSOLE_ERROR, "job %ld failed: %s", id, err);
        loaded_job_clear(&a->l);
        return;
    }
    const char *pool = a->l.b.pool[0] ? a->l.b.pool : NULL;
    const char *why = NULL;
    int tiles = 0;
    bool files = false;
    for (int i = 0; i < a->l.b.nframes; i++) {
        tiles += image_format_tile_count(&a->l.frames[i].fmt);
        bool known = false;   /* the same job as one in the run (its workers hold it) */
        for (int k = 0; k < f->nframes && !known; k++)
            known = strcmp(a->l.frames[i].jb->hash, f->frames[k].jb->hash) == 0;
        files = files || (a->l.frames[i].jb->nfiles > 0 && !known);
    }
    if ((pool != NULL) != (f->pool != NULL) || (pool && strcmp(pool, f->pool) != 0))
        why = "another pool";
    else if (tiles > SERVE_RUN_TILES - f->ntiles)
        why = "too many tiles for one run";
    if (why) {
        s->no_overlap = true;
        console_log(f->con, CONSOLE_INFO, "job %ld waits for the end of job %ld (%s)", id,
                    s->act[s->nact - 1].id, why);
        loaded_job_clear(&a->l);
        return;
    }
    if (!queue_start(s->q, id, tiles, err, sizeof err)) {   /* cancelled meanwhile */
        loaded_job_clear(&a->l);
        return;
    }
    a->id = id;
    a->resume = resume;
    a->first_frame = f->nframes;
    a->nframes = a->l.b.nframes;
    a->first_tile = f->ntiles;
    a->ntiles = tiles;
    a->start_ms = now;
    s->nact++;
    if (files)   /* its files are fetched afresh: its leases wait for them (farm_messages.c) */
        for (size_t i = 0; i < registry_count(f->reg); i++) registry_at(f->reg, i)->files_ready = false;
    int before = c.leased;
    int rc = farm_serve_append(f, a->l.frames, a->l.b.nframes, err, sizeof err);
    s->opt.scene_path = a->l.b.scene;
    if (rc != AAFARM_EXIT_OK) {   /* its output or journal: it fails, the run ends */
        farm_fail_tile(f, a->first_tile, "%s", err);
        return;
    }
    char more[160];
    snprintf(more, sizeof more, "; joins while %d tile%s of job %ld %s out", before,
             before == 1 ? "" : "s", s->act[s->nact - 2].id, before == 1 ? "is" : "are");
    say_started(s, f, a, more);
    farm_grant_all(f, now);
    say_overlap(s, f);
}

/* Once a loop turn: idle, is there a job? Running: the next job may
 * join; every SERVE_CHECK_MS, a job written is done, a cancelled one
 * ends the run, the others' progress goes to the database. */
static void tick(farm *f, int64_t now)
{
    serve *s = f->serve;
    if (s->nact == 0) {
        if (now - s->checked_ms < SERVE_CHECK_MS) return;
        s->checked_ms = now;
        bool resume;
        if (can_render(f) && queue_next(s->q, &resume, NULL, 0) >= 0)
            f->state = FARM_DONE;   /* idle ends */
        return;
    }
    maybe_overlap(s, f, now);
    say_overlap(s, f);
    if (now - s->checked_ms < SERVE_CHECK_MS) return;
    s->checked_ms = now;
    for (int i = 0; i < s->nact && f->state == FARM_RUNNING; i++) {
        active_job *a = &s->act[i];
        if (a->ended) continue;
        if (job_written(f, a)) {
            record_done(s, f, a, now);
        } else if (queue_cancel_asked(s->q, a->id)) {
            console_log(f->con, CONSOLE_INFO, "job %ld cancelled", a->id);
            s->cancelled = a->id;
            f->state = FARM_CANCELLED;
        } else {
            queue_progress(s->q, a->id, job_tiles_done(f, a), NULL, 0);
        }
    }
}

/* The run's job of a tile, or -1. */
static int job_of_tile(const serve *s, int tile)
{
    for (int i = s->nact - 1; i >= 0; i--)
        if (tile >= s->act[i].first_tile) return i;
    return -1;
}

/* The run ended: each job's end into the database (the one that failed or
 * was cancelled; the others, unless done, back to the queue with their
 * journals, or left 'running' for the next master when this one stops). */
static void end_run(serve *s, farm *f)
{
    int64_t now = farm_now_ms();
    int culprit = f->state == FARM_FAILED && f->failed_tile >= 0
                      ? job_of_tile(s, f->failed_tile)
                      : -1;
    for (int i = 0; i < s->nact; i++) {
        active_job *a = &s->act[i];
        if (a->ended) continue;
        farm_state fate = f->state;
        if (job_written(f, a)) fate = FARM_DONE;
        else if (f->state == FARM_CANCELLED && a->id != s->cancelled) fate = FARM_REQUEUED;
        else if (f->state == FARM_FAILED && culprit >= 0 && culprit != i) fate = FARM_REQUEUED;
        bool keep = fate == FARM_REQUEUED || fate == FARM_INTERRUPTED || fate == FARM_NO_WORKERS;
        for (int k = 0; k < a->nframes && a->first_frame + k < f->nframes; k++) {
            f->frames[a->first_frame + k].keep_journal = keep;
            f->frames[a->first_frame + k].end = fate;
        }
        int done = job_tiles_done(f, a);
        switch (fate) {
        case FARM_DONE: record_done(s, f, a, now); break;
        case FARM_CANCELLED:
            queue_end(s->q, a->id, "cancelled", AAFARM_EXIT_INTERRUPTED,
                      "cancelled while running", NULL, 0);
            break;
        case FARM_REQUEUED:   /* back in the queue: it resumes from its journal */
            queue_progress(s->q, a->id, done, NULL, 0);
            queue_requeue(s->q, a->id, NULL, 0);
            if (f->state == FARM_REQUEUED)
                console_log(f->con, CONSOLE_INFO, "job %ld requeued: every local worker exited "
                            "(%d of %d tiles in its journal); it resumes when they are back",
                            a->id, done, a->ntiles);
            else
                console_log(f->con, CONSOLE_INFO, "job %ld requeued: the job beside it %s (%d of "
                            "%d tiles in its journal); it resumes from there", a->id,
                            f->state == FARM_CANCELLED ? "was cancelled" : "failed", done,
                            a->ntiles);
            break;
        case FARM_INTERRUPTED:   /* stays 'running': the next master resumes it */
        case FARM_NO_WORKERS:
            queue_progress(s->q, a->id, done, NULL, 0);
            console_log(f->con, CONSOLE_INFO, "job %ld %s: a master started on the same "
                        "database resumes it", a->id,
                        fate == FARM_INTERRUPTED ? "interrupted" : "stopped (no workers)");
            break;
        default:
            queue_end(s->q, a->id, "failed", AAFARM_EXIT_FAILURE, f->failure, NULL, 0);
            console_log(f->con, CONSOLE_ERROR, "job %ld failed: %s", a->id, f->failure);
            break;
        }
    }
    farm_serve_end_job(f);
    for (int i = 0; i < s->nact; i++) loaded_job_clear(&s->act[i].l);
    s->nact = 0;
    s->cancelled = -1;
    s->no_overlap = false;
    f->pool = NULL;
    s->opt.scene_path = NULL;   /* it pointed into a job freed now */
}

/* Runs job id, and the jobs that join it, to their end (or the master's). */
static void run_jobs(serve *s, farm *f, long id, bool resume)
{
    active_job *a = &s->act[0];
    memset(a, 0, sizeof *a);
    char err[2 * ERR_LEN];
    bool ok = load_job(s, id, &a->l, err, sizeof err);
    s->opt.scene_path = ok ? a->l.b.scene : "?";
    s->nact = 1;
    s->cancelled = -1;
    s->no_overlap = false;
    a->id = id;
    a->resume = resume;
    a->nframes = ok ? a->l.b.nframes : 0;
    f->pool = ok && a->l.b.pool[0] ? a->l.b.pool : NULL;
    int rc = farm_serve_job(f, ok ? a->l.frames : NULL, a->nframes, err, sizeof err);
    a->ntiles = f->ntiles;
    a->start_ms = f->start_ms;
    if (!ok || rc != AAFARM_EXIT_OK) {
        f->state = FARM_FAILED;
        f->failed_tile = -1;
        snprintf(f->failure, sizeof f->failure, "%s", err);
    } else if (!queue_start(s->q, id, f->ntiles, err, sizeof err)) {
        f->state = FARM_CANCELLED;   /* cancelled between the look and now */
        s->cancelled = id;
    } else {
        say_started(s, f, a, "");
        if (f->pool && !pool_workers(f))
            console_log(f->con, CONSOLE_INFO, "job %ld waits for a worker of pool %s (aafarm-worker "
                        "--connect ... --pool %s)", id, f->pool, f->pool);
        farm_serve_loop(f);
    }
    end_run(s, f);
}

int farm_serve(const farm_options *opt, const char *db_path)
{
    serve s;
    memset(&s, 0, sizeof s);
    s.opt = *opt;
    s.opt.resume = true;     /* every job continues from its journal */
    s.opt.preview = NULL;
    s.opt.stats_json = NULL;
    s.cancelled = -1;
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
    farm_console_open(&f, opt);
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
                run_jobs(&s, &f, id, resume);
            } else {   /* idle until a job comes */
                farm_serve_job(&f, NULL, 0, err, sizeof err);
                farm_serve_loop(&f);
                farm_serve_end_job(&f);
            }
            if (f.state == FARM_INTERRUPTED || atomic_load(interrupted)) {
                rc = AAFARM_EXIT_INTERRUPTED;
                break;
            }
            if (f.state == FARM_NO_WORKERS) {   /* said when it gave up */
                rc = AAFARM_EXIT_NO_WORKERS;
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
