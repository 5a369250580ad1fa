/*
 * rib_parser.h: the parser's state, shared by the files that implement
 * the RIB requests (internal to common/scene; the public entry points are
 * scene_parse / scene_load in scene.h).
 *
 *   rib_parser.c       the request loop, the table of requests and where
 *                      each may appear, blocks (Frame/World/Attribute/
 *                      Transform), the end-of-file checks
 *   rib_options.c      camera and image options (Format, Projection, ...)
 *   rib_attributes.c   attributes, transforms, shaders, lights, Declare
 *   rib_geometry.c     the base surfaces (Sphere ... Polygon, Patch)
 *   rib_params.c       parameter lists: typing and reading values
 *   rib_archive.c      ReadArchive: archives found, loaded and read in place
 *   rib_inline_archive.c  ArchiveBegin/End: inline archives, recorded and
 *                      replayed by ReadArchive of their names
 *   rib_instance.c     ObjectBegin/End, ObjectInstance: retained surfaces
 *   rib_mesh.c         PointsPolygons, PointsGeneralPolygons, GeneralPolygon
 *   rib_patch.c        Basis, Patch "bicubic", PatchMesh
 *   rib_nupatch.c      NuPatch (rational, order <= 16), TrimCurve (warned)
 *   rib_ignored.c      requests read past with a warning, motion blocks
 *
 * The graphics state follows RI Specification 3.2 §4: options are global
 * and frozen at WorldBegin; attributes (with the current transform) are
 * saved and restored by AttributeBegin/End, the transform alone by
 * TransformBegin/End. Before WorldBegin the current transform maps to
 * camera space (it becomes camera_from_world); inside the world it maps
 * object space to world space, starting from the identity.
 */
#ifndef SCENE_RIB_PARSER_H
#define SCENE_RIB_PARSER_H

#include <stdbool.h>

#include "scene/rib_decl.h"
#include "scene/rib_reader.h"
#include "scene/scene.h"
#include "sl/diag.h"
#include "sl/source.h"

/* The lights on for new objects, one byte per scene light (Illuminate),
 * shared by the current attributes and the blocks that saved them and
 * copied on write, so that AttributeBegin costs the same whatever the
 * number of lights. */
typedef struct rib_light_set {
    int refs;
    int n, cap;
    unsigned char on[];
} rib_light_set;

/* The attributes of RI Spec §4.2 that aafarm records. */
typedef struct rib_attributes {
    mat4 ctm;                      /* current transform (see above) */
    int surface, displacement;     /* shader call indices, -1: none */
    double Cs[3], Os[3];
    int sides;
    scene_orientation orientation;
    double shading_rate;
    double displacement_bound;
    const char *bound_space;       /* interned (rib_parser_intern) */
    const char *name;              /* interned, or NULL */
    bool shadows;                  /* Attribute "light" "shadows" */
    rib_light_set *lights_on;      /* NULL: none on */
    double ubasis[16], vbasis[16]; /* Basis (row-major, RIB order; bezier) */
    int ustep, vstep;              /* Basis steps (3 3) */
    bool texcoords;                /* TextureCoordinates other than the default */
    double st[8];                  /* s1 t1 .. s4 t4 (rib_texcoord.c) */
} rib_attributes;

typedef enum rib_block_kind {
    RIB_BLOCK_FRAME,
    RIB_BLOCK_WORLD,
    RIB_BLOCK_ATTRIBUTE,
    RIB_BLOCK_TRANSFORM,
    RIB_BLOCK_OBJECT,              /* ObjectBegin: defs[object_def] */
} rib_block_kind;

/* At most this many blocks open at once (docs/scenes.md, Limits): each
 * saves the attributes (about 500 bytes), and a deeper RIB is either an
 * attack or a generator's bug. */
enum { RIB_MAX_BLOCKS = 100000 };

/* An open block. What the requests ask of the stack is kept per block, so
 * that every push, pop and question costs O(1) at any depth. */
typedef struct rib_block {
    rib_block_kind kind;
    sl_pos pos;                    /* where it opened */
    rib_attributes saved;          /* restored when it closes */
    int object_def;                /* RIB_BLOCK_OBJECT: index into defs */
    int object_block;              /* the open ObjectBegin block at or below, -1: none */
    int frame_world_block;         /* the outermost open Frame or World block, -1: none */
} rib_block;

/* A surface of an object definition, with the transform current inside
 * the definition (relative to its ObjectBegin). */
typedef struct rib_object_part {
    const geom_surface *surface;   /* prepared, kept by the scene; NULL for a mesh */
    const scene_mesh *mesh;        /* a mesh (owned by the scene), or NULL */
    mat4 ctm;
    sl_pos pos;
    int first_object;              /* the first object placed from it, -1: none yet */
    const scene_primvar *primvars; /* its primitive variables (kept by the scene) */
    int nprimvars;
} rib_object_part;

typedef struct rib_object_def {
    char *handle;                  /* NULL: a malformed ObjectBegin */
    sl_pos pos;
    rib_object_part *parts;
    int nparts;
    bool warned;                   /* about attributes inside it */
} rib_object_def;

/* One archive being read: its (normalized) name and the ReadArchive that
 * reads it. */
typedef struct rib_archive_link {
    const char *file;              /* interned */
    sl_pos read_at;
} rib_archive_link;

typedef struct rib_parser {
    sl_diag *diag;
    const char *file;              /* owned by scene->file */
    rib_reader *reader;
    scene *scene;
    rib_decls *decls;
    rib_attributes attr;
    rib_block *blocks;
    int nblocks, blocks_cap;
    int lights_cap, objects_cap, shaders_cap, spaces_cap;
    char **strings;                /* interned strings */
    int nstrings, strings_cap;
    char **warned;                 /* unknown requests already warned about */
    int nwarned;
    bool unknown_overflow;         /* too many names to track: silent */
    /* progress */
    bool have_format, have_projection, have_screen;
    bool in_world, world_seen, world_done;
    bool primitives_tried;         /* a base surface request was seen */
    sl_pos world_pos;
    bool skipping_frame;           /* inside a frame other than the chosen one */
    int skip_depth;                /* FrameBegin nesting while skipping */
    int frame_select;              /* the index of the frame to read */
    bool scanning;                 /* scene_scan_frames: read no frame */
    int frames_cap;                /* of scene->frame_numbers */
    char **shader_path;            /* Option "searchpath" "shader" dirs */
    int nshader_path;
    char **archive_path;           /* Option "searchpath" "archive" dirs */
    int narchive_path;
    char **texture_path;           /* Option "searchpath" "texture" dirs */
    int ntexture_path;
    sl_source_set *archives;       /* where archive texts come from */
    sl_source_set *diag_sources;   /* diag's set: archives added for carets */
    rib_archive_link archive_chain[SCENE_ARCHIVE_MAX_DEPTH];
    int narchive_chain;            /* archives being read, outermost first */
    struct rib_inline_archives *inline_archives;   /* ArchiveBegin definitions and
                                    * the one being recorded (rib_inline_archive.c) */
    rib_object_def *defs;          /* ObjectBegin definitions, in order */
    int ndefs;
    bool warned_mesh_vars;         /* primitive variables a mesh ignores */
    const scene_primvar *surface_vars;   /* the primitive variables of the surface
                                    * rib_add_surface adds next (rib_primvar.c) */
    int nsurface_vars;
    bool warned_trim;              /* TrimCurve */
    bool warned_early_light;       /* a LightSource before WorldBegin */
    bool in_motion, motion_taken;  /* MotionBegin open; its first sample read */
    sl_pos motion_pos;
    int max_objects;               /* SCENE_MAX_OBJECTS or the caller's */
    long nown;                     /* objects counted against it */
    long ninstances;               /* instances, displaced meshes' apart (SCENE_MAX_INSTANCES) */
    bool objects_overflow;         /* that limit was reported */
    unsigned char *mesh_counted;   /* per scene mesh (its index): its pieces are in
                                      scene.npieces for its undisplaced placements */
    int mesh_counted_cap;
    bool blocks_overflow;          /* RIB_MAX_BLOCKS was passed: the parse stops */
    const scene_check *check;      /* a check's parse (scene_check_frame), or NULL */
    const atomic_int *cancel;      /* the program's stop flag (a signal), or NULL */
    int threads;                   /* a mesh's faces are read over this many (rib_mesh.c) */
    unsigned requests;             /* read so far (the flag is looked at every
                                      RIB_CANCEL_EVERY) */
    bool cancelled;                /* the flag was found set: the parse stops */
} rib_parser;

/* How many requests the parser reads between two looks at its cancel flag
 * (a request costs well under a microsecond; archives included). */
enum { RIB_CANCEL_EVERY = 256 };

/* Reports an error / warning naming the request: "Sphere: <message>". */
void rib_error(rib_parser *p, const rib_request *req, sl_pos pos, const char *fmt, ...)
    SL_PRINTF(4, 5);
void rib_warning(rib_parser *p, const rib_request *req, sl_pos pos, const char *fmt, ...)
    SL_PRINTF(4, 5);

/* A copy of s that lives as long as the parser. */
const char *rib_parser_intern(rib_parser *p, const char *s);

/* Reads the numbers from argument `first` on (bare numbers and arrays,
 * flattened) up to the next string; exactly `n` of them are needed, named
 * `what` in the error ("radius zmin zmax thetamax"). Returns the index of
 * the first argument after them, or -1 after an error. */
int rib_read_numbers(rib_parser *p, const rib_request *req, int first, int n,
                     double *out, const char *what);

/* The whole numbers >= min of array argument i, malloc'd (the caller
 * frees), *count of them; NULL with an error naming `what`. An empty array
 * gives a non-NULL result with *count 0 when allow_empty, else an error. */
int *rib_read_ints(rib_parser *p, const rib_request *req, int i, int min, bool allow_empty,
                   int *count, const char *what);

/* Reads one string argument at index `i` named `what`; NULL after an
 * error. */
const char *rib_read_string(rib_parser *p, const rib_request *req, int i, const char *what);

/* Fails (with an error) when arguments are left after index `i`. */
bool rib_no_more_args(rib_parser *p, const rib_request *req, int i);

/* Dispatches the requests of p->reader until its end (or the
 * diagnostics' cap). */
void rib_parser_run(rib_parser *p);

/* Dispatches one request as the loop of rib_parser_run does; false
 * (nothing done) once the parse is to stop (the diagnostics' cap, too many
 * blocks, the cancel flag). */
bool rib_parser_step(rib_parser *p, const rib_request *req);

/* ---- parameter lists (rib_params.c) ------------------------------------- */

typedef enum rib_params_mode {
    RIB_PARAMS_UNIFORM,            /* shader calls: exactly one value each */
    RIB_PARAMS_VARYING,            /* primitives: a multiple of the type's size */
    RIB_PARAMS_LOOSE,              /* Attribute/Option: undeclared names untyped */
} rib_params_mode;

typedef struct rib_params {
    scene_param *items;
    int count;
} rib_params;

/* Reads "name" value pairs from argument `first` on. Returns false after
 * an error (reported); *out is then empty. */
bool rib_params_read(rib_parser *p, const rib_request *req, int first,
                     rib_params_mode mode, rib_params *out);
void rib_params_clear(rib_params *params);
const scene_param *rib_params_find(const rib_params *params, const char *name);
/* The geometry's "P": NULL after an error (missing, or not declared a
 * point), reported at the request or at the parameter. */
const scene_param *rib_params_points(rib_parser *p, const rib_request *req,
                                     const rib_params *params);

/* ---- the requests -------------------------------------------------------- */

typedef void (*rib_request_fn)(rib_parser *p, const rib_request *req);

/* rib_options.c */
void rib_version(rib_parser *p, const rib_request *req);
void rib_display(rib_parser *p, const rib_request *req);
void rib_format(rib_parser *p, const rib_request *req);
void rib_projection(rib_parser *p, const rib_request *req);
void rib_screen_window(rib_parser *p, const rib_request *req);
void rib_clipping(rib_parser *p, const rib_request *req);
void rib_depth_of_field(rib_parser *p, const rib_request *req);
void rib_pixel_samples(rib_parser *p, const rib_request *req);
void rib_pixel_filter(rib_parser *p, const rib_request *req);
void rib_exposure(rib_parser *p, const rib_request *req);
void rib_option(rib_parser *p, const rib_request *req);
void rib_options_finish(rib_parser *p, const rib_request *req);   /* WorldBegin */

/* rib_attributes.c */
void rib_shading_rate(rib_parser *p, const rib_request *req);
void rib_identity(rib_parser *p, const rib_request *req);
void rib_translate(rib_parser *p, const rib_request *req);
void rib_rotate(rib_parser *p, const rib_request *req);
void rib_scale(rib_parser *p, const rib_request *req);
void rib_concat_transform(rib_parser *p, const rib_request *req);
void rib_transform(rib_parser *p, const rib_request *req);
void rib_coordinate_system(rib_parser *p, const rib_request *req);
void rib_coord_sys_transform(rib_parser *p, const rib_request *req);
void rib_light_source(rib_parser *p, const rib_request *req);
void rib_illuminate(rib_parser *p, const rib_request *req);
void rib_surface(rib_parser *p, const rib_request *req);
void rib_displacement(rib_parser *p, const rib_request *req);
void rib_color(rib_parser *p, const rib_request *req);
void rib_opacity(rib_parser *p, const rib_request *req);
void rib_attribute(rib_parser *p, const rib_request *req);
void rib_declare(rib_parser *p, const rib_request *req);
void rib_sides(rib_parser *p, const rib_request *req);
void rib_orientation(rib_parser *p, const rib_request *req);
void rib_reverse_orientation(rib_parser *p, const rib_request *req);
void rib_attributes_init(rib_attributes *a);
void rib_attributes_copy(rib_attributes *dst, const rib_attributes *src);
void rib_attributes_clear(rib_attributes *a);
void rib_shaders_finish(rib_parser *p);           /* at WorldBegin */

/* rib_geometry.c */
void rib_sphere(rib_parser *p, const rib_request *req);
void rib_disk(rib_parser *p, const rib_request *req);
void rib_cylinder(rib_parser *p, const rib_request *req);
void rib_cone(rib_parser *p, const rib_request *req);
void rib_torus(rib_parser *p, const rib_request *req);
void rib_hyperboloid(rib_parser *p, const rib_request *req);
void rib_paraboloid(rib_parser *p, const rib_request *req);
void rib_polygon(rib_parser *p, const rib_request *req);
void rib_patch(rib_parser *p, const rib_request *req);

/* rib_archive.c */
void rib_read_archive(rib_parser *p, const rib_request *req);

/* rib_inline_archive.c: ArchiveBegin starts recording; ArchiveEnd outside
 * a recording is an error. The filter takes every request while one is
 * recorded, and ReadArchive of an inline archive's name (replayed): true
 * when it took req. finish reports a block never closed; destroy frees. */
void rib_archive_begin(rib_parser *p, const rib_request *req);
void rib_archive_end(rib_parser *p, const rib_request *req);
bool rib_inline_archive_filter(rib_parser *p, const rib_request *req);
void rib_inline_archive_finish(rib_parser *p);
void rib_inline_archives_destroy(rib_parser *p);

/* rib_instance.c */
void rib_object_begin(rib_parser *p, const rib_request *req);
void rib_object_end(rib_parser *p, const rib_request *req);
void rib_object_instance(rib_parser *p, const rib_request *req);
/* The definition being recorded (innermost ObjectBegin), or NULL. */
rib_object_def *rib_defining(rib_parser *p);
/* Records a prepared surface (or a mesh: mesh non-NULL, surf unused) in
 * the definition being recorded. */
void rib_record_surface(rib_parser *p, const rib_request *req, const geom_surface *surf,
                        const scene_mesh *mesh);
void rib_object_defs_clear(rib_parser *p);

/* rib_geometry.c: adds a prepared surface as an object with the current
 * attributes and transform, or records it in the object being defined;
 * with p->surface_vars, its primitive variables (copied). */
void rib_add_surface(rib_parser *p, const rib_request *req, const geom_surface *surf);

/* rib_patch.c */
void rib_basis(rib_parser *p, const rib_request *req);
void rib_patch_mesh(rib_parser *p, const rib_request *req);
/* The type argument of Patch and PatchMesh: *cubic for "bicubic", else
 * "bilinear"; false with an error for anything else (rib_patch.c). */
bool rib_read_patch_type(rib_parser *p, const rib_request *req, bool *cubic);
struct rib_primvars;
/* pv: the patch's other primitive variables (rib_primvar.h), or NULL */
void rib_patch_bicubic(rib_parser *p, const rib_request *req, const scene_param *P,
                       struct rib_primvars *pv);
/* The primitive variables of a Patch or PatchMesh: counts as rib_primvars_collect
 * wants; vertex-class variables of bicubic patches are dropped with a warning */
bool rib_patch_primvars(rib_parser *p, const rib_request *req, const rib_params *params,
                        const int counts[6], bool cubic, struct rib_primvars *out);
/* The variables of one patch (corners (0,0), (1,0), (0,1), (1,1)): patch
 * `uniform`, varying values at (pu + du) mod nuvar, (pv + dv) mod nvvar of an
 * nuvar x nvvar grid, vertex values at points vtx[4] (NULL: none), set as
 * the next surface's (p->surface_vars, out holds them). */
void rib_patch_vars(rib_parser *p, const struct rib_primvars *pv, int uniform, int pu, int pv_,
                    int nuvar, int nvvar, const int *vtx, scene_primvar *out);
void rib_basis_default(double m[16], int *step);

/* rib_nupatch.c */
void rib_nu_patch(rib_parser *p, const rib_request *req);
void rib_trim_curve(rib_parser *p, const rib_request *req);

/* rib_subdiv.c */
void rib_subdivision_mesh(rib_parser *p, const rib_request *req);
void rib_hierarchical_subdivision_mesh(rib_parser *p, const rib_request *req);

/* scene_mesh.c: building a mesh (the parser's side of scene_mesh.h). The
 * arrays are copied; the variables' values are found among params' arrays
 * and copied too. */
struct rib_primvars;
scene_mesh *scene_mesh_new(const double *P, int npoints, const int *idx, int nidx,
                           scene_mesh_nclass ncls, const double *N, int nN,
                           const struct rib_primvars *pv, const rib_params *params);
/* The same without copies (a million-face mesh's arrays are ~60 MB): the
 * mesh takes P, idx and N (NULL: none), which the caller allocated and
 * must no longer free, and moves the variables' arrays out of params (their
 * values become NULL there); the pointers stay valid while the mesh lives. */
scene_mesh *scene_mesh_new_taking(double *P, int npoints, int *idx, int nidx,
                                  scene_mesh_nclass ncls, double *N, int nN,
                                  const struct rib_primvars *pv, rib_params *params);
/* Adds a piece: a polygon of face `face`'s ncorners corners from
 * face-vertex fv0, started at corner k[0] (k NULL: the first), or the
 * triangle of its corners k[0..3). */
/* A check's mesh (scene_check_frame): the pieces added are counted, and
 * nothing else is kept; nprimvars: each piece's variables. */
scene_mesh *scene_mesh_new_counted(int nprimvars);
void scene_mesh_add_piece(scene_mesh *self, scene_piece_kind kind, int face, int fv0,
                          const int k[3], int ncorners);
void scene_mesh_trim(scene_mesh *self);          /* frees the spare capacity */
void scene_mesh_set_index(scene_mesh *self, int index);
/* Makes the mesh a subdivision mesh's (its pieces SCENE_PIECE_SUBDIV):
 * the refined mesh sd (the scene's) and the control faces' corner counts. */
struct geom_subdiv;
void scene_mesh_set_subdiv(scene_mesh *self, const struct geom_subdiv *sd, const int *nverts,
                           int nfaces);
/* A subdivision mesh's control faces' first face-vertices (nfaces + 1)
 * and the face-vertices' points (its vertex indices): what its refined
 * mesh reads for its control faces (geom_subdiv_share_faces; the scene
 * holds both, and outlives the worker's world) */
const int *scene_mesh_face_offsets(const scene_mesh *self);
const int *scene_mesh_indices(const scene_mesh *self);
vec3 scene_mesh_corner_normal(scene_mesh_nclass ncls, const double *N, int face,
                              const int *idx, int fv0, int i);
/* Hands a mesh (with pieces) to the scene, placed as one object with the
 * current attributes or recorded in the object being defined. */
void rib_add_mesh(rib_parser *p, const rib_request *req, scene_mesh *mesh);

/* rib_mesh.c */
void rib_points_polygons(rib_parser *p, const rib_request *req);
/* A Polygon (checked: convex, planar) with primitive variables other than
 * "P" and "N": added as a one-face mesh, true; false (nothing done) when
 * it has none. */
bool rib_polygon_vars(rib_parser *p, const rib_request *req, const rib_params *params,
                      const scene_param *P);
void rib_points_general_polygons(rib_parser *p, const rib_request *req);
void rib_general_polygon(rib_parser *p, const rib_request *req);

/* rib_texcoord.c: TextureCoordinates; the variables of a surface placed
 * with them (vars and the "s", "t" pair, into out): their count, or -1
 * when the surface keeps vars as they are. */
void rib_texture_coordinates(rib_parser *p, const rib_request *req);
int rib_texcoord_vars(const rib_parser *p, const geom_surface *surf, const scene_primvar *vars,
                      int nvars, scene_primvar out[SCENE_MAX_PRIMVARS]);

/* rib_ignored.c: requests read past with one warning per name. True
 * when req is one of them (warned about, nothing else done). */
bool rib_ignored_request(rib_parser *p, const rib_request *req);
/* An option inside the world or after it: warned about once, ignored. */
void rib_option_in_world(rib_parser *p, const rib_request *req);
/* MotionBegin/MotionEnd and the requests between them: true when req is
 * taken care of (the block's bounds, or a later time sample, skipped);
 * false for anything the caller should run. */
bool rib_motion_filter(rib_parser *p, const rib_request *req);

/* rib_geometry.c: adds an object for a prepared surface (kept by the
 * scene: scene_keep) or a mesh (mesh non-NULL, surf NULL) with the current
 * attributes and the object-to-world transform ctm; pos is where the
 * surface was written. vars_kept: vars[0..nvars) is kept by the scene (a
 * recorded part's) and the object may point at it. first: for a later
 * ObjectInstance placement of a recorded part, the scene index of the
 * part's first placement (a reference in the renderer: it counts against
 * SCENE_MAX_INSTANCES, not the objects' limit; a displaced mesh's counts
 * its pieces unless it is the first moved rigidly), else -1. */
void rib_place_surface(rib_parser *p, const rib_request *req, const geom_surface *surf,
                       const scene_mesh *mesh, mat4 ctm, sl_pos pos,
                       const scene_primvar *vars, int nvars, bool vars_kept, int first);

/* rib_parser.c: blocks */
/* False (reported, and the parse stops) past RIB_MAX_BLOCKS. */
bool rib_push_block(rib_parser *p, const rib_request *req, rib_block_kind kind);
void rib_close_block(rib_parser *p, const rib_request *req, rib_block_kind kind);

/* Growing the scene's arrays (rib_parser.c). */
scene_light *rib_add_light(rib_parser *p);
scene_object *rib_add_object(rib_parser *p);
scene_shader *rib_add_shader(rib_parser *p);
scene_space *rib_add_space(rib_parser *p);

#endif
