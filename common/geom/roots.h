/*
 * roots.h: real roots of small polynomials, for the exact ray intersection
 * of the undisplaced surfaces (geom_intersect): quadratics for the quadrics
 * and bilinear patches, degree <= 4 for the torus.
 *
 * Grazing rays are the hard case: a ray tangent to a surface gives a double
 * root that rounding may turn into a near-miss (negative discriminant, or a
 * quartic whose local minimum lies a hair above 0). Both solvers take a
 * tolerance on the polynomial's value that the caller derives from the
 * magnitudes of the terms of its coefficients, and report such near-touches
 * as roots, so tangent rays hit.
 */
#ifndef GEOM_ROOTS_H
#define GEOM_ROOTS_H

/* Real roots of a x^2 + b x + c, ascending; a == 0 is the linear case. A
 * discriminant b^2 - 4ac in [-tol, 0) counts as 0; one in [-tol, merge]
 * (merge >= 0) gives the double root -b/2a, twice (where c/q below would
 * divide two rounding errors; merge = 0 when the caller polishes its roots
 * anyway). Uses the cancellation-free form q = -(b + sign(b) sqrt(disc))/2,
 * roots q/a and c/q (Numerical Recipes §5.6). Non-finite roots (a tiny a)
 * are dropped. Returns the number of roots (0..2). */
int geom_quadratic(double a, double b, double c, double tol, double merge,
                   double roots[2]);

enum { GEOM_POLY_MAX_DEGREE = 4, GEOM_POLY_MAX_ROOTS = 16 };

/* Real roots in [lo, hi] of sum c[i] x^i (deg <= 4), ascending. tolc[i]
 * bounds the uncertainty of c[i]: a local extremum x whose |p(x)| <=
 * sum tolc[i] |x|^i is reported as a (touching) root. Roots are isolated by
 * the roots of the derivative (recursively), which split [lo, hi] into
 * monotone pieces; a sign change in a piece is refined by safeguarded
 * Newton-bisection. Returns the number of roots (<= GEOM_POLY_MAX_ROOTS,
 * near-duplicates possible at touching roots). */
int geom_poly_roots(const double *c, const double *tolc, int deg, double lo,
                    double hi, double *roots);

#endif
