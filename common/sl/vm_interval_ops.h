/*
 * vm_interval_ops.h: the scalar operations of the VM in interval arithmetic,
 * shared by two instantiations of the dispatch loop: vm_interval.c (names
 * v_*, the plain mode) and vm_interval_deriv.c (names b_*, the values of the
 * mode that also carries derivative bounds, vm_deriv.inc). Each operation
 * spells both its names, VM_OP(v_add, b_add), so that grep finds either;
 * the including file defines VM_OP(plain, deriv) to pick one.
 */
#ifndef VM_OP
#error "define VM_OP(plain, deriv) before including this file"
#endif

typedef ia_interval I;

static inline void VM_OP(v_const, b_const)(sl_vm *vm, I *z, double k)
{
    (void)vm;
    *z = isfinite(k) ? ia_point(k) : ia_entire();
}
static inline void VM_OP(v_mov, b_mov)(sl_vm *vm, I *z, const I *x) { (void)vm; *z = *x; }
static inline void VM_OP(v_swap, b_swap)(sl_vm *vm, I *a, I *b)
{
    (void)vm;
    I t = *a;
    *a = *b;
    *b = t;
}
static inline void VM_OP(v_unbounded, b_unbounded)(sl_vm *vm, I *z) { (void)vm; *z = ia_entire(); }
static inline bool VM_OP(v_is_const, b_is_const)(const I *x, double *k)
{
    *k = x->lo;
    return x->lo == x->hi && !(x->flags & AA_UNBOUNDED);
}
static inline void VM_OP(v_range, b_range)(const I *x, double *lo, double *hi)
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
EXACT_BIN(VM_OP(v_add, b_add), SL_OP_ADD, ia_add)
EXACT_BIN(VM_OP(v_sub, b_sub), SL_OP_SUB, ia_sub)
EXACT_BIN(VM_OP(v_div, b_div), SL_OP_DIV, ia_div)
BIN(VM_OP(v_pow, b_pow), ia_pow)
BIN(VM_OP(v_atan2, b_atan2), ia_atan2)
EXACT_BIN(VM_OP(v_mod, b_mod), SL_OP_MOD, ia_mod)
BIN(VM_OP(v_min, b_min), ia_min)
BIN(VM_OP(v_max, b_max), ia_max)
BIN(VM_OP(v_step, b_step), ia_step)
UN(VM_OP(v_neg, b_neg), ia_neg)
UN(VM_OP(v_sqrt, b_sqrt), ia_sqrt)
UN(VM_OP(v_invsqrt, b_invsqrt), ia_invsqrt)
UN(VM_OP(v_exp, b_exp), ia_exp)
UN(VM_OP(v_log, b_log), ia_log)
UN(VM_OP(v_sin, b_sin), ia_sin)
UN(VM_OP(v_cos, b_cos), ia_cos)
UN(VM_OP(v_tan, b_tan), ia_tan)
UN(VM_OP(v_asin, b_asin), ia_asin)
UN(VM_OP(v_acos, b_acos), ia_acos)
UN(VM_OP(v_atan, b_atan), ia_atan)
UN(VM_OP(v_abs, b_abs), ia_abs)
UN(VM_OP(v_sign, b_sign), ia_sign)
UN(VM_OP(v_floor, b_floor), ia_floor)
UN(VM_OP(v_ceil, b_ceil), ia_ceil)
UN(VM_OP(v_round, b_round), ia_round)
#undef BIN
#undef UN
#undef EXACT_BIN

/* x * x is a square (never negative), as aa_mul does for its affine forms */
static inline void VM_OP(v_mul, b_mul)(sl_vm *vm, I *z, const I *x, const I *y)
{
    (void)vm;
    if (!exact(SL_OP_MUL, z, x, y))
        *z = x == y ? ia_sqr(*x) : ia_mul(*x, *y);
}

static inline void VM_OP(v_clamp, b_clamp)(sl_vm *vm, I *z, const I *x, const I *lo, const I *hi)
{
    (void)vm;
    unsigned kink = x->flags & AA_KINK;
    *z = ia_clamp(*x, *lo, *hi);
    if (sl_unit_clamp(lo->lo, hi->lo) && lo->lo == lo->hi && hi->lo == hi->hi)
        z->flags = (z->flags & ~(unsigned)AA_KINK) | kink;
}
static inline void VM_OP(v_smoothstep, b_smoothstep)(sl_vm *vm, I *z, const I *e0, const I *e1, const I *x)
{
    (void)vm;
    *z = ia_smoothstep(*e0, *e1, *x);
}
static inline void VM_OP(v_mix, b_mix)(sl_vm *vm, I *z, const I *x, const I *y, const I *a)
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

static inline int VM_OP(v_cmp, b_cmp)(sl_vm *vm, int op, const I *x, const I *y)
{
    (void)vm;
    if (ia_is_empty(*x) || ia_is_empty(*y))
        return 2;
    return cmp_ranges(op, x->lo, x->hi, y->lo, y->hi);
}

static inline void VM_OP(v_bool, b_bool)(sl_vm *vm, I *z, int t)
{
    (void)vm;
    *z = t == 2 ? ia_make(0.0, 1.0) : ia_point(t ? 1.0 : 0.0);
}
static inline int VM_OP(v_truth, b_truth)(const I *x)
{
    return x->lo > 0.5 ? 1 : x->hi < 0.5 ? 0 : 2;
}
static inline bool VM_OP(v_same, b_same)(const I *x, const I *y)
{
    return x->lo == y->lo && x->hi == y->hi && x->flags == y->flags;
}
static inline void VM_OP(v_merge, b_merge)(sl_vm *vm, I *z, const I *x, const I *y)
{
    (void)vm;
    *z = ia_merge(*x, *y);
}

static inline sl_status VM_OP(v_noise, b_noise)(sl_vm *vm, I *S, const sl_insn *in, int pc)
{
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    I p[4];
    memcpy(p, &S[in->b], (size_t)dim * sizeof *p);
    int period[4] = { 0, 0, 0, 0 };
    if (kind == SL_NOISE_PERIODIC) {
        for (int k = 0; k < dim; k++) {
            double q;
            if (!VM_OP(v_is_const, b_is_const)(&S[in->d + k], &q)) {
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

/* texture lookups: the bound of the filter over the ranges of s, t and the
 * footprint (tex_bound: the min-max pyramid); the gradient (bump) within
 * the derivative bounds (tex_lipschitz) */
static inline sl_status VM_OP(v_texture, b_texture)(sl_vm *vm, I *S, const sl_insn *in, int pc)
{
    sl_status st = SL_OK;
    const tex_texture *t = sl_vm_texture(vm, vm->str[in->b], pc, &st);
    if (!t)
        return st;
    I a[6];
    memcpy(a, &S[in->c], sizeof a);
    double q;
    if (!VM_OP(v_is_const, b_is_const)(&a[4], &q))
        return sl_vm_texture_channel_error(vm, pc);
    tex_wrap sw = (tex_wrap)SL_TEXOP_SWRAP(in->d), tw = (tex_wrap)SL_TEXOP_TWRAP(in->d);
    int c = sl_tex_channel(q);
    if (SL_TEXOP_KIND(in->d) == SL_TEXOP_GRAD) {
        double ls, lt;
        tex_lipschitz(t, c, &ls, &lt);
        S[in->a] = ia_make(-ls, ls);
        S[in->a + 1] = ia_make(-lt, lt);
        return SL_OK;
    }
    tex_range r = { { a[0].lo, a[0].hi }, { a[1].lo, a[1].hi }, { a[2].lo, a[2].hi },
                    { a[3].lo, a[3].hi } };
    for (int i = 0; i < sl_texop_outs(in->d); i++) {
        int ch = c < 0 ? -1 : c + i;
        if (ch < 0 || ch >= tex_channels(t)) {
            if (in->d & SL_TEXOP_FILL)
                S[in->a + i] = a[5];
            else
                S[in->a + i] = ia_point(sl_tex_default_fill(ch));
            continue;
        }
        double lo, hi;
        tex_bound(t, ch, &r, sw, tw, 0.0, &lo, &hi);
        S[in->a + i] = ia_make(lo, hi);
    }
    return SL_OK;
}

static inline void VM_OP(v_random, b_random)(sl_vm *vm, I *z)
{
    (void)vm;
    *z = ia_make(0.0, 1.0);
    z->flags |= AA_DISCONTINUOUS;
}

static inline void VM_OP(v_unknown, b_unknown)(I *z)
{
    *z = ia_entire();
}
#define VM_OPS_T I
#include "vm_stub_ops.inc"
#undef VM_OPS_T

