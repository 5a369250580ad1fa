/*
 * standalone.c: the standalone renderer (see standalone.h). Each thread
 * works through a contiguous run of tiles (tile_runs.h: neighbouring tiles
 * one after the other keep its box cache warm, as Pharr & Hanrahan's tile
 * orders do; idle threads steal half a run), renders them with its own
 * trace_thread, compresses them, and hands the compressed chunks to the
 * one writer under a mutex. At the end of the frame, when no tile is left
 * to take, a thread helps the tiles still being traced: it takes blocks of
 * 8 x 8 pixels' samples of the tile with the most blocks left (trace/
 * render.h, trace_tile_samples), so the frame's tail is a block, not a
 * tile (one expensive tile would otherwise keep one core busy while the
 * others wait).
 */
#include "standalone.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "image/preview.h"
#include "image/writer.h"
#include "job/frames.h"
#include "job/job_scene.h"
#include "tex/tex.h"
#include "tile_render.h"
#include "tile_runs.h"
#include "tile_share.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/xalloc.h"

/* Set by SIGINT/SIGTERM (a lock-free atomic: safe in a handler); every
 * render thread's trace_thread watches it, so a render stops within one
 * ray's walk, not at the end of a tile. */
static atomic_int interrupted;

static void on_signal(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
}

typedef struct shared {
    const standalone_options *opt;
    const job_scene *js;
    image_format fmt;
    image_writer *writer;
    tile_runs runs;                /* which tiles each thread renders next */
    atomic_int next_thread;        /* hands out thread indexes */
    int ntiles;
    pthread_mutex_t lock;          /* writer, progress, error, board */
    tile_board board;              /* the tiles being traced (tile_share.h) */
    long tail_blocks;              /* blocks traced by a thread not their owner */
    int done;
    bool failed;
    char error[ERR_LEN];
    trace_stats stats;
    trace_object_work *work;       /* per object, summed over the threads */
    worker_nonfinite nonfinite;    /* summed; x, y of the first tile's first */
    double t_start;
} shared;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void progress(shared *s)
{
    if (s->opt->verbosity < 0 || !isatty(STDERR_FILENO)) return;
    double el = now_s() - s->t_start;
    double eta = s->done > 0 ? el * (s->ntiles - s->done) / s->done : 0;
    fprintf(stderr, "\r  %d/%d tiles  %.1f s  ETA %.0f s   ", s->done, s->ntiles, el, eta);
    if (s->done == s->ntiles) fputc('\n', stderr);
    fflush(stderr);
}

/* Takes blocks of the tile being traced with the most blocks left until
 * no tile has any; false when a shader failed or the render was stopped. */
static bool help_tail(shared *s, trace_thread *th)
{
    for (;;) {
        pthread_mutex_lock(&s->lock);
        tile_share *sh = tile_board_pick(&s->board);
        pthread_mutex_unlock(&s->lock);
        if (!sh) return true;
        long mine = 0;
        bool ok = tile_share_trace(sh, th, &mine);
        pthread_mutex_lock(&s->lock);
        s->tail_blocks += mine;
        tile_board_leave(&s->board, sh, ok, th);
        pthread_mutex_unlock(&s->lock);
        if (!ok) return false;
    }
}

/* Traces tile `r` with the threads that come to help (help_tail), filters
 * it and compresses it: the tile's file (the caller frees) with *chunk
 * pointing at its compressed chunk, or NULL with the reason in err. */
static void *trace_tile(shared *s, trace_thread *th, int me, image_rect r,
                        worker_nonfinite *nf, const void **chunk, size_t *chunk_len,
                        char *err, size_t errsz)
{
    tile_share sh;
    tile_share_init(&sh, s->js->renderer, r);
    tile_board_publish(&s->board, me, &sh);
    bool ok = tile_share_trace(&sh, th, NULL);
    tile_board_withdraw(&s->board, me, &sh);
    void *exr = NULL;
    size_t exr_len = 0;
    if (!ok) {
        err_set(err, errsz, "tile at (%d,%d): %s", r.x0, r.y0, th->error);
    } else if (sh.failed) {
        err_set(err, errsz, "%s", sh.error);
    } else {
        image_tile *tile = worker_filter_tile(s->js, sh.ts, r, s->fmt.layers, nf, err, errsz);
        /* compressed here, in parallel: the writer's lock only copies it */
        if (tile)
            image_tile_encode_chunk(tile, &s->fmt, &exr, &exr_len, chunk, chunk_len, err,
                                    errsz);
        image_tile_destroy(&tile);
    }
    tile_share_clear(&sh);
    return exr;
}

static void *render_thread(void *arg)
{
    shared *s = arg;
    trace_thread *th = trace_thread_new(&s->js->world);
    trace_thread_set_cancel(th, &interrupted);
    trace_thread_set_print(th, worker_print_shader_line, NULL);
    int tx_count = image_format_tiles_x(&s->fmt);
    int me = atomic_fetch_add(&s->next_thread, 1);
    for (;;) {
        int i = tile_runs_take(&s->runs, me);
        if (i < 0) {
            if (!interrupted) help_tail(s, th);
            break;
        }
        if (interrupted) break;
        pthread_mutex_lock(&s->lock);
        bool stop = s->failed;
        pthread_mutex_unlock(&s->lock);
        if (stop) break;
        image_rect r = image_format_tile_rect(&s->fmt, i % tx_count, i / tx_count);
        char err[ERR_LEN];
        worker_nonfinite nf = {0, 0, 0};
        const void *chunk = NULL;
        size_t chunk_len = 0;
        void *exr = trace_tile(s, th, me, r, &nf, &chunk, &chunk_len, err, sizeof err);
        pthread_mutex_lock(&s->lock);
        if (exr && nf.count) {
            if (!s->nonfinite.count || nf.y < s->nonfinite.y ||
                (nf.y == s->nonfinite.y && nf.x < s->nonfinite.x)) {
                s->nonfinite.x = nf.x;
                s->nonfinite.y = nf.y;
            }
            s->nonfinite.count += nf.count;
        }
        if (!exr) {
            if (!s->failed) snprintf(s->error, sizeof s->error, "%s", err);
            s->failed = true;
        } else if (!image_writer_put_chunk(s->writer, i % tx_count, i / tx_count, chunk,
                                           chunk_len, err, sizeof err)) {
            if (!s->failed) snprintf(s->error, sizeof s->error, "%s", err);
            s->failed = true;
        } else {
            s->done++;
            progress(s);
        }
        pthread_mutex_unlock(&s->lock);
        free(exr);
    }
    trace_thread_sync_stats(th);
    pthread_mutex_lock(&s->lock);
    trace_stats_add(&s->stats, &th->stats);
    trace_object_work_add(s->work, th->work, s->js->world.nobjects);
    pthread_mutex_unlock(&s->lock);
    trace_thread_destroy(&th);
    return NULL;
}

static int default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

static bool write_stats_json(const char *path, const shared *s, int threads, double secs)
{
    FILE *f = fopen(path, "w");
    if (!f) return false;
    char extra[8192];
    tex_tile_stats ts;
    tex_tiles_stats(tex_tiles_process(), &ts);
    trace_world_counts wc;
    trace_world_count(&s->js->world, &wc);
    snprintf(extra, sizeof extra,
             "\"scene\": \"%s\", \"width\": %d, \"height\": %d, \"tiles\": %d, "
             "\"threads\": %d, \"arith\": \"%s\", \"cache_bytes\": %zu, \"seconds\": %.3f, "
             "\"nonfinite_samples\": %llu, \"texture_bytes\": %zu, "
             "\"texture_tile_loads\": %llu, \"texture_tile_evictions\": %llu, "
             "\"texture_tile_peak_bytes\": %zu, \"world_objects\": %d, \"world_meshes\": %d, "
             "\"world_pieces\": %ld, \"instance_groups\": %d, \"instances\": %ld, "
             "\"instances_moved\": %ld, \"instances_own\": %ld, \"tail_blocks\": %ld",
             s->opt->scene_path, s->fmt.width, s->fmt.height, s->ntiles, threads,
             trace_arith_name(s->opt->job.arith), s->opt->cache_bytes, secs,
             (unsigned long long)s->nonfinite.count, ts.budget, ts.loads, ts.evictions,
             ts.peak_bytes, wc.objects, wc.meshes, wc.pieces, wc.groups, wc.placements,
             wc.moved, wc.own, s->tail_blocks);
    trace_stats_write_json(&s->stats, extra, f);
    fputc('\n', f);
    return fclose(f) == 0;
}

/* The outputs of one frame. */
typedef struct frame_out {
    const char *output, *preview, *stats_json;
} frame_out;

/* Renders one frame's job (loaded and checked) into its outputs. */
static int render_frame(const standalone_options *opt, const job *jb, const frame_out *fo)
{
    sl_diag *diag = sl_diag_new();
    job_scene *js = job_scene_new_threads(jb, opt->cache_bytes, true,
                                          opt->threads > 0 ? opt->threads : default_threads(),
                                          &interrupted, diag);
    if (atomic_load(&interrupted)) {   /* also while the world was built */
        sl_diag_destroy(&diag);
        fprintf(stderr, "aafarm-worker: interrupted; %s not written\n", fo->output);
        job_scene_destroy(&js);
        return AAFARM_EXIT_INTERRUPTED;
    }
    if (js) trace_renderer_set_log(js->renderer, worker_log_warning, NULL);
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!js) {
        /* job_load checked the scene and compiled the shaders; what fails
         * after it is a shader at run time (its budget): a render failure */
        return AAFARM_EXIT_FAILURE;
    }

    shared s = {.opt = opt, .js = js};
    s.fmt = (image_format){js->world.camera.xres, js->world.camera.yres,
                           opt->job.tile_size, 0};
    char err[ERR_LEN];
    if (!image_format_check(&s.fmt, err, sizeof err)) {
        fprintf(stderr, "aafarm-worker: %s\n", err);
        job_scene_destroy(&js);
        return AAFARM_EXIT_INPUT;
    }
    s.writer = image_writer_new(fo->output, &s.fmt, err, sizeof err);
    if (!s.writer) {
        fprintf(stderr, "aafarm-worker: %s\n", err);
        job_scene_destroy(&js);
        return AAFARM_EXIT_FAILURE;
    }
    s.ntiles = image_format_tile_count(&s.fmt);
    s.work = xcalloc((size_t)js->world.nobjects + 1, sizeof *s.work);
    pthread_mutex_init(&s.lock, NULL);
    int threads = opt->threads > 0 ? opt->threads : default_threads();
    atomic_init(&s.next_thread, 0);
    tile_runs_init(&s.runs, s.ntiles, threads);
    tile_board_init(&s.board, &s.lock, NULL, threads);
    if (opt->verbosity >= 0)
        fprintf(stderr, "aafarm-worker: %s: %dx%d, %d tiles of %d, %d thread%s, %s arithmetic\n",
                opt->scene_path, s.fmt.width, s.fmt.height, s.ntiles, s.fmt.tile_size,
                threads, threads == 1 ? "" : "s", trace_arith_name(opt->job.arith));

    s.t_start = now_s();
    pthread_t *tids = xcalloc((size_t)threads, sizeof *tids);
    for (int i = 0; i < threads; i++) pthread_create(&tids[i], NULL, render_thread, &s);
    for (int i = 0; i < threads; i++) pthread_join(tids[i], NULL);
    free(tids);
    double secs = now_s() - s.t_start;

    int rc = AAFARM_EXIT_OK;
    if (interrupted) {
        fprintf(stderr, "\naafarm-worker: interrupted; %s not written\n", fo->output);
        image_writer_destroy(&s.writer);
        rc = AAFARM_EXIT_INTERRUPTED;
    } else if (s.failed) {
        fprintf(stderr, "aafarm-worker: %s\naafarm-worker: %s not written\n", s.error, fo->output);
        image_writer_destroy(&s.writer);
        rc = AAFARM_EXIT_FAILURE;
    } else if (!image_writer_finish(&s.writer, err, sizeof err)) {
        fprintf(stderr, "aafarm-worker: %s\n", err);
        image_writer_destroy(&s.writer);
        rc = AAFARM_EXIT_FAILURE;
    }
    /* the preview is read back from the finished EXR, as the farm's master
     * makes it (one function, the same half samples: the same PNG bytes) */
    if (rc == AAFARM_EXIT_OK && fo->preview &&
        !image_preview_write_png_exr_cancel(fo->preview, fo->output, &interrupted, err,
                                            sizeof err)) {
        if (atomic_load(&interrupted)) {
            fprintf(stderr, "aafarm-worker: interrupted; %s written, %s not written\n",
                    fo->output, fo->preview);
            rc = AAFARM_EXIT_INTERRUPTED;
        } else {
            fprintf(stderr, "aafarm-worker: %s\n", err);
            rc = AAFARM_EXIT_FAILURE;
        }
    }
    if (rc == AAFARM_EXIT_OK && s.nonfinite.count)
        fprintf(stderr, "aafarm-worker: warning: %llu NaN/Inf samples (the first at pixel "
                "(%d,%d)) were written as 0 (Z: as no hit); a shader divides by zero or "
                "overflows there\n", (unsigned long long)s.nonfinite.count, s.nonfinite.x,
                s.nonfinite.y);
    if (rc == AAFARM_EXIT_OK && opt->verbosity >= 0) {
        trace_object_work_report(&js->world, s.work, "aafarm-worker", stderr);
        fprintf(stderr, "aafarm-worker: wrote %s (%.2f s)\n", fo->output, secs);
    }
    if (opt->stats) {
        fprintf(stderr, "statistics:\n");
        trace_stats_print(&s.stats, stderr);
        /* what the world holds (trace_world_count), as the lines above */
        trace_world_counts wc;
        trace_world_count(&js->world, &wc);
        fprintf(stderr, "  %-18s %d\n  %-18s %d\n  %-18s %ld\n  %-18s %d\n  %-18s %ld\n"
                "  %-18s %ld\n  %-18s %ld\n", "world_objects", wc.objects, "world_meshes",
                wc.meshes, "world_pieces", wc.pieces, "instance_groups", wc.groups, "instances",
                wc.placements, "instances_moved", wc.moved, "instances_own", wc.own);
        /* blocks of 8 x 8 pixels traced by a thread that had no tile left,
         * for the thread that owned the tile (the frame's tail) */
        fprintf(stderr, "  %-18s %ld\n", "tail_blocks", s.tail_blocks);
        tex_tile_stats ts;
        tex_tiles_stats(tex_tiles_process(), &ts);
        if (ts.loads)
            fprintf(stderr, "  texture tiles (this process): %llu loaded, %llu evicted, peak "
                    "%.1f MiB of a %.1f MiB budget%s\n", ts.loads, ts.evictions,
                    ts.peak_bytes / 1048576.0, ts.budget / 1048576.0,
                    ts.budget ? "" : " (unlimited)");
    }
    if (fo->stats_json && !write_stats_json(fo->stats_json, &s, threads, secs)) {
        fprintf(stderr, "aafarm-worker: cannot write %s: %s\n", fo->stats_json, strerror(errno));
        if (rc == AAFARM_EXIT_OK) rc = AAFARM_EXIT_FAILURE;
    }
    free(s.work);
    tile_runs_clear(&s.runs);
    tile_board_clear(&s.board);
    pthread_mutex_destroy(&s.lock);
    job_scene_destroy(&js);
    return rc;
}

/* A per-frame name for an optional output (the preview, the statistics). */
static char *frame_name(const char *name, const job *jb, int nframes)
{
    if (!name) return NULL;
    char err[ERR_LEN];
    char *out = frame_output_name(name, jb->frame_number, nframes, false, err, sizeof err);
    if (!out) fprintf(stderr, "aafarm-worker: %s\n", err);
    return out;
}

int worker_standalone(const standalone_options *opt)
{
    /* first: a signal during preparation must not leave a temporary file */
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    sl_diag *diag = sl_diag_new();
    bool usage = false;
    frame_sequence *seq = frame_sequence_load(opt->scene_path, &opt->job, opt->frames,
                                              opt->output, &usage, &interrupted, diag);
    if (atomic_load(&interrupted)) {   /* while reading, compiling, checking */
        sl_diag_destroy(&diag);
        frame_sequence_destroy(&seq);
        fprintf(stderr, "aafarm-worker: interrupted while loading %s; nothing written\n",
                opt->scene_path);
        return AAFARM_EXIT_INTERRUPTED;
    }
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!seq) return usage ? AAFARM_EXIT_USAGE : AAFARM_EXIT_INPUT;
    if (seq->numbered && opt->verbosity >= 0)
        fprintf(stderr, "aafarm-worker: %s has %d frames: each one's number goes before the "
                "extension of %s (%s ...; put %%04d in the name to place it)\n",
                opt->scene_path, seq->nframes, seq->numbered, seq->outputs[0]);
    int rc = AAFARM_EXIT_OK;
    for (int i = 0; i < seq->count && rc == AAFARM_EXIT_OK; i++) {
        const job *jb = seq->jobs[i];
        if (atomic_load(&interrupted)) {
            fprintf(stderr, "aafarm-worker: interrupted; %s not written\n", seq->outputs[i]);
            rc = AAFARM_EXIT_INTERRUPTED;
            break;
        }
        if (seq->count > 1 && opt->verbosity >= 0)
            fprintf(stderr, "aafarm-worker: frame %d (%d of %d) -> %s\n", jb->frame_number,
                    i + 1, seq->count, seq->outputs[i]);
        char *preview = frame_name(opt->preview, jb, seq->nframes);
        char *stats_json = frame_name(opt->stats_json, jb, seq->nframes);
        frame_out fo = {seq->outputs[i], preview, stats_json};
        if ((opt->preview && !preview) || (opt->stats_json && !stats_json))
            rc = AAFARM_EXIT_USAGE;
        else
            rc = render_frame(opt, jb, &fo);
        free(preview);
        free(stats_json);
    }
    frame_sequence_destroy(&seq);
    return rc;
}
