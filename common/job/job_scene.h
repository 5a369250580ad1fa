/*
 * job_scene.h: a job made ready to render: the parsed scene, its compiled
 * shader programs and instances (one per Surface / Displacement call, with
 * the RIB's parameter values), the renderer's camera-space world built
 * from them, and the prepared renderer (root boxes, BVH).
 *
 * A worker builds one per job and keeps it across tiles; the master builds
 * one without the renderer, only to check the job before sending it.
 */
#ifndef JOB_JOB_SCENE_H
#define JOB_JOB_SCENE_H

#include "job/job.h"
#include "scene/scene.h"
#include "tex/tex.h"
#include "trace/render.h"

typedef struct job_scene {
    const job *job;
    scene *scene;
    sl_program **programs;         /* per job shader (job->shaders order) */
    sl_instance **instances;       /* per scene shader call (scene->shaders) */
    trace_world world;
    trace_renderer *renderer;      /* NULL when built with render = false */
    tex_cache *textures;           /* the textures the shaders read (world.textures) */
    trace_primvar *primvars;       /* every object's primitive variables (world.objects[].primvars) */
    trace_mesh *meshes;            /* the mesh objects' sources (world.objects[].mesh) */
    int nmeshes;
    struct job_group *groups;      /* the instances kept as references
                                      (world.objects[].group, job_scene.c) */
    int ngroups;
} job_scene;

/* cache_bytes: this worker's box cache budget per thread (0: unlimited);
 * the displaced meshes' root boxes, shared by the threads, get as much
 * again per thread (trace_options.roots_bytes).
 * render: also prepare the renderer (root boxes and BVH). cancel: the
 * program's stop flag (trace_options.cancel) or NULL. NULL on errors
 * (in diag; "interrupted" when cancel was set). The job must outlive the
 * job_scene. */
job_scene *job_scene_new(const job *job, size_t cache_bytes, bool render,
                         const atomic_int *cancel, sl_diag *diag);
/* The same, the scene's polygon meshes parsed (scene_parse_frame_threads)
 * and the renderer's world built with `threads` threads (the root
 * boxes of displaced meshes' pieces, trace_options.build_threads): a
 * worker passes its rendering threads. The scene is the same for any. */
job_scene *job_scene_new_threads(const job *job, size_t cache_bytes, bool render, int threads,
                                 const atomic_int *cancel, sl_diag *diag);
/* The master's check of a job whose scene it has parsed with
 * job_scene_checker (scene_check_frame: no mesh arrays, references
 * checked and dropped): the scene is taken (destroyed with the result, or
 * on errors); compiles, binds, builds the check's world and checks it as
 * job_scene_new(render = false) does. */
job_scene *job_scene_check(const job *job, scene *sc, const atomic_int *cancel, sl_diag *diag);

/* What job_scene_check's parse hands the scene parser: the renderer's
 * test of a reference's transforms (trace_object_derive), made for each
 * placement as it is read. */
const scene_check *job_scene_checker(void);

void job_scene_destroy(job_scene **self_p);

#endif
