/*
 * job.h: a render job, the small thing that travels (DESIGN.md §2): the
 * scene text, the sources of every shader it uses (and of their
 * #includes), and the options that decide pixels. Identified by a content
 * hash, so a worker that holds a job is not sent it again.
 *
 *   job_load       the master / standalone side: read a RIB file, find its
 *                  shaders on the scene's search path, load them, check
 *                  everything compiles (fail fast, file:line:col), hash
 *   job_new + job_add_*   the worker side: rebuild the job from the
 *                  message fields, then job_finish computes the hash
 *   job_scene_new  parse + compile + build the renderer's world: what a
 *                  worker renders tiles with (job_scene.h)
 *
 * Options that change pixels (arithmetic, shader budget, tile size: the
 * tile grid of the output file) are part of the job and of its hash; per
 * worker settings (threads, cache budget) are not: they change speed only.
 */
#ifndef JOB_JOB_H
#define JOB_JOB_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"
#include "sl/source.h"
#include "trace/world.h"
#include "util/hash.h"

typedef struct job_options {
    trace_arith arith;             /* bounding arithmetic (default affine) */
    int tile_size;                 /* pixels (default 32) */
    long max_instructions;         /* shader budget per evaluation (default 1e6) */
    int frame;                     /* which FrameBegin block (0: the first, or
                                      the whole file without frames); in the
                                      hash when not 0 (docs/protocol.md) */
} job_options;

void job_options_default(job_options *opt);

typedef struct job_shader {
    char *name;                    /* as the RIB names it: "wave" */
    char *file;                    /* its main source in job.sources */
} job_shader;

typedef struct job {
    char *scene_file;              /* name of the RIB (for messages) */
    char *scene_text;
    size_t scene_len;
    sl_source_set *sources;        /* every shader source the job needs */
    job_shader *shaders;
    int nshaders;
    job_options options;
    char hash[HASH_HEX_SIZE];      /* set by job_finish / job_load */
    /* set by job_load from the scene, for naming outputs (not hashed) */
    int frame_number;              /* the frame's FrameBegin number (1 without) */
    int nframes;                   /* FrameBegin blocks in the file (0: none) */
    int *frame_numbers;            /* their numbers, in order */
    char *display_name;            /* the frame's Display name, or NULL */
    int xres, yres;                /* the frame's Format */
} job;

/* Reads and checks the RIB at rib_path and everything it needs. NULL when
 * anything is wrong; diag holds the errors. */
job *job_load(const char *rib_path, const job_options *options, sl_diag *diag);

/* The RIB at rib_path (at most 64 MiB), malloc'd; NULL with an error. */
char *job_read_scene(const char *rib_path, size_t *len, sl_diag *diag);

job *job_new(const char *scene_file, const char *scene_text, size_t scene_len,
             const job_options *options);
/* Adds a shader source (name, text) / a shader (RIB name -> main source).
 * Return false on a duplicate or invalid entry, with a reason in why. */
bool job_add_source(job *self, const char *name, const char *text, size_t len,
                    char *why, int why_size);
bool job_add_shader(job *self, const char *name, const char *file,
                    char *why, int why_size);
/* Computes the hash; false if the job is inconsistent (why says so). */
bool job_finish(job *self, char *why, int why_size);
void job_destroy(job **self_p);

/* The main source of shader `name`, or NULL. */
const char *job_shader_file(const job *self, const char *name);

const char *trace_arith_name(trace_arith arith);       /* "affine" */
bool trace_arith_parse(const char *text, trace_arith *out);

#endif
