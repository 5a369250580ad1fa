/*
 * noise_bound.c: proven bounds of noise and pnoise over a box, the
 * interval and affine modes (the interface: noise.h; the function and its
 * global bound: noise.c; cellnoise's bounds: cellnoise_bound.c; the
 * derivations in full: docs/noise.md).
 *
 * ---- smoothness, and why one Taylor expansion spans cells --------------
 * s(0) = s'(0) = s''(0) = 0 and s(1) = 1, s'(1) = s''(1) = 0, so on a face
 * f_k = 1 of a cell the terms with c_k = 0 vanish to second order and the
 * others agree to second order with the neighbour cell's terms at f_k = 0:
 * the noise is C^2 everywhere (its third derivative jumps). Hence
 *     N(x) = N(c) + grad N(c) . (x - c) + 1/2 (x-c)^T H(xi) (x-c)
 * holds for any box, xi on the segment from c to x, with H enclosed over
 * every cell piece of the box.
 *
 * ---- bounds over a box ---------------------------------------------------
 * Two methods (enclose picks; docs/noise.md "Two methods, one rule"):
 *
 * The Taylor model (taylor_model_d): value, gradient and Hessian of raw at
 * the box centre c from ONE float evaluation (point_jet_at) with an
 * a-priori bound of its rounding (point_jet_err, derived there), and the
 * third-order remainder of Taylor's theorem (integral form, valid across
 * cell faces since the noise is C^2 and piecewise polynomial) from bounds
 * of the third partials over the box:
 *   affine:   n0 + sum_k alpha_k (x_k - c_k) +- delta, alpha_k = K g_k(c),
 *             delta = the errors of N(c), alpha + the quadratic term with
 *             H(c) (diagonal terms only half: d_k^2 in [0, r_k^2] moves
 *             the centre) + the cubic remainder;
 *   interval: n0 +- (sum |alpha_k| r_k + delta);
 *   gradient: K (g(c) +- (sum_k |H_jk(c)| r_k + the quadratic remainder)).
 *
 * The interval jets (enclose_jets), where the Taylor remainder is large:
 * the box is cut at the lattice planes into pieces (at most 2 cells per
 * axis; 3 or more give the global range [0, 1]); a piece wider than
 * NOISE_SPLIT_WIDTH is halved while the box has at most NOISE_MAX_SUBBOXES
 * sub-boxes. On each sub-box an interval "jet" is evaluated: value,
 * gradient and Hessian of raw, from per-axis enclosures of s, s', s''
 * (s and s' have exact ranges from their monotonicity; s'' from its end
 * points and its extrema at (3 -+ sqrt 3)/6) and the sum above written as
 * nested linear interpolations, one axis at a time (cell_jet_d, on the
 * two-lane vector kit of noise_interval.h where the compiler has one: the
 * same bits). An axis on a lattice plane (or a sliver of one, projected)
 * is not interpolated: the jets take the corners of its side only
 * ("Point axes" at cell_jet_d). At the box centre c the float jet's value
 * and gradient are used.
 *   interval: [0,1] ∩ natural extension (hull over sub-boxes)
 *             ∩ centred (mean-value) form N(c) + sum_k [dN/dx_k over box]
 *               [-r_k, r_k] (one sub-box), or the hull over sub-boxes of
 *               their own centred forms (several).
 *   affine:   N(x) = n0 + sum_k alpha_k (x_k - c_k) +- delta with
 *             n0, alpha_k the midpoints of the enclosures of N(c), dN/dx_k(c),
 *             delta = rad N(c) + sum_k rad(dN/dx_k(c)) r_k
 *                     + 1/2 sum_jk mag(H_jk over box) r_j r_k
 *             (used alone only by SL_NOISE_BOX_JETS).
 * In both, the x_k - c_k are the input forms less their centre values (so
 * the result is an alpha-combination of the inputs' noise symbols plus one
 * new symbol with coefficient delta). If its radius exceeds the interval
 * result's by NOISE_MINRANGE_RATIO the interval result on a new symbol is
 * used instead. The form's interval hull is met with the interval result.
 * Every value is an enclosure (the interval kit of noise_interval.h, on
 * rounding.h, rounds outward; the float jet carries its proven error), so
 * all results hold for the exact real function, rounding included.
 */
#include "sl/noise.h"
#include "sl/noise_internal.h"
#include "sl/noise_interval.h"
#include "aa/rounding.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/*
 * The affine result keeps its correlation with the inputs, which later
 * operations can use (noise(P) - noise(P) is small, P + N*noise(P) keeps
 * its dependence on u and v); the interval one does not. The linear form
 * is kept unless its radius exceeds the interval's by this factor.
 */
#define NOISE_MINRANGE_RATIO 1.25

/* Coordinates beyond this magnitude give the global range in interval and
 * affine mode (all lattice arithmetic stays exact far below it). */
#define NOISE_BOX_LIMIT 0x1p51

/* Bounds over a box: cell pieces wider than this are halved, as long as
 * the box has at most NOISE_MAX_SUBBOXES sub-boxes (docs/noise.md). */
#define NOISE_SPLIT_WIDTH 0.2
#define NOISE_MAX_SUBBOXES 16

/* Bounds over a box (enclose): the Taylor model alone is the answer where
 * its third-order remainder is at most this share of its radius; above,
 * the interval jets' range and gradient are met with it. Measured on
 * dented and the knot (docs/benchmarks.md, "noise: Taylor models"): below
 * 0.5 the jets cost more than they save; above, dented needs a sixth fewer
 * boxes with them, and boxes a third of a cell wide get half the width. */
#define NOISE_TAYLOR_SHARE 0.5

/* A box that crosses a lattice plane by at most this much (and by at most
 * 2^-24 of its own largest width) is treated as the cell on the other side
 * plus a sliver, bounded by the derivative bounds (enclose). */
#define NOISE_SLIVER_MAX 0x1p-30
#define NOISE_SLIVER_REL 0x1p-24

/* ---------------------------------------------------------------------- */
/* enclosures of the fade and its derivatives                              */
/* ---------------------------------------------------------------------- */

/* s(t) at a point t of [0, 1], as an enclosure (issue 24, session 26:
 * the interval kit's eight operations took 166 instructions, 1.6 % of
 * dented's). fade(t) = ((t t) t) ((t (6t - 15)) + 10) in round to nearest
 * errs by at most u s + 66u t^3 (the derivation at point_jet_err below,
 * u = 2^-53), and t^3 <= s (the second factor is at least 1 on [0, 1]),
 * so by at most 67u s, plus 2^-1074 per product where it underflows;
 * s -+ (2^-46 s + 2^-1000), whose own rounding is at most u s, holds the
 * exact value. */
static iv fade_at(double t)
{
    double s = fade(t), m = s * 0x1p-46 + 0x1p-1000;
    return iv_mk(s - m, s + m);
}

/* q(t) = t(1 - t) at a point t of [0, 1]: in round to nearest within
 * (2u + u^2) q (1 - t and the product each within u of their results),
 * plus an underflow; q -+ (2^-50 q + 2^-1000) holds it */
static iv q_at(double t)
{
    double q = t * (1.0 - t), m = q * 0x1p-50 + 0x1p-1000;
    return iv_mk(q - m, q + m);
}

/* s''(t) = 60 q(t) (1 - 2t) at a point */
static iv dds_at(double t)
{
    iv one_m = iv_sub(iv_pt(1.0), iv_mul_int(iv_pt(t), 2));
    return iv_mul(iv_scale_pos(q_at(t), 60.0), one_m);
}

/* s'' has its extrema +-10/sqrt(3) at t = (3 -+ sqrt 3)/6; these brackets
 * contain the two points and DDS_MAX is above 10/sqrt(3) = 5.7735026918962576. */
#define DDS_T1_LO 0.2113248654
#define DDS_T1_HI 0.2113248655
#define DDS_T2_LO 0.7886751345
#define DDS_T2_HI 0.7886751346
#define DDS_MAX   5.77350269189626

static iv clip01(iv a)
{
    return iv_mk(a.lo < 0.0 ? 0.0 : a.lo, a.hi > 1.0 ? 1.0 : a.hi);
}

/* Per axis, over an interval F within [0, 1]: the weights w_0 = 1 - s and
 * w_1 = s, the derivatives s' (>= 0) and s'' (those of w_0 are their
 * negatives), and the offsets f - b. */
typedef struct axis_fade {
    iv w[2], ds, dds, d[2];
} axis_fade;

static void axis_setup(axis_fade *a, iv F, int order)
{
    a->d[0] = F;
    a->d[1] = iv_sub(F, iv_pt(1.0));
    /* s is increasing on [0, 1] (s' = 30 t^2 (1-t)^2 >= 0) */
    iv s = clip01(iv_mk(fade_at(F.lo).lo, fade_at(F.hi).hi));
    a->w[1] = s;
    a->w[0] = clip01(iv_sub(iv_pt(1.0), s));   /* 1 - s is in [0, 1] */
    if (order >= 1) {
        /* s' = 30 q^2, q = t(1-t) increasing below 1/2, decreasing above */
        iv qa = q_at(F.lo), qb = q_at(F.hi);
        double qlo = qa.lo < qb.lo ? qa.lo : qb.lo;
        double qhi = (F.lo <= 0.5 && F.hi >= 0.5) ? 0.25
                     : (qa.hi > qb.hi ? qa.hi : qb.hi);
        if (qlo < 0.0)
            qlo = 0.0;
        iv q = iv_mk(qlo, qhi);
        iv ds = iv_scale_pos(iv_mul(q, q), 30.0);
        if (ds.lo < 0.0)
            ds.lo = 0.0;
        a->ds = ds;
    }
    if (order >= 2) {
        iv dd = iv_hull(dds_at(F.lo), dds_at(F.hi));
        if (F.lo <= DDS_T1_HI && F.hi >= DDS_T1_LO && dd.hi < DDS_MAX)
            dd.hi = DDS_MAX;
        if (F.lo <= DDS_T2_HI && F.hi >= DDS_T2_LO && dd.lo > -DDS_MAX)
            dd.lo = -DDS_MAX;
        a->dds = dd;
    }
}

/* ---------------------------------------------------------------------- */
/* interval jets of raw noise over one cell piece                          */
/* ---------------------------------------------------------------------- */

typedef struct jet {
    iv v;
    iv g[4];
    iv h[4][4];          /* j <= k used */
} jet;

/* Copies the parts of a jet (jet, or vjet below: the same fields) that
 * its order has (the whole struct is 336 bytes, of which an order-1 jet
 * in 3D uses 64: copying all of it cost an eighth of sl_bench's dented
 * time, a `rep movsq` per interpolation step) */
#define JET_COPY(dim, order, dst, src)                                  \
    do {                                                                \
        (dst)->v = (src)->v;                                            \
        if ((order) >= 1)                                               \
            for (int j_ = 0; j_ < (dim); j_++) (dst)->g[j_] = (src)->g[j_]; \
        if ((order) >= 2)                                               \
            for (int j_ = 0; j_ < (dim); j_++)                          \
                for (int k_ = j_; k_ < (dim); k_++)                     \
                    (dst)->h[j_][k_] = (src)->h[j_][k_];                \
    } while (0)


/*
 * Value (order 0), gradient (order >= 1) and Hessian (order 2) of raw
 * noise over the piece described by ax[], as nested linear
 * interpolations: raw = sum_c W_c l_c with W_c = prod_k w_k[c_k] is
 *     raw = sum_{b_D} w_D[b_D] ( ... sum_{b_1} w_1[b_1] l_{b_1..b_D} ),
 * one axis at a time. Each corner starts as the jet of its linear
 * function l_c = g_c . (f - c) (value l_c, gradient g_c, Hessian 0); one
 * step along axis k combines two jets A (c_k = 0) and B (c_k = 1) with
 * the weights w_0 = 1 - s, w_1 = s of f_k (s' = D, s'' = DD) by the
 * product rule:
 *   v    = w_0 A + w_1 B
 *   g_k  = w_0 A_k + w_1 B_k + D (B - A)
 *   g_j  = w_0 A_j + w_1 B_j                                  (j != k)
 *   h_kk = w_0 A_kk + w_1 B_kk + 2 D (B_k - A_k) + DD (B - A)
 *   h_jk = w_0 A_jk + w_1 B_jk + D (B_j - A_j)                (j != k)
 *   h_jl = w_0 A_jl + w_1 B_jl                                (j, l != k)
 * 2^D - 1 steps instead of a product per corner, and the differences
 * B - A keep the weights' derivatives from being counted twice. Every
 * operation is an interval operation with outward rounding, so each part
 * encloses the true one over the piece. Weights are >= 0 (clipped to
 * [0, 1] in axis_setup), which halves their products (ivv_mul_pos).
 */
/*
 * Point axes. An axis k whose piece is the single point f_k = b (b = 0 or
 * 1: a lattice plane, pmask bit k, side pside bit k) needs no step: there
 * w_b = 1, w_(1-b) = 0 and s' = s'' = 0 exactly, so a step along k gives
 * the jet of the corners on side b unchanged (value, every gradient and
 * Hessian part; the kk part gets 2 s' (..) + s'' (..) = 0), and their
 * linear functions have g_k (f_k - b) = 0. So only the corners on side b
 * are interpolated, along the other axes: 2^(dim-1) corners and half the
 * steps for a box on a ground plane y = 0 (enclose_jets projects such
 * thin pieces onto the plane). The gradient's and Hessian's parts along k
 * are carried by the other steps as any part off their own axis. With no
 * point axis the operations are exactly the ones of before.
 */
/* always inlined into cell_jet, once per (dim, order), so the loops unroll;
 * on the vector kit where there is one, else the scalar kit, through the
 * same ivv_ names (noise_interval.h: the same bits either way) */
typedef struct vjet {
    ivv v;
    ivv g[4];
    ivv h[4][4];
} vjet;

static inline __attribute__((always_inline)) void
cell_jet_d(int dim, const axis_fade *ax, const uint32_t h[16], int order,
           unsigned pmask, unsigned pside, jet *J)
{
    vjet t[16];
    int act[4] = { 0, 1, 2, 3 }, na = 0;
    for (int k = 0; k < dim; k++)
        if (!(pmask >> k & 1u))
            act[na++] = k;
    int n = 1 << na;
    for (int c = 0; c < n; c++) {
        /* the full corner: the point axes' sides, c's bits on the others */
        unsigned cf = pside & pmask;
        for (int m = 0; m < na; m++)
            cf |= (unsigned)((c >> m) & 1) << act[m];
        int g[4];
        gradient(dim, h[cf], g);
        iv l = iv_pt(0.0);
        for (int m = 0; m < na; m++) {
            int k = act[m];
            if (m == 0)
                l = iv_mul_int(ax[k].d[(cf >> k) & 1u], g[k]);
            else if (g[k] != 0)
                l = iv_add(l, iv_mul_int(ax[k].d[(cf >> k) & 1u], g[k]));
        }
        t[c].v = ivv_of(l);
        if (order < 1)
            continue;
        for (int k = 0; k < dim; k++)
            t[c].g[k] = ivv_pt((double)g[k]);
        /* the corners' Hessians are 0: the first step knows it */
    }
    for (int st = 0; st < na; st++) {
        int k = act[st] & 3;            /* (0..3: tells the compiler) */
        n >>= 1;
        ivv w0 = ivv_of(ax[k].w[0]), w1 = ivv_of(ax[k].w[1]);
        ivv D = ivv_of(ax[k].ds);
        iv DD = ax[k].dds;
        for (int i = 0; i < n; i++) {
            const vjet *A = &t[2 * i], *B = &t[2 * i + 1];
            vjet r;
            r.v = ivv_add(ivv_mul_pos(w0, A->v), ivv_mul_pos(w1, B->v));
            if (order >= 1) {
                ivv dv = ivv_sub(B->v, A->v);
                for (int j = 0; j < dim; j++)
                    r.g[j] = ivv_add(ivv_mul_pos(w0, A->g[j]), ivv_mul_pos(w1, B->g[j]));
                r.g[k] = ivv_add(r.g[k], ivv_mul_pos(D, dv));
                if (order >= 2) {
                    for (int j = 0; j < dim; j++)
                        for (int m = j; m < dim; m++)
                            r.h[j][m] = st == 0 ? ivv_pt(0.0)
                                                : ivv_add(ivv_mul_pos(w0, A->h[j][m]),
                                                          ivv_mul_pos(w1, B->h[j][m]));
                    ivv dgk = ivv_sub(B->g[k], A->g[k]);
                    ivv m = ivv_mul_pos(D, dgk);
                    ivv kk = ivv_add(ivv_twice(m), ivv_of(iv_mul(DD, iv_of_v(dv))));
                    r.h[k][k] = ivv_add(r.h[k][k], kk);
                    for (int j = 0; j < dim; j++) {
                        if (j == k)
                            continue;
                        ivv t_jk = ivv_mul_pos(D, ivv_sub(B->g[j], A->g[j]));
                        if (j < k) r.h[j][k] = ivv_add(r.h[j][k], t_jk);
                        else r.h[k][j] = ivv_add(r.h[k][j], t_jk);
                    }
                }
            }
            JET_COPY(dim, order, &t[i], &r);
        }
    }
    if (order >= 2 && na == 0)          /* every axis a point: H = 0 */
        for (int j = 0; j < dim; j++)
            for (int m = j; m < dim; m++)
                t[0].h[j][m] = ivv_pt(0.0);
    J->v = iv_of_v(t[0].v);
    if (order < 1)
        return;
    for (int j = 0; j < dim; j++)
        J->g[j] = iv_of_v(t[0].g[j]);
    if (order < 2)
        return;
    for (int j = 0; j < dim; j++)
        for (int m = j; m < dim; m++)
            J->h[j][m] = iv_of_v(t[0].h[j][m]);
}

static void cell_jet(int dim, const axis_fade *ax, const uint32_t h[16],
                     int order, unsigned pmask, unsigned pside, jet *J)
{
#define CELL_JET_ORDERS(D)                                           \
    switch (order) {                                                 \
    case 0: cell_jet_d(D, ax, h, 0, pmask, pside, J); break;         \
    case 1: cell_jet_d(D, ax, h, 1, pmask, pside, J); break;         \
    default: cell_jet_d(D, ax, h, 2, pmask, pside, J); break;        \
    }
    switch (dim) {
    case 1: CELL_JET_ORDERS(1) break;
    case 2: CELL_JET_ORDERS(2) break;
    case 3: CELL_JET_ORDERS(3) break;
    default: CELL_JET_ORDERS(4) break;
    }
#undef CELL_JET_ORDERS
}

/* ---------------------------------------------------------------------- */
/* the jet at a point, in float, with an a-priori error bound              */
/* ---------------------------------------------------------------------- */
/*
 * Value, gradient and Hessian of raw noise at one point, computed in plain
 * double arithmetic (round to nearest, -ffp-contract=off) by the nested
 * linear interpolations of cell_jet_d, and an a-priori bound of their
 * distance to the exact jet at that point (point_jet_err). Three to ten
 * times cheaper than the same jet in the interval kit; the bounds over
 * boxes start from it (the centre of the box, enclose).
 *
 * The error bound (sl_noise_point_jet_error runs the recurrence below;
 * point_jet_err holds its results rounded up by a factor >= 2.5, and
 * test_sl_noise checks the table against the function). Standard model:
 * every operation errs by at most u = 2^-53 times the magnitude of its
 * result, plus eta = 2^-1000 for underflow (generous: 2^-1074 suffices).
 *   Magnitudes of the exact quantities (the derivative bounds above,
 *   which hold for every partial interpolation too: it is a convex
 *   combination, over the axes interpolated so far, of the corners'
 *   linear functions): values <= Mv = 8, gradients <= Mg = 40, Hessian
 *   entries <= Mh = 160, s, 1 - s in [0, 1], s' <= 1.875, |s''| <= 5.7736.
 *   The fade at t in [0, 1]: s = ((t t) t) ((t (6t - 15)) + 10) errs by
 *   at most 67u (6u, 21u, 36u, 46u along the inner factor, 2u the cube,
 *   then 46u + 10 * 2u + u), so s and 1 - s by Ew = 96u; s' = (30 q) q
 *   with q = t (1 - t) (q errs by 1.25u) by ED = 32u (22.5u); s'' =
 *   (60 q)(1 - 2t) by EDD = 128u (111u).
 *   Corners: l_c = sum_k g_k d_k with d_k = f_k or f_k - 1 (the latter
 *   errs by u), |g_k| <= 8: at most 4 * 16u + 3 * 8u < 128u = Ev;
 *   gradients (integers) and Hessians (0) are exact.
 *   One interpolation step, parts of A and B erring by Ev, Eg, Eh: a part
 *   w0 A + w1 B (w0 + w1 = 1 exactly) errs by E (1 + 2 Ew) + M (2 Ew +
 *   4u); a product D (B - A) of a derivative weight (bound MD, error ED)
 *   and a difference (bound 2M, error 2E + 2uM) by MD (2E + 2uM) + 2M ED
 *   + (2E + 2uM) ED + 4u MD M; each further sum by u times twice the
 *   part's bound. The gradient part along the step's axis adds D (B - A)
 *   of the values; the Hessian's kk part 2 D (B_k - A_k) + DD (B - A),
 *   its jk parts D (B_j - A_j).
 *   The point: f = c - floor(c) is rounded (by at most u, |f| <= 1), so
 *   the jet computed is that of a point c' of the same closed cell with
 *   |c'_k - c_k| <= u; within the cell raw is a polynomial, and the mean
 *   value theorem with the derivative bounds NOISE_D1/D2/D3_BOUND adds
 *   D1 dim u, D2 dim u and D3 dim u to value, gradient and Hessian.
 * Results (units of u): 1D 1736 / 9162 / 43123, 2D 3344 / 24204 /
 * 171867, 3D 4952 / 45126 / 430333, 4D 6560 / 71928 / 862619.
 */

static const double point_jet_err[SL_NOISE_MAX_DIM + 1][3] = {
    { 0.0, 0.0, 0.0 },
    { 0x1p-41, 0x1p-38, 0x1p-36 },
    { 0x1p-42, 0x1p-39, 0x1p-36 },
    { 0x1p-41, 0x1p-38, 0x1p-35 },
    { 0x1p-40, 0x1p-37, 0x1p-33 },
};

void sl_noise_point_jet_error(int dim, double err[3], double used[3])
{
    /* per dim: bounds of values, gradients, Hessian entries and third
     * partials of raw (and of every partial interpolation) */
    static const double mag[SL_NOISE_MAX_DIM + 1][4] = {
        { 0, 0, 0, 0 },
        { 8.0, 38.0, 152.4, 1237.2 },
        { 2.0, 8.5, 35.7, 274.7 },
        { 2.0, 8.5, 35.7, 274.7 },
        { 3.0, 12.25, 49.7, 394.7 },
    };
    const double u = 0x1p-53, eta = 0x1p-1000;
    const double MD = 1.875, MDD = 5.7736;
    const double Ew = 96 * u, ED = 32 * u, EDD = 128 * u;
    double Ev = 128 * u, Eg = 0.0, Eh = 0.0;
    if (!dim_ok(dim)) {
        err[0] = err[1] = err[2] = used[0] = used[1] = used[2] = 0.0;
        return;
    }
    const double Mv = mag[dim][0], Mg = mag[dim][1], Mh = mag[dim][2];
    for (int j = 0; j < 3; j++)
        used[j] = point_jet_err[dim][j];
    for (int k = 0; k < dim; k++) {
        double lv = Ev * (1 + 2 * Ew) + Mv * (2 * Ew + 4 * u) + 3 * eta;
        double lg = Eg * (1 + 2 * Ew) + Mg * (2 * Ew + 4 * u) + 3 * eta;
        double lh = Eh * (1 + 2 * Ew) + Mh * (2 * Ew + 4 * u) + 3 * eta;
        double dv = 2 * Ev + 2 * u * Mv + eta, dg = 2 * Eg + 2 * u * Mg + eta;
        double Dv = MD * dv + 2 * Mv * ED + dv * ED + 4 * u * MD * Mv + eta;
        double Dg = MD * dg + 2 * Mg * ED + dg * ED + 4 * u * MD * Mg + eta;
        double DDv = MDD * dv + 2 * Mv * EDD + dv * EDD + 4 * u * MDD * Mv + eta;
        double hkk = lh + 2 * Dg + DDv + 4 * u * Mh + 2 * eta;
        double hjk = lh + Dg + 2 * u * Mh + eta;
        Ev = lv;
        Eg = lg + Dv + 2 * u * Mg + eta;
        Eh = hkk > hjk ? hkk : hjk;
    }
    err[0] = Ev + mag[dim][1] * dim * u;
    err[1] = Eg + mag[dim][2] * dim * u;
    err[2] = Eh + mag[dim][3] * dim * u;
}

#if NOISE_IV_VECTOR
/*
 * point_jet_d(3, f, hs, 2, J) on two-lane vectors (the renderer's noise(P)
 * is 3D; issue 24, session 26): a partial jet is five lane pairs, (v, g0)
 * (g1, g2) (h00, h01) (h02, h11) (h12, h22), and the interpolation w0 A +
 * w1 B of a step is five vector products and sums, the same IEEE
 * operations as the scalar loop's on every lane; the terms of the step's
 * own axis (D (B - A) and the Hessian's) are added lane by lane in the
 * same order as there. The same bits as point_jet_d (test_sl_noise_kits
 * compares this build with the scalar one, NOISE_IV_SCALAR).
 */
typedef double pj2 __attribute__((vector_size(16)));
typedef struct pjet3 { pj2 p[5]; } pjet3;

static inline __attribute__((always_inline)) void
pjet3_step(pjet3 *R, const pjet3 *A, const pjet3 *B, int k, double w0, double w1, double D,
           double DD, bool first)
{
    const pj2 W0 = { w0, w0 }, W1 = { w1, w1 };
    const int n = first ? 2 : 5;      /* the first step's Hessians: 0 */
    for (int i = 0; i < n; i++)
        R->p[i] = W0 * A->p[i] + W1 * B->p[i];
    if (first)
        R->p[2] = R->p[3] = R->p[4] = (pj2){ 0.0, 0.0 };
    double dv = B->p[0][0] - A->p[0][0];
    double dg0 = B->p[0][1] - A->p[0][1], dg1 = B->p[1][0] - A->p[1][0],
           dg2 = B->p[1][1] - A->p[1][1];
    if (k == 0) {
        R->p[0][1] = R->p[0][1] + D * dv;                            /* g0 */
        R->p[2][0] = R->p[2][0] + (2.0 * (D * dg0) + DD * dv);       /* h00 */
        R->p[2][1] = R->p[2][1] + D * dg1;                           /* h01 */
        R->p[3][0] = R->p[3][0] + D * dg2;                           /* h02 */
    } else if (k == 1) {
        R->p[1][0] = R->p[1][0] + D * dv;                            /* g1 */
        R->p[3][1] = R->p[3][1] + (2.0 * (D * dg1) + DD * dv);       /* h11 */
        R->p[2][1] = R->p[2][1] + D * dg0;                           /* h01 */
        R->p[4][0] = R->p[4][0] + D * dg2;                           /* h12 */
    } else {
        R->p[1][1] = R->p[1][1] + D * dv;                            /* g2 */
        R->p[4][1] = R->p[4][1] + (2.0 * (D * dg2) + DD * dv);       /* h22 */
        R->p[3][0] = R->p[3][0] + D * dg0;                           /* h02 */
        R->p[4][0] = R->p[4][0] + D * dg1;                           /* h12 */
    }
}

static void point_jet_3v(const double f[4], const uint32_t hs[16], point_jet *J)
{
    double w0[4], w1[4], D[4], DD[4], d[4][2];
    jet_weights(3, f, w0, w1, D, DD, d);
    pjet3 t[8], a[4], b[2], r;
    for (int c = 0; c < 8; c++) {
        int g[4];
        gradient(3, hs[c], g);
        double l = (double)g[0] * d[0][c & 1];
        l = l + (double)g[1] * d[1][(c >> 1) & 1];
        l = l + (double)g[2] * d[2][(c >> 2) & 1];
        t[c].p[0] = (pj2){ l, (double)g[0] };
        t[c].p[1] = (pj2){ (double)g[1], (double)g[2] };
    }
    for (int i = 0; i < 4; i++)
        pjet3_step(&a[i], &t[2 * i], &t[2 * i + 1], 0, w0[0], w1[0], D[0], DD[0], true);
    for (int i = 0; i < 2; i++)
        pjet3_step(&b[i], &a[2 * i], &a[2 * i + 1], 1, w0[1], w1[1], D[1], DD[1], false);
    pjet3_step(&r, &b[0], &b[1], 2, w0[2], w1[2], D[2], DD[2], false);
    J->v = r.p[0][0];
    J->g[0] = r.p[0][1];
    J->g[1] = r.p[1][0];
    J->g[2] = r.p[1][1];
    J->h[0][0] = r.p[2][0];
    J->h[0][1] = r.p[2][1];
    J->h[0][2] = r.p[3][0];
    J->h[1][1] = r.p[3][1];
    J->h[1][2] = r.p[4][0];
    J->h[2][2] = r.p[4][1];
}
#endif

/* The float jet of raw noise at the point c (|c_k| < 2^51). */
static void point_jet_at(int dim, const double *c, const int *period, uint32_t seed,
                         point_jet *J)
{
    double f[4];
    uint32_t hs[16];
    lattice_at(dim, c, period, seed, f, hs);
    switch (dim) {
    case 1: point_jet_d(1, f, hs, 2, J, NULL); break;
    case 2: point_jet_d(2, f, hs, 2, J, NULL); break;
#if NOISE_IV_VECTOR
    case 3: point_jet_3v(f, hs, J); break;
#else
    case 3: point_jet_d(3, f, hs, 2, J, NULL); break;
#endif
    default: point_jet_d(4, f, hs, 2, J, NULL); break;
    }
}

/* The float value of raw noise at cell coordinates f (in [0, 1], exact)
 * with the corners' hashes hs; within point_jet_err[dim][0] of the exact
 * value (the value's part of the bound needs nothing of the others'). */
static double point_value(int dim, const double f[4], const uint32_t hs[16])
{
    point_jet J;
    switch (dim) {
    case 1: point_jet_d(1, f, hs, 0, &J, NULL); break;
    case 2: point_jet_d(2, f, hs, 0, &J, NULL); break;
    case 3: point_jet_d(3, f, hs, 0, &J, NULL); break;
    default: point_jet_d(4, f, hs, 0, &J, NULL); break;
    }
    return J.v;
}

/* The enclosures of value and gradient that the float jet gives. */
static void point_jet_enclosure(int dim, const point_jet *P, jet *C)
{
    const double *e = point_jet_err[dim];
    C->v = iv_mk(out_dn(P->v - e[0]), out_up(P->v + e[0]));
    for (int k = 0; k < dim; k++)
        C->g[k] = iv_mk(out_dn(P->g[k] - e[1]), out_up(P->g[k] + e[1]));
}

/* ---------------------------------------------------------------------- */
/* bounds over a box                                                       */
/* ---------------------------------------------------------------------- */

typedef struct box_query {
    int dim;
    uint32_t seed;
    const int *period;
    double lo[4], hi[4];       /* the box */
    double c[4], r[4];         /* centre in the box; |x_k - c_k| <= r_k on it */
} box_query;

typedef struct box_result {
    iv range;                  /* encloses N over the box, within [0, 1] */
    iv grad[4];                /* encloses dN/dp_k over the box */
    double n0, alpha[4], delta;   /* affine: N(x) in n0 + sum alpha (x-c) +- delta */
} box_result;

/* the piece interval of cell i for the box [lo, hi] along one axis */
static iv piece_of(double lo, double hi, int64_t i)
{
    double di = (double)i;
    return clip01(iv_mk(fp_add_dn(lo, -di), fp_add_up(hi, -di)));
}

/* The lattice cells the box meets along each axis: the first, i0[k],
 * and how many, ncell[k] (1 or 2); false for a non-finite or huge box or
 * one that meets 3 or more cells along an axis (only [0, 1] is known) */
static bool box_cells(const box_query *q, int64_t i0[4], int ncell[4])
{
    for (int k = 0; k < q->dim; k++) {
        double lo = q->lo[k], hi = q->hi[k];
        if (!(lo <= hi) || !(lo > -NOISE_BOX_LIMIT) || !(hi < NOISE_BOX_LIMIT))
            return false;
        int64_t a = lat_floor(lo), b = lat_floor(hi);
        if (b > a && (double)b == hi)
            b--;                       /* the face f = 0 of cell b is in cell b-1 */
        if (b - a >= 2)
            return false;
        i0[k] = a;
        ncell[k] = (int)(b - a) + 1;
    }
    return true;
}

/*
 * Encloses N = 0.5 + K raw over the box (and, with want_affine, its
 * linearisation at the centre; with want_grad, its gradient is what the
 * caller wants most). Returns false when only the global range
 * [0, 1] is known (non-finite or huge box, or 3+ cells along an axis).
 */
static bool enclose_jets(const box_query *q, bool want_affine, const point_jet *P,
                         box_result *res)
{
    int dim = q->dim;
    int64_t i0[4];
    int ncell[4];
    if (!box_cells(q, i0, ncell)) return false;

    /*
     * Slivers. A box that crosses a lattice plane by a sliver of width e
     * (a plane at y = 0 in shader space, whose y range is a few rounding
     * errors around 0, crosses one on every box) would cost a second cell
     * piece and twice the jets. Instead the sliver's cell is dropped: a
     * point x of the sliver and its projection x' on the plane (which is
     * in the piece kept) are joined by a segment inside one cell, where
     * the noise is a polynomial, and value, gradient and Hessian agree
     * across the plane (C^2), so
     *   |raw(x) - raw(x')| <= D1 e,  |d raw(x) - d raw(x')| <= D2 e,
     *   |d2 raw(x) - d2 raw(x')| <= D3 e
     * (the NOISE_D*_BOUND). The hulls over the piece kept, widened by
     * these amounts, enclose the whole box; with slivers on several axes
     * the widths add up (one projection per axis).
     */
    double widest = 0.0, sliver = 0.0;
    for (int k = 0; k < dim; k++)
        if (q->hi[k] - q->lo[k] > widest)
            widest = q->hi[k] - q->lo[k];
    double sliver_max = NOISE_SLIVER_REL * widest;
    if (sliver_max > NOISE_SLIVER_MAX)
        sliver_max = NOISE_SLIVER_MAX;
    for (int k = 0; k < dim; k++) {
        if (ncell[k] != 2)
            continue;
        double plane = (double)(i0[k] + 1);
        double below = fp_add_up(plane, -q->lo[k]), above = fp_add_up(q->hi[k], -plane);
        if (below <= sliver_max && below <= above) {
            i0[k] += 1;                 /* keep the cell above the plane */
            ncell[k] = 1;
            sliver = fp_add_up(sliver, below);
        } else if (above <= sliver_max) {
            ncell[k] = 1;               /* keep the cell below */
            sliver = fp_add_up(sliver, above);
        }
    }

    /*
     * Point axes. A piece [0, e] or [1 - e, 1] of one cell with e at most
     * the sliver width (the ground plane y = 0 again: after the sliver is
     * dropped, its piece is [0, a few ulps]) is projected onto its lattice
     * plane f_k = 0 or 1, by the argument above (its e goes into the
     * widening), and the jets skip the axis (cell_jet_d, "Point axes"): on
     * a plane the interval jets cost half. A piece that is the plane
     * itself needs no widening.
     */
    unsigned pmask = 0, pside = 0;
    for (int k = 0; k < dim; k++) {
        if (ncell[k] != 1)
            continue;
        iv F = piece_of(q->lo[k], q->hi[k], i0[k]);
        if (F.lo == 0.0 && F.hi <= sliver_max) {
            pmask |= 1u << k;
            if (F.hi > 0.0)
                sliver = fp_add_up(sliver, F.hi);
        } else if (F.hi == 1.0 && fp_add_up(1.0, -F.lo) <= sliver_max) {
            pmask |= 1u << k;
            pside |= 1u << k;
            if (F.lo < 1.0)
                sliver = fp_add_up(sliver, fp_add_up(1.0, -F.lo));
        }
    }

    /* segments per axis: the cell pieces, each halved when wider than
     * NOISE_SPLIT_WIDTH, as long as there are at most NOISE_MAX_SUBBOXES
     * sub-boxes in all */
    iv piece[4][2];
    int parts[4][2], total = 1, split_total = 1;
    for (int k = 0; k < dim; k++) {
        int nk = 0, sk = 0;
        for (int j = 0; j < ncell[k]; j++) {
            piece[k][j] = piece_of(q->lo[k], q->hi[k], i0[k] + j);
            if (pmask >> k & 1u)
                piece[k][j] = iv_pt(pside >> k & 1u ? 1.0 : 0.0);
            parts[k][j] = piece[k][j].hi - piece[k][j].lo > NOISE_SPLIT_WIDTH ? 2 : 1;
            nk += 1;
            sk += parts[k][j];
        }
        total *= nk;
        split_total *= sk;
    }
    bool split = split_total > total && split_total <= NOISE_MAX_SUBBOXES;
    int order = want_affine ? 2 : 1;
    axis_fade ax[4][4];
    iv segF[4][4];
    int segcell[4][4], nseg[4];
    uint32_t key[4][3];
    for (int k = 0; k < dim; k++) {
        nseg[k] = 0;
        for (int j = 0; j < ncell[k]; j++) {
            iv F = piece[k][j];
            if (split && parts[k][j] == 2) {
                double m = iv_mid(F);
                segF[k][nseg[k]] = iv_mk(F.lo, m);
                segcell[k][nseg[k]++] = j;
                segF[k][nseg[k]] = iv_mk(m, F.hi);
                segcell[k][nseg[k]++] = j;
            } else {
                segF[k][nseg[k]] = F;
                segcell[k][nseg[k]++] = j;
            }
        }
        for (int s = 0; s < nseg[k]; s++)
            axis_setup(&ax[k][s], segF[k][s], order);
        for (int j = 0; j <= ncell[k]; j++)
            key[k][j] = lat_key(i0[k] + j, q->period, k);
    }
    int nsub = 1;
    for (int k = 0; k < dim; k++)
        nsub *= nseg[k];

    /* every sub-box: its jet (hull of gradient and Hessian kept), and with
     * several sub-boxes its own range: natural extension meet the centred
     * form about its midpoint */
    jet hull;
    memset(&hull, 0, sizeof hull);
    iv subrange = iv_mk(0.0, 0.0);
    /* the corners' hashes per cell (bit k: the second cell along axis k),
     * computed once: the halves of a split piece share their cell */
    uint32_t cell_h[16][16];
    unsigned cell_done = 0;
    for (int sb = 0; sb < nsub; sb++) {
        axis_fade pax[4];
        uint32_t pkey[4][2];
        unsigned cell = 0;
        int rest = sb;
        for (int k = 0; k < dim; k++) {
            int s = rest % nseg[k];
            rest /= nseg[k];
            pax[k] = ax[k][s];
            pkey[k][0] = key[k][segcell[k][s]];
            pkey[k][1] = key[k][segcell[k][s] + 1];
            cell |= (unsigned)segcell[k][s] << k;
        }
        const uint32_t *h = cell_h[cell];
        if (!(cell_done >> cell & 1u)) {
            corner_hashes(dim, q->seed, pkey, cell_h[cell]);
            cell_done |= 1u << cell;
        }
        jet J;
        cell_jet(dim, pax, h, order, pmask, pside, &J);
        if (nsub > 1) {
            double r[4], fm[4];
            rest = sb;
            for (int k = 0; k < dim; k++) {
                iv F = segF[k][rest % nseg[k]];
                rest /= nseg[k];
                fm[k] = iv_mid(F);
                r[k] = iv_rad_about(F, fm[k]);
            }
            /* the value at the sub-box's midpoint: the float jet's */
            double mvf = point_value(dim, fm, h), e0 = point_jet_err[dim][0];
            iv mv = iv_mk(out_dn(mvf - e0), out_up(mvf + e0));
            for (int k = 0; k < dim; k++)
                mv = iv_add(mv, iv_mul_sym(J.g[k], r[k]));
            iv sr = J.v;
            if (mv.lo > sr.lo) sr.lo = mv.lo;
            if (mv.hi < sr.hi) sr.hi = mv.hi;
            subrange = sb == 0 ? sr : iv_hull(subrange, sr);
        }
        if (sb == 0) {
            JET_COPY(dim, order, &hull, &J);
            continue;
        }
        hull.v = iv_hull(hull.v, J.v);
        for (int j = 0; j < dim; j++) {
            hull.g[j] = iv_hull(hull.g[j], J.g[j]);
            if (order >= 2)
                for (int k = j; k < dim; k++)
                    hull.h[j][k] = iv_hull(hull.h[j][k], J.h[j][k]);
        }
    }

    if (sliver > 0.0) {
        double a1 = fp_mul_up(NOISE_D1_BOUND, sliver), a2 = fp_mul_up(NOISE_D2_BOUND, sliver),
               a3 = fp_mul_up(NOISE_D3_BOUND, sliver);
        hull.v = iv_add(hull.v, iv_mk(-a1, a1));
        subrange = iv_add(subrange, iv_mk(-a1, a1));
        for (int j = 0; j < dim; j++) {
            hull.g[j] = iv_add(hull.g[j], iv_mk(-a2, a2));
            if (order >= 2)
                for (int k = j; k < dim; k++)
                    hull.h[j][k] = iv_add(hull.h[j][k], iv_mk(-a3, a3));
        }
    }

    /* the centre point of the whole box (for the affine linearisation, or
     * for the centred form when the box is one sub-box): the float jet at
     * the centre with its a-priori error (point_jet_at) */
    jet C;
    memset(&C, 0, sizeof C);
    bool need_centre = want_affine || nsub == 1;
    if (need_centre)
        point_jet_enclosure(dim, P, &C);

    double K = noise_scale[dim];
    iv half = iv_pt(0.5);
    iv raw = hull.v;
    if (nsub > 1) {
        if (subrange.lo > raw.lo) raw.lo = subrange.lo;
        if (subrange.hi < raw.hi) raw.hi = subrange.hi;
    }
    if (need_centre) {
        /* the centred form over the whole box */
        iv mv = C.v;
        for (int k = 0; k < dim; k++)
            mv = iv_add(mv, iv_mul_sym(hull.g[k], q->r[k]));
        if (mv.lo > raw.lo) raw.lo = mv.lo;
        if (mv.hi < raw.hi) raw.hi = mv.hi;
    }
    iv scaled_raw = iv_add(half, iv_scale_pos(raw, K));
    iv range = iv_mk(0.0, 1.0);
    if (scaled_raw.lo > range.lo) range.lo = scaled_raw.lo;
    if (scaled_raw.hi < range.hi) range.hi = scaled_raw.hi;
    if (!(range.lo <= range.hi))       /* cannot happen; stay safe */
        range = iv_mk(0.0, 1.0);
    res->range = range;
    for (int k = 0; k < dim; k++)
        res->grad[k] = iv_scale_pos(hull.g[k], K);

    if (!want_affine)
        return true;
    iv N0 = iv_add(half, iv_scale_pos(C.v, K));
    double n0 = iv_mid(N0);
    double delta = iv_rad_about(N0, n0);
    for (int k = 0; k < dim; k++) {
        iv G = iv_scale_pos(C.g[k], K);
        double a = iv_mid(G);
        res->alpha[k] = a;
        delta = fp_add_up(delta, fp_mul_up(iv_rad_about(G, a), q->r[k]));
    }
    /* Lagrange remainder: 1/2 sum_jk |H_jk| r_j r_k, H symmetric */
    double rem = 0.0;
    for (int j = 0; j < dim; j++) {
        rem = fp_add_up(rem, fp_mul_up(iv_mag(hull.h[j][j]),
                                       fp_mul_up(q->r[j], q->r[j])));
        for (int k = j + 1; k < dim; k++)
            rem = fp_add_up(rem, fp_mul_up(2.0 * iv_mag(hull.h[j][k]),
                                           fp_mul_up(q->r[j], q->r[k])));
    }
    rem = fp_mul_up(0.5 * K, rem);
    res->n0 = n0;
    res->delta = fp_add_up(delta, rem);
    return true;
}

/* ---------------------------------------------------------------------- */
/* Taylor models over small boxes                                          */
/* ---------------------------------------------------------------------- */
/*
 * Over a box of radii r_k about c (|d_k| <= r_k, d = x - c), Taylor's
 * theorem with the integral remainder,
 *     raw(c + d) = raw(c) + g.d + 1/2 d^T H d
 *                  + int_0^1 (1-t)^2/2 D^3 raw(c + t d)[d, d, d] dt,
 * g and H raw's gradient and Hessian at c, holds across cell faces: raw
 * is C^2 and piecewise polynomial, so t -> d^2/dt^2 raw(c + t d) is
 * continuous and piecewise polynomial (absolutely continuous), and the
 * remainder is at most 1/6 sup |D^3 raw[d, d, d]| <= 1/6 sum_ijk
 * M3_ijk r_i r_j r_k, with M3 the bounds of the third partials below.
 * The same for each component of the gradient, one order lower:
 *     d_j raw(c + d) = g_j + sum_k H_jk d_k + R_j,
 *     |R_j| <= 1/2 sum_kl M3_jkl r_k r_l.
 * g, H come from the float jet at c with its a-priori error (point_jet_at),
 * so one evaluation at a point replaces the interval jets over the box's
 * 2^dim-corner cells; the result is an affine form in d directly (the
 * linear part exactly as the jets' path has it, the rest on the new
 * symbol), and the diagonal terms 1/2 H_kk d_k^2, d_k^2 in [0, r_k^2],
 * move the centre by H_kk r_k^2 / 4 and add |H_kk| r_k^2 / 4 (not / 2).
 *
 * Third partials (every hash), by the product rule on raw = sum_c W_c l_c
 * as for NOISE_D1..D3_BOUND, but with the box's own factors: for xi in
 * the box (each coordinate in the cell pieces F_k of the box along axis
 * k), sum_c |d^alpha W_c(xi)| = prod_k 2 |s^(alpha_k)(f_k)| <= prod_k
 * S_k(alpha_k) with S_k(0) = 1 and S_k(j) = 2 max over F_k of |s^(j)|;
 * |l_c(xi)| = |g_c . (f - c)| <= L = gmax * (sum of the m largest of
 * max over F_k of max(f_k, 1 - f_k)) ((gmax, m) as for the global bound);
 * |g_cj| <= gm = 8, 1, 1, 1 for 1D-4D. So
 *   |d^alpha raw| <= L prod_k S_k(alpha_k)
 *                    + sum_j alpha_j gm S_j(alpha_j - 1) prod_{k != j} S_k(alpha_k).
 * Over [0, 1] the maxima of |s^(j)| over an interval are at its ends or
 * at the interior critical points: s' = 30 t^2 (1-t)^2 peaks at 1/2
 * (1.875); |s''| = |60 t (1-t)(1-2t)| at (3 -+ sqrt 3)/6 (10/sqrt 3);
 * |s'''| = |60 (6t^2 - 6t + 1)| at 1/2 (30). End values are computed in
 * round to nearest (errors below 2^-40 for these small polynomials) and
 * raised by 2^-30. With F_k = [0, 1] this gives the global figures (1D:
 * 1237.2; 2D, 3D: 274.7, 126.3, 147.7 for alpha = (3), (2, 1),
 * (1, 1, 1); 4D: 394.7, 169.6, 200.4); boxes a tenth of a cell wide get
 * about a half of them.
 * The remainders are sums of non-negative products of at most ~300
 * operations, computed in round to nearest and scaled by 1 + 2^-40
 * (> (1 + u)^300), with radii raised to at least 2^-300 so that no
 * product underflows.
 */
#define TAYLOR_SUM_SCALE (1.0 + 0x1p-40)
#define TAYLOR_POLY_SLACK 0x1p-30

/* upper bounds of s', |s''|, |s'''| over [a, b] within [0, 1]; always
 * inlined (the calls, one per axis and cell piece, took 2.6 % of dented) */
static inline __attribute__((always_inline)) void
fade_derivative_max(double a, double b, double out[3])
{
    double ends[2] = { a, b };
    out[0] = out[1] = out[2] = 0.0;
    for (int e = 0; e < 2; e++) {
        double t = ends[e], q = t * (1.0 - t);
        double d1 = 30.0 * q * q, d2 = fabs(60.0 * q * (1.0 - 2.0 * t)),
               d3 = fabs(60.0 * (6.0 * t * t - 6.0 * t + 1.0));
        if (d1 > out[0]) out[0] = d1;
        if (d2 > out[1]) out[1] = d2;
        if (d3 > out[2]) out[2] = d3;
    }
    if (a <= 0.5 && b >= 0.5) {
        out[0] = 1.875;
        if (out[2] < 30.0) out[2] = 30.0;
    }
    if ((a <= DDS_T1_HI && b >= DDS_T1_LO) || (a <= DDS_T2_HI && b >= DDS_T2_LO))
        out[1] = DDS_MAX;
    for (int j = 0; j < 3; j++)
        out[j] = out[j] * TAYLOR_SUM_SCALE + TAYLOR_POLY_SLACK;
}

/* The Taylor model's parts: range, gradient and the affine n0, alpha,
 * delta of res (as enclose_jets fills them), the third-order remainder
 * rem3 (raw units) and the largest share of a gradient component's
 * radius that its remainder takes, which the rule in enclose weighs. Always
 * inlined once per dim (taylor_model), so the loops unroll. */
static inline __attribute__((always_inline)) void
taylor_model_d(int dim, const box_query *q, const int64_t *i0, const point_jet *P,
               box_result *res, double *rem3, double *grad_share, bool want_grad)
{
    static const double gmax_of[5] = { 0, 8, 1, 1, 1 }, gm_of[5] = { 0, 8, 1, 1, 1 };
    static const int m_of[5] = { 0, 1, 2, 2, 3 };
    const double *e = point_jet_err[dim];
    double r[4], S[4][4], dmax[4];
    for (int k = 0; k < dim; k++) {
        r[k] = q->r[k] > 0x1p-300 ? q->r[k] : 0x1p-300;
        /* the box's cell pieces along k (at most two: enclose checked;
         * i0[k] = lat_floor(lo[k]), box_cells') */
        double di = (double)i0[k];
        double a = fp_add_dn(q->lo[k], -di), b = fp_add_up(q->hi[k], -di);
        if (a < 0.0) a = 0.0;
        double m[3];
        if (b > 1.0) {
            double m2[3], b1 = fp_add_up(b, -1.0);
            fade_derivative_max(a, 1.0, m);
            fade_derivative_max(0.0, b1 < 1.0 ? b1 : 1.0, m2);
            for (int j = 0; j < 3; j++)
                if (m2[j] > m[j]) m[j] = m2[j];
            dmax[k] = 1.0;
        } else {
            fade_derivative_max(a, b, m);
            dmax[k] = b > 1.0 - a ? b : 1.0 - a;
        }
        S[k][0] = 1.0;
        for (int j = 0; j < 3; j++)
            S[k][j + 1] = 2.0 * m[j];
    }
    /* L = gmax * (sum of the m largest dmax) */
    double L = 0.0;
    if (dim == 3) {
        /* the two largest of three, without the selection's unpredictable
         * branches: (0 + x1) + x2 = x1 + x2 in either order (commutative,
         * all >= 0), so the same bits as the loop below */
        double s01 = dmax[0] + dmax[1], s02 = dmax[0] + dmax[2],
               s12 = dmax[1] + dmax[2];
        bool min0 = dmax[0] <= dmax[1] && dmax[0] <= dmax[2];
        bool min1 = !min0 && dmax[1] <= dmax[2];
        L = min0 ? s12 : (min1 ? s02 : s01);
        L = L * gmax_of[dim] * TAYLOR_SUM_SCALE;
    } else {
        double d[4];
        for (int k = 0; k < dim; k++)
            d[k] = dmax[k];
        for (int t = 0; t < m_of[dim]; t++) {
            int best = t;
            for (int k = t + 1; k < dim; k++)
                if (d[k] > d[best]) best = k;
            double x = d[best];
            d[best] = d[t];
            d[t] = x;
            L += x;
        }
        L = L * gmax_of[dim] * TAYLOR_SUM_SCALE;
    }
    double gm = gm_of[dim];

    /* The bounds of the third partials by pattern: d^3/dx_i^3, d^3/dx_i^2
     * dx_j, d^3/dx_i dx_j dx_k (distinct); then 1/6 sum over ordered triples
     * ijk of M3_ijk r_i r_j r_k (multiplicities 1, 3, 6) and, for each
     * component a, 1/2 sum over ordered pairs kl of M3_akl r_k r_l. */
    double c3 = 0.0, gr[4] = { 0.0, 0.0, 0.0, 0.0 };
    for (int i = 0; i < dim; i++) {
        double Miii = L * S[i][3] + 3.0 * gm * S[i][2];
        c3 += Miii * (r[i] * r[i] * r[i]);
        if (want_grad)
            gr[i] += 0.5 * Miii * (r[i] * r[i]);
        for (int j = 0; j < dim; j++) {
            if (j == i)
                continue;
            double Miij = L * S[i][2] * S[j][1] + 2.0 * gm * S[i][1] * S[j][1] + gm * S[i][2];
            c3 += 3.0 * Miij * (r[i] * r[i] * r[j]);
            if (want_grad) {
                gr[i] += Miij * (r[i] * r[j]);           /* pairs (i, j), (j, i) */
                gr[j] += 0.5 * Miij * (r[i] * r[i]);     /* pair (i, i) */
            }
        }
        for (int j = i + 1; j < dim; j++)
            for (int k = j + 1; k < dim; k++) {
                double Mijk = L * S[i][1] * S[j][1] * S[k][1] +
                              gm * (S[j][1] * S[k][1] + S[i][1] * S[k][1] + S[i][1] * S[j][1]);
                c3 += 6.0 * Mijk * (r[i] * r[j] * r[k]);
                if (want_grad) {
                    gr[i] += Mijk * (r[j] * r[k]);
                    gr[j] += Mijk * (r[i] * r[k]);
                    gr[k] += Mijk * (r[i] * r[j]);
                }
            }
    }
    c3 = c3 / 6.0 * TAYLOR_SUM_SCALE;
    *rem3 = c3;

    double K = noise_scale[dim];

    /* gradient over the box: g_j + sum_k H_jk d_k + R_j (only for a
     * caller that wants it: noise_aa and noise_ia do not) */
    *grad_share = 0.0;
    for (int j = 0; j < dim && !want_grad; j++)
        res->grad[j] = iv_mk(-INFINITY, INFINITY);
    for (int j = 0; j < dim && want_grad; j++) {
        double w = e[1];
        for (int k = 0; k < dim; k++) {
            double h = j <= k ? P->h[j][k] : P->h[k][j];
            w += (fabs(h) + e[2]) * r[k];
        }
        w = (w + gr[j]) * TAYLOR_SUM_SCALE;
        if (gr[j] > *grad_share * w)
            *grad_share = gr[j] / w;
        res->grad[j] = iv_scale_pos(iv_mk(out_dn(P->g[j] - w), out_up(P->g[j] + w)), K);
    }

    /* The value, in round to nearest with its rounding bounded a priori
     * (issue 24, session 26: the interval kit's outward rounding per
     * operation took a third of the model's instructions). Over the box,
     * raw(c + d) = raw(c) + g(c) . d + d^T H(c) d / 2 + R3 (|R3| <= rem3),
     * the float jet within e_v, e_g, e_h of raw(c), g(c), H(c) entrywise;
     * d_k^2 in [0, r_k^2] moves the diagonal terms' centre by h_kk r_k^2
     * / 4 and leaves |h_kk| r_k^2 / 4 + e_h r_k^2 / 2 (the off-diagonal
     * terms: (|h_jk| + e_h) r_j r_k, both orders), so
     *   N in n0* + sum_k K g_k d_k +- K (e_v + e_g sum_k r_k + quad + rem3)
     * with n0* = 1/2 + K (v + sum_k h_kk r_k^2 / 4). n0 and alpha_k = K g_k
     * are that in round to nearest: n0 within 2^-49 of the same sums in
     * magnitude (a0: 3 dim + 2 roundings, r_k^2, its product and the sum
     * per axis, then K s0 and 1/2 + .: each at most u of the magnitude of
     * what it rounds, so 14u < 16u in 4D), alpha_k within u |alpha_k|,
     * whose r_k-weighted sum is 2^-53 lin. delta adds all of it; every
     * sum of nonnegative terms is raised by TAYLOR_SUM_SCALE (> (1 +
     * u)^300) and 2^-1000 (the underflow of every product), as the
     * remainders above. */
    double s0 = P->v, a0 = fabs(P->v), quad = 0.0, rsum = 0.0;
    for (int k = 0; k < dim; k++) {
        double rq = q->r[k], hk = 0.25 * P->h[k][k];
        s0 = s0 + hk * (rq * rq);
        a0 = a0 + fabs(hk) * (rq * rq);
        quad += (0.25 * fabs(P->h[k][k]) + 0.5 * e[2]) * (r[k] * r[k]);
        for (int j = k + 1; j < dim; j++)
            quad += (fabs(P->h[k][j]) + e[2]) * (r[k] * r[j]);
        rsum += rq;
    }
    double n0 = 0.5 + K * s0;
    double lin = 0.0;
    for (int k = 0; k < dim; k++) {
        double a = K * P->g[k];
        res->alpha[k] = a;
        lin += fabs(a) * q->r[k];
    }
    double delta = K * (e[0] + e[1] * rsum + quad + c3) + 0x1p-49 * (0.5 + K * a0) +
                   0x1p-53 * lin;
    delta = delta * TAYLOR_SUM_SCALE + 0x1p-1000;
    res->n0 = n0;
    res->delta = delta;

    /* the range: n0 +- (sum |alpha_k| r_k + delta), within [0, 1] */
    double rho = (lin + delta) * TAYLOR_SUM_SCALE + 0x1p-1000;
    iv range = iv_mk(out_dn(n0 - rho), out_up(n0 + rho));
    if (range.lo < 0.0) range.lo = 0.0;
    if (range.hi > 1.0) range.hi = 1.0;
    if (!(range.lo <= range.hi))
        range = iv_mk(0.0, 1.0);
    res->range = range;
}

static void taylor_model(const box_query *q, const int64_t *i0, const point_jet *P,
                         box_result *res, double *rem3, double *grad_share, bool want_grad)
{
#define TAYLOR_GRAD(D)                                                        \
    if (want_grad) taylor_model_d(D, q, i0, P, res, rem3, grad_share, true);  \
    else taylor_model_d(D, q, i0, P, res, rem3, grad_share, false);
    switch (q->dim) {
    case 1: TAYLOR_GRAD(1) break;
    case 2: TAYLOR_GRAD(2) break;
    case 3: TAYLOR_GRAD(3) break;
    default: TAYLOR_GRAD(4) break;
    }
#undef TAYLOR_GRAD
}

/* The box methods (sl_noise_set_box_method): per thread, for tests and
 * benchmarks; the renderer keeps the default. */
static _Thread_local int box_method = SL_NOISE_BOX_AUTO;

void sl_noise_set_box_method(int method)
{
    box_method = method;
}

/*
 * Encloses N = 0.5 + K raw over the box (and, with want_affine, its
 * linearisation at the centre; with want_grad, its gradient is what the
 * caller wants most: without it res->grad may be the whole line, the
 * Taylor model skips the gradient's terms). Returns false when only the
 * global range [0, 1] is known (non-finite or huge box, or 3+ cells
 * along an axis).
 *
 * The Taylor model first (one float jet at the centre); where its
 * third-order remainder is more than NOISE_TAYLOR_SHARE of its radius
 * (or, with want_grad, that of a gradient component of its radius),
 * the interval jets over the box's cell pieces (to first order) are taken
 * too and the range and gradient intervals met (both enclose the same
 * sets, so their meet does). The affine part stays the Taylor model's:
 * meeting the jets' own (to second order) too changed dented's boxes per
 * ray by under 1 % at 8 % more time (docs/benchmarks.md, "noise:
 * Taylor models"); where it is much wider than the range, noise_aa puts
 * the range on a new symbol instead.
 */
static bool enclose(const box_query *q, bool want_affine, bool want_grad,
                    box_result *res)
{
    int dim = q->dim;
    int64_t i0[4];
    int ncell[4];
    if (!box_cells(q, i0, ncell)) return false;
    point_jet P;
    point_jet_at(dim, q->c, q->period, q->seed, &P);
    if (box_method == SL_NOISE_BOX_JETS)
        return enclose_jets(q, want_affine, &P, res);

    double rem3, grad_share;
    taylor_model(q, i0, &P, res, &rem3, &grad_share, want_grad);
    double K = noise_scale[dim];
    double rho = 0.5 * (res->range.hi - res->range.lo);
    double rem = K * rem3;
    if (box_method == SL_NOISE_BOX_TAYLOR ||
        (rem <= NOISE_TAYLOR_SHARE * rho && !(want_grad && grad_share > NOISE_TAYLOR_SHARE)))
        return true;

    /* the interval jets (to first order: the natural extension, the centred
     * form and the gradient's hull) for the range and the gradient */
    box_result J;
    if (!enclose_jets(q, false, &P, &J))
        return true;                     /* cannot happen (checked above) */
    if (J.range.lo > res->range.lo) res->range.lo = J.range.lo;
    if (J.range.hi < res->range.hi) res->range.hi = J.range.hi;
    if (!(res->range.lo <= res->range.hi))     /* cannot happen; stay safe */
        res->range = iv_hull(res->range, J.range);
    for (int k = 0; k < dim; k++) {
        if (J.grad[k].lo > res->grad[k].lo) res->grad[k].lo = J.grad[k].lo;
        if (J.grad[k].hi < res->grad[k].hi) res->grad[k].hi = J.grad[k].hi;
        if (!(res->grad[k].lo <= res->grad[k].hi))
            res->grad[k] = iv_hull(res->grad[k], J.grad[k]);
    }
    return true;
}

/* ---------------------------------------------------------------------- */
/* interval mode                                                           */
/* ---------------------------------------------------------------------- */

static ia_interval ia_with(double lo, double hi, unsigned flags)
{
    ia_interval r = ia_make(lo, hi);
    r.flags |= flags;
    return r;
}

/* The box of interval inputs; false when an input is unbounded. */
static bool box_from_ia(box_query *q, int dim, const ia_interval *p,
                        unsigned *flags, bool *empty)
{
    bool ok = true;
    *flags = 0;
    *empty = false;
    for (int k = 0; k < dim; k++) {
        *flags |= p[k].flags;
        if (ia_is_empty(p[k])) {
            *empty = true;
            continue;
        }
        double lo = p[k].lo, hi = p[k].hi;
        if (!isfinite(lo) || !isfinite(hi)) {
            ok = false;
            continue;
        }
        double c = 0.5 * lo + 0.5 * hi;
        if (c < lo) c = lo;
        if (c > hi) c = hi;
        q->lo[k] = lo;
        q->hi[k] = hi;
        q->c[k] = c;
        double r1 = fp_add_up(hi, -c), r2 = fp_add_up(c, -lo);
        q->r[k] = r1 > r2 ? r1 : r2;
    }
    *flags &= ~(unsigned)AA_UNBOUNDED;
    return ok;
}

static ia_interval noise_ia(int dim, const ia_interval *p, const int *period,
                            unsigned channel)
{
    if (!dim_ok(dim))
        return ia_make(0.0, 1.0);
    box_query q;
    unsigned flags;
    bool empty;
    q.dim = dim;
    q.seed = channel_seed(channel);
    q.period = period;
    bool ok = box_from_ia(&q, dim, p, &flags, &empty);
    if (empty) {
        ia_interval e = ia_empty();
        e.flags = flags;
        return e;
    }
    box_result res;
    if (!ok || !enclose(&q, false, false, &res))
        return ia_with(0.0, 1.0, flags);
    return ia_with(res.range.lo, res.range.hi, flags);
}

bool sl_noise_gradient_ia(int dim, const ia_interval *p, const int *period, int component,
                          ia_interval *value, ia_interval *grad)
{
    if (!dim_ok(dim) || component < -1 || component > 2)
        return false;
    box_query q;
    unsigned flags;
    bool empty;
    q.dim = dim;
    q.seed = channel_seed(component < 0 ? CH_NOISE : CH_VNOISE + (unsigned)component);
    q.period = period;
    box_result res;
    if (!box_from_ia(&q, dim, p, &flags, &empty) || empty ||
        !enclose(&q, false, true, &res))
        return false;
    for (int k = 0; k < dim; k++)
        grad[k] = ia_make(res.grad[k].lo, res.grad[k].hi);
    *value = ia_with(res.range.lo, res.range.hi, flags);
    return true;
}

ia_interval sl_noise_ia(int dim, const ia_interval *p)
{
    return noise_ia(dim, p, NULL, CH_NOISE);
}

ia_interval sl_pnoise_ia(int dim, const ia_interval *p, const int *period)
{
    return noise_ia(dim, p, period, CH_NOISE);
}

void sl_vnoise_ia(int dim, const ia_interval *p, ia_interval out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = noise_ia(dim, p, NULL, CH_VNOISE + (unsigned)i);
}

void sl_vpnoise_ia(int dim, const ia_interval *p, const int *period,
                   ia_interval out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = noise_ia(dim, p, period, CH_VNOISE + (unsigned)i);
}

/* ---------------------------------------------------------------------- */
/* affine mode                                                             */
/* ---------------------------------------------------------------------- */

static void aa_interval_result(aa_context *ctx, aa_form *out, double lo,
                               double hi, unsigned flags)
{
    aa_from_interval(ctx, out, ia_with(lo, hi, flags));
}

static void noise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p,
                     const int *period, unsigned channel)
{
    if (!dim_ok(dim)) {
        aa_interval_result(ctx, out, 0.0, 1.0, 0);
        return;
    }
    box_query q;
    unsigned flags = 0;
    bool ok = true;
    q.dim = dim;
    q.seed = channel_seed(channel);
    q.period = period;
    for (int k = 0; k < dim; k++) {
        flags |= p[k].flags;
        if (p[k].flags & AA_UNBOUNDED) {
            ok = false;
            continue;
        }
        /* The box: the input's range, widened to contain the centre x0
         * (the Taylor expansion runs from x0 to every value, so the
         * segment must lie in the box where the Hessian is enclosed).
         * |x - x0| is bounded both by the form's radius and by the box. */
        double c = p[k].x0, rad;
        ia_interval R = aa_range_radius(&p[k], &rad);
        q.lo[k] = R.lo < c ? R.lo : c;
        q.hi[k] = R.hi > c ? R.hi : c;
        q.c[k] = c;
        /* the box's reach from c, rounded up (out_up: a step of 2^-52 of
         * the magnitude, more than the subtraction's rounding) */
        double rb1 = out_up(q.hi[k] - c), rb2 = out_up(c - q.lo[k]);
        double rb = rb1 > rb2 ? rb1 : rb2;
        q.r[k] = rb < rad ? rb : rad;
        if (!isfinite(R.lo) || !isfinite(R.hi) || !isfinite(rad))
            ok = false;
    }
    flags &= ~(unsigned)AA_UNBOUNDED;
    box_result res;
    if (!ok || !enclose(&q, true, false, &res)) {
        aa_interval_result(ctx, out, 0.0, 1.0, flags);
        return;
    }

    /* which of two enclosures to keep: the radii in round to nearest */
    double rho_lin = res.delta;
    for (int k = 0; k < dim; k++)
        rho_lin += fabs(res.alpha[k]) * q.r[k];
    double rho_int = 0.5 * (res.range.hi - res.range.lo);
    if (!(rho_lin <= NOISE_MINRANGE_RATIO * rho_int) || !isfinite(rho_lin)) {
        aa_interval_result(ctx, out, res.range.lo, res.range.hi, flags);
        return;
    }

    /* n0 + sum alpha_k (x_k - c_k): y_k is x_k with its centre removed
     * (exactly: the same coefficients, centre x0 - x0 = 0); the rounding of
     * the combination goes to err in aa_lincomb. In 3D (point noise, the
     * usual case) aa_lincomb3_centred does both in one pass, bit for bit. */
    if (dim == 3) {
        aa_lincomb3_centred(ctx, out, res.alpha, p, res.n0);   /* one pass */
    } else {
        aa_form y[4];
        for (int k = 0; k < dim; k++)
            aa_add_s(ctx, &y[k], &p[k], -p[k].x0);    /* x0 - x0: exact */
        if (dim == 1) {
            aa_lincomb(ctx, out, res.alpha[0], &y[0], 0.0, NULL, res.n0);
        } else {
            aa_lincomb(ctx, out, res.alpha[0], &y[0], res.alpha[1], &y[1], res.n0);
            for (int k = 2; k < dim; k++)
                aa_lincomb(ctx, out, 1.0, out, res.alpha[k], &y[k], 0.0);
        }
    }
    /* +- delta on a new symbol; the hull (of the linear part) widens by it */
    double hull_lo = out_dn(out->lo - res.delta), hull_hi = out_up(out->hi + res.delta);
    aa_add_new_error(ctx, out, res.delta);
    out->lo = hull_lo;
    out->hi = hull_hi;
    if (out->flags & AA_UNBOUNDED) {    /* cannot happen: stay safe */
        aa_interval_result(ctx, out, res.range.lo, res.range.hi, flags);
        return;
    }
    out->flags = (unsigned short)(out->flags | flags);
    /* The form's interval hull (affine.h) becomes the interval result: both
     * enclose the noise over the box, so aa_range gives their meet and the
     * affine result is never wider than the interval one. */
    if (res.range.lo > out->lo)
        out->lo = res.range.lo;
    if (res.range.hi < out->hi)
        out->hi = res.range.hi;
}

void sl_noise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p)
{
    noise_aa(ctx, out, dim, p, NULL, CH_NOISE);
}

void sl_pnoise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p,
                  const int *period)
{
    noise_aa(ctx, out, dim, p, period, CH_NOISE);
}

void sl_vnoise_aa(aa_context *ctx, aa_form out[3], int dim, const aa_form *p)
{
    for (int i = 0; i < 3; i++)
        noise_aa(ctx, &out[i], dim, p, NULL, CH_VNOISE + (unsigned)i);
}

void sl_vpnoise_aa(aa_context *ctx, aa_form out[3], int dim, const aa_form *p,
                   const int *period)
{
    for (int i = 0; i < 3; i++)
        noise_aa(ctx, &out[i], dim, p, period, CH_VNOISE + (unsigned)i);
}
