/*
 * noise_internal.h: what noise.c (the function in float mode) and
 * noise_bound.c (its proven bounds over boxes: interval and affine modes)
 * share: the lattice hashing, the gradient sets, the fade, the scales,
 * the global derivative bounds and the float jet at a point (value,
 * gradient, Hessian by nested interpolations: noise.c's gradient, the
 * start of noise_bound.c's bounds). Private to the noise; its interface is
 * noise.h. The functions are static inline: the jets and the float
 * evaluation both unroll them per dimension.
 */
#ifndef SL_NOISE_INTERNAL_H
#define SL_NOISE_INTERNAL_H

#include "sl/noise.h"

#include <stdbool.h>
#include <stdint.h>

/* the scales K_D of raw noise (K_D * B_D <= 1/2, B_D the proven bounds
 * of |raw|: raw_bound in noise.c) */
static const double noise_scale[SL_NOISE_MAX_DIM + 1] = {
    0.0, 0.125, 0.5,
    0x1.ee048b82b793bp-2,       /* 0.5/1.0364, rounded down */
    0x1.4d1dd05d45c9bp-2,       /* 0.5/1.537, rounded down */
};

/*
 * Global bounds of the first, second and third partial derivatives of raw
 * noise (every dimension, every hash), for merging slivers (enclose).
 * With S(0) = 1, S(j) = 2 max|d^j s/dt^j| (S(1) = 3.75, S(2) = 20/sqrt 3 <
 * 11.548, S(3) = 120, the third derivative being 60(6t^2 - 6t + 1)),
 * G1 = max sum_k |g_k| (8, 2, 2, 3 for 1D-4D) and gm = max |g_k| (8, 1, 1,
 * 1), the product rule on raw = sum_c W_c l_c (l_c linear; the sum over
 * corners of |d^alpha W_c| is prod_k S(alpha_k)) gives
 *   |d^alpha raw| <= G1 prod_k S(alpha_k)
 *                    + sum_j alpha_j gm S(alpha_j - 1) prod_{k != j} S(alpha_k).
 * The largest over |alpha| = 1, 2, 3 are 1D's: 38, 152.4 and 1237.2.
 */
#define NOISE_D1_BOUND 40.0
#define NOISE_D2_BOUND 160.0
#define NOISE_D3_BOUND 1300.0

/* Hash channels: the scalar noise, three vector channels, and cellnoise. */
enum {
    CH_NOISE = 0,
    CH_VNOISE = 1,        /* 1, 2, 3 */
    CH_CELL = 4,
    CH_VCELL = 5,         /* 5, 6, 7 */
};

/* ---------------------------------------------------------------------- */
/* lattice hashing                                                         */
/* ---------------------------------------------------------------------- */

static inline uint32_t mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

static inline uint32_t channel_seed(unsigned channel)
{
    return mix32(0x6a09e667u ^ (0x9e3779b9u * (channel + 1u)));
}

/* floor(x) as an integer; 0 for NaN, infinities and |x| >= 2^62. */
static inline int64_t lat_floor(double x)
{
    if (!(x > -0x1p62 && x < 0x1p62))
        return 0;
    int64_t i = (int64_t)x;              /* toward zero, exact here */
    if ((double)i > x)
        i--;
    return i;
}

/* The hash key of lattice coordinate i on axis k: wrapped by the period,
 * else taken modulo 2^32. */
static inline uint32_t lat_key(int64_t i, const int *period, int k)
{
    if (period != NULL && period[k] >= 1) {
        int64_t p = period[k];
        int64_t m = i % p;
        if (m < 0)
            m += p;
        return (uint32_t)m;
    }
    return (uint32_t)(uint64_t)i;
}

/* Hashes of the 2^dim corners: corner c (bit k = axis k) uses key[k][c_k].
 * Axes are mixed from the last to the first, sharing prefixes. */
static inline void corner_hashes(int dim, uint32_t seed, const uint32_t key[][2],
                          uint32_t h[16])
{
    int n = 1;
    h[0] = seed;
    for (int k = dim - 1; k >= 0; k--) {
        for (int j = n - 1; j >= 0; j--) {
            uint32_t e = h[j];
            h[2 * j + 1] = mix32(e ^ key[k][1]);
            h[2 * j] = mix32(e ^ key[k][0]);
        }
        n *= 2;
    }
}

static const signed char grad2[8][2] = {
    { 1, 1 }, { -1, 1 }, { 1, -1 }, { -1, -1 },
    { 1, 0 }, { -1, 0 }, { 0, 1 }, { 0, -1 },
};

static const signed char grad3[12][3] = {
    { 1, 1, 0 }, { -1, 1, 0 }, { 1, -1, 0 }, { -1, -1, 0 },
    { 1, 0, 1 }, { -1, 0, 1 }, { 1, 0, -1 }, { -1, 0, -1 },
    { 0, 1, 1 }, { 0, -1, 1 }, { 0, 1, -1 }, { 0, -1, -1 },
};

/* 4D: three components +-1 and one 0; index h & 31: bits 3-4 the zero
 * axis, bits 0-2 the signs of the other three in order */
static const signed char grad4[32][4] = {
    {  0,  1,  1,  1 }, {  0, -1,  1,  1 }, {  0,  1, -1,  1 }, {  0, -1, -1,  1 },
    {  0,  1,  1, -1 }, {  0, -1,  1, -1 }, {  0,  1, -1, -1 }, {  0, -1, -1, -1 },
    {  1,  0,  1,  1 }, { -1,  0,  1,  1 }, {  1,  0, -1,  1 }, { -1,  0, -1,  1 },
    {  1,  0,  1, -1 }, { -1,  0,  1, -1 }, {  1,  0, -1, -1 }, { -1,  0, -1, -1 },
    {  1,  1,  0,  1 }, { -1,  1,  0,  1 }, {  1, -1,  0,  1 }, { -1, -1,  0,  1 },
    {  1,  1,  0, -1 }, { -1,  1,  0, -1 }, {  1, -1,  0, -1 }, { -1, -1,  0, -1 },
    {  1,  1,  1,  0 }, { -1,  1,  1,  0 }, {  1, -1,  1,  0 }, { -1, -1,  1,  0 },
    {  1,  1, -1,  0 }, { -1,  1, -1,  0 }, {  1, -1, -1,  0 }, { -1, -1, -1,  0 },
};

/* 1D: 1 + (h & 7), negated when bit 3 is set */
static inline int grad1(uint32_t h)
{
    int g = 1 + (int)(h & 7u);
    return (h & 8u) ? -g : g;
}

/* 3D: one of twelve, h scaled to [0, 12) by a multiply-high (unbiased to
 * within 2^-32) */
static inline const signed char *grad3_of(uint32_t h)
{
    return grad3[((uint64_t)h * 12u) >> 32];
}

/* The gradient of hash h (integer components). */
static inline void gradient(int dim, uint32_t h, int g[4])
{
    switch (dim) {
    case 1:
        g[0] = grad1(h);
        break;
    case 2:
        g[0] = grad2[h & 7u][0];
        g[1] = grad2[h & 7u][1];
        break;
    case 3: {
        const signed char *t = grad3_of(h);
        g[0] = t[0];
        g[1] = t[1];
        g[2] = t[2];
        break;
    }
    default: {
        const signed char *t = grad4[h & 31u];
        g[0] = t[0];
        g[1] = t[1];
        g[2] = t[2];
        g[3] = t[3];
        break;
    }
    }
}

/* ---------------------------------------------------------------------- */
/* the fade, and the point's cell                                          */
/* ---------------------------------------------------------------------- */

static inline double fade(double t)
{
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

static inline double dfade(double t)
{
    double q = t * (1.0 - t);
    return 30.0 * q * q;
}

static inline bool dim_ok(int dim) { return dim >= 1 && dim <= SL_NOISE_MAX_DIM; }

/* Fractional parts and corner hashes of point p. */
static inline void lattice_at(int dim, const double *p, const int *period,
                       uint32_t seed, double f[4], uint32_t h[16])
{
    uint32_t key[4][2];
    for (int k = 0; k < dim; k++) {
        int64_t i = lat_floor(p[k]);
        f[k] = (p[k] > -0x1p62 && p[k] < 0x1p62) ? p[k] - (double)i : 0.0;
        key[k][0] = lat_key(i, period, k);
        key[k][1] = lat_key(i + 1, period, k);
    }
    corner_hashes(dim, seed, key, h);
}

static inline double scaled(int dim, double raw)
{
    double v = 0.5 + noise_scale[dim] * raw;
    return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

/* the value of a cell of cellnoise, in [0, 1 - 2^-24] */
static inline double cell_value(int dim, const int64_t *cell, uint32_t seed)
{
    uint32_t h = seed;
    for (int k = dim - 1; k >= 0; k--)
        h = mix32(h ^ lat_key(cell[k], NULL, k));
    return (double)(h >> 8) * 0x1p-24;
}

/* ---------------------------------------------------------------------- */
/* the float jet at a point                                                */
/* ---------------------------------------------------------------------- */

/* Value, gradient and Hessian of raw noise at a point, in plain double
 * arithmetic by nested linear interpolations (noise_bound.c derives the
 * a-priori bound of its error, point_jet_err, and starts every bound over
 * a box from it; noise.c's float gradient is its order 1) */
typedef struct point_jet {
    double v, g[4], h[4][4];     /* h[j][k], j <= k used */
} point_jet;

/* s''(t) = 60 t (1 - t)(1 - 2t), as noise_bound.c's error bound assumes */
static inline double ddfade(double t)
{
    double q = t * (1.0 - t);
    return (60.0 * q) * (1.0 - 2.0 * t);
}

/* The weights of the float jets' interpolation steps along each axis at
 * cell coordinates f: w0 = 1 - s, w1 = s, D = s', DD = s'', and the
 * offsets d = f, f - 1 of the corners' linear functions */
static inline __attribute__((always_inline)) void
jet_weights(int dim, const double f[4], double w0[4], double w1[4], double D[4], double DD[4],
            double d[4][2])
{
    for (int k = 0; k < dim; k++) {
        double s = fade(f[k]);
        w1[k] = s;
        w0[k] = 1.0 - s;
        D[k] = dfade(f[k]);
        DD[k] = ddfade(f[k]);
        d[k][0] = f[k];
        d[k][1] = f[k] - 1.0;
    }
}

/* The jet to `order` (0: the value; 1: and the gradient; 2: and the
 * Hessian, whose parts j <= k J holds; the parts an order leaves out are
 * not written); always inlined once per dim, so the loops unroll. With
 * raw not NULL, also raw noise as noise.c's raw_value computes it, bit
 * for bit (its interpolations a + s (b - a) beside the jet's w0 a + w1 b,
 * on the same corner values and the same s: issue 24, session 29, the
 * float gradient's second pass over the corners gone) */
static inline __attribute__((always_inline)) void
point_jet_d(int dim, const double f[4], const uint32_t hs[16], int order, point_jet *J,
            double *raw)
{
    double w0[4], w1[4], D[4], DD[4], d[4][2];
    jet_weights(dim, f, w0, w1, D, DD, d);
    point_jet t[16];
    double rv[16];
    int n = 1 << dim;
    for (int c = 0; c < n; c++) {
        int g[4];
        gradient(dim, hs[c], g);
        double l = (double)g[0] * d[0][c & 1];
        for (int k = 1; k < dim; k++)
            l = l + (double)g[k] * d[k][(c >> k) & 1];
        t[c].v = l;
        if (raw)
            rv[c] = l;
        if (order == 0)
            continue;
        /* the corners' Hessians (0) are never read: the step along axis 0
         * sets the Hessian parts without them */
        for (int k = 0; k < dim; k++)
            t[c].g[k] = (double)g[k];
    }
    /* Each step writes its results straight into the other buffer (no
     * temporary jet copied back: the compiler copied its scalar stores with
     * 16-byte loads, a store-forwarding stall that took a fifth of
     * point_jet_at), and the loops have constant trip counts once dim is
     * (so they unroll). The operations and their order are unchanged. */
    point_jet u[8];
    point_jet *src = t, *dst = u;
#pragma GCC unroll 4
    for (int k = 0; k < dim; k++) {
        const int nk = (1 << dim) >> (k + 1);
        if (k == dim - 1)
            dst = J;        /* the last step writes the result (no copy) */
#pragma GCC unroll 8
        for (int i = 0; i < nk; i++) {
            const point_jet *A = &src[2 * i], *B = &src[2 * i + 1];
            point_jet *R = &dst[i];
            if (raw)                     /* in place: i < 2i for i > 0 */
                rv[i] = rv[2 * i] + w1[k] * (rv[2 * i + 1] - rv[2 * i]);
            double dv = B->v - A->v;
            R->v = w0[k] * A->v + w1[k] * B->v;
            if (order == 0)
                continue;
            for (int j = 0; j < dim; j++)
                R->g[j] = w0[k] * A->g[j] + w1[k] * B->g[j];
            R->g[k] = R->g[k] + D[k] * dv;
            if (order == 1)
                continue;            /* value and gradient only: no Hessian */
            for (int j = 0; j < dim; j++)
                for (int m = j; m < dim; m++)
                    R->h[j][m] = k == 0 ? 0.0 : w0[k] * A->h[j][m] + w1[k] * B->h[j][m];
            double dgk = B->g[k] - A->g[k];
            R->h[k][k] = R->h[k][k] + (2.0 * (D[k] * dgk) + DD[k] * dv);
            for (int j = 0; j < dim; j++) {
                if (j == k)
                    continue;
                double tjk = D[k] * (B->g[j] - A->g[j]);
                if (j < k) R->h[j][k] = R->h[j][k] + tjk;
                else R->h[k][j] = R->h[k][j] + tjk;
            }
        }
        point_jet *x = src;
        src = dst;
        dst = x;
    }
    if (raw)
        *raw = rv[0];
}


#endif
