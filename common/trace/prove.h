/*
 * prove.h: proven hits. Before a quadtree cell of a displaced surface is
 * subdivided down to pixel-sized leaves, the Krawczyk test (interval
 * Newton; Moore, Krawczyk 1969, as in Neumaier, "Interval methods for
 * systems of equations", §5) is tried on the ray's equation over the cell:
 *
 *     P(u, v) on the line o + t d,   (u, v) in the cell,
 *
 * with P the displaced surface in camera space (as two plane equations
 * G(u, v) = 0, prove.c). The test needs bounds of P's true derivatives
 * over the cell widened by a quarter on each side (trace_surface_slopes)
 * and an enclosure of P at its centre, both kept per cell; where the
 * cell's test is too coarse, Newton's iteration places the zero and a
 * second test on a small box about it, with an enclosure of P there,
 * proves it (prove.c). It answers
 *
 *   TRACE_PROOF_MISS     G has no zero there, or its one zero is off the
 *                        base surface or outside (tmin, tmax): the ray
 *                        misses the surface over this cell (exactly, not
 *                        within a tolerance)
 *   TRACE_PROOF_HIT      G has exactly one zero over the widened cell: the
 *                        ray meets the surface there once (in the cell or
 *                        just beside it: the cell holds no other), at a
 *                        point enclosed by the proof's box, where Newton's
 *                        iteration settles (the hit and its shading point)
 *   TRACE_PROOF_UNKNOWN  neither (too large a cell, a root near the cell's
 *                        border, a grazing ray, no slope bounds): the
 *                        caller subdivides as before
 *
 * Both verdicts are proofs, rounding included (midpoint-radius arithmetic
 * whose radii cover the rounding, prove.c), so a cell the test settles needs no further boxes and loses
 * no intersection: Heidrich & Seidel's guarantee (§3) is kept, and the hit
 * is the surface's own point rather than a leaf box's (issue 10, "exact
 * hit points"). A pure function of (object, cell, ray): images stay the
 * same across threads, tiles and workers.
 */
#ifndef TRACE_PROVE_H
#define TRACE_PROVE_H

#include <stdbool.h>

#include "trace/box.h"
#include "trace/displace.h"
#include "trace/thread.h"
#include "trace/world.h"

typedef enum trace_proof {
    TRACE_PROOF_UNKNOWN,
    TRACE_PROOF_MISS,
    TRACE_PROOF_HIT,
} trace_proof;

/* One Newton step for the ray against the tangent plane at a surface
 * point: solves [Pu | Pv | -d] s = -f, f = P - (o + t d), by Cramer's
 * rule for the steps of u, v and t. False when the ray runs along the
 * plane or the steps of u or v are not finite (a caller using s[2] tests
 * it itself). */
bool trace_newton_step(vec3 Pu, vec3 Pv, vec3 d, vec3 f, double s[3]);

/* Whether proofs can succeed on this object at all: a displaced object
 * (not an instance) whose N has known slopes (trace_surface_has_slopes:
 * flat ones, quadrics under a similarity). Elsewhere the slope bounds
 * would be the whole line and every try wasted. */
bool trace_prove_eligible(const trace_object *obj);

/* Whether the test would have slope bounds over the cell (kept for the
 * test, as the test's own): false where the displacement jumps, reads a
 * texture or a first derivative over it */
bool trace_prove_cell_has_slopes(trace_thread *th, const trace_object *obj, const double r[4]);

/* What an undecided test tells the walk (prove.h, intersect.c) */
typedef struct trace_proof_detail {
    /* the width of the operator's box K over the widened cell's, per
     * (u, v) axis, the larger (infinite when the test had no slopes): K
     * shrinks about as fast as the cell (its width goes as the cell's
     * squared), so a test that failed with spread s is unlikely to
     * succeed on cells more than 1/s of this one */
    double spread;
    /* G's Jacobian may be singular over the cell (its determinant's
     * bounds hold 0): the ray may run along the surface there, a fold at
     * a silhouette, where no test succeeds however small the cell; or the
     * zero lies across the base surface's edge. Finer leaves tell a hit
     * from a near miss there. */
    bool fold;
} trace_proof_detail;

/* A zero of one ray's equations on one object, proven by an earlier test
 * of the same walk: a (u, v) box holding it (set: known). Its t is at
 * least the walk's best hit, so a cell whose widened box holds it and
 * where G is one-to-one has nothing better: a miss without Newton's
 * iteration (the cells beside a proven hit, whose tests found the same
 * zero again and lost it as a tie). */
typedef struct trace_zero {
    bool set;
    double uv[2][2];
} trace_zero;

/* The test on the cell r = {u0, u1, v0, v1} for the camera-space ray;
 * (tmin, tmax) is the range a hit must lie in (a zero whose t is proven
 * to within rounding of tmax, a tie with the hit found so far, counts as
 * outside it); *zero a zero known from this walk, if set, and on
 * TRACE_PROOF_HIT the new one's box. On TRACE_PROOF_HIT: *t, and *sp, the
 * surface point at the hit (dual mode, as trace_surface_point_eval), on
 * the ray to 2^-16 of the cell or better. On TRACE_PROOF_UNKNOWN: *why. */
trace_proof trace_prove_hit(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                            const double r[4], double tmin, double tmax, trace_zero *zero,
                            double *t, trace_surface_point *sp, trace_proof_detail *why);

#endif
