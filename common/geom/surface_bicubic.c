/*
 * surface_bicubic.c: the bicubic Bezier patch (GEOM_BICUBIC), the form
 * every bicubic basis of RenderMan's Patch and PatchMesh is converted to
 * (RI Specification 3.2 §5.3; the parser multiplies the basis matrices
 * into Bezier control points, common/scene/rib_patch.c):
 *
 *     P(u,v) = sum_ij B_i(u) B_j(v) P_ij,   P_ij = verts[4 j + i]
 *
 * with the cubic Bernstein polynomials B_0..3 (u varies fastest, as in the
 * RIB). Here: prepare, the float and dual evaluation, interval and affine
 * enclosures over a (u,v) box (conservative including rounding: only
 * common/aa operations, and the control points are exact doubles), and the
 * ray intersection.
 *
 * The enclosures are the tensor form in both arithmetics: with s = 1 - u,
 * the basis s^3, 3 s^2 u, 3 s u^2, u^3 and its derivative
 * 3 (-s^2, s^2 - 2 s u, 2 s u - u^2, u^2) from the products s^2, s u, u^2,
 * s^3, s^2 u, s u^2, u^3 (7 non-affine operations per parameter); the rows
 * C_j = sum_i B_i(u) P_ij and D_j = sum_i B_i'(u) P_ij are affine in
 * those; then P = sum_j B_j(v) C_j, dPdu = sum_j B_j(v) D_j,
 * dPdv = sum_j B_j'(v) C_j (12 products per coordinate) and
 * Ng = dPdu x dPdv (6): 56 non-affine operations in all. The slopes of
 * the unit normal over a box (for hit proofs, trace/prove.c) come from
 * the piece of the patch over the box, as a Bezier net of its own, whose
 * first and second differences bound the derivatives.
 *
 * Intersection: recursive de Casteljau subdivision of the control net,
 * each piece pruned by its net's box against the ray's slab interval (the
 * piece lies in its net's hull). From pieces of side 1/8 (1/32 where the
 * ray may touch the surface tangentially: the hodographs' bound on Ng.d
 * holds 0) Newton's method on o + t d = P(u,v) from the box centre,
 * accepted when it converges inside the box. A transversal box
 * (Ng.d of one sign) holds at most one hit, so one found ends it; other
 * boxes are split on (a grazing ray may cross twice, close together) down
 * to side 2^-16. Newton's t varies by a few ulps with its
 * start, so a hit within a relative 1e-9 of tmin counts as the one at
 * tmin (a caller walking the hits along a ray gets each once). The bounds
 * are the control points' box (the patch lies in their convex hull).
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* ---- float ---------------------------------------------------------- */

static void bernstein_b(double u, double b[4])
{
    double s = 1 - u;
    b[0] = s * s * s, b[1] = 3 * s * s * u, b[2] = 3 * s * u * u, b[3] = u * u * u;
}

static void bernstein(double u, double b[4], double d1[4], double d2[4])
{
    double s = 1 - u;
    bernstein_b(u, b);
    d1[0] = -3 * s * s, d1[1] = 3 * (s * s - 2 * s * u), d1[2] = 3 * (2 * s * u - u * u);
    d1[3] = 3 * u * u;
    d2[0] = 6 * s, d2[1] = -12 * s + 6 * u, d2[2] = 6 * s - 12 * u, d2[3] = 6 * u;
}

static vec3 tensor(const vec3 *p, const double *bu, const double *bv)
{
    vec3 r = v3(0, 0, 0);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            r = v3_add(r, v3_scale(p[4 * j + i], bu[i] * bv[j]));
    return r;
}

vec3 geom_bicubic_eval_point(const geom_surface *s, double u, double v)
{
    /* P as geom_bicubic_eval_dual makes it (the same bernstein weights, the
     * same sum in the same order: the same bits), without the 5 tensor
     * sums of the derivatives (the grid spacing's 81 points a piece) */
    double bu[4], bv[4];
    bernstein_b(u, bu);
    bernstein_b(v, bv);
    return tensor(s->verts, bu, bv);
}

void geom_bicubic_eval_dual(const geom_surface *s, double u, double v, geom_sample *out)
{
    double bu[4], du[4], ddu[4], bv[4], dv[4], ddv[4];
    bernstein(u, bu, du, ddu);
    bernstein(v, bv, dv, ddv);
    const vec3 *p = s->verts;
    out->P = tensor(p, bu, bv);
    out->dPdu = tensor(p, du, bv);
    out->dPdv = tensor(p, bu, dv);
    vec3 Puu = tensor(p, ddu, bv), Puv = tensor(p, du, dv), Pvv = tensor(p, bu, ddv);
    out->Ng = v3_cross(out->dPdu, out->dPdv);
    out->dNgdu = v3_add(v3_cross(Puu, out->dPdv), v3_cross(out->dPdu, Puv));
    out->dNgdv = v3_add(v3_cross(Puv, out->dPdv), v3_cross(out->dPdu, Pvv));
}

/* ---- interval ------------------------------------------------------- */

static void basis_ia(ia_interval u, ia_interval b[4], ia_interval d[4])
{
    ia_interval s = ia_sub(ia_point(1), u);
    ia_interval s2 = ia_mul(s, s), su = ia_mul(s, u), u2 = ia_mul(u, u);
    b[0] = ia_mul(s2, s);
    b[1] = ia_mul_s(ia_mul(s2, u), 3);
    b[2] = ia_mul_s(ia_mul(s, u2), 3);
    b[3] = ia_mul(u2, u);
    d[0] = ia_mul_s(s2, -3);
    d[1] = ia_mul_s(ia_sub(s2, ia_mul_s(su, 2)), 3);
    d[2] = ia_mul_s(ia_sub(ia_mul_s(su, 2), u2), 3);
    d[3] = ia_mul_s(u2, 3);
}

/* sum_i w[i] p[i] */
static ia_interval dot4_ia(const ia_interval w[4], const double p[4])
{
    ia_interval r = ia_mul_s(w[0], p[0]);
    for (int i = 1; i < 4; i++)
        r = ia_add(r, ia_mul_s(w[i], p[i]));
    return r;
}

static ia_interval sum4_ia(const ia_interval a[4], const ia_interval b[4])
{
    ia_interval r = ia_mul(a[0], b[0]);
    for (int i = 1; i < 4; i++)
        r = ia_add(r, ia_mul(a[i], b[i]));
    return r;
}

static void cross_ia(const ia_interval a[3], const ia_interval b[3], ia_interval out[3])
{
    for (int c = 0; c < 3; c++) {
        int i = (c + 1) % 3, j = (c + 2) % 3;
        out[c] = ia_sub(ia_mul(a[i], b[j]), ia_mul(a[j], b[i]));
    }
}

/* The piece of the patch over the box as a Bezier patch of its own,
 * q[c][j][i] for coordinate c (geom_net_piece): it and its derivatives
 * (Bezier patches whose control points are the net's differences) lie in
 * the hulls of their control points (Farin, "Curves and Surfaces for
 * CAGD", §4.3, §16.2) */
static bool piece_net(const geom_surface *s, ia_interval u, ia_interval v,
                      ia_interval q[3][4][4])
{
    double p[48], big = 0;
    for (int i = 0; i < 16; i++)
        for (int c = 0; c < 3; c++) {
            p[3 * i + c] = v3_comp(s->verts[i], c);
            big = geom_max(big, fabs(p[3 * i + c]));   /* fmax's bits, no call */
        }
    for (int c = 0; c < 3; c++)
        if (!geom_net_piece(p + c, 3, 4, 4, u.lo, u.hi, v.lo, v.hi, GEOM_NET_PAD * big,
                            &q[c][0][0], 4))
            return false;
    return true;
}

/* Over the piece, with the net q of one coordinate: the hull of the
 * k-th differences along u (ku) and v (kv), times the derivative's
 * factors (3, 6, 9: d^(ku+kv)/ds^ku dt^kv of the Bernstein form) */
static ia_interval net_diff(ia_interval q[4][4], int ku, int kv)
{
    static const double factor[3][3] = {{1, 3, 6}, {3, 9, 0}, {6, 0, 0}};
    ia_interval h = ia_empty();
    for (int j = 0; j + kv < 4; j++)
        for (int i = 0; i + ku < 4; i++) {
            ia_interval d;
            if (ku == 2)
                d = ia_add(ia_sub(q[j][i + 2], ia_mul_s(q[j][i + 1], 2)), q[j][i]);
            else if (kv == 2)
                d = ia_add(ia_sub(q[j + 2][i], ia_mul_s(q[j + 1][i], 2)), q[j][i]);
            else if (ku == 1 && kv == 1)
                d = ia_add(ia_sub(q[j + 1][i + 1], q[j + 1][i]), ia_sub(q[j][i], q[j][i + 1]));
            else if (ku == 1)
                d = ia_sub(q[j][i + 1], q[j][i]);
            else if (kv == 1)
                d = ia_sub(q[j + 1][i], q[j][i]);
            else
                d = q[j][i];
            h = i == 0 && j == 0 ? d : ia_hull(h, d);
        }
    return ia_mul_s(h, factor[ku][kv]);
}

static ia_interval meet(ia_interval a, ia_interval b)
{
    double lo = fmax(a.lo, b.lo), hi = fmin(a.hi, b.hi);
    return lo <= hi ? ia_make(lo, hi) : a;
}

void geom_bicubic_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *o)
{
    ia_interval bu[4], du[4], bv[4], dv[4];
    basis_ia(u, bu, du);
    basis_ia(v, bv, dv);
    for (int c = 0; c < 3; c++) {
        ia_interval C[4], D[4];
        for (int j = 0; j < 4; j++) {
            double row[4];
            for (int i = 0; i < 4; i++)
                row[i] = v3_comp(s->verts[4 * j + i], c);
            C[j] = dot4_ia(bu, row);
            D[j] = dot4_ia(du, row);
        }
        o->P[c] = sum4_ia(bv, C);
        o->dPdu[c] = sum4_ia(bv, D);
        o->dPdv[c] = sum4_ia(dv, C);
    }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        o->Ng[c] = ia_sub(ia_mul(o->dPdu[a], o->dPdv[b]), ia_mul(o->dPdu[b], o->dPdv[a]));
    }
}

void geom_bicubic_tighten_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *o)
{
    ia_interval q[3][4][4];
    if (!(u.hi - u.lo > 0x1p-20) || !(v.hi - v.lo > 0x1p-20) || !piece_net(s, u, v, q)) return;
    ia_interval iu = ia_recip(ia_sub(ia_point(u.hi), ia_point(u.lo)));
    ia_interval iv = ia_recip(ia_sub(ia_point(v.hi), ia_point(v.lo)));
    for (int c = 0; c < 3; c++) {
        o->P[c] = meet(o->P[c], net_diff(q[c], 0, 0));
        o->dPdu[c] = meet(o->dPdu[c], ia_mul(net_diff(q[c], 1, 0), iu));
        o->dPdv[c] = meet(o->dPdv[c], ia_mul(net_diff(q[c], 0, 1), iv));
    }
    ia_interval Ng[3];
    cross_ia(o->dPdu, o->dPdv, Ng);
    for (int c = 0; c < 3; c++) o->Ng[c] = meet(o->Ng[c], Ng[c]);
}

/* ---- slopes of the unit normal -------------------------------------- */

bool geom_bicubic_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                   ia_interval dNdu[3], ia_interval dNdv[3])
{
    /* the derivatives from the piece's net: d/du = d/ds / (u1 - u0), and
     * likewise for v */
    ia_interval q[3][4][4];
    if (!(u.hi - u.lo > 0x1p-20) || !(v.hi - v.lo > 0x1p-20) || !piece_net(s, u, v, q))
        return false;
    ia_interval iu = ia_recip(ia_sub(ia_point(u.hi), ia_point(u.lo)));
    ia_interval iv = ia_recip(ia_sub(ia_point(v.hi), ia_point(v.lo)));
    ia_interval Pu[3], Pv[3], Puu[3], Puv[3], Pvv[3];
    for (int c = 0; c < 3; c++) {
        Pu[c] = ia_mul(net_diff(q[c], 1, 0), iu);
        Pv[c] = ia_mul(net_diff(q[c], 0, 1), iv);
        Puu[c] = ia_mul(ia_mul(net_diff(q[c], 2, 0), iu), iu);
        Puv[c] = ia_mul(ia_mul(net_diff(q[c], 1, 1), iu), iv);
        Pvv[c] = ia_mul(ia_mul(net_diff(q[c], 0, 2), iv), iv);
    }
    /* Ng = Pu x Pv, its derivatives Puu x Pv + Pu x Puv and Puv x Pv +
     * Pu x Pvv */
    ia_interval N[3], a[3], b[3], Nu[3], Nv[3];
    cross_ia(Pu, Pv, N);
    cross_ia(Puu, Pv, a);
    cross_ia(Pu, Puv, b);
    for (int c = 0; c < 3; c++) Nu[c] = ia_add(a[c], b[c]);
    cross_ia(Puv, Pv, a);
    cross_ia(Pu, Pvv, b);
    for (int c = 0; c < 3; c++) Nv[c] = ia_add(a[c], b[c]);
    return geom_unit_slopes_ia(N, Nu, Nv, dNdu, dNdv);
}

/* ---- affine --------------------------------------------------------- */

static void basis_aa(aa_context *ctx, const aa_form *u, aa_form b[4], aa_form d[4])
{
    aa_form s, s2, su, u2, t;
    aa_lincomb(ctx, &s, -1, u, 0, u, 1);
    aa_mul(ctx, &s2, &s, &s);
    aa_mul(ctx, &su, &s, u);
    aa_mul(ctx, &u2, u, u);
    aa_mul(ctx, &b[0], &s2, &s);
    aa_mul(ctx, &t, &s2, u);
    aa_mul_s(ctx, &b[1], &t, 3);
    aa_mul(ctx, &t, &s, &u2);
    aa_mul_s(ctx, &b[2], &t, 3);
    aa_mul(ctx, &b[3], &u2, u);
    aa_mul_s(ctx, &d[0], &s2, -3);
    aa_lincomb(ctx, &d[1], 3, &s2, -6, &su, 0);
    aa_lincomb(ctx, &d[2], 6, &su, -3, &u2, 0);
    aa_mul_s(ctx, &d[3], &u2, 3);
}

static void dot4_aa(aa_context *ctx, aa_form *z, const aa_form w[4], const double p[4])
{
    aa_form t;
    aa_lincomb(ctx, z, p[0], &w[0], p[1], &w[1], 0);
    aa_lincomb(ctx, &t, p[2], &w[2], p[3], &w[3], 0);
    aa_add(ctx, z, z, &t);
}

static void sum4_aa(aa_context *ctx, aa_form *z, const aa_form a[4], const aa_form b[4])
{
    aa_form t;
    aa_mul(ctx, z, &a[0], &b[0]);
    for (int i = 1; i < 4; i++) {
        aa_mul(ctx, &t, &a[i], &b[i]);
        aa_add(ctx, z, z, &t);
    }
}

void geom_bicubic_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                          const aa_form *v, geom_aa *o)
{
    aa_form bu[4], du[4], bv[4], dv[4];
    basis_aa(ctx, u, bu, du);
    basis_aa(ctx, v, bv, dv);
    for (int c = 0; c < 3; c++) {
        aa_form C[4], D[4];
        for (int j = 0; j < 4; j++) {
            double row[4];
            for (int i = 0; i < 4; i++)
                row[i] = v3_comp(s->verts[4 * j + i], c);
            dot4_aa(ctx, &C[j], bu, row);
            dot4_aa(ctx, &D[j], du, row);
        }
        sum4_aa(ctx, &o->P[c], bv, C);
        sum4_aa(ctx, &o->dPdu[c], bv, D);
        sum4_aa(ctx, &o->dPdv[c], dv, C);
    }
    geom_ng_aa(ctx, o);
}

bool geom_bicubic_net_aa(aa_context *ctx, const geom_surface *b, const aa_form *s,
                         const aa_form *t, geom_aa *o)
{
    ia_interval sr = aa_range(s), tr = aa_range(t);
    double s0 = sr.lo, s1 = sr.hi, t0 = tr.lo, t1 = tr.hi;
    /* below 2^-12 the rounding of the net's differences over the box's
     * width (~ulp(P) / width) would outgrow the quadratic term */
    if (!(s1 - s0 > 0x1p-12) || !(t1 - t0 > 0x1p-12) || (s->flags | t->flags))
        return false;
    ia_interval q[3][4][4];
    if (!piece_net(b, sr, tr, q)) return false;
    ia_interval is = ia_recip(ia_sub(ia_point(s1), ia_point(s0)));
    ia_interval it = ia_recip(ia_sub(ia_point(t1), ia_point(t0)));
    for (int c = 0; c < 3; c++) {
        ia_interval du[4][4], dv[4][4];
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 3; i++) du[j][i] = ia_mul_s(ia_sub(q[c][j][i + 1], q[c][j][i]), 3);
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 4; i++) dv[j][i] = ia_mul_s(ia_sub(q[c][j + 1][i], q[c][j][i]), 3);
        geom_net_form(ctx, &o->P[c], &q[c][0][0], 4, 4, 4, ia_point(1), s, t, s0, s1, t0, t1);
        geom_net_form(ctx, &o->dPdu[c], &du[0][0], 4, 3, 4, is, s, t, s0, s1, t0, t1);
        geom_net_form(ctx, &o->dPdv[c], &dv[0][0], 4, 4, 3, it, s, t, s0, s1, t0, t1);
    }
    geom_ng_aa(ctx, o);
    return true;
}

bool geom_bicubic_net_range_P(const geom_surface *b, const aa_form *s, const aa_form *t,
                              ia_interval P[3])
{
    /* geom_bicubic_net_aa's conditions and P nets, and the hull that
     * geom_net_form gives P's forms (scale 1): the form's affine range
     * holds that hull (the plane over the box plus the net's largest
     * distance from it reaches every net point), so aa_range is the hull */
    ia_interval sr = aa_range(s), tr = aa_range(t);
    if (!(sr.hi - sr.lo > 0x1p-12) || !(tr.hi - tr.lo > 0x1p-12) || (s->flags | t->flags))
        return false;
    ia_interval q[3][4][4];
    if (!piece_net(b, sr, tr, q)) return false;
    ia_interval one = ia_point(1);
    for (int c = 0; c < 3; c++) {
        ia_interval hull = ia_empty();
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                ia_interval x = ia_mul(q[c][j][i], one);
                hull = i == 0 && j == 0 ? x : ia_hull(hull, x);
            }
        if (!isfinite(hull.lo) || !isfinite(hull.hi)) return false;
        P[c] = hull;
    }
    return true;
}

/* ---- prepare and bounds --------------------------------------------- */

bool geom_bicubic_prepare(geom_surface *s, char *err, size_t errsz)
{
    if (s->nverts != 16)
        return err_set(err, errsz, "bicubic patch needs 16 control points, got %d",
                         s->nverts);
    double size = 0;
    for (int i = 0; i < 16; i++) {
        vec3 p = s->verts[i];
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return err_set(err, errsz, "bicubic patch control point %d is not finite", i);
        size = fmax(size, v3_length(v3_sub(p, s->verts[0])));
    }
    if (!isfinite(size) || size > 1e150)
        return err_set(err, errsz, "bicubic patch control points are too large");
    /* degenerate: all control points on one line (no normal anywhere) */
    double area = 0;
    for (int i = 1; i < 16; i++)
        for (int j = i + 1; j < 16; j++)
            area = fmax(area, v3_length(v3_cross(v3_sub(s->verts[i], s->verts[0]),
                                                 v3_sub(s->verts[j], s->verts[0]))));
    if (!(area > 1e-12 * size * size))
        return err_set(err, errsz, "bicubic patch is degenerate: its control points "
                         "lie on one line");
    return true;
}

void geom_bicubic_bounds(const geom_surface *s, vec3 *lo, vec3 *hi)
{
    *lo = *hi = s->verts[0];
    for (int i = 1; i < 16; i++) {
        vec3 p = s->verts[i];
        lo->x = fmin(lo->x, p.x), lo->y = fmin(lo->y, p.y), lo->z = fmin(lo->z, p.z);
        hi->x = fmax(hi->x, p.x), hi->y = fmax(hi->y, p.y), hi->z = fmax(hi->z, p.z);
    }
}

/* ---- intersection --------------------------------------------------- */

/* The ray's t interval inside the box [lo, hi] (slabs), within [t0, t1]. */
static bool slab(vec3 o, vec3 d, vec3 lo, vec3 hi, double *t0, double *t1)
{
    double a = *t0, b = *t1;
    for (int c = 0; c < 3; c++) {
        double oc = v3_comp(o, c), dc = v3_comp(d, c);
        double l = v3_comp(lo, c), h = v3_comp(hi, c);
        if (dc == 0) {
            if (oc < l || oc > h)
                return false;
            continue;
        }
        double ta = (l - oc) / dc, tb = (h - oc) / dc;
        if (ta > tb) { double t = ta; ta = tb; tb = t; }
        /* widen by a relative hair: the divisions round */
        double w = 1e-12 * (fabs(ta) + fabs(tb)) + 1e-300;
        a = fmax(a, ta - w);
        b = fmin(b, tb + w);
        if (a > b)
            return false;
    }
    *t0 = a, *t1 = b;
    return true;
}

/* A sub-patch's Bezier net (de Casteljau subdivision, in float: used to
 * prune and start Newton, never to bound shading); its (u,v) square is the
 * walk's (geom_patch_intersect). */
typedef struct net { vec3 p[16]; } net;

/* Splits the 4 points p[0], p[k], p[2k], p[3k] at 1/2 into a and b. */
static void split4(const vec3 *p, int k, vec3 *a, vec3 *b)
{
    vec3 p01 = v3_scale(v3_add(p[0], p[k]), 0.5), p12 = v3_scale(v3_add(p[k], p[2 * k]), 0.5);
    vec3 p23 = v3_scale(v3_add(p[2 * k], p[3 * k]), 0.5);
    vec3 q0 = v3_scale(v3_add(p01, p12), 0.5), q1 = v3_scale(v3_add(p12, p23), 0.5);
    vec3 m = v3_scale(v3_add(q0, q1), 0.5);
    a[0] = p[0], a[k] = p01, a[2 * k] = q0, a[3 * k] = m;
    b[0] = m, b[k] = q1, b[2 * k] = p23, b[3 * k] = p[3 * k];
}

/* The four quarters of n (u halves, then v halves). */
static void split_net(const net *n, net out[4])
{
    net half[2];
    for (int j = 0; j < 4; j++)
        split4(n->p + 4 * j, 1, half[0].p + 4 * j, half[1].p + 4 * j);
    for (int a = 0; a < 2; a++)
        for (int i = 0; i < 4; i++)
            split4(half[a].p + i, 4, out[a].p + i, out[2 + a].p + i);
}

static void net_box(const net *n, double pad, vec3 *lo, vec3 *hi)
{
    *lo = *hi = n->p[0];
    for (int i = 1; i < 16; i++) {
        vec3 p = n->p[i];
        lo->x = fmin(lo->x, p.x), lo->y = fmin(lo->y, p.y), lo->z = fmin(lo->z, p.z);
        hi->x = fmax(hi->x, p.x), hi->y = fmax(hi->y, p.y), hi->z = fmax(hi->z, p.z);
    }
    *lo = v3_sub(*lo, v3(pad, pad, pad));
    *hi = v3_add(*hi, v3(pad, pad, pad));
}

/* Whether det(Pu, Pv, d) keeps one sign over the net: Pu and Pv lie in the
 * hulls of the nets' differences (the hodographs), and the determinant is
 * bilinear in them, so its extremes are at pairs of hull points. */
static bool transversal(const net *n, vec3 d)
{
    vec3 du[12], dv[12];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 3; i++) {
            du[3 * j + i] = v3_sub(n->p[4 * j + i + 1], n->p[4 * j + i]);
            dv[3 * i + j] = v3_sub(n->p[4 * (i + 1) + j], n->p[4 * i + j]);
        }
    double lo = INFINITY, hi = -INFINITY;
    for (int a = 0; a < 12; a++) {
        vec3 c = v3_cross(dv[a], d);
        for (int b = 0; b < 12; b++) {
            double x = v3_dot(du[b], c);
            lo = fmin(lo, x), hi = fmax(hi, x);
        }
    }
    double tiny = 1e-9 * (fabs(lo) + fabs(hi));
    return lo > tiny || hi < -tiny;
}

/* The walk's view of the nets (geom_patch_walk): a stack of them. */
typedef struct bicubic_walk {
    net *stack;
    vec3 o, d;
    double pad;
} bicubic_walk;

static bool bicubic_clip(void *user, int k, double tmin, double best, double *t0, double *t1)
{
    bicubic_walk *bw = user;
    vec3 blo, bhi;
    net_box(&bw->stack[k], bw->pad, &blo, &bhi);
    *t0 = tmin, *t1 = best;
    return slab(bw->o, bw->d, blo, bhi, t0, t1);
}

static bool bicubic_transversal(void *user, int k)
{
    bicubic_walk *bw = user;
    return transversal(&bw->stack[k], bw->d);
}

static void bicubic_split(void *user, int k)
{
    bicubic_walk *bw = user;
    net cur = bw->stack[k];
    split_net(&cur, bw->stack + k);
}

bool geom_bicubic_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                            geom_hit *hit)
{
    vec3 lo, hi;
    geom_bicubic_bounds(s, &lo, &hi);
    double size = v3_length(v3_sub(hi, lo));
    double scale = size + v3_length(o) + 1e-300;
    bicubic_walk bw = { xmalloc(GEOM_PATCH_STACK * sizeof(net)), o, d, 1e-12 * scale };
    for (int i = 0; i < 16; i++)
        bw.stack[0].p[i] = s->verts[i];
    geom_patch_walk w = { s, geom_bicubic_eval_dual, scale, bicubic_clip, bicubic_transversal,
                          bicubic_split, false, &bw };
    bool found = geom_patch_intersect(&w, o, d, tmin, tmax, hit);
    free(bw.stack);
    return found;
}
