/*
 * corpus.h: the shader corpus of issue 9 (tests/shaders/corpus) as the
 * corpus tests see it: every shader and header read from disk, the six
 * test surfaces (plane, sphere, ellipsoid, cylinder, bilinear patch, mesh
 * of triangles, Catmull-Clark subdivision surfaces, a rational NuPatch,
 * and two of bases with singular points: apexes, collapsed edges)
 * as RIB text, an in-memory job of one shader on one
 * surface, and a small deterministic random generator.
 */
#ifndef TESTS_CORPUS_CORPUS_H
#define TESTS_CORPUS_CORPUS_H

#include <stdbool.h>
#include <stdint.h>

#include "fixture.h"

typedef struct corpus_file {
    char name[64];           /* "bricks" (a shader) or "include/noises.h" */
    char *text;
} corpus_file;

typedef struct corpus {
    corpus_file *shaders;    /* sorted by name; shader name = file name */
    int nshaders;
    corpus_file *headers;    /* include/<x>.h */
    int nheaders;
    char texdir[64];         /* the maps the texture shaders read (written by
                                corpus_load, removed by corpus_free) */
} corpus;

/* Reads AAFARM_CORPUS_DIR (compile-time path of tests/shaders/corpus).
 * AAFARM_CORPUS_ONLY=name1,name2 keeps only those shaders. Writes the maps
 * of the tex_* shaders into a temporary folder that every job's texture
 * search path names: corpus_height.exr (96 x 64 periodic fBm, one channel)
 * and corpus_rgb.exr (24 x 16, three channels of random texels). */
bool corpus_load(corpus *c);
void corpus_free(corpus *c);
/* The two as a cmocka group's setup and teardown return them (0, or -1
 * when the corpus cannot be read); the group state is not used. */
int corpus_group_load(corpus *c, void **state);
int corpus_group_free(corpus *c, void **state);

typedef enum corpus_surface {
    CORPUS_PLANE, CORPUS_SPHERE, CORPUS_ELLIPSOID, CORPUS_CYLINDER,
    CORPUS_PATCH, CORPUS_MESH, CORPUS_SUBDIV, CORPUS_NURBS,
    CORPUS_APEX,             /* a disk, a cone (scaled unevenly) and a paraboloid
                              * whose centre and apexes have Ng = 0 */
    CORPUS_COLLAPSED,        /* patches with a collapsed edge (bilinear,
                              * bicubic) and a hyperboloid from the axis */
    CORPUS_NSURFACES
} corpus_surface;

const char *corpus_surface_name(corpus_surface s);

/* The job of shader `sh` displacing surface `s` (camera at the origin
 * looking down +z, object about 5 units away, 1 unit in size), a
 * `xres` x `yres` image, bounding arithmetic `arith`; render: also
 * prepare the renderer (root boxes, BVH). Prints diagnostics and returns
 * false on failure. */
bool corpus_open(fixture *f, const corpus *c, const corpus_file *sh,
                 corpus_surface s, trace_arith arith, int xres, int yres, bool render);

/* The same for a world of one's own: `world` is the RIB between
 * WorldBegin and WorldEnd (inside an AttributeBegin, after the texture
 * search path, Format and Projection corpus_open gives every job); `what`
 * names it in messages. The shader is not bound: `world` says where. */
bool corpus_open_world(fixture *f, const corpus *c, const corpus_file *sh, const char *what,
                       const char *world, trace_arith arith, int xres, int yres, bool render);

/* Environment integer with a default (values < 1 give the default). */
long corpus_env_long(const char *name, long def);

/* splitmix64 */
typedef struct corpus_rng { uint64_t s; } corpus_rng;
double corpus_rng_uniform(corpus_rng *r);    /* [0, 1) */

#endif
