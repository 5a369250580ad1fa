/*
 * vm_interval.c: the VM in rounding-safe interval arithmetic (common/aa
 * interval.h), the comparison peer of the affine mode (Heidrich & Seidel
 * 1998 §7.1). Every slot encloses all values the shader can compute over
 * the input box; comparisons are tri-state and undecided branches are run
 * both ways and merged (vm_exec.inc). Du/Dv/Deriv/calculatenormal/area are
 * unbounded (AA_UNBOUNDED): the box cache only needs P.
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <string.h>

#define VM_T ia_interval
#define VM_SUFFIX interval
#define VM_FILE(vm) ((vm)->i)

typedef ia_interval I;

static inline void v_const(sl_vm *vm, I *z, double k)
{
    (void)vm;
    *z = isfinite(k) ? ia_point(k) : ia_entire();
}
static inline void v_mov(sl_vm *vm, I *z, const I *x) { (void)vm; *z = *x; }
static inline void v_swap(sl_vm *vm, I *a, I *b)
{
    (void)vm;
    I t = *a;
    *a = *b;
    *b = t;
}
static inline void v_unbounded(sl_vm *vm, I *z) { (void)vm; *z = ia_entire(); }
static inline bool v_is_const(const I *x, double *k)
{
    *k = x->lo;
    return x->lo == x->hi && !(x->flags & AA_UNBOUNDED);
}
static inline void v_range(const I *x, double *lo, double *hi)
{
    *lo = x->lo;
    *hi = x->hi;
}

/* exact point arithmetic where the double result is exact (vm_internal.h) */
static inline bool exact(int op, I *z, const I *x, const I *y)
{
    double r;
    if (x->lo != x->hi || y->lo != y->hi || ((x->flags | y->flags) & AA_UNBOUNDED) ||
        !sl_exact_op(op, x->lo, y->lo, &r))
        return false;
    unsigned flags = x->flags | y->flags;
    *z = ia_point(r);
    z->flags = flags;
    return true;
}

#define BIN(name, f) \
    static inline void name(sl_vm *vm, I *z, const I *x, const I *y) { (void)vm; *z = f(*x, *y); }
#define UN(name, f) \
    static inline void name(sl_vm *vm, I *z, const I *x) { (void)vm; *z = f(*x); }
#define EXACT_BIN(name, op, f)                                               \
    static inline void name(sl_vm *vm, I *z, const I *x, const I *y)        \
    {                                                                        \
        (void)vm;                                                            \
        if (!exact(op, z, x, y))                                             \
            *z = f(*x, *y);                                                  \
    }
EXACT_BIN(v_add, SL_OP_ADD, ia_add)
EXACT_BIN(v_sub, SL_OP_SUB, ia_sub)
EXACT_BIN(v_div, SL_OP_DIV, ia_div)
BIN(v_pow, ia_pow)
BIN(v_atan2, ia_atan2)
BIN(v_mod, ia_mod)
BIN(v_min, ia_min)
BIN(v_max, ia_max)
BIN(v_step, ia_step)
UN(v_neg, ia_neg)
UN(v_sqrt, ia_sqrt)
UN(v_invsqrt, ia_invsqrt)
UN(v_exp, ia_exp)
UN(v_log, ia_log)
UN(v_sin, ia_sin)
UN(v_cos, ia_cos)
UN(v_tan, ia_tan)
UN(v_asin, ia_asin)
UN(v_acos, ia_acos)
UN(v_atan, ia_atan)
UN(v_abs, ia_abs)
UN(v_sign, ia_sign)
UN(v_floor, ia_floor)
UN(v_ceil, ia_ceil)
UN(v_round, ia_round)
#undef BIN
#undef UN
#undef EXACT_BIN

/* x * x is a square (never negative), as aa_mul does for its affine forms */
static inline void v_mul(sl_vm *vm, I *z, const I *x, const I *y)
{
    (void)vm;
    if (!exact(SL_OP_MUL, z, x, y))
        *z = x == y ? ia_sqr(*x) : ia_mul(*x, *y);
}

static inline void v_clamp(sl_vm *vm, I *z, const I *x, const I *lo, const I *hi)
{
    (void)vm;
    *z = ia_clamp(*x, *lo, *hi);
}
static inline void v_smoothstep(sl_vm *vm, I *z, const I *e0, const I *e1, const I *x)
{
    (void)vm;
    *z = ia_smoothstep(*e0, *e1, *x);
}
static inline void v_mix(sl_vm *vm, I *z, const I *x, const I *y, const I *a)
{
    (void)vm;
    *z = ia_mix(*x, *y, *a);
}

/* Tri-state comparison of two enclosures. Empty or NaN bounds: maybe. */
static inline int cmp_ranges(int op, double alo, double ahi, double blo, double bhi)
{
    switch (op) {
    case SL_OP_LT:
        return ahi < blo ? 1 : alo >= bhi ? 0 : 2;
    case SL_OP_LE:
        return ahi <= blo ? 1 : alo > bhi ? 0 : 2;
    case SL_OP_GT:
        return alo > bhi ? 1 : ahi <= blo ? 0 : 2;
    case SL_OP_GE:
        return alo >= bhi ? 1 : ahi < blo ? 0 : 2;
    case SL_OP_EQ:
        return (alo == ahi && blo == bhi && alo == blo) ? 1 : (ahi < blo || bhi < alo) ? 0 : 2;
    default:
        return (alo == ahi && blo == bhi && alo == blo) ? 0 : (ahi < blo || bhi < alo) ? 1 : 2;
    }
}

static inline int v_cmp(sl_vm *vm, int op, const I *x, const I *y)
{
    (void)vm;
    if (ia_is_empty(*x) || ia_is_empty(*y))
        return 2;
    return cmp_ranges(op, x->lo, x->hi, y->lo, y->hi);
}

static inline void v_bool(sl_vm *vm, I *z, int t)
{
    (void)vm;
    *z = t == 2 ? ia_make(0.0, 1.0) : ia_point(t ? 1.0 : 0.0);
}
static inline int v_truth(const I *x)
{
    return x->lo > 0.5 ? 1 : x->hi < 0.5 ? 0 : 2;
}
static inline bool v_same(const I *x, const I *y)
{
    return x->lo == y->lo && x->hi == y->hi && x->flags == y->flags;
}
static inline void v_merge(sl_vm *vm, I *z, const I *x, const I *y)
{
    (void)vm;
    *z = ia_merge(*x, *y);
}

static inline sl_status v_noise(sl_vm *vm, I *S, const sl_insn *in, int pc)
{
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    I p[4];
    memcpy(p, &S[in->b], (size_t)dim * sizeof *p);
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
    I out[3];
    if (v & SL_NOISE_VECTOR) {
        if (kind == SL_NOISE_CELL)
            sl_vcellnoise_ia(dim, p, out);
        else
            sl_vpnoise_ia(dim, p, kind == SL_NOISE_PERIODIC ? period : NULL, out);
        memcpy(&S[in->a], out, sizeof out);
    } else {
        S[in->a] = kind == SL_NOISE_CELL ? sl_cellnoise_ia(dim, p)
                                         : sl_pnoise_ia(dim, p, kind == SL_NOISE_PERIODIC ? period : NULL);
    }
    return SL_OK;
}

static inline void v_random(sl_vm *vm, I *z)
{
    (void)vm;
    *z = ia_make(0.0, 1.0);
    z->flags |= AA_DISCONTINUOUS;
}

static inline void v_unknown(I *z)
{
    *z = ia_entire();
}
static inline void v_du(sl_vm *vm, I *z, const I *x) { (void)vm; (void)x; v_unknown(z); }
static inline void v_dv(sl_vm *vm, I *z, const I *x) { (void)vm; (void)x; v_unknown(z); }
static inline void v_deriv(sl_vm *vm, I *z, const I *x, const I *y)
{
    (void)vm; (void)x; (void)y;
    v_unknown(z);
}
static inline void v_calcnormal(sl_vm *vm, I *S, int z, int p)
{
    (void)vm; (void)p;
    for (int i = 0; i < 3; i++)
        v_unknown(&S[z + i]);
}
static inline void v_area(sl_vm *vm, I *S, int z, int p)
{
    (void)vm; (void)p;
    v_unknown(&S[z]);
}

static inline int v_light_samples(sl_vm *vm, I *S, sl_light_sample *out, bool *unbounded)
{
    (void)S;
    *unbounded = vm->light_fn != NULL;
    for (int k = 0; k < vm->nfixed_lights; k++)
        out[k] = vm->fixed_lights[k];
    return vm->nfixed_lights;
}

#include "vm_exec.inc"
