/*
 * prove.h: proven hits. Before a quadtree cell of a displaced surface is
 * subdivided down to pixel-sized leaves, the Krawczyk test (interval
 * Newton; Moore, Krawczyk 1969, as in Neumaier, "Interval methods for
 * systems of equations", §5) is tried on the ray's equation over the cell:
 *
 *     F(u, v, t) = P(u, v) - (o + t d) = 0,   (u, v) in the cell,
 *                                              t in the cell's box's t range
 *
 * with P the displaced surface in camera space. The test needs bounds of
 * P's true derivatives over the cell (trace_surface_slopes) and an
 * enclosure of P at one point, and it answers
 *
 *   TRACE_PROOF_MISS     F has no zero there: the ray misses the surface
 *                        over this cell (exactly, not within a tolerance)
 *   TRACE_PROOF_HIT      F has exactly one zero there: the ray meets the
 *                        surface over this cell once, at a point enclosed
 *                        by the proof's box, which Newton's iteration then
 *                        finds to rounding (the hit and its shading point)
 *   TRACE_PROOF_UNKNOWN  neither (too large a cell, a root near the cell's
 *                        border, a grazing ray, no slope bounds): the
 *                        caller subdivides as before
 *
 * Both verdicts are proofs, rounding included (ia_* with outward
 * rounding), so a cell the test settles needs no further boxes and loses
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

/* Whether proofs can succeed on this object at all: a displaced object
 * (not an instance) whose N has known slopes (trace_surface_has_slopes:
 * flat ones, quadrics under a similarity). Elsewhere the slope bounds
 * would be the whole line and every try wasted. */
bool trace_prove_eligible(const trace_object *obj);

/* The test on the cell r = {u0, u1, v0, v1} for the camera-space ray;
 * (tmin, tmax) is the range a hit must lie in. On TRACE_PROOF_HIT: *t,
 * and *sp, the surface point at the hit (dual mode, as
 * trace_surface_point_eval). *spread: the width of the operator's box K
 * over the cell's, per (u, v) axis, the larger (infinite when the test
 * had no slopes): K shrinks about as fast as the cell (its width goes as
 * the cell's squared), so a test that failed with spread s is unlikely
 * to succeed on cells more than 1/s of this one. */
trace_proof trace_prove_hit(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                            const double r[4], double tmin, double tmax,
                            double *t, trace_surface_point *sp, double *spread);

#endif
