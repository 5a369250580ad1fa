/*
 * fixture.h: test helpers for the renderer: a job built in memory from RIB
 * text and shader sources (no files), made ready to render.
 */
#ifndef TESTS_TRACE_FIXTURE_H
#define TESTS_TRACE_FIXTURE_H

#include "job/job.h"
#include "job/job_scene.h"

typedef struct fixture_shader {
    const char *name;      /* "constd" (its source is named "<name>.sl") */
    const char *source;
} fixture_shader;

typedef struct fixture {
    job *job;
    job_scene *js;
    sl_diag *diag;
} fixture;

/* Builds the job and its scene with the given options (NULL: defaults) and
 * cache budget. On failure prints the diagnostics and returns false
 * (f->js NULL; f->diag keeps them for tests of error messages). */
bool fixture_open(fixture *f, const char *rib, const fixture_shader *shaders,
                  int nshaders, const job_options *opt, size_t cache_bytes);
/* fixture_open with one shader, `name` from `source`, on the RIB that
 * rib_format gives with its one %s replaced by the shader's name (defaults,
 * default cache) */
bool fixture_open_named(fixture *f, const char *rib_format, const char *name,
                        const char *source);
void fixture_close(fixture *f);

/* The surfaces of the world that use their prototype's boxes: objects
 * with a box_proto, and the placements of groups that are their
 * prototype moved (trace/group.h) */
int fixture_count_shared(const trace_world *w);

/* Renders the whole image into rgba (4 per px) and z with tiles of `tile`
 * pixels, each tile on one of `nthreads` trace_threads in turn (round
 * robin, so threads see tiles in different orders than a single one).
 * cache_bytes overrides the world's budget for these threads. */
bool fixture_render(fixture *f, int tile, int nthreads, size_t cache_bytes,
                    float *rgba, float *z);

/* The RIB text (malloc'd) of a closed torus (radii 1 and 0.4) of nu x nv
 * quads sharing their points, 32 x 32 pixels: `head` (RIB text after
 * WorldBegin, may be "") and then the mesh as `request` ("PointsPolygons"
 * or "SubdivisionMesh \"catmull-clark\""). */
char *fixture_torus_rib(int nu, int nv, const char *head, const char *request);

/* The RIB text (malloc'd) of n instances of one definition (`definition`:
 * its RIB text, inside ObjectBegin 1) on a square grid seen from the
 * front, 16 x 16 pixels, each moved and turned differently (rigid
 * motions), under one Surface "plastic" and Displacement `shader` with
 * "float Km" [km]. */
char *fixture_instances_rib(int n, const char *definition, const char *shader, double km);

/* Bytes the allocator holds (glibc's mallinfo2; 0 under ASan, whose
 * allocator it does not see: byte budgets are checked only where it
 * reads more) */
size_t fixture_heap_bytes(void);

#endif
