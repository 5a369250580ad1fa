/*
 * nurbs.h: rational B-spline patches of any order (RI Specification 3.2
 * §5.4, NuPatch) as base surfaces of common/geom.
 *
 * A geom_nurbs is one NuPatch, shared by its pieces: every knot interval
 * pair inside [umin, umax] x [vmin, vmax] is one polynomial piece of the
 * homogeneous surface, converted to a rational tensor Bezier patch of the
 * same orders by knot insertion (the Bezier points of an interval [a, b]
 * are the blossom values f(a..a, b..b), de Boor's algorithm with one
 * argument per level: Ramshaw 1987, Boehm 1980). Each piece is one
 * geom_surface of kind GEOM_NURBS pointing at the patch (nurbs,
 * nurbs_piece), so a piece costs no copy of control points, and every
 * arithmetic evaluates the same net (nurbs_eval.c):
 *
 *     P(u,v) = H(u,v).xyz / H(u,v).w,   H = sum_ij B_i(u) B_j(v) Hw_ij
 *
 * with the Bernstein polynomials of the piece's degrees and the
 * homogeneous points Hw_ij = (w x, w y, w z, w), w > 0 (RenderMan's "Pw":
 * the Cartesian point is (x, y, z) / w). (u, v) of a piece run over the
 * unit square; the piece's knot range is geom_nurbs_piece_range.
 *
 * Since every weight is positive and the Bernstein polynomials are
 * non-negative and sum to 1, H.w over the piece lies in [min w, max w] of
 * its net (bounded away from 0, so P / w never divides by a range holding
 * 0) and P lies in the convex hull of the projected points Hw_ij.xyz /
 * Hw_ij.w: the interval and affine evaluations are met with both.
 */
#ifndef GEOM_NURBS_H
#define GEOM_NURBS_H

#include <stdbool.h>

#include "geom/surface.h"

/* The largest order (degree + 1) in each direction. */
enum { GEOM_NURBS_MAX_ORDER = 16 };
/* The most numbers the pieces' nets of one patch may hold (256 MiB). */
enum { GEOM_NURBS_MAX_NET = 1 << 25 };

/* A NuPatch as the RIB gives it. Knots nondecreasing, n >= order,
 * knot[order-1] <= min < max <= knot[n]; Pw: 4 numbers per point (w x,
 * w y, w z, w), u fastest, every w > 0 and finite. */
typedef struct geom_nurbs_desc {
    int nu, uorder;
    const double *uknot;           /* nu + uorder */
    double umin, umax;
    int nv, vorder;
    const double *vknot;           /* nv + vorder */
    double vmin, vmax;
    const double *Pw;              /* 4 * nu * nv */
} geom_nurbs_desc;

typedef struct geom_nurbs geom_nurbs;

/* Builds the pieces; NULL with a one-line reason in err (an order out of
 * range, knots or a range that do not fit, a weight <= 0, a piece whose
 * points all lie on one line, more than GEOM_NURBS_MAX_NET numbers). */
geom_nurbs *geom_nurbs_new(const geom_nurbs_desc *desc, char *err, size_t errsz);
void geom_nurbs_destroy(geom_nurbs **self_p);

/* Pieces, u intervals fastest. */
int geom_nurbs_npieces(const geom_nurbs *self);

/* A GEOM_NURBS surface for piece k (prepared). */
void geom_nurbs_surface(const geom_nurbs *self, int k, geom_surface *out);

/* The knot range [u0, u1] x [v0, v1] of piece k (its unit square's image). */
void geom_nurbs_piece_range(const geom_nurbs *self, int k, double *u0, double *u1,
                            double *v0, double *v1);

#endif
