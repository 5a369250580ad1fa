/*
 * shade.c: surface shading, lights (built-in and light shaders),
 * shadows, and the rays shaders trace (trace(), shadow(); see shade.h).
 */
#include "trace/shade.h"
#include "trace/mesh.h"

#include "trace/displace.h"
#include "trace/primvar.h"
#include "util/err.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The light samples of one shading point, kept for the shader's next
 * ambient(), diffuse(), specular(), phong() or illuminance loop: each asks
 * for them (plastic three times), and each would trace the shadow rays
 * again. The samples depend on the point alone (P and N of the context,
 * the lights and their shaders, whose VM starts every run from the same
 * seed and has no messages of the surface's), so the copy is what a new
 * call would give (test_trace_light_memo: the same pixels with the memo
 * off, world option light_memo).
 * Up to this many samples; a call asking for more makes them anew. */
#define LIGHT_MEMO 16

typedef struct shade_ctx {
    const trace_renderer *r;
    trace_thread *th;
    const trace_object *obj;       /* the shaded object: its lights */
    vec3 P;              /* the shaded point */
    vec3 N;              /* unit normal used to offset shadow rays */
    double offset;       /* shadow ray offset (camera units) */
    double tol;          /* shadow ray leaf tolerance (camera units) */
    int depth;           /* trace() rays that led here (0: a primary hit) */
    int light;           /* the light shader being run (its index), or -1 */
    int nmemo;           /* light samples kept (memo), or -1: none yet */
    int memo_max;        /* the `max` they were made for */
    sl_light_sample memo[LIGHT_MEMO];
} shade_ctx;

static void shade_hit(const trace_renderer *r, trace_thread *th, const trace_ray *ray,
                      const trace_hit *hit, int depth, double rgb[3], double *alpha,
                      vec3 *P_out);
static double shadow_ray(void *user, const char *map, const double P[3], const double D[3],
                         double tmax);

static double smoothstep_d(double e0, double e1, double x)
{
    if (x <= e0) return 0;
    if (x >= e1) return 1;
    double t = (x - e0) / (e1 - e0);
    return t * t * (3 - 2 * t);
}

/* Is the segment from P along L (to parameter tmax) blocked? It leaves
 * from P moved off the surface on L's side. */
static bool occluded_from(shade_ctx *c, vec3 P, vec3 L, double tmax)
{
    trace_thread *th = c->th;
    vec3 side = v3_dot(c->N, L) >= 0 ? c->N : v3_neg(c->N);
    vec3 o = v3_add(P, v3_scale(side, c->offset));
    trace_ray ray;
    trace_ray_init(&ray, o, L, 0.0, tmax);
    trace_tolerance tol = {c->tol, 0.0};
    trace_hit hit = {.t = tmax, .obj = NULL};
    th->stats.shadow_rays++;
    return trace_bvh_intersect(c->r->bvh, th, &ray, &tol, true, &hit);
}

/* Is the segment from the shaded point along L (to parameter tmax) blocked? */
static bool occluded(shade_ctx *c, vec3 L, double tmax)
{
    return occluded_from(c, c->P, L, tmax);
}

/* The light samples of the shading point c (at most max): each light's L
 * and Cl, a shadowed light's dropped where its shadow ray is blocked */
static int make_light_samples(shade_ctx *c, sl_light_sample *out, int max)
{
    const trace_world *w = c->r->world;
    int n = 0;
    for (int i = 0; i < c->obj->nlights && n < max; i++) {
        const trace_light *l = &w->lights[c->obj->lights[i]];
        sl_light_sample *s = &out[n];
        double atten = 1.0, tmax = 1.0;
        vec3 L;
        s->ambient = false;
        switch (l->kind) {
        case TRACE_LIGHT_AMBIENT:
            s->ambient = true;
            s->L[0] = s->L[1] = s->L[2] = 0;
            for (int k = 0; k < 3; k++) s->Cl[k] = l->color[k];
            n++;
            continue;
        case TRACE_LIGHT_DISTANT:
            L = v3_neg(l->dir);
            tmax = INFINITY;
            break;
        case TRACE_LIGHT_POINT:
            L = v3_sub(l->from, c->P);
            atten = 1.0 / v3_dot(L, L);
            break;
        case TRACE_LIGHT_SHADER: {
            /* RI Spec 3.2 §9.3: the light shader at Ps (its own VM: this
             * callback runs inside the surface shader's run) */
            double Ps[3] = {c->P.x, c->P.y, c->P.z};
            sl_vm *lvm = c->th->light_vm;
            sl_vm_set_spaces(lvm, &l->shader_spaces);
            sl_tracer tracer = {.shadow = shadow_ray, .user = c};
            sl_vm_set_tracer(lvm, &tracer);
            c->light = c->obj->lights[i];
            sl_status st = sl_light_eval(lvm, l->shader, Ps, s);
            c->light = -1;
            if (st != SL_OK) {
                trace_thread_fail(c->th, sl_vm_error(lvm));
                continue;
            }
            s->directional = l->directional;
            if (s->ambient) { n++; continue; }
            L = v3(s->L[0], s->L[1], s->L[2]);
            if (!(s->Cl[0] != 0 || s->Cl[1] != 0 || s->Cl[2] != 0)) continue;
            if (l->shadows && occluded(c, L, l->directional ? INFINITY : 1.0 - 1e-9)) continue;
            n++;
            continue;
        }
        case TRACE_LIGHT_SPOT: {
            L = v3_sub(l->from, c->P);
            double d2 = v3_dot(L, L);
            double cosang = -v3_dot(L, l->dir) / sqrt(d2);
            if (cosang <= l->cos_outside) { atten = 0; break; }
            atten = pow(cosang, l->beamdistribution) / d2 *
                    smoothstep_d(l->cos_outside, l->cos_inside, cosang);
            break;
        }
        default:
            continue;
        }
        if (!(atten > 0) || !isfinite(atten)) continue;
        if (l->shadows && occluded(c, L, tmax * (1.0 - 1e-9))) continue;
        s->L[0] = L.x; s->L[1] = L.y; s->L[2] = L.z;
        s->directional = l->kind == TRACE_LIGHT_DISTANT;
        for (int k = 0; k < 3; k++) s->Cl[k] = l->color[k] * atten;
        n++;
    }
    return n;
}

/* The VM's light callback: make_light_samples once per shading point,
 * copies of them after (LIGHT_MEMO) */
static int light_samples(void *user, const double P[3], sl_light_sample *out, int max)
{
    (void)P;   /* the shaded point is c->P: a shader moving P does not move shadows */
    shade_ctx *c = user;
    if (c->nmemo >= 0 && c->memo_max == max) {
        memcpy(out, c->memo, (size_t)c->nmemo * sizeof *out);
        return c->nmemo;
    }
    int n = make_light_samples(c, out, max);
    if (n <= LIGHT_MEMO && c->r->world->options.light_memo) {
        memcpy(c->memo, out, (size_t)n * sizeof *out);
        c->nmemo = n;
        c->memo_max = max;
    }
    return n;
}

/* shadow(map, P) (RI Spec 3.2 §15.7): aafarm has no shadow maps yet (the
 * texture work, issue 16), so every map is missing and the answer is a
 * traced shadow ray from P towards the light: 1 blocked, 0 lit; one
 * warning per light (per render) says so. */
/* One more trace()/shadow() ray for this primary hit; false (the thread
 * failed, with a message) beyond TRACE_MAX_SHADER_RAYS. */
static bool count_shader_ray(shade_ctx *c, const char *what)
{
    trace_thread *th = c->th;
    if (th->failed) return false;
    if (++th->shader_rays <= TRACE_MAX_SHADER_RAYS) return true;
    char msg[ERR_LEN];
    snprintf(msg, sizeof msg, "surface shader '%s': more than %d rays traced by trace() and "
             "shadow() for one sample (the limit; at %s)",
             c->obj->surface ? sl_program_name(sl_instance_program(c->obj->surface)) : "",
             TRACE_MAX_SHADER_RAYS, what);
    trace_thread_fail(th, msg);
    return false;
}

static double shadow_ray(void *user, const char *map, const double P[3], const double D[3],
                         double tmax)
{
    shade_ctx *c = user;
    if (!count_shader_ray(c, "shadow()"))
        return 0;
    const trace_world *w = c->r->world;
    int slot = c->light >= 0 ? c->light : w->nlights;
    if (!atomic_exchange(&c->r->shadow_warned[slot], 1) && c->r->log) {
        char msg[ERR_LEN];
        if (c->light >= 0)
            snprintf(msg, sizeof msg, "light %d (shader '%s'): shadow map '%s' does "
                     "not exist; shadow() is answered by a traced shadow ray", c->light,
                     sl_program_name(sl_instance_program(w->lights[c->light].shader)), map);
        else
            snprintf(msg, sizeof msg, "surface shader '%s': shadow map '%s' does not "
                     "exist; shadow() is answered by a traced shadow ray",
                     c->obj->surface ? sl_program_name(sl_instance_program(c->obj->surface))
                                     : "", map);
        c->r->log(c->r->log_user, msg);
    }
    vec3 p = v3(P[0], P[1], P[2]), d = v3(D[0], D[1], D[2]);
    if (!isfinite(v3_dot(p, p)) || !isfinite(v3_dot(d, d)))
        return 0;
    return occluded_from(c, p, d, isinf(tmax) ? INFINITY : tmax * (1.0 - 1e-9)) ? 1.0 : 0.0;
}

/* trace(P, R) (RI Spec 3.2 §15.6): the colour the ray from P along R sees,
 * the hit shaded with its surface shader one level deeper (its own VM);
 * black where the ray leaves the scene or is deeper than the world's
 * max_ray_depth (Option "trace" "maxdepth", default 4). The ray leaves P moved off the surface like a
 * shadow ray, with the shadow rays' tolerance. */
static void trace_ray_cb(void *user, const double P[3], const double R[3], double Ci[3])
{
    shade_ctx *c = user;
    Ci[0] = Ci[1] = Ci[2] = 0;
    vec3 p = v3(P[0], P[1], P[2]), d = v3(R[0], R[1], R[2]);
    double d2 = v3_dot(d, d);
    int maxdepth = c->r->world->options.max_ray_depth;
    if (maxdepth > TRACE_RAY_DEPTH_LIMIT) maxdepth = TRACE_RAY_DEPTH_LIMIT;
    if (c->depth >= maxdepth || !(d2 > 0) || !isfinite(d2) ||
        !isfinite(v3_dot(p, p)) || !count_shader_ray(c, "trace()"))
        return;
    vec3 side = v3_dot(c->N, d) >= 0 ? c->N : v3_neg(c->N);
    trace_ray ray;
    trace_ray_init(&ray, v3_add(p, v3_scale(side, c->offset)), d, 0.0, INFINITY);
    trace_tolerance tol = {c->tol, 0.0};
    trace_hit hit = {.t = INFINITY, .obj = NULL};
    if (!trace_bvh_intersect(c->r->bvh, c->th, &ray, &tol, false, &hit))
        return;
    double alpha;
    vec3 at;
    shade_hit(c->r, c->th, &ray, &hit, c->depth + 1, Ci, &alpha, &at);
}

static inline void float_const_(double *z, double k) { *z = k; }
#define G_T double
#define G_SUFFIX float
#define G_SET sl_vm_set_float
#define G_CONST float_const_
#include "trace/globals.inc"

static void set3(sl_vm *vm, sl_global g, vec3 v)
{
    double a[3] = {v.x, v.y, v.z};
    sl_vm_set_float(vm, g, a);
}

static void default_surface(const trace_object *obj, vec3 I, vec3 N, double u, double v,
                            double rgb[3], double *alpha)
{
    /* RenderMan's defaultsurface: a facing ratio, Ka 0.2, Kd 0.8; Cs and
     * Os from the primitive variables where given */
    double Cs[3], Os[3];
    if (!trace_primvar_global(obj, SL_G_Cs, u, v, Cs))
        for (int k = 0; k < 3; k++) Cs[k] = obj->Cs[k];
    if (!trace_primvar_global(obj, SL_G_Os, u, v, Os))
        for (int k = 0; k < 3; k++) Os[k] = obj->Os[k];
    double f = fabs(v3_dot(v3_normalize(I), N));
    for (int k = 0; k < 3; k++) rgb[k] = Os[k] * Cs[k] * (0.2 + 0.8 * f);
    *alpha = (Os[0] + Os[1] + Os[2]) / 3.0;
}

static bool has_outputs(const sl_instance *inst)
{
    return sl_program_has_outputs(sl_instance_program(inst));
}

/* Message passing (RI Spec 3.2 §15.7): the displacement shader's output
 * parameters at this hit, for displacement("name", x) in the surface
 * shader. The hit point's evaluation (dual mode, as the intersector's
 * trace_surface_point_eval) runs again on the shading VM, where the
 * captured values must live; only when the displacement shader has
 * outputs. The object's attributes the surface can ask for with
 * attribute() are set here too. */
static void pass_messages(trace_thread *th, sl_vm *vm, const trace_object *obj, double u,
                          double v)
{
    sl_vm_clear_messages(vm, SL_MSG_DISPLACEMENT);
    double sides = obj->sides;
    sl_vm_set_message(vm, SL_MSG_ATTRIBUTE, "Sides", SL_TYPE_FLOAT, &sides, NULL);
    if (!obj->displacement || !has_outputs(obj->displacement)) return;
    trace_surface_point ignored;
    trace_surface_point_eval_on(th, vm, obj, u, v, &ignored);
    sl_vm_capture_outputs(vm, SL_MSG_DISPLACEMENT);
}

void trace_shade_hit(const trace_renderer *r, trace_thread *th,
                     const trace_ray *ray, const trace_hit *hit,
                     double rgb[3], double *alpha, vec3 *P_out)
{
    th->shader_rays = 0;
    shade_hit(r, th, ray, hit, 0, rgb, alpha, P_out);
}

/* A hit seen through `depth` trace() rays: its surface shader runs on the
 * VM of that depth (the shallower ones are busy in their trace() calls). */
static void shade_hit(const trace_renderer *r, trace_thread *th, const trace_ray *ray,
                      const trace_hit *hit, int depth, double rgb[3], double *alpha,
                      vec3 *P_out)
{
    /* a mesh piece's view: a copy of its own for this depth, which the
     * shadow and trace() rays below cannot overwrite (mesh.h) */
    const trace_object *obj = trace_view_hold(th, hit->obj, depth);
    trace_surface_point sp;
    if (hit->has_point) sp = hit->point;
    else trace_surface_point_eval(th, obj, hit->u, hit->v, &sp);
    if (hit->kind == TRACE_LEAF_WALL) {
        sp.P = trace_ray_at(ray, hit->t);
        sp.N = sp.Ng = hit->wall_normal;
    } else if (hit->kind == TRACE_LEAF_EXACT) {
        sp.P = trace_ray_at(ray, hit->t);
    }
    *P_out = sp.P;
    vec3 I = v3_sub(sp.P, ray->o);

    if (!obj->surface) {
        default_surface(obj, I, sp.N, sp.u, sp.v, rgb, alpha);
        return;
    }
    double pixel_tol = r->primary_tol.a + r->primary_tol.b * fabs(sp.P.z);
    shade_ctx c = {.r = r, .th = th, .obj = obj, .P = sp.P, .N = sp.N,
                   .offset = 2.0 * hit->leaf_size + 1e-9 * (1.0 + v3_length(sp.P)),
                   .tol = hit->leaf_size > pixel_tol ? hit->leaf_size : pixel_tol,
                   .depth = depth, .light = -1, .nmemo = -1};
    sl_vm *vm = trace_thread_shade_vm(th, depth);
    pass_messages(th, vm, obj, sp.u, sp.v);
    double P[3] = {sp.P.x, sp.P.y, sp.P.z}, N[3] = {sp.N.x, sp.N.y, sp.N.z};
    double Ng[3] = {sp.Ng.x, sp.Ng.y, sp.Ng.z};
    double dPdu[3] = {sp.dPdu.x, sp.dPdu.y, sp.dPdu.z};
    double dPdv[3] = {sp.dPdv.x, sp.dPdv.y, sp.dPdv.z};
    bind_globals_float(vm, obj, &obj->surface_spaces, P, N, Ng, dPdu, dPdv, &sp.u, &sp.v,
                       NULL, false);
    /* a surface shader's I is the incident ray (from the ray's origin: the
     * eye for perspective, the image plane for orthographic cameras) */
    set3(vm, SL_G_I, I);
    sl_vm_set_lights(vm, light_samples, &c);
    sl_tracer tracer = {.trace = trace_ray_cb, .shadow = shadow_ray, .user = &c};
    sl_vm_set_tracer(vm, &tracer);
    sl_vm_set_float(vm, SL_G_Cs, obj->Cs);
    sl_vm_set_float(vm, SL_G_Os, obj->Os);
    trace_primvars_bind(vm, obj, true);     /* st, Cs, Os, the shader's own names */
    th->stats.evals_float++;
    if (sl_vm_run(vm, obj->surface, SL_MODE_FLOAT, NULL) != SL_OK) {
        trace_thread_fail(th, sl_vm_error(vm));
        rgb[0] = rgb[1] = rgb[2] = 0;
        *alpha = 1;
        return;
    }
    double Ci[3], Oi[3];
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    sl_vm_get_float(vm, SL_G_Oi, Oi);
    for (int k = 0; k < 3; k++) rgb[k] = Ci[k];
    *alpha = (Oi[0] + Oi[1] + Oi[2]) / 3.0;
}
