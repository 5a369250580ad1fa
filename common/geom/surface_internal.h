/*
 * surface_internal.h: what the files implementing surface.h share and no one
 * else needs: the slots of geom_surface.consts, the sweep constants, and the
 * inverse of the sweep angle used by the ray intersection.
 *
 * Exact constants. The interval and affine evaluations must enclose the
 * exact real P(u,v) of the parameters as given, so a derived constant such
 * as zmax - zmin is never rounded to one double: geom_surface_prepare keeps
 * an interval enclosure of it (computed with the rounding-safe ia_* ops) in
 * s->consts[], and the evaluations multiply by that interval. Which slot holds
 * what depends on the kind:
 *
 *   sphere, torus   K_DPHI            phi1 - phi0 (sphere), phimax - phimin
 *   cylinder        K_DZ              zmax - zmin
 *   paraboloid      K_DZ, K_PK, K_PC  zmax - zmin, rmax^2/zmax, K_DZ*K_PK/2
 *   hyperboloid     K_D + 0..2        point2 - point1
 *   polygon         K_NG + 0..2       axis_u x axis_v
 *                   K_VNC, K_VNU,     with vertex normals: the interpolated
 *                   K_VNV + 0..2      normal is C + u A + v B (points)
 *   patch           K_B, K_C, K_A     P10-P00, P01-P00, P11-P10-P01+P00
 *                   K_N0, K_N1, K_N2  b x c, b x a, a x c: Ng = n0 + u n1 + v n2
 */
#ifndef GEOM_SURFACE_INTERNAL_H
#define GEOM_SURFACE_INTERNAL_H

#include "geom/surface.h"

#include <stdint.h>
#include <string.h>

enum {
    K_DPHI = 0,
    K_DZ = 0, K_PK = 1, K_PC = 2,
    K_D = 0,
    K_NG = 0, K_VNC = 3, K_VNU = 6, K_VNV = 9,
    K_B = 0, K_C = 3, K_A = 6, K_N0 = 9, K_N1 = 12, K_N2 = 15,
};

#define GEOM_TWO_PI 6.283185307179586     /* 2*M_PI, the double below 2 pi */

/* A sweep angle may exceed 2 pi by this much (degrees converted to radians
 * by the scene parser round); the surface is then the full revolution. */
#define GEOM_SWEEP_SLACK 1e-9

/* The phi range of a sphere or torus: [*a, *b]. */
static inline void geom_phi_range(const geom_surface *s, double *a, double *b)
{
    if (s->kind == GEOM_SPHERE) {
        *a = s->phi0;
        *b = s->phi1;
    } else {
        *a = s->phimin;
        *b = s->phimax;
    }
}

/* The parameter t in [0,1] with angle == t*sweep (mod 2 pi), sweep != 0 of
 * either sign; false when the angle lies in the cut-away part. Angles within
 * tol radians of either end count as that end. */
bool geom_sweep_param(double angle, double sweep, double tol, double *t);

/* fmin and fmax without the call (libm's are calls through the PLT: ~7 %
 * of the instructions of parsing a mesh). The same number as glibc's on
 * x86_64 for every input, signed zeros included: its fmin is `minsd`,
 * which returns the second operand unless the first is less (so
 * fmin(-0.0, 0.0) is 0.0 and fmin(0.0, -0.0) is -0.0, as here), and a
 * quiet NaN operand gives the other one (a signalling NaN, which no
 * arithmetic makes, gives a NaN there). tests/geom/test_geom_minmax.c compares the
 * bits with libm's over zeros, infinities, NaN and random numbers. */
static inline double geom_min(double x, double y)
{
    return x < y || y != y ? x : y;
}

static inline double geom_max(double x, double y)
{
    return x > y || y != y ? x : y;
}

/* An enclosure of the product of two numbers in one multiplication, when
 * it is finite and not zero (false otherwise: the caller takes its general
 * operation). Then ia_mul(ia_point(a), ia_point(b)) and
 * ia_mul_s(ia_point(a), b) are both [fp_mul_dn(a, b), fp_mul_up(a, b)]:
 * the rounded product stepped one double down and one up (rounding.h),
 * which is what this makes, the same bits, from one product instead of
 * two with their tests. */
static inline bool geom_point_product(double a, double b, ia_interval *out)
{
    double p = a * b;
    uint64_t bits;
    memcpy(&bits, &p, sizeof bits);
    if ((bits & 0x7fffffffffffffffull) - 1u >= 0x7fefffffffffffffull)
        return false;                   /* zero, infinite or NaN */
    uint64_t lo = bits + ((bits >> 63) ? 1u : ~(uint64_t)0);
    uint64_t hi = bits + ((bits >> 63) ? ~(uint64_t)0 : 1u);
    double l, h;
    memcpy(&l, &lo, sizeof l);
    memcpy(&h, &hi, sizeof h);
    *out = ia_make(l, h);
    return true;
}

/* The polygon part of geom_surface_prepare (surface_polygon.c). */
bool geom_polygon_prepare(geom_surface *s, char *err, size_t errsz);

/* The vertex-normal part of polygon prepare (surface_vertex_normal.c). */
bool geom_vertex_normal_prepare(geom_surface *s, char *err, size_t errsz);

/* The bicubic Bezier patch (surface_bicubic.c). */
bool geom_bicubic_prepare(geom_surface *s, char *err, size_t errsz);
void geom_bicubic_eval_dual(const geom_surface *s, double u, double v, geom_sample *out);
/* P of geom_bicubic_eval_dual alone, the same bits */
vec3 geom_bicubic_eval_point(const geom_surface *s, double u, double v);
void geom_bicubic_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);
/* o->Ng = o->dPdu x o->dPdv in affine arithmetic (surface_affine.c) */
void geom_ng_aa(aa_context *ctx, geom_aa *o);

/* Bezier nets of pieces, and affine forms from them (bezier_net.c). */
#define GEOM_NET_PAD 0x1p-40
/* The n control points (stride apart) of a curve of degree n - 1 over
 * [a, b] (in [0, 1]), in float: q[k * qstride] */
void geom_bezier_piece(const double *p, int stride, int n, double a, double b, double *q,
                       int qstride);
/* The net of one coordinate of the patch with ku x kv points p (point
 * (i, j) at p[(j ku + i) stride]) over [s0,s1] x [t0,t1], each point
 * widened by pad (GEOM_NET_PAD of the largest coordinate): q[j ld + i].
 * False unless the box lies in the unit square but for 2^-20 (the pad's
 * bound needs t in [0, 1]; that much beyond adds a factor 1 + 2^-19 a
 * level) or with a non-finite pad. */
bool geom_net_piece(const double *p, int stride, int ku, int kv, double s0, double s1,
                    double t0, double t1, double pad, ia_interval *q, int ld);
/* An affine form of the patch with net w[j * ld + i] (nu x nv points at
 * (i/(nu-1), j/(nv-1)) of the piece [s0,s1] x [t0,t1] of the inputs s, t),
 * times scale: a plane in s and t plus a new symbol for the net's largest
 * distance from it; the net's hull for the form's hull */
void geom_net_form(aa_context *ctx, aa_form *z, const ia_interval *w, int ld, int nu, int nv,
                   ia_interval scale, const aa_form *s, const aa_form *t, double s0,
                   double s1, double t0, double t1);
/* Affine forms of P, dPdu, dPdv (and Ng from them) over the box of the
 * inputs s, t from the Bezier net of the patch's piece there: a plane in
 * s and t plus one symbol for the net's distance from it (cheaper than
 * the tensor form, and tighter on boxes of a few pixels); false on
 * boxes thinner than 2^-12 (tensor form there) */
bool geom_bicubic_net_aa(aa_context *ctx, const geom_surface *b, const aa_form *s,
                         const aa_form *t, geom_aa *out);
/* The ranges of geom_bicubic_net_aa's P over the same box, the same bits,
 * without the forms (the nets of P alone, no plane, no derivatives);
 * false where geom_bicubic_net_aa is false or P is not finite */
bool geom_bicubic_net_range_P(const geom_surface *b, const aa_form *s, const aa_form *t,
                              ia_interval P[3]);
/* The slopes of the unit normal Nn = N / |N| from bounds of N and of its
 * derivatives dN/du, dN/dv over a box: d Nn = (dN - Nn (Nn . dN)) / |N|;
 * false where |N| may vanish or a bound is not finite */
bool geom_unit_slopes_ia(const ia_interval N[3], const ia_interval dNu[3],
                         const ia_interval dNv[3], ia_interval dNdu[3], ia_interval dNdv[3]);
/* geom_eval_ia's bounds met with those of the piece of the patch over
 * the box, a Bezier net of its own (tighter on wide boxes, where the
 * tensor form loses the basis functions' correlation, and dearer) */
void geom_bicubic_tighten_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);
/* Bounds of d/du, d/dv of the unit normal Ng/|Ng| over the box; false
 * where |Ng| may vanish there */
bool geom_bicubic_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                   ia_interval dNdu[3], ia_interval dNdv[3]);
void geom_bicubic_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                          const aa_form *v, geom_aa *out);
void geom_bicubic_bounds(const geom_surface *s, vec3 *lo, vec3 *hi);
bool geom_bicubic_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                            geom_hit *hit);

/* Catmull-Clark faces (subdiv_eval.c). */
void geom_subdiv_eval_dual(const geom_surface *s, double u, double v, geom_sample *out);
vec3 geom_subdiv_eval_point(const geom_surface *s, double u, double v);
void geom_subdiv_range_P_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                            const aa_form *v, ia_interval P[3]);
void geom_subdiv_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);
void geom_subdiv_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                         const aa_form *v, geom_aa *out);
void geom_subdiv_bounds(const geom_surface *s, vec3 *lo, vec3 *hi);
bool geom_subdiv_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                           geom_hit *hit);

/* NuPatch pieces (nurbs_eval.c). */
bool geom_nurbs_prepare(geom_surface *s, char *err, size_t errsz);
void geom_nurbs_eval_dual(const geom_surface *s, double u, double v, geom_sample *out);

/* A surface's point with its first derivatives at (u, v) (the dual
 * evaluations above), and Newton's method for a ray's hit on such a
 * patch, shared by the bicubic and NuPatch intersections
 * (surface_intersect.c). */
typedef void (*geom_dual_eval_fn)(const geom_surface *s, double u, double v, geom_sample *out);
bool geom_patch_newton(const geom_surface *s, geom_dual_eval_fn eval, vec3 o, vec3 d,
                       double *t, double *u, double *v, double scale);
/* A patch's ray intersection by subdivision (surface_intersect.c), shared
 * by bicubic patches and NuPatch pieces, which differ in their nets only:
 * the walk keeps each sub-patch's (u,v) square on a stack of
 * GEOM_PATCH_STACK slots, the patch keeps the net of slot k. clip gives
 * the ray's t range [*t0, *t1] within [tmin, best] over slot k's net
 * (false: the ray misses it); transversal says whether Ng.d keeps one sign
 * over it; split writes its four quarters into slots k..k+3 (quarter i at
 * slot k+i, or at k+3-i with quarter0_on_top). */
enum { GEOM_PATCH_STACK = 3 * 16 + 8 };
typedef struct geom_patch_walk {
    const geom_surface *s;
    geom_dual_eval_fn eval;
    double scale;                 /* geom_patch_newton's */
    bool (*clip)(void *user, int k, double tmin, double best, double *t0, double *t1);
    bool (*transversal)(void *user, int k);
    void (*split)(void *user, int k);
    bool quarter0_on_top;
    void *user;
} geom_patch_walk;
bool geom_patch_intersect(const geom_patch_walk *w, vec3 o, vec3 d, double tmin, double tmax,
                          geom_hit *hit);
void geom_nurbs_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);
void geom_nurbs_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                        const aa_form *v, geom_aa *out);
void geom_nurbs_bounds(const geom_surface *s, vec3 *lo, vec3 *hi);
/* A bilinear patch's general solve alone, without geom_intersect's slab
 * rejection (surface_intersect.c, patch_slab_misses): the oracle that
 * test_geom_same_bits holds the short path to. */
bool geom_patch_solve(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                      geom_hit *hit);
bool geom_nurbs_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                          geom_hit *hit);

#endif
