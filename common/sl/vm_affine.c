/*
 * vm_affine.c: the VM in rounding-safe affine arithmetic (common/aa
 * affine.h) over the caller's aa_context: the range analysis of Heidrich
 * & Seidel 1998 §4. Slots are aa_forms written in place; copies move only
 * the coefficients in use. A comparison looks at the affine form of the
 * difference of its operands, so correlated operands (u against u + 0.1)
 * decide where intervals could not; undecided ones run both branches and
 * merge with aa_merge (§4.1, §5). Du/Dv/Deriv/calculatenormal/area are
 * unbounded (AA_UNBOUNDED): the box cache only needs P.
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define VM_T aa_form
#define VM_SUFFIX affine
#define VM_FILE(vm) ((vm)->a)

typedef aa_form A;

static inline void v_const(sl_vm *vm, A *z, double k) { (void)vm; aa_const(z, k); }
static inline void v_mov(sl_vm *vm, A *z, const A *x)
{
    (void)vm;
    if (z != x)
        memcpy(z, x, offsetof(aa_form, c) + (size_t)x->n * sizeof x->c[0]);
}
static inline void v_swap(sl_vm *vm, A *a, A *b)
{
    A t;
    v_mov(vm, &t, a);
    v_mov(vm, a, b);
    v_mov(vm, b, &t);
}
static inline void v_unbounded(sl_vm *vm, A *z) { (void)vm; aa_unbounded(z, 0); }
static inline bool v_is_const(const A *x, double *k)
{
    *k = x->x0;
    return aa_is_point(x);
}
static inline void v_range(const A *x, double *lo, double *hi)
{
    ia_interval r = aa_range(x);
    *lo = r.lo;
    *hi = r.hi;
}

/* exact point arithmetic where the double result is exact (vm_internal.h) */
static inline bool exact(int op, A *z, const A *x, const A *y)
{
    double r;
    if (x->err != 0.0 || y->err != 0.0 || !aa_is_point(x) || !aa_is_point(y) ||
        !sl_exact_op(op, x->x0, y->x0, &r))
        return false;
    unsigned short flags = (unsigned short)(x->flags | y->flags);
    aa_const(z, r);
    z->flags = flags;
    return true;
}

#define BIN(name, f) \
    static inline void name(sl_vm *vm, A *z, const A *x, const A *y) { f(vm->ctx, z, x, y); }
#define UN(name, f) \
    static inline void name(sl_vm *vm, A *z, const A *x) { f(vm->ctx, z, x); }
#define EXACT_BIN(name, op, f)                                               \
    static inline void name(sl_vm *vm, A *z, const A *x, const A *y)        \
    {                                                                        \
        if (!exact(op, z, x, y))                                             \
            f(vm->ctx, z, x, y);                                             \
    }
EXACT_BIN(v_add, SL_OP_ADD, aa_add)
EXACT_BIN(v_sub, SL_OP_SUB, aa_sub)
EXACT_BIN(v_mul, SL_OP_MUL, aa_mul)
EXACT_BIN(v_div, SL_OP_DIV, aa_div)
BIN(v_pow, aa_pow)
BIN(v_atan2, aa_atan2)
BIN(v_mod, aa_mod)
BIN(v_min, aa_min)
BIN(v_max, aa_max)
BIN(v_step, aa_step)
UN(v_neg, aa_neg)
UN(v_sqrt, aa_sqrt)
UN(v_invsqrt, aa_invsqrt)
UN(v_exp, aa_exp)
UN(v_log, aa_log)
UN(v_sin, aa_sin)
UN(v_cos, aa_cos)
UN(v_tan, aa_tan)
UN(v_asin, aa_asin)
UN(v_acos, aa_acos)
UN(v_atan, aa_atan)
UN(v_abs, aa_abs)
UN(v_sign, aa_sign)
UN(v_floor, aa_floor)
UN(v_ceil, aa_ceil)
UN(v_round, aa_round)
#undef BIN
#undef UN
#undef EXACT_BIN

static inline void v_clamp(sl_vm *vm, A *z, const A *x, const A *lo, const A *hi)
{
    aa_clamp(vm->ctx, z, x, lo, hi);
}
static inline void v_smoothstep(sl_vm *vm, A *z, const A *e0, const A *e1, const A *x)
{
    aa_smoothstep(vm->ctx, z, e0, e1, x);
}
static inline void v_mix(sl_vm *vm, A *z, const A *x, const A *y, const A *a)
{
    aa_mix(vm->ctx, z, x, y, a);
}

/* Tri-state comparison through the range of x - y (keeps correlations). */
static inline int v_cmp(sl_vm *vm, int op, const A *x, const A *y)
{
    A d;
    aa_sub(vm->ctx, &d, x, y);
    ia_interval r = aa_range(&d);
    if ((d.flags & AA_UNBOUNDED) || !(r.lo <= r.hi))
        return 2;
    switch (op) {
    case SL_OP_LT: return r.hi < 0 ? 1 : r.lo >= 0 ? 0 : 2;
    case SL_OP_LE: return r.hi <= 0 ? 1 : r.lo > 0 ? 0 : 2;
    case SL_OP_GT: return r.lo > 0 ? 1 : r.hi <= 0 ? 0 : 2;
    case SL_OP_GE: return r.lo >= 0 ? 1 : r.hi < 0 ? 0 : 2;
    case SL_OP_EQ: return (r.lo == 0 && r.hi == 0) ? 1 : (r.lo > 0 || r.hi < 0) ? 0 : 2;
    default: return (r.lo == 0 && r.hi == 0) ? 0 : (r.lo > 0 || r.hi < 0) ? 1 : 2;
    }
}

/* 0, 1, or the form 0.5 +- 0.5 (no noise symbol: a private error) */
static inline void v_bool(sl_vm *vm, A *z, int t)
{
    (void)vm;
    aa_const(z, t == 1 ? 1.0 : 0.0);
    if (t == 2) {
        z->x0 = 0.5;
        z->err = 0.5;
        z->lo = 0.0;
        z->hi = 1.0;
    }
}
static inline int v_truth(const A *x)
{
    ia_interval r = aa_range(x);
    return r.lo > 0.5 ? 1 : r.hi < 0.5 ? 0 : 2;
}
static inline bool v_same(const A *x, const A *y)
{
    if (x->x0 != y->x0 || x->err != y->err || x->n != y->n || x->flags != y->flags ||
        x->lo != y->lo || x->hi != y->hi)
        return false;
    return memcmp(x->c, y->c, (size_t)x->n * sizeof x->c[0]) == 0;
}
static inline void v_merge(sl_vm *vm, A *z, const A *x, const A *y)
{
    aa_merge(vm->ctx, z, x, y);
}

static inline sl_status v_noise(sl_vm *vm, A *S, const sl_insn *in, int pc)
{
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    const A *p = &S[in->b];
    int period[4] = { 0, 0, 0, 0 };
    if (kind == SL_NOISE_PERIODIC) {
        for (int k = 0; k < dim; k++) {
            double q;
            if (!v_is_const(&S[in->d + k], &q)) {
                char where[256];
                sl_program_pos_string(vm->prog, pc, where, sizeof where);
                return sl_vm_fail(vm, SL_ERR_RUNTIME, "the period of pnoise must not vary "
                                  "over the surface (at %s)", where);
            }
            period[k] = (int)q;
        }
    }
    A out[3];                        /* the noise functions may not alias p */
    int outs = (v & SL_NOISE_VECTOR) ? 3 : 1;
    const int *per = kind == SL_NOISE_PERIODIC ? period : NULL;
    if (outs == 3) {
        if (kind == SL_NOISE_CELL)
            sl_vcellnoise_aa(vm->ctx, out, dim, p);
        else
            sl_vpnoise_aa(vm->ctx, out, dim, p, per);
    } else if (kind == SL_NOISE_CELL) {
        sl_cellnoise_aa(vm->ctx, out, dim, p);
    } else {
        sl_pnoise_aa(vm->ctx, out, dim, p, per);
    }
    for (int i = 0; i < outs; i++)
        v_mov(vm, &S[in->a + i], &out[i]);
    return SL_OK;
}

static inline void v_random(sl_vm *vm, A *z)
{
    v_bool(vm, z, 2);               /* [0, 1] on a private error term */
    z->flags |= AA_DISCONTINUOUS;
}

static inline void v_unknown(A *z) { aa_unbounded(z, 0); }
static inline void v_du(sl_vm *vm, A *z, const A *x) { (void)vm; (void)x; v_unknown(z); }
static inline void v_dv(sl_vm *vm, A *z, const A *x) { (void)vm; (void)x; v_unknown(z); }
static inline void v_deriv(sl_vm *vm, A *z, const A *x, const A *y)
{
    (void)vm; (void)x; (void)y;
    v_unknown(z);
}
static inline void v_calcnormal(sl_vm *vm, A *S, int z, int p)
{
    (void)vm; (void)p;
    for (int i = 0; i < 3; i++)
        v_unknown(&S[z + i]);
}
static inline void v_area(sl_vm *vm, A *S, int z, int p)
{
    (void)vm; (void)p;
    v_unknown(&S[z]);
}

static inline int v_light_samples(sl_vm *vm, A *S, sl_light_sample *out, bool *unbounded)
{
    (void)S;
    *unbounded = vm->light_fn != NULL;
    for (int k = 0; k < vm->nfixed_lights; k++)
        out[k] = vm->fixed_lights[k];
    return vm->nfixed_lights;
}

#include "vm_exec.inc"
