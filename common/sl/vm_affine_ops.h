/*
 * vm_affine_ops.h: the scalar operations of the VM in affine arithmetic,
 * shared by two instantiations of the dispatch loop: vm_affine.c (names
 * v_*, the plain mode) and vm_affine_deriv.c (names b_*, the values of the
 * mode that also carries derivative bounds, vm_deriv.inc). Each operation
 * spells both its names, VM_OP(v_add, b_add), so that grep finds either;
 * the including file defines VM_OP(plain, deriv) to pick one.
 */
#ifndef VM_OP
#error "define VM_OP(plain, deriv) before including this file"
#endif

typedef aa_form A;

static inline void VM_OP(v_const, b_const)(sl_vm *vm, A *z, double k) { (void)vm; aa_const(z, k); }
static inline void VM_OP(v_mov, b_mov)(sl_vm *vm, A *z, const A *x)
{
    (void)vm;
    assert(x->n <= AA_MAX_SYMBOLS);      /* a form's symbol count fits its array */
    /* whole, as a struct (the coefficients past n are stale by design): a
     * fixed size compiles to a few vector moves, where memcpy up to n was
     * a libc call per move (issue 24) */
    if (z != x)
        memcpy(z, x, sizeof *z);
}
static inline void VM_OP(v_swap, b_swap)(sl_vm *vm, A *a, A *b)
{
    A t;
    VM_OP(v_mov, b_mov)(vm, &t, a);
    VM_OP(v_mov, b_mov)(vm, a, b);
    VM_OP(v_mov, b_mov)(vm, b, &t);
}
static inline void VM_OP(v_unbounded, b_unbounded)(sl_vm *vm, A *z) { (void)vm; aa_unbounded(z, 0); }
static inline bool VM_OP(v_is_const, b_is_const)(const A *x, double *k)
{
    *k = x->x0;
    return aa_is_point(x);
}
static inline void VM_OP(v_range, b_range)(const A *x, double *lo, double *hi)
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

/* Case splits (sl_vm_split_begin, shader.h): whether this operation is
 * split, and which of its two values this run takes */
static inline bool split_take(sl_vm *vm, int *pick)
{
    if (!vm->split.on || vm->split.full) return false;
    const int32_t *same = vm->prog->split_same;
    if (same && same[vm->split.pc] >= 0) {
        /* the same value as an earlier split (split_plan.c): its case; it
         * ran just before on this operand, and the run is not full */
        for (int i = vm->split.n - 1; i >= 0; i--)
            if (vm->split.at[i] == same[vm->split.pc]) {
                *pick = vm->split.pick[i];
                return true;
            }
    }
    if (vm->split.n >= vm->split.max) {
        vm->split.full = true;            /* this one takes both values */
        return false;
    }
    int i = vm->split.n++;
    if (i >= vm->split.fixed) vm->split.pick[i] = 0;
    vm->split.at[i] = vm->split.pc;
    *pick = vm->split.pick[i];
    return true;
}

/* floor, ceil, round of x over a range where they take two values: one of
 * them exactly, in its case */
static inline bool split_stepped(sl_vm *vm, A *z, const A *x, ia_interval (*fi)(ia_interval))
{
    if (!vm->split.on || (x->flags & AA_UNBOUNDED)) return false;
    ia_interval r = aa_range(x);
    if (!isfinite(r.lo) || !isfinite(r.hi)) return false;
    ia_interval v = fi(r);
    int pick;
    if (!(v.hi - v.lo == 1.0) || !split_take(vm, &pick)) return false;
    unsigned short flags = (unsigned short)((x->flags & ~AA_UNBOUNDED) | AA_DISCONTINUOUS);
    aa_const(z, pick ? v.hi : v.lo);
    z->flags = flags;
    return true;
}

/* step(edge, x) where it is undecided: 0 or 1 */
static inline bool split_step(sl_vm *vm, A *z, const A *edge, const A *x)
{
    if (!vm->split.on || ((x->flags | edge->flags) & AA_UNBOUNDED)) return false;
    A d;
    aa_sub(vm->ctx, &d, x, edge);
    ia_interval r = aa_range(&d);
    int pick;
    if (!(r.lo < 0 && r.hi >= 0) || !split_take(vm, &pick)) return false;
    unsigned short flags = (unsigned short)(((x->flags | edge->flags) & ~AA_UNBOUNDED) |
                                            AA_DISCONTINUOUS);
    aa_const(z, pick);
    z->flags = flags;
    return true;
}

/* mod(x, y) = x - k y where k = floor(x / y) takes two values: x - k y for
 * one of them (the affine form: its correlation with x stays) */
static inline bool split_mod(sl_vm *vm, A *z, const A *x, const A *y)
{
    if (!vm->split.on || ((x->flags | y->flags) & AA_UNBOUNDED)) return false;
    ia_interval rx = aa_range(x), ry = aa_range(y);
    if (!isfinite(rx.lo) || !isfinite(rx.hi) || !isfinite(ry.lo) || !isfinite(ry.hi) ||
        (ry.lo <= 0 && ry.hi >= 0))
        return false;
    ia_interval k = ia_floor(ia_div(rx, ry));
    int pick;
    if (!(k.hi - k.lo == 1.0) || !split_take(vm, &pick)) return false;
    unsigned short flags = (unsigned short)(((x->flags | y->flags) & ~AA_UNBOUNDED) |
                                            AA_DISCONTINUOUS);
    aa_lincomb(vm->ctx, z, 1.0, x, -(pick ? k.hi : k.lo), y, 0.0);
    z->flags = (unsigned short)(z->flags | flags);
    return true;
}

/*
 * A transform by a matrix of constants (transform("shader", P) in most
 * displacement shaders): r[i] = sum_j k[i][j] x[j] (+ k[i][3] for a
 * point), each row one aa_lincomb3 instead of three products and three
 * sums (issue 24: 9 products and 9 sums were 4 % of dented's time). Its
 * rounding is bounded once a row (affine.c); every coefficient is still
 * sum_j k[i][j] x[j]_s in round to nearest. Operands without noise
 * symbols (a uniform point) are left to the products and sums, whose
 * exact point arithmetic keeps them points. Returns false there.
 */
static inline bool VM_OP(v_rows3, b_rows3)(sl_vm *vm, A r[3], const double k[3][4],
                                            const A x[3], bool point)
{
    if (x[0].n == 0 && x[1].n == 0 && x[2].n == 0)
        return false;
    for (int i = 0; i < 3; i++)
        aa_lincomb3(vm->ctx, &r[i], k[i], x, point ? k[i][3] : 0.0);
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
EXACT_BIN(VM_OP(v_add, b_add), SL_OP_ADD, aa_add)
EXACT_BIN(VM_OP(v_sub, b_sub), SL_OP_SUB, aa_sub)
EXACT_BIN(VM_OP(v_mul, b_mul), SL_OP_MUL, aa_mul)
EXACT_BIN(VM_OP(v_div, b_div), SL_OP_DIV, aa_div)
BIN(VM_OP(v_pow, b_pow), aa_pow)
BIN(VM_OP(v_atan2, b_atan2), aa_atan2)
BIN(VM_OP(v_min, b_min), aa_min)
BIN(VM_OP(v_max, b_max), aa_max)
UN(VM_OP(v_neg, b_neg), aa_neg)
UN(VM_OP(v_sqrt, b_sqrt), aa_sqrt)
UN(VM_OP(v_invsqrt, b_invsqrt), aa_invsqrt)
UN(VM_OP(v_exp, b_exp), aa_exp)
UN(VM_OP(v_log, b_log), aa_log)
UN(VM_OP(v_sin, b_sin), aa_sin)
UN(VM_OP(v_cos, b_cos), aa_cos)
UN(VM_OP(v_tan, b_tan), aa_tan)
UN(VM_OP(v_asin, b_asin), aa_asin)
UN(VM_OP(v_acos, b_acos), aa_acos)
UN(VM_OP(v_atan, b_atan), aa_atan)
UN(VM_OP(v_abs, b_abs), aa_abs)
UN(VM_OP(v_sign, b_sign), aa_sign)
#undef BIN
#undef UN
#undef EXACT_BIN

static inline void VM_OP(v_mod, b_mod)(sl_vm *vm, A *z, const A *x, const A *y)
{
    if (!exact(SL_OP_MOD, z, x, y) && !split_mod(vm, z, x, y))
        aa_mod(vm->ctx, z, x, y);
}
static inline void VM_OP(v_step, b_step)(sl_vm *vm, A *z, const A *edge, const A *x)
{
    if (!split_step(vm, z, edge, x))
        aa_step(vm->ctx, z, edge, x);
}
static inline void VM_OP(v_floor, b_floor)(sl_vm *vm, A *z, const A *x)
{
    if (!split_stepped(vm, z, x, ia_floor))
        aa_floor(vm->ctx, z, x);
}
static inline void VM_OP(v_ceil, b_ceil)(sl_vm *vm, A *z, const A *x)
{
    if (!split_stepped(vm, z, x, ia_ceil))
        aa_ceil(vm->ctx, z, x);
}
static inline void VM_OP(v_round, b_round)(sl_vm *vm, A *z, const A *x)
{
    if (!split_stepped(vm, z, x, ia_round))
        aa_round(vm->ctx, z, x);
}

static inline void VM_OP(v_clamp, b_clamp)(sl_vm *vm, A *z, const A *x, const A *lo, const A *hi)
{
    unsigned kink = x->flags & AA_KINK;
    aa_clamp(vm->ctx, z, x, lo, hi);
    if (sl_unit_clamp(lo->x0, hi->x0) && aa_is_point(lo) && aa_is_point(hi))
        z->flags = (unsigned short)((z->flags & ~(unsigned)AA_KINK) | kink);
}
static inline void VM_OP(v_smoothstep, b_smoothstep)(sl_vm *vm, A *z, const A *e0, const A *e1, const A *x)
{
    aa_smoothstep(vm->ctx, z, e0, e1, x);
}
static inline void VM_OP(v_mix, b_mix)(sl_vm *vm, A *z, const A *x, const A *y, const A *a)
{
    aa_mix(vm->ctx, z, x, y, a);
}

/* Tri-state comparison through the range of x - y (keeps correlations). */
static inline int VM_OP(v_cmp, b_cmp)(sl_vm *vm, int op, const A *x, const A *y)
{
    ia_interval r;
    double e;
    if (aa_exact_difference(x, y, &e)) {        /* two constants: the same range */
        r.lo = r.hi = e;
    } else {
        A d;
        aa_sub(vm->ctx, &d, x, y);
        r = aa_range(&d);
        if ((d.flags & AA_UNBOUNDED) || !(r.lo <= r.hi))
            return 2;
    }
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
static inline void VM_OP(v_bool, b_bool)(sl_vm *vm, A *z, int t)
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
static inline int VM_OP(v_truth, b_truth)(const A *x)
{
    if (aa_is_exact_const(x))                   /* its range: [x0, x0] */
        return x->x0 > 0.5 ? 1 : x->x0 < 0.5 ? 0 : 2;
    ia_interval r = aa_range(x);
    return r.lo > 0.5 ? 1 : r.hi < 0.5 ? 0 : 2;
}
static inline bool VM_OP(v_same, b_same)(const A *x, const A *y)
{
    if (x->x0 != y->x0 || x->err != y->err || x->n != y->n || x->flags != y->flags ||
        x->lo != y->lo || x->hi != y->hi)
        return false;
    return memcmp(x->c, y->c, (size_t)x->n * sizeof x->c[0]) == 0;
}
static inline void VM_OP(v_merge, b_merge)(sl_vm *vm, A *z, const A *x, const A *y)
{
    aa_merge(vm->ctx, z, x, y);
}

static inline sl_status VM_OP(v_noise, b_noise)(sl_vm *vm, A *S, const sl_insn *in, int pc)
{
    int v = in->c, dim = SL_NOISE_DIM(v), kind = SL_NOISE_KIND(v);
    const A *p = &S[in->b];
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
    A tmp[3];                        /* the noise functions may not alias p: */
    int outs = (v & SL_NOISE_VECTOR) ? 3 : 1;     /* straight into the slots when */
    bool apart = in->a + outs <= in->b || in->b + dim <= in->a;   /* they are not p */
    A *out = apart ? &S[in->a] : tmp;
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
    for (int i = 0; i < outs && !apart; i++)
        VM_OP(v_mov, b_mov)(vm, &S[in->a + i], &out[i]);
    return SL_OK;
}

/* An affine form of [lo, hi] on a private error term (no symbol). */
static inline void VM_OP(v_span, b_span)(A *z, double lo, double hi)
{
    aa_const(z, 0.5 * lo + 0.5 * hi);
    double r = fmax(z->x0 - lo, hi - z->x0);
    z->err = r * (1 + 0x1p-50) + 0x1p-1070;
    z->lo = lo;
    z->hi = hi;
}

/* texture lookups: where every lookup of the range blends the same
 * bilinear cells (tex_cells), the sum of their bilinear forms over the
 * affine forms of s and t, widened by a relative 1e-9 (the float mode's
 * rounding) and clamped to the cells' texels; elsewhere the bound of the
 * filter over the ranges (tex_bound). The gradient (bump) within the
 * derivative bounds. */
static inline void VM_OP(v_cells, b_cells)(sl_vm *vm, A *z, const A *s, const A *t, const tex_cell *cell,
                                int n)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int q = 0; q < n; q++) {
        const tex_cell *c = &cell[q];
        const double *v = c->v;
        A fx, fy, k;
        aa_mul_s(vm->ctx, &fx, s, (double)c->w);
        aa_add_s(vm->ctx, &fx, &fx, -(0.5 + c->oi));
        aa_mul_s(vm->ctx, &fy, t, (double)c->h);
        aa_add_s(vm->ctx, &fy, &fy, -(0.5 + c->oj));
        aa_mul(vm->ctx, &k, &fx, &fy);
        aa_mul_s(vm->ctx, &k, &k, v[3] - v[2] - v[1] + v[0]);
        aa_mul_s(vm->ctx, &fx, &fx, v[1] - v[0]);
        aa_mul_s(vm->ctx, &fy, &fy, v[2] - v[0]);
        aa_add(vm->ctx, &k, &k, &fx);
        aa_add(vm->ctx, &k, &k, &fy);
        aa_add_s(vm->ctx, &k, &k, v[0]);
        if (c->weight != 1.0)
            aa_mul_s(vm->ctx, &k, &k, c->weight);
        if (q == 0)
            VM_OP(v_mov, b_mov)(vm, z, &k);
        else
            aa_add(vm->ctx, z, z, &k);
        for (int i = 0; i < 4; i++) {
            lo = fmin(lo, v[i]);
            hi = fmax(hi, v[i]);
        }
    }
    A e, flo, fhi;
    double eps = 1e-9 * fmax(fabs(lo), fabs(hi)) + 0x1p-1000;
    VM_OP(v_span, b_span)(&e, -eps, eps);
    aa_add(vm->ctx, z, z, &e);
    aa_const(&flo, lo);
    aa_const(&fhi, hi);
    aa_clamp(vm->ctx, z, z, &flo, &fhi);
}

/* The lookup of TEXTURE instruction `in` of texture t (sl_vm_texture),
 * its arguments at arg[0..5], into out[0..outs): the derivative mode
 * hands in its slots' values where a copy of them was (issue 24). */
static inline sl_status VM_OP(v_texture_args, b_texture_args)(sl_vm *vm, const tex_texture *t,
                                                              const A *const arg[6],
                                                              const sl_insn *in, int pc,
                                                              A out[3])
{
    double q;
    if (!VM_OP(v_is_const, b_is_const)(arg[4], &q))
        return sl_vm_texture_channel_error(vm, pc);
    tex_wrap sw = (tex_wrap)SL_TEXOP_SWRAP(in->d), tw = (tex_wrap)SL_TEXOP_TWRAP(in->d);
    int c = sl_tex_channel(q);
    int outs = sl_texop_outs(in->d);
    if (SL_TEXOP_KIND(in->d) == SL_TEXOP_GRAD) {
        double ls, lt;
        tex_lipschitz(t, c, &ls, &lt);
        VM_OP(v_span, b_span)(&out[0], -ls, ls);
        VM_OP(v_span, b_span)(&out[1], -lt, lt);
    } else {
        tex_range r;
        double *ends[4] = { r.s, r.t, r.ws, r.wt };
        for (int k = 0; k < 4; k++) {
            ia_interval x = aa_range(arg[k]);
            ends[k][0] = x.lo;
            ends[k][1] = x.hi;
        }
        for (int i = 0; i < outs; i++) {
            int ch = c < 0 ? -1 : c + i;
            tex_cell cells[2];
            double lo, hi;
            int n;
            if (ch < 0 || ch >= tex_channels(t)) {
                if (in->d & SL_TEXOP_FILL)
                    VM_OP(v_mov, b_mov)(vm, &out[i], arg[5]);
                else
                    aa_const(&out[i], sl_tex_default_fill(ch));
            } else if ((n = tex_cells_or_bound(t, ch, &r, sw, tw, 0.0, cells, &lo, &hi)) > 0) {
                VM_OP(v_cells, b_cells)(vm, &out[i], arg[0], arg[1], cells, n);
            } else {
                VM_OP(v_span, b_span)(&out[i], lo, hi);
            }
        }
    }
    return SL_OK;
}

static inline sl_status VM_OP(v_texture, b_texture)(sl_vm *vm, A *S, const sl_insn *in, int pc)
{
    sl_status st = SL_OK;
    const tex_texture *t = sl_vm_texture(vm, vm->str[in->b], pc, &st);
    if (!t)
        return st;
    const A *arg[6];
    for (int k = 0; k < 6; k++)
        arg[k] = &S[in->c + k];
    A out[3];
    st = VM_OP(v_texture_args, b_texture_args)(vm, t, arg, in, pc, out);
    if (st != SL_OK)
        return st;
    for (int i = 0; i < sl_texop_outs(in->d); i++)
        VM_OP(v_mov, b_mov)(vm, &S[in->a + i], &out[i]);
    return SL_OK;
}

static inline void VM_OP(v_random, b_random)(sl_vm *vm, A *z)
{
    VM_OP(v_bool, b_bool)(vm, z, 2);               /* [0, 1] on a private error term */
    z->flags |= AA_DISCONTINUOUS;
}

static inline void VM_OP(v_unknown, b_unknown)(A *z) { aa_unbounded(z, 0); }
#define VM_OPS_T A
#include "vm_stub_ops.inc"
#undef VM_OPS_T

