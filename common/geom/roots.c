/*
 * roots.c: real roots of quadratics and of polynomials of degree <= 4 on an
 * interval (see roots.h for the method and why touching roots matter).
 * No allocation; recursion depth is the degree.
 */
#include "geom/roots.h"

#include <float.h>
#include <math.h>
#include <stdbool.h>

int geom_quadratic(double a, double b, double c, double tol, double merge,
                   double roots[2])
{
    if (a == 0) {
        if (b == 0)
            return 0;
        roots[0] = -c / b;
        return isfinite(roots[0]) ? 1 : 0;
    }
    double disc = b * b - 4 * a * c;
    if (!(disc >= -tol))
        return 0;
    if (disc <= merge) {                /* a double root, within rounding */
        roots[0] = roots[1] = -b / (2 * a);
        return isfinite(roots[0]) ? 2 : 0;
    }
    if (disc < 0)
        disc = 0;
    double q = -0.5 * (b + copysign(sqrt(disc), b));
    double x1 = q / a, x2 = c / q;
    int n = 0;
    if (isfinite(x1))
        roots[n++] = x1;
    if (isfinite(x2))
        roots[n++] = x2;
    if (n == 2 && roots[0] > roots[1]) {
        double t = roots[0];
        roots[0] = roots[1];
        roots[1] = t;
    }
    return n;
}

/* ---------------------------------------------------------------------- */
/* polynomials                                                             */
/* ---------------------------------------------------------------------- */

static double horner(const double *c, int deg, double x)
{
    double p = c[deg];
    for (int i = deg - 1; i >= 0; i--)
        p = p * x + c[i];
    return p;
}

/* value and derivative together */
static double horner_d(const double *c, int deg, double x, double *dp)
{
    double p = c[deg], d = 0;
    for (int i = deg - 1; i >= 0; i--) {
        d = d * x + p;
        p = p * x + c[i];
    }
    *dp = d;
    return p;
}

static double touch_bound(const double *tolc, int deg, double x)
{
    double ax = fabs(x), t = 0;
    for (int i = deg; i >= 0; i--)
        t = t * ax + tolc[i];
    return t;
}

/* The root in (a, b) of a polynomial monotone there with p(a), p(b) of
 * opposite signs: Newton steps while they stay inside the bracket and
 * shrink it fast, bisection otherwise. */
static double refine(const double *c, int deg, double a, double b, double fa)
{
    double x = 0.5 * (a + b), prev = b - a;
    for (int it = 0; it < 200; it++) {
        double d, f = horner_d(c, deg, x, &d);
        if (f == 0)
            return x;
        if ((f < 0) == (fa < 0))
            a = x;
        else
            b = x;
        double width = b - a;
        if (width <= 4 * DBL_EPSILON * fmax(fabs(a), fabs(b)) || width <= DBL_MIN)
            break;
        double xn = d != 0 ? x - f / d : a - 1;
        if (xn > a && xn < b && fabs(xn - x) < 0.5 * prev) {
            prev = fabs(xn - x);
            if (xn == x)
                return x;
            x = xn;
        } else {
            prev = width;
            x = 0.5 * (a + b);
            if (x <= a || x >= b)
                break;
        }
    }
    return 0.5 * (a + b);
}

static int add_root(double *roots, int n, double x)
{
    if (n >= GEOM_POLY_MAX_ROOTS)
        return n;
    for (int i = 0; i < n; i++)
        if (roots[i] == x)
            return n;
    roots[n] = x;
    return n + 1;
}

static void sort(double *x, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && x[j - 1] > x[j]; j--) {
            double t = x[j];
            x[j] = x[j - 1];
            x[j - 1] = t;
        }
}

int geom_poly_roots(const double *c, const double *tolc, int deg, double lo,
                    double hi, double *roots)
{
    while (deg > 0 && c[deg] == 0)
        deg--;
    if (deg <= 0 || !(lo <= hi))
        return 0;
    if (deg == 1) {
        double x = -c[0] / c[1];
        if (x >= lo && x <= hi)
            roots[0] = x;
        return x >= lo && x <= hi ? 1 : 0;
    }
    double dc[GEOM_POLY_MAX_DEGREE], dt[GEOM_POLY_MAX_DEGREE];
    for (int i = 0; i < deg; i++) {
        dc[i] = (i + 1) * c[i + 1];
        dt[i] = (i + 1) * tolc[i + 1];
    }
    double crit[GEOM_POLY_MAX_ROOTS];
    int nc = geom_poly_roots(dc, dt, deg - 1, lo, hi, crit);

    /* monotone pieces between lo, the critical points, hi */
    double edge[GEOM_POLY_MAX_ROOTS + 2];
    int ne = 0;
    edge[ne++] = lo;
    for (int i = 0; i < nc; i++)
        if (crit[i] > edge[ne - 1] && crit[i] < hi)
            edge[ne++] = crit[i];
    edge[ne++] = hi;

    int n = 0;
    double fa = horner(c, deg, edge[0]);
    for (int i = 0; i + 1 < ne; i++) {
        double a = edge[i], b = edge[i + 1], fb = horner(c, deg, b);
        if (fa == 0)
            n = add_root(roots, n, a);
        else if (fb != 0 && (fa < 0) != (fb < 0))
            n = add_root(roots, n, refine(c, deg, a, b, fa));
        fa = fb;
    }
    if (fa == 0)
        n = add_root(roots, n, hi);
    for (int i = 1; i + 1 < ne; i++)        /* touching roots */
        if (fabs(horner(c, deg, edge[i])) <= touch_bound(tolc, deg, edge[i]))
            n = add_root(roots, n, edge[i]);
    sort(roots, n);
    return n;
}
