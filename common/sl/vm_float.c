/*
 * vm_float.c: the VM in plain double arithmetic, the ordinary evaluation
 * of a shader at one point (surface shading, and the float reference the
 * bound tests compare against). Derivatives are 0 in this mode and
 * calculatenormal returns the current N (shader.h).
 *
 * The functions follow the definitions the interval and affine versions
 * enclose (common/aa): mod(x, y) = x - y floor(x/y), round halves away
 * from zero, step(edge, x) = x < edge ? 0 : 1, smoothstep 0 below e0, 1
 * from e1 on.
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <string.h>

#define VM_T double
#define VM_SUFFIX float
#define VM_FILE(vm) ((vm)->f)
#define VM_VARIANT VM_VAR_FLOAT

static inline void v_const(sl_vm *vm, double *z, double k) { (void)vm; *z = k; }
static inline void v_mov(sl_vm *vm, double *z, const double *x) { (void)vm; *z = *x; }
static inline void v_swap(sl_vm *vm, double *a, double *b)
{
    (void)vm;
    double t = *a;
    *a = *b;
    *b = t;
}
static inline void v_unbounded(sl_vm *vm, double *z) { (void)vm; *z = NAN; }
static inline bool v_is_const(const double *x, double *k) { *k = *x; return true; }
static inline void v_range(const double *x, double *lo, double *hi) { *lo = *hi = *x; }

static inline void v_add(sl_vm *vm, double *z, const double *x, const double *y) { (void)vm; *z = *x + *y; }
static inline void v_sub(sl_vm *vm, double *z, const double *x, const double *y) { (void)vm; *z = *x - *y; }
static inline void v_mul(sl_vm *vm, double *z, const double *x, const double *y) { (void)vm; *z = *x * *y; }
static inline void v_div(sl_vm *vm, double *z, const double *x, const double *y) { (void)vm; *z = *x / *y; }
static inline void v_neg(sl_vm *vm, double *z, const double *x) { (void)vm; *z = -*x; }

#define UNARY(name, expr) \
    static inline void name(sl_vm *vm, double *z, const double *x) { (void)vm; double a = *x; *z = (expr); }
UNARY(v_sqrt, sqrt(a))
UNARY(v_invsqrt, 1.0 / sqrt(a))
UNARY(v_exp, exp(a))
UNARY(v_log, log(a))
UNARY(v_sin, sin(a))
UNARY(v_cos, cos(a))
UNARY(v_tan, tan(a))
UNARY(v_asin, asin(a))
UNARY(v_acos, acos(a))
UNARY(v_atan, atan(a))
UNARY(v_abs, fabs(a))
UNARY(v_sign, a > 0 ? 1.0 : a < 0 ? -1.0 : 0.0)
UNARY(v_floor, floor(a))
UNARY(v_ceil, ceil(a))
UNARY(v_round, round(a))
#undef UNARY

static inline double fmod_floor(double a, double b)
{
    double r = fmod(a, b);
    if (r != 0 && ((r < 0) != (b < 0)))
        r += b;
    return r;
}

static inline double smoothstep(double e0, double e1, double x)
{
    if (x < e0)
        return 0.0;
    if (x >= e1)
        return 1.0;
    double t = (x - e0) / (e1 - e0);
    return t * t * (3.0 - 2.0 * t);
}

#define BINARY(name, expr) \
    static inline void name(sl_vm *vm, double *z, const double *x, const double *y) \
    { (void)vm; double a = *x, b = *y; *z = (expr); }
BINARY(v_pow, pow(a, b))
BINARY(v_atan2, atan2(a, b))
BINARY(v_mod, fmod_floor(a, b))
BINARY(v_min, a < b ? a : b)
BINARY(v_max, a > b ? a : b)
BINARY(v_step, b < a ? 0.0 : 1.0)
#undef BINARY

static inline void v_clamp(sl_vm *vm, double *z, const double *x, const double *lo, const double *hi)
{
    (void)vm;
    double a = *x;
    a = a < *lo ? *lo : a;
    *z = a > *hi ? *hi : a;
}
static inline void v_smoothstep(sl_vm *vm, double *z, const double *e0, const double *e1, const double *x)
{
    (void)vm;
    *z = smoothstep(*e0, *e1, *x);
}
static inline void v_mix(sl_vm *vm, double *z, const double *x, const double *y, const double *a)
{
    (void)vm;
    *z = *x * (1.0 - *a) + *y * *a;
}

static inline int v_cmp(sl_vm *vm, int op, const double *x, const double *y)
{
    (void)vm;
    double a = *x, b = *y;
    switch (op) {
    case SL_OP_LT: return a < b;
    case SL_OP_LE: return a <= b;
    case SL_OP_GT: return a > b;
    case SL_OP_GE: return a >= b;
    case SL_OP_EQ: return a == b;
    default: return a != b;
    }
}
static inline void v_bool(sl_vm *vm, double *z, int t) { (void)vm; *z = t ? 1.0 : 0.0; }
static inline int v_truth(const double *x) { return *x != 0.0; }
static inline bool v_same(const double *x, const double *y) { return *x == *y; }
static inline void v_merge(sl_vm *vm, double *z, const double *x, const double *y)
{
    (void)vm;
    (void)y;
    *z = *x;          /* never called: float conditions are always decided */
}

static inline sl_status v_noise(sl_vm *vm, double *S, const sl_insn *in, int pc)
{
    (void)vm;
    (void)pc;
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    const double *p = &S[in->b];
    int period[4] = { 0, 0, 0, 0 };
    if (kind == SL_NOISE_PERIODIC)
        for (int k = 0; k < dim; k++)
            period[k] = (int)S[in->d + k];
    double out[3];
    if (v & SL_NOISE_VECTOR) {
        if (kind == SL_NOISE_CELL)
            sl_vcellnoise(dim, p, out);
        else
            sl_vpnoise(dim, p, kind == SL_NOISE_PERIODIC ? period : NULL, out);
        memcpy(&S[in->a], out, sizeof out);
    } else {
        S[in->a] = kind == SL_NOISE_CELL ? sl_cellnoise(dim, p)
                                         : sl_pnoise(dim, p, kind == SL_NOISE_PERIODIC ? period : NULL);
    }
    return SL_OK;
}

/* texture lookups (bytecode.h TEXTURE): the filter of tex.h at a point */
static inline sl_status v_texture(sl_vm *vm, double *S, const sl_insn *in, int pc)
{
    sl_status st = SL_OK;
    const tex_texture *t = sl_vm_texture(vm, vm->str[in->b], pc, &st);
    if (!t)
        return st;
    double a[6];
    memcpy(a, &S[in->c], sizeof a);
    tex_wrap sw = (tex_wrap)SL_TEXOP_SWRAP(in->d), tw = (tex_wrap)SL_TEXOP_TWRAP(in->d);
    int c = sl_tex_channel(a[4]);
    if (SL_TEXOP_KIND(in->d) == SL_TEXOP_GRAD) {
        tex_sample(t, c, a[0], a[1], a[2], a[3], sw, tw, a[5], &S[in->a], &S[in->a + 1]);
        return SL_OK;
    }
    for (int i = 0; i < sl_texop_outs(in->d); i++) {
        int ch = c < 0 ? -1 : c + i;
        S[in->a + i] = tex_sample(t, ch, a[0], a[1], a[2], a[3], sw, tw,
                                  sl_tex_fill(in->d, ch, a[5]), NULL, NULL);
    }
    return SL_OK;
}

static inline void v_random(sl_vm *vm, double *z) { *z = sl_vm_random(vm); }
static inline void v_du(sl_vm *vm, double *z, const double *x) { (void)vm; (void)x; *z = 0.0; }
static inline void v_dv(sl_vm *vm, double *z, const double *x) { (void)vm; (void)x; *z = 0.0; }
static inline void v_deriv(sl_vm *vm, double *z, const double *x, const double *y)
{
    (void)vm; (void)x; (void)y;
    *z = 0.0;
}
static inline void v_calcnormal(sl_vm *vm, double *S, int z, int p)
{
    (void)vm;
    (void)p;
    int n = sl_global_slot(SL_G_N);
    double N[3] = { S[n], S[n + 1], S[n + 2] };
    memcpy(&S[z], N, sizeof N);
}
static inline void v_area(sl_vm *vm, double *S, int z, int p)
{
    (void)vm;
    (void)p;
    S[z] = 0.0;
}

static inline int v_light_samples(sl_vm *vm, double *S, sl_light_sample *out, bool *unbounded)
{
    *unbounded = false;
    return sl_vm_light_samples(vm, &S[sl_global_slot(SL_G_P)], out);
}

#include "vm_exec.inc"
