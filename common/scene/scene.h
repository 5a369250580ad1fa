/*
 * scene.h: the scene model (scene) that the RIB parser builds and the
 * renderer consumes: the camera and image options, the lights, the objects
 * (a base surface from common/geom plus its transforms, attributes and
 * shader references), the shader search path.
 *
 * A scene is built from RenderMan Interface Bytestream text (a subset of
 * RI Specification 3.2, see docs/scenes.md for the table of requests):
 *
 *   scene_parse(file, text, len, diag)   from memory (archives from disk)
 *   scene_load(path, diag)               from a file (archives from disk)
 *   scene_parse_archives(file, text, len, archives, diag)
 *                                        archives from a source set: a
 *                                        worker gets the scene text in
 *                                        the job and the archives as the
 *                                        job's files
 *
 * All return NULL when there was any error; every error is in diag with
 * its file:line:col and names the RIB request. Warnings (unknown requests,
 * ignored frames) may be reported on success.
 *
 * Spaces (RenderMan conventions, docs/scenes.md "Conventions"):
 *   camera space is left-handed, the camera at the origin looking down +z,
 *   x right, y up. "world" is the space current at WorldBegin. Every
 *   transform is stored twice, to world and to camera, so the renderer may
 *   work in either; camera.camera_from_world links the two
 *   (to_camera = camera_from_world * to_world). Matrices follow
 *   util/vecmath.h (column vectors: p' = m * p).
 *
 * Units: angles in the RIB are degrees; base surfaces here (geom_surface)
 * are in radians as common/geom expects. The field of view stays in
 * degrees (camera.fov); the spotlight's cone angles are radians, as in the
 * standard spotlight shader.
 *
 * All strings and arrays are owned by the scene; scene_destroy frees them.
 */
#ifndef SCENE_SCENE_H
#define SCENE_SCENE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "geom/surface.h"
#include "scene/scene_mesh.h"
#include "sl/diag.h"
#include "sl/shader.h"
#include "sl/source.h"
#include "util/vecmath.h"

/* ---- camera and image options ------------------------------------------ */

typedef enum scene_projection {
    SCENE_PERSPECTIVE,
    SCENE_ORTHOGRAPHIC,
} scene_projection;

typedef struct scene_camera {
    int xres, yres;                /* Format */
    double pixel_aspect;           /* Format's third number */
    scene_projection projection;   /* Projection */
    double fov;                    /* degrees, perspective only (default 90) */
    double screen[4];              /* ScreenWindow left right bottom top */
    double near_clip, far_clip;    /* Clipping (default 1e-10, 1e30) */
    double fstop;                  /* DepthOfField; 0: a pinhole (the default) */
    double focal_length, focal_distance;   /* camera-space units */
    mat4 camera_from_world;        /* the transform current at WorldBegin */
    mat4 world_from_camera;        /* its inverse */
} scene_camera;

typedef enum scene_filter_kind {
    SCENE_FILTER_BOX,
    SCENE_FILTER_GAUSSIAN,
    SCENE_FILTER_TRIANGLE,
    SCENE_FILTER_CATMULL_ROM,
    SCENE_FILTER_SINC,
} scene_filter_kind;

typedef struct scene_filter {
    scene_filter_kind kind;        /* default gaussian 2 2 */
    double xwidth, ywidth;         /* in pixels */
} scene_filter;

/* ---- shader references ------------------------------------------------- */

/* Storage classes of primitive variables (RI Spec 3.2 §5.1), as declared
 * ("vertex float foo"); SCENE_CLASS_NONE: not said (told by the count). */
typedef enum scene_class {
    SCENE_CLASS_NONE, SCENE_CLASS_CONSTANT, SCENE_CLASS_UNIFORM, SCENE_CLASS_VARYING,
    SCENE_CLASS_VERTEX, SCENE_CLASS_FACEVARYING,
} scene_class;

/* One parameter of a Surface / Displacement call, typed from Declare, the
 * predeclared standard names or an inline declaration ("uniform float Km").
 * Numbers: values[0..count), count = components(type) * arraylen (float 1,
 * point/vector/normal/color 3, matrix 16). Strings: string, count 1. */
typedef struct scene_param {
    char *name;
    sl_type type;
    int arraylen;                  /* 1 unless declared as an array */
    double *values;                /* NULL for strings */
    int count;
    char *string;                  /* string parameters only */
    sl_pos pos;                    /* where the name was written */
    scene_class cls;               /* primitive variables: the declared class */
} scene_param;

/* A primitive variable over one object (docs/scenes.md "Primitive
 * variables"): per component k, the value at (u,v) of the object's own
 * parametrisation is the polynomial sum over i, j < 4 of c[i + 4 j][k]
 * u^i v^j (linear over a mesh triangle, bilinear over a patch, bicubic for
 * the vertex class of a bicubic patch, constant for the constant and
 * uniform classes). Points, vectors and normals are in object space.
 * "st" arrives as two floats "s" and "t". */
typedef struct scene_primvar {
    char name[64];
    sl_type type;                  /* float, color, point, vector or normal */
    int size;                      /* components: 1 or 3 */
    double c[16][3];               /* c[i + 4 j]: the term of u^i v^j */
} scene_primvar;

/* The most primitive variables one object carries ("st" counts two). */
enum { SCENE_MAX_PRIMVARS = 16 };

/* One Surface or Displacement request, or a LightSource naming a light
 * shader. "shader" space is the transform
 * current at the request. */
typedef struct scene_shader {
    sl_shader_kind kind;
    char *name;                    /* "wave": find "wave.sl" on the search path */
    scene_param *params;
    int nparams;
    mat4 shader_to_world;
    mat4 shader_to_camera;
    sl_pos pos;
} scene_shader;

/* ---- lights -------------------------------------------------------------- */

typedef enum scene_light_kind {
    SCENE_AMBIENT_LIGHT,           /* intensity lightcolor */
    SCENE_DISTANT_LIGHT,           /* + from to */
    SCENE_POINT_LIGHT,             /* + from */
    SCENE_SPOT_LIGHT,              /* + from to coneangle conedeltaangle beamdistribution */
    SCENE_SHADER_LIGHT,            /* any other name: a light shader (shader) */
} scene_light_kind;

typedef struct scene_light {
    scene_light_kind kind;
    char *handle;                  /* the RIB sequence number or name, as text */
    /* parameters in light space, RenderMan's defaults where not given:
     * intensity 1, lightcolor (1,1,1), from (0,0,0), to (0,0,1),
     * coneangle 30 deg, conedeltaangle 5 deg (in radians),
     * beamdistribution 2 */
    double intensity;
    double lightcolor[3];
    vec3 from, to;
    double coneangle, conedeltaangle, beamdistribution;
    bool shadows;                  /* casts shadows (docs/scenes.md "Shadows") */
    int shader;                    /* SCENE_SHADER_LIGHT: index into scene.shaders
                                      (kind SL_SHADER_LIGHT, shader space = light
                                      space, its parameters); else -1 */
    mat4 light_to_world, light_to_camera;
    vec3 from_world, to_world;     /* from / to transformed */
    vec3 from_camera, to_camera;
    sl_pos pos;
} scene_light;

/* ---- objects -------------------------------------------------------------- */

typedef enum scene_orientation {
    SCENE_OUTSIDE,                 /* RenderMan's default */
    SCENE_INSIDE,
    SCENE_LH,
    SCENE_RH,
} scene_orientation;

/* The attributes a run of objects shares (RI Spec 3.2 §4: the graphics
 * state at the primitive), kept once by the scene (scene_keep) and pointed
 * at by every object placed while they did not change: a run of instances
 * with one set of attributes costs one record (issue 23). The strings and
 * the light list are kept by the scene too and shared with the previous
 * record where equal. */
typedef struct scene_attributes {
    double Os[3];                  /* Opacity */
    double shading_rate;
    double displacement_bound;     /* Attribute "displacementbound" "sphere" */
    const char *displacement_bound_space;   /* its "coordinatesystem" ("object") */
    const char *name;              /* Attribute "identifier" "name", or NULL */
    const int *lights;             /* indices into scene.lights that are on */
    int nlights;
    int surface_shader;            /* index into scene.shaders, -1: none */
    int displacement_shader;       /* index into scene.shaders, -1: none */
    int sides;                     /* 1 or 2 */
    scene_orientation orientation; /* as recorded (ReverseOrientation applied) */
} scene_attributes;

/* One placed primitive or mesh: what differs from object to object (the
 * surface, the transform, the colour, the primitive variables), and the
 * shared attributes. ~216 bytes (an instance's share of the scene). */
typedef struct scene_object {
    mat4 object_to_world;          /* to camera space and back:
                                      scene_object_transforms */
    double Cs[3];                  /* Color */
    const geom_surface *surface;   /* object space, radians; prepared; kept by
                                    * the scene (scene_keep) and shared by the
                                    * objects placed from one recorded surface
                                    * (instances); NULL for a mesh */
    const scene_attributes *attr;  /* kept by the scene, shared with the
                                    * previous object where equal */
    sl_pos pos;                    /* the defining request (file = scene.file) */
    const scene_primvar *primvars; /* its primitive variables (other than P, N):
                                    * kept by the scene (scene_keep), shared
                                    * with the previous object where equal */
    const scene_mesh *mesh;        /* a polygon mesh (scene_mesh.h): its pieces stand
                                    * for `surface` (unused) and `primvars` (none
                                    * here); owned by scene.meshes. NULL: one surface */
    int nprimvars;
    int instance_of;               /* ObjectInstance: the index of the first object
                                    * placed from the same recorded surface (its
                                    * own index for that one); -1: not instanced.
                                    * The renderer may share its boxes (Instances) */
    bool reverse_normals;          /* flip Ng (attr->orientation vs handedness) */
} scene_object;

/* CoordinateSystem "name": a named space. */
typedef struct scene_space {
    char *name;
    mat4 to_world, to_camera;
    sl_pos pos;
} scene_space;

/* ---- the scene ------------------------------------------------------------ */

typedef struct scene {
    char *file;                    /* the name the RIB was parsed under */
    scene_camera camera;
    int pixel_samples[2];          /* PixelSamples (default 2 2) */
    double shading_rate;           /* ShadingRate current at WorldBegin */
    double exposure_gain, exposure_gamma;   /* Exposure (default 1 1) */
    scene_filter filter;
    char *display_name;            /* Display, NULL when not given */
    char *display_type;            /* "file", "openexr", ... */
    char *display_mode;            /* "rgb", "rgba", ... */
    scene_light *lights;
    int nlights;
    scene_object *objects;
    int nobjects;
    scene_shader *shaders;         /* every Surface / Displacement call */
    int nshaders;
    scene_space *spaces;
    int nspaces;
    char **search_path;            /* NULL-terminated directories */
    int nsearch_path;
    char **texture_path;           /* Option "searchpath" "texture" dirs, then
                                      the RIB's folder (NULL-terminated): where
                                      the files a shader names are found */
    int ntexture_path;
    char **shader_names;           /* distinct shaders the objects and lights use */
    int nshader_names;
    char **archives;               /* ReadArchive files read (normalized), in
                                    * order of first reading; positions inside
                                    * them point at these names */
    int narchives;
    /* frames (docs/scenes.md "Frames"): the file's FrameBegin blocks, in
     * order, and the one this scene was parsed from */
    int frame;                     /* its index (0: the first, or the whole
                                    * file when it has no FrameBegin) */
    int frame_number;              /* its FrameBegin number (1 without one) */
    int nframes;                   /* FrameBegin blocks in the file (0: none) */
    int *frame_numbers;            /* each one's number, nframes of them */
    int trace_maxdepth;            /* Option "trace" "maxdepth": nested trace()
                                    * rays (-1: not given, the renderer's 4) */
    struct geom_subdiv **subdivs;  /* SubdivisionMesh meshes, shared by their
                                    * faces' surfaces (geom/subdiv.h) */
    int nsubdivs;
    struct geom_nurbs **nurbs;     /* rational / high-order NuPatches, shared
                                    * by their pieces' surfaces (geom/nurbs.h) */
    int nnurbs;
    scene_mesh **meshes;           /* polygon meshes, each placed by one or more
                                    * objects (scene_object.mesh) */
    int nmeshes;
    bool checked;                  /* parsed by scene_check_frame: meshes count their
                                    * pieces but keep no arrays, references dropped */
    long nchecked_placements;      /* those references (checked, not kept) */
    long npieces;                  /* the pieces a renderer keeps boxes for: an
                                    * undisplaced mesh's once, a displaced mesh's
                                    * once per placing object (but an instance
                                    * moving the first rigidly), other objects one */
    void **kept;                   /* what the objects share (scene_keep) */
    size_t nkept, kept_cap;
} scene;

/* The largest Option "trace" "maxdepth" (each depth is a shading VM per
 * thread). */
enum { SCENE_MAX_TRACE_DEPTH = 16 };

/* ---- building ------------------------------------------------------------ */

/* Hands `block` (from xalloc) to the scene, which frees it with itself;
 * returns it. What objects point at and may share (surfaces, primitive
 * variables, names, light lists) lives there. */
void *scene_keep(scene *self, void *block);

/* Parses RIB text[0..len) named `file` (for positions and the RIB folder
 * of the search path). While parsing, diag's source set is a private copy
 * of the text (for caret lines); it is set to NULL before returning. */
scene *scene_parse(const char *file, const char *text, size_t len, sl_diag *diag);

/* Reads the file at `path` and parses it under that name. */
scene *scene_load(const char *path, sl_diag *diag);

/* As scene_parse, with the texts of ReadArchive taken from `archives`
 * (sl/source.h; its loader, if any, is asked for missing names). The
 * master and standalone read archives from disk (scene_archive_set_new, or
 * common/job's loader that also makes each archive a job file); a worker
 * reads them from the job's files in its store (common/job/job_archive.c).
 * scene_parse and scene_load read archives from disk (a private set).
 * `archives` NULL: ReadArchive finds nothing. */
scene *scene_parse_archives(const char *file, const char *text, size_t len,
                            sl_source_set *archives, sl_diag *diag);

/* The largest archive, uncompressed: an archive travels as a file of the
 * job (once per host, docs/farm.md), not inside the Job message, so its
 * bound is what one parse may hold in memory. The top-level scene text
 * keeps its own bound (the Job message's, 4 MiB). */
#define SCENE_ARCHIVE_MAX_BYTES ((size_t)1 << 30)

/* An empty set for archive texts: at most SCENE_ARCHIVE_MAX_BYTES each,
 * read from disk by scene_archive_load_from_disk. */
sl_source_set *scene_archive_set_new(void);

/* An sl_source_loader: reads file `name` from disk into the set,
 * gunzipping it when gzip-compressed; 1 when it does not exist. */
int scene_archive_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag,
                                 void *arg);

/* Reads the archive at `path` (plain or gzip) into the set under `name`
 * (the name messages use): 0, 1 when there is no such file, -1 on another
 * failure (in diag: unreadable, a damaged gzip stream, larger than the
 * set's maximum size). */
int scene_archive_read(sl_source_set *set, const char *name, const char *path,
                       sl_diag *diag);

/* How deep archives may read archives. */
enum { SCENE_ARCHIVE_MAX_DEPTH = 16 };

/* The most objects a scene may place (primitives and meshes: each an
 * object of its own in the renderer, ~9 KB; instances have their own
 * limit below), so that a scene
 * received over the network
 * cannot exhaust the memory of the master or a worker (issue 12). The
 * scene text itself is bounded by the source size (4 MiB, sl/source.h),
 * each archive by SCENE_ARCHIVE_MAX_BYTES. */
enum { SCENE_MAX_OBJECTS = 1 << 20 };

/* The most ObjectInstance placements a scene may hold: each is a
 * reference in a worker (trace/group.h: ~400 bytes with its scene object,
 * docs/renderer.md "Instances as references"), so 2^24 of them fit a 24 GB
 * worker; those of a displaced mesh that are not its first moved rigidly
 * also count its pieces (SCENE_MAX_PIECES). */
enum { SCENE_MAX_INSTANCES = 1 << 24 };

/* The most mesh pieces (a face, or a triangle of one) a scene may hold
 * boxes for (scene.npieces: instances of an undisplaced mesh count its
 * pieces once, displaced ones each time but where an instance moves the
 * first placement rigidly): ~100 bytes each
 * in a worker (docs/renderer.md "Meshes"), so 2^25 of them fit a 24 GB
 * worker with room for the box cache. */
#define SCENE_MAX_PIECES (1L << 25)

/* The pieces of an object: a mesh's, or 1. Piece k's surface and
 * primitive variables (out: at most RIB's 16 per object) into s, vars,
 * *nvars. */
int scene_object_npieces(const scene_object *object);

/* Object o's transforms between its object space and camera space: the
 * camera's camera_from_world times its object_to_world, and the inverse,
 * made the way the parser checked them (so the same bits every time; the
 * parser refused a singular one). Not kept per object: 256 bytes an
 * instance. */
void scene_object_transforms(const scene *self, const scene_object *object, mat4 *to_camera,
                             mat4 *from_camera);
bool scene_object_piece(const scene_object *object, int k, geom_surface *s,
                        scene_primvar *vars, int *nvars);
/* Piece k's outline (scene_mesh_piece_outline; an object of no mesh:
 * its surface). */
bool scene_object_piece_outline(const scene_object *object, int k, geom_surface *s);

/* As scene_parse_archives, with at most max_objects objects (more is an
 * error naming the request that passes the limit). */
scene *scene_parse_limited(const char *file, const char *text, size_t len,
                           sl_source_set *archives, int max_objects, sl_diag *diag);

/* As scene_parse_limited, reading the frame with index `frame` (the
 * frame-th FrameBegin block, from 0; RI Spec 3.2 §4: the requests outside
 * every frame apply to all of them, those inside the other frames are
 * skipped). Any parse tells the file's frames (scene.nframes,
 * scene.frame_numbers); an index past the last frame is an error.
 * cancel: the program's stop flag (a signal) or NULL; the parser looks at
 * it every RIB_CANCEL_EVERY requests (archives included) and, when it is
 * set, stops with the error "interrupted" (NULL). */
scene *scene_parse_frame(const char *file, const char *text, size_t len,
                         sl_source_set *archives, int max_objects, int frame,
                         const atomic_int *cancel, sl_diag *diag);

/* As scene_parse_frame, the faces of each large polygon mesh prepared over
 * `threads` threads (a worker's: common/job). The scene, its messages and
 * their order are those of one thread (rib_mesh.c puts the faces' pieces
 * and messages together in face order). */
scene *scene_parse_frame_threads(const char *file, const char *text, size_t len,
                                 sl_source_set *archives, int max_objects, int frame,
                                 int threads, const atomic_int *cancel, sl_diag *diag);

/* What a check's parse (scene_check_frame) asks of its caller: whether
 * an instance the renderer would keep as a reference to its
 * prototype (scene_object_placeable) is one it can place (its transforms:
 * the renderer's own test); false with a message, reported at the
 * ObjectInstance. */
typedef struct scene_check {
    bool (*placement)(void *user, const scene *sc, const scene_object *proto,
                      const scene_object *placement, char *err, size_t errsz);
    void *user;
} scene_check;

/* As scene_parse_frame, for a program that checks a scene without
 * rendering it (the master): the same requests read and the same errors
 * reported at the same places, but what only a renderer needs is not kept,
 * so that a million-face mesh or a million instances cost the check little
 * memory (issue 23). Meshes (scene_mesh.h) count their pieces but keep no
 * arrays (scene_object_piece must not be called on them); an ObjectInstance
 * placement that the renderer keeps as a reference is handed to
 * check->placement and not kept (scene.nchecked_placements counts them).
 * The scene is marked `checked`. */
scene *scene_check_frame(const char *file, const char *text, size_t len,
                         sl_source_set *archives, int max_objects, int frame,
                         const scene_check *check, const atomic_int *cancel, sl_diag *diag);

/* May object o, a later placement of the recorded surface that object
 * proto placed first (o->instance_of), be a reference to it in the
 * renderer (trace/group.h): the same surface or mesh in object space,
 * the same shaders (displacement included), sides,
 * lights, primitive variables and name, only its transform, orientation
 * and colour its own? */
bool scene_object_placeable(const scene_object *o, const scene_object *proto);

/* The frames of a RIB without reading any of them: their FrameBegin
 * numbers into a malloc'd *numbers (NULL when there is none). Returns
 * their count (0: no FrameBegin, the file is one frame), or -1 when the
 * requests outside the frames have errors (in diag; cancel as above). */
int scene_scan_frames(const char *file, const char *text, size_t len,
                      sl_source_set *archives, int **numbers, const atomic_int *cancel,
                      sl_diag *diag);

void scene_destroy(scene **self_p);

/* ---- queries -------------------------------------------------------------- */

/* The object's shaders, or NULL when it has none. */
const scene_shader *scene_object_surface(const scene *self, const scene_object *object);
const scene_shader *scene_object_displacement(const scene *self, const scene_object *object);

/* Frees a parameter's strings and values (and zeroes it). */
void scene_param_clear(scene_param *param);

/* A parameter of a shader call by name, or NULL. */
const scene_param *scene_shader_param(const scene_shader *shader, const char *name);

/* The search path as sl_compile takes it (NULL-terminated). */
const char *const *scene_search_path(const scene *self);

/* Decides whether a candidate file exists (arg: the caller's context). */
typedef bool (*scene_file_exists_fn)(const char *path, void *arg);

/* The file of shader `name`: the first "<dir>/<name>.sl" on the search
 * path for which exists() says yes (exists NULL: readable on disk).
 * Returns a malloc'd path the caller frees, or NULL. */
char *scene_find_shader(const scene *self, const char *name,
                        scene_file_exists_fn exists, void *arg);

/* Names for messages and tools. */
const char *scene_light_kind_name(scene_light_kind kind);     /* "spotlight" */
const char *scene_filter_name(scene_filter_kind kind);        /* "gaussian" */
const char *scene_projection_name(scene_projection p);        /* "perspective" */
const char *scene_orientation_name(scene_orientation o);      /* "outside" */

#endif
