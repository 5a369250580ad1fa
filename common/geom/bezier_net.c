/*
 * bezier_net.c: Bezier nets of a piece of a polynomial patch, and affine
 * forms from them (bicubic patches, subdivision sub-patches and NuPatch
 * pieces, docs/geometry.md "Affine operations per evaluation").
 *
 * The piece of a Bezier curve over [a, b] is a Bezier curve of its own,
 * whose control points are the blossoms f(a, .., a, b, .., b) (de
 * Casteljau with a at the first levels and b at the rest; Farin, "Curves
 * and Surfaces for CAGD", §4.3); a patch's, rows then columns. Computed
 * in float, each point is widened by GEOM_NET_PAD of the net's largest
 * coordinate B: a level's r + (r' - r) t carries the earlier errors in
 * the convex combination (1 - t) e + t e' (t in [0, 1]) and adds three
 * roundings of at most u |x|, |x| <= 3 B, so under 10 u B a level, 10 n u B
 * for a curve of degree n, 20 n u B for a net (rows, then columns): at
 * degree 15, 300 u B, and GEOM_NET_PAD = 2^-40 = 8192 u.
 *
 * geom_net_form: the patch over the piece lies in the hull of its net,
 * and so does the patch minus any plane, whose net is the control points
 * minus the plane's values at the net's abscissae (a plane is a Bezier
 * patch of any degree with those control points). So a plane fitted to
 * the net plus one new noise symbol for the largest such difference is an
 * affine form of the patch over the piece, linear in the inputs' symbols.
 */
#include "geom/nurbs.h"
#include "geom/surface.h"
#include "geom/surface_internal.h"

#include <assert.h>
#include <math.h>

/* A cubic's piece (n = 4), the loops below written out: the same
 * operations in the same order (the same bits) without the loops' and
 * arrays' cost; a bicubic patch's or subdivision sub-patch's every box
 * makes 24 of them */
#define LERP(x, y, t) ((x) + ((y) - (x)) * (t))
static void cubic_piece(const double *p, int stride, double a, double b, double *q,
                        int qstride)
{
    double r0 = p[0], r1 = p[stride], r2 = p[2 * stride], r3 = p[3 * stride];
    double t0 = LERP(r0, r1, b), t1 = LERP(r1, r2, b), t2 = LERP(r2, r3, b);
    t0 = LERP(t0, t1, b), t1 = LERP(t1, t2, b);
    q[3 * qstride] = LERP(t0, t1, b);
    r0 = LERP(r0, r1, a), r1 = LERP(r1, r2, a), r2 = LERP(r2, r3, a);
    t0 = LERP(r0, r1, b), t1 = LERP(r1, r2, b);
    q[2 * qstride] = LERP(t0, t1, b);
    r0 = LERP(r0, r1, a), r1 = LERP(r1, r2, a);
    q[qstride] = LERP(r0, r1, b);
    q[0] = LERP(r0, r1, a);
}
#undef LERP

void geom_bezier_piece(const double *p, int stride, int n, double a, double b, double *q,
                       int qstride)
{
    assert(n >= 1 && n <= GEOM_NURBS_MAX_ORDER);
    if (n == 4) {
        cubic_piece(p, stride, a, b, q, qstride);
        return;
    }
    /* q[k]: n - 1 levels, a at the first m = n - 1 - k, b at the last k.
     * The levels at a are each q's prefix: computed once, as r, and each
     * q[k] goes on from r at b (the same operations on the same values as
     * running every q from p: the same bits; for a cubic 16 interpolations
     * instead of 24) */
    double r[GEOM_NURBS_MAX_ORDER];
    for (int i = 0; i < n; i++) r[i] = p[i * stride];
    for (int m = 0; m < n; m++) {
        double t[GEOM_NURBS_MAX_ORDER];
        for (int i = 0; i < n - m; i++) t[i] = r[i];
        for (int l = m; l < n - 1; l++)
            for (int i = 0; i < n - 1 - l; i++) t[i] = t[i] + (t[i + 1] - t[i]) * b;
        q[(n - 1 - m) * qstride] = t[0];
        for (int i = 0; i < n - 1 - m; i++) r[i] = r[i] + (r[i + 1] - r[i]) * a;
    }
}

bool geom_net_piece(const double *p, int stride, int ku, int kv, double s0, double s1,
                    double t0, double t1, double pad, ia_interval *q, int ld)
{
    const double e = 0x1p-20;          /* a rounding's worth past the square */
    if (!(s0 >= -e && s1 <= 1 + e && t0 >= -e && t1 <= 1 + e) || !isfinite(pad)) return false;
    assert(ku >= 1 && kv >= 1 && ku <= GEOM_NURBS_MAX_ORDER && kv <= GEOM_NURBS_MAX_ORDER);
    double h[GEOM_NURBS_MAX_ORDER][GEOM_NURBS_MAX_ORDER];
    for (int j = 0; j < kv; j++) geom_bezier_piece(p + j * ku * stride, stride, ku, s0, s1, h[j], 1);
    for (int i = 0; i < ku; i++) {
        /* zeroed: GCC 12 at -O2 without asserts cannot see kv >= 1 and
         * warns that geom_bezier_piece may read it unset */
        double col[GEOM_NURBS_MAX_ORDER] = {0}, r[GEOM_NURBS_MAX_ORDER];
        for (int j = 0; j < kv; j++) col[j] = h[j][i];
        geom_bezier_piece(col, 1, kv, t0, t1, r, 1);
        for (int j = 0; j < kv; j++) q[j * ld + i] = ia_make(r[j] - pad, r[j] + pad);
    }
    return true;
}

static double mid_ia(ia_interval x) { return 0.5 * x.lo + 0.5 * x.hi; }

static double max2(double a, double b) { return a > b ? a : b; }   /* no NaN here */

void geom_net_form(aa_context *ctx, aa_form *z, const ia_interval *w, int ld, int nu, int nv,
                   ia_interval scale, const aa_form *s, const aa_form *t, double s0,
                   double s1, double t0, double t1)
{
    assert(nu >= 2 && nv >= 2 && ld >= nu);
    assert(nu <= GEOM_NURBS_MAX_ORDER && nv <= GEOM_NURBS_MAX_ORDER);
#define W(j, i) w[(j) * ld + (i)]
    /* the points' midpoints once (the same sums of the same values) */
    double mid[GEOM_NURBS_MAX_ORDER][GEOM_NURBS_MAX_ORDER];
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) mid[j][i] = mid_ia(W(j, i));
    double ds = 0, dt = 0, mean = 0;
    for (int j = 0; j < nv; j++) ds += mid[j][nu - 1] - mid[j][0];
    for (int i = 0; i < nu; i++) dt += mid[nv - 1][i] - mid[0][i];
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) mean += mid[j][i];
    double sc = mid_ia(scale);
    ds = ds / nv * sc;
    dt = dt / nu * sc;
    mean = mean / (nu * nv) * sc;
    /* any plane serves: the distances below are taken from this one */
    double alpha = ds / (s1 - s0), beta = dt / (t1 - t0);
    double gamma = mean - alpha * (0.5 * s0 + 0.5 * s1) - beta * (0.5 * t0 + 0.5 * t1);
    if (!isfinite(alpha) || !isfinite(beta) || !isfinite(gamma)) alpha = beta = gamma = 0;
    double rmax = 0;
    ia_interval hull = ia_empty();
    /* the plane's terms at the net's abscissae, once per column and row
     * (the same operations on the same values as per point: the same
     * bits; the asset's subdivision rocks spent 16 % of their time here) */
    ia_interval at_s[GEOM_NURBS_MAX_ORDER], at_t[GEOM_NURBS_MAX_ORDER];
    for (int i = 0; i < nu; i++) {
        ia_interval si = ia_add(ia_point(s0), ia_mul_s(ia_sub(ia_point(s1), ia_point(s0)),
                                                       (double)i / (nu - 1)));
        at_s[i] = ia_mul_s(si, alpha);
    }
    for (int j = 0; j < nv; j++) {
        ia_interval tj = ia_add(ia_point(t0), ia_mul_s(ia_sub(ia_point(t1), ia_point(t0)),
                                                       (double)j / (nv - 1)));
        at_t[j] = ia_mul_s(tj, beta);
    }
    /* every input finite and under 2^400 in magnitude (the usual case):
     * then no end below overflows or is NaN, and no interval is empty, so
     * the interval operations' checks for those cases are no-ops: the ends
     * alone, by the same directed roundings (the same bits) */
    const double big = 0x1p400;
    bool tame = fabs(gamma) < big && fabs(scale.lo) < big && fabs(scale.hi) < big;
    for (int i = 0; i < nu && tame; i++)
        tame = at_s[i].lo <= at_s[i].hi && fabs(at_s[i].lo) < big && fabs(at_s[i].hi) < big;
    for (int j = 0; j < nv && tame; j++)
        tame = at_t[j].lo <= at_t[j].hi && fabs(at_t[j].lo) < big && fabs(at_t[j].hi) < big;
    for (int j = 0; j < nv && tame; j++)
        for (int i = 0; i < nu && tame; i++)
            tame = W(j, i).lo <= W(j, i).hi && fabs(W(j, i).lo) < big && fabs(W(j, i).hi) < big;
    if (tame) {
        double hlo = 0, hhi = 0;
        for (int j = 0; j < nv; j++)
            for (int i = 0; i < nu; i++) {
                ia_interval x = ia_mul(W(j, i), scale);
                double plo = fp_add_dn(fp_add_dn(at_s[i].lo, at_t[j].lo), gamma);
                double phi = fp_add_up(fp_add_up(at_s[i].hi, at_t[j].hi), gamma);
                double dlo = fp_add_dn(x.lo, -phi), dhi = fp_add_up(x.hi, -plo);
                rmax = max2(rmax, max2(-dlo, dhi));
                bool first = i == 0 && j == 0;
                hlo = first ? x.lo : ia_min2_(hlo, x.lo);   /* ia_hull's */
                hhi = first ? x.hi : ia_max2_(hhi, x.hi);
            }
        hull = ia_make(hlo, hhi);
    } else {
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            ia_interval x = ia_mul(W(j, i), scale);
            ia_interval plane = ia_add(ia_add(at_s[i], at_t[j]), ia_point(gamma));
            ia_interval d = ia_sub(x, plane);
            /* (comparisons, not fmin/fmax: calls into libm; d's ends are
             * never NaN, and a zero's sign does not matter: no error) */
            rmax = max2(rmax, max2(-d.lo, d.hi));
            hull = i == 0 && j == 0 ? x : ia_hull(hull, x);
        }
    }
#undef W
    aa_lincomb(ctx, z, alpha, s, beta, t, gamma);
    if (!(rmax < INFINITY) || !isfinite(hull.lo) || !isfinite(hull.hi)) {
        aa_unbounded(z, AA_UNBOUNDED);
        return;
    }
    aa_add_new_error(ctx, z, rmax);
    z->lo = hull.lo;
    z->hi = hull.hi;
}
