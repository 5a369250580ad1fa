/*
 * affine_internal.h: the pieces affine.c shares with affine_funcs.c. Not a
 * public interface.
 */
#ifndef AA_AFFINE_INTERNAL_H
#define AA_AFFINE_INTERNAL_H

#include "aa/affine.h"

/* z = alpha*x + zeta +- delta: the result of a linear approximation of a
 * non-affine function (Heidrich & Seidel §4: f^a plus a new noise symbol).
 * delta must already be an upper bound on the approximation error; the
 * rounding of alpha*x + zeta is accounted for here. hull is the interval
 * enclosure of f over the operand's range, which becomes z's hull. */
void aa_apply_linear(aa_context *ctx, aa_form *z, const aa_form *x,
                     double alpha, double zeta, double delta, ia_interval hull,
                     unsigned flags);

/* aa_range(x) for r = aa_radius(x), for callers that need both. */
ia_interval aa_range_r(const aa_form *x, double r);

/* Intersects z's hull with r (another enclosure of the same values). */
void aa_meet_hull(aa_form *z, ia_interval r);

/* z = the interval r on a fresh noise symbol (min-range approximation with
 * alpha = 0), with flags; unbounded when r is. */
void aa_set_interval(aa_context *ctx, aa_form *z, ia_interval r, unsigned flags);

#endif
