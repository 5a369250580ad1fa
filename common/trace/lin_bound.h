/*
 * lin_bound.h: a box's linear bound (issue 24, "Lazy children",
 * docs/renderer.md): what the affine run that made a box knows beyond the
 * box, kept so that the box's children can be bounded before they are
 * evaluated.
 *
 * Over the box's (u,v) cell, with eu, ev in [-1, 1] the cell's u and v as
 * aa_input maps them (the affine run's symbols 0 and 1), coordinate k of
 * every point of the surface lies in
 *     x[k] + u[k] eu + v[k] ev +- r[k]
 * (the run's forms: centre, u and v terms, the other terms and the error
 * as the radius). Three spellings:
 *   trace_lin   floats, as the run leaves it on its box (trace_lin_set);
 *   trace_qlin  12 bytes of codes against the box it is stored with, as
 *               the box cache keeps it (trace_qlin_encode): x and r in
 *               255ths of the box's side, u and v in 127ths;
 *   trace_dlin  doubles, decoded from the codes (trace_qlin_decode).
 * Every step rounds so that what it gives holds every point that what it
 * was given held: the error of a float or a code goes into the radius,
 * rounded up.
 *
 * The restricted bound (trace_lin_restrict) of a child cell c of the cell
 * r: eu lies in [-1, 0] where c ends at or below r's centre, in [0, 1]
 * where it starts at or above (aa_input_mid gives that centre), and ev
 * alike; the ends of x + u eu + v ev -+ r over those ranges, rounded
 * outward.
 */
#ifndef TRACE_LIN_BOUND_H
#define TRACE_LIN_BOUND_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "aa/affine.h"
#include "aa/rounding.h"
#include "trace/float_round.h"

typedef struct trace_lin {
    float x[3], u[3], v[3], r[3];
} trace_lin;

typedef struct trace_qlin {
    uint8_t x[3], r[3];
    int8_t u[3], v[3];
} trace_qlin;

typedef struct trace_dlin {
    double x[3], u[3], v[3], r[3];
} trace_dlin;

/* |a - b| rounded up */
static inline double trace_abs_diff_up(double a, double b)
{
    return fmax(fp_add_up(a, -b), fp_add_up(b, -a));
}

/* Coordinate k from doubles: x, u, v to the nearest floats and r raised by
 * what that moved, |x - x'| + |u - u'| + |v - v'| (eu, ev in [-1, 1]),
 * rounded up. False where it does not fit the floats (the caller drops
 * the bound). */
static inline bool trace_lin_set(trace_lin *l, int k, double x, double u, double v, double r)
{
    float fx = (float)x, fu = (float)u, fv = (float)v;
    double e = fp_add_up(fp_add_up(trace_abs_diff_up(x, fx), trace_abs_diff_up(u, fu)),
                         fp_add_up(trace_abs_diff_up(v, fv), r));
    l->x[k] = fx;
    l->u[k] = fu;
    l->v[k] = fv;
    l->r[k] = trace_float_up(e);
    return isfinite(fx) && isfinite(fu) && isfinite(fv) && isfinite(l->r[k]);
}

/* The codes' steps on a box side of length e: 255ths (x, r), 127ths (u, v) */
static inline void trace_qlin_steps(double e, double *s, double *su)
{
    *s = e / 255.0;
    *su = e / 127.0;
}

/* The codes decoded against the box [lo, hi] they were stored with */
static inline void trace_qlin_decode(const trace_qlin *q, const double lo[3], const double hi[3],
                                     trace_dlin *d)
{
    for (int k = 0; k < 3; k++) {
        double s, su;
        trace_qlin_steps(hi[k] - lo[k], &s, &su);
        d->x[k] = lo[k] + q->x[k] * s;
        d->u[k] = q->u[k] * su;
        d->v[k] = q->v[k] * su;
        d->r[k] = q->r[k] * s;
    }
}

static inline double trace_qlin_clamp(double q, double lo, double hi)
{
    return q < lo ? lo : q > hi ? hi : q;
}

/* l as codes against the box [lo, hi] (finite, lo <= hi: the box l's
 * surface lies in). Along a side of length 0 the box itself is the bound
 * (all codes 0: x = lo). False where the radius does not fit in 255
 * steps (the bound is no narrower than the box: the caller drops it). */
static inline bool trace_qlin_encode(const trace_lin *l, const double lo[3], const double hi[3],
                                     trace_qlin *q)
{
    for (int k = 0; k < 3; k++) {
        double e = hi[k] - lo[k];
        q->x[k] = q->r[k] = 0;
        q->u[k] = q->v[k] = 0;
        if (!(e >= 0.0) || !isfinite(e) || !isfinite(lo[k])) return false;
        if (e == 0.0) continue;
        double s, su;
        trace_qlin_steps(e, &s, &su);
        if (!(s > 0.0) || !(su > 0.0)) return false;
        double x = l->x[k], u = l->u[k], v = l->v[k];
        q->x[k] = (uint8_t)trace_qlin_clamp(nearbyint((x - lo[k]) / s), 0.0, 255.0);
        q->u[k] = (int8_t)trace_qlin_clamp(nearbyint(u / su), -127.0, 127.0);
        q->v[k] = (int8_t)trace_qlin_clamp(nearbyint(v / su), -127.0, 127.0);
        double xq = lo[k] + q->x[k] * s, uq = q->u[k] * su, vq = q->v[k] * su;
        double r = fp_add_up(fp_add_up((double)l->r[k], trace_abs_diff_up(x, xq)),
                             fp_add_up(trace_abs_diff_up(u, uq), trace_abs_diff_up(v, vq)));
        if (!(r <= 255.0 * s)) return false;
        double qr = ceil(r / s);
        while (qr <= 255.0 && qr * s < r) qr += 1.0;     /* as decoded, at least r */
        if (qr > 255.0) return false;
        q->r[k] = (uint8_t)qr;
    }
    return true;
}

/* The restricted bound of the child cell c of the cell r (see the top) */
static inline void trace_lin_restrict(const trace_dlin *d, const double r[4], const double c[4],
                                      double lo[3], double hi[3])
{
    double mu = aa_input_mid(r[0], r[1]), mv = aa_input_mid(r[2], r[3]);
    double ua = c[0] >= mu ? 0.0 : -1.0, ub = c[1] <= mu ? 0.0 : 1.0;
    double va = c[2] >= mv ? 0.0 : -1.0, vb = c[3] <= mv ? 0.0 : 1.0;
    for (int k = 0; k < 3; k++) {
        double u1 = d->u[k] * ua, u2 = d->u[k] * ub, v1 = d->v[k] * va, v2 = d->v[k] * vb;
        lo[k] = fp_add_dn(fp_add_dn(fp_add_dn(d->x[k], fmin(u1, u2)), fmin(v1, v2)), -d->r[k]);
        hi[k] = fp_add_up(fp_add_up(fp_add_up(d->x[k], fmax(u1, u2)), fmax(v1, v2)), d->r[k]);
    }
}

#endif
