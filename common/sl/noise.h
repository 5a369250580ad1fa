/*
 * noise.h: the noise functions of the shading language: noise, pnoise,
 * cellnoise and their vector-valued variants in 1 to 4 dimensions, each in
 * three modes:
 *
 *   float     double in, double out (the ordinary shader evaluation);
 *   interval  ia_interval in, an interval out that encloses the exact real
 *             function over the whole input box, rounding included;
 *   affine    aa_form in, an aa_form out that depends on the inputs' noise
 *             symbols (a linearisation plus one new noise symbol), so that a
 *             displacement P + N*noise(P) keeps its dependence on u and v
 *             (Heidrich & Seidel 1998, §4: noise is a non-affine function
 *             that gets "a best affine approximation plus a new error term").
 *
 * noise is Perlin's improved gradient noise (K. Perlin, "Improving Noise",
 * SIGGRAPH 2002): the quintic fade 6t^5 - 15t^4 + 10t^3 and gradients from a
 * small fixed set, dotted with the offset to each lattice corner. Its raw
 * value is scaled by a proven bound of its magnitude into RenderMan's range:
 *
 *     noise(p) = 0.5 + 0.5 * raw(p) / B_dim,     always within [0, 1],
 *
 * with B_1 = 4, B_2 = 1, B_3 = 1.0364, B_4 = 1.537 (noise.c and
 * docs/noise.md give the gradient sets and the proof; the 3D and 4D bounds
 * are re-certified by tests/sl/test_sl_noise.c on every run).
 *
 * Determinism: the lattice hash is an integer hash, the lattice logic uses
 * no libm, and the arithmetic is plain IEEE double as written (the build
 * has -ffp-contract=off), so every host of a farm computes the same bits.
 * The hash sees lattice coordinates modulo 2^32, so noise repeats with
 * period 2^32 along each axis. Coordinates that are not finite or whose
 * magnitude is at least 2^62 are treated as 0 (their value is of no use).
 *
 * pnoise: period[k] >= 1 wraps lattice coordinate k modulo period[k], so
 * pnoise(p + period[k]*e_k) == pnoise(p) (up to the rounding of p itself);
 * period[k] <= 0, or period == NULL, leaves axis k unwrapped, where pnoise
 * equals noise.
 *
 * cellnoise: one value in [0, 1) per integer cell (floor of each
 * coordinate), a multiple of 2^-24, piecewise constant.
 *
 * Vector variants (point/color/vector noise) return three channels from
 * three further hash seeds, uncorrelated with each other and with the
 * float variant.
 *
 * Bounds (interval and affine modes; docs/noise.md):
 *   - across at most two lattice cells along every axis (the noise is C^2
 *     everywhere, so one Taylor expansion spans the cell faces): a Taylor
 *     model at the box centre from one float evaluation of value,
 *     gradient and Hessian there (with an a-priori bound of its rounding)
 *     and a third-order remainder from bounds of the third derivatives
 *     over the box; affine: its linear part plus the rest on one new
 *     symbol (the interval result on a new symbol when that is much
 *     narrower); interval: its range. Where the remainder is large, also
 *     the interval jets over the box's cell pieces (the centred form with
 *     the gradient enclosed over the box, met with the natural interval
 *     extension; wide boxes cut into a few sub-boxes), the two met;
 *   - across three or more cells along some axis: the global range [0, 1].
 *   cellnoise: the hull of the values of the cells the box meets (at most
 *   64, else [0, 1)), flagged AA_DISCONTINUOUS when that is more than one.
 * All results are rounding-safe in the sense of common/aa (docs/arithmetic.md).
 * Input flags are kept (AA_DISCONTINUOUS) except AA_UNBOUNDED: noise of an
 * unbounded input is simply the global range.
 *
 * dim must be 1..4 (SL_NOISE_MAX_DIM); any other dim gives 0.5, or [0, 1].
 * Affine mode uses one new noise symbol of ctx per scalar result (three for
 * the vector variants); once ctx's capacity is spent it folds into err.
 */
#ifndef SL_NOISE_H
#define SL_NOISE_H

#include <stddef.h>

#include "aa/affine.h"
#include "aa/interval.h"

#define SL_NOISE_MAX_DIM 4

/* ---- float mode ---- */
double sl_noise(int dim, const double *p);
double sl_pnoise(int dim, const double *p, const int *period);
double sl_cellnoise(int dim, const double *p);
void sl_vnoise(int dim, const double *p, double out[3]);
void sl_vpnoise(int dim, const double *p, const int *period, double out[3]);
void sl_vcellnoise(int dim, const double *p, double out[3]);

/* noise (period == NULL) or pnoise at p; writes d noise / d p[k] to
 * grad[0..dim-1] and returns the value (equal to sl_pnoise's). */
double sl_noise_grad(int dim, const double *p, const int *period, double *grad);

/* ---- interval mode ---- */
ia_interval sl_noise_ia(int dim, const ia_interval *p);
ia_interval sl_pnoise_ia(int dim, const ia_interval *p, const int *period);
ia_interval sl_cellnoise_ia(int dim, const ia_interval *p);
void sl_vnoise_ia(int dim, const ia_interval *p, ia_interval out[3]);
void sl_vpnoise_ia(int dim, const ia_interval *p, const int *period,
                   ia_interval out[3]);
void sl_vcellnoise_ia(int dim, const ia_interval *p, ia_interval out[3]);
/* Bounds of d noise / d p[k] (k < dim) over the box p, and the value's
 * (*value: within what sl_noise_ia / sl_pnoise_ia / sl_vnoise_ia give,
 * narrower where the gradient's bound took the interval jets too): noise
 * or pnoise (period NULL or not), component -1 for the scalar noise, 0..2
 * for those of the vector noise. False where none are known (an unbounded
 * or empty input, a box over more than two lattice cells on an axis). The
 * Taylor model's gradient (g(c) + H(c) d + a third-order remainder), met
 * with the hull of the interval jets' gradients over the box's cell
 * pieces where that remainder is large (docs/noise.md). */
bool sl_noise_gradient_ia(int dim, const ia_interval *p, const int *period, int component,
                          ia_interval *value, ia_interval *grad);

/* ---- affine mode (out may not alias p) ---- */
void sl_noise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p);
void sl_pnoise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p,
                  const int *period);
void sl_cellnoise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p);
void sl_vnoise_aa(aa_context *ctx, aa_form out[3], int dim, const aa_form *p);
void sl_vpnoise_aa(aa_context *ctx, aa_form out[3], int dim, const aa_form *p,
                   const int *period);
void sl_vcellnoise_aa(aa_context *ctx, aa_form out[3], int dim,
                      const aa_form *p);

/* ---- the constants behind the range (for tests and docs) ---- */
/* B_dim: proven bound of |raw noise| (0 for an invalid dim). */
double sl_noise_raw_bound(int dim);
/* The factor K_dim with noise = 0.5 + K_dim * raw; K_dim * B_dim <= 1/2. */
double sl_noise_scale(int dim);
/* Bounds of |any first, second, third partial derivative of raw noise|,
 * every dimension (derived in noise.c; used for slivers). order 1..3. */
double sl_noise_raw_derivative_bound(int order);

/* The rounding error of the float jet (value, gradient, Hessian of raw
 * noise) at a point that the box bounds start from: derived[0..2] the
 * bounds the derivation in noise.c gives, used[0..2] those noise.c uses
 * (a table that must not be below them; the tests check it). */
void sl_noise_point_jet_error(int dim, double derived[3], double used[3]);

/* How noise over a box is bounded, for tests and benchmarks (the calling
 * thread only; default SL_NOISE_BOX_AUTO): the Taylor model at the box's
 * centre where its remainder is small, else also the interval jets over
 * the box's cell pieces, the two met; or either alone. */
enum { SL_NOISE_BOX_AUTO = 0, SL_NOISE_BOX_JETS = 1, SL_NOISE_BOX_TAYLOR = 2 };
void sl_noise_set_box_method(int method);

/* ---- fixed-dimension spellings ---- */
static inline double sl_noise1(double x) { return sl_noise(1, &x); }
static inline double sl_noise2(double x, double y)
{
    const double p[2] = { x, y };
    return sl_noise(2, p);
}
static inline double sl_noise3(const double p[3]) { return sl_noise(3, p); }
static inline double sl_noise4(const double p[4]) { return sl_noise(4, p); }

static inline double sl_pnoise1(double x, int period)
{
    return sl_pnoise(1, &x, &period);
}
static inline double sl_pnoise2(double x, double y, int px, int py)
{
    const double p[2] = { x, y };
    const int per[2] = { px, py };
    return sl_pnoise(2, p, per);
}
static inline double sl_pnoise3(const double p[3], const int period[3])
{
    return sl_pnoise(3, p, period);
}
static inline double sl_pnoise4(const double p[4], const int period[4])
{
    return sl_pnoise(4, p, period);
}

static inline double sl_cellnoise1(double x) { return sl_cellnoise(1, &x); }
static inline double sl_cellnoise2(double x, double y)
{
    const double p[2] = { x, y };
    return sl_cellnoise(2, p);
}
static inline double sl_cellnoise3(const double p[3]) { return sl_cellnoise(3, p); }
static inline double sl_cellnoise4(const double p[4]) { return sl_cellnoise(4, p); }

static inline double sl_noise3_grad(const double p[3], double grad[3])
{
    return sl_noise_grad(3, p, NULL, grad);
}

static inline ia_interval sl_noise1_ia(ia_interval x) { return sl_noise_ia(1, &x); }
static inline ia_interval sl_noise2_ia(ia_interval x, ia_interval y)
{
    const ia_interval p[2] = { x, y };
    return sl_noise_ia(2, p);
}
static inline ia_interval sl_noise3_ia(const ia_interval p[3]) { return sl_noise_ia(3, p); }
static inline ia_interval sl_noise4_ia(const ia_interval p[4]) { return sl_noise_ia(4, p); }
static inline ia_interval sl_pnoise3_ia(const ia_interval p[3], const int period[3])
{
    return sl_pnoise_ia(3, p, period);
}
static inline ia_interval sl_cellnoise3_ia(const ia_interval p[3])
{
    return sl_cellnoise_ia(3, p);
}

static inline void sl_noise1_aa(aa_context *ctx, aa_form *out, const aa_form *x)
{
    sl_noise_aa(ctx, out, 1, x);
}
static inline void sl_noise3_aa(aa_context *ctx, aa_form *out, const aa_form p[3])
{
    sl_noise_aa(ctx, out, 3, p);
}
static inline void sl_noise4_aa(aa_context *ctx, aa_form *out, const aa_form p[4])
{
    sl_noise_aa(ctx, out, 4, p);
}
static inline void sl_pnoise3_aa(aa_context *ctx, aa_form *out, const aa_form p[3],
                                 const int period[3])
{
    sl_pnoise_aa(ctx, out, 3, p, period);
}
static inline void sl_cellnoise3_aa(aa_context *ctx, aa_form *out, const aa_form p[3])
{
    sl_cellnoise_aa(ctx, out, 3, p);
}

#endif
