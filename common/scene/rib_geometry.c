/*
 * rib_geometry.c: the geometric primitives of RI Specification 3.2 §5:
 * the quadrics of §5.2 (Sphere, Disk, Cylinder, Cone, Torus, Hyperboloid,
 * Paraboloid), Polygon (§5.1, convex planar) and Patch "bilinear" (§5.3).
 * Each becomes one scene_object: its geom_surface in object space (angles
 * converted from the RIB's degrees to radians), its transforms and the
 * current attributes (a scene_attributes record, the previous object's
 * when equal).
 *
 * Validation is geom_surface_prepare's (common/geom), whose reason goes
 * into the message ("Sphere: sphere radius must be > 0, got -1"); when the
 * library is built without common/geom, basic checks here stand in.
 */
#include "scene/rib_parser.h"
#include "scene/rib_primvar.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double radians(double degrees) { return degrees * (M_PI / 180.0); }

/* ---------------------------------------------------------------------- */
/* validation                                                              */
/* ---------------------------------------------------------------------- */

#ifndef SCENE_HAVE_GEOM
/* Stand-in checks for builds without common/geom. */
static bool basic_check(const geom_surface *s, char *err, size_t errsz)
{
    const char *what = NULL;
    switch (s->kind) {
    case GEOM_SPHERE: case GEOM_CYLINDER:
        if (!(s->radius > 0)) what = "radius must be > 0";
        else if (s->zmin == s->zmax) what = "zmin must differ from zmax";
        break;
    case GEOM_DISK: case GEOM_CONE:
        if (!(s->radius > 0)) what = "radius must be > 0";
        break;
    case GEOM_PARABOLOID:
        if (!(s->rmax > 0)) what = "rmax must be > 0";
        else if (s->zmin == s->zmax) what = "zmin must differ from zmax";
        break;
    case GEOM_TORUS:
        if (!(s->minorrad > 0)) what = "minor radius must be > 0";
        else if (s->phimin == s->phimax) what = "phimin must differ from phimax";
        break;
    case GEOM_HYPERBOLOID:
        if (s->point1.x == s->point2.x && s->point1.y == s->point2.y &&
            s->point1.z == s->point2.z)
            what = "point1 and point2 must differ";
        break;
    default:
        break;
    }
    bool theta_ok = s->thetamax != 0 && fabs(s->thetamax) <= 2 * M_PI + 1e-9;
    if (!what && s->kind < GEOM_POLYGON && !theta_ok)
        what = "thetamax must be non-zero and at most 360 degrees";
    if (what)
        err_set(err, errsz, "%s", what);
    return what == NULL;
}
#endif

static bool prepare_surface(geom_surface *s, char *err, size_t errsz)
{
#ifdef SCENE_HAVE_GEOM
    return geom_surface_prepare(s, err, errsz);
#else
    return basic_check(s, err, errsz);
#endif
}

/* ---------------------------------------------------------------------- */
/* the object                                                              */
/* ---------------------------------------------------------------------- */

/* The flip of Ng the orientation asks for: "outside" keeps the normals
 * geom computes (outward for quadrics), "inside" flips them, "lh"/"rh"
 * flip when the object's space has the other handedness (camera space is
 * left-handed; a negative determinant mirrors). */
static bool reverse_normals(scene_orientation o, const mat4 *object_to_camera)
{
    bool left_handed = mat4_det3(object_to_camera) > 0;
    switch (o) {
    case SCENE_OUTSIDE: return false;
    case SCENE_INSIDE:  return true;
    case SCENE_LH:      return !left_handed;
    case SCENE_RH:      return left_handed;
    }
    return false;
}

/* The previous object's block when it equals block[0..size) (a run of
 * instances with one set of attributes shares one copy), else a kept copy;
 * NULL when size is 0. */
static const void *shared_copy(rib_parser *p, const void *prev, size_t prev_size,
                               const void *block, size_t size)
{
    if (size == 0) return NULL;
    if (prev && prev_size == size && memcmp(prev, block, size) == 0) return prev;
    void *copy = xmalloc(size);
    memcpy(copy, block, size);
    return scene_keep(p->scene, copy);
}

static const char *shared_string(rib_parser *p, const char *prev, const char *s)
{
    if (!s) return NULL;
    return shared_copy(p, prev, prev ? strlen(prev) + 1 : 0, s, strlen(s) + 1);
}

/* the lights that are on, as indices into scene.lights */
static void object_lights(rib_parser *p, const scene_attributes *prev, scene_attributes *at)
{
    const rib_attributes *a = &p->attr;
    int few[64];                   /* most scenes: no allocation per object */
    int *on = p->scene->nlights <= 64 ? few : xmalloc((size_t)p->scene->nlights * sizeof *on);
    int n = a->lights_on ? a->lights_on->n : 0, non = 0;
    for (int i = 0; i < p->scene->nlights && i < n; i++)
        if (a->lights_on->on[i])
            on[non++] = i;
    at->lights = shared_copy(p, prev ? prev->lights : NULL,
                             prev ? (size_t)prev->nlights * sizeof *on : 0, on,
                             (size_t)non * sizeof *on);
    at->nlights = non;
    if (on != few) free(on);
}

/* Whether two records say the same (the strings and light lists compared by
 * pointer: object_attributes shares them with the previous record's where
 * equal; the numbers bitwise, as each object used to copy them). */
static bool attributes_same(const scene_attributes *x, const scene_attributes *y)
{
    return memcmp(x->Os, y->Os, sizeof x->Os) == 0 &&
           memcmp(&x->shading_rate, &y->shading_rate, sizeof x->shading_rate) == 0 &&
           memcmp(&x->displacement_bound, &y->displacement_bound,
                  sizeof x->displacement_bound) == 0 &&
           x->displacement_bound_space == y->displacement_bound_space &&
           x->name == y->name && x->lights == y->lights && x->nlights == y->nlights &&
           x->surface_shader == y->surface_shader &&
           x->displacement_shader == y->displacement_shader && x->sides == y->sides &&
           x->orientation == y->orientation;
}

/* The current attributes as a record kept by the scene: the previous
 * object's when equal (a run of instances with one set of attributes
 * shares one record), else a new one whose strings and lights are the
 * previous record's where equal. */
static const scene_attributes *object_attributes(rib_parser *p, const scene_attributes *prev)
{
    const rib_attributes *a = &p->attr;
    scene_attributes at;
    memset(&at, 0, sizeof at);
    memcpy(at.Os, a->Os, sizeof at.Os);
    at.shading_rate = a->shading_rate;
    at.displacement_bound = a->displacement_bound;
    at.displacement_bound_space = shared_string(p, prev ? prev->displacement_bound_space : NULL,
                                                a->bound_space);
    at.name = shared_string(p, prev ? prev->name : NULL, a->name);
    object_lights(p, prev, &at);
    at.surface_shader = a->surface;
    at.displacement_shader = a->displacement;
    at.sides = a->sides;
    at.orientation = a->orientation;
    if (prev && attributes_same(prev, &at)) return prev;
    scene_attributes *kept = scene_keep(p->scene, xmalloc(sizeof *kept));
    *kept = at;
    return kept;
}

void rib_place_surface(rib_parser *p, const rib_request *req, const geom_surface *surf,
                       const scene_mesh *mesh, mat4 ctm, sl_pos pos,
                       const scene_primvar *vars, int nvars, bool vars_kept, int first)
{
    assert(!surf == !!mesh);
    const rib_attributes *a = &p->attr;
    scene_primvar with_st[SCENE_MAX_PRIMVARS];     /* TextureCoordinates (rib_texcoord.c) */
    int nst = mesh ? -1 : rib_texcoord_vars(p, surf, vars, nvars, with_st);
    if (nst >= 0) {
        vars = with_st;
        nvars = nst;
        vars_kept = false;
    }
    mat4 to_camera = mat4_mul(p->scene->camera.camera_from_world, ctm), inv;
    if (!mat4_invert(&to_camera, &inv)) {
        rib_error(p, req, req->pos, "the current transform is singular (a Scale by 0?)");
        return;
    }
    /* an instance is a reference in the renderer (trace/group.h): a few
     * hundred bytes, where an object of its own takes ~9 KB */
    bool reference = first >= 0;
    if (reference ? p->ninstances >= SCENE_MAX_INSTANCES : p->nown >= p->max_objects) {
        if (!p->objects_overflow) {
            if (reference)
                rib_error(p, req, req->pos, "too many instances (the limit is %ld instances "
                          "per scene): split the scene into several renders",
                          (long)SCENE_MAX_INSTANCES);
            else
                rib_error(p, req, req->pos, "too many objects (the limit is %d per scene, "
                          "instances apart): split the scene into several renders, "
                          "use fewer, larger primitives, or place repeated ones with "
                          "ObjectInstance", p->max_objects);
        }
        p->objects_overflow = true;
        return;
    }
    /* what a renderer keeps per piece (trace/mesh.h): an undisplaced
     * mesh's boxes once, whatever places it; a displaced mesh's per
     * placement (its shader runs in each object's space), but for a
     * placement that moves its first rigidly (the renderer's may then be
     * the first's surface moved: trace/instance.c; where its shader says
     * otherwise, the worker refuses what it cannot number: group.c) */
    long pieces = mesh ? scene_mesh_npieces(mesh) : 1;
    if (mesh && first >= 0 && a->displacement >= 0) {
        const scene_object *f = &p->scene->objects[first];
        mat4 f_to_camera = mat4_mul(p->scene->camera.camera_from_world, f->object_to_world), f_inv;
        mat4 motion = mat4_mul(to_camera, mat4_invert(&f_to_camera, &f_inv) ? f_inv
                                                                              : mat4_identity());
        if (f->attr->displacement_shader == a->displacement && mat4_is_rotation(&motion) &&
            f->attr->orientation == a->orientation)
            pieces = 0;
    }
    int mi = mesh ? scene_mesh_index(mesh) : -1;
    if (mi >= 0 && mi >= p->mesh_counted_cap) {
        int cap = p->mesh_counted_cap;
        p->mesh_counted_cap = mi + 1 > 2 * cap ? mi + 1 : 2 * cap;
        p->mesh_counted = xrealloc(p->mesh_counted, (size_t)p->mesh_counted_cap);
        memset(p->mesh_counted + cap, 0, (size_t)(p->mesh_counted_cap - cap));
    }
    bool shared = mi >= 0 && a->displacement < 0;
    if (shared && p->mesh_counted[mi]) pieces = 0;
    if (p->scene->npieces + pieces > SCENE_MAX_PIECES) {
        if (!p->objects_overflow)
            rib_error(p, req, req->pos, "too many mesh faces: %ld placed before this one's %ld "
                      "(the limit is %ld pieces per scene; a displaced mesh's count again for each "
                      "instance but those that move the first rigidly): "
                      "split the scene into several renders or use fewer faces",
                      p->scene->npieces, pieces, SCENE_MAX_PIECES);
        p->objects_overflow = true;
        return;
    }
    p->scene->npieces += pieces;
    if (shared) p->mesh_counted[mi] = 1;
    if (reference) p->ninstances++; else p->nown++;
    const scene_object *prev = p->scene->nobjects > 0 ? &p->scene->objects[p->scene->nobjects - 1]
                                                      : NULL;
    scene_object *o = rib_add_object(p);
    if (prev) prev = &p->scene->objects[p->scene->nobjects - 2];   /* the array moved */
    o->surface = surf;
    o->mesh = mesh;
    o->object_to_world = ctm;
    o->attr = object_attributes(p, prev ? prev->attr : NULL);
    memcpy(o->Cs, a->Cs, sizeof o->Cs);
    o->reverse_normals = reverse_normals(a->orientation, &to_camera);
    o->pos = pos;
    o->primvars = vars_kept || nvars == 0
        ? (nvars > 0 ? vars : NULL)
        : shared_copy(p, prev ? prev->primvars : NULL,
                      prev ? (size_t)prev->nprimvars * sizeof *vars : 0, vars,
                      (size_t)nvars * sizeof *vars);
    o->nprimvars = nvars;
}

void rib_add_surface(rib_parser *p, const rib_request *req, const geom_surface *surf)
{
    if (rib_defining(p)) {
        rib_record_surface(p, req, surf, NULL);
        return;
    }
    geom_surface *kept = scene_keep(p->scene, xmalloc(sizeof *kept));
    *kept = *surf;
    rib_place_surface(p, req, kept, NULL, p->attr.ctm, req->pos, p->surface_vars,
                      p->nsurface_vars, false, -1);
}

void rib_add_mesh(rib_parser *p, const rib_request *req, scene_mesh *mesh)
{
    scene *s = p->scene;
    s->meshes = xreallocarray(s->meshes, (size_t)s->nmeshes + 1, sizeof *s->meshes);
    scene_mesh_set_index(mesh, s->nmeshes);
    s->meshes[s->nmeshes++] = mesh;
    if (rib_defining(p))
        rib_record_surface(p, req, NULL, mesh);
    else
        rib_place_surface(p, req, NULL, mesh, p->attr.ctm, req->pos, NULL, 0, false, -1);
}

/* Validates the surface and adds the object with the current attributes
 * (or records it in the object being defined, rib_instance.c). */
static void add_object(rib_parser *p, const rib_request *req, geom_surface *surf)
{
    char err[ERR_LEN] = "";
    if (!prepare_surface(surf, err, sizeof err)) {
        rib_error(p, req, req->pos, "%s", err[0] ? err : "invalid parameters");
        return;
    }
    rib_add_surface(p, req, surf);
}

/* Reads the positional numbers, then the parameter list (typed, values
 * ignored: aafarm's quadrics take no primitive variables). */
static bool read_quadric(rib_parser *p, const rib_request *req, int n, double *v,
                         const char *what)
{
    int next = rib_read_numbers(p, req, 0, n, v, what);
    rib_params params;
    if (next < 0 || !rib_params_read(p, req, next, RIB_PARAMS_VARYING, &params))
        return false;
    rib_params_clear(&params);
    return true;
}

static geom_surface new_surface(geom_kind kind)
{
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = kind;
    return s;
}

/* ---------------------------------------------------------------------- */
/* quadrics (§5.2)                                                         */
/* ---------------------------------------------------------------------- */

/* One quadric request: its kind, its positional numbers (named in `what`
 * for errors) and the surface field each goes to, angles in degrees. */
typedef struct quadric_arg {
    size_t offset;                /* of a double in geom_surface */
    bool angle;                   /* given in degrees, kept in radians */
} quadric_arg;

typedef struct quadric_form {
    geom_kind kind;
    const char *what;
    int n;
    quadric_arg arg[7];
} quadric_form;

#define FIELD(f) { offsetof(geom_surface, f), false }
#define ANGLE(f) { offsetof(geom_surface, f), true }
static const quadric_form sphere = { GEOM_SPHERE, "radius zmin zmax thetamax", 4,
    { FIELD(radius), FIELD(zmin), FIELD(zmax), ANGLE(thetamax) } };
static const quadric_form disk = { GEOM_DISK, "height radius thetamax", 3,
    { FIELD(height), FIELD(radius), ANGLE(thetamax) } };
static const quadric_form cylinder = { GEOM_CYLINDER, "radius zmin zmax thetamax", 4,
    { FIELD(radius), FIELD(zmin), FIELD(zmax), ANGLE(thetamax) } };
static const quadric_form cone = { GEOM_CONE, "height radius thetamax", 3,
    { FIELD(height), FIELD(radius), ANGLE(thetamax) } };
static const quadric_form torus = { GEOM_TORUS,
    "majorradius minorradius phimin phimax thetamax", 5,
    { FIELD(majorrad), FIELD(minorrad), ANGLE(phimin), ANGLE(phimax), ANGLE(thetamax) } };
static const quadric_form hyperboloid = { GEOM_HYPERBOLOID, "point1 point2 thetamax", 7,
    { FIELD(point1.x), FIELD(point1.y), FIELD(point1.z), FIELD(point2.x), FIELD(point2.y),
      FIELD(point2.z), ANGLE(thetamax) } };
static const quadric_form paraboloid = { GEOM_PARABOLOID, "rmax zmin zmax thetamax", 4,
    { FIELD(rmax), FIELD(zmin), FIELD(zmax), ANGLE(thetamax) } };
#undef FIELD
#undef ANGLE

static void quadric(rib_parser *p, const rib_request *req, const quadric_form *f)
{
    double v[7];
    if (!read_quadric(p, req, f->n, v, f->what))
        return;
    geom_surface s = new_surface(f->kind);
    for (int i = 0; i < f->n; i++)
        *(double *)((char *)&s + f->arg[i].offset) = f->arg[i].angle ? radians(v[i]) : v[i];
    add_object(p, req, &s);
}

void rib_sphere(rib_parser *p, const rib_request *req) { quadric(p, req, &sphere); }
void rib_disk(rib_parser *p, const rib_request *req) { quadric(p, req, &disk); }
void rib_cylinder(rib_parser *p, const rib_request *req) { quadric(p, req, &cylinder); }
void rib_cone(rib_parser *p, const rib_request *req) { quadric(p, req, &cone); }
void rib_torus(rib_parser *p, const rib_request *req) { quadric(p, req, &torus); }
void rib_hyperboloid(rib_parser *p, const rib_request *req) { quadric(p, req, &hyperboloid); }
void rib_paraboloid(rib_parser *p, const rib_request *req) { quadric(p, req, &paraboloid); }

/* ---------------------------------------------------------------------- */
/* Polygon (§5.1), Patch "bilinear" (§5.3)                                 */
/* ---------------------------------------------------------------------- */

/* The "P" parameter of a primitive; NULL (with an error) when missing. */
static const scene_param *find_P(rib_parser *p, const rib_request *req, const rib_params *params)
{
    const scene_param *P = rib_params_find(params, "P");
    if (!P)
        rib_error(p, req, req->pos, "missing the vertices: add \"P\" [x y z x y z ...]");
    else if (P->type != SL_TYPE_POINT) {
        rib_error(p, req, P->pos, "\"P\" must be declared as a point, not a %s",
                  rib_type_name(P->type));
        P = NULL;
    }
    return P;
}

static void take_vertices(geom_surface *s, const scene_param *P, int n)
{
    s->nverts = n;
    for (int i = 0; i < n; i++)
        s->verts[i] = v3(P->values[3 * i], P->values[3 * i + 1], P->values[3 * i + 2]);
}

void rib_polygon(rib_parser *p, const rib_request *req)
{
    rib_params params;
    if (!rib_params_read(p, req, 0, RIB_PARAMS_VARYING, &params))
        return;
    const scene_param *P = find_P(p, req, &params);
    int n = P ? P->count / 3 : 0;
    if (P && n < 3)
        rib_error(p, req, P->pos, "a polygon needs at least 3 vertices, got %d", n);
    else if (P && n > GEOM_MAX_POLY_VERTS)
        rib_error(p, req, P->pos, "at most %d vertices are supported, got %d",
                  GEOM_MAX_POLY_VERTS, n);
    else if (P) {
        geom_surface s = new_surface(GEOM_POLYGON);
        take_vertices(&s, P, n);
        char err[ERR_LEN] = "";
        if (!prepare_surface(&s, err, sizeof err))
            rib_error(p, req, req->pos, "%s", err[0] ? err : "invalid parameters");
        else if (!rib_polygon_vars(p, req, &params, P))   /* with primitive variables */
            rib_add_surface(p, req, &s);
    }
    rib_params_clear(&params);
}

void rib_patch(rib_parser *p, const rib_request *req)
{
    bool cubic;
    if (!rib_read_patch_type(p, req, &cubic))
        return;
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_VARYING, &params))
        return;
    const scene_param *P = find_P(p, req, &params);
    int counts[] = { 0, 1, 1, 4, cubic ? 16 : 4, 0 };
    rib_primvars pv;
    if (P && !rib_patch_primvars(p, req, &params, counts, cubic, &pv))
        P = NULL;
    if (P && cubic)
        rib_patch_bicubic(p, req, P, &pv);
    else if (P && P->count != 12)
        rib_error(p, req, P->pos, "a bilinear patch needs 4 points in \"P\" (12 numbers), "
                  "got %d numbers", P->count);
    else if (P) {
        geom_surface s = new_surface(GEOM_PATCH);
        take_vertices(&s, P, 4);
        static const int corner[4] = { 0, 1, 2, 3 };
        scene_primvar vars[RIB_MAX_PRIMVARS];
        rib_patch_vars(p, &pv, 0, 0, 0, 2, 2, corner, vars);
        add_object(p, req, &s);
        p->surface_vars = NULL;
        p->nsurface_vars = 0;
    }
    if (P)
        rib_primvars_clear(&pv);
    rib_params_clear(&params);
}
