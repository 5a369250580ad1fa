/*
 * job_proto.c: a Job message back into a job (job_proto.h).
 */
#include "job_proto.h"

#include <limits.h>
#include <string.h>

#include "util/err.h"

static job_options options_of(const proto_render_options *o)
{
    job_options jo;
    job_options_default(&jo);
    jo.arith = o->arithmetic == PROTO_ARITH_INTERVAL ? TRACE_ARITH_INTERVAL : TRACE_ARITH_AFFINE;
    jo.tile_size = (int)o->tile_size;
    if (o->instruction_budget)
        jo.max_instructions = o->instruction_budget > (uint64_t)LONG_MAX ? LONG_MAX
                                                                          : (long)o->instruction_budget;
    /* an index no scene can have is refused by job_finish */
    jo.frame = o->frame > (uint32_t)INT_MAX / 2 ? -1 : (int)o->frame;
    return jo;
}

job *job_from_proto(const proto_job *m, char *err, size_t errsz)
{
    job_options jo = options_of(&m->options);
    job *jb = job_new(m->scene_name, (const char *)m->scene_text, m->scene_len, &jo);
    bool ok = true;
    for (size_t i = 0; ok && i < m->n_sources; i++)
        ok = job_add_source(jb, m->sources[i].name, (const char *)m->sources[i].text,
                            m->sources[i].text_len, err, errsz);
    for (size_t i = 0; ok && i < m->n_shaders; i++)
        ok = job_add_shader(jb, m->shaders[i].name, m->shaders[i].source, err, errsz);
    for (size_t i = 0; ok && i < m->n_files; i++)
        ok = job_add_file(jb, m->files[i].name, m->files[i].sha256, m->files[i].size, err, errsz);
    jb->files_known = true;                 /* the sender's list, even when empty */
    if (ok) ok = job_finish(jb, err, errsz);
    if (ok && strcmp(jb->hash, m->job_hash) != 0)
        ok = err_set(err, errsz, "its content hashes to %.12s... here, the message says "
                     "%.12s... (the sender and this program run different aafarm versions?)",
                     jb->hash, m->job_hash);
    if (!ok) job_destroy(&jb);
    return jb;
}
