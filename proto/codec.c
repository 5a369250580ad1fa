/*
 * codec.c: the plain messages of message.h to and from the protobuf-c
 * structs generated from aafarm.proto (message_pb.h), and the saved Job.
 *
 * Field for field, nothing judged here: the checks are message.c's. The
 * generated structs want mutable pointers (char *, uint8_t *) even for
 * what they only read when packing; the casts below drop a const that
 * packing never writes through.
 */
#include "message_pb.h"

#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

_Static_assert(PROTO_HELLO == (int)AAFARM__ENVELOPE__BODY_HELLO &&
                   PROTO_FILES_READY == (int)AAFARM__ENVELOPE__BODY_FILES_READY &&
                   PROTO_NONE == (int)AAFARM__ENVELOPE__BODY__NOT_SET,
               "proto_kind numbers the Envelope's oneof as aafarm.proto does");

/* protobuf has no absent string: NULL goes out as "". */
static char *str(const char *s) { return (char *)(s ? s : ""); }

/* ---------------------------------------------------------------------- */
/* plain -> generated (sending)                                            */
/* ---------------------------------------------------------------------- */

static void job_out(envelope_out *out, const proto_job *m)
{
    Aafarm__Job *j = &out->body.job;
    aafarm__job__init(j);
    j->job_hash = str(m->job_hash);
    j->scene_name = str(m->scene_name);
    j->scene_text.data = (uint8_t *)m->scene_text;
    j->scene_text.len = m->scene_len;

    /* the pointer arrays and the structs they point at, in one block */
    size_t nsrc = m->n_sources, nsh = m->n_shaders, nf = m->n_files;
    size_t nx = m->options.n_extra;
    size_t bytes = (nsrc + nsh + nf + nx) * sizeof(void *) + nsrc * sizeof(Aafarm__Source) +
                   nsh * sizeof(Aafarm__ShaderBinding) + nf * sizeof(Aafarm__FileRef) +
                   nx * sizeof(Aafarm__Option);
    char *at = out->arrays = xmalloc(bytes ? bytes : 1);
    Aafarm__Source **srcp = (Aafarm__Source **)at;
    Aafarm__ShaderBinding **shp = (Aafarm__ShaderBinding **)(srcp + nsrc);
    Aafarm__FileRef **fp = (Aafarm__FileRef **)(shp + nsh);
    Aafarm__Option **xp = (Aafarm__Option **)(fp + nf);
    Aafarm__Source *src = (Aafarm__Source *)(xp + nx);
    Aafarm__ShaderBinding *sh = (Aafarm__ShaderBinding *)(src + nsrc);
    Aafarm__FileRef *f = (Aafarm__FileRef *)(sh + nsh);
    Aafarm__Option *x = (Aafarm__Option *)(f + nf);

    for (size_t i = 0; i < nsrc; i++) {
        aafarm__source__init(&src[i]);
        src[i].name = str(m->sources[i].name);
        src[i].text.data = (uint8_t *)m->sources[i].text;
        src[i].text.len = m->sources[i].text_len;
        srcp[i] = &src[i];
    }
    j->n_sources = nsrc;
    j->sources = nsrc ? srcp : NULL;
    for (size_t i = 0; i < nsh; i++) {
        aafarm__shader_binding__init(&sh[i]);
        sh[i].name = str(m->shaders[i].name);
        sh[i].source = str(m->shaders[i].source);
        shp[i] = &sh[i];
    }
    j->n_shaders = nsh;
    j->shaders = nsh ? shp : NULL;
    for (size_t i = 0; i < nf; i++) {
        aafarm__file_ref__init(&f[i]);
        f[i].name = str(m->files[i].name);
        f[i].sha256 = str(m->files[i].sha256);
        f[i].size = m->files[i].size;
        fp[i] = &f[i];
    }
    j->n_files = nf;
    j->files = nf ? fp : NULL;

    const proto_render_options *o = &m->options;
    Aafarm__RenderOptions *po = &out->options;
    aafarm__render_options__init(po);
    po->width = o->width;
    po->height = o->height;
    po->tile_size = o->tile_size;
    po->arithmetic = o->arithmetic == PROTO_ARITH_INTERVAL ? AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL
                                                           : AAFARM__ARITHMETIC__ARITHMETIC_AFFINE;
    po->cache_bytes = o->cache_bytes;
    po->instruction_budget = o->instruction_budget;
    po->n_layers = o->n_layers;
    po->layers = (char **)o->layers;
    for (size_t i = 0; i < nx; i++) {
        aafarm__option__init(&x[i]);
        x[i].key = str(o->extra[i].key);
        x[i].value = str(o->extra[i].value);
        xp[i] = &x[i];
    }
    po->n_extra = nx;
    po->extra = nx ? xp : NULL;
    po->frame = o->frame;
    j->options = po;
    out->env.job = j;
}

void envelope_out_init(envelope_out *out, const proto_msg *msg)
{
    memset(out, 0, sizeof *out);
    aafarm__envelope__init(&out->env);
    out->env.body_case = (Aafarm__Envelope__BodyCase)msg->kind;
    switch (msg->kind) {
    case PROTO_HELLO: {
        const proto_hello *m = &msg->hello;
        Aafarm__Hello *b = &out->body.hello;
        aafarm__hello__init(b);
        b->protocol_version = m->protocol_version;
        b->worker_name = str(m->worker_name);
        b->host = str(m->host);
        b->pid = m->pid;
        b->threads = m->threads;
        b->n_jobs_held = m->n_jobs_held;
        b->jobs_held = (char **)m->jobs_held;
        b->software = str(m->software);
        b->pool = str(m->pool);
        out->env.hello = b;
        break;
    }
    case PROTO_WELCOME: {
        const proto_welcome *m = &msg->welcome;
        Aafarm__Welcome *b = &out->body.welcome;
        aafarm__welcome__init(b);
        b->protocol_version = m->protocol_version;
        b->master_name = str(m->master_name);
        b->master_session = m->master_session;
        b->heartbeat_ms = m->heartbeat_ms;
        b->heartbeat_liveness = m->heartbeat_liveness;
        out->env.welcome = b;
        break;
    }
    case PROTO_REJECT: {
        Aafarm__Reject *b = &out->body.reject;
        aafarm__reject__init(b);
        b->code = (Aafarm__RejectCode)msg->reject.code;
        b->reason = str(msg->reject.reason);
        b->protocol_version = msg->reject.protocol_version;
        out->env.reject = b;
        break;
    }
    case PROTO_ASK:
        aafarm__ask__init(&out->body.ask);
        out->body.ask.credits = msg->ask.credits;
        out->env.ask = &out->body.ask;
        break;
    case PROTO_JOB: job_out(out, &msg->job); break;
    case PROTO_NEED_JOB:
        aafarm__need_job__init(&out->body.need_job);
        out->body.need_job.job_hash = str(msg->need_job.job_hash);
        out->body.need_job.lease_id = msg->need_job.lease_id;
        out->env.need_job = &out->body.need_job;
        break;
    case PROTO_GRANT: {
        const proto_grant *m = &msg->grant;
        Aafarm__Grant *b = &out->body.grant;
        aafarm__grant__init(b);
        aafarm__rect__init(&out->rect);
        out->rect.x = m->tile.x;
        out->rect.y = m->tile.y;
        out->rect.width = m->tile.width;
        out->rect.height = m->tile.height;
        b->job_hash = str(m->job_hash);
        b->lease_id = m->lease_id;
        b->tile_index = m->tile_index;
        b->tile = &out->rect;
        b->deadline_ms = m->deadline_ms;
        out->env.grant = b;
        break;
    }
    case PROTO_RESULT: {
        const proto_result *m = &msg->result;
        Aafarm__Result *b = &out->body.result;
        Aafarm__TileStats *st = &out->stats;
        aafarm__result__init(b);
        aafarm__tile_stats__init(st);
        st->rays = m->stats.rays;
        st->boxes = m->stats.boxes;
        st->shader_evals = m->stats.shader_evals;
        st->cache_hits = m->stats.cache_hits;
        st->cache_misses = m->stats.cache_misses;
        st->cache_evictions = m->stats.cache_evictions;
        st->peak_cache_bytes = m->stats.peak_cache_bytes;
        st->cpu_seconds = m->stats.cpu_seconds;
        st->wall_seconds = m->stats.wall_seconds;
        st->nonfinite_samples = m->stats.nonfinite_samples;
        b->job_hash = str(m->job_hash);
        b->lease_id = m->lease_id;
        b->tile_index = m->tile_index;
        b->stats = st;
        b->exr_bytes = m->exr_bytes;
        out->env.result = b;
        break;
    }
    case PROTO_FAILURE: {
        const proto_failure *m = &msg->failure;
        Aafarm__Failure *b = &out->body.failure;
        aafarm__failure__init(b);
        b->job_hash = str(m->job_hash);
        b->lease_id = m->lease_id;
        b->tile_index = m->tile_index;
        b->message = str(m->message);
        b->retryable = m->retryable;
        out->env.failure = b;
        break;
    }
    case PROTO_HEARTBEAT:
        aafarm__heartbeat__init(&out->body.heartbeat);
        out->body.heartbeat.n_leases = msg->heartbeat.n_leases;
        out->body.heartbeat.leases = (uint64_t *)msg->heartbeat.leases;
        out->env.heartbeat = &out->body.heartbeat;
        break;
    case PROTO_JOB_DONE: {
        Aafarm__JobDone *b = &out->body.job_done;
        aafarm__job_done__init(b);
        b->job_hash = str(msg->job_done.job_hash);
        b->status = (Aafarm__JobStatus)msg->job_done.status;
        b->message = str(msg->job_done.message);
        out->env.job_done = b;
        break;
    }
    case PROTO_SHUTDOWN:
        aafarm__shutdown__init(&out->body.shutdown);
        out->body.shutdown.reason = str(msg->shutdown.reason);
        out->env.shutdown = &out->body.shutdown;
        break;
    case PROTO_NEED_FILE: {
        const proto_need_file *m = &msg->need_file;
        Aafarm__NeedFile *b = &out->body.need_file;
        aafarm__need_file__init(b);
        b->job_hash = str(m->job_hash);
        b->sha256 = str(m->sha256);
        b->offset = m->offset;
        b->length = m->length;
        b->received = m->received;
        out->env.need_file = b;
        break;
    }
    case PROTO_FILE_CHUNK: {
        const proto_file_chunk *m = &msg->file_chunk;
        Aafarm__FileChunk *b = &out->body.file_chunk;
        aafarm__file_chunk__init(b);
        b->sha256 = str(m->sha256);
        b->offset = m->offset;
        b->file_size = m->file_size;
        b->length = m->length;
        out->env.file_chunk = b;
        break;
    }
    case PROTO_FILES_READY: {
        const proto_files_ready *m = &msg->files_ready;
        Aafarm__FilesReady *b = &out->body.files_ready;
        aafarm__files_ready__init(b);
        b->job_hash = str(m->job_hash);
        b->hits = m->hits;
        b->misses = m->misses;
        b->fetched_bytes = m->fetched_bytes;
        out->env.files_ready = b;
        break;
    }
    case PROTO_NONE:
    default:
        break;   /* the check says what is wrong with it */
    }
}

void envelope_out_clear(envelope_out *out)
{
    free(out->arrays);
    out->arrays = NULL;
}

size_t proto_msg_packed_size(const proto_msg *msg)
{
    envelope_out out;
    envelope_out_init(&out, msg);
    size_t n = aafarm__envelope__get_packed_size(&out.env);
    envelope_out_clear(&out);
    return n;
}

/* ---------------------------------------------------------------------- */
/* generated -> plain (receiving)                                          */
/* ---------------------------------------------------------------------- */

static bool job_view(const Aafarm__Job *j, proto_job *m, void **block)
{
    const Aafarm__RenderOptions *o = j->options;
    size_t nsrc = j->n_sources, nsh = j->n_shaders, nf = j->n_files;
    size_t nx = o ? o->n_extra : 0;
    size_t bytes = nsrc * sizeof(proto_source) + nsh * sizeof(proto_shader_binding) +
                   nf * sizeof(proto_file_ref) + nx * sizeof(proto_option);
    /* a peer chose these counts: no abort when the memory is not there */
    char *at = *block = bytes ? try_malloc(bytes) : NULL;
    if (bytes && !at)
        return false;
    proto_source *src = (proto_source *)at;
    proto_shader_binding *sh = (proto_shader_binding *)(src + nsrc);
    proto_file_ref *f = (proto_file_ref *)(sh + nsh);
    proto_option *x = (proto_option *)(f + nf);

    *m = (proto_job){
        .job_hash = j->job_hash,
        .scene_name = j->scene_name,
        .scene_text = j->scene_text.data,
        .scene_len = j->scene_text.len,
        .n_sources = nsrc, .sources = src,
        .n_shaders = nsh, .shaders = sh,
        .n_files = nf, .files = f,
    };
    for (size_t i = 0; i < nsrc; i++)
        src[i] = (proto_source){j->sources[i]->name, j->sources[i]->text.data,
                                j->sources[i]->text.len};
    for (size_t i = 0; i < nsh; i++)
        sh[i] = (proto_shader_binding){j->shaders[i]->name, j->shaders[i]->source};
    for (size_t i = 0; i < nf; i++)
        f[i] = (proto_file_ref){j->files[i]->name, j->files[i]->sha256, j->files[i]->size};
    if (o) {
        for (size_t i = 0; i < nx; i++) x[i] = (proto_option){o->extra[i]->key, o->extra[i]->value};
        m->options = (proto_render_options){
            .width = o->width,
            .height = o->height,
            .tile_size = o->tile_size,
            .arithmetic = o->arithmetic == AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL
                              ? PROTO_ARITH_INTERVAL : PROTO_ARITH_AFFINE,
            .cache_bytes = o->cache_bytes,
            .instruction_budget = o->instruction_budget,
            .n_layers = o->n_layers,
            .layers = (const char *const *)o->layers,
            .n_extra = nx,
            .extra = x,
            .frame = o->frame,
        };
    }
    return true;
}

bool proto_msg_view(const Aafarm__Envelope *env, proto_msg *msg, void **block)
{
    memset(msg, 0, sizeof *msg);
    *block = NULL;
    msg->kind = (proto_kind)env->body_case;
    switch (env->body_case) {
    case AAFARM__ENVELOPE__BODY_HELLO: {
        const Aafarm__Hello *b = env->hello;
        msg->hello = (proto_hello){b->protocol_version, b->worker_name, b->host, b->pid,
                                   b->threads, b->n_jobs_held,
                                   (const char *const *)b->jobs_held, b->software, b->pool};
        break;
    }
    case AAFARM__ENVELOPE__BODY_WELCOME: {
        const Aafarm__Welcome *b = env->welcome;
        msg->welcome = (proto_welcome){b->protocol_version, b->master_name, b->master_session,
                                       b->heartbeat_ms, b->heartbeat_liveness};
        break;
    }
    case AAFARM__ENVELOPE__BODY_REJECT:
        msg->reject = (proto_reject){(proto_reject_code)env->reject->code, env->reject->reason,
                                     env->reject->protocol_version};
        break;
    case AAFARM__ENVELOPE__BODY_ASK: msg->ask.credits = env->ask->credits; break;
    case AAFARM__ENVELOPE__BODY_JOB: return job_view(env->job, &msg->job, block);
    case AAFARM__ENVELOPE__BODY_NEED_JOB:
        msg->need_job = (proto_need_job){env->need_job->job_hash, env->need_job->lease_id};
        break;
    case AAFARM__ENVELOPE__BODY_GRANT: {
        const Aafarm__Grant *b = env->grant;
        msg->grant = (proto_grant){b->job_hash, b->lease_id, b->tile_index, {0, 0, 0, 0},
                                   b->deadline_ms};
        if (b->tile)
            msg->grant.tile = (proto_rect){b->tile->x, b->tile->y, b->tile->width,
                                           b->tile->height};
        break;
    }
    case AAFARM__ENVELOPE__BODY_RESULT: {
        const Aafarm__Result *b = env->result;
        msg->result = (proto_result){.job_hash = b->job_hash, .lease_id = b->lease_id,
                                     .tile_index = b->tile_index, .exr_bytes = b->exr_bytes};
        const Aafarm__TileStats *s = b->stats;
        if (s)
            msg->result.stats = (proto_tile_stats){
                s->rays, s->boxes, s->shader_evals, s->cache_hits, s->cache_misses,
                s->cache_evictions, s->peak_cache_bytes, s->cpu_seconds, s->wall_seconds,
                s->nonfinite_samples};
        break;
    }
    case AAFARM__ENVELOPE__BODY_FAILURE: {
        const Aafarm__Failure *b = env->failure;
        msg->failure = (proto_failure){b->job_hash, b->lease_id, b->tile_index, b->message,
                                       b->retryable};
        break;
    }
    case AAFARM__ENVELOPE__BODY_HEARTBEAT:
        msg->heartbeat = (proto_heartbeat){env->heartbeat->n_leases, env->heartbeat->leases};
        break;
    case AAFARM__ENVELOPE__BODY_JOB_DONE:
        msg->job_done = (proto_job_done){env->job_done->job_hash,
                                         (proto_job_status)env->job_done->status,
                                         env->job_done->message};
        break;
    case AAFARM__ENVELOPE__BODY_SHUTDOWN: msg->shutdown.reason = env->shutdown->reason; break;
    case AAFARM__ENVELOPE__BODY_NEED_FILE: {
        const Aafarm__NeedFile *b = env->need_file;
        msg->need_file = (proto_need_file){b->job_hash, b->sha256, b->offset, b->length,
                                           b->received};
        break;
    }
    case AAFARM__ENVELOPE__BODY_FILE_CHUNK: {
        const Aafarm__FileChunk *b = env->file_chunk;
        msg->file_chunk = (proto_file_chunk){b->sha256, b->offset, b->file_size, b->length};
        break;
    }
    case AAFARM__ENVELOPE__BODY_FILES_READY: {
        const Aafarm__FilesReady *b = env->files_ready;
        msg->files_ready = (proto_files_ready){b->job_hash, b->hits, b->misses, b->fetched_bytes};
        break;
    }
    default: break;
    }
    return true;
}

/* ---------------------------------------------------------------------- */
/* the saved Job                                                           */
/* ---------------------------------------------------------------------- */

/* A deep copy in one block: the structs, then the arrays, then the bytes
 * of every string and text. Laid out twice: once to measure (base NULL),
 * once to fill. */
struct proto_saved_job {
    proto_job job;
};

typedef struct layout {
    char *base;    /* NULL: measuring */
    size_t used;
} layout;

static void *take(layout *l, size_t bytes, size_t align)
{
    l->used = (l->used + align - 1) / align * align;
    void *p = l->base ? l->base + l->used : NULL;
    l->used += bytes;
    return p;
}

static const char *copy_str(layout *l, const char *s)
{
    size_t n = strlen(s ? s : "") + 1;
    char *p = take(l, n, 1);
    if (p) memcpy(p, s ? s : "", n);
    return p;
}

static const uint8_t *copy_bytes(layout *l, const uint8_t *b, size_t n)
{
    uint8_t *p = take(l, n ? n : 1, 1);
    if (p && n) memcpy(p, b, n);
    return p;
}

#define TAKE_ARRAY(l, type, n) ((type *)take((l), (n) * sizeof(type), _Alignof(type)))

static void copy_job(layout *l, const proto_job *m, proto_job *d)
{
    const proto_render_options *o = &m->options;
    proto_source *src = TAKE_ARRAY(l, proto_source, m->n_sources);
    proto_shader_binding *sh = TAKE_ARRAY(l, proto_shader_binding, m->n_shaders);
    proto_file_ref *f = TAKE_ARRAY(l, proto_file_ref, m->n_files);
    proto_option *x = TAKE_ARRAY(l, proto_option, o->n_extra);
    const char **layers = TAKE_ARRAY(l, const char *, o->n_layers);
    bool fill = l->base != NULL;
    const char *hash = copy_str(l, m->job_hash), *scene = copy_str(l, m->scene_name);
    const uint8_t *text = copy_bytes(l, m->scene_text, m->scene_len);
    for (size_t i = 0; i < m->n_sources; i++) {
        proto_source s = {copy_str(l, m->sources[i].name),
                          copy_bytes(l, m->sources[i].text, m->sources[i].text_len),
                          m->sources[i].text_len};
        if (fill) src[i] = s;
    }
    for (size_t i = 0; i < m->n_shaders; i++) {
        proto_shader_binding b = {copy_str(l, m->shaders[i].name),
                                  copy_str(l, m->shaders[i].source)};
        if (fill) sh[i] = b;
    }
    for (size_t i = 0; i < m->n_files; i++) {
        proto_file_ref r = {copy_str(l, m->files[i].name), copy_str(l, m->files[i].sha256),
                            m->files[i].size};
        if (fill) f[i] = r;
    }
    for (size_t i = 0; i < o->n_extra; i++) {
        proto_option e = {copy_str(l, o->extra[i].key), copy_str(l, o->extra[i].value)};
        if (fill) x[i] = e;
    }
    for (size_t i = 0; i < o->n_layers; i++) {
        const char *s = copy_str(l, o->layers[i]);
        if (fill) layers[i] = s;
    }
    if (!fill) return;
    *d = *m;
    d->job_hash = hash;
    d->scene_name = scene;
    d->scene_text = text;
    d->sources = src;
    d->shaders = sh;
    d->files = f;
    d->options.extra = x;
    d->options.layers = layers;
}

proto_saved_job *proto_saved_job_new(const proto_job *job)
{
    layout l = {NULL, sizeof(proto_saved_job)};
    copy_job(&l, job, NULL);
    proto_saved_job *self = xmalloc(l.used);
    l = (layout){(char *)self, sizeof(proto_saved_job)};
    copy_job(&l, job, &self->job);
    return self;
}

const proto_job *proto_saved_job_get(const proto_saved_job *self)
{
    return &self->job;
}

void proto_saved_job_destroy(proto_saved_job **self_p)
{
    free(*self_p);
    *self_p = NULL;
}
