/*
 * rib_parser.c: the RIB request loop (scene_parse, scene_load): the table
 * of supported requests with where each may appear, the block structure
 * (FrameBegin/End, WorldBegin/End, AttributeBegin/End, TransformBegin/End,
 * RI Specification 3.2 §4), unknown requests, and the checks at the end of
 * the text. The requests themselves live in rib_options.c,
 * rib_attributes.c and rib_geometry.c.
 *
 * Error policy: every error names the request and its file:line:col; the
 * parser goes on with the next request (so one run reports many errors,
 * up to the diagnostics' cap) and returns NULL at the end if there was
 * any. A request with a malformed argument is skipped whole.
 */
#include "scene/rib_parser.h"
#include "sl/source.h"
#include "sl/strbuf.h"
#include "util/suggest.h"
#include "util/xalloc.h"

#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---------------------------------------------------------------------- */
/* messages and small helpers                                              */
/* ---------------------------------------------------------------------- */

static void vreport(rib_parser *p, sl_diag_level level, const rib_request *req,
                    sl_pos pos, const char *fmt, va_list ap)
{
    char msg[2048];
    vsnprintf(msg, sizeof msg, fmt, ap);
    /* inside an archive: name the chain, innermost first */
    for (int i = p->narchive_chain - 1; i >= 0; i--) {
        const rib_archive_link *l = &p->archive_chain[i];
        size_t used = strlen(msg);
        snprintf(msg + used, sizeof msg - used, "%s archive %s read at %s:%d:%d%s",
                 i == p->narchive_chain - 1 ? " (in" : ",", l->file, l->read_at.file,
                 l->read_at.line, l->read_at.col, i == 0 ? ")" : "");
    }
    if (req)
        sl_diag_report(p->diag, level, pos, "%s: %s", req->name, msg);
    else
        sl_diag_report(p->diag, level, pos, "%s", msg);
}

void rib_error(rib_parser *p, const rib_request *req, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(p, SL_DIAG_ERROR, req, pos, fmt, ap);
    va_end(ap);
}

void rib_warning(rib_parser *p, const rib_request *req, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(p, SL_DIAG_WARNING, req, pos, fmt, ap);
    va_end(ap);
}

const char *rib_parser_intern(rib_parser *p, const char *s)
{
    if (p->nstrings == p->strings_cap) {
        p->strings_cap = p->strings_cap ? 2 * p->strings_cap : 16;
        p->strings = xrealloc(p->strings, (size_t)p->strings_cap * sizeof *p->strings);
    }
    p->strings[p->nstrings] = xstrndup(s, strlen(s));
    return p->strings[p->nstrings++];
}

int rib_read_numbers(rib_parser *p, const rib_request *req, int first, int n,
                     double *out, const char *what)
{
    int got = 0, i = first;
    for (; i < req->nargs && rib_arg_is_numeric(&req->args[i]); i++) {
        int k;
        const double *v = rib_arg_numbers(req, &req->args[i], &k);
        for (int j = 0; j < k; j++, got++)
            if (got < n)
                out[got] = v[j];
    }
    if (got != n) {
        rib_error(p, req, req->pos, "expected %d number%s (%s), got %d", n,
                  n == 1 ? "" : "s", what, got);
        return -1;
    }
    return i;
}

/* The whole numbers >= min of array argument i (NULL with an error). An
 * empty array gives a non-NULL result with *count 0 when allow_empty. */
int *rib_read_ints(rib_parser *p, const rib_request *req, int i, int min, bool allow_empty,
                    int *count, const char *what)
{
    if (i >= req->nargs || !rib_arg_is_numeric(&req->args[i])) {
        rib_error(p, req, i < req->nargs ? req->args[i].pos : req->pos,
                  "missing %s (an array of whole numbers)", what);
        return NULL;
    }
    int n;
    const double *v = rib_arg_numbers(req, &req->args[i], &n);
    if (n == 0 && !allow_empty) {
        rib_error(p, req, req->args[i].pos, "%s is empty", what);
        return NULL;
    }
    int *out = xrealloc(NULL, (size_t)(n + 1) * sizeof *out);
    for (int k = 0; k < n; k++) {
        if (!(v[k] == floor(v[k]) && v[k] >= min && v[k] <= 1e9)) {
            rib_error(p, req, req->args[i].pos, "%s: entry %d is %g, expected a whole number "
                      ">= %d", what, k, v[k], min);
            free(out);
            return NULL;
        }
        out[k] = (int)v[k];
    }
    *count = n;
    return out;
}

const char *rib_read_string(rib_parser *p, const rib_request *req, int i, const char *what)
{
    if (i >= req->nargs) {
        rib_error(p, req, req->pos, "missing %s (a string)", what);
        return NULL;
    }
    const rib_arg *arg = &req->args[i];
    if (!rib_arg_is_string(arg) || arg->count != 1) {
        rib_error(p, req, arg->pos, "%s must be a string, got %s", what, rib_arg_describe(arg));
        return NULL;
    }
    return rib_arg_string(req, arg);
}

bool rib_no_more_args(rib_parser *p, const rib_request *req, int i)
{
    if (i >= req->nargs)
        return true;
    rib_error(p, req, req->args[i].pos, "unexpected extra argument (%s)",
              rib_arg_describe(&req->args[i]));
    return false;
}

/* ---------------------------------------------------------------------- */
/* growing the scene                                                       */
/* ---------------------------------------------------------------------- */

static void *grow(void *items, int count, int *cap, size_t size)
{
    if (count < *cap)
        return items;
    *cap = *cap ? 2 * *cap : 8;
    return xrealloc(items, (size_t)*cap * size);
}

scene_light *rib_add_light(rib_parser *p)
{
    scene *s = p->scene;
    s->lights = grow(s->lights, s->nlights, &p->lights_cap, sizeof *s->lights);
    memset(&s->lights[s->nlights], 0, sizeof *s->lights);
    return &s->lights[s->nlights++];
}

scene_object *rib_add_object(rib_parser *p)
{
    scene *s = p->scene;
    s->objects = grow(s->objects, s->nobjects, &p->objects_cap, sizeof *s->objects);
    memset(&s->objects[s->nobjects], 0, sizeof *s->objects);
    s->objects[s->nobjects].instance_of = -1;
    return &s->objects[s->nobjects++];
}

scene_shader *rib_add_shader(rib_parser *p)
{
    scene *s = p->scene;
    s->shaders = grow(s->shaders, s->nshaders, &p->shaders_cap, sizeof *s->shaders);
    memset(&s->shaders[s->nshaders], 0, sizeof *s->shaders);
    return &s->shaders[s->nshaders++];
}

scene_space *rib_add_space(rib_parser *p)
{
    scene *s = p->scene;
    s->spaces = grow(s->spaces, s->nspaces, &p->spaces_cap, sizeof *s->spaces);
    memset(&s->spaces[s->nspaces], 0, sizeof *s->spaces);
    return &s->spaces[s->nspaces++];
}

/* ---------------------------------------------------------------------- */
/* blocks                                                                  */
/* ---------------------------------------------------------------------- */

static const char *begin_name(rib_block_kind kind)
{
    static const char *const names[] = { "FrameBegin", "WorldBegin", "AttributeBegin",
                                         "TransformBegin", "ObjectBegin" };
    return names[kind];
}

static const char *end_name(rib_block_kind kind)
{
    static const char *const names[] = { "FrameEnd", "WorldEnd", "AttributeEnd",
                                         "TransformEnd", "ObjectEnd" };
    return names[kind];
}

bool rib_push_block(rib_parser *p, const rib_request *req, rib_block_kind kind)
{
    if (p->nblocks >= RIB_MAX_BLOCKS) {
        if (!p->blocks_overflow)
            rib_error(p, req, req->pos, "blocks nested too deeply (more than %d open at once): "
                      "flatten the nesting of AttributeBegin/TransformBegin blocks",
                      RIB_MAX_BLOCKS);
        p->blocks_overflow = true;
        return false;
    }
    p->blocks = grow(p->blocks, p->nblocks, &p->blocks_cap, sizeof *p->blocks);
    const rib_block *outer = p->nblocks > 0 ? &p->blocks[p->nblocks - 1] : NULL;
    int index = p->nblocks++;
    rib_block *b = &p->blocks[index];
    b->kind = kind;
    b->pos = req->pos;
    b->object_def = -1;
    b->object_block = kind == RIB_BLOCK_OBJECT ? index : outer ? outer->object_block : -1;
    b->frame_world_block = outer && outer->frame_world_block >= 0 ? outer->frame_world_block
                           : kind == RIB_BLOCK_FRAME || kind == RIB_BLOCK_WORLD ? index : -1;
    rib_attributes_copy(&b->saved, &p->attr);
    return true;
}

/* The end of the world: it must hold an object (unless the objects it
 * tried to hold were wrong: those have their own errors). `who` names the
 * request that ends it (WorldEnd, or WorldBegin when never closed). */
static void world_finish(rib_parser *p, const char *who, sl_pos pos)
{
    p->in_world = false;
    p->world_done = true;
    if (p->scene->nobjects == 0 && !p->primitives_tried)
        sl_diag_error(p->diag, pos,
                      "%s: the world has no objects (add a surface between WorldBegin and "
                      "WorldEnd, e.g. Sphere 1 -1 1 360)", who);
}

/* Pops the innermost block, restoring what it saved. */
static void pop_block(rib_parser *p, const char *who, sl_pos pos)
{
    rib_block *b = &p->blocks[--p->nblocks];
    if (b->kind == RIB_BLOCK_TRANSFORM) {
        p->attr.ctm = b->saved.ctm;
        rib_attributes_clear(&b->saved);
    } else {
        rib_attributes_clear(&p->attr);
        p->attr = b->saved;
    }
    if (b->kind == RIB_BLOCK_WORLD)
        world_finish(p, who, pos);
}

/* Blocks of `kind` cannot be closed from inside these. */
static bool is_boundary(rib_block_kind kind, rib_block_kind inner)
{
    if (kind == RIB_BLOCK_ATTRIBUTE || kind == RIB_BLOCK_TRANSFORM)
        return inner == RIB_BLOCK_WORLD || inner == RIB_BLOCK_FRAME || inner == RIB_BLOCK_OBJECT;
    if (kind == RIB_BLOCK_WORLD || kind == RIB_BLOCK_OBJECT)
        return inner == RIB_BLOCK_FRAME || (kind == RIB_BLOCK_OBJECT && inner == RIB_BLOCK_WORLD);
    return false;
}

/* An ...End request: closes the innermost open block of `kind`, with an
 * error for each block left open inside it. */
void rib_close_block(rib_parser *p, const rib_request *req, rib_block_kind kind)
{
    int i = p->nblocks - 1;
    while (i >= 0 && p->blocks[i].kind != kind && !is_boundary(kind, p->blocks[i].kind))
        i--;
    if (i < 0 || p->blocks[i].kind != kind) {
        rib_error(p, req, req->pos, "there is no open %s to close", begin_name(kind));
        return;
    }
    while (p->nblocks - 1 > i) {
        const rib_block *b = &p->blocks[p->nblocks - 1];
        rib_error(p, req, req->pos, "the %s opened at %s:%d:%d is not closed (missing %s)",
                  begin_name(b->kind), b->pos.file, b->pos.line, b->pos.col, end_name(b->kind));
        pop_block(p, req->name, req->pos);
    }
    pop_block(p, req->name, req->pos);
}

/* ---------------------------------------------------------------------- */
/* block requests                                                          */
/* ---------------------------------------------------------------------- */

/* Every FrameBegin block is a frame; the one with index p->frame_select is
 * read and the others are skipped whole (archives they read included).
 * Each frame's number is recorded (scene.frame_numbers): the RIB's, or
 * the previous one plus 1 when it gives none. */
static void frame_begin(rib_parser *p, const rib_request *req)
{
    bool one_number = req->nargs == 1 && req->args[0].kind == RIB_ARG_NUMBER;
    if (!req->broken && req->nargs > 0 && !one_number)
        rib_error(p, req, req->pos, "takes one argument, the frame number");
    int fw = p->nblocks > 0 ? p->blocks[p->nblocks - 1].frame_world_block : -1;
    if (fw >= 0) {
        const rib_block *b = &p->blocks[fw];
        rib_error(p, req, req->pos, "not allowed inside the %s opened at %s:%d:%d",
                  begin_name(b->kind), b->pos.file, b->pos.line, b->pos.col);
        return;
    }
    scene *s = p->scene;
    int number = s->nframes > 0 ? s->frame_numbers[s->nframes - 1] + 1 : 1;
    if (one_number && !req->broken) {
        double v = req->nums[req->args[0].first];
        if (v != floor(v) || v < 0 || v > 99999999) {
            rib_error(p, req, req->args[0].pos, "the frame number must be a whole number "
                      "0..99999999, got %g", v);
            return;
        }
        number = (int)v;
    }
    s->frame_numbers = grow(s->frame_numbers, s->nframes, &p->frames_cap,
                            sizeof *s->frame_numbers);
    int index = s->nframes;
    s->frame_numbers[s->nframes++] = number;
    if (index != p->frame_select) {
        p->skipping_frame = true;
        p->skip_depth = 0;
        return;
    }
    s->frame = index;
    s->frame_number = number;
    if (!rib_push_block(p, req, RIB_BLOCK_FRAME))
        return;
}

static void frame_end(rib_parser *p, const rib_request *req)
{
    rib_close_block(p, req, RIB_BLOCK_FRAME);
}

static void world_begin(rib_parser *p, const rib_request *req)
{
    if (p->in_world) {
        rib_error(p, req, req->pos, "the world opened at %s:%d:%d is still open (missing WorldEnd)",
                  p->world_pos.file, p->world_pos.line, p->world_pos.col);
        return;
    }
    if (p->world_done) {
        rib_error(p, req, req->pos, "a scene has one world, and the one at %s:%d:%d is closed "
                  "(put all objects in it)", p->world_pos.file, p->world_pos.line,
                  p->world_pos.col);
        return;
    }
    rib_options_finish(p, req);
    scene_camera *cam = &p->scene->camera;
    cam->camera_from_world = p->attr.ctm;
    if (!mat4_invert(&cam->camera_from_world, &cam->world_from_camera))
        rib_error(p, req, req->pos, "the camera transform is singular (check the Scale, "
                  "Transform and ConcatTransform requests before WorldBegin)");
    p->scene->shading_rate = p->attr.shading_rate;
    rib_shaders_finish(p);
    if (!rib_push_block(p, req, RIB_BLOCK_WORLD))
        return;
    p->attr.ctm = mat4_identity();
    p->in_world = p->world_seen = true;
    p->world_pos = req->pos;
}

static void world_end(rib_parser *p, const rib_request *req)
{
    rib_close_block(p, req, RIB_BLOCK_WORLD);
}

static void attribute_begin(rib_parser *p, const rib_request *req)
{
    if (!rib_push_block(p, req, RIB_BLOCK_ATTRIBUTE))
        return;
}

static void attribute_end(rib_parser *p, const rib_request *req)
{
    rib_close_block(p, req, RIB_BLOCK_ATTRIBUTE);
}

static void transform_begin(rib_parser *p, const rib_request *req)
{
    if (!rib_push_block(p, req, RIB_BLOCK_TRANSFORM))
        return;
}

static void transform_end(rib_parser *p, const rib_request *req)
{
    rib_close_block(p, req, RIB_BLOCK_TRANSFORM);
}

/* ---------------------------------------------------------------------- */
/* the table of requests                                                   */
/* ---------------------------------------------------------------------- */

typedef enum where {
    ANYWHERE,
    OPTIONS,        /* before WorldBegin */
    WORLD,          /* between WorldBegin and WorldEnd */
    PRIMITIVE,      /* a base surface: in the world */
    BLOCK,          /* block structure: run even when malformed */
    BLOCK_WORLD,    /* block structure inside the world (ObjectBegin/End) */
} where;

typedef struct request_def {
    const char *name;
    rib_request_fn fn;
    where where;
} request_def;

/* Shader "name" "handle" (RSL 2 co-shaders, PRMan 13.5): not supported;
 * the shaders that would look the handle up cannot compile either. */
static void rib_coshader(rib_parser *p, const rib_request *req)
{
    rib_error(p, req, req->pos, "RSL 2 co-shaders are not supported: aafarm compiles "
              "each shader on its own; put the co-shader's code in a function of the shader "
              "that uses it");
}

static const request_def requests[] = {
    { "version", rib_version, ANYWHERE },
    { "Display", rib_display, OPTIONS },
    { "Format", rib_format, OPTIONS },
    { "Projection", rib_projection, OPTIONS },
    { "ScreenWindow", rib_screen_window, OPTIONS },
    { "Clipping", rib_clipping, OPTIONS },
    { "PixelSamples", rib_pixel_samples, OPTIONS },
    { "PixelFilter", rib_pixel_filter, OPTIONS },
    { "Exposure", rib_exposure, OPTIONS },
    { "Option", rib_option, OPTIONS },
    { "FrameBegin", frame_begin, BLOCK },
    { "FrameEnd", frame_end, BLOCK },
    { "WorldBegin", world_begin, BLOCK },
    { "WorldEnd", world_end, BLOCK },
    { "AttributeBegin", attribute_begin, BLOCK },
    { "AttributeEnd", attribute_end, BLOCK },
    { "TransformBegin", transform_begin, BLOCK },
    { "TransformEnd", transform_end, BLOCK },
    { "ShadingRate", rib_shading_rate, ANYWHERE },
    { "Identity", rib_identity, ANYWHERE },
    { "Translate", rib_translate, ANYWHERE },
    { "Rotate", rib_rotate, ANYWHERE },
    { "Scale", rib_scale, ANYWHERE },
    { "ConcatTransform", rib_concat_transform, ANYWHERE },
    { "Transform", rib_transform, ANYWHERE },
    { "CoordinateSystem", rib_coordinate_system, WORLD },
    { "CoordSysTransform", rib_coord_sys_transform, WORLD },
    { "LightSource", rib_light_source, ANYWHERE },   /* before WorldBegin: warned */
    { "Illuminate", rib_illuminate, WORLD },
    { "Surface", rib_surface, ANYWHERE },
    { "Displacement", rib_displacement, ANYWHERE },
    { "Shader", rib_coshader, ANYWHERE },
    { "Color", rib_color, ANYWHERE },
    { "Opacity", rib_opacity, ANYWHERE },
    { "Attribute", rib_attribute, ANYWHERE },
    { "Declare", rib_declare, ANYWHERE },
    { "Sides", rib_sides, ANYWHERE },
    { "Orientation", rib_orientation, ANYWHERE },
    { "ReverseOrientation", rib_reverse_orientation, ANYWHERE },
    { "Sphere", rib_sphere, PRIMITIVE },
    { "Disk", rib_disk, PRIMITIVE },
    { "Cylinder", rib_cylinder, PRIMITIVE },
    { "Cone", rib_cone, PRIMITIVE },
    { "Torus", rib_torus, PRIMITIVE },
    { "Hyperboloid", rib_hyperboloid, PRIMITIVE },
    { "Paraboloid", rib_paraboloid, PRIMITIVE },
    { "Polygon", rib_polygon, PRIMITIVE },
    { "Patch", rib_patch, PRIMITIVE },
    { "PointsPolygons", rib_points_polygons, PRIMITIVE },
    { "SubdivisionMesh", rib_subdivision_mesh, PRIMITIVE },
    { "HierarchicalSubdivisionMesh", rib_hierarchical_subdivision_mesh, PRIMITIVE },
    { "PointsGeneralPolygons", rib_points_general_polygons, PRIMITIVE },
    { "GeneralPolygon", rib_general_polygon, PRIMITIVE },
    { "PatchMesh", rib_patch_mesh, PRIMITIVE },
    { "Basis", rib_basis, ANYWHERE },
    { "TextureCoordinates", rib_texture_coordinates, ANYWHERE },
    { "NuPatch", rib_nu_patch, PRIMITIVE },
    { "TrimCurve", rib_trim_curve, ANYWHERE },
    { "ReadArchive", rib_read_archive, ANYWHERE },
    { "ArchiveBegin", rib_archive_begin, BLOCK },     /* rib_inline_archive.c */
    { "ArchiveEnd", rib_archive_end, BLOCK },
    { "ObjectBegin", rib_object_begin, BLOCK_WORLD },
    { "ObjectEnd", rib_object_end, BLOCK_WORLD },
    { "ObjectInstance", rib_object_instance, WORLD },
    { "DepthOfField", rib_depth_of_field, OPTIONS },
};

enum { NREQUESTS = sizeof requests / sizeof requests[0] };

/* The table by name: an open-addressed hash of the requests' indices
 * (+1; 0: empty), made once per process. A scene of a million instances
 * is some ten million requests: a look-up is one hash and one strcmp. */
enum { REQUEST_SLOTS = 256 };
static unsigned char request_slots[REQUEST_SLOTS];
static pthread_once_t request_slots_once = PTHREAD_ONCE_INIT;

static unsigned request_hash(const char *name)
{
    unsigned h = 2166136261u;          /* FNV-1a */
    for (const unsigned char *c = (const unsigned char *)name; *c; c++)
        h = (h ^ *c) * 16777619u;
    return h;
}

static void make_request_slots(void)
{
    _Static_assert(NREQUESTS < REQUEST_SLOTS / 2 && NREQUESTS < 255, "the table has room");
    for (int i = 0; i < NREQUESTS; i++) {
        unsigned k = request_hash(requests[i].name) % REQUEST_SLOTS;
        while (request_slots[k])
            k = (k + 1) % REQUEST_SLOTS;
        request_slots[k] = (unsigned char)(i + 1);
    }
}

static const request_def *find_request(const char *name)
{
    pthread_once(&request_slots_once, make_request_slots);
    for (unsigned k = request_hash(name) % REQUEST_SLOTS; request_slots[k];
         k = (k + 1) % REQUEST_SLOTS)
        if (strcmp(requests[request_slots[k] - 1].name, name) == 0)
            return &requests[request_slots[k] - 1];
    return NULL;
}

/* The known request closest to an unknown name (util/suggest.h), or NULL. */
static const request_def *closest_request(const char *name)
{
    const char *names[NREQUESTS];
    for (int i = 0; i < NREQUESTS; i++)
        names[i] = requests[i].name;
    const char *near = suggest_closest(name, names, NREQUESTS);
    return near ? find_request(near) : NULL;
}

/* One warning per unknown request name, with the closest known name when
 * one is near ("Sphere" for "sphere" or "Spere"); past
 * RIB_MAX_UNKNOWN_NAMES names (binary or garbage input) one last warning
 * says that no more come. */
enum { RIB_MAX_UNKNOWN_NAMES = 100 };
static void unknown_request(rib_parser *p, const rib_request *req, const request_def *near)
{
    for (int i = 0; i < p->nwarned; i++)
        if (strcmp(p->warned[i], req->name) == 0)
            return;
    if (p->nwarned == RIB_MAX_UNKNOWN_NAMES) {
        if (!p->unknown_overflow)
            rib_warning(p, req, req->pos, "unknown request, ignored with its arguments; "
                        "%d unknown names so far: not reporting more", p->nwarned);
        p->unknown_overflow = true;
        return;
    }
    p->warned = xrealloc(p->warned, (size_t)(p->nwarned + 1) * sizeof *p->warned);
    p->warned[p->nwarned++] = xstrndup(req->name, strlen(req->name));
    if (near)
        rib_warning(p, req, req->pos, "unknown request, ignored with its arguments "
                    "(did you mean %s?)", near->name);
    else
        rib_warning(p, req, req->pos, "unknown request, ignored with its arguments");
}

/* False (with an error) when the request may not appear here. */
static bool allowed_here(rib_parser *p, const rib_request *req, where w)
{
    if (w == OPTIONS && (p->in_world || p->world_done)) {
        rib_option_in_world(p, req);   /* warned, as other renderers do */
        return false;
    }
    if ((w == WORLD || w == PRIMITIVE || w == BLOCK_WORLD) && !p->in_world) {
        rib_error(p, req, req->pos, "must come between WorldBegin and WorldEnd");
        return false;
    }
    return true;
}

/* The requests that change only the current transform. */
static bool is_transform(rib_request_fn fn)
{
    return fn == rib_identity || fn == rib_translate || fn == rib_rotate || fn == rib_scale ||
           fn == rib_concat_transform || fn == rib_transform;
}

/* While skipping a later frame, only the frame nesting matters. */
static void skip_frame_request(rib_parser *p, const rib_request *req)
{
    if (strcmp(req->name, "FrameBegin") == 0)
        p->skip_depth++;
    else if (strcmp(req->name, "FrameEnd") == 0 && p->skip_depth-- == 0)
        p->skipping_frame = false;
}

static void dispatch(rib_parser *p, const rib_request *req)
{
    if (p->skipping_frame) {
        skip_frame_request(p, req);
        return;
    }
    if (rib_inline_archive_filter(p, req))   /* recorded, or an inline archive read */
        return;
    if (rib_motion_filter(p, req))
        return;
    const request_def *def = find_request(req->name);
    rib_request misspelt;
    if (!def) {
        if (rib_ignored_request(p, req))
            return;
        const request_def *near = closest_request(req->name);
        if (!near || (near->where != BLOCK && near->where != BLOCK_WORLD)) {
            unknown_request(p, req, near);
            return;
        }
        /* A misspelt block opener or closer ("WorldBegn") is an error, and
         * is read as the block request it is closest to: skipping it would
         * bury it under an error for every request of the block. */
        rib_error(p, req, req->pos, "unknown request (did you mean %s?); read as %s for the "
                  "rest of the checks", near->name, near->name);
        misspelt = *req;
        misspelt.name = (char *)near->name;
        req = &misspelt;
        def = near;
    }
    if (def->where == PRIMITIVE && p->in_world)
        p->primitives_tried = true;
    bool block = def->where == BLOCK || def->where == BLOCK_WORLD;
    if (req->broken && !block)
        return;
    if (!allowed_here(p, req, def->where))
        return;
    if (block && strcmp(req->name, "FrameBegin") != 0 && strcmp(req->name, "ObjectBegin") != 0
        && strcmp(req->name, "ArchiveBegin") != 0 && !req->broken)
        rib_no_more_args(p, req, 0);
    rib_object_def *defining = rib_defining(p);
    if (defining && !block && def->where != PRIMITIVE && def->fn != rib_read_archive &&
        def->fn != rib_declare && def->fn != rib_basis && !is_transform(def->fn) &&
        !defining->warned) {
        rib_warning(p, req, req->pos, "inside an object definition only surfaces and their "
                    "transforms are kept; instances take the attributes current at "
                    "ObjectInstance");
        defining->warned = true;
    }
    def->fn(p, req);
}

/* ---------------------------------------------------------------------- */
/* the end of the text                                                     */
/* ---------------------------------------------------------------------- */

static void close_open_blocks(rib_parser *p)
{
    while (p->nblocks > 0) {
        const rib_block *b = &p->blocks[p->nblocks - 1];
        const char *who = begin_name(b->kind);
        sl_pos pos = b->pos;
        sl_diag_error(p->diag, pos, "%s: this block is never closed (missing %s)", who,
                      end_name(b->kind));
        pop_block(p, who, pos);
    }
}

/* "scenes" for "scenes/wave.rib", "." for "wave.rib". */
static char *rib_folder(const char *file)
{
    const char *slash = strrchr(file, '/');
    if (!slash)
        return xstrndup(".", 1);
    if (slash == file)
        return xstrndup("/", 1);
    return xstrndup(file, (size_t)(slash - file));
}

static void add_path(char ***path, int *npath, char *dir)
{
    for (int i = 0; i < *npath; i++)
        if (strcmp((*path)[i], dir) == 0) {
            free(dir);
            return;
        }
    *path = xrealloc(*path, (size_t)(*npath + 2) * sizeof **path);
    (*path)[(*npath)++] = dir;
    (*path)[*npath] = NULL;
}

/* The Option dirs (relative ones are relative to the RIB's folder), then
 * the RIB's folder itself: the shader path, and the same way the texture
 * path. */
static void finish_one_path(const char *folder, char **dirs, int ndirs, char ***path,
                            int *npath)
{
    for (int i = 0; i < ndirs; i++) {
        const char *dir = dirs[i];
        if (dir[0] == '/' || strcmp(folder, ".") == 0) {
            add_path(path, npath, sl_source_normalize(dir));
            continue;
        }
        size_t n = strlen(folder) + strlen(dir) + 2;
        char *joined = xrealloc(NULL, n);
        snprintf(joined, n, "%s/%s", folder, dir);
        add_path(path, npath, sl_source_normalize(joined));
        free(joined);
    }
    add_path(path, npath, sl_source_normalize(folder));
}

static void finish_search_path(rib_parser *p)
{
    scene *s = p->scene;
    char *folder = rib_folder(s->file);
    finish_one_path(folder, p->shader_path, p->nshader_path, &s->search_path,
                    &s->nsearch_path);
    finish_one_path(folder, p->texture_path, p->ntexture_path, &s->texture_path,
                    &s->ntexture_path);
    free(folder);
}

static void add_shader_name(scene *s, const char *name)
{
    for (int i = 0; i < s->nshader_names; i++)
        if (strcmp(s->shader_names[i], name) == 0)
            return;
    s->shader_names = xrealloc(s->shader_names,
                                  (size_t)(s->nshader_names + 1) * sizeof *s->shader_names);
    s->shader_names[s->nshader_names++] = xstrndup(name, strlen(name));
}

/* The names of the shaders the objects and lights call, in the order of
 * their first call; each shader call looked at once, however many objects
 * share it. */
static void finish_shader_names(scene *s)
{
    unsigned char *seen = xcalloc((size_t)(s->nshaders > 0 ? s->nshaders : 1), 1);
    for (int i = 0; i < s->nobjects; i++) {
        const scene_shader *calls[2] = { scene_object_surface(s, &s->objects[i]),
                                         scene_object_displacement(s, &s->objects[i]) };
        for (int k = 0; k < 2; k++) {
            if (!calls[k] || seen[calls[k] - s->shaders])
                continue;
            seen[calls[k] - s->shaders] = 1;
            add_shader_name(s, calls[k]->name);
        }
    }
    free(seen);
    for (int i = 0; i < s->nlights; i++)
        if (s->lights[i].kind == SCENE_SHADER_LIGHT)
            add_shader_name(s, s->shaders[s->lights[i].shader].name);
}

static void finish(rib_parser *p)
{
    if (p->skipping_frame)
        p->skipping_frame = false;
    if (p->in_motion)
        sl_diag_error(p->diag, p->motion_pos, "MotionBegin: this block is never closed "
                      "(missing MotionEnd)");
    rib_inline_archive_finish(p);
    close_open_blocks(p);
    int nframes = p->scene->nframes;
    if (p->scanning)
        return;
    if (p->frame_select > 0 && p->frame_select >= nframes) {
        sl_pos whole = { p->file, 0, 0 };
        sl_diag_error(p->diag, whole, "frame index %d asked for, but the file has %d frame%s "
                      "(FrameBegin blocks)", p->frame_select, nframes, nframes == 1 ? "" : "s");
        return;
    }
    if (!p->world_seen) {
        sl_pos whole = { p->file, 0, 0 };
        sl_diag_error(p->diag, whole, "the scene has no world (add WorldBegin, then the "
                      "lights and objects, then WorldEnd)");
    }
    finish_search_path(p);
    finish_shader_names(p->scene);
}

/* ---------------------------------------------------------------------- */
/* entry points                                                            */
/* ---------------------------------------------------------------------- */

static scene *scene_new(const char *file)
{
    scene *s = xrealloc(NULL, sizeof *s);
    memset(s, 0, sizeof *s);
    s->file = xstrndup(file, strlen(file));
    s->camera.fov = 90;
    s->camera.near_clip = 1e-10;
    s->camera.far_clip = 1e30;
    s->camera.pixel_aspect = 1;
    s->camera.camera_from_world = s->camera.world_from_camera = mat4_identity();
    s->pixel_samples[0] = s->pixel_samples[1] = 2;
    s->shading_rate = 1;
    s->exposure_gain = s->exposure_gamma = 1;
    s->filter.kind = SCENE_FILTER_GAUSSIAN;
    s->filter.xwidth = s->filter.ywidth = 2;
    s->frame_number = 1;
    s->trace_maxdepth = -1;
    return s;
}

static void parser_clear(rib_parser *p)
{
    while (p->nblocks > 0)
        rib_attributes_clear(&p->blocks[--p->nblocks].saved);
    free(p->blocks);
    rib_attributes_clear(&p->attr);
    for (int i = 0; i < p->nstrings; i++)
        free(p->strings[i]);
    free(p->strings);
    for (int i = 0; i < p->nwarned; i++)
        free(p->warned[i]);
    free(p->warned);
    for (int i = 0; i < p->nshader_path; i++)
        free(p->shader_path[i]);
    free(p->shader_path);
    for (int i = 0; i < p->narchive_path; i++)
        free(p->archive_path[i]);
    free(p->archive_path);
    for (int i = 0; i < p->ntexture_path; i++)
        free(p->texture_path[i]);
    free(p->texture_path);
    rib_object_defs_clear(p);
    free(p->mesh_counted);
    rib_inline_archives_destroy(p);
    rib_decls_destroy(&p->decls);
    rib_reader_destroy(&p->reader);
}

/* Is the parse to stop for the program's flag (a signal)? Looked at every
 * RIB_CANCEL_EVERY requests; once set, reported once (at req) and kept. */
static bool cancelled(rib_parser *p, const rib_request *req)
{
    if (!p->cancelled && p->cancel && ++p->requests % RIB_CANCEL_EVERY == 0 &&
        atomic_load_explicit(p->cancel, memory_order_relaxed)) {
        sl_diag_error(p->diag, req->pos, "interrupted (SIGINT/SIGTERM) while reading the scene");
        p->cancelled = true;
    }
    return p->cancelled;
}

bool rib_parser_step(rib_parser *p, const rib_request *req)
{
    if (sl_diag_full(p->diag) || p->blocks_overflow || p->cancelled || cancelled(p, req))
        return false;
    dispatch(p, req);
    return true;
}

void rib_parser_run(rib_parser *p)
{
    rib_request *req;
    while (!sl_diag_full(p->diag) && !p->blocks_overflow && !p->cancelled &&
           (req = rib_reader_next(p->reader)) && !cancelled(p, req))
        dispatch(p, req);
}

static void parse_all(rib_parser *p)
{
    rib_parser_run(p);
    if (!sl_diag_full(p->diag) && !p->blocks_overflow && !p->cancelled)
        finish(p);
}

scene *scene_parse(const char *file, const char *text, size_t len, sl_diag *diag)
{
    sl_source_set *archives = scene_archive_set_new();
    scene *s = scene_parse_archives(file, text, len, archives, diag);
    sl_source_set_destroy(&archives);
    return s;
}

scene *scene_parse_archives(const char *file, const char *text, size_t len,
                            sl_source_set *archives, sl_diag *diag)
{
    return scene_parse_limited(file, text, len, archives, SCENE_MAX_OBJECTS, diag);
}

scene *scene_parse_limited(const char *file, const char *text, size_t len,
                           sl_source_set *archives, int max_objects, sl_diag *diag)
{
    return scene_parse_frame(file, text, len, archives, max_objects, 0, NULL, diag);
}

static scene *parse_frame(const char *file, const char *text, size_t len,
                          sl_source_set *archives, int max_objects, int frame, bool scanning,
                          const scene_check *check, int threads, const atomic_int *cancel,
                          sl_diag *diag);

scene *scene_parse_frame(const char *file, const char *text, size_t len,
                         sl_source_set *archives, int max_objects, int frame,
                         const atomic_int *cancel, sl_diag *diag)
{
    return parse_frame(file, text, len, archives, max_objects, frame, false, NULL, 1, cancel,
                       diag);
}

scene *scene_parse_frame_threads(const char *file, const char *text, size_t len,
                                 sl_source_set *archives, int max_objects, int frame,
                                 int threads, const atomic_int *cancel, sl_diag *diag)
{
    return parse_frame(file, text, len, archives, max_objects, frame, false, NULL, threads,
                       cancel, diag);
}

scene *scene_check_frame(const char *file, const char *text, size_t len,
                         sl_source_set *archives, int max_objects, int frame,
                         const scene_check *check, const atomic_int *cancel, sl_diag *diag)
{
    return parse_frame(file, text, len, archives, max_objects, frame, false, check, 1, cancel,
                       diag);
}

int scene_scan_frames(const char *file, const char *text, size_t len,
                      sl_source_set *archives, int **numbers, const atomic_int *cancel,
                      sl_diag *diag)
{
    *numbers = NULL;
    scene *s = parse_frame(file, text, len, archives, SCENE_MAX_OBJECTS, INT_MAX, true, NULL,
                           1, cancel, diag);
    if (!s)
        return -1;
    int n = s->nframes;
    *numbers = s->frame_numbers;
    s->frame_numbers = NULL;
    scene_destroy(&s);
    return n;
}

static scene *parse_frame(const char *file, const char *text, size_t len,
                          sl_source_set *archives, int max_objects, int frame, bool scanning,
                          const scene_check *check, int threads, const atomic_int *cancel,
                          sl_diag *diag)
{
    if (!file || !*file)
        file = "<scene>";
    if (!text)
        len = 0, text = "";
    sl_source_set *set = sl_source_set_new();
    if (len >= sl_source_set_max_size(set))
        sl_source_set_set_max_size(set, len + 1);
    sl_source_set_add(set, file, text, len);
    sl_diag_set_sources(diag, set);

    int errors_before = sl_diag_error_count(diag);
    rib_parser p;
    memset(&p, 0, sizeof p);
    p.diag = diag;
    p.archives = archives;
    p.diag_sources = set;
    p.max_objects = max_objects;
    p.frame_select = frame < 0 ? 0 : frame;
    p.scanning = scanning;
    p.cancel = cancel;
    p.threads = threads < 1 ? 1 : threads;
    p.check = check;
    p.scene = scene_new(file);
    p.scene->checked = check != NULL;
    p.file = p.scene->file;
    p.decls = rib_decls_new();
    p.reader = rib_reader_new(p.file, text, len, diag);
    rib_attributes_init(&p.attr);
    parse_all(&p);
    parser_clear(&p);

    sl_diag_set_sources(diag, NULL);
    sl_source_set_destroy(&set);
    if (sl_diag_error_count(diag) > errors_before)
        scene_destroy(&p.scene);
    else if (p.scene->nobjects > 0)    /* the growth's slack: up to half a million instances' */
        p.scene->objects = xreallocarray(p.scene->objects, (size_t)p.scene->nobjects,
                                         sizeof *p.scene->objects);
    return p.scene;
}

scene *scene_load(const char *path, sl_diag *diag)
{
    sl_source_set *set = sl_source_set_new();
    scene *s = NULL;
    if (sl_source_set_load_file(set, path, path, diag) == 0) {
        const sl_source *src = sl_source_set_at(set, 0);
        s = scene_parse(path, src->text, src->len, diag);
    }
    sl_source_set_destroy(&set);
    return s;
}
