/*
 * rib_attributes.c: the attribute requests of RI Specification 3.2 §4.2
 * and §4.3 (transformations): ShadingRate, Color, Opacity, Sides,
 * Orientation, ReverseOrientation, Attribute, Declare, the transforms,
 * CoordinateSystem / CoordSysTransform, Surface and Displacement (the
 * shader calls), LightSource and Illuminate.
 *
 * Transform requests premultiply onto the current transform (§4.3: "the
 * transformation is applied before all previously applied ones"): in
 * column-vector terms ctm = ctm * T, so T acts on points first.
 *
 * Lights (§4.2.3): a LightSource adds a light and turns it on in the
 * current attribute state; a light declared inside AttributeBegin/End is
 * off again after AttributeEnd. Illuminate turns a light on or off for
 * the objects that follow. Each object records the lights on for it.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* the attribute state                                                     */
/* ---------------------------------------------------------------------- */

void rib_attributes_init(rib_attributes *a)
{
    memset(a, 0, sizeof *a);
    a->ctm = mat4_identity();
    a->surface = a->displacement = -1;
    for (int i = 0; i < 3; i++)
        a->Cs[i] = a->Os[i] = 1;
    a->sides = 2;
    a->orientation = SCENE_OUTSIDE;
    a->shading_rate = 1;
    a->bound_space = "object";
    rib_basis_default(a->ubasis, &a->ustep);
    rib_basis_default(a->vbasis, &a->vstep);
}

void rib_attributes_copy(rib_attributes *dst, const rib_attributes *src)
{
    *dst = *src;
    if (dst->lights_on)
        dst->lights_on->refs++;       /* shared: copied when either changes it */
}

void rib_attributes_clear(rib_attributes *a)
{
    rib_light_set *s = a->lights_on;
    if (s) {
        assert(s->refs > 0);
        if (--s->refs == 0)
            free(s);
    }
    a->lights_on = NULL;
}

static void set_light_on(rib_attributes *a, int index, bool on)
{
    rib_light_set *s = a->lights_on;
    int n = s ? s->n : 0;
    if (!s || s->refs > 1 || index >= s->cap) {     /* a copy of its own, with room */
        int cap = s ? s->cap : 8;
        while (cap <= index)
            cap *= 2;
        rib_light_set *t = xmalloc(sizeof *t + (size_t)cap);
        t->refs = 1;
        t->n = n;
        t->cap = cap;
        if (n > 0)
            memcpy(t->on, s->on, (size_t)n);
        rib_attributes_clear(a);
        a->lights_on = s = t;
    }
    if (index >= s->n) {
        memset(s->on + s->n, 0, (size_t)(index + 1 - s->n));
        s->n = index + 1;
    }
    s->on[index] = on;
}

/* ---------------------------------------------------------------------- */
/* simple attributes                                                       */
/* ---------------------------------------------------------------------- */

/* Reads exactly n numbers and nothing else. */
static bool numbers_only(rib_parser *p, const rib_request *req, int n, double *v, const char *what)
{
    int next = rib_read_numbers(p, req, 0, n, v, what);
    return next >= 0 && rib_no_more_args(p, req, next);
}

void rib_shading_rate(rib_parser *p, const rib_request *req)
{
    double v;
    if (!numbers_only(p, req, 1, &v, "size"))
        return;
    if (!(v > 0)) {
        rib_error(p, req, req->pos, "the shading rate must be > 0, got %g", v);
        return;
    }
    p->attr.shading_rate = v;
}

void rib_color(rib_parser *p, const rib_request *req)
{
    numbers_only(p, req, 3, p->attr.Cs, "red green blue");
}

void rib_opacity(rib_parser *p, const rib_request *req)
{
    double v[3];
    if (!numbers_only(p, req, 3, v, "red green blue"))
        return;
    for (int i = 0; i < 3; i++)
        if (!(v[i] >= 0 && v[i] <= 1)) {
            rib_error(p, req, req->pos, "the opacity must be between 0 and 1, got %g %g %g",
                      v[0], v[1], v[2]);
            return;
        }
    memcpy(p->attr.Os, v, sizeof v);
}

void rib_sides(rib_parser *p, const rib_request *req)
{
    double v;
    if (!numbers_only(p, req, 1, &v, "1 or 2"))
        return;
    if (v != 1 && v != 2) {
        rib_error(p, req, req->pos, "must be 1 or 2, got %g", v);
        return;
    }
    p->attr.sides = (int)v;
}

static const char *const orientation_names[] = { "outside", "inside", "lh", "rh" };

const char *scene_orientation_name(scene_orientation o)
{
    return (unsigned)o < 4 ? orientation_names[o] : "?";
}

void rib_orientation(rib_parser *p, const rib_request *req)
{
    const char *s = rib_read_string(p, req, 0, "the orientation");
    if (!s || !rib_no_more_args(p, req, 1))
        return;
    for (int i = 0; i < 4; i++)
        if (strcmp(s, orientation_names[i]) == 0) {
            p->attr.orientation = (scene_orientation)i;
            return;
        }
    rib_error(p, req, req->args[0].pos, "unknown orientation \"%s\" (expected \"outside\", "
              "\"inside\", \"lh\" or \"rh\")", s);
}

void rib_reverse_orientation(rib_parser *p, const rib_request *req)
{
    (void)req;
    static const scene_orientation flipped[] = { SCENE_INSIDE, SCENE_OUTSIDE, SCENE_RH, SCENE_LH };
    p->attr.orientation = flipped[p->attr.orientation];
}

/* ---------------------------------------------------------------------- */
/* Attribute and Declare                                                   */
/* ---------------------------------------------------------------------- */

static void displacement_bound(rib_parser *p, const rib_request *req, const rib_params *params)
{
    const scene_param *sphere = rib_params_find(params, "sphere");
    const scene_param *space = rib_params_find(params, "coordinatesystem");
    if (sphere && sphere->type == SL_TYPE_FLOAT) {
        if (!(sphere->values[0] >= 0)) {
            rib_error(p, req, sphere->pos, "\"sphere\" must be >= 0, got %g", sphere->values[0]);
            return;
        }
        p->attr.displacement_bound = sphere->values[0];
    }
    if (space && space->string)
        p->attr.bound_space = rib_parser_intern(p, space->string);
}

/* "on"/"off" (or a number, non-zero for on). */
static bool read_switch(rib_parser *p, const rib_request *req, const scene_param *param, bool *out)
{
    if (param->string && (strcmp(param->string, "on") == 0 || strcmp(param->string, "off") == 0)) {
        *out = strcmp(param->string, "on") == 0;
        return true;
    }
    if (param->values && param->count == 1) {
        *out = param->values[0] != 0;
        return true;
    }
    rib_error(p, req, param->pos, "\"%s\" must be \"on\" or \"off\"%s%s%s", param->name,
              param->string ? ", got \"" : "", param->string ? param->string : "",
              param->string ? "\"" : "");
    return false;
}

void rib_attribute(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the attribute name");
    if (!name || (strcmp(name, "displacementbound") != 0 && strcmp(name, "identifier") != 0 &&
                  strcmp(name, "light") != 0))
        return;   /* other attributes are ignored quietly */
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params))
        return;
    const scene_param *v;
    if (strcmp(name, "displacementbound") == 0) {
        displacement_bound(p, req, &params);
    } else if (strcmp(name, "identifier") == 0 && (v = rib_params_find(&params, "name"))) {
        if (v->string)
            p->attr.name = rib_parser_intern(p, v->string);
    } else if (strcmp(name, "light") == 0 && (v = rib_params_find(&params, "shadows"))) {
        read_switch(p, req, v, &p->attr.shadows);
    }
    rib_params_clear(&params);
}

void rib_declare(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the parameter name");
    const char *text = name ? rib_read_string(p, req, 1, "the declaration") : NULL;
    if (!text || !rib_no_more_args(p, req, 2))
        return;
    if (!*name || strpbrk(name, " \t\n[]")) {
        rib_error(p, req, req->args[0].pos, "the name \"%s\" must be one word", name);
        return;
    }
    rib_decl decl;
    char err[ERR_LEN];
    if (!rib_decl_parse(text, false, &decl, NULL, NULL, err, sizeof err)) {
        rib_error(p, req, req->args[1].pos, "cannot read the declaration \"%s\": %s "
                  "(expected [class] type [n], e.g. \"uniform float\")", text, err);
        return;
    }
    rib_decls_add(p->decls, name, decl);
}

/* ---------------------------------------------------------------------- */
/* transforms                                                              */
/* ---------------------------------------------------------------------- */

static void concat(rib_parser *p, mat4 t)
{
    p->attr.ctm = mat4_mul(p->attr.ctm, t);
}

void rib_identity(rib_parser *p, const rib_request *req)
{
    if (rib_no_more_args(p, req, 0))
        p->attr.ctm = mat4_identity();
}

void rib_translate(rib_parser *p, const rib_request *req)
{
    double v[3];
    if (numbers_only(p, req, 3, v, "dx dy dz"))
        concat(p, mat4_translate(v[0], v[1], v[2]));
}

void rib_rotate(rib_parser *p, const rib_request *req)
{
    double v[4];
    if (!numbers_only(p, req, 4, v, "angle dx dy dz"))
        return;
    if (v[1] == 0 && v[2] == 0 && v[3] == 0) {
        rib_error(p, req, req->pos, "the rotation axis is (0, 0, 0)");
        return;
    }
    concat(p, mat4_rotate(v[0], v[1], v[2], v[3]));
}

void rib_scale(rib_parser *p, const rib_request *req)
{
    double v[3];
    if (numbers_only(p, req, 3, v, "sx sy sz"))
        concat(p, mat4_scale(v[0], v[1], v[2]));
}

void rib_concat_transform(rib_parser *p, const rib_request *req)
{
    double v[16];
    if (numbers_only(p, req, 16, v, "a 4x4 matrix"))
        concat(p, mat4_from_rib(v));
}

void rib_transform(rib_parser *p, const rib_request *req)
{
    double v[16];
    if (numbers_only(p, req, 16, v, "a 4x4 matrix"))
        p->attr.ctm = mat4_from_rib(v);
}

/* The current transform to camera space (inside the world). */
static mat4 ctm_to_camera(const rib_parser *p)
{
    return mat4_mul(p->scene->camera.camera_from_world, p->attr.ctm);
}

void rib_coordinate_system(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the space name");
    if (!name || !rib_no_more_args(p, req, 1))
        return;
    scene_space *space = rib_add_space(p);
    space->name = xstrndup(name, strlen(name));
    space->to_world = p->attr.ctm;
    space->to_camera = ctm_to_camera(p);
    space->pos = req->pos;
}

void rib_coord_sys_transform(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the space name");
    if (!name || !rib_no_more_args(p, req, 1))
        return;
    if (strcmp(name, "world") == 0) {
        p->attr.ctm = mat4_identity();
        return;
    }
    if (strcmp(name, "camera") == 0) {
        p->attr.ctm = p->scene->camera.world_from_camera;
        return;
    }
    for (int i = p->scene->nspaces - 1; i >= 0; i--)
        if (strcmp(p->scene->spaces[i].name, name) == 0) {
            p->attr.ctm = p->scene->spaces[i].to_world;
            return;
        }
    rib_error(p, req, req->args[0].pos, "no coordinate system named \"%s\" (define it first "
              "with CoordinateSystem \"%s\")", name, name);
}

/* ---------------------------------------------------------------------- */
/* Surface, Displacement                                                   */
/* ---------------------------------------------------------------------- */

/* Shader names are plain names: the file is "<dir>/<name>.sl" on the
 * search path. */
static bool plain_name(const char *s)
{
    if (!*s)
        return false;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
              (*s >= '0' && *s <= '9') || *s == '_' || *s == '-' || *s == '.'))
            return false;
    return true;
}

/* A shader call: the name in argument 0, the parameters from argument
 * `first` on. Returns the index into scene.shaders, -2 after an error. */
static int shader_call_at(rib_parser *p, const rib_request *req, sl_shader_kind kind, int first)
{
    const char *name = rib_read_string(p, req, 0, "the shader name");
    if (!name)
        return -2;
    if (!plain_name(name) || name[0] == '.') {
        rib_error(p, req, req->args[0].pos, "the shader name \"%s\" must be a plain name "
                  "(letters, digits, '_'); put its folder on the search path with Option "
                  "\"searchpath\" \"shader\" [\"dir:&\"]", name);
        return -2;
    }
    rib_params params;
    if (!rib_params_read(p, req, first, RIB_PARAMS_UNIFORM, &params))
        return -2;
    scene_shader *sh = rib_add_shader(p);
    sh->kind = kind;
    sh->name = xstrndup(name, strlen(name));
    sh->params = params.items;
    sh->nparams = params.count;
    sh->pos = req->pos;
    if (p->in_world) {
        sh->shader_to_world = p->attr.ctm;
        sh->shader_to_camera = ctm_to_camera(p);
    } else {
        sh->shader_to_camera = p->attr.ctm;   /* to_world at WorldBegin */
    }
    return p->scene->nshaders - 1;
}

static int shader_call(rib_parser *p, const rib_request *req, sl_shader_kind kind)
{
    return shader_call_at(p, req, kind, 1);
}

void rib_surface(rib_parser *p, const rib_request *req)
{
    int i = shader_call(p, req, SL_SHADER_SURFACE);
    if (i >= -1)
        p->attr.surface = i;
}

void rib_displacement(rib_parser *p, const rib_request *req)
{
    int i = shader_call(p, req, SL_SHADER_DISPLACEMENT);
    if (i >= -1)
        p->attr.displacement = i;
}

/* Shader calls made before WorldBegin: their world transform is known
 * once the camera is. */
void rib_shaders_finish(rib_parser *p)
{
    const mat4 *w = &p->scene->camera.world_from_camera;
    for (int i = 0; i < p->scene->nshaders; i++) {
        scene_shader *sh = &p->scene->shaders[i];
        sh->shader_to_world = mat4_mul(*w, sh->shader_to_camera);
    }
    /* lights declared before WorldBegin: their world placement is known
     * now (every light that exists at WorldBegin is one) */
    for (int i = 0; i < p->scene->nlights; i++) {
        scene_light *l = &p->scene->lights[i];
        l->light_to_world = mat4_mul(*w, l->light_to_camera);
        l->from_world = mat4_xform_point(&l->light_to_world, l->from);
        l->to_world = mat4_xform_point(&l->light_to_world, l->to);
    }
}

/* ---------------------------------------------------------------------- */
/* LightSource, Illuminate                                                 */
/* ---------------------------------------------------------------------- */

enum { P_INTENSITY = 1, P_LIGHTCOLOR = 2, P_FROM = 4, P_TO = 8, P_CONE = 16 };

static const struct { const char *name; scene_light_kind kind; int params; } light_kinds[] = {
    { "ambientlight", SCENE_AMBIENT_LIGHT, P_INTENSITY | P_LIGHTCOLOR },
    { "distantlight", SCENE_DISTANT_LIGHT, P_INTENSITY | P_LIGHTCOLOR | P_FROM | P_TO },
    { "pointlight", SCENE_POINT_LIGHT, P_INTENSITY | P_LIGHTCOLOR | P_FROM },
    { "spotlight", SCENE_SPOT_LIGHT, P_INTENSITY | P_LIGHTCOLOR | P_FROM | P_TO | P_CONE },
};

const char *scene_light_kind_name(scene_light_kind kind)
{
    return (unsigned)kind < 4 ? light_kinds[kind].name
           : kind == SCENE_SHADER_LIGHT ? "light shader" : "?";
}

static void light_defaults(scene_light *l)
{
    l->intensity = 1;
    l->lightcolor[0] = l->lightcolor[1] = l->lightcolor[2] = 1;
    l->from = v3(0, 0, 0);
    l->to = v3(0, 0, 1);
    l->coneangle = 30 * M_PI / 180;
    l->conedeltaangle = 5 * M_PI / 180;
    l->beamdistribution = 2;
}

/* Which parameter bit a name sets (0: not a light parameter). */
static int light_param_bit(const char *name)
{
    static const struct { const char *name; int bit; } names[] = {
        { "intensity", P_INTENSITY }, { "lightcolor", P_LIGHTCOLOR }, { "from", P_FROM },
        { "to", P_TO }, { "coneangle", P_CONE }, { "conedeltaangle", P_CONE },
        { "beamdistribution", P_CONE },
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i].name) == 0)
            return names[i].bit;
    return 0;
}

static void set_light_param(scene_light *l, const scene_param *v)
{
    const double *x = v->values;
    if (strcmp(v->name, "intensity") == 0) l->intensity = x[0];
    else if (strcmp(v->name, "lightcolor") == 0) memcpy(l->lightcolor, x, 3 * sizeof *x);
    else if (strcmp(v->name, "from") == 0) l->from = v3(x[0], x[1], x[2]);
    else if (strcmp(v->name, "to") == 0) l->to = v3(x[0], x[1], x[2]);
    else if (strcmp(v->name, "coneangle") == 0) l->coneangle = x[0];
    else if (strcmp(v->name, "conedeltaangle") == 0) l->conedeltaangle = x[0];
    else if (strcmp(v->name, "beamdistribution") == 0) l->beamdistribution = x[0];
}

/* Applies the parameters; false after an error. */
static bool light_params(rib_parser *p, const rib_request *req, int allowed,
                         const rib_params *params, scene_light *l)
{
    for (int i = 0; i < params->count; i++) {
        const scene_param *v = &params->items[i];
        int bit = light_param_bit(v->name);
        bool scalar = (bit & (P_INTENSITY | P_CONE)) != 0;
        if (strcmp(v->name, "shadows") == 0 || strcmp(v->name, "__shadows") == 0) {
            if (!read_switch(p, req, v, &l->shadows))
                return false;
        } else if (bit && (allowed & bit) && v->values && v->count == (scalar ? 1 : 3)) {
            set_light_param(l, v);
        } else if (bit && (allowed & bit)) {
            rib_error(p, req, v->pos, "parameter \"%s\" must be a %s, not a %s%s", v->name,
                      scalar ? "float" : bit == P_LIGHTCOLOR ? "color" : "point",
                      rib_type_name(v->type), v->arraylen > 1 ? " array" : "");
            return false;
        } else {
            rib_warning(p, req, v->pos, "\"%s\" is not a parameter of %s (ignored)", v->name,
                        scene_light_kind_name(l->kind));
        }
    }
    return true;
}

static void light_transforms(rib_parser *p, scene_light *l)
{
    l->light_to_world = p->attr.ctm;
    l->light_to_camera = ctm_to_camera(p);
    l->from_world = mat4_xform_point(&l->light_to_world, l->from);
    l->to_world = mat4_xform_point(&l->light_to_world, l->to);
    l->from_camera = mat4_xform_point(&l->light_to_camera, l->from);
    l->to_camera = mat4_xform_point(&l->light_to_camera, l->to);
}

/* The handle as text: "1" for 1, the string itself for a string. */
static char *handle_text(const rib_request *req, const rib_arg *arg)
{
    char buf[64];
    if (rib_arg_is_string(arg))
        return xstrndup(rib_arg_string(req, arg), strlen(rib_arg_string(req, arg)));
    int n;
    const double *v = rib_arg_numbers(req, arg, &n);
    snprintf(buf, sizeof buf, "%.17g", v[0]);
    return xstrndup(buf, strlen(buf));
}

static bool valid_handle(rib_parser *p, const rib_request *req, const rib_arg *arg)
{
    if ((arg->kind == RIB_ARG_NUMBER) || (arg->kind == RIB_ARG_STRING))
        return true;
    rib_error(p, req, arg->pos, "the light handle must be a number or a string, got %s",
              rib_arg_describe(arg));
    return false;
}

void rib_light_source(rib_parser *p, const rib_request *req)
{
    if (!p->in_world && p->world_done) {
        rib_error(p, req, req->pos, "must come between WorldBegin and WorldEnd");
        return;
    }
    const char *name = rib_read_string(p, req, 0, "the light shader name");
    if (!name)
        return;
    /* Other renderers accept lights before WorldBegin: the light is then
     * in the space current there (the camera's, as built so far), and
     * rib_shaders_finish places it in the world at WorldBegin. */
    if (!p->in_world && !p->warned_early_light) {
        rib_warning(p, req, req->pos, "a light before WorldBegin is placed where the camera "
                    "transform built so far puts it (move it after WorldBegin to place it in "
                    "world space)");
        p->warned_early_light = true;
    }
    int k = -1;
    for (int i = 0; i < 4; i++)
        if (strcmp(name, light_kinds[i].name) == 0)
            k = i;
    /* parameters come in pairs: an odd count left means a handle */
    bool has_handle = (req->nargs - 1) % 2 == 1;
    if (has_handle && !valid_handle(p, req, &req->args[1]))
        return;
    if (k < 0) {
        /* not a built-in: a light shader (RI Spec 3.2 §9.3), compiled with
         * the job's shaders, its parameters set on its instance, shader
         * space the light's space */
        int sh = shader_call_at(p, req, SL_SHADER_LIGHT, has_handle ? 2 : 1);
        if (sh < 0)
            return;
        scene_light l;
        memset(&l, 0, sizeof l);
        l.kind = SCENE_SHADER_LIGHT;
        l.shader = sh;
        l.shadows = p->attr.shadows;
        light_defaults(&l);
        l.handle = has_handle ? handle_text(req, &req->args[1]) : NULL;
        l.pos = req->pos;
        light_transforms(p, &l);
        *rib_add_light(p) = l;
        set_light_on(&p->attr, p->scene->nlights - 1, true);
        return;
    }
    rib_params params;
    if (!rib_params_read(p, req, has_handle ? 2 : 1, RIB_PARAMS_UNIFORM, &params))
        return;
    scene_light l;
    memset(&l, 0, sizeof l);
    l.kind = light_kinds[k].kind;
    l.shader = -1;
    l.shadows = p->attr.shadows;
    light_defaults(&l);
    bool ok = light_params(p, req, light_kinds[k].params, &params, &l);
    rib_params_clear(&params);
    if (!ok)
        return;
    l.handle = has_handle ? handle_text(req, &req->args[1]) : NULL;
    l.pos = req->pos;
    light_transforms(p, &l);
    *rib_add_light(p) = l;
    set_light_on(&p->attr, p->scene->nlights - 1, true);
}

void rib_illuminate(rib_parser *p, const rib_request *req)
{
    double on;
    if (req->nargs < 1 || !valid_handle(p, req, &req->args[0])) {
        if (req->nargs < 1)
            rib_error(p, req, req->pos, "missing the light handle");
        return;
    }
    int next = rib_read_numbers(p, req, 1, 1, &on, "1 for on or 0 for off");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    char *handle = handle_text(req, &req->args[0]);
    int found = -1;
    for (int i = p->scene->nlights - 1; i >= 0 && found < 0; i--)
        if (p->scene->lights[i].handle && strcmp(p->scene->lights[i].handle, handle) == 0)
            found = i;
    if (found < 0)
        rib_error(p, req, req->args[0].pos, "no light has the handle %s", handle);
    else
        set_light_on(&p->attr, found, on != 0);
    free(handle);
}
