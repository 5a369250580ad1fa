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

struct job_message {
    Aafarm__Job job;
    Aafarm__RenderOptions options;
    Aafarm__Source *source;
    Aafarm__Source **sources;
    Aafarm__ShaderBinding *binding;
    Aafarm__ShaderBinding **bindings;
    Aafarm__FileRef *file;
    Aafarm__FileRef **files;
};

job_message *job_message_new(const job *jb, const image_format *fmt)
{
    job_message *self = calloc(1, sizeof *self);
    size_t nsrc = sl_source_set_count(jb->sources), nsh = (size_t)jb->nshaders;
    if (!self) abort();
    self->source = calloc(nsrc + 1, sizeof *self->source);
    self->sources = calloc(nsrc + 1, sizeof *self->sources);
    self->binding = calloc(nsh + 1, sizeof *self->binding);
    self->bindings = calloc(nsh + 1, sizeof *self->bindings);
    if (!self->source || !self->sources || !self->binding || !self->bindings) abort();

    aafarm__job__init(&self->job);
    self->job.job_hash = (char *)jb->hash;
    self->job.scene_name = jb->scene_file;
    self->job.scene_text.data = (uint8_t *)jb->scene_text;
    self->job.scene_text.len = jb->scene_len;
    for (size_t i = 0; i < nsrc; i++) {
        const sl_source *s = sl_source_set_at(jb->sources, i);
        aafarm__source__init(&self->source[i]);
        self->source[i].name = (char *)s->name;
        self->source[i].text.data = (uint8_t *)s->text;
        self->source[i].text.len = s->len;
        self->sources[i] = &self->source[i];
    }
    self->job.n_sources = nsrc;
    self->job.sources = self->sources;
    for (size_t i = 0; i < nsh; i++) {
        aafarm__shader_binding__init(&self->binding[i]);
        self->binding[i].name = jb->shaders[i].name;
        self->binding[i].source = jb->shaders[i].file;
        self->bindings[i] = &self->binding[i];
    }
    self->job.n_shaders = nsh;
    self->job.shaders = self->bindings;
    /* the files by name and hash only: their bytes go once per host */
    size_t nf = (size_t)jb->nfiles;
    self->file = calloc(nf + 1, sizeof *self->file);
    self->files = calloc(nf + 1, sizeof *self->files);
    if (!self->file || !self->files) abort();
    for (size_t i = 0; i < nf; i++) {
        aafarm__file_ref__init(&self->file[i]);
        self->file[i].name = jb->files[i].name;
        self->file[i].sha256 = (char *)jb->files[i].sha256;
        self->file[i].size = jb->files[i].size;
        self->files[i] = &self->file[i];
    }
    self->job.n_files = nf;
    self->job.files = self->files;

    aafarm__render_options__init(&self->options);
    self->options.width = (uint32_t)fmt->width;
    self->options.height = (uint32_t)fmt->height;
    self->options.tile_size = (uint32_t)jb->options.tile_size;
    self->options.arithmetic = jb->options.arith == TRACE_ARITH_INTERVAL
                                   ? AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL
                                   : AAFARM__ARITHMETIC__ARITHMETIC_AFFINE;
    self->options.cache_bytes = 0;   /* each worker's own --cache-bytes */
    self->options.instruction_budget = (uint64_t)jb->options.max_instructions;
    self->options.frame = (uint32_t)jb->options.frame;
    self->job.options = &self->options;
    return self;
}

void job_message_destroy(job_message **self_p)
{
    job_message *self = *self_p;
    if (!self) return;
    free(self->source);
    free(self->sources);
    free(self->binding);
    free(self->bindings);
    free(self->file);
    free(self->files);
    free(self);
    *self_p = NULL;
}

Aafarm__Job *job_message_job(job_message *self) { return &self->job; }

size_t job_message_packed_size(job_message *self)
{
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_JOB;
    env.job = &self->job;
    return aafarm__envelope__get_packed_size(&env);
}
