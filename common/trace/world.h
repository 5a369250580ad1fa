/*
 * world.h: the renderer's view of a scene, everything in CAMERA space
 * (RenderMan's "current" space, so shaders see the values they expect):
 * the camera, the objects (base surface + transforms + shader instances +
 * their camera-space root box), the lights, and the render options.
 *
 * The RIB parser (common/scene) produces a scene model in RIB terms; the
 * adapter in render_setup.c turns it into a trace_world. Everything here is
 * read-only while rendering and shared by all threads; the per-thread
 * mutable state (VM, box cache, statistics) lives in trace_thread
 * (render.h).
 */
#ifndef TRACE_WORLD_H
#define TRACE_WORLD_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stddef.h>

#include "geom/surface.h"
#include "sl/shader.h"
#include "trace/box.h"
#include "util/vecmath.h"

typedef enum trace_arith { TRACE_ARITH_AFFINE, TRACE_ARITH_INTERVAL } trace_arith;

/* A primitive variable of an object (docs/scenes.md "Primitive
 * variables"), in camera space: per component k, the polynomial sum
 * c[i + 4 j][k] u^i v^j over the object's (u,v). It sets a global (s,
 * t, Cs, Os) and the shaders' parameters of its name (trace/primvar.c). */
typedef struct trace_primvar {
    sl_global global;              /* SL_G_s, SL_G_t, SL_G_Cs, SL_G_Os; SL_G__COUNT: none */
    int displacement_param;        /* its index in the displacement program, -1: none */
    int surface_param;             /* ... in the surface program, -1: none */
    int size;                      /* 1 or 3 */
    double c[16][3];
} trace_primvar;

/* The most primitive variables a surface hands to its shaders (RIB's
 * RIB_MAX_PRIMVARS: "st" counts two). */
enum { TRACE_MAX_PRIMVARS = 16 };

struct trace_object;
struct trace_mesh_bvh;

/* A mesh (issue 23, trace/mesh.h): ONE world object that stands for many
 * pieces (the faces of a PointsPolygons, or triangles of them), kept by
 * whoever built the world as a source of pieces and made into a full
 * trace_object (a "view") only where a ray reaches the piece. Its boxes
 * and BVH are in the mesh's OBJECT space, so the objects that place one
 * undisplaced mesh (instances) may share one trace_mesh: a displaced one
 * has a trace_mesh per object (its boxes run its shader in that object's
 * camera space). */
typedef struct trace_mesh {
    int npieces;
    int nprimvars;                 /* each piece's primitive variables */
    /* Piece k of the mesh object obj: its object-space surface (prepared)
     * and, when pv is not NULL, its primitive variables in camera space
     * (*npv of them, at most nprimvars; as trace_primvar, with obj's
     * shaders' parameters); false if the piece cannot be made (never for a
     * piece of a parsed mesh). A pure function, called from any thread. */
    bool (*piece)(const void *user, const struct trace_object *obj, int k, geom_surface *s,
                  trace_primvar *pv, int *npv);
    /* Optional (NULL: piece): piece k's outline, what the world's pass
     * over the pieces reads for their bounds and shared edges: a polygon's
     * corners and plane basis (geom_polygon_basis: origin, axes, normal,
     * nuv and uv the same bits as piece gives them), any other kind's
     * surface as piece makes it; for an undisplaced mesh. A pure
     * function, called from any thread. */
    bool (*outline)(const void *user, int k, geom_surface *s);
    const void *user;
    /* derived: trace_world_prepare, trace_renderer_new (trace_mesh_clear
     * frees them) */
    int first_id;                  /* piece k's object id is first_id + k (-1:
                                      not given yet); shared by the objects
                                      that share the mesh */
    uint8_t *shared_edges;         /* per piece, bits 0-7 of its
                                      trace_object.shared_edges (the first
                                      placing object's transform) */
    struct trace_mesh_edges *wide; /* and its bits 8-63 (polygons of more
                                      than 8 corners), by piece, nwide */
    int nwide;
    float (*bounds)[6];            /* per piece: object-space box (lo, hi),
                                      rounded outward (displaced: undisplaced,
                                      over its (u,v) square: mesh.c adds its
                                      region's shift); freed once the BVH
                                      (which keeps them in 6 bytes each) is
                                      built */
    struct trace_lazy_roots *lazy; /* displaced: the pieces' root boxes and
                                      du/dv, made when a ray first reaches
                                      them (mesh.c) */
    struct trace_mesh_bvh *bvh;    /* over the pieces' bounds */
} trace_mesh;

/* Instances kept as references (issue 23, trace/group.h): the objects
 * that place one recorded surface or mesh again with the prototype's
 * shaders, each only a transform and a colour in the scene; ONE world
 * object (a "group") stands for them, a BVH over their camera-space
 * boxes, and a placement becomes a full trace_object (a view) only where
 * a ray reaches it. A displaced surface's or mesh's placement is its
 * prototype's displaced surface moved rigidly (box_proto) where that is
 * the surface its own shader gives (trace/instance.c), else a surface of
 * its own with its own boxes (a displaced mesh's: a trace_mesh of its
 * own, own_meshes). */
typedef struct trace_group {
    int n;                         /* placements */
    int proto;                     /* the prototype: its index in world.objects
                                      (placement k is it moved) */
    /* Placement k's transforms (object <-> camera space), as given by the
     * scene; a pure function, called from any thread. */
    void (*transform)(const void *user, int k, mat4 *to_camera, mat4 *from_camera);
    /* Placement k as a full object into *out, a copy of the prototype with
     * the transforms set: the rest that differs (its shaders' spaces,
     * colour, orientation, primitive variables into pv); false if it
     * cannot be made (never for a parsed scene). A pure function. */
    bool (*place)(const void *user, int k, struct trace_object *out, trace_primvar *pv);
    const void *user;
    /* derived (trace_world_prepare, trace_renderer_new; trace_group_clear
     * frees them) */
    int first;                     /* placement k's number in the world: first + k */
    struct trace_mesh_bvh *bvh;    /* over the placements' camera-space boxes */
    /* a displaced prototype's placements (else own = NULL): own[k] < 0:
     * placement k is the prototype moved (its boxes are the
     * prototype's), else its root box is own_roots[own[k]] and its boxes
     * are its own. A displaced surface's placement k has the id
     * first_id + k (its own cell caches: its points are in its camera
     * space); a displaced mesh's placements have none (first_id = -1): a
     * moved one is intersected as its prototype, the ray moved into the
     * prototype's camera space (group.c), and an own one has the pieces,
     * ids and boxes of own_meshes[own[k]], a mesh of its own over the
     * prototype's pieces (trace_group_classify_meshes) */
    int first_id;
    int32_t *own;
    trace_box *own_roots;
    int nown;
    trace_mesh *own_meshes;
    float (*proto_bounds)[6];      /* a displaced mesh's: its pieces' undisplaced
                                      boxes, until the own meshes are built */
} trace_group;

typedef struct trace_object {
    int id;                        /* index in trace_world.objects; a mesh
                                      piece's view: its mesh's first_id + k,
                                      so caches tell pieces apart */
    int top;                       /* index in trace_world.objects (the mesh
                                      object of a piece's view) */
    trace_mesh *mesh;              /* a mesh object (its surf, primvars and
                                      root are unused); NULL: one surface
                                      (and a piece's view) */
    trace_group *group;            /* a group of placements (nothing else of the
                                      object is used but its bound); NULL: none */
    int place;                     /* a placement's view (or a piece of one): its
                                      number in the world + 1; 0: not one. The
                                      views of two placements share their ids
                                      (the same object-space surface) */
    char name[64];                 /* for messages: "sphere at ufo.rib:12" */
    geom_surface surf;
    mat4 to_camera, from_camera;   /* object space <-> camera space */
    sl_spaces displacement_spaces; /* named spaces for each shader: "shader" */
    sl_spaces surface_spaces;      /* space is where its RIB call was made */
    const sl_instance *displacement;   /* NULL: no displacement */
    const sl_instance *surface;        /* NULL: the default surface */
    double Cs[3], Os[3];
    int sides;                     /* 1 or 2 */
    const int *lights;             /* indices into trace_world.lights that */
    int nlights;                   /* shine on this object (Illuminate, scopes) */
    bool flip;                     /* reversed orientation: negate normals */
    double scale;                  /* largest stretch of to_camera (spectral norm) */
    double normal_scale;           /* to_camera a similarity: |camera N| of a unit
                                      object normal is 1/normal_scale; else 0 */
    double normal_len2[2];         /* bounds of |from_camera^T n|^2, n unit */
    double du, dv;                 /* the shader globals du, dv: per-object
                                      constants (render.c, docs/renderer.md) */
    uint64_t shared_edges;         /* polygons: bit i, edge i (geom_polygon_edge)
                                      is also another polygon's (world.c) */
    bool box_skip_tangents;        /* the displacement shader never names dPdu,
                                      dPdv nor takes derivatives: boxes need
                                      not transform the tangents (world.c) */
    bool box_runs_skip_tangents;   /* its affine box runs read neither dPdu,
                                      dPdv nor the derivative bounds of P and
                                      I (sl_program_box_reads: a height map's
                                      calculatenormal alone did): the affine
                                      boxes leave them out (displace.c) */
    bool bend_unknown;             /* its displacement reads a texture: a
                                      lookup over several texels is a bound,
                                      so its boxes' bend says nothing of the
                                      surface's: hit proofs are tried on
                                      cells of any bend (intersect.c,
                                      TRACE_PROVE_BEND), and leaves start at
                                      their centre (intersect.c, leaf_start) */
    trace_box root;                /* OBJECT space box over the whole (u,v) square */
    trace_box bound;               /* camera space box of root (for the BVH) */
    /* instances (trace/instance.c): the earlier instance of the same
     * recorded surface whose object-space boxes (and displaced surface,
     * moved rigidly) this object uses; NULL: its own. The adapter proposes
     * it, trace_renderer_new keeps it only where that changes no surface */
    const trace_primvar *primvars; /* its primitive variables (not owned) */
    int nprimvars;
    const struct trace_object *box_proto;
    mat4 from_proto, to_proto;     /* box_proto's camera space -> ours, and back */
} trace_object;

/* The object whose boxes (and box cache entries) stand for obj's. */
static inline const trace_object *trace_box_owner(const trace_object *obj)
{
    return obj->box_proto ? obj->box_proto : obj;
}

typedef enum trace_light_kind {
    TRACE_LIGHT_AMBIENT, TRACE_LIGHT_DISTANT, TRACE_LIGHT_POINT, TRACE_LIGHT_SPOT,
    TRACE_LIGHT_SHADER,            /* a light shader run by sl_light_eval */
} trace_light_kind;

/* RenderMan's standard light sources (RI Spec 3.2, Appendix A), in camera
 * space. */
typedef struct trace_light {
    trace_light_kind kind;
    double color[3];               /* intensity * lightcolor */
    vec3 from;                     /* point, spot */
    vec3 dir;                      /* distant, spot: unit, from -> to */
    double cos_outside, cos_inside;    /* spot: cos(coneangle), cos(coneangle - delta) */
    double beamdistribution;
    bool shadows;
    /* TRACE_LIGHT_SHADER: the instance (not owned), its spaces (shader
     * space = light space) and whether its L is the same at every point
     * (solar: shadow rays go to infinity; else to Ps + L) */
    const sl_instance *shader;
    sl_spaces shader_spaces;
    bool directional;
} trace_light;

/* RI Spec 3.2 §4.1.4 (and its filter functions in the appendix) */
typedef enum trace_filter_kind {
    TRACE_FILTER_BOX, TRACE_FILTER_GAUSSIAN, TRACE_FILTER_TRIANGLE,
    TRACE_FILTER_CATMULL_ROM, TRACE_FILTER_SINC,
} trace_filter_kind;

typedef struct trace_camera {
    int xres, yres;
    bool orthographic;
    double screen[4];              /* ScreenWindow left right bottom top */
    double tan_half_fov;           /* perspective: screen window at z = 1 is scaled by this */
    double near_clip, far_clip;
    double lens_radius;            /* thin lens (DepthOfField); 0: a pinhole */
    double focal_distance;         /* camera-space depth in focus */
    mat4 camera_from_world, world_from_camera;
} trace_camera;

typedef struct trace_options {
    trace_arith arith;             /* bounding arithmetic */
    size_t cache_bytes;            /* per thread box cache budget; 0: unlimited */
    size_t roots_bytes;            /* the displaced meshes' root boxes, shared
                                      by the threads (trace/lazy_roots.h): the
                                      world's budget for them; 0: unlimited */
    int aa_capacity;               /* noise symbols per box query */
    long max_instructions;         /* shader budget per evaluation */
    double leaf_fraction;          /* box size / pixel footprint at which to stop */
    long max_nodes_per_ray;        /* work limit of one ray against one object:
                                      quadtree nodes visited (intersect.c) */
    int max_ray_depth;             /* nested trace() rays from shaders (RIB
                                      Option "trace" "maxdepth"; at most
                                      TRACE_RAY_DEPTH_LIMIT) */
    int build_threads;             /* threads trace_renderer_new may use for
                                      the boxes of displaced meshes' pieces
                                      (0, 1: the calling thread alone) */
    bool lazy_roots;               /* a displaced mesh's root boxes made when
                                      a ray first reaches its pieces (mesh.c);
                                      off: all of them when the world is built */
    bool lazy_children;            /* below a node with a linear bound, a
                                      child evaluated when a ray meets its
                                      restricted bound (intersect.c); off:
                                      all four at once, the same boxes (for
                                      tests: the same pixels either way) */
    bool tape_pruning;             /* children's box runs take the decisions
                                      their node's run proved (displace.c,
                                      common/sl/tape_plan.c); off: every box
                                      run takes the whole program */
    bool leaf_start;               /* a leaf's Newton steps start where the
                                      ray meets its box's linear bound
                                      (intersect.c, leaf_start); off: at
                                      the cell's centre (for tests and
                                      benchmarks) */
    bool prove_hits;               /* try hit proofs on small cells
                                      (trace/prove.h); off: leaves only */
    bool light_memo;               /* a shading point's light samples (and
                                      their shadow rays) made once for all
                                      the shader's light calls (shade.c);
                                      off: made on every call (for tests) */
    const atomic_int *cancel;      /* the program's stop flag (a signal), or
                                      NULL: every trace_thread and shader VM
                                      of the world watches it, the root boxes
                                      of trace_renderer_new too */
} trace_options;

/* The default work limit: 20x the largest walk of the paper's scenes
 * (wave 54, nail 205, ufo 156 nodes: `aafarm-worker --stats` prints
 * max_nodes_per_ray); docs/renderer.md "Bounded work". */
enum { TRACE_DEFAULT_MAX_NODES_PER_RAY = 4096 };

void trace_options_default(trace_options *opt);

typedef struct trace_world {
    trace_camera camera;
    int samples_x, samples_y;      /* PixelSamples */
    double shading_rate;
    trace_filter_kind filter;
    double filter_width[2];
    double gain, gamma;            /* Exposure */
    trace_object *objects;
    int nobjects;
    int nids;                      /* object ids in use: the objects, then every
                                      mesh's pieces (trace_world_prepare) */
    trace_light *lights;
    int nlights;
    trace_options options;
    struct tex_cache *textures;    /* what texture() reads (tex/tex.h); NULL: none */
} trace_world;

/* Derives each object's id, scale, normal bounds and du/dv (world.c);
 * false with a message naming the object when its transform is not finite
 * or nearly singular. Called by trace_renderer_new; idempotent. */
bool trace_world_prepare(trace_world *world, char *err, size_t errsz);

/* The per-object part of trace_world_prepare alone (the checks, scale,
 * normal bounds, du, dv): what a world that is never rendered needs (the
 * master's check of a job: no piece ids, shared edges or pieces' boxes). */
bool trace_world_check(trace_world *world, char *err, size_t errsz);

/* The object's du, dv (world.c; a mesh piece's view sets its own). */
void trace_object_grid_spacing(const trace_world *world, trace_object *obj);
/* Upper bounds of what trace_object_grid_spacing gives obj, from a 3 x 3
 * grid of the same points (9 evaluations instead of 81): du, dv lie in
 * [2^-16, *du] and [2^-16, *dv]. */
void trace_object_grid_spacing_max(const trace_world *world, const trace_object *obj,
                                   double *du, double *dv);

/* What trace_world_check derives of one object from its transforms
 * (scale, normal bounds, and du, dv when `grid`); false with a message
 * naming it when they are not finite or nearly singular. A placement's
 * view derives its own (trace/group.c). */
bool trace_object_derive(const trace_world *world, trace_object *obj, bool grid, char *err,
                         size_t errsz);

/* What a world holds, for a worker's --stats (after trace_renderer_new:
 * the groups' placements are sorted into moved and own when it builds
 * them). */
typedef struct trace_world_counts {
    int objects;                   /* world objects but groups */
    int meshes;                    /* mesh objects among them */
    long pieces;                   /* their pieces (each shared mesh once) */
    int groups;                    /* groups of placements (instances) */
    long placements;
    long moved;                    /* displaced placements that are their
                                      prototype moved (its boxes) */
    long own;                      /* displaced placements with surfaces and
                                      boxes of their own */
} trace_world_counts;

void trace_world_count(const trace_world *world, trace_world_counts *out);

#endif
