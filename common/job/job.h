/*
 * job.h: a render job, the small thing that travels (DESIGN.md §2): the
 * scene text, the sources of every shader it uses (and of their
 * #includes), and the options that decide pixels. Identified by a content
 * hash, so a worker that holds a job is not sent it again.
 *
 *   job_load       the master / standalone side: read a RIB file, find its
 *                  shaders on the scene's search path (then among the built-in
 *                  standard shaders, sl/standard.h), load them, check
 *                  everything compiles (fail fast, file:line:col), hash
 *   job_new + job_add_*   the worker side: rebuild the job from the
 *                  message fields, then job_finish computes the hash
 *   job_scene_new  parse + compile + build the renderer's world: what a
 *                  worker renders tiles with (job_scene.h)
 *
 * Files (textures): a job names the data files its shaders read (name,
 * SHA-256, size), not their bytes. job_load finds them (job_files.c); the
 * master ships them to each host once, a worker keeps them in its
 * content-addressed store (docs/textures.md, "The wire and the cache").
 * The hashes are part of the job hash, so a file changed on the master's
 * disk makes a new job and a stale copy is never used. job_file_resolve
 * turns a name into the local path (the texture module's resolver).
 *
 * Archives (ReadArchive, plain or gzip) are files of the job too, named
 * JOB_ARCHIVE_PREFIX + the archive's normalized path ("archive:parts/
 * obj.rib.gz"), hashed as they lie on disk (compressed). job_load adds
 * them while it parses; every parse of the job reads their texts from the
 * files' local paths, gunzipping them (job_archive.c). So the Job message
 * carries the top-level RIB and the shader sources only, and an archive
 * (up to SCENE_ARCHIVE_MAX_BYTES uncompressed) reaches each host once.
 *
 * Options that change pixels (arithmetic, shader budget, tile size: the
 * tile grid of the output file) are part of the job and of its hash; per
 * worker settings (threads, cache budget) are not: they change speed only.
 */
#ifndef JOB_JOB_H
#define JOB_JOB_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

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

/* The limits of the options that decide pixels, the same on every
 * program's command line (--tile, --budget). */
#define JOB_TILE_SIZE_MIN 1
#define JOB_TILE_SIZE_MAX 1024
#define JOB_BUDGET_MIN 1000L
#define JOB_BUDGET_MAX 1000000000L

/* One of the command-line options every program that makes a job takes:
 * opt "--tile" (a size), "--arith" (affine|interval) or "--budget" (a
 * number), its value text into *self. False with the message "OPT wants
 * ..., got 'TEXT'" in err (the program prefixes its name). */
bool job_options_parse_arg(job_options *self, const char *opt, const char *text, char *err,
                           size_t errsz);

/* The name prefix of the job files that are archives (see above). */
#define JOB_ARCHIVE_PREFIX "archive:"

typedef struct job_shader {
    char *name;                    /* as the RIB names it: "wave" */
    char *file;                    /* its main source in job.sources */
} job_shader;

typedef struct job_file {
    char *name;                    /* as the shader or the RIB writes it: "height.exr" */
    char sha256[HASH_HEX_SIZE];    /* of its content (64 hex digits) */
    uint64_t size;                 /* bytes */
    char *path;                    /* the local copy: on the master's disk, or in a
                                      worker's store; NULL while not present */
    /* job_load: what stat said of `path` when its bytes were hashed (device,
     * inode, size, mtime in ns); the master re-hashes a file it serves only
     * when that changed. stamped false elsewhere. */
    bool stamped;
    uint64_t dev, ino;
    int64_t mtime_ns;
} job_file;

typedef struct job {
    char *scene_file;              /* name of the RIB (for messages) */
    char *scene_text;
    size_t scene_len;
    sl_source_set *sources;        /* every shader source the job needs */
    job_shader *shaders;
    int nshaders;
    job_options options;
    job_file *files;               /* the data files its shaders read and the
                                      archives its scene reads, by name */
    int nfiles;
    bool files_known;              /* files is the whole list (job_load collected
                                      it, or a master sent it): textures come
                                      only from there. false (a job built in
                                      memory, as tests do): from the scene's
                                      texture search path on disk */
    char hash[HASH_HEX_SIZE];      /* set by job_finish / job_load */
    /* set by job_load from the scene, for naming outputs (not hashed) */
    int frame_number;              /* the frame's FrameBegin number (1 without) */
    int nframes;                   /* FrameBegin blocks in the file (0: none) */
    int *frame_numbers;            /* their numbers, in order */
    char *display_name;            /* the frame's Display name, or NULL */
    int xres, yres;                /* the frame's Format */
} job;

/* Reads and checks the RIB at rib_path and everything it needs. NULL when
 * anything is wrong; diag holds the errors. cancel: the program's stop
 * flag (a signal) or NULL: parsing, compiling and building the world look
 * at it, and a load that finds it set fails with "interrupted". */
job *job_load(const char *rib_path, const job_options *options, const atomic_int *cancel,
              sl_diag *diag);

/* The RIB at rib_path (at most 64 MiB), malloc'd; NULL with an error. */
char *job_read_scene(const char *rib_path, size_t *len, sl_diag *diag);

job *job_new(const char *scene_file, const char *scene_text, size_t scene_len,
             const job_options *options);
/* Adds a shader source (name, text) / a shader (RIB name -> main source).
 * Return false on a duplicate or invalid entry, with a reason in err. */
bool job_add_source(job *self, const char *name, const char *text, size_t len,
                    char *err, size_t errsz);
bool job_add_shader(job *self, const char *name, const char *file,
                    char *err, size_t errsz);
/* Adds a file (name, SHA-256 as 64 lowercase hex digits, size) without a
 * local path. False on an empty or duplicate name or a bad hash. */
bool job_add_file(job *self, const char *name, const char *hex, uint64_t size,
                  char *err, size_t errsz);
/* The file named `name`, or NULL. */
job_file *job_file_find(const job *self, const char *name);
/* Sets (a copy of) the local path of file i (NULL: not present). */
void job_file_set_path(job *self, int i, const char *path);
/* Sum of the files' sizes. */
uint64_t job_files_bytes(const job *self);

/* The resolver the texture module opens files through: true and the local
 * path of the job's file `name` in path[0..path_size), or false and the reason
 * (not one of the job's files, not present here, the path too long).
 * `job` is a const job *. */
bool job_file_resolve(void *job, const char *name, char *path, size_t path_size, char *err,
                      size_t errsz);

/* The same lookup job_collect_files makes, for a name on the texture search
 * path of `scene` (a const scene *), before the job's files are collected:
 * the path found on disk, or false and the reason in err. */
bool job_texture_path_resolve(void *scene, const char *name, char *path, size_t path_size,
                              char *err, size_t errsz);

/* Collects the job's files (job_files.c): every string constant of the
 * compiled programs and every string parameter of the scene's shader calls
 * that names a regular file on the scene's texture search path is hashed
 * and added with its path on disk. False (errors in diag) when such a file
 * cannot be read. */
struct job_scene;
bool job_collect_files(job *self, const struct job_scene *js, sl_diag *diag);

/* Computes the hash; false if the job is inconsistent (err says so). */
bool job_finish(job *self, char *err, size_t errsz);
void job_destroy(job **self_p);

/* The main source of shader `name`, or NULL. */
const char *job_shader_file(const job *self, const char *name);

const char *trace_arith_name(trace_arith arith);       /* "affine" */
bool trace_arith_parse(const char *text, trace_arith *out);

#endif
