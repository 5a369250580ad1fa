/*
 * noise.c: noise, pnoise, cellnoise and their vector variants in float,
 * interval and affine modes (the interface and its promises: noise.h; the
 * derivations in full: docs/noise.md).
 *
 * Sources:
 *   K. Perlin, "Improving Noise", SIGGRAPH 2002: the quintic fade
 *     s(t) = 6t^5 - 15t^4 + 10t^3 and the gradient scheme (gradients from a
 *     small fixed set chosen by a hash of the lattice point; the 3D set is
 *     Perlin's twelve cube-edge directions).
 *   W. Heidrich, H.-P. Seidel, "Ray-tracing Procedural Displacement
 *     Shaders", GI 1998, §4: a non-affine function in affine arithmetic is
 *     its affine approximation plus a new noise symbol for its error.
 *   The hash's mixing step is the 32-bit finaliser of MurmurHash3
 *   (A. Appleby, public domain): xor-shift/multiply constants only.
 *
 * ---- the function ----------------------------------------------------
 * With i = floor(x) and f = x - i in [0, 1]^D, the raw noise is
 *
 *     raw(x) = sum over corners c in {0,1}^D of W_c(f) * (g_c . (f - c)),
 *     W_c(f) = prod_k w_{c_k}(f_k),  w_1 = s, w_0 = 1 - s,
 *
 * g_c the gradient hashed from lattice point i + c. Gradient sets:
 *   1D: g in {+-1, ..., +-8}                          (16)
 *   2D: (+-1,+-1), (+-1,0), (0,+-1)                   (8)
 *   3D: permutations of (+-1,+-1,0), Perlin 2002       (12)
 *   4D: three components +-1 and one 0                 (32)
 * Every set is symmetric under sign changes and permutations of the axes,
 * and max over the set of g . d is gmax * (sum of the m largest |d_k|),
 * with (gmax, m) = (8,1), (1,2), (1,2), (1,3).
 *
 * ---- the global bound (docs/noise.md, "The global bound") --------------
 * Since W_c >= 0 and sum_c W_c = 1:
 *     |raw(x)| <= Phi(f) := sum_c W_c(f) * gmax * top_m(|f - c|).
 * (Phi is also the supremum over all gradient assignments, so no bound
 * valid for every hash can be smaller.) Phi is invariant under f_k -> 1-f_k
 * (w_0(1-t) = w_1(t), |1-t-c| = |t-(1-c)|) and under permutations of the
 * axes, so its maximum is taken on S = {0 <= f_1 <= ... <= f_D <= 1/2}.
 *   1D: Phi = 8 phi(f) with phi(t) = (1-s(t)) t + s(t)(1-t). On [0, 1/2],
 *       phi(t) - 1/2 = (1-2t)(s(t) - 1/2) <= 0 because s is increasing and
 *       s(1/2) = 1/2. So B_1 = 4 (reached at f = 1/2).
 *   2D: top_2 is the sum of both: Phi = phi(f_1) + phi(f_2) <= 1, B_2 = 1.
 *   3D, 4D: on S the set of the m largest |f_k - c_k| is the same for every
 *       point (the components with c_k = 1 are >= 1/2 >= those with
 *       c_k = 0, and each group is ordered by k), so Phi is a polynomial P
 *       on S. A branch-and-bound over S with interval arithmetic and the
 *       mean-value form (tests/sl/test_sl_noise.c, run on every test run)
 *       proves P <= 1.0364 (3D) and P <= 1.537 (4D); the largest values
 *       it meets are 1.0363524 and 1.5365770 (a local search finds the
 *       maxima 1.03635381 and 1.53658233), so the bounds are within 0.03%
 *       of the supremum over all hashes.
 * The scale K_D is a double with K_D * B_D <= 1/2 exactly (checked by the
 * test with directed rounding), so the real function 0.5 + K_D * raw lies
 * in [0, 1]; the float result is clamped to [0, 1] against its own
 * rounding.
 *
 * The bounds over a box (interval and affine modes) are in noise_bound.c;
 * the lattice, gradients and fade both files use in noise_internal.h.
 */
#include "sl/noise.h"
#include "sl/noise_internal.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* the proven bounds B_D of |raw| (the scales K_D, K_D * B_D <= 1/2: noise_internal.h) */
static const double raw_bound[SL_NOISE_MAX_DIM + 1] = {
    0.0, 4.0, 1.0, 1.0364, 1.537
};

/* ---------------------------------------------------------------------- */
/* float mode                                                              */
/* ---------------------------------------------------------------------- */

/* raw noise by nested linear interpolation of the corner dot products
 * g_c . (f - c), one loop per dimension so that the loops have constant
 * bounds */
static double raw_value(int dim, const double f[4], const uint32_t h[16])
{
    double v[16], d[4][2];
    for (int k = 0; k < dim; k++) {
        d[k][0] = f[k];
        d[k][1] = f[k] - 1.0;
    }
    switch (dim) {
    case 1:
        for (int c = 0; c < 2; c++)
            v[c] = (double)grad1(h[c]) * d[0][c];
        break;
    case 2:
        for (int c = 0; c < 4; c++) {
            const signed char *g = grad2[h[c] & 7u];
            v[c] = g[0] * d[0][c & 1] + g[1] * d[1][(c >> 1) & 1];
        }
        break;
    case 3:
        for (int c = 0; c < 8; c++) {
            const signed char *g = grad3_of(h[c]);
            v[c] = g[0] * d[0][c & 1] + g[1] * d[1][(c >> 1) & 1] +
                   g[2] * d[2][(c >> 2) & 1];
        }
        break;
    default:
        for (int c = 0; c < 16; c++) {
            const signed char *g = grad4[h[c] & 31u];
            v[c] = g[0] * d[0][c & 1] + g[1] * d[1][(c >> 1) & 1] +
                   g[2] * d[2][(c >> 2) & 1] + g[3] * d[3][(c >> 3) & 1];
        }
        break;
    }
    int n = 1 << dim;
    for (int k = 0; k < dim; k++) {
        double s = fade(f[k]);
        n >>= 1;
        for (int j = 0; j < n; j++)
            v[j] = v[2 * j] + s * (v[2 * j + 1] - v[2 * j]);
    }
    return v[0];
}

static inline double noise_float_d(int dim, const double *p, const int *period,
                                   uint32_t seed)
{
    double f[4];
    uint32_t h[16];
    lattice_at(dim, p, period, seed, f, h);
    return scaled(dim, raw_value(dim, f, h));
}

/* dispatched on a constant dim, so that the loops above unroll */
static double noise_float(int dim, const double *p, const int *period,
                          unsigned channel)
{
    uint32_t seed = channel_seed(channel);
    switch (dim) {
    case 1: return noise_float_d(1, p, period, seed);
    case 2: return noise_float_d(2, p, period, seed);
    case 3: return noise_float_d(3, p, period, seed);
    case 4: return noise_float_d(4, p, period, seed);
    default: return 0.5;
    }
}

double sl_noise(int dim, const double *p)
{
    return noise_float(dim, p, NULL, CH_NOISE);
}

double sl_pnoise(int dim, const double *p, const int *period)
{
    return noise_float(dim, p, period, CH_NOISE);
}

void sl_vnoise(int dim, const double *p, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = noise_float(dim, p, NULL, CH_VNOISE + (unsigned)i);
}

void sl_vpnoise(int dim, const double *p, const int *period, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = noise_float(dim, p, period, CH_VNOISE + (unsigned)i);
}

/* The value and gradient of noise at p; always inlined once per dim (the
 * dispatch below) so that the loops unroll. The value is sl_noise's, bit
 * for bit (raw_value's interpolations, taken beside the jet's); the
 * gradient is the float jet's to order 1 (noise_internal.h: the nested
 * interpolations, 2^dim - 1 steps; issue 24, session 26: with the product
 * of weights per corner and per component before, a 3D call took 2,320
 * instructions, then 1,490 with raw_value's own pass over the corners) */
static inline __attribute__((always_inline)) double
noise_grad_d(int dim, const double *p, const int *period, double *grad)
{
    double f[4];
    uint32_t h[16];
    lattice_at(dim, p, period, channel_seed(CH_NOISE), f, h);
    point_jet J;
    double raw;
    point_jet_d(dim, f, h, 1, &J, &raw);
    for (int k = 0; k < dim; k++)
        grad[k] = J.g[k] * noise_scale[dim];
    return scaled(dim, raw);
}

double sl_noise_grad(int dim, const double *p, const int *period, double *grad)
{
    switch (dim) {
    case 1: return noise_grad_d(1, p, period, grad);
    case 2: return noise_grad_d(2, p, period, grad);
    case 3: return noise_grad_d(3, p, period, grad);
    case 4: return noise_grad_d(4, p, period, grad);
    default: return 0.5;
    }
}

/* ---- cellnoise ---- */

static double cellnoise_float(int dim, const double *p, unsigned channel)
{
    if (!dim_ok(dim))
        return 0.5;
    int64_t cell[4];
    for (int k = 0; k < dim; k++)
        cell[k] = lat_floor(p[k]);
    return cell_value(dim, cell, channel_seed(channel));
}

double sl_cellnoise(int dim, const double *p)
{
    return cellnoise_float(dim, p, CH_CELL);
}

void sl_vcellnoise(int dim, const double *p, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = cellnoise_float(dim, p, CH_VCELL + (unsigned)i);
}

double sl_noise_raw_bound(int dim)
{
    return dim_ok(dim) ? raw_bound[dim] : 0.0;
}

double sl_noise_raw_derivative_bound(int order)
{
    return order == 1 ? NOISE_D1_BOUND : order == 2 ? NOISE_D2_BOUND : NOISE_D3_BOUND;
}

double sl_noise_scale(int dim)
{
    return dim_ok(dim) ? noise_scale[dim] : 0.0;
}
