/*
 * vm.c: the virtual machine's public face (shader.h): creation with all
 * memory allocated up front, globals in and out in each arithmetic, spaces
 * and lights, and sl_vm_run, which checks its arguments and hands over to
 * the backend of the mode (vm_float.c, vm_dual.c, vm_interval.c,
 * vm_affine.c).
 */
#include "sl/vm_internal.h"
#include "sl/check.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static const sl_limits default_limits = { 1000000, 64 };

const char *sl_mode_name(sl_mode mode)
{
    switch (mode) {
    case SL_MODE_FLOAT: return "float";
    case SL_MODE_DUAL: return "dual";
    case SL_MODE_INTERVAL: return "interval";
    case SL_MODE_AFFINE: return "affine";
    }
    return "?";
}

sl_vm *sl_vm_new(const sl_limits *limits)
{
    sl_vm *self = xcalloc(1, sizeof *self);
    self->limits = limits ? *limits : default_limits;
    if (self->limits.max_instructions <= 0)
        self->limits.max_instructions = default_limits.max_instructions;
    if (self->limits.max_loop_iterations <= 0)
        self->limits.max_loop_iterations = default_limits.max_loop_iterations;
    for (int s = 0; s < SL_SPACE__COUNT; s++) {
        self->identity.to_current[s] = mat4_identity();
        self->identity.from_current[s] = mat4_identity();
    }
    self->spaces = &self->identity;
    self->near = 0;
    self->far = 1;
    self->depth_stale = true;
    static const double unit_window[4] = { -1, 1, -1, 1 };
    mat4 id = mat4_identity();
    sl_vm_set_projection(self, &id, unit_window, 1, 1);
    sl_vm_set_message(self, SL_MSG_RENDERERINFO, "renderer", SL_TYPE_STRING, NULL, "aafarm");
    self->f = xcalloc(SL_MAX_SLOTS, sizeof *self->f);
    self->d = xcalloc(SL_MAX_SLOTS, sizeof *self->d);
    self->i = xcalloc(SL_MAX_SLOTS, sizeof *self->i);
    self->a = xcalloc(SL_MAX_SLOTS, sizeof *self->a);
    self->str = xcalloc(SL_MAX_STRING_SLOTS, sizeof *self->str);
    size_t pool_value = sizeof(aa_form);
    if (sizeof(sl_aderiv) > pool_value)
        pool_value = sizeof(sl_aderiv);
    if (sizeof(sl_ideriv) > pool_value)
        pool_value = sizeof(sl_ideriv);
    self->pool = xcalloc(SL_VM_POOL_VALUES, pool_value);
    self->spool = xcalloc(SL_VM_POOL_VALUES, sizeof *self->spool);
    sl_vm_clear_globals(self);
    return self;
}

void sl_vm_destroy(sl_vm **self_p)
{
    sl_vm *self = *self_p;
    if (!self)
        return;
    free(self->f);
    free(self->d);
    free(self->i);
    free(self->a);
    free(self->id);
    free(self->ad);
    free(self->str);
    free(self->pool);
    free(self->spool);
    vm_uniform_free(self);
    free(self);
    *self_p = NULL;
}

/* current -> camera, then z -> (z - near) / (far - near): the camera
 * matrix with row 2 replaced by s (row 2) - s near (row 3), s = 1/(far -
 * near) (what scale(1,1,s) * translate(0,0,-near) * camera gives, in 8
 * products instead of 128: this runs at every box's binding of spaces) */
static void update_depth(sl_vm *self)
{
    const mat4 *cam = &self->spaces->from_current[SL_SPACE_CAMERA];
    double s = 1 / (self->far - self->near), t = s * -self->near;
    self->depth = *cam;
    for (int j = 0; j < 4; j++)
        self->depth.m[2][j] = s * cam->m[2][j] + t * cam->m[3][j];
    self->depth_stale = false;
}

void sl_vm_set_spaces(sl_vm *self, const sl_spaces *spaces)
{
    self->spaces = spaces ? spaces : &self->identity;
    self->depth_stale = true;           /* made when a shader asks for it */
    self->proj_stale = true;
}

void sl_vm_set_projection(sl_vm *self, const mat4 *screen_from_camera,
                          const double window[4], int xres, int yres)
{
    double l = window[0], r = window[1], b = window[2], t = window[3];
    self->screen_from_camera = *screen_from_camera;
    mat4 n = mat4_identity();
    n.m[0][0] = 1 / (r - l);
    n.m[0][3] = -l / (r - l);
    n.m[1][1] = -1 / (t - b);            /* y down: top is 0 */
    n.m[1][3] = t / (t - b);
    self->ndc_from_screen = n;
    self->raster_from_ndc = mat4_scale(xres, yres, 1);
    self->proj_stale = true;
}

mat4 sl_projection_perspective(double fov_degrees, double near, double far)
{
    double k = 1 / tan(fov_degrees * (M_PI / 360));
    mat4 m = mat4_identity();
    m.m[0][0] = m.m[1][1] = k;
    m.m[2][2] = far / (far - near);
    m.m[2][3] = -far * near / (far - near);
    m.m[3][2] = 1;
    m.m[3][3] = 0;
    return m;
}

mat4 sl_projection_orthographic(double near, double far)
{
    mat4 m = mat4_identity();
    m.m[2][2] = 1 / (far - near);
    m.m[2][3] = -near / (far - near);
    return m;
}

/* screen, NDC, raster from "current" (each the last one's, times its map)
 * and back (the inverse of each map, then camera -> current). */
static void update_projection(sl_vm *self)
{
    const mat4 *maps[3] = { &self->screen_from_camera, &self->ndc_from_screen,
                            &self->raster_from_ndc };
    mat4 from = self->spaces->from_current[SL_SPACE_CAMERA];
    mat4 to = self->spaces->to_current[SL_SPACE_CAMERA];
    for (int k = 0; k < 3; k++) {
        mat4 inv;
        mat4_invert(maps[k], &inv);         /* singular (a flat window): identity */
        from = mat4_mul(*maps[k], from);
        to = mat4_mul(to, inv);
        self->proj_from[k] = from;
        self->proj_to[k] = to;
    }
    self->proj_stale = false;
}

/* ---- light shaders ---- */

sl_status sl_light_eval(sl_vm *self, const sl_instance *inst, const double Ps[3],
                        sl_light_sample *out)
{
    static const double zero[3] = { 0, 0, 0 };
    memset(out, 0, sizeof *out);
    sl_vm_clear_globals(self);
    sl_vm_set_float(self, SL_G_P, Ps);
    sl_vm_set_float(self, SL_G_L, zero);
    sl_vm_set_float(self, SL_G_Cl, zero);
    sl_status st = sl_vm_run(self, inst, SL_MODE_FLOAT, NULL);
    if (st != SL_OK)
        return st;
    const sl_program *p = inst->program;
    if (p->kind != SL_SHADER_LIGHT)
        return sl_vm_fail(self, SL_ERR_RUNTIME, "'%s' is not a light shader", p->name);
    double L[3];
    sl_vm_get_float(self, SL_G_L, L);
    sl_vm_get_float(self, SL_G_Cl, out->Cl);
    for (int i = 0; i < 3; i++)      /* the light's L points at Ps; the sample's away */
        out->L[i] = -L[i];
    out->ambient = !p->emits_light;
    return SL_OK;
}

/* ---- message passing ---- */

static vm_message *message_slot(sl_vm *self, int scope, const char *name)
{
    for (int i = 0; i < self->nmessages; i++)
        if (self->messages[i].scope == scope && strcmp(self->messages[i].name, name) == 0)
            return &self->messages[i];
    if (self->nmessages == SL_VM_MAX_MESSAGES)
        return NULL;
    vm_message *m = &self->messages[self->nmessages++];
    memset(m, 0, sizeof *m);
    m->scope = scope;
    snprintf(m->name, sizeof m->name, "%s", name);
    return m;
}

static bool set_message(sl_vm *self, int scope, const char *name, int size,
                        const double *values, const char *string, bool varying)
{
    if (scope < 0 || scope >= SL_MSG__COUNT || !name || strlen(name) >= 64 ||
        (size == 0 && (!string || strlen(string) >= 128)) || (size > 0 && !values))
        return false;
    vm_message *m = message_slot(self, scope, name);
    if (!m)
        return false;
    m->size = size;
    m->varying = varying;
    if (size)
        memcpy(m->v, values, (size_t)size * sizeof *values);
    else
        snprintf(m->s, sizeof m->s, "%s", string);
    return true;
}

bool sl_vm_set_message(sl_vm *self, sl_message_scope scope, const char *name, sl_type type,
                       const double *values, const char *string)
{
    int size = type == SL_TYPE_STRING ? 0 : type == SL_TYPE_FLOAT ? 1
             : type == SL_TYPE_MATRIX ? 16 : 3;
    return set_message(self, (int)scope, name, size, values, string, false);
}

int sl_vm_capture_outputs(sl_vm *self, sl_message_scope scope)
{
    const sl_program *p = self->prog;
    if (!p || (self->mode != SL_MODE_FLOAT && self->mode != SL_MODE_DUAL))
        return 0;
    int n = 0;
    for (int i = 0; i < p->nparams; i++) {
        const sl_param *q = &p->params[i];
        if (!q->output)
            continue;
        double v[16];
        bool str = q->type == SL_TYPE_STRING;
        if (!str && q->size > 16)
            continue;                   /* arrays are not messages */
        for (int k = 0; !str && k < q->size; k++)
            v[k] = self->mode == SL_MODE_FLOAT ? self->f[q->slot + k] : self->d[q->slot + k].v;
        const char *s = str ? self->str[q->slot] : NULL;
        n += set_message(self, (int)scope, q->name, str ? 0 : q->size, v, s ? s : "", true);
    }
    return n;
}

void sl_vm_clear_messages(sl_vm *self, sl_message_scope scope)
{
    int kept = 0;
    for (int i = 0; i < self->nmessages; i++)
        if (self->messages[i].scope != (int)scope) {
            if (kept != i)           /* a message is ~340 bytes: no copy onto itself */
                self->messages[kept] = self->messages[i];
            kept++;
        }
    self->nmessages = kept;
}

const vm_message *sl_vm_message(const sl_vm *vm, int scope, const char *name, int size)
{
    if (!name)
        return NULL;
    for (int i = 0; i < vm->nmessages; i++) {
        const vm_message *m = &vm->messages[i];
        if (m->scope == scope && m->size == size && strcmp(m->name, name) == 0)
            return m;
    }
    return NULL;
}

void sl_vm_set_print(sl_vm *self, sl_print_fn fn, void *ctx)
{
    self->print = fn;
    self->print_ctx = ctx;
}

void sl_vm_set_box_runs(sl_vm *self, bool on) { self->box_runs = on; }

void sl_vm_set_tape(sl_vm *self, const uint8_t *plan, uint32_t tape, bool record)
{
    self->tape_plan = plan;
    self->tape_in = tape;
    self->tape_record = record;
}

uint32_t sl_vm_tape(const sl_vm *self)
{
    uint32_t t = self->tape_in;
    const sl_program *p = self->prog;
    if (!p || !self->tape_record)
        return t;
    for (int i = 0; i < p->ntape_sites; i++) {
        unsigned mask = ((1u << SL_TAPE_BITS) - 1) << (SL_TAPE_BITS * i);
        unsigned d = self->tape_seen[i];
        if (!(t & mask) && d >= 1 && d <= 3)
            t |= d << (SL_TAPE_BITS * i);
    }
    return t;
}

void sl_vm_set_cancel(sl_vm *self, const atomic_int *flag)
{
    self->cancel = flag;
}

void sl_vm_set_clipping(sl_vm *self, double near, double far)
{
    if (!(far > near) || !isfinite(far) || !isfinite(near))
        return;
    self->near = near;
    self->far = far;
    self->depth_stale = true;
}

void sl_vm_set_lights(sl_vm *self, sl_light_fn fn, void *user)
{
    self->light_fn = fn;
    self->light_user = user;
}

void sl_vm_set_fixed_lights(sl_vm *self, const sl_light_sample *samples, int count)
{
    if (count < 0)
        count = 0;
    if (count > SL_VM_MAX_LIGHTS)
        count = SL_VM_MAX_LIGHTS;
    if (count)
        memcpy(self->fixed_lights, samples, (size_t)count * sizeof *samples);
    self->nfixed_lights = count;
}

void sl_vm_set_tracer(sl_vm *self, const sl_tracer *tracer)
{
    if (tracer)
        self->tracer = *tracer;
    else
        memset(&self->tracer, 0, sizeof self->tracer);
}

bool sl_vm_traces(const sl_vm *vm, int kind)
{
    return kind == SL_RAY_TRACE ? vm->tracer.trace != NULL : vm->tracer.shadow != NULL;
}

/* shadow(): the segment towards the light. In a light shader L points from
 * the light to Ps (illuminate: the light is at Ps - L; solar: at infinity
 * along -L); in a surface shader the current light of the illuminance loop
 * gives L (towards it) and whether it is at infinity. */
void sl_vm_ray(sl_vm *vm, int kind, const char *map, const double P[3], const double D[3],
               double out[3])
{
    out[0] = out[1] = out[2] = 0;
    if (!sl_vm_traces(vm, kind))
        return;
    if (kind == SL_RAY_TRACE) {
        vm->tracer.trace(vm->tracer.user, P, D, out);
        return;
    }
    double dir[3], tmax = 1.0;
    for (int k = 0; k < 3; k++)
        dir[k] = kind == SL_RAY_SHADOW_SURFACE ? D[k] : -D[k];
    if (kind == SL_RAY_SHADOW_SOLAR) {
        tmax = INFINITY;
    } else if (kind == SL_RAY_SHADOW_SURFACE) {
        if (vm->illum_next <= 0 || vm->illum_next > vm->nillum)
            return;               /* outside an illuminance loop: no light */
        if (vm->illum[vm->illum_next - 1].directional)
            tmax = INFINITY;
    }
    if (!(dir[0] != 0 || dir[1] != 0 || dir[2] != 0))
        return;
    double f = vm->tracer.shadow(vm->tracer.user, map ? map : "", P, dir, tmax);
    out[0] = f > 0 ? (f < 1 ? f : 1) : 0;
}

void sl_vm_set_seed(sl_vm *self, uint64_t seed) { self->seed = seed; }

/* ---------------------------------------------------------------------- */
/* globals                                                                 */
/* ---------------------------------------------------------------------- */

static bool global_ok(sl_global g) { return (unsigned)g < SL_G__COUNT; }

/* Clearing is lazy: each mode's globals are zeroed when that mode is
 * first used after sl_vm_clear_globals (the renderer clears before every
 * run, and uses one mode per run). */
void sl_vm_clear_globals(sl_vm *self)
{
    self->clear_pending = 0xf;
    self->nvarying = 0;
    self->gderiv_set = 0;              /* every global's derivatives unknown */
}

_Static_assert(SL_GLOBAL_SLOTS <= 64, "gderiv_set has a bit per global slot");

/* d/du (k = 0) or d/dv (k = 1) of global slot s: given, or unknown */
static ia_interval gderiv_of(const sl_vm *self, int s, int k)
{
    return (self->gderiv_set >> s) & 1 ? self->gderiv[s][k] : ia_entire();
}

static bool add_varying(sl_vm *self, bool global, int target, int size,
                        const double coef[16][3])
{
    if (self->nvarying >= SL_VM_MAX_VARYING || size < 1 || size > 3)
        return false;
    vm_varying *v = &self->varying[self->nvarying++];
    v->global = global;
    v->target = target;
    v->size = size;
    memcpy(v->c, coef, sizeof v->c);
    return true;
}

bool sl_vm_set_varying_global(sl_vm *self, sl_global g, const double coef[16][3])
{
    if (!global_ok(g))
        return false;
    return add_varying(self, true, sl_global_slot(g), sl_global_size(g), coef);
}

bool sl_vm_set_varying_param(sl_vm *self, int param, int size, const double coef[16][3])
{
    return param >= 0 && add_varying(self, false, param, size, coef);
}

void sl_vm_set_derivs(sl_vm *self, sl_global g, const ia_interval *du, const ia_interval *dv)
{
    if (!global_ok(g))
        return;
    int s = sl_global_slot(g), size = sl_global_size(g);    /* calls: not in the loop */
    for (int k = 0; k < size; k++) {
        self->gderiv[s + k][0] = du[k];
        self->gderiv[s + k][1] = dv[k];
        self->gderiv_set |= (uint64_t)1 << (s + k);
    }
}

static void ensure_clear(sl_vm *self, sl_mode mode)
{
    unsigned bit = 1u << mode;
    if (!(self->clear_pending & bit))
        return;
    self->clear_pending &= ~bit;
    switch (mode) {
    case SL_MODE_FLOAT: memset(self->f, 0, SL_GLOBAL_SLOTS * sizeof *self->f); break;
    case SL_MODE_DUAL: memset(self->d, 0, SL_GLOBAL_SLOTS * sizeof *self->d); break;
    case SL_MODE_INTERVAL:
        for (int s = 0; s < SL_GLOBAL_SLOTS; s++)
            self->i[s] = ia_point(0.0);
        break;
    case SL_MODE_AFFINE:
        for (int s = 0; s < SL_GLOBAL_SLOTS; s++)
            aa_const(&self->a[s], 0.0);
        break;
    }
}

/* A global's values, 1 or 3 of them (sl_global_size), as a copy of fixed
 * size, which compiles to a few moves: a copy of unknown size was a libc
 * call for every global of every evaluation (issue 24) */
#define COPY_GLOBAL(dst, src, count)                                    \
    do {                                                                \
        assert((count) == 1 || (count) == 3);                           \
        if ((count) == 3)                                               \
            memcpy((dst), (src), 3 * sizeof *(dst));                    \
        else                                                            \
            memcpy((dst), (src), sizeof *(dst));                        \
    } while (0)

void sl_vm_set_float(sl_vm *self, sl_global g, const double *values)
{
    ensure_clear(self, SL_MODE_FLOAT);
    if (!global_ok(g))
        return;
    COPY_GLOBAL(&self->f[sl_global_slot(g)], values, sl_global_size(g));
}

void sl_vm_set_dual(sl_vm *self, sl_global g, const sl_dual *values)
{
    ensure_clear(self, SL_MODE_DUAL);
    if (!global_ok(g))
        return;
    COPY_GLOBAL(&self->d[sl_global_slot(g)], values, sl_global_size(g));
}

void sl_vm_set_interval(sl_vm *self, sl_global g, const ia_interval *values)
{
    ensure_clear(self, SL_MODE_INTERVAL);
    if (!global_ok(g))
        return;
    COPY_GLOBAL(&self->i[sl_global_slot(g)], values, sl_global_size(g));
}

/* count forms (a form is never read past n: the rest of its array is
 * stale by design, affine.h): the fields before the coefficients, then
 * the coefficients in blocks of four up to n (AA_MAX_SYMBOLS is a
 * multiple of four), each block a fixed-size copy: a few vector moves,
 * where a copy up to n compiled to rep movs, whose start-up cost
 * dominated these short copies, and a whole form moved 168 bytes for the
 * 2-4 symbols of most globals (issue 24) */
_Static_assert(AA_MAX_SYMBOLS % 4 == 0, "coefficients copy in blocks of four");
static inline void copy_form(aa_form *dst, const aa_form *src)
{
    int n = src->n;
    assert(n <= AA_MAX_SYMBOLS);
    memcpy(dst, src, offsetof(aa_form, c));
    for (int i = 0; i < n; i += 4)
        memcpy(&dst->c[i], &src->c[i], 4 * sizeof src->c[0]);
}

static void copy_forms(aa_form *dst, const aa_form *src, int count)
{
    for (int k = 0; k < count; k++)
        copy_form(&dst[k], &src[k]);
}

void sl_vm_set_affine(sl_vm *self, sl_global g, const aa_form *values)
{
    ensure_clear(self, SL_MODE_AFFINE);
    if (!global_ok(g))
        return;
    copy_forms(&self->a[sl_global_slot(g)], values, sl_global_size(g));
}

void sl_vm_get_float(const sl_vm *self, sl_global g, double *values)
{
    ensure_clear((sl_vm *)self, SL_MODE_FLOAT);
    if (global_ok(g))
        COPY_GLOBAL(values, &self->f[sl_global_slot(g)], sl_global_size(g));
}

void sl_vm_get_dual(const sl_vm *self, sl_global g, sl_dual *values)
{
    ensure_clear((sl_vm *)self, SL_MODE_DUAL);
    if (global_ok(g))
        COPY_GLOBAL(values, &self->d[sl_global_slot(g)], sl_global_size(g));
}

void sl_vm_get_interval(const sl_vm *self, sl_global g, ia_interval *values)
{
    ensure_clear((sl_vm *)self, SL_MODE_INTERVAL);
    if (global_ok(g))
        COPY_GLOBAL(values, &self->i[sl_global_slot(g)], sl_global_size(g));
}

void sl_vm_get_affine(const sl_vm *self, sl_global g, aa_form *values)
{
    ensure_clear((sl_vm *)self, SL_MODE_AFFINE);
    if (global_ok(g))
        copy_forms(values, &self->a[sl_global_slot(g)], sl_global_size(g));
}

/* ---------------------------------------------------------------------- */
/* helpers of the backends                                                 */
/* ---------------------------------------------------------------------- */

sl_status sl_vm_fail(sl_vm *vm, sl_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    err_vset(vm->error, sizeof vm->error, fmt, ap);
    va_end(ap);
    err_prefix(vm->error, sizeof vm->error, "shader '%s'", vm->prog ? vm->prog->name : "?");
    return st;
}

const mat4 *sl_vm_space_id(sl_vm *vm, int space, int dir)
{
    if (space == SL_SPACE_DEPTH) {
        if (vm->depth_stale) update_depth(vm);
        return &vm->depth;
    }
    if (space >= SL_SPACE_SCREEN && space < SL_SPACE__NAMED) {
        if (vm->proj_stale) update_projection(vm);
        return dir == SL_SPACE_TO_CURRENT ? &vm->proj_to[space - SL_SPACE_SCREEN]
                                          : &vm->proj_from[space - SL_SPACE_SCREEN];
    }
    if (space < 0 || space >= SL_SPACE__COUNT)
        return NULL;
    return dir == SL_SPACE_TO_CURRENT ? &vm->spaces->to_current[space]
                                      : &vm->spaces->from_current[space];
}

const mat4 *sl_vm_space(sl_vm *vm, const char *name, int dir)
{
    return sl_vm_space_id(vm, name ? sl_space_find(name) : -1, dir);
}

int sl_vm_light_samples(sl_vm *vm, const double P[3], sl_light_sample *out)
{
    int n = 0;
    if (vm->light_fn) {
        n = vm->light_fn(vm->light_user, P, out, SL_VM_MAX_LIGHTS);
        if (n < 0)
            n = 0;
        if (n > SL_VM_MAX_LIGHTS)
            n = SL_VM_MAX_LIGHTS;
    }
    for (int k = 0; k < vm->nfixed_lights && n < SL_VM_MAX_LIGHTS; k++)
        out[n++] = vm->fixed_lights[k];
    return n;
}

double sl_vm_random(sl_vm *vm)
{
    uint64_t z = (vm->rng += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1p-53;
}

/* ---------------------------------------------------------------------- */
/* running                                                                 */
/* ---------------------------------------------------------------------- */

static void load_strings(sl_vm *vm, const sl_program *p)
{
    for (int k = 0; k < p->nstrings; k++)
        vm->str[p->string_slots[k]] = p->strings[k];
}

/* Whether this affine run takes or records a tape (sl_vm_set_tape): a box
 * run with a tape plan, or recording a program's tape sites; it runs in
 * the VM instantiated with VM_TAPE */
static bool tape_run(const sl_vm *self)
{
    return self->box_runs && !self->slopes &&
           (self->tape_plan || (self->tape_record && self->prog->tape_site_of));
}

/* A program that takes derivatives runs in the derivative-carrying variant
 * of its range mode (vm_deriv.inc): the globals go in with the bounds of
 * sl_vm_set_derivs, and their values come back to the mode's own file,
 * where sl_vm_get_* read them. */
static sl_status run_with_derivatives(sl_vm *self, sl_mode mode)
{
    sl_status st;
    if (mode == SL_MODE_AFFINE) {
        if (!self->ad)
            self->ad = xcalloc(SL_MAX_SLOTS, sizeof *self->ad);
        /* only the globals the program may touch (a slot it never names
         * keeps its value in self->a; issue 24: copying all 46 forms in
         * and out was 12 % of a displaced terrain's time) */
        uint64_t used = self->prog->global_slots ? self->prog->global_slots : ~0ull;
        for (uint64_t m = used; m; m &= m - 1) {
            int s = __builtin_ctzll(m);
            if (s >= SL_GLOBAL_SLOTS) break;
            copy_form(&self->ad[s].v, &self->a[s]);     /* up to n, fixed-size blocks */
            self->ad[s].du = gderiv_of(self, s, 0);
            self->ad[s].dv = gderiv_of(self, s, 1);
        }
        st = tape_run(self) ? sl_vm_exec_affine_deriv_tape(self) : sl_vm_exec_affine_deriv(self);
        for (uint64_t m = used; m; m &= m - 1) {
            int s = __builtin_ctzll(m);
            if (s >= SL_GLOBAL_SLOTS) break;
            copy_form(&self->a[s], &self->ad[s].v);
        }
    } else {
        if (!self->id)
            self->id = xcalloc(SL_MAX_SLOTS, sizeof *self->id);
        for (int s = 0; s < SL_GLOBAL_SLOTS; s++)
            self->id[s] = (sl_ideriv){self->i[s], gderiv_of(self, s, 0), gderiv_of(self, s, 1)};
        st = sl_vm_exec_interval_deriv(self);
        for (int s = 0; s < SL_GLOBAL_SLOTS; s++)
            self->i[s] = self->id[s].v;
    }
    return st;
}

static sl_status run(sl_vm *self, const sl_instance *inst, sl_mode mode, aa_context *ctx,
                     bool slopes);

sl_status sl_vm_run(sl_vm *self, const sl_instance *inst, sl_mode mode, aa_context *ctx)
{
    return run(self, inst, mode, ctx, false);
}

sl_status sl_vm_run_slopes(sl_vm *self, const sl_instance *inst)
{
    self->slopes = true;
    sl_status st = run(self, inst, SL_MODE_INTERVAL, NULL, true);
    self->slopes = false;
    return st;
}

void sl_vm_get_slopes(const sl_vm *self, sl_global g, ia_interval *du, ia_interval *dv)
{
    int n = global_ok(g) ? sl_global_size(g) : 0, s = global_ok(g) ? sl_global_slot(g) : 0;
    for (int k = 0; k < n; k++) {
        du[k] = self->id ? self->id[s + k].du : ia_entire();
        dv[k] = self->id ? self->id[s + k].dv : ia_entire();
    }
}

static sl_status run(sl_vm *self, const sl_instance *inst, sl_mode mode, aa_context *ctx,
                     bool slopes)
{
    self->error[0] = '\0';
    self->executed = 0;
    self->prog = inst ? inst->program : NULL;
    if (!inst)
        return sl_vm_fail(self, SL_ERR_RUNTIME, "no shader instance to run");
    if (mode == SL_MODE_AFFINE && !ctx)
        return sl_vm_fail(self, SL_ERR_RUNTIME, "affine mode needs an aa_context");
    const sl_program *p = inst->program;
    if (p->nslots > SL_MAX_SLOTS || p->nstring_slots > SL_MAX_STRING_SLOTS)
        return sl_vm_fail(self, SL_ERR_RUNTIME, "program exceeds the VM's slot limits");
    self->inst = inst;
    self->ctx = ctx;
    self->mode = mode;
    self->strings_used = 0;
    self->nframes = 0;
    self->pool_top = 0;
    self->spool_top = 0;
    self->naccs = 0;
    self->acc_bottom = SL_VM_POOL_VALUES;
    self->sacc_bottom = SL_VM_POOL_VALUES;
    self->rng = self->seed;
    self->nillum = self->illum_next = 0;
    self->split.n = 0;
    self->split.full = false;
    ensure_clear(self, mode);
    load_strings(self, p);
    if (slopes || (p->takes_derivatives && (mode == SL_MODE_INTERVAL || mode == SL_MODE_AFFINE)))
        return run_with_derivatives(self, mode);
    switch (mode) {
    case SL_MODE_FLOAT: return sl_vm_exec_float(self);
    case SL_MODE_DUAL: return sl_vm_exec_dual(self);
    case SL_MODE_INTERVAL: return sl_vm_exec_interval(self);
    case SL_MODE_AFFINE:
        return tape_run(self) ? sl_vm_exec_affine_tape(self) : sl_vm_exec_affine(self);
    }
    return sl_vm_fail(self, SL_ERR_RUNTIME, "unknown mode %d", (int)mode);
}

void sl_vm_split_begin(sl_vm *self, int max_ops)
{
    assert(max_ops >= 0 && max_ops <= SL_VM_MAX_SPLITS);
    self->split.on = max_ops > 0;
    self->split.max = max_ops;
    self->split.n = self->split.fixed = 0;
}

/* the next case in depth-first order: the last split of the run that
 * took its lower value takes the upper one, the splits after it start
 * again from their lower values */
bool sl_vm_split_next(sl_vm *self)
{
    if (!self->split.on) return false;
    assert(self->split.n >= self->split.fixed && self->split.n <= self->split.max);
    int i = self->split.n - 1;
    while (i >= 0 && self->split.pick[i] == 1) i--;
    if (i < 0) return false;
    self->split.pick[i] = 1;
    self->split.fixed = i + 1;
    return true;
}

bool sl_vm_split_full(const sl_vm *self) { return self->split.full; }

void sl_vm_split_end(sl_vm *self)
{
    self->split.on = false;
    self->split.max = self->split.n = self->split.fixed = 0;
    self->split.full = false;
}

const char *sl_vm_error(const sl_vm *self) { return self->error; }
long sl_vm_instructions(const sl_vm *self) { return self->executed; }
