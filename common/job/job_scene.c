/*
 * job_scene.c: from a job to a renderable world (see job_scene.h): parse
 * the RIB, compile each shader once, make one instance per shader call
 * with the RIB's parameter values, and translate the scene model (RIB
 * terms) into the renderer's camera-space world (trace/world.h).
 */
#include "job/job_scene.h"
#include "job/job_internal.h"
#include "trace/group.h"
#include "trace/mesh.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A shader's named spaces for an object whose transforms are to_camera,
 * from_camera (scene_object_transforms); sh: the shader's call (its
 * "shader" space), NULL: the object's. */
static void spaces_for(const scene *sc, const mat4 *to_camera, const mat4 *from_camera,
                       const scene_shader *sh, sl_spaces *sp)
{
    mat4 id = mat4_identity();
    for (int i = 0; i < SL_SPACE__COUNT; i++) sp->to_current[i] = sp->from_current[i] = id;
    sp->to_current[SL_SPACE_WORLD] = sc->camera.camera_from_world;
    sp->from_current[SL_SPACE_WORLD] = sc->camera.world_from_camera;
    sp->to_current[SL_SPACE_OBJECT] = *to_camera;
    sp->from_current[SL_SPACE_OBJECT] = *from_camera;
    if (sh) {
        sp->to_current[SL_SPACE_SHADER] = sh->shader_to_camera;
        mat4_invert(&sh->shader_to_camera, &sp->from_current[SL_SPACE_SHADER]);
    } else {
        sp->to_current[SL_SPACE_SHADER] = *to_camera;
        sp->from_current[SL_SPACE_SHADER] = *from_camera;
    }
}

static void build_camera(const scene *sc, trace_world *w)
{
    const scene_camera *c = &sc->camera;
    trace_camera *t = &w->camera;
    t->xres = c->xres;
    t->yres = c->yres;
    t->orthographic = c->projection == SCENE_ORTHOGRAPHIC;
    memcpy(t->screen, c->screen, sizeof t->screen);
    t->tan_half_fov = tan(c->fov * (M_PI / 360.0));
    t->near_clip = c->near_clip;
    t->far_clip = c->far_clip;
    /* RenderMan's thin lens: its diameter is focallength / fstop */
    t->lens_radius = c->fstop > 0 ? 0.5 * c->focal_length / c->fstop : 0.0;
    t->focal_distance = c->focal_distance;
    t->camera_from_world = c->camera_from_world;
    t->world_from_camera = c->world_from_camera;
}

/* A light shader's spaces: "shader" and "object" are the light's space
 * (RI Spec 3.2 §9.3: a light's coordinate system is the one current at
 * its LightSource). */
static void light_spaces(const scene *sc, const scene_light *l, sl_spaces *sp)
{
    mat4 id = mat4_identity(), from_light;
    mat4_invert(&l->light_to_camera, &from_light);
    for (int i = 0; i < SL_SPACE__COUNT; i++) sp->to_current[i] = sp->from_current[i] = id;
    sp->to_current[SL_SPACE_WORLD] = sc->camera.camera_from_world;
    sp->from_current[SL_SPACE_WORLD] = sc->camera.world_from_camera;
    sp->to_current[SL_SPACE_OBJECT] = sp->to_current[SL_SPACE_SHADER] = l->light_to_camera;
    sp->from_current[SL_SPACE_OBJECT] = sp->from_current[SL_SPACE_SHADER] = from_light;
}

/* Is the light shader's L the same at two unrelated points (solar: a
 * direction, so shadow rays go to infinity)? */
static bool light_directional(const trace_light *t)
{
    static const double pa[3] = {0.0, 0.0, 1.0}, pb[3] = {0.37, -0.21, 2.3};
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_spaces(vm, &t->shader_spaces);
    sl_light_sample a, b;
    bool same = sl_light_eval(vm, t->shader, pa, &a) == SL_OK &&
                sl_light_eval(vm, t->shader, pb, &b) == SL_OK;
    for (int k = 0; k < 3 && same; k++)
        same = fabs(a.L[k] - b.L[k]) <= 1e-12 * (1.0 + fabs(a.L[k]));
    sl_vm_destroy(&vm);
    return same;
}

static void build_lights(const scene *sc, sl_instance *const *instances, trace_world *w)
{
    w->nlights = sc->nlights;
    w->lights = xcalloc((size_t)(sc->nlights > 0 ? sc->nlights : 1), sizeof *w->lights);
    for (int i = 0; i < sc->nlights; i++) {
        const scene_light *l = &sc->lights[i];
        trace_light *t = &w->lights[i];
        if (l->kind == SCENE_SHADER_LIGHT) {
            t->kind = TRACE_LIGHT_SHADER;
            t->shader = instances[l->shader];
            light_spaces(sc, l, &t->shader_spaces);
            t->directional = light_directional(t);
            t->shadows = l->shadows;
            continue;
        }
        static const trace_light_kind kinds[] = {
            [SCENE_AMBIENT_LIGHT] = TRACE_LIGHT_AMBIENT, [SCENE_DISTANT_LIGHT] = TRACE_LIGHT_DISTANT,
            [SCENE_POINT_LIGHT] = TRACE_LIGHT_POINT, [SCENE_SPOT_LIGHT] = TRACE_LIGHT_SPOT};
        t->kind = kinds[l->kind];
        for (int k = 0; k < 3; k++) t->color[k] = l->intensity * l->lightcolor[k];
        t->from = l->from_camera;
        t->dir = v3_normalize(v3_sub(l->to_camera, l->from_camera));
        t->cos_outside = cos(l->coneangle);
        t->cos_inside = cos(l->coneangle - l->conedeltaangle);
        t->beamdistribution = l->beamdistribution;
        t->shadows = l->shadows;
    }
}

static trace_filter_kind filter_kind(scene_filter_kind k)
{
    switch (k) {
    case SCENE_FILTER_BOX: return TRACE_FILTER_BOX;
    case SCENE_FILTER_TRIANGLE: return TRACE_FILTER_TRIANGLE;
    case SCENE_FILTER_CATMULL_ROM: return TRACE_FILTER_CATMULL_ROM;
    case SCENE_FILTER_SINC: return TRACE_FILTER_SINC;
    case SCENE_FILTER_GAUSSIAN:
    default: return TRACE_FILTER_GAUSSIAN;
    }
}

static int program_index(const job *jb, const char *name)
{
    for (int i = 0; i < jb->nshaders; i++)
        if (strcmp(jb->shaders[i].name, name) == 0) return i;
    return -1;
}

/* Was the program's stop flag set? Then "interrupted" goes into diag. */
static bool interrupted(const atomic_int *cancel, sl_diag *diag)
{
    if (!cancel || !atomic_load_explicit(cancel, memory_order_relaxed)) return false;
    sl_diag_error(diag, (sl_pos){0}, "interrupted (SIGINT/SIGTERM)");
    return true;
}

static bool compile_programs(job_scene *self, const atomic_int *cancel, sl_diag *diag)
{
    const job *jb = self->job;
    bool ok = true;
    self->programs = xcalloc((size_t)(jb->nshaders > 0 ? jb->nshaders : 1), sizeof *self->programs);
    for (int i = 0; i < jb->nshaders; i++) {
        if (cancel && atomic_load_explicit(cancel, memory_order_relaxed)) return false;
        self->programs[i] = sl_compile(jb->sources, jb->shaders[i].file,
                                       scene_search_path(self->scene), cancel, diag);
        if (!self->programs[i]) ok = false;
    }
    return ok;
}

static const char *kind_name(sl_shader_kind k)
{
    switch (k) {
    case SL_SHADER_SURFACE: return "surface";
    case SL_SHADER_DISPLACEMENT: return "displacement";
    case SL_SHADER_LIGHT: return "light";
    default: return "shader of another kind";
    }
}

static sl_instance *make_instance(job_scene *self, const scene_shader *call, sl_diag *diag)
{
    int p = program_index(self->job, call->name);
    if (p < 0) {
        sl_diag_error(diag, call->pos, "shader '%s' is not part of the job", call->name);
        return NULL;
    }
    const sl_program *prog = self->programs[p];
    if (sl_program_kind(prog) != call->kind) {
        sl_diag_error(diag, call->pos, "'%s' is a %s shader, used here as a %s shader "
                      "(give it to %s instead)",
                      call->name, kind_name(sl_program_kind(prog)), kind_name(call->kind),
                      sl_program_kind(prog) == SL_SHADER_SURFACE ? "Surface"
                      : sl_program_kind(prog) == SL_SHADER_LIGHT ? "LightSource"
                      : "Displacement");
        return NULL;
    }
    sl_instance *inst = sl_instance_new(prog);
    for (int k = 0; k < call->nparams; k++) {
        const scene_param *pa = &call->params[k];
        char err[ERR_LEN];
        bool ok = pa->type == SL_TYPE_STRING
                      ? sl_instance_set_string(inst, pa->name, pa->string, err, sizeof err)
                      : sl_instance_set(inst, pa->name, pa->type, pa->values, pa->count,
                                        err, sizeof err);
        if (!ok) sl_diag_warning(diag, pa->pos, "shader '%s': %s (parameter ignored)", call->name, err);
    }
    return inst;
}

/* sl's parameter sizes: float 1, point/vector/normal/color 3 */
static int param_size(sl_type t)
{
    return t == SL_TYPE_FLOAT ? 1 : (t == SL_TYPE_POINT || t == SL_TYPE_VECTOR ||
                                     t == SL_TYPE_NORMAL || t == SL_TYPE_COLOR) ? 3 : 0;
}

/* The parameter of the instance's program that primitive variable v sets
 * (same name and number of components, not an output), or -1. */
static int primvar_param(const sl_instance *inst, const scene_primvar *v)
{
    if (!inst) return -1;
    const sl_program *prog = sl_instance_program(inst);
    int i = sl_program_find_param(prog, v->name);
    if (i < 0) return -1;
    sl_param_info info;
    sl_program_param(prog, i, &info);
    return !info.output && param_size(info.type) == v->size ? i : -1;
}

/* Primitive variables vars[0..n) of object t in camera space, with the
 * globals and parameters they set (trace/primvar.c). */
static void convert_primvars(const scene_primvar *vars, int n, const trace_object *t,
                             trace_primvar *out)
{
    for (int i = 0; i < n; i++) {
        const scene_primvar *v = &vars[i];
        trace_primvar *pv = &out[i];
        memset(pv, 0, sizeof *pv);
        pv->size = v->size;
        pv->global = SL_G__COUNT;
        if (v->size == 1 && strcmp(v->name, "s") == 0) pv->global = SL_G_s;
        if (v->size == 1 && strcmp(v->name, "t") == 0) pv->global = SL_G_t;
        if (v->size == 3 && strcmp(v->name, "Cs") == 0) pv->global = SL_G_Cs;
        if (v->size == 3 && strcmp(v->name, "Os") == 0) pv->global = SL_G_Os;
        pv->displacement_param = primvar_param(t->displacement, v);
        pv->surface_param = primvar_param(t->surface, v);
        for (int k = 0; k < 16; k++) {
            vec3 c = v3(v->c[k][0], v->c[k][1], v->c[k][2]);
            if (v->type == SL_TYPE_POINT)
                c = k == 0 ? mat4_xform_point(&t->to_camera, c) : mat4_xform_vector(&t->to_camera, c);
            else if (v->type == SL_TYPE_VECTOR)
                c = mat4_xform_vector(&t->to_camera, c);
            else if (v->type == SL_TYPE_NORMAL)
                c = mat4_xform_normal(&t->from_camera, c);
            else {
                for (int j = 0; j < 3; j++) pv->c[k][j] = v->c[k][j];
                continue;
            }
            pv->c[k][0] = c.x, pv->c[k][1] = c.y, pv->c[k][2] = c.z;
        }
    }
}

static void build_primvars(const scene_object *o, trace_object *t, trace_primvar *out)
{
    convert_primvars(o->primvars, o->nprimvars, t, out);
    t->primvars = out;
    t->nprimvars = o->nprimvars;
}

_Static_assert((int)SCENE_MAX_PRIMVARS <= (int)TRACE_MAX_PRIMVARS, "a piece's variables fit a view");

/* trace_mesh.piece: piece k of the scene object `user` (scene_mesh.h
 * makes it again from the mesh's arrays), its variables in the camera
 * space of the mesh object t. */
static bool mesh_piece(const void *user, const trace_object *t, int k, geom_surface *s,
                       trace_primvar *pv, int *npv)
{
    const scene_object *o = user;
    scene_primvar vars[TRACE_MAX_PRIMVARS];
    int n = 0;
    if (!scene_object_piece(o, k, s, vars, &n)) return false;
    if (pv) convert_primvars(vars, n, t, pv);
    *npv = n;
    return true;
}

/* trace_mesh.outline: piece k's outline (scene_object_piece_outline) */
static bool mesh_outline(const void *user, int k, geom_surface *s)
{
    return scene_object_piece_outline(user, k, s);
}

/* The instances of a prototype kept as references (trace/group.h): the
 * scene objects they are, whose transforms, spaces, colours and primitive
 * variables their views take. */
typedef struct job_group {
    trace_group group;
    const scene *scene;
    int *objects;                  /* placement k: scene.objects[objects[k]] */
} job_group;

static void group_transform(const void *user, int k, mat4 *to_camera, mat4 *from_camera)
{
    const job_group *g = user;
    scene_object_transforms(g->scene, &g->scene->objects[g->objects[k]], to_camera, from_camera);
}

static bool group_place(const void *user, int k, trace_object *t, trace_primvar *pv)
{
    const job_group *g = user;
    const scene *sc = g->scene;
    const scene_object *o = &sc->objects[g->objects[k]];
    spaces_for(sc, &t->to_camera, &t->from_camera, scene_object_displacement(sc, o),
               &t->displacement_spaces);
    spaces_for(sc, &t->to_camera, &t->from_camera, scene_object_surface(sc, o), &t->surface_spaces);
    memcpy(t->Cs, o->Cs, sizeof t->Cs);
    memcpy(t->Os, o->attr->Os, sizeof t->Os);
    t->flip = o->reverse_normals;
    convert_primvars(o->primvars, o->nprimvars, t, pv);
    t->primvars = pv;
    t->nprimvars = o->nprimvars;
    return true;
}

/* Which objects are references (placements) and of which prototype:
 * proto_of[i] is the prototype's scene index, or -1 for an object of its
 * own; the count of each prototype's placements in nplaced[]. */
static int find_placements(const scene *sc, int *proto_of, int *nplaced)
{
    int n = 0;
    for (int i = 0; i < sc->nobjects; i++) {
        const scene_object *o = &sc->objects[i];
        int j = o->instance_of;
        proto_of[i] = -1;
        nplaced[i] = 0;
        if (j < 0 || j >= i || proto_of[j] >= 0 || !scene_object_placeable(o, &sc->objects[j]))
            continue;
        proto_of[i] = j;
        nplaced[j]++;
        n++;
    }
    return n;
}

/* The object name build_object gives an object (the prototype's, for a
 * reference's message). */
static void object_name(const scene *sc, const scene_object *o, char *out, size_t outsz)
{
    snprintf(out, outsz, "%s at %s:%d",
             o->attr->name ? o->attr->name : o->mesh ? "mesh" : geom_kind_name(o->surface->kind),
             o->pos.file ? o->pos.file : sc->file, o->pos.line);
}

static void build_object(job_scene *self, const scene_object *o, trace_object *t,
                         trace_primvar *pv, int *undisplaced)
{
    const scene *sc = self->scene;
    object_name(sc, o, t->name, sizeof t->name);
    if (o->surface) t->surf = *o->surface;
    scene_object_transforms(sc, o, &t->to_camera, &t->from_camera);
    const scene_shader *ds = scene_object_displacement(sc, o);
    const scene_shader *ss = scene_object_surface(sc, o);
    spaces_for(sc, &t->to_camera, &t->from_camera, ds, &t->displacement_spaces);
    spaces_for(sc, &t->to_camera, &t->from_camera, ss, &t->surface_spaces);
    const scene_attributes *a = o->attr;
    t->displacement = a->displacement_shader >= 0 ? self->instances[a->displacement_shader] : NULL;
    t->surface = a->surface_shader >= 0 ? self->instances[a->surface_shader] : NULL;
    memcpy(t->Cs, o->Cs, sizeof t->Cs);
    memcpy(t->Os, o->attr->Os, sizeof t->Os);
    t->sides = a->sides;
    t->flip = o->reverse_normals;
    t->lights = a->lights;
    t->nlights = a->nlights;
    build_primvars(o, t, pv);
    if (o->mesh) {
        /* the objects placing one undisplaced mesh share its pieces'
         * boxes and BVH (object space, trace/mesh.h); a displaced one
         * has its own (its shader runs in each object's camera space) */
        int si = scene_mesh_index(o->mesh);
        trace_mesh *m = !t->displacement && undisplaced[si] >= 0
                            ? &self->meshes[undisplaced[si]] : NULL;
        if (!m) {
            if (!t->displacement) undisplaced[si] = self->nmeshes;
            m = &self->meshes[self->nmeshes++];
            m->npieces = scene_mesh_npieces(o->mesh);
            m->nprimvars = scene_mesh_nprimvars(o->mesh);
            m->piece = mesh_piece;
            m->outline = mesh_outline;
            m->user = o;
        }
        t->mesh = m;
    }
}

static bool build_objects(job_scene *self, sl_diag *diag)
{
    const scene *sc = self->scene;
    trace_world *w = &self->world;
    bool ok = true;
    self->instances = xcalloc((size_t)(sc->nshaders > 0 ? sc->nshaders : 1), sizeof *self->instances);
    for (int i = 0; i < sc->nshaders; i++) {
        self->instances[i] = make_instance(self, &sc->shaders[i], diag);
        if (!self->instances[i]) ok = false;
    }
    if (!ok) return false;
    size_t nsc = (size_t)(sc->nobjects > 0 ? sc->nobjects : 1);
    int *proto_of = xmalloc(sizeof *proto_of * nsc);
    int *nplaced = xmalloc(sizeof *nplaced * nsc);
    int *world_of = xmalloc(sizeof *world_of * nsc);    /* scene index -> world index */
    int nplacements = find_placements(sc, proto_of, nplaced);
    int nown = sc->nobjects - nplacements;
    if (nown > SCENE_MAX_OBJECTS) {
        /* instances that differ from their prototype are objects of
         * their own (~9 KB each), not references */
        int differ = 0;
        for (int i = 0; i < sc->nobjects; i++)
            differ += sc->objects[i].instance_of >= 0 && sc->objects[i].instance_of != i &&
                      proto_of[i] < 0;
        sl_diag_error(diag, (sl_pos){0}, "%s: %d objects of their own in the renderer (the "
                      "limit is %d): %d of the instances differ from their first placement in "
                      "shaders, sides, lights or primitive variables (a Surface call before each "
                      "ObjectInstance?); give them the same ones, so they are kept as references",
                      sc->file, nown, SCENE_MAX_OBJECTS, differ);
        free(proto_of);
        free(nplaced);
        free(world_of);
        return false;
    }
    self->ngroups = 0;
    for (int i = 0; i < sc->nobjects; i++) self->ngroups += nplaced[i] > 0;
    /* the objects of their own, in scene order, then one group per
     * prototype with placements (after it: trace_world_check) */
    w->nobjects = nown + self->ngroups;
    w->objects = xcalloc((size_t)(w->nobjects > 0 ? w->nobjects : 1), sizeof *w->objects);
    self->groups = xcalloc((size_t)(self->ngroups > 0 ? self->ngroups : 1), sizeof *self->groups);
    int nmeshes = 0;
    size_t nprimvars = 0;
    for (int i = 0; i < sc->nobjects; i++)
        if (proto_of[i] < 0) {
            nmeshes += sc->objects[i].mesh != NULL;
            nprimvars += (size_t)sc->objects[i].nprimvars;
        }
    self->meshes = xcalloc((size_t)(nmeshes > 0 ? nmeshes : 1), sizeof *self->meshes);
    /* per scene mesh: the trace_mesh its undisplaced placements share */
    int *undisplaced = xmalloc(sizeof *undisplaced * (size_t)(sc->nmeshes > 0 ? sc->nmeshes : 1));
    for (int i = 0; i < sc->nmeshes; i++) undisplaced[i] = -1;
    self->primvars = xcalloc(nprimvars > 0 ? nprimvars : 1, sizeof *self->primvars);
    trace_primvar *next_primvar = self->primvars;
    int next = 0, *group_of = nplaced;  /* reused: a prototype's group, then its fill */
    for (int i = 0; i < sc->nobjects; i++) {
        world_of[i] = -1;
        if (proto_of[i] >= 0) continue;
        const scene_object *o = &sc->objects[i];
        trace_object *t = &w->objects[next];
        world_of[i] = next++;
        build_object(self, o, t, next_primvar, undisplaced);
        next_primvar += o->nprimvars;
        /* an instance proposes sharing its prototype's boxes (trace/instance.c) */
        if (!o->mesh && o->instance_of >= 0 && o->instance_of < i && world_of[o->instance_of] >= 0)
            t->box_proto = &w->objects[world_of[o->instance_of]];
    }
    /* the groups: placement k of each in scene order */
    int ng = 0;
    for (int i = 0; i < sc->nobjects; i++) {
        if (nplaced[i] == 0) { group_of[i] = -1; continue; }
        job_group *g = &self->groups[ng];
        g->scene = sc;
        g->objects = xmalloc(sizeof *g->objects * (size_t)nplaced[i]);
        g->group.proto = world_of[i];
        g->group.transform = group_transform;
        g->group.place = group_place;
        g->group.user = g;
        trace_object *t = &w->objects[nown + ng];
        t->group = &g->group;
        t->to_camera = t->from_camera = mat4_identity();
        char proto_name[sizeof t->name];
        memcpy(proto_name, w->objects[world_of[i]].name, sizeof proto_name);
        snprintf(t->name, sizeof t->name, "%d instances of %.40s", nplaced[i], proto_name);
        group_of[i] = ng++;
    }
    for (int i = 0; i < sc->nobjects; i++)
        if (proto_of[i] >= 0) {
            job_group *g = &self->groups[group_of[proto_of[i]]];
            g->objects[g->group.n++] = i;
        }
    free(undisplaced);
    free(proto_of);
    free(nplaced);
    free(world_of);
    return true;
}

/* The textures (docs/textures.md): a cache whose resolver finds names on
 * the scene's texture search path and in the RIB's folder; every name the
 * bound shaders use is resolved now (render: also opened), so that a
 * missing map is an error naming the shader call, not a failed tile. */
static bool open_textures(job_scene *self, sl_diag *diag, bool render)
{
    const scene *sc = self->scene;
    self->textures = tex_cache_new(0);
    /* the job's files (job_file_resolve: the disk on the master and
     * standalone, the host's store on a worker); before job_load has
     * collected them, and for jobs built in memory (tests), the same search
     * of the texture path */
    if (render && self->job->files_known)
        tex_cache_set_resolver(self->textures, job_file_resolve, (void *)self->job);
    else
        tex_cache_set_resolver(self->textures, job_texture_path_resolve, (void *)sc);
    self->world.textures = self->textures;
    bool ok = true;
    for (int i = 0; i < sc->nshaders; i++) {
        const char *names[32];
        int n = sl_instance_texture_names(self->instances[i], names, 32);
        for (int k = 0; k < n; k++) {
            char err[ERR_LEN], path[4096], reason[ERR_LEN];
            bool found = render ? tex_cache_get(self->textures, names[k], err, sizeof err) != NULL
                                : job_texture_path_resolve((void *)sc, names[k], path, sizeof path,
                                                           reason, sizeof reason);
            if (!found) {
                if (!render)
                    err_set(err, sizeof err, "texture '%s': %s", names[k], reason);
                sl_diag_error(diag, sc->shaders[i].pos, "shader '%s': %s", sc->shaders[i].name,
                              err);
                ok = false;
            }
        }
    }
    return ok;
}

job_scene *job_scene_new(const job *jb, size_t cache_bytes, bool render,
                         const atomic_int *cancel, sl_diag *diag)
{
    return job_scene_new_threads(jb, cache_bytes, render, 1, cancel, diag);
}

/* scene_check.placement: what trace_world_check asks of each placement of
 * a group (its view's transforms, trace_object_derive), asked as it is
 * read. */
static bool check_placement(void *user, const scene *sc, const scene_object *proto,
                            const scene_object *placement, char *err, size_t errsz)
{
    (void)user;
    static const trace_world none;    /* derive without the grid reads no world */
    trace_object probe;
    memset(&probe, 0, sizeof probe);
    object_name(sc, proto, probe.name, sizeof probe.name);
    scene_object_transforms(sc, placement, &probe.to_camera, &probe.from_camera);
    return trace_object_derive(&none, &probe, false, err, errsz);
}

const scene_check *job_scene_checker(void)
{
    static const scene_check checker = { check_placement, NULL };
    return &checker;
}

static job_scene *build(job_scene *self, size_t cache_bytes, bool render, int threads,
                        const atomic_int *cancel, sl_diag *diag);

job_scene *job_scene_new_threads(const job *jb, size_t cache_bytes, bool render, int threads,
                                 const atomic_int *cancel, sl_diag *diag)
{
    job_scene *self = xcalloc(1, sizeof *self);
    self->job = jb;
    /* archives come from the job's files (the master's disk, this host's
     * store), never from a folder of this machine; their texts are freed
     * once parsed */
    sl_source_set *archives = job_archive_set_new(jb);
    self->scene = scene_parse_frame_threads(jb->scene_file, jb->scene_text, jb->scene_len,
                                            archives, SCENE_MAX_OBJECTS, jb->options.frame,
                                            threads, cancel, diag);
    sl_source_set_destroy(&archives);
    return build(self, cache_bytes, render, threads, cancel, diag);
}

job_scene *job_scene_check(const job *jb, scene *sc, const atomic_int *cancel, sl_diag *diag)
{
    job_scene *self = xcalloc(1, sizeof *self);
    self->job = jb;
    self->scene = sc;
    return build(self, 0, false, 1, cancel, diag);
}

/* From the parsed scene (NULL: its errors are in diag) on. */
static job_scene *build(job_scene *self, size_t cache_bytes, bool render, int threads,
                        const atomic_int *cancel, sl_diag *diag)
{
    const job *jb = self->job;
    bool ok = self->scene != NULL;
    assert(!ok || !render || !self->scene->checked);
    if (ok) ok = compile_programs(self, cancel, diag);
    if (ok) ok = build_objects(self, diag);
    if (ok) ok = !interrupted(cancel, diag);
    if (ok) ok = open_textures(self, diag, render);
    if (ok) ok = !interrupted(cancel, diag);
    if (ok) {
        const scene *sc = self->scene;
        trace_world *w = &self->world;
        build_camera(sc, w);
        build_lights(sc, self->instances, w);
        w->samples_x = sc->pixel_samples[0];
        w->samples_y = sc->pixel_samples[1];
        w->shading_rate = sc->shading_rate;
        w->filter = filter_kind(sc->filter.kind);
        w->filter_width[0] = sc->filter.xwidth;
        w->filter_width[1] = sc->filter.ywidth;
        w->gain = sc->exposure_gain;
        w->gamma = sc->exposure_gamma;
        trace_options_default(&w->options);
        w->options.arith = jb->options.arith;
        w->options.max_instructions = jb->options.max_instructions;
        w->options.cache_bytes = cache_bytes;
        /* the root boxes shared by the threads (trace/lazy_roots.h): as
         * much again as their caches, so a worker's boxes stay within
         * 2 x threads x cache_bytes (issue 23) */
        w->options.roots_bytes = cache_bytes * (size_t)(threads > 1 ? threads : 1);
        w->options.cancel = cancel;
        w->options.build_threads = threads;
        if (sc->trace_maxdepth >= 0) w->options.max_ray_depth = sc->trace_maxdepth;
    }
    if (ok && !render) {
        /* a check (the master's): no pieces' shared edges or boxes */
        char err[ERR_LEN];
        if (!trace_world_check(&self->world, err, sizeof err)) {
            sl_diag_error(diag, (sl_pos){0}, "%s", err);
            ok = false;
        }
    }
    if (ok && render) {
        char err[ERR_LEN];
        self->renderer = trace_renderer_new(&self->world, err, sizeof err);
        if (!self->renderer) {
            sl_diag_error(diag, (sl_pos){0}, "%s", err);
            ok = false;
        }
    }
    if (!ok) job_scene_destroy(&self);
    return self;
}

void job_scene_destroy(job_scene **self_p)
{
    job_scene *self = *self_p;
    if (!self) return;
    trace_renderer_destroy(&self->renderer);
    if (self->instances)
        for (int i = 0; i < (self->scene ? self->scene->nshaders : 0); i++)
            sl_instance_destroy(&self->instances[i]);
    free(self->instances);
    if (self->programs)
        for (int i = 0; i < self->job->nshaders; i++) sl_program_destroy(&self->programs[i]);
    free(self->programs);
    free(self->world.objects);
    free(self->world.lights);
    free(self->primvars);
    for (int i = 0; i < self->nmeshes; i++) trace_mesh_clear(&self->meshes[i]);
    free(self->meshes);
    for (int i = 0; i < self->ngroups; i++) {
        trace_group_clear(&self->groups[i].group);
        free(self->groups[i].objects);
    }
    free(self->groups);
    tex_cache_destroy(&self->textures);
    scene_destroy(&self->scene);
    free(self);
    *self_p = NULL;
}
