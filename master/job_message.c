/*
 * job_message.c: job -> Job message (see job_message.h). The worker does
 * the reverse in worker/worker_jobs.c and recomputes the hash, so every
 * field that enters the hash (common/job/job.c, job_finish) must be sent:
 * the scene name and text, each source's name and text, the shader
 * bindings, the arithmetic, the tile size, the instruction budget and each
 * file's name, SHA-256 and size.
 */
#include "job_message.h"

#include <stdlib.h>

#include "util/xalloc.h"

struct job_message {
    proto_job job;
    proto_source *sources;
    proto_shader_binding *bindings;
    proto_file_ref *files;
};

job_message *job_message_new(const job *jb, const image_format *fmt)
{
    job_message *self = xcalloc(1, sizeof *self);
    size_t nsrc = sl_source_set_count(jb->sources), nsh = (size_t)jb->nshaders;
    size_t nf = (size_t)jb->nfiles;
    self->sources = xcalloc(nsrc + 1, sizeof *self->sources);
    self->bindings = xcalloc(nsh + 1, sizeof *self->bindings);
    self->files = xcalloc(nf + 1, sizeof *self->files);

    proto_job *m = &self->job;
    m->job_hash = jb->hash;
    m->scene_name = jb->scene_file;
    m->scene_text = (const uint8_t *)jb->scene_text;
    m->scene_len = jb->scene_len;
    for (size_t i = 0; i < nsrc; i++) {
        const sl_source *s = sl_source_set_at(jb->sources, i);
        self->sources[i] = (proto_source){s->name, (const uint8_t *)s->text, s->len};
    }
    m->n_sources = nsrc;
    m->sources = self->sources;
    for (size_t i = 0; i < nsh; i++)
        self->bindings[i] = (proto_shader_binding){jb->shaders[i].name, jb->shaders[i].file};
    m->n_shaders = nsh;
    m->shaders = self->bindings;
    /* the files by name and hash only: their bytes go once per host */
    for (size_t i = 0; i < nf; i++)
        self->files[i] = (proto_file_ref){jb->files[i].name, jb->files[i].sha256,
                                          jb->files[i].size};
    m->n_files = nf;
    m->files = self->files;

    m->options = (proto_render_options){
        .width = (uint32_t)fmt->width,
        .height = (uint32_t)fmt->height,
        .tile_size = (uint32_t)jb->options.tile_size,
        .arithmetic = jb->options.arith == TRACE_ARITH_INTERVAL ? PROTO_ARITH_INTERVAL
                                                                : PROTO_ARITH_AFFINE,
        .cache_bytes = 0,   /* each worker's own --cache-bytes */
        .instruction_budget = (uint64_t)jb->options.max_instructions,
        .frame = (uint32_t)jb->options.frame,
    };
    return self;
}

void job_message_destroy(job_message **self_p)
{
    job_message *self = *self_p;
    if (!self) return;
    free(self->sources);
    free(self->bindings);
    free(self->files);
    free(self);
    *self_p = NULL;
}

const proto_job *job_message_job(const job_message *self) { return &self->job; }

size_t job_message_packed_size(const job_message *self)
{
    proto_msg msg = {.kind = PROTO_JOB, .job = self->job};
    return proto_msg_packed_size(&msg);
}
