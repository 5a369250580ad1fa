/*
 * vm_dual.c: the VM in forward-mode automatic differentiation: every slot
 * carries (value, d/du, d/dv) and every operation applies the chain rule
 * (Heidrich & Seidel 1998 §4.1: "we store the triple (x, dx/du, dx/dv) for
 * each expression"). Du(x) and Dv(x) read the derivative parts, so
 * calculatenormal(P) = Du(P) x Dv(P) is exact for the shader as written,
 * not a divided difference. Discontinuous functions (floor, step, ...)
 * have derivative 0 away from their jumps. Results of Du/Dv/Deriv and
 * calculatenormal carry no second derivatives (those parts are 0).
 *
 * Vector noise has no analytic gradient in sl/noise.h; its derivatives
 * are central differences along dp/du and dp/dv (noise is C^2).
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <string.h>

#define VM_T sl_dual
#define VM_SUFFIX dual
#define VM_FILE(vm) ((vm)->d)
#define VM_VARIANT VM_VAR_DUAL

static inline sl_dual dd(double v, double du, double dv)
{
    sl_dual r = { v, du, dv };
    return r;
}
/* f(x) with f'(x) = k */
static inline sl_dual chain(double v, double k, sl_dual x) { return dd(v, k * x.du, k * x.dv); }

static inline void v_const(sl_vm *vm, sl_dual *z, double k) { (void)vm; *z = dd(k, 0, 0); }
static inline void v_mov(sl_vm *vm, sl_dual *z, const sl_dual *x) { (void)vm; *z = *x; }
static inline void v_swap(sl_vm *vm, sl_dual *a, sl_dual *b)
{
    (void)vm;
    sl_dual t = *a;
    *a = *b;
    *b = t;
}
static inline void v_unbounded(sl_vm *vm, sl_dual *z) { (void)vm; *z = dd(NAN, NAN, NAN); }
static inline bool v_is_const(const sl_dual *x, double *k) { *k = x->v; return true; }
static inline void v_range(const sl_dual *x, double *lo, double *hi) { *lo = *hi = x->v; }

static inline void v_add(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    *z = dd(x->v + y->v, x->du + y->du, x->dv + y->dv);
}
static inline void v_sub(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    *z = dd(x->v - y->v, x->du - y->du, x->dv - y->dv);
}
static inline void v_mul(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    *z = dd(x->v * y->v, x->du * y->v + x->v * y->du, x->dv * y->v + x->v * y->dv);
}
static inline void v_div(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    double q = x->v / y->v;
    *z = dd(q, (x->du - q * y->du) / y->v, (x->dv - q * y->dv) / y->v);
}
static inline void v_neg(sl_vm *vm, sl_dual *z, const sl_dual *x) { (void)vm; *z = dd(-x->v, -x->du, -x->dv); }

#define UNARY(name, value, deriv)                                                \
    static inline void name(sl_vm *vm, sl_dual *z, const sl_dual *x)            \
    {                                                                            \
        (void)vm;                                                                \
        double a = x->v, f = (value);                                            \
        (void)f;                                                                 \
        *z = chain(f, (deriv), *x);                                              \
    }
UNARY(v_sqrt, sqrt(a), 0.5 / f)
UNARY(v_invsqrt, 1.0 / sqrt(a), -0.5 * f / a)
UNARY(v_exp, exp(a), f)
UNARY(v_log, log(a), 1.0 / a)
UNARY(v_sin, sin(a), cos(a))
UNARY(v_cos, cos(a), -sin(a))
UNARY(v_tan, tan(a), 1.0 + f * f)
UNARY(v_asin, asin(a), 1.0 / sqrt(1.0 - a * a))
UNARY(v_acos, acos(a), -1.0 / sqrt(1.0 - a * a))
UNARY(v_atan, atan(a), 1.0 / (1.0 + a * a))
UNARY(v_abs, fabs(a), a < 0 ? -1.0 : 1.0)
UNARY(v_sign, a > 0 ? 1.0 : a < 0 ? -1.0 : 0.0, 0.0)
UNARY(v_floor, floor(a), 0.0)
UNARY(v_ceil, ceil(a), 0.0)
UNARY(v_round, round(a), 0.0)
#undef UNARY

static inline void v_pow(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    double a = x->v, b = y->v, f = pow(a, b);
    double kx = b == 0.0 ? 0.0 : b * pow(a, b - 1.0);
    double ky = (y->du != 0.0 || y->dv != 0.0) && a > 0 ? f * log(a) : 0.0;
    *z = dd(f, kx * x->du + ky * y->du, kx * x->dv + ky * y->dv);
}

static inline void v_atan2(sl_vm *vm, sl_dual *z, const sl_dual *y, const sl_dual *x)
{
    (void)vm;
    double r2 = x->v * x->v + y->v * y->v;
    double ky = r2 > 0 ? x->v / r2 : 0.0, kx = r2 > 0 ? -y->v / r2 : 0.0;
    *z = dd(atan2(y->v, x->v), ky * y->du + kx * x->du, ky * y->dv + kx * x->dv);
}

static inline void v_mod(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    double a = x->v, b = y->v;
    double r = fmod(a, b);
    if (r != 0 && ((r < 0) != (b < 0)))
        r += b;
    double k = floor(a / b);                 /* mod = x - k y, k locally constant */
    *z = dd(r, x->du - k * y->du, x->dv - k * y->dv);
}

static inline void v_min(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    *z = x->v < y->v ? *x : *y;
}
static inline void v_max(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    *z = x->v > y->v ? *x : *y;
}
static inline void v_step(sl_vm *vm, sl_dual *z, const sl_dual *edge, const sl_dual *x)
{
    (void)vm;
    *z = dd(x->v < edge->v ? 0.0 : 1.0, 0.0, 0.0);
}
static inline void v_clamp(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *lo, const sl_dual *hi)
{
    sl_dual t;
    v_max(vm, &t, x, lo);
    v_min(vm, z, &t, hi);
}
static inline void v_smoothstep(sl_vm *vm, sl_dual *z, const sl_dual *e0, const sl_dual *e1, const sl_dual *x)
{
    (void)vm;
    if (x->v < e0->v) {
        *z = dd(0, 0, 0);
        return;
    }
    if (x->v >= e1->v) {
        *z = dd(1, 0, 0);
        return;
    }
    double w = e1->v - e0->v, t = (x->v - e0->v) / w;
    double k = 6.0 * t * (1.0 - t);              /* d/dt of t^2 (3 - 2t) */
    /* dt = ((dx - de0) w - (x - e0)(de1 - de0)) / w^2 */
    double tu = ((x->du - e0->du) - t * (e1->du - e0->du)) / w;
    double tv = ((x->dv - e0->dv) - t * (e1->dv - e0->dv)) / w;
    *z = dd(t * t * (3.0 - 2.0 * t), k * tu, k * tv);
}
static inline void v_mix(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y, const sl_dual *a)
{
    (void)vm;
    double s = 1.0 - a->v, d = y->v - x->v;
    *z = dd(x->v * s + y->v * a->v, x->du * s + y->du * a->v + d * a->du,
            x->dv * s + y->dv * a->v + d * a->dv);
}

static inline int v_cmp(sl_vm *vm, int op, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    double a = x->v, b = y->v;
    switch (op) {
    case SL_OP_LT: return a < b;
    case SL_OP_LE: return a <= b;
    case SL_OP_GT: return a > b;
    case SL_OP_GE: return a >= b;
    case SL_OP_EQ: return a == b;
    default: return a != b;
    }
}
static inline void v_bool(sl_vm *vm, sl_dual *z, int t) { (void)vm; *z = dd(t ? 1.0 : 0.0, 0, 0); }
static inline int v_truth(const sl_dual *x) { return x->v != 0.0; }
static inline bool v_same(const sl_dual *x, const sl_dual *y)
{
    return x->v == y->v && x->du == y->du && x->dv == y->dv;
}
static inline void v_merge(sl_vm *vm, sl_dual *z, const sl_dual *x, const sl_dual *y)
{
    (void)vm;
    (void)y;
    *z = *x;          /* never called: dual conditions are always decided */
}

/* Values of the noise variant at p (dim values), into out[0..outs). */
static void noise_at(int v, int dim, const double *p, const int *period, double *out)
{
    int kind = SL_NOISE_KIND(v);
    if (v & SL_NOISE_VECTOR) {
        if (kind == SL_NOISE_CELL)
            sl_vcellnoise(dim, p, out);
        else
            sl_vpnoise(dim, p, period, out);
    } else {
        out[0] = kind == SL_NOISE_CELL ? sl_cellnoise(dim, p) : sl_pnoise(dim, p, period);
    }
}

/* Derivative along direction dir of the noise at p, by central difference. */
static void noise_directional(int v, int dim, const double *p, const double *dir,
                              const int *period, double *out, int outs)
{
    double len = 0;
    for (int k = 0; k < dim; k++)
        len += dir[k] * dir[k];
    if (len == 0) {
        for (int i = 0; i < outs; i++)
            out[i] = 0;
        return;
    }
    double h = 1e-5 / sqrt(len);
    double a[4], b[4], fa[3], fb[3];
    for (int k = 0; k < dim; k++) {
        a[k] = p[k] + h * dir[k];
        b[k] = p[k] - h * dir[k];
    }
    noise_at(v, dim, a, period, fa);
    noise_at(v, dim, b, period, fb);
    for (int i = 0; i < outs; i++)
        out[i] = (fa[i] - fb[i]) / (2 * h);
}

static inline sl_status v_noise(sl_vm *vm, sl_dual *S, const sl_insn *in, int pc)
{
    (void)vm;
    (void)pc;
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    int outs = (v & SL_NOISE_VECTOR) ? 3 : 1;
    double p[4], pu[4], pv[4];
    int period[4] = { 0, 0, 0, 0 };
    for (int k = 0; k < dim; k++) {
        p[k] = S[in->b + k].v;
        pu[k] = S[in->b + k].du;
        pv[k] = S[in->b + k].dv;
        if (kind == SL_NOISE_PERIODIC)
            period[k] = (int)S[in->d + k].v;
    }
    const int *per = kind == SL_NOISE_PERIODIC ? period : NULL;
    double f[3], fu[3] = { 0, 0, 0 }, fv[3] = { 0, 0, 0 };
    if (kind != SL_NOISE_CELL && outs == 1) {
        double grad[4];
        f[0] = sl_noise_grad(dim, p, per, grad);
        for (int k = 0; k < dim; k++) {
            fu[0] += grad[k] * pu[k];
            fv[0] += grad[k] * pv[k];
        }
    } else {
        noise_at(v, dim, p, per, f);
        if (kind != SL_NOISE_CELL) {
            noise_directional(v, dim, p, pu, per, fu, outs);
            noise_directional(v, dim, p, pv, per, fv, outs);
        }
    }
    for (int i = 0; i < outs; i++)
        S[in->a + i] = dd(f[i], fu[i], fv[i]);
    return SL_OK;
}

/* texture lookups: the filter of tex.h and its derivatives along s and t
 * by the chain rule, at a fixed footprint (docs/textures.md); the
 * gradient (bump) carries no second derivatives */
static inline sl_status v_texture(sl_vm *vm, sl_dual *S, const sl_insn *in, int pc)
{
    sl_status st = SL_OK;
    const tex_texture *t = sl_vm_texture(vm, vm->str[in->b], pc, &st);
    if (!t)
        return st;
    sl_dual a[6];
    memcpy(a, &S[in->c], sizeof a);
    tex_wrap sw = (tex_wrap)SL_TEXOP_SWRAP(in->d), tw = (tex_wrap)SL_TEXOP_TWRAP(in->d);
    int c = sl_tex_channel(a[4].v);
    double ds, dt;
    if (SL_TEXOP_KIND(in->d) == SL_TEXOP_GRAD) {
        tex_sample(t, c, a[0].v, a[1].v, a[2].v, a[3].v, sw, tw, a[5].v, &ds, &dt);
        S[in->a] = dd(ds, 0, 0);
        S[in->a + 1] = dd(dt, 0, 0);
        return SL_OK;
    }
    for (int i = 0; i < sl_texop_outs(in->d); i++) {
        int ch = c < 0 ? -1 : c + i;
        if (ch < 0 || ch >= tex_channels(t)) {
            S[in->a + i] = (in->d & SL_TEXOP_FILL) ? a[5] : dd(sl_tex_default_fill(ch), 0, 0);
            continue;
        }
        double v = tex_sample(t, ch, a[0].v, a[1].v, a[2].v, a[3].v, sw, tw, a[5].v, &ds, &dt);
        S[in->a + i] = dd(v, ds * a[0].du + dt * a[1].du, ds * a[0].dv + dt * a[1].dv);
    }
    return SL_OK;
}

static inline void v_random(sl_vm *vm, sl_dual *z) { *z = dd(sl_vm_random(vm), 0, 0); }
static inline void v_du(sl_vm *vm, sl_dual *z, const sl_dual *x) { (void)vm; *z = dd(x->du, 0, 0); }
static inline void v_dv(sl_vm *vm, sl_dual *z, const sl_dual *x) { (void)vm; *z = dd(x->dv, 0, 0); }

/* Deriv(a, b) = da/db along the surface: the least-squares quotient
 * (Du a Du b + Dv a Dv b) / (Du b^2 + Dv b^2); 0 where b does not vary. */
static inline void v_deriv(sl_vm *vm, sl_dual *z, const sl_dual *a, const sl_dual *b)
{
    (void)vm;
    double den = b->du * b->du + b->dv * b->dv;
    *z = dd(den > 0 ? (a->du * b->du + a->dv * b->dv) / den : 0.0, 0, 0);
}

static inline void v_calcnormal(sl_vm *vm, sl_dual *S, int z, int p)
{
    (void)vm;
    vec3 a = v3(S[p].du, S[p + 1].du, S[p + 2].du);
    vec3 b = v3(S[p].dv, S[p + 1].dv, S[p + 2].dv);
    vec3 n = v3_cross(a, b);
    S[z] = dd(n.x, 0, 0);
    S[z + 1] = dd(n.y, 0, 0);
    S[z + 2] = dd(n.z, 0, 0);
}

static inline void v_area(sl_vm *vm, sl_dual *S, int z, int p)
{
    (void)vm;
    vec3 a = v3(S[p].du, S[p + 1].du, S[p + 2].du);
    vec3 b = v3(S[p].dv, S[p + 1].dv, S[p + 2].dv);
    S[z] = dd(v3_length(v3_cross(a, b)), 0, 0);
}

static inline int v_light_samples(sl_vm *vm, sl_dual *S, sl_light_sample *out, bool *unbounded)
{
    int g = sl_global_slot(SL_G_P);
    double P[3] = { S[g].v, S[g + 1].v, S[g + 2].v };
    *unbounded = false;
    return sl_vm_light_samples(vm, P, out);
}

#include "vm_exec.inc"
