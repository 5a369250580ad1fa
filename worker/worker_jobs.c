/*
 * worker_jobs.c: Job message -> verified, compiled job, and the small
 * list of jobs a worker keeps (see worker_jobs.h).
 */
#include "worker_jobs.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "file_store.h"
#include "job_proto.h"
#include "tile_render.h"
#include "util/err.h"
#include "util/xalloc.h"

struct worker_jobs {
    held_job **jobs;           /* newest first */
    int count, max;
    size_t cache_bytes;
    int threads;                   /* for preparing a job (worker_jobs_set_threads) */
    const atomic_int *cancel;  /* the worker's stop flag, or NULL */
};

held_job *held_job_retain(held_job *self)
{
    int was = atomic_fetch_add(&self->refs, 1);
    assert(was >= 1);   /* only a job someone still holds is retained */
    (void)was;
    return self;
}

void held_job_release(held_job **self_p)
{
    held_job *self = *self_p;
    if (!self) return;
    *self_p = NULL;
    int was = atomic_fetch_sub(&self->refs, 1);
    assert(was >= 1);   /* never released more often than held */
    if (was != 1) return;
    job_scene_destroy(&self->js);
    job_destroy(&self->jb);
    for (int i = 0; i < self->nfile_fds; i++) file_store_release(self->file_fds[i]);
    free(self->file_fds);
    free(self);
}

worker_jobs *worker_jobs_new(int max_held, size_t cache_bytes, const atomic_int *cancel)
{
    worker_jobs *self = xcalloc(1, sizeof *self);
    self->cancel = cancel;
    self->max = max_held < 1 ? 1 : max_held;
    self->jobs = xcalloc((size_t)self->max, sizeof *self->jobs);
    self->cache_bytes = cache_bytes;
    self->threads = 1;
    return self;
}

void worker_jobs_set_threads(worker_jobs *self, int threads)
{
    self->threads = threads > 0 ? threads : 1;
}

void worker_jobs_destroy(worker_jobs **self_p)
{
    worker_jobs *self = *self_p;
    if (!self) return;
    for (int i = 0; i < self->count; i++) held_job_release(&self->jobs[i]);
    free(self->jobs);
    free(self);
    *self_p = NULL;
}

held_job *worker_jobs_find(const worker_jobs *self, const char *hash)
{
    for (int i = 0; i < self->count; i++)
        if (strcmp(self->jobs[i]->hash, hash) == 0) return self->jobs[i];
    return NULL;
}

/* The job from the message's fields, hashed again and compared. */
static job *rebuild(const proto_job *m, char *err, size_t errsz)
{
    char why[ERR_LEN];
    job *jb = job_from_proto(m, why, sizeof why);
    if (!jb) err_set(err, errsz, "job %.12s...: %s", m->job_hash, why);
    return jb;
}

static bool layers_of(const proto_render_options *o, unsigned *layers, char *err, size_t errsz)
{
    *layers = 0;
    for (size_t i = 0; i < o->n_layers; i++) {
        if (strcmp(o->layers[i], "N") == 0) *layers |= IMAGE_LAYER_N;
        else if (strcmp(o->layers[i], "P") == 0) *layers |= IMAGE_LAYER_P;
        else if (strcmp(o->layers[i], "RGBA") != 0) {
            err_set(err, errsz, "unknown EXR layer '%s' (this worker writes RGBA, Z, N, P)",
                    o->layers[i]);
            return false;
        }
    }
    return true;
}

/* Compiles the job and checks the image it describes. */
static bool prepare(held_job *h, const proto_job *m, size_t cache_bytes, int threads,
                    const atomic_int *cancel)
{
    sl_diag *diag = sl_diag_new();
    h->js = job_scene_new_threads(h->jb, cache_bytes, true, threads, cancel, diag);
    if (h->js) trace_renderer_set_log(h->js->renderer, worker_log_warning, NULL);
    if (!h->js) {
        char *text = sl_diag_to_string(diag);
        size_t n = strlen(text);
        while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == ' ')) text[--n] = '\0';
        snprintf(h->error, sizeof h->error, "job %.12s... does not compile here: %s", h->hash, text);
        free(text);
        sl_diag_destroy(&diag);
        return false;
    }
    sl_diag_destroy(&diag);
    const proto_render_options *o = &m->options;
    h->fmt = (image_format){(int)o->width, (int)o->height, (int)o->tile_size, 0};
    if (!layers_of(o, &h->fmt.layers, h->error, sizeof h->error)) return false;
    if (h->js->world.camera.xres != h->fmt.width || h->js->world.camera.yres != h->fmt.height) {
        snprintf(h->error, sizeof h->error, "job %.12s...: the master says %ux%u pixels, the "
                 "scene here says %dx%d", h->hash, o->width, o->height,
                 h->js->world.camera.xres, h->js->world.camera.yres);
        return false;
    }
    if (!image_format_check(&h->fmt, h->error, sizeof h->error)) {
        err_prefix(h->error, sizeof h->error, "job %.12s...", h->hash);
        return false;
    }
    return true;
}

static void keep(worker_jobs *self, held_job *h)
{
    if (self->count == self->max) held_job_release(&self->jobs[--self->count]);
    memmove(&self->jobs[1], &self->jobs[0], sizeof *self->jobs * (size_t)self->count);
    self->jobs[0] = h;
    self->count++;
}

held_job *worker_jobs_add_broken(worker_jobs *self, const char *hash, const char *error)
{
    held_job *h = worker_jobs_find(self, hash);
    if (h) return h;
    h = xcalloc(1, sizeof *h);
    atomic_init(&h->refs, 1);
    snprintf(h->hash, sizeof h->hash, "%s", hash);
    snprintf(h->error, sizeof h->error, "%s", error);
    h->broken = true;
    keep(self, h);
    return h;
}

held_job *worker_jobs_add(worker_jobs *self, const proto_job *m, char *const *file_paths,
                          const int *file_fds)
{
    held_job *h = worker_jobs_find(self, m->job_hash);
    if (h) {
        for (size_t i = 0; file_fds && i < m->n_files; i++) file_store_release(file_fds[i]);
        return h;
    }
    h = xcalloc(1, sizeof *h);
    atomic_init(&h->refs, 1);
    snprintf(h->hash, sizeof h->hash, "%s", m->job_hash);
    if (file_fds && m->n_files) {
        h->nfile_fds = (int)m->n_files;
        h->file_fds = xmalloc(sizeof *h->file_fds * m->n_files);
        memcpy(h->file_fds, file_fds, sizeof *h->file_fds * m->n_files);
    }
    size_t cache = self->cache_bytes ? self->cache_bytes : (size_t)m->options.cache_bytes;
    h->jb = rebuild(m, h->error, sizeof h->error);
    /* the texture module opens the files through job_file_resolve */
    for (size_t i = 0; h->jb && file_paths && i < m->n_files; i++)
        job_file_set_path(h->jb, (int)i, file_paths[i]);
    if (h->jb && m->n_files && !file_paths) {
        snprintf(h->error, sizeof h->error, "job %.12s...: its files are not here",
                 m->job_hash);
        job_destroy(&h->jb);
    }
    if (!h->jb || !prepare(h, m, cache, self->threads, self->cancel)) {
        h->broken = true;
        job_scene_destroy(&h->js);
        job_destroy(&h->jb);
    }
    keep(self, h);
    return h;
}

size_t worker_jobs_hashes(const worker_jobs *self, char **out, size_t max)
{
    size_t n = 0;
    for (int i = 0; i < self->count && n < max; i++)
        if (!self->jobs[i]->broken) out[n++] = self->jobs[i]->hash;
    return n;
}
