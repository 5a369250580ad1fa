/*
 * noise_interval.h: the small inline interval kit of noise's proven bounds
 * (noise_bound.c): [lo, hi] pairs whose every operation rounds outward by
 * a relative step and never produces a subnormal (the argument below).
 * It is not common/aa's interval type: that one steps one ulp with
 * fp_next_up/fp_next_down and carries flags, and the jets' cost depends on
 * these few always-inlined instructions (docs/noise.md).
 */
#ifndef SL_NOISE_INTERVAL_H
#define SL_NOISE_INTERVAL_H

#include "aa/rounding.h"

#include <math.h>

/*
 * All quantities here are finite and small (|.| < 2^10): no overflow. Each
 * bound is the round-to-nearest result x of ONE operation (+ - *), moved
 * outward by out_dn/out_up, which always covers that operation's rounding:
 *   x normal: the exact result v is within half an ulp of x, i.e. v >=
 *     pred(x). t = RN(|x| 2^-52 + 2^-600) >= ulp(x): for |x| >= 2^-548,
 *     |x| 2^-52 is exact (a power-of-two scaling that stays normal) and
 *     >= ulp(x); below, 2^-600 alone is >= ulp(x). So x - t <= x - ulp(x)
 *     <= pred(x), and by the monotonicity of rounding RN(x - t) <=
 *     pred(x) <= v.
 *   x subnormal or zero: v >= x - 2^-1075 (the underflow of a product; a
 *     sum is exact there) and t >= 2^-600, so RN(x - t) <= x - 2^-1075.
 * A result of magnitude below 2^-500 then becomes -2^-500 (it is above
 * that, so this moves it further out). So every bound is 0 (iv_pt(0), a
 * clipped weight) or at least 2^-500 in magnitude, products of two bounds
 * are at least 2^-1000, and nothing here is subnormal: subnormal operands
 * and results cost a microcode assist of ~100 cycles on x86, which made
 * the jets 2-5x slower when the step added 2^-1074 (docs/noise.md).
 * out_up is the mirror image. The cost is one or two ulps of width, and
 * 2^-500 of absolute width near 0.
 */

typedef struct iv {
    double lo, hi;
} iv;

/* the kit's operations are a few instructions each: always inline them
 * (the jets of noise_bound.c are large enough that GCC would otherwise
 * call them) */
#define IV_INLINE static inline __attribute__((always_inline))

IV_INLINE double out_dn(double x)
{
    double t = x - (fabs(x) * 0x1p-52 + 0x1p-600);
    return fabs(t) < 0x1p-500 ? -0x1p-500 : t;
}
IV_INLINE double out_up(double x)
{
    double t = x + (fabs(x) * 0x1p-52 + 0x1p-600);
    return fabs(t) < 0x1p-500 ? 0x1p-500 : t;
}

IV_INLINE iv iv_mk(double lo, double hi)
{
    iv r = { lo, hi };
    return r;
}
IV_INLINE iv iv_pt(double x) { return iv_mk(x, x); }
IV_INLINE iv iv_add(iv a, iv b)
{
    return iv_mk(out_dn(a.lo + b.lo), out_up(a.hi + b.hi));
}
IV_INLINE iv iv_sub(iv a, iv b)
{
    return iv_mk(out_dn(a.lo - b.hi), out_up(a.hi - b.lo));
}
IV_INLINE iv iv_neg(iv a) { return iv_mk(-a.hi, -a.lo); }
IV_INLINE iv iv_mul(iv a, iv b)
{
    double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
    double lo = p1 < p2 ? p1 : p2, hi = p1 < p2 ? p2 : p1;
    double lo2 = p3 < p4 ? p3 : p4, hi2 = p3 < p4 ? p4 : p3;
    return iv_mk(out_dn(lo < lo2 ? lo : lo2), out_up(hi > hi2 ? hi : hi2));
}
/* a times [-r, r] for r >= 0: the same bits as iv_mul(a, iv_mk(-r, r))
 * (its four products are +-a.lo r and +-a.hi r, rounding is symmetric,
 * so their least is -(mag(a) r) and their greatest mag(a) r), with one
 * product */
IV_INLINE iv iv_mul_sym(iv a, double r)
{
    double l = fabs(a.lo), h = fabs(a.hi);
    double p = (l > h ? l : h) * r;
    return iv_mk(out_dn(-p), out_up(p));
}
/* a times a small integer: exact for 0, +-1, +-2, +-4, +-8 */
IV_INLINE iv iv_mul_int(iv a, int g)
{
    switch (g) {
    case 0: return iv_pt(0.0);
    case 1: return a;
    case -1: return iv_neg(a);
    case 2: case 4: case 8:
        return iv_mk(a.lo * g, a.hi * g);
    case -2: case -4: case -8:
        return iv_mk(a.hi * g, a.lo * g);
    default: {
        double x = a.lo * g, y = a.hi * g;
        if (g < 0) { double t = x; x = y; y = t; }
        return iv_mk(out_dn(x), out_up(y));
    }
    }
}
/* a times a non-negative double */
IV_INLINE iv iv_scale_pos(iv a, double k)
{
    return iv_mk(out_dn(a.lo * k), out_up(a.hi * k));
}
IV_INLINE iv iv_hull(iv a, iv b)
{
    return iv_mk(a.lo < b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi);
}
IV_INLINE double iv_mag(iv a)
{
    double l = fabs(a.lo), h = fabs(a.hi);
    return l > h ? l : h;
}
IV_INLINE double iv_mid(iv a) { return 0.5 * a.lo + 0.5 * a.hi; }
/* max |a - m| for a point m, rounded up */
static inline double iv_rad_about(iv a, double m)
{
    double r1 = fp_add_up(a.hi, -m), r2 = fp_add_up(m, -a.lo);
    double r = r1 > r2 ? r1 : r2;
    return r > 0.0 ? r : 0.0;
}

/*
 * The same kit on two-lane vectors (GCC and Clang vector extensions):
 * lane 0 the lower bound, lane 1 the upper, so one instruction does both
 * bounds' operation. Every lane computes exactly the scalar kit's IEEE
 * operations (out_dn(x) = x - m and x + (-1 * m) are the same rounded
 * sum, -1 * m being exact; the selections of iv_mul_pos are masks), so
 * the results are the same bits; the interval jets (noise_bound.c) run on
 * it where the compiler has the extensions, and on the scalar kit
 * otherwise (NOISE_IV_VECTOR 0; -DNOISE_IV_SCALAR forces it, to compare:
 * test_sl_noise_kits), through the same ivv_ names.
 */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(NOISE_IV_SCALAR)
#define NOISE_IV_VECTOR 1
typedef double ivv __attribute__((vector_size(16)));
typedef long long ivv_mask __attribute__((vector_size(16)));

IV_INLINE ivv ivv_of(iv a)
{
    ivv r = { a.lo, a.hi };
    return r;
}
IV_INLINE iv iv_of_v(ivv a) { return iv_mk(a[0], a[1]); }
IV_INLINE ivv ivv_pt(double x)
{
    ivv r = { x, x };
    return r;
}
/* (hi, lo) */
IV_INLINE ivv ivv_swap(ivv a)
{
#if defined(__clang__)
    return __builtin_shufflevector(a, a, 1, 0);
#else
    const ivv_mask idx = { 1, 0 };
    return __builtin_shuffle(a, idx);
#endif
}
IV_INLINE ivv ivv_abs(ivv a)
{
    const ivv_mask m = { 0x7fffffffffffffffLL, 0x7fffffffffffffffLL };
    return (ivv)((ivv_mask)a & m);
}
/* out_dn on lane 0, out_up on lane 1 */
IV_INLINE ivv ivv_out(ivv x)
{
    const ivv sgn = { -1.0, 1.0 }, tiny = { -0x1p-500, 0x1p-500 };
    const ivv eps = { 0x1p-52, 0x1p-52 }, floor_ = { 0x1p-600, 0x1p-600 },
              lim = { 0x1p-500, 0x1p-500 };
    ivv t = x + sgn * (ivv_abs(x) * eps + floor_);
    ivv_mask small = ivv_abs(t) < lim;
    return (ivv)(((ivv_mask)t & ~small) | ((ivv_mask)tiny & small));
}
IV_INLINE ivv ivv_add(ivv a, ivv b) { return ivv_out(a + b); }
IV_INLINE ivv ivv_sub(ivv a, ivv b) { return ivv_out(a - ivv_swap(b)); }
/* a times b for a >= 0, as iv_mul_pos */
IV_INLINE ivv ivv_mul_pos(ivv a, ivv b)
{
    const ivv zero = { 0.0, 0.0 };
    ivv_mask nonneg = b >= zero;
    ivv f = (ivv)(((ivv_mask)a & nonneg) | ((ivv_mask)ivv_swap(a) & ~nonneg));
    return ivv_out(f * b);
}
IV_INLINE ivv ivv_twice(ivv a) { return 2.0 * a; }
#else
#define NOISE_IV_VECTOR 0
/* The same names on the scalar kit, so that the jets are written once
 * (noise_bound.c's cell_jet_d) and run on either kit. */
typedef iv ivv;
IV_INLINE ivv ivv_of(iv a) { return a; }
IV_INLINE iv iv_of_v(ivv a) { return a; }
IV_INLINE ivv ivv_pt(double x) { return iv_pt(x); }
IV_INLINE ivv ivv_add(ivv a, ivv b) { return iv_add(a, b); }
IV_INLINE ivv ivv_sub(ivv a, ivv b) { return iv_sub(a, b); }
/* a times b for a >= 0 (a.lo >= 0): two products, picked by b's signs */
IV_INLINE ivv ivv_mul_pos(ivv a, ivv b)
{
    double lo = b.lo >= 0.0 ? a.lo * b.lo : a.hi * b.lo;
    double hi = b.hi >= 0.0 ? a.hi * b.hi : a.lo * b.hi;
    return iv_mk(out_dn(lo), out_up(hi));
}
IV_INLINE ivv ivv_twice(ivv a) { return iv_mk(2.0 * a.lo, 2.0 * a.hi); }
#endif

#endif
