/*
 * codegen_builtin.c: code generation for calls of built-in functions (see
 * codegen.h; the generator's state and helpers are in codegen_internal.h).
 *
 * gen_builtin lowers a call by its built-in's lowering kind (builtins.h):
 * lane-wise opcodes, noise, transforms, colour spaces, matrices, strings
 * and format strings, texture lookups, splines, ray queries and the
 * lighting statements' helpers. Expressions, statements, slots and user
 * function inlining are in codegen.c.
 */
#include "sl/codegen_internal.h"
#include "sl/builtins.h"
#include "sl/check.h"
#include "sl/format.h"
#include "sl/lexer.h"
#include "sl/strbuf.h"
#include "tex/tex.h"

#include <math.h>
#include <string.h>

static int op_inputs(sl_opcode op)
{
    switch (op) {
    case SL_OP_CLAMP: case SL_OP_SMOOTHSTEP: case SL_OP_MIX: return 3;
    case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_MOD: case SL_OP_MIN: case SL_OP_MAX:
    case SL_OP_STEP: case SL_OP_DERIV:
        return 2;
    default: return 1;
    }
}

/* Componentwise op over the result's lanes. */
static int gen_lanes(cg *g, sl_opcode op, const int *args, const int *sizes, int n, int dst)
{
    int k = op_inputs(op);
    int z = cg_target(g, cg_lane_safe(dst, n, args, sizes, k), n);
    for (int i = 0; i < n; i++) {
        int in[3] = { 0, 0, 0 };
        for (int j = 0; j < k; j++)
            in[j] = cg_lane(args[j], sizes[j], i);
        cg_emit(g, op, z + i, in[0], in[1], in[2]);
    }
    return cg_into(g, z, dst, n);
}

/* Copies n values into consecutive fresh slots unless they already are. */
static int consecutive(cg *g, const int *slots, const int *sizes, int n)
{
    int total = 0;
    for (int i = 0; i < n; i++)
        total += sizes[i];
    if (n == 1 && !(slots[0] & CONST_TAG))
        return slots[0];
    int base = cg_alloc_slots(g, total), o = 0;
    for (int i = 0; i < n; i++) {
        cg_emit_mov(g, base + o, slots[i], sizes[i]);
        o += sizes[i];
    }
    return base;
}

static int gen_noise(cg *g, sl_node *e, const int *args, const int *sizes, int dst)
{
    const sl_builtin *b = e->builtin;
    int kind = (int)b->k;
    int n = e->nlist;
    int inputs = kind == SL_NOISE_PERIODIC ? n / 2 : n;
    int dim = 0;
    for (int i = 0; i < inputs; i++)
        dim += sizes[i];
    int in = consecutive(g, args, sizes, inputs);
    int period = 0;
    if (kind == SL_NOISE_PERIODIC)
        period = consecutive(g, args + inputs, sizes + inputs, inputs);
    int outs = cg_size_of(e);
    int z = cg_alloc_slots(g, outs);
    cg_emit(g, SL_OP_NOISE, z, in, SL_NOISE_VARIANT(dim, kind, outs == 3), period);
    return cg_into(g, z, dst, outs);
}

static int gen_transform(cg *g, sl_node *e, const int *args, int dst)
{
    sl_opcode op = e->builtin->op;
    int n = e->nlist;
    int x = args[n - 1];
    if (n == 2 && e->list[0]->ty == SL_TYPE_MATRIX) {
        int m = args[0];
        if (op == SL_OP_XNORMAL) {
            int inv = cg_alloc_slots(g, 16);
            cg_emit(g, SL_OP_MINVERT, inv, m, 0, 0);
            m = inv;
        }
        int z = cg_alloc_slots(g, 3);
        cg_emit(g, op, z, m, x, 0);
        return cg_into(g, z, dst, 3);
    }
    if (n == 3)       /* from space a to "current", then to space b */
        x = cg_gen_space_xform(g, op, e->list[0], SL_SPACE_TO_CURRENT, x, -1);
    return cg_gen_space_xform(g, op, e->list[n - 2], SL_SPACE_FROM_CURRENT, x, dst);
}

/* v * inversesqrt(v . v), each component clamped to [-1, 1]: the identity
 * on a unit vector, and in interval/affine mode it keeps the result bounded
 * where |v| can vanish over a range (normalize(dPdu) at a pole, N of a
 * wide range): a unit vector's components never leave [-1, 1] (issue 9). */
static int gen_normalize(cg *g, int v, int dst)
{
    int d = cg_gen_dot(g, v, v, 3, -1);
    int r = cg_op1(g, SL_OP_INVSQRT, d);
    int z = cg_target(g, dst, 3);
    int lo = cg_const_slot(g, -1.0), hi = cg_const_slot(g, 1.0);
    for (int i = 0; i < 3; i++) {
        cg_emit(g, SL_OP_MUL, z + i, v + i, r, 0);
        cg_emit(g, SL_OP_CLAMP, z + i, z + i, lo, hi);
    }
    return z;
}

/* faceforward(N, I [, Nref = Ng]) = (I . Nref < 0) ? N : -N */
typedef struct ff_job {
    int n, z;
    bool negate;
} ff_job;

static void gen_ff_job(cg *g, void *arg)
{
    ff_job *job = arg;
    for (int i = 0; i < 3; i++)
        cg_emit(g, job->negate ? SL_OP_NEG : SL_OP_MOV, job->z + i, job->n + i, 0, 0);
}

static int gen_faceforward(cg *g, sl_node *e, const int *args, int dst)
{
    int nref = e->nlist == 3 ? args[2] : sl_global_slot(SL_G_Ng);
    int z = cg_alloc_slots(g, 3);
    int mark = g->sp;
    int d = cg_gen_dot(g, args[1], nref, 3, -1);
    int c = cg_op2(g, SL_OP_LT, d, cg_const_slot(g, 0));
    g->sp = mark;
    ff_job a = { args[0], z, false }, b = { args[0], z, true };
    cg_gen_branches(g, c, gen_ff_job, &a, gen_ff_job, &b);
    return cg_into(g, z, dst, 3);
}

static int gen_reflect(cg *g, const int *args, int dst)
{
    int d = cg_gen_dot(g, args[0], args[1], 3, -1);
    int t = cg_op2(g, SL_OP_MUL, d, cg_const_slot(g, 2));
    int z = cg_alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        int u = cg_op2(g, SL_OP_MUL, t, args[1] + i);
        cg_emit(g, SL_OP_SUB, z + i, args[0] + i, u, 0);
    }
    return cg_into(g, z, dst, 3);
}

static int gen_light(cg *g, sl_node *e, const int *args, int dst)
{
    int z = cg_alloc_slots(g, 3);
    cg_emit(g, e->builtin->op, z, e->nlist > 0 ? args[0] : 0, e->nlist > 1 ? args[1] : 0,
         e->nlist > 2 ? args[2] : 0);
    return cg_into(g, z, dst, 3);
}

/* ---------------------------------------------------------------------- */
/* color spaces and matrices                                               */
/* ---------------------------------------------------------------------- */

typedef struct select_job {
    int src, z, n;
} select_job;

static void gen_select_job(cg *g, void *arg)
{
    select_job *job = arg;
    cg_emit_mov(g, job->z, job->src, job->n);
}

/* z = cond ? x : y over n slots (a branch: merged where cond is maybe). */
static int gen_select(cg *g, int cond, int x, int y, int n)
{
    int z = cg_alloc_slots(g, n);
    select_job a = { x, z, n }, b = { y, z, n };
    cg_gen_branches(g, cond, gen_select_job, &a, gen_select_job, &b);
    return z;
}

/* x / y, y replaced by 1 where it is 0 (the conversions' black and grey). */
static int safe_div(cg *g, int x, int y)
{
    int one = cg_const_slot(g, 1);
    int d = gen_select(g, cg_op2(g, SL_OP_EQ, y, cg_const_slot(g, 0)), one, y, 1);
    return cg_op2(g, SL_OP_DIV, x, d);
}

/* The linear color spaces: rgb -> space (3x3, row-major). */
static const double xyz_from_rgb[9] = {      /* linear Rec. 709 / sRGB primaries, D65 */
    0.4124564, 0.3575761, 0.1804375,
    0.2126729, 0.7151522, 0.0721750,
    0.0193339, 0.1191920, 0.9503041,
};
static const double yiq_from_rgb[9] = {      /* NTSC */
    0.299, 0.587, 0.114,
    0.596, -0.274, -0.322,
    0.211, -0.523, 0.312,
};

static void invert3(const double m[9], double inv[9])
{
    double c[9] = {
        m[4] * m[8] - m[5] * m[7], m[2] * m[7] - m[1] * m[8], m[1] * m[5] - m[2] * m[4],
        m[5] * m[6] - m[3] * m[8], m[0] * m[8] - m[2] * m[6], m[2] * m[3] - m[0] * m[5],
        m[3] * m[7] - m[4] * m[6], m[1] * m[6] - m[0] * m[7], m[0] * m[4] - m[1] * m[3],
    };
    double det = m[0] * c[0] + m[1] * c[3] + m[2] * c[6];
    for (int i = 0; i < 9; i++)
        inv[i] = c[i] / det;
}

static int gen_mat3(cg *g, const double m[9], int x)
{
    int z = cg_alloc_slots(g, 3);
    for (int r = 0; r < 3; r++) {
        cg_emit(g, SL_OP_MUL, z + r, x, cg_const_slot(g, m[r * 3]), 0);
        for (int k = 1; k < 3; k++)
            cg_emit(g, SL_OP_ADD, z + r, z + r, cg_op2(g, SL_OP_MUL, x + k, cg_const_slot(g, m[r * 3 + k])), 0);
    }
    return z;
}

/* hsv / hsl -> rgb without branches: channel k of the fully saturated hue
 * is clamp(|mod(6 h + (0, 4, 2)_k, 6) - 3| - 1, 0, 1); hsv scales it
 * towards white by s and by v, hsl around l. */
static int gen_from_hue(cg *g, int x, bool hsl)
{
    static const double offset[3] = { 0, 4, 2 };
    int z = cg_alloc_slots(g, 3);
    int h6 = cg_op2(g, SL_OP_MUL, x, cg_const_slot(g, 6));
    int chroma;
    if (hsl) {       /* s (1 - |2 l - 1|) */
        int l2 = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_MUL, x + 2, cg_const_slot(g, 2)), cg_const_slot(g, 1));
        chroma = cg_op2(g, SL_OP_MUL, x + 1, cg_op2(g, SL_OP_SUB, cg_const_slot(g, 1), cg_op1(g, SL_OP_ABS, l2)));
    } else {         /* s v */
        chroma = cg_op2(g, SL_OP_MUL, x + 1, x + 2);
    }
    for (int k = 0; k < 3; k++) {
        int a = offset[k] ? cg_op2(g, SL_OP_ADD, h6, cg_const_slot(g, offset[k])) : h6;
        a = cg_op2(g, SL_OP_MOD, a, cg_const_slot(g, 6));
        a = cg_op1(g, SL_OP_ABS, cg_op2(g, SL_OP_SUB, a, cg_const_slot(g, 3)));
        a = cg_op2(g, SL_OP_SUB, a, cg_const_slot(g, 1));
        cg_emit(g, SL_OP_CLAMP, a, a, cg_const_slot(g, 0), cg_const_slot(g, 1));
        if (hsl) {   /* l + chroma (c - 1/2) */
            int d = cg_op2(g, SL_OP_SUB, a, cg_const_slot(g, 0.5));
            cg_emit(g, SL_OP_ADD, z + k, x + 2, cg_op2(g, SL_OP_MUL, chroma, d), 0);
        } else {     /* v - chroma + chroma c = v (1 - s + s c) */
            int d = cg_op2(g, SL_OP_SUB, a, cg_const_slot(g, 1));
            cg_emit(g, SL_OP_ADD, z + k, x + 2, cg_op2(g, SL_OP_MUL, chroma, d), 0);
        }
    }
    return z;
}

/* rgb -> hsv / hsl: M = max, m = min, C = M - m; the hue from the sector
 * of the largest channel (0 for greys), h in [0, 1). */
static int gen_to_hue(cg *g, int x, bool hsl)
{
    int z = cg_alloc_slots(g, 3);
    int r = x, gg = x + 1, b = x + 2;
    int M = cg_op2(g, SL_OP_MAX, r, cg_op2(g, SL_OP_MAX, gg, b));
    int m = cg_op2(g, SL_OP_MIN, r, cg_op2(g, SL_OP_MIN, gg, b));
    int C = cg_op2(g, SL_OP_SUB, M, m);
    int hr = cg_op2(g, SL_OP_MOD, safe_div(g, cg_op2(g, SL_OP_SUB, gg, b), C), cg_const_slot(g, 6));
    int hg = cg_op2(g, SL_OP_ADD, safe_div(g, cg_op2(g, SL_OP_SUB, b, r), C), cg_const_slot(g, 2));
    int hb = cg_op2(g, SL_OP_ADD, safe_div(g, cg_op2(g, SL_OP_SUB, r, gg), C), cg_const_slot(g, 4));
    int h = gen_select(g, cg_op2(g, SL_OP_EQ, M, r), hr,
                       gen_select(g, cg_op2(g, SL_OP_EQ, M, gg), hg, hb, 1), 1);
    cg_emit(g, SL_OP_DIV, z, h, cg_const_slot(g, 6), 0);
    if (hsl) {
        int l = cg_op2(g, SL_OP_MUL, cg_op2(g, SL_OP_ADD, M, m), cg_const_slot(g, 0.5));
        int l2 = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_MUL, l, cg_const_slot(g, 2)), cg_const_slot(g, 1));
        int d = cg_op2(g, SL_OP_SUB, cg_const_slot(g, 1), cg_op1(g, SL_OP_ABS, l2));
        cg_emit(g, SL_OP_MOV, z + 1, safe_div(g, C, d), 0, 0);
        cg_emit(g, SL_OP_MOV, z + 2, l, 0, 0);
    } else {
        cg_emit(g, SL_OP_MOV, z + 1, safe_div(g, C, M), 0, 0);
        cg_emit(g, SL_OP_MOV, z + 2, M, 0, 0);
    }
    return z;
}

/* A color in `space` to rgb (from) or rgb to `space` (!from). */
int cg_gen_color_space(cg *g, int space, int x, bool from)
{
    double inv[9];
    switch ((sl_color_space)space) {
    case SL_CSPACE_RGB: return x;
    case SL_CSPACE_HSV: return from ? gen_from_hue(g, x, false) : gen_to_hue(g, x, false);
    case SL_CSPACE_HSL: return from ? gen_from_hue(g, x, true) : gen_to_hue(g, x, true);
    case SL_CSPACE_YIQ:
        if (!from)
            return gen_mat3(g, yiq_from_rgb, x);
        invert3(yiq_from_rgb, inv);
        return gen_mat3(g, inv, x);
    case SL_CSPACE_XYZ:
        if (!from)
            return gen_mat3(g, xyz_from_rgb, x);
        invert3(xyz_from_rgb, inv);
        return gen_mat3(g, inv, x);
    case SL_CSPACE_XYY:
        if (!from) {     /* XYZ -> (X, Y) / (X + Y + Z), Y */
            int q = gen_mat3(g, xyz_from_rgb, x);
            int sum = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_ADD, q, q + 1), q + 2);
            int z = cg_alloc_slots(g, 3);
            cg_emit(g, SL_OP_MOV, z, safe_div(g, q, sum), 0, 0);
            cg_emit(g, SL_OP_MOV, z + 1, safe_div(g, q + 1, sum), 0, 0);
            cg_emit(g, SL_OP_MOV, z + 2, q + 1, 0, 0);
            return z;
        } else {         /* X = x Y / y, Z = (1 - x - y) Y / y */
            int q = cg_alloc_slots(g, 3);
            int k = safe_div(g, x + 2, x + 1);
            cg_emit(g, SL_OP_MUL, q, x, k, 0);
            cg_emit(g, SL_OP_MOV, q + 1, x + 2, 0, 0);
            int w = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_SUB, cg_const_slot(g, 1), x), x + 1);
            cg_emit(g, SL_OP_MUL, q + 2, w, k, 0);
            invert3(xyz_from_rgb, inv);
            return gen_mat3(g, inv, q);
        }
    }
    return x;
}

static int gen_ctransform(cg *g, sl_node *e, const int *args, int dst)
{
    int n = e->nlist, x = args[n - 1];
    if (n == 3)
        x = cg_gen_color_space(g, sl_color_space_find(e->list[0]->name), x, true);
    x = cg_gen_color_space(g, sl_color_space_find(e->list[n - 2]->name), x, false);
    return cg_into(g, x, dst, 3);
}

/* determinant: Laplace expansion by the 2x2 minors of rows 0-1 and 2-3
 * (the same for the transposed matrix the slots hold). */
static int gen_determinant(cg *g, int m, int dst)
{
    static const int pairs[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };
    static const double sign[6] = { 1, -1, 1, 1, -1, 1 };
    int z = cg_target(g, dst, 1);
    for (int i = 0; i < 6; i++) {
        int a = pairs[i][0], b = pairs[i][1];
        int c = pairs[5 - i][0], d = pairs[5 - i][1];
        int top = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_MUL, m + a, m + 4 + b),
                      cg_op2(g, SL_OP_MUL, m + b, m + 4 + a));
        int bot = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_MUL, m + 8 + c, m + 12 + d),
                      cg_op2(g, SL_OP_MUL, m + 8 + d, m + 12 + c));
        int t = cg_op2(g, SL_OP_MUL, top, bot);
        if (i == 0)
            cg_emit(g, SL_OP_MOV, z, t, 0, 0);
        else
            cg_emit(g, sign[i] > 0 ? SL_OP_ADD : SL_OP_SUB, z, z, t, 0);
    }
    return z;
}

/* translate(m, t), rotate(m, angle, axis), scale(m, s): the transform is
 * applied first, then m (as RiTranslate, RiRotate and RiScale concatenate
 * onto the current transformation): m' = X * m in RenderMan's order. The
 * slots hold the transpose (points as columns): X's 3x3 part at r * 4 + c,
 * the translation in column 3. */
static int gen_matrix_xform(cg *g, sl_node *e, const int *args, int dst)
{
    int x = cg_alloc_slots(g, 16);
    int zero = cg_const_slot(g, 0), one = cg_const_slot(g, 1);
    for (int i = 0; i < 16; i++)
        cg_emit(g, SL_OP_MOV, x + i, i % 5 == 0 ? one : zero, 0, 0);
    int kind = (int)e->builtin->k;
    if (kind == 0) {
        for (int r = 0; r < 3; r++)
            cg_emit(g, SL_OP_MOV, x + r * 4 + 3, args[1] + r, 0, 0);
    } else if (kind == 2) {
        for (int r = 0; r < 3; r++)
            cg_emit(g, SL_OP_MOV, x + r * 5, args[1] + r, 0, 0);
    } else {         /* Rodrigues: c I + s [a]x + (1 - c) a a^T, a the unit axis */
        int a = gen_normalize(g, args[2], -1);
        int c = cg_op1(g, SL_OP_COS, args[1]), s = cg_op1(g, SL_OP_SIN, args[1]);
        int t = cg_op2(g, SL_OP_SUB, one, c);
        for (int r = 0; r < 3; r++) {
            for (int col = 0; col < 3; col++) {
                int v = cg_op2(g, SL_OP_MUL, t, cg_op2(g, SL_OP_MUL, a + r, a + col));
                if (r == col) {
                    cg_emit(g, SL_OP_ADD, x + r * 4 + col, v, c, 0);
                    continue;
                }
                int k = 3 - r - col;              /* the third axis */
                bool plus = (col - r + 3) % 3 == 2; /* [a]x: +a_k below the cycle */
                int w = cg_op2(g, SL_OP_MUL, s, a + k);
                cg_emit(g, plus ? SL_OP_ADD : SL_OP_SUB, x + r * 4 + col, v, w, 0);
            }
        }
    }
    return cg_gen_matmul(g, args[0], x, dst);
}

/* comp(m, row, col) / setcomp(m, row, col, v): element (row, col) of the
 * matrix as written (row vectors) is slot col * 4 + row. */
static int gen_mcomp(cg *g, const int *args, bool set, int dst)
{
    int m = args[0], r = args[1], c = args[2];
    if ((r & CONST_TAG) && (c & CONST_TAG)) {
        double rv = floor(g->prog->consts[r & ~CONST_TAG]);
        double cv = floor(g->prog->consts[c & ~CONST_TAG]);
        if (!(rv >= 0 && rv < 4 && cv >= 0 && cv < 4)) {
            cg_fail(g, "matrix element (%g, %g) does not exist (rows and columns 0 to 3)", rv, cv);
            return 0;
        }
        int slot = m + (int)cv * 4 + (int)rv;
        if (!set)
            return cg_into(g, slot, dst, 1);
        cg_emit(g, SL_OP_MOV, slot, args[3], 0, 0);
        return 0;
    }
    /* a row or column outside 0..3 pushes the index past the 16 elements,
     * where aload/astore stop the run (range modes: clamped, conservative) */
    int fr = cg_op1(g, SL_OP_FLOOR, r), fc = cg_op1(g, SL_OP_FLOOR, c);
    int bad = cg_op2(g, SL_OP_OR, cg_op2(g, SL_OP_OR, cg_op2(g, SL_OP_LT, fr, cg_const_slot(g, 0)),
                                   cg_op2(g, SL_OP_GT, fr, cg_const_slot(g, 3))),
                  cg_op2(g, SL_OP_OR, cg_op2(g, SL_OP_LT, fc, cg_const_slot(g, 0)),
                      cg_op2(g, SL_OP_GT, fc, cg_const_slot(g, 3))));
    int index = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, fc, cg_const_slot(g, 4)), fr);
    index = cg_op2(g, SL_OP_ADD, index, cg_op2(g, SL_OP_MUL, bad, cg_const_slot(g, 64)));
    if (set) {
        cg_emit(g, SL_OP_ASTORE, m, index, args[3], cg_array_operand(16, 1));
        cg_record_write(g, m, 16);
        return 0;
    }
    int z = cg_alloc_slots(g, 1);
    cg_emit(g, SL_OP_ALOAD, z, m, index, cg_array_operand(16, 1));
    return cg_into(g, z, dst, 1);
}

/* refract(I, N, eta) = eta I - (eta I.N + sqrt(k)) N with k = 1 - eta^2
 * (1 - (I.N)^2); (0, 0, 0) where k < 0 (total internal reflection). */
static int gen_refract(cg *g, int I, int N, int eta, int dst)
{
    int d = cg_gen_dot(g, I, N, 3, -1);
    int one = cg_const_slot(g, 1);
    int sin2 = cg_op2(g, SL_OP_SUB, one, cg_op2(g, SL_OP_MUL, d, d));
    int k = cg_op2(g, SL_OP_SUB, one, cg_op2(g, SL_OP_MUL, cg_op2(g, SL_OP_MUL, eta, eta), sin2));
    int root = cg_op1(g, SL_OP_SQRT, cg_op2(g, SL_OP_MAX, k, cg_const_slot(g, 0)));
    int a = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, eta, d), root);
    int r = cg_alloc_slots(g, 3), zero = cg_alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        cg_emit(g, SL_OP_SUB, r + i, cg_op2(g, SL_OP_MUL, eta, I + i), cg_op2(g, SL_OP_MUL, a, N + i), 0);
        cg_emit(g, SL_OP_MOV, zero + i, cg_const_slot(g, 0), 0, 0);
    }
    int z = gen_select(g, cg_op2(g, SL_OP_LT, k, cg_const_slot(g, 0)), zero, r, 3);
    return cg_into(g, z, dst, 3);
}

/* fresnel(I, N, eta, Kr, Kt [, R, T]) (I and N unit vectors; eta the
 * ratio of the indices of refraction, as for refract): Cook and Torrance's
 * unpolarised dielectric reflectance with c = |I.N|, g^2 = 1/eta^2 + c^2 -
 * 1: Kr = 1/2 ((g - c)/(g + c))^2 (1 + ((c (g + c) - 1)/(c (g - c) + 1))^2),
 * 1 where g^2 < 0 (total internal reflection); Kt = 1 - Kr; R = reflect(I,
 * N), T = refract(I, N, eta). */
static int gen_fresnel(cg *g, sl_node *e, const int *args)
{
    int I = args[0], N = args[1], eta = args[2];
    int one = cg_const_slot(g, 1);
    int c = cg_op1(g, SL_OP_ABS, cg_gen_dot(g, I, N, 3, -1));
    int inv = cg_op2(g, SL_OP_DIV, one, eta);
    int g2 = cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, inv, inv),
                                   cg_op2(g, SL_OP_MUL, c, c)), one);
    int gg = cg_op1(g, SL_OP_SQRT, cg_op2(g, SL_OP_MAX, g2, cg_const_slot(g, 0)));
    int gpc = cg_op2(g, SL_OP_ADD, gg, c), gmc = cg_op2(g, SL_OP_SUB, gg, c);
    int a = safe_div(g, gmc, gpc);
    int b = safe_div(g, cg_op2(g, SL_OP_SUB, cg_op2(g, SL_OP_MUL, c, gpc), one),
                     cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, c, gmc), one));
    int f = cg_op2(g, SL_OP_MUL, cg_op2(g, SL_OP_MUL, cg_const_slot(g, 0.5), cg_op2(g, SL_OP_MUL, a, a)),
                cg_op2(g, SL_OP_ADD, one, cg_op2(g, SL_OP_MUL, b, b)));
    int kr = gen_select(g, cg_op2(g, SL_OP_LT, g2, cg_const_slot(g, 0)), one, f, 1);
    if (e->nlist == 7) {      /* before Kr and Kt: the outputs may alias I or N */
        int r = gen_reflect(g, args, -1), t = gen_refract(g, I, N, eta, -1);
        cg_emit_mov(g, args[5], r, 3);
        cg_emit_mov(g, args[6], t, 3);
    }
    cg_emit(g, SL_OP_MOV, args[3], kr, 0, 0);
    cg_emit(g, SL_OP_SUB, args[4], one, kr, 0);
    return 0;
}

/* depth(P): z of P in camera space, (z - near) / (far - near), through the
 * VM's depth pseudo-space (sl_vm_set_clipping). */
static int gen_depth(cg *g, int p, int dst)
{
    int m = cg_alloc_slots(g, 16);
    cg_emit(g, SL_OP_SPACEK, m, SL_SPACE_DEPTH, SL_SPACE_TO_CURRENT, 0);
    int z = cg_alloc_slots(g, 3);
    cg_emit(g, SL_OP_XPOINT, z, m, p, 0);
    return cg_into(g, z + 2, dst, 1);
}

/* filterstep(edge, x [, x1] [, "width", w] [, "filter", name]): the step
 * box-filtered over [x - fw/2, x + fw/2], fw = w (|Du(x)| du + |Dv(x)| dv)
 * the filter width of x, i.e. clamp((x - edge) / fw + 1/2, 0, 1); with x1,
 * over [min(x, x1), max(x, x1)]. A zero width gives the step. */
static int gen_filterstep(cg *g, sl_node *e, const int *args, int dst)
{
    int nf = 0;
    while (nf < e->nlist && e->list[nf]->ty == SL_TYPE_FLOAT)
        nf++;
    int width = -1;
    for (int i = nf; i + 1 < e->nlist; i += 2)
        if (strcmp(e->list[i]->name, "width") == 0)
            width = args[i + 1];
    int edge = args[0], x = args[1];
    int tiny = cg_const_slot(g, 1e-12);
    int r;
    if (nf == 3) {
        int lo = cg_op2(g, SL_OP_MIN, x, args[2]), hi = cg_op2(g, SL_OP_MAX, x, args[2]);
        int w = cg_op2(g, SL_OP_SUB, hi, lo);
        if (width >= 0) {       /* widen about the middle */
            int mid = cg_op2(g, SL_OP_MUL, cg_op2(g, SL_OP_ADD, lo, hi), cg_const_slot(g, 0.5));
            w = cg_op2(g, SL_OP_MUL, w, width);
            hi = cg_op2(g, SL_OP_ADD, mid, cg_op2(g, SL_OP_MUL, w, cg_const_slot(g, 0.5)));
        }
        r = cg_op2(g, SL_OP_DIV, cg_op2(g, SL_OP_SUB, hi, edge), cg_op2(g, SL_OP_MAX, w, tiny));
    } else {
        int du = cg_op1(g, SL_OP_ABS, cg_op1(g, SL_OP_DU, x));
        int dv = cg_op1(g, SL_OP_ABS, cg_op1(g, SL_OP_DV, x));
        int w = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, du, sl_global_slot(SL_G_du)),
                    cg_op2(g, SL_OP_MUL, dv, sl_global_slot(SL_G_dv)));
        if (width >= 0)
            w = cg_op2(g, SL_OP_MUL, w, width);
        r = cg_op2(g, SL_OP_DIV, cg_op2(g, SL_OP_SUB, x, edge), cg_op2(g, SL_OP_MAX, w, tiny));
        r = cg_op2(g, SL_OP_ADD, r, cg_const_slot(g, 0.5));
    }
    int z = cg_target(g, dst, 1);
    cg_emit(g, SL_OP_CLAMP, z, r, cg_const_slot(g, 0), cg_const_slot(g, 1));
    return z;
}

/* The parts of an illuminance loop (parser.c): start, next (loads L and
 * Cl: they are written by the loop), and the cone test of
 * illuminance(P, axis, angle): L . axis >= cos(angle) |L| |axis|. */
static int gen_illuminance(cg *g, sl_node *e, const int *args, int dst)
{
    sl_opcode op = e->builtin->op;
    if (op == SL_OP_LSTART) {
        cg_emit(g, SL_OP_LSTART, 0, 0, 0, 0);
        return 0;
    }
    int L = sl_global_slot(SL_G_L);
    if (op == SL_OP_LNEXT) {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_LNEXT, z, 0, 0, 0);
        cg_record_write(g, L, 3);
        cg_record_write(g, sl_global_slot(SL_G_Cl), 3);
        return z;
    }
    int d = cg_gen_dot(g, L, args[0], 3, -1);
    int ll = cg_op1(g, SL_OP_SQRT, cg_gen_dot(g, L, L, 3, -1));
    int la = cg_op1(g, SL_OP_SQRT, cg_gen_dot(g, args[0], args[0], 3, -1));
    int r = cg_op2(g, SL_OP_MUL, cg_op2(g, SL_OP_MUL, cg_op1(g, SL_OP_COS, args[1]), ll), la);
    int z = cg_target(g, dst, 1);
    cg_emit(g, SL_OP_GE, z, d, r, 0);
    return z;
}

/* concat, format, printf: a chain of scat over the pieces; a numeric
 * conversion becomes sfmt with the C spec ("%5.2f"; d and i as "lld"; the
 * triple and matrix conversions as "f" per component). */
typedef struct fmt_job {
    cg *g;
    sl_node *e;
    int next, cur;
} fmt_job;

static void fmt_append(cg *g, fmt_job *job, int s)
{
    int z = cg_alloc_string(g);
    cg_emit(g, SL_OP_SCAT, z, job->cur, s, 0);
    cg_record_string_write(g, z);
    job->cur = z;
}

static void fmt_piece(void *arg, const char *spec, size_t len, char conv, const char *lit,
                      size_t litlen)
{
    fmt_job *job = arg;
    cg *g = job->g;
    if (litlen)
        fmt_append(g, job, cg_string_const(g, lit, litlen));
    if (!spec)
        return;
    sl_node *a = job->e->list[job->next++];
    int x = cg_gen_expr(g, a, -1);
    if (conv == 's') {
        fmt_append(g, job, x);
        return;
    }
    char c_spec[32];
    const char *tail = strchr("di", conv) ? "lld" : strchr("eg", conv) ? (conv == 'e' ? "e" : "g")
                                                                      : "f";
    snprintf(c_spec, sizeof c_spec, "%.*s%s", (int)(len), spec, tail);
    int t = cg_alloc_string(g);
    cg_emit(g, SL_OP_SFMT, t, x, cg_string_const(g, c_spec, strlen(c_spec)), cg_size_of(a));
    cg_record_string_write(g, t);
    fmt_append(g, job, t);
}

int cg_gen_strings(cg *g, sl_node *e, int dst)
{
    sl_opcode op = e->builtin->op;
    fmt_job job = { g, e, 1, cg_string_const(g, "", 0) };
    if (op == SL_OP_SCAT) {
        job.cur = cg_gen_expr(g, e->list[0], -1);
        for (int i = 1; i < e->nlist; i++)
            fmt_append(g, &job, cg_gen_expr(g, e->list[i], -1));
        return cg_into_string(g, job.cur, dst);
    }
    sl_format_walk(e->list[0]->name, fmt_piece, &job);
    if (op == SL_OP_SPRINT) {
        cg_emit(g, SL_OP_SPRINT, job.cur, 0, 0, 0);
        return 0;
    }
    return cg_into_string(g, job.cur, dst);
}

/* textureinfo(name, "datum", var): TEXINFO into var (its type string is
 * "texture" whenever the texture opens). */
static int gen_texture_info(cg *g, sl_node *e, int name, int dst)
{
    int q = (int)e->num;
    sl_sym *var = e->list[2]->sym;
    int z = cg_target(g, dst, 1);
    int size = q == SL_TEXINFO_RESOLUTION ? 2 : q == SL_TEXINFO_TYPE ? 0 : 1;
    cg_emit(g, SL_OP_TEXINFO, z, name, size ? var->slot : 0, q);
    if (size)
        cg_record_write(g, var->slot, size);
    else
        cg_emit(g, SL_OP_SMOV, var->slot, cg_string_const(g, "texture", 7), 0, 0);
    return z;
}

/* texture(), environment(), bump(), textureinfo() (check_texture; the
 * lookups of docs/textures.md): the six argument slots of TEXTURE
 * (bytecode.h) and the op. Footprint: the four-corner form's extent in s
 * and t times "width" ("swidth", "twidth"), plus "blur" ("sblur",
 * "tblur"); the other forms have the blur alone. environment() turns its
 * direction D into lat-long coordinates s = 1/2 + atan2(D.y, D.x) / 2pi,
 * t = acos(D.z / |D|) / pi (s periodic, t clamped); bump() returns
 * dh/ds (N x dPdt) + dh/dt (dPds x N), the change of the normal that a
 * displacement by h along N makes (to first order). */
int cg_gen_texture(cg *g, sl_node *e, int dst)
{
    int kind = e->op, npos = (int)e->num;
    int name = cg_gen_expr(g, e->a, -1);
    if (kind == SL_TEX_INFO)
        return gen_texture_info(g, e, name, dst);
    int chan = e->b ? cg_gen_expr(g, e->b, -1) : cg_const_slot(g, 0);
    int pos[8];
    for (int i = 0; i < npos; i++)
        pos[i] = cg_gen_expr(g, e->list[1 + i], -1);
    int blur[2] = { -1, -1 }, width[2] = { -1, -1 }, fill = cg_const_slot(g, 0);
    int fill_given = 0;                  /* SL_TEXOP_FILL */
    int wrap[2] = { TEX_WRAP_PERIODIC, kind == SL_TEX_ENVIRONMENT ? TEX_WRAP_CLAMP
                                                                  : TEX_WRAP_PERIODIC };
    for (int i = 1 + npos; i + 1 < e->nlist; i += 2) {   /* "blur" before "sblur" */
        const char *pn = e->list[i]->name;
        sl_node *v = e->list[i + 1];
        if (strcmp(pn, "filter") == 0 || strcmp(pn, "samples") == 0)
            continue;
        if (strstr(pn, "wrap")) {
            int w = tex_wrap_find(v->name);
            if (pn[0] != 't')
                wrap[0] = w;
            if (pn[0] != 's')
                wrap[1] = w;
            continue;
        }
        int x = cg_gen_expr(g, v, -1);
        if (strcmp(pn, "fill") == 0) {
            fill = x;
            fill_given = SL_TEXOP_FILL;
        }
        int *dstp = strstr(pn, "blur") ? blur : strstr(pn, "width") ? width : NULL;
        if (!dstp)
            continue;
        if (pn[0] != 't')
            dstp[0] = x;
        if (pn[0] != 's')
            dstp[1] = x;
    }
    int st[2], w[2];
    int zero = cg_const_slot(g, 0);
    if (kind == SL_TEX_ENVIRONMENT) {
        int d = gen_normalize(g, pos[0], -1);
        int a = cg_op2(g, SL_OP_ATAN2, d + 1, d);
        st[0] = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, a, cg_const_slot(g, 0.5 / M_PI)),
                    cg_const_slot(g, 0.5));
        st[1] = cg_op2(g, SL_OP_MUL, cg_op1(g, SL_OP_ACOS, d + 2), cg_const_slot(g, 1.0 / M_PI));
    } else if (npos == 8) {
        for (int k = 0; k < 2; k++) {
            int sum = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_ADD, pos[k], pos[k + 2]),
                          cg_op2(g, SL_OP_ADD, pos[k + 4], pos[k + 6]));
            st[k] = cg_op2(g, SL_OP_MUL, sum, cg_const_slot(g, 0.25));
            int lo = cg_op2(g, SL_OP_MIN, cg_op2(g, SL_OP_MIN, pos[k], pos[k + 2]),
                         cg_op2(g, SL_OP_MIN, pos[k + 4], pos[k + 6]));
            int hi = cg_op2(g, SL_OP_MAX, cg_op2(g, SL_OP_MAX, pos[k], pos[k + 2]),
                         cg_op2(g, SL_OP_MAX, pos[k + 4], pos[k + 6]));
            w[k] = cg_op2(g, SL_OP_SUB, hi, lo);
            if (width[k] >= 0)
                w[k] = cg_op2(g, SL_OP_MUL, w[k], width[k]);
        }
    } else if ((kind == SL_TEX_TEXTURE && npos == 2) || (kind == SL_TEX_BUMP && npos == 5)) {
        st[0] = pos[npos - 2];
        st[1] = pos[npos - 1];
    } else {
        st[0] = sl_global_slot(SL_G_s);
        st[1] = sl_global_slot(SL_G_t);
    }
    for (int k = 0; k < 2; k++) {
        if (npos != 8 || kind != SL_TEX_TEXTURE)
            w[k] = zero;
        if (blur[k] >= 0)
            w[k] = cg_op2(g, SL_OP_ADD, w[k], cg_op1(g, SL_OP_ABS, blur[k]));
    }
    int args = cg_alloc_slots(g, 6);
    int src[6] = { st[0], st[1], w[0], w[1], chan, fill };
    for (int k = 0; k < 6; k++)
        cg_emit(g, SL_OP_MOV, args + k, src[k], 0, 0);
    int op = kind == SL_TEX_BUMP ? SL_TEXOP_GRAD
           : cg_size_of(e) == 3 ? SL_TEXOP_COLOR : SL_TEXOP_FLOAT;
    int outs = sl_texop_outs(SL_TEXOP(op, wrap[0], wrap[1]));
    int z = cg_alloc_slots(g, outs);
    cg_emit(g, SL_OP_TEXTURE, z, name, args, SL_TEXOP(op, wrap[0], wrap[1]) | fill_given);
    if (kind != SL_TEX_BUMP)
        return cg_into(g, z, dst, outs);
    int a = cg_gen_cross(g, pos[0], pos[2], -1), b = cg_gen_cross(g, pos[1], pos[0], -1);
    int r = cg_target(g, dst, 3);
    for (int i = 0; i < 3; i++)
        cg_emit(g, SL_OP_ADD, r + i, cg_op2(g, SL_OP_MUL, z, a + i), cg_op2(g, SL_OP_MUL, z + 1, b + i),
             0);
    return r;
}

/* spline([basis,] t, knots): x = clamp(t, 0, 1) * segments; the segment
 * seg = min(floor(x), segments - 1) and its 4 knots are read with aload
 * (in interval/affine mode: the merge of every knot the segment range can
 * reach, so the result is conservative), then the cubic of the basis is
 * evaluated in x - seg by Horner's rule. */
int cg_gen_spline(cg *g, sl_node *e, int dst)
{
    const sl_spline_basis *b = sl_spline_basis_get(e->op);
    int first = e->list[0]->ty == SL_TYPE_STRING ? 1 : 0;
    int n = cg_size_of(e);
    int t = cg_gen_expr(g, e->list[first], -1);
    int nknots, base;
    sl_node *k0 = e->list[first + 1];
    if (sl_ty_is_array(k0->ty)) {
        nknots = cg_array_len(k0->sym);
        base = k0->sym->slot;
        if (nknots < 4 || (nknots - 4) % b->step != 0) {
            cg_fail(g, "a '%s' spline takes 4%s knots, not the %d of '%s'", b->name,
                 b->step == 3 ? ", 7, 10, ..." : b->step == 2 ? ", 6, 8, ..." : " or more",
                 nknots, k0->name);
            return 0;
        }
    } else {
        nknots = e->nlist - first - 1;
        base = cg_alloc_slots(g, nknots * n);
        for (int i = 0; i < nknots; i++) {
            int mark = g->sp;
            cg_gen_expr(g, e->list[first + 1 + i], base + i * n);
            g->sp = mark;
        }
    }
    int segs = (nknots - 4) / b->step + 1;
    int x = cg_alloc_slots(g, 1);
    cg_emit(g, SL_OP_CLAMP, x, t, cg_const_slot(g, 0), cg_const_slot(g, 1));
    int knot[4];                     /* first slot of each of the segment's knots */
    if (segs == 1) {
        for (int j = 0; j < 4; j++)
            knot[j] = base + j * n;
    } else {
        cg_emit(g, SL_OP_MUL, x, x, cg_const_slot(g, segs), 0);
        int seg = cg_op2(g, SL_OP_MIN, cg_op1(g, SL_OP_FLOOR, x), cg_const_slot(g, segs - 1));
        cg_emit(g, SL_OP_SUB, x, x, seg, 0);
        int at = cg_op2(g, SL_OP_MUL, seg, cg_const_slot(g, b->step));
        for (int j = 0; j < 4; j++) {
            if (e->op == SL_SPLINE_CONSTANT && j != 1)
                continue;
            int index = j ? cg_op2(g, SL_OP_ADD, at, cg_const_slot(g, j)) : at;
            knot[j] = cg_alloc_slots(g, n);
            for (int k = 0; k < n; k++)
                cg_emit(g, SL_OP_ALOAD, knot[j] + k, base + k, index, cg_array_operand(nknots, n));
        }
    }
    if (e->op == SL_SPLINE_CONSTANT)
        return cg_into(g, knot[1], dst, n);
    int z = cg_target(g, dst, n);
    for (int k = 0; k < n; k++) {
        bool started = false;
        for (int i = 0; i < 4; i++) {
            /* the coefficient of x^(3-i): sum_j m[i][j] knot_j */
            int c = -1;
            for (int j = 0; j < 4; j++) {
                double w = b->m[i][j];
                if (w == 0)
                    continue;
                int term = w == 1 ? knot[j] + k : cg_op2(g, SL_OP_MUL, knot[j] + k, cg_const_slot(g, w));
                c = c < 0 ? term : cg_op2(g, SL_OP_ADD, c, term);
            }
            if (started)
                cg_emit(g, SL_OP_MUL, z + k, z + k, x, 0);
            if (c >= 0) {
                if (started)
                    cg_emit(g, SL_OP_ADD, z + k, z + k, c, 0);
                else
                    cg_emit(g, SL_OP_MOV, z + k, c, 0, 0);
                started = true;
            }
        }
    }
    return z;
}

/* The rest of RI Spec 3.2's built-ins, lowered to scalar operations:
 * ptlined(P0, P1, Q), the distance from Q to the segment P0 P1 (t =
 * clamp((Q - P0).(P1 - P0) / |P1 - P0|^2, 0, 1)); rotate(Q, angle, P0, P1),
 * Q rotated by angle (radians) about the line through P0 and P1, as
 * RiRotate and rotate(m, angle, axis) turn (Rodrigues' formula about the
 * unit axis a: p cos + (a ^ p) sin + a (a.p)(1 - cos)); specularbrdf(L, N,
 * V, roughness), the lobe specular() sums: pow(max(0, normalize(N) .
 * normalize(normalize(L) + V)), 1 / roughness) as a grey colour;
 * shadername(), the shader's name. */
static int gen_extra(cg *g, const sl_builtin *b, const int *args, int dst)
{
    switch ((int)b->k) {
    case 0: {
        int v = cg_alloc_slots(g, 3), w = cg_alloc_slots(g, 3), d = cg_alloc_slots(g, 3);
        for (int i = 0; i < 3; i++) {
            cg_emit(g, SL_OP_SUB, v + i, args[1] + i, args[0] + i, 0);
            cg_emit(g, SL_OP_SUB, w + i, args[2] + i, args[0] + i, 0);
        }
        int vv = cg_op2(g, SL_OP_MAX, cg_gen_dot(g, v, v, 3, -1), cg_const_slot(g, 1e-300));
        int t = cg_alloc_slots(g, 1);
        cg_emit(g, SL_OP_CLAMP, t, cg_op2(g, SL_OP_DIV, cg_gen_dot(g, w, v, 3, -1), vv),
             cg_const_slot(g, 0), cg_const_slot(g, 1));
        for (int i = 0; i < 3; i++)
            cg_emit(g, SL_OP_SUB, d + i, w + i, cg_op2(g, SL_OP_MUL, t, v + i), 0);
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_SQRT, z, cg_gen_dot(g, d, d, 3, -1), 0, 0);
        return z;
    }
    case 1: {
        int axis = cg_alloc_slots(g, 3), p = cg_alloc_slots(g, 3), r = cg_alloc_slots(g, 3);
        for (int i = 0; i < 3; i++) {
            cg_emit(g, SL_OP_SUB, axis + i, args[3] + i, args[2] + i, 0);
            cg_emit(g, SL_OP_SUB, p + i, args[0] + i, args[2] + i, 0);
        }
        int a = gen_normalize(g, axis, -1);
        int c = cg_op1(g, SL_OP_COS, args[1]), sn = cg_op1(g, SL_OP_SIN, args[1]);
        int ap = cg_op2(g, SL_OP_MUL, cg_gen_dot(g, a, p, 3, -1),
                     cg_op2(g, SL_OP_SUB, cg_const_slot(g, 1), c));
        int x = cg_gen_cross(g, a, p, -1);
        for (int i = 0; i < 3; i++) {
            int sum = cg_op2(g, SL_OP_ADD, cg_op2(g, SL_OP_MUL, p + i, c),
                          cg_op2(g, SL_OP_MUL, x + i, sn));
            sum = cg_op2(g, SL_OP_ADD, sum, cg_op2(g, SL_OP_MUL, a + i, ap));
            cg_emit(g, SL_OP_ADD, r + i, args[2] + i, sum, 0);
        }
        return cg_into(g, r, dst, 3);
    }
    case 2: {
        int L = gen_normalize(g, args[0], -1), H = cg_alloc_slots(g, 3);
        for (int i = 0; i < 3; i++)
            cg_emit(g, SL_OP_ADD, H + i, L + i, args[2] + i, 0);
        int Hn = gen_normalize(g, H, -1), Nn = gen_normalize(g, args[1], -1);
        int c = cg_op2(g, SL_OP_MAX, cg_gen_dot(g, Nn, Hn, 3, -1), cg_const_slot(g, 0));
        int lobe = cg_op2(g, SL_OP_POW, c, cg_op2(g, SL_OP_DIV, cg_const_slot(g, 1), args[3]));
        int z = cg_target(g, dst, 3);
        for (int i = 0; i < 3; i++)
            cg_emit(g, SL_OP_MOV, z + i, lobe, 0, 0);
        return z;
    }
    default:
        return cg_into_string(g, cg_string_const(g, g->prog->name, strlen(g->prog->name)), dst);
    }
}

/* trace(P, R) and shadow(name, P): one RAY instruction, answered by the
 * renderer's tracer at points (vm.c sl_vm_ray). shadow() aims at the light
 * through the L global: in a light shader at the light of the last
 * illuminate (Ps - L) or solar (-L, to infinity), in a surface shader at
 * the current light of the illuminance loop. A displacement shader runs
 * over ranges of the surface, where a ray cannot be bounded: an error. */
static int gen_ray(cg *g, sl_node *e, int *args, int dst)
{
    bool trace = e->builtin->k == SL_RAY_TRACE;
    if (g->prog->kind == SL_SHADER_DISPLACEMENT) {
        cg_fail(g, "%s() cannot be used in a displacement shader: it runs over ranges of the "
             "surface, where a traced ray has no bound (use it in a surface%s shader)",
             trace ? "trace" : "shadow", trace ? "" : " or light");
        return 0;
    }
    int kind = trace ? SL_RAY_TRACE
             : g->prog->kind == SL_SHADER_LIGHT ? (g->solar ? SL_RAY_SHADOW_SOLAR
                                                            : SL_RAY_SHADOW_ILLUMINATE)
             : SL_RAY_SHADOW_SURFACE;
    int n = trace ? 3 : 1;
    int P = trace ? args[0] : args[1];
    int D = trace ? args[1] : sl_global_slot(SL_G_L);
    int map = 0;
    if (!trace) {                 /* a slot of its own: a constant's is fixed up later */
        map = cg_alloc_string(g);
        cg_emit(g, SL_OP_SMOV, map, args[0], 0, 0);
    }
    int z = cg_alloc_slots(g, n);
    cg_emit(g, SL_OP_RAY, z, P, D, kind | map << SL_RAY_KIND_BITS);
    return cg_into(g, z, dst, n);
}

int cg_gen_builtin(cg *g, sl_node *e, int dst)
{
    const sl_builtin *b = e->builtin;
    int args[8], sizes[8];
    for (int i = 0; i < e->nlist; i++) {
        sl_node *a = e->list[i];
        sizes[i] = cg_size_of(a);
        args[i] = cg_gen_expr(g, a, -1);
    }
    int n = cg_size_of(e);
    switch (b->lower) {
    case SL_LOWER_OP: return gen_lanes(g, b->op, args, sizes, n, dst);
    case SL_LOWER_SCALE: {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_MUL, z, args[0], cg_const_slot(g, b->k), 0);
        return z;
    }
    case SL_LOWER_LOGBASE: {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_DIV, z, cg_op1(g, SL_OP_LOG, args[0]), cg_op1(g, SL_OP_LOG, args[1]), 0);
        return z;
    }
    case SL_LOWER_LENGTH: {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_SQRT, z, cg_gen_dot(g, args[0], args[0], 3, -1), 0, 0);
        return z;
    }
    case SL_LOWER_NORMALIZE: return gen_normalize(g, args[0], dst);
    case SL_LOWER_DISTANCE: {
        int d = cg_alloc_slots(g, 3);
        for (int i = 0; i < 3; i++)
            cg_emit(g, SL_OP_SUB, d + i, args[1] + i, args[0] + i, 0);
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_SQRT, z, cg_gen_dot(g, d, d, 3, -1), 0, 0);
        return z;
    }
    case SL_LOWER_DOT: return cg_gen_dot(g, args[0], args[1], 3, dst);
    case SL_LOWER_CROSS: return cg_gen_cross(g, args[0], args[1], dst);
    case SL_LOWER_FACEFORWARD: return gen_faceforward(g, e, args, dst);
    case SL_LOWER_REFLECT: return gen_reflect(g, args, dst);
    case SL_LOWER_TRANSFORM: return gen_transform(g, e, args, dst);
    case SL_LOWER_CALCNORMAL: case SL_LOWER_AREA: {
        int z = cg_alloc_slots(g, n);
        cg_emit(g, b->op, z, args[0], 0, 0);
        return cg_into(g, z, dst, n);
    }
    case SL_LOWER_DERIV: return gen_lanes(g, b->op, args, sizes, n, dst);
    case SL_LOWER_COMP: return cg_into(g, args[0] + (int)b->k, dst, 1);
    case SL_LOWER_SETCOMP_K:
        cg_emit(g, SL_OP_MOV, args[0] + (int)b->k, args[1], 0, 0);
        return 0;
    case SL_LOWER_COMP_RT: {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_COMP, z, args[0], args[1], 0);
        return z;
    }
    case SL_LOWER_SETCOMP_RT:
        cg_emit(g, SL_OP_SETCOMP, args[0], args[1], args[2], 0);
        return 0;
    case SL_LOWER_NOISE: return gen_noise(g, e, args, sizes, dst);
    case SL_LOWER_RANDOM: {
        int z = cg_alloc_slots(g, n);
        cg_emit(g, SL_OP_RANDOM, z, n, 0, 0);
        return cg_into(g, z, dst, n);
    }
    case SL_LOWER_LIGHT: return gen_light(g, e, args, dst);
    case SL_LOWER_CTRANSFORM: return gen_ctransform(g, e, args, dst);
    case SL_LOWER_DETERMINANT: return gen_determinant(g, args[0], dst);
    case SL_LOWER_MATRIX_XFORM: return gen_matrix_xform(g, e, args, dst);
    case SL_LOWER_MCOMP: return gen_mcomp(g, args, false, dst);
    case SL_LOWER_MSETCOMP: return gen_mcomp(g, args, true, dst);
    case SL_LOWER_REFRACT: return gen_refract(g, args[0], args[1], args[2], dst);
    case SL_LOWER_FRESNEL: return gen_fresnel(g, e, args);
    case SL_LOWER_DEPTH: return gen_depth(g, args[0], dst);
    case SL_LOWER_FILTERSTEP: return gen_filterstep(g, e, args, dst);
    case SL_LOWER_ILLUMINANCE: return gen_illuminance(g, e, args, dst);
    case SL_LOWER_EMITTER: {      /* L = Ps - position / axis / 0 */
        int L = sl_global_slot(SL_G_L), P = sl_global_slot(SL_G_P);
        g->prog->emits_light = true;
        g->solar = b->k != 0;
        for (int i = 0; i < 3; i++) {
            if (b->k == 0)
                cg_emit(g, SL_OP_SUB, L + i, P + i, args[0] + i, 0);
            else
                cg_emit(g, SL_OP_MOV, L + i, e->nlist ? args[0] + i : cg_const_slot(g, 0), 0, 0);
        }
        return 0;
    }
    case SL_LOWER_MESSAGE: {
        bool str = e->list[1]->ty == SL_TYPE_STRING;
        int size = str ? 0 : cg_size_of(e->list[1]);
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_MESSAGE, z, args[0], args[1], (int)b->k | size << 4);
        if (str)
            cg_record_string_write(g, args[1]);
        else
            cg_record_write(g, args[1], size);
        return z;
    }
    case SL_LOWER_RAY: return gen_ray(g, e, args, dst);
    case SL_LOWER_EXTRA: return gen_extra(g, b, args, dst);
    case SL_LOWER_SPLINE: case SL_LOWER_STRINGS: break;     /* cg_gen_spline, cg_gen_strings */
    case SL_LOWER_TEXTURE: break;                           /* cg_gen_texture */
    case SL_LOWER_MATCH: {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_SMATCH, z, args[0], args[1], 0);
        return z;
    }
    }
    return 0;
}
