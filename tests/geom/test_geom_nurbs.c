/*
 * test_geom_nurbs.c: rational B-spline patches of any order (GEOM_NURBS,
 * common/geom/nurbs.h) against an independent evaluation written here:
 * the Cox-de Boor recursion of the basis functions and of their
 * derivatives, in long double, on the homogeneous control points of the
 * whole patch (not on the library's Bezier pieces), then the quotient
 * rule. Patches: a quarter cylinder (the classic rational quadratic arc,
 * middle weight sqrt(2)/2), a full circle of four such arcs extruded, a
 * random rational patch of orders 4 x 3 with a double knot, a polynomial
 * patch of orders 6 x 5, a rational order 5 x 2 over part of its domain.
 *
 *   float      P, dPdu, dPdv, Ng of every piece at random points equal the
 *              oracle's (dNgdu, dNgdv: central differences of Ng)
 *   circle     the arcs lie on the exact unit circle, the normal is radial
 *   contain    over random boxes of every piece (dyadic and any size) the
 *              oracle's P, dPdu, dPdv, Ng lie in the interval and affine
 *              enclosures (affine capacities 2, default, max) and P in
 *              geom_bounds: 0 violations; no box is unbounded (the weights'
 *              range keeps 1/w finite); boxes of side <= 1e-3 bound P to
 *              within 1% of the patch size
 *   intersect  rays aimed at oracle points hit them; rays beside miss
 *   errors     weights <= 0, orders 1 and 17, collinear points, too many
 *              pieces
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/nurbs.h"
#include "geom_fixtures.h"

typedef long double ld;

typedef struct patch {
    const char *name;
    int nu, ou, nv, ov;
    double ku[40], kv[40], umin, umax, vmin, vmax;
    double Pw[4 * 200];
} patch;

/* N_{i,p}(t), i = 0..n-1, and their derivatives, by the Cox-de Boor
 * recursion raised degree by degree from the indicator functions of the
 * knot intervals: right-open intervals [U_i, U_i+1), or left-open ones
 * (U_i, U_i+1] when `left` (the limit from below: the end of a piece at
 * an inner knot); t at the domain's start or end counts in its first or
 * last non-empty interval */
static void basis_all(const double *U, int n, int p, ld t, bool left, ld *N, ld *dN)
{
    ld b[64] = { 0 }, prev[64] = { 0 };
    int m = n + p;                          /* intervals [U_i, U_i+1], i < m */
    for (int i = 0; i < m; i++) {
        bool in = left ? (U[i] < t && t <= U[i + 1]) : (U[i] <= t && t < U[i + 1]);
        if (!left && t == U[n] && U[i] < U[i + 1] && U[i + 1] == U[n]) in = true;
        if (left && t == U[p] && U[i] < U[i + 1] && U[i] == U[p]) in = true;
        b[i] = in;
    }
    for (int d = 1; d <= p; d++) {
        memcpy(prev, b, sizeof b);
        for (int i = 0; i < m - d; i++) {
            ld x = 0, y = 0;
            if (U[i + d] > U[i]) x = (t - U[i]) / ((ld)U[i + d] - U[i]) * prev[i];
            if (U[i + d + 1] > U[i + 1])
                y = (U[i + d + 1] - t) / ((ld)U[i + d + 1] - U[i + 1]) * prev[i + 1];
            b[i] = x + y;
        }
    }
    for (int i = 0; i < n; i++) {
        N[i] = b[i];
        ld x = 0, y = 0;          /* prev: degree p-1 (p >= 1) */
        if (U[i + p] > U[i]) x = p / ((ld)U[i + p] - U[i]) * prev[i];
        if (U[i + p + 1] > U[i + 1]) y = p / ((ld)U[i + p + 1] - U[i + 1]) * prev[i + 1];
        dN[i] = x - y;
    }
}

/* P, Pu, Pv at knot-space (u, v) */
static void oracle(const patch *pt, ld u, ld v, bool lu, bool lv, ld P[3], ld Pu[3], ld Pv[3])
{
    ld H[4] = { 0 }, Hu[4] = { 0 }, Hv[4] = { 0 };
    ld Nu[64], dNu[64], Nv[64], dNv[64];
    basis_all(pt->ku, pt->nu, pt->ou - 1, u, lu, Nu, dNu);
    basis_all(pt->kv, pt->nv, pt->ov - 1, v, lv, Nv, dNv);
    for (int j = 0; j < pt->nv; j++)
        for (int i = 0; i < pt->nu; i++) {
            const double *h = pt->Pw + 4 * (j * pt->nu + i);
            for (int c = 0; c < 4; c++) {
                H[c] += Nu[i] * Nv[j] * h[c];
                Hu[c] += dNu[i] * Nv[j] * h[c];
                Hv[c] += Nu[i] * dNv[j] * h[c];
            }
        }
    for (int c = 0; c < 3; c++) {
        P[c] = H[c] / H[3];
        Pu[c] = (Hu[c] - Hu[3] * P[c]) / H[3];
        Pv[c] = (Hv[c] - Hv[3] * P[c]) / H[3];
    }
}

/* the oracle at (s, t) of piece k, derivatives per unit of s and t */
typedef struct exact { ld q[4][3]; } exact;       /* P, Pu, Pv, Ng */

static void oracle_piece(const patch *pt, const geom_nurbs *nb, int k, double s, double t,
                         exact *e)
{
    double u0, u1, v0, v1;
    geom_nurbs_piece_range(nb, k, &u0, &u1, &v0, &v1);
    ld u = u0 + (ld)s * ((ld)u1 - u0), v = v0 + (ld)t * ((ld)v1 - v0);
    if (s == 1) u = u1;
    if (t == 1) v = v1;
    oracle(pt, u, v, s == 1, t == 1, e->q[0], e->q[1], e->q[2]);
    for (int c = 0; c < 3; c++) {
        e->q[1][c] *= (ld)u1 - u0;
        e->q[2][c] *= (ld)v1 - v0;
    }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        e->q[3][c] = e->q[1][a] * e->q[2][b] - e->q[1][b] * e->q[2][a];
    }
}

static geom_nurbs *build(const patch *pt)
{
    geom_nurbs_desc d = { pt->nu, pt->ou, pt->ku, pt->umin, pt->umax,
                          pt->nv, pt->ov, pt->kv, pt->vmin, pt->vmax, pt->Pw };
    char why[256];
    geom_nurbs *nb = geom_nurbs_new(&d, why, sizeof why);
    if (!nb) fail_msg("%s: %s", pt->name, why);
    return nb;
}

/* ---- the patches ---- */

#define W2 0.70710678118654752440

static void set_pw(patch *p, int i, int j, double x, double y, double z, double w)
{
    double *h = p->Pw + 4 * (j * p->nu + i);
    h[0] = x * w, h[1] = y * w, h[2] = z * w, h[3] = w;
}

static int make_patches(patch *out)
{
    int n = 0;
    /* a quarter cylinder: the arc (1,0) (1,1) (0,1), weights 1 w 1, z 0..1 */
    patch *p = &out[n++];
    memset(p, 0, sizeof *p);
    *p = (patch){ .name = "quarter cylinder", .nu = 3, .ou = 3, .nv = 2, .ov = 2,
                  .ku = { 0, 0, 0, 1, 1, 1 }, .kv = { 0, 0, 1, 1 }, .umax = 1, .vmax = 1 };
    for (int j = 0; j < 2; j++) {
        set_pw(p, 0, j, 1, 0, j, 1);
        set_pw(p, 1, j, 1, 1, j, W2);
        set_pw(p, 2, j, 0, 1, j, 1);
    }
    /* a full circle of four arcs (9 points), extruded */
    p = &out[n++];
    memset(p, 0, sizeof *p);
    *p = (patch){ .name = "cylinder", .nu = 9, .ou = 3, .nv = 2, .ov = 2,
                  .ku = { 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4 }, .kv = { 0, 0, 1, 1 },
                  .umax = 4, .vmax = 1 };
    static const double cx[9] = { 1, 1, 0, -1, -1, -1, 0, 1, 1 };
    static const double cy[9] = { 0, 1, 1, 1, 0, -1, -1, -1, 0 };
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 9; i++)
            set_pw(p, i, j, cx[i], cy[i], 2 * j - 1, i % 2 ? W2 : 1);
    /* random rational, orders 4 x 3, a double knot in u */
    fx_seed(41);
    p = &out[n++];
    memset(p, 0, sizeof *p);
    *p = (patch){ .name = "rational 4x3", .nu = 6, .ou = 4, .nv = 5, .ov = 3,
                  .ku = { 0, 0, 0, 0, 1, 1, 2.5, 2.5, 2.5, 2.5 },
                  .kv = { 0, 0, 0, 0.7, 1.5, 2, 2, 2 }, .umax = 2.5, .vmax = 2 };
    for (int j = 0; j < p->nv; j++)
        for (int i = 0; i < p->nu; i++)
            set_pw(p, i, j, i * 0.4, j * 0.5, fx_range(-0.3, 0.3), fx_range(0.3, 3));
    /* polynomial of orders 6 x 5 (beyond bicubic), uniform knots */
    p = &out[n++];
    memset(p, 0, sizeof *p);
    *p = (patch){ .name = "order 6x5", .nu = 7, .ou = 6, .nv = 6, .ov = 5, .umin = 5,
                  .umax = 7, .vmin = 4, .vmax = 6 };
    for (int k = 0; k < 13; k++) p->ku[k] = k;
    for (int k = 0; k < 11; k++) p->kv[k] = k;
    for (int j = 0; j < p->nv; j++)
        for (int i = 0; i < p->nu; i++)
            set_pw(p, i, j, i * 0.3, j * 0.3, 0.2 * sin(i + 2.0 * j), 1);
    /* rational 5 x 2 over part of its domain */
    p = &out[n++];
    memset(p, 0, sizeof *p);
    *p = (patch){ .name = "rational 5x2 part", .nu = 7, .ou = 5, .nv = 3, .ov = 2,
                  .ku = { 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3 }, .kv = { 0, 0, 1, 2, 2 },
                  .umin = 0.4, .umax = 2.2, .vmin = 0.5, .vmax = 2 };
    for (int j = 0; j < p->nv; j++)
        for (int i = 0; i < p->nu; i++)
            set_pw(p, i, j, cos(i * 0.5) * (1 + j), sin(i * 0.5) * (1 + j), 0.3 * j,
                   fx_range(0.2, 5));
    return n;
}

static ld dist3(const ld a[3], vec3 b)
{
    ld x = a[0] - b.x, y = a[1] - b.y, z = a[2] - b.z;
    return sqrtl(x * x + y * y + z * z);
}

static ld len3(const ld a[3])
{
    return sqrtl(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* ---- float ---- */

static void test_float(void **state)
{
    (void)state;
    static patch P[8];
    int np = make_patches(P);
    fx_seed(5);
    for (int k = 0; k < np; k++) {
        geom_nurbs *nb = build(&P[k]);
        ld worst = 0;
        for (int pc = 0; pc < geom_nurbs_npieces(nb); pc++) {
            geom_surface s;
            geom_nurbs_surface(nb, pc, &s);
            char why[100];
            assert_true(geom_surface_prepare(&s, why, sizeof why));
            assert_int_equal(s.kind, GEOM_NURBS);
            for (int i = 0; i < 40; i++) {
                double u = i < 4 ? (i & 1) : fx_unit(), v = i < 4 ? (i >> 1) : fx_unit();
                exact e;
                oracle_piece(&P[k], nb, pc, u, v, &e);
                geom_sample g;
                geom_eval_dual(&s, u, v, &g);
                vec3 got[4] = { g.P, g.dPdu, g.dPdv, g.Ng };
                for (int q = 0; q < 4; q++) {
                    ld err = dist3(e.q[q], got[q]) / (1 + len3(e.q[q]));
                    worst = fmaxl(worst, err);
                    if (!(err < 1e-9))
                        fail_msg("%s piece %d at (%g, %g): quantity %d off by %Lg", P[k].name,
                                 pc, u, v, q, err);
                }
                /* dNgdu, dNgdv: central differences of the library's Ng */
                double h = 1e-5;
                if (u > h && u < 1 - h && v > h && v < 1 - h) {
                    geom_sample a, b, c, d;
                    geom_eval(&s, u + h, v, &a);
                    geom_eval(&s, u - h, v, &b);
                    geom_eval(&s, u, v + h, &c);
                    geom_eval(&s, u, v - h, &d);
                    vec3 fu = v3_scale(v3_sub(a.Ng, b.Ng), 1 / (2 * h));
                    vec3 fv = v3_scale(v3_sub(c.Ng, d.Ng), 1 / (2 * h));
                    assert_true(v3_length(v3_sub(fu, g.dNgdu)) < 1e-5 * (1 + v3_length(fu)));
                    assert_true(v3_length(v3_sub(fv, g.dNgdv)) < 1e-5 * (1 + v3_length(fv)));
                }
            }
        }
        printf("%-20s %3d pieces, worst relative difference from de Boor %.2Lg\n", P[k].name,
               geom_nurbs_npieces(nb), worst);
        geom_nurbs_destroy(&nb);
    }
}

/* ---- the exact circle ---- */

static void test_circle(void **state)
{
    (void)state;
    static patch P[8];
    make_patches(P);
    fx_seed(6);
    for (int k = 0; k < 2; k++) {
        geom_nurbs *nb = build(&P[k]);
        assert_int_equal(geom_nurbs_npieces(nb), k == 0 ? 1 : 4);
        double worst = 0;
        for (int pc = 0; pc < geom_nurbs_npieces(nb); pc++) {
            geom_surface s;
            geom_nurbs_surface(nb, pc, &s);
            for (int i = 0; i < 500; i++) {
                geom_sample g;
                double u = fx_unit(), v = fx_unit();
                geom_eval(&s, u, v, &g);
                worst = fmax(worst, fabs(hypot(g.P.x, g.P.y) - 1));
                /* the normal is radial: Ng x (x, y, 0) = 0, and outward
                 * for this orientation (u counter-clockwise, v up) */
                vec3 radial = v3(g.P.x, g.P.y, 0);
                double n = v3_length(g.Ng);
                assert_true(v3_length(v3_cross(g.Ng, radial)) < 1e-12 * n);
                assert_true(v3_dot(g.Ng, radial) > 0);
            }
        }
        printf("%-20s largest | |P.xy| - 1 | = %.2g\n", P[k].name, worst);
        assert_true(worst < 1e-15);
        geom_nurbs_destroy(&nb);
    }
}

/* ---- containment ---- */

typedef struct tally { long boxes, points, violations, unbounded, loose; double worst; } tally;

static double excess(ld x, ia_interval r, ld slack)
{
    if (x < r.lo - slack) return (double)(r.lo - x);
    if (x > r.hi + slack) return (double)(x - r.hi);
    return 0;
}

static void contain_box(const patch *pt, const geom_nurbs *nb, int pc, double u0, double u1,
                        double v0, double v1, int capacity, double size, tally *t)
{
    geom_surface s;
    geom_nurbs_surface(nb, pc, &s);
    aa_context ctx;
    aa_context_init(&ctx, capacity);
    aa_form U, V;
    aa_input(&ctx, &U, u0, u1);
    aa_input(&ctx, &V, v0, v1);
    geom_aa ga;
    geom_eval_aa(&ctx, &s, &U, &V, &ga);
    geom_ia gi;
    geom_eval_ia(&s, ia_make(u0, u1), ia_make(v0, v1), &gi);
    const aa_form *af[4] = { ga.P, ga.dPdu, ga.dPdv, ga.Ng };
    const ia_interval *ir[4] = { gi.P, gi.dPdu, gi.dPdv, gi.Ng };
    ia_interval ar[4][3];
    bool unbounded = false;
    for (int q = 0; q < 4; q++)
        for (int c = 0; c < 3; c++) {
            ar[q][c] = aa_range(&af[q][c]);
            if (!isfinite(ar[q][c].lo) || !isfinite(ar[q][c].hi) ||
                !isfinite(ir[q][c].lo) || !isfinite(ir[q][c].hi))
                unbounded = true;
        }
    t->boxes++;
    t->unbounded += unbounded;
    if (fmax(u1 - u0, v1 - v0) <= 1e-3)
        for (int c = 0; c < 3; c++)
            if (!(ar[0][c].hi - ar[0][c].lo <= 0.01 * size)) t->loose++;
    vec3 lo, hi;
    geom_bounds(&s, &lo, &hi);
    ia_interval br[3] = { ia_make(lo.x, hi.x), ia_make(lo.y, hi.y), ia_make(lo.z, hi.z) };
    for (int k = 0; k < 25; k++) {
        double u = k < 4 ? (k & 1 ? u1 : u0) : u0 + (u1 - u0) * fx_unit();
        double v = k < 4 ? (k & 2 ? v1 : v0) : v0 + (v1 - v0) * fx_unit();
        exact e;
        oracle_piece(pt, nb, pc, u, v, &e);
        for (int q = 0; q < 4; q++) {
            ld slack = 1e-11L * (1 + len3(e.q[q]));
            for (int c = 0; c < 3; c++) {
                double x = fmax(excess(e.q[q][c], ar[q][c], slack),
                                excess(e.q[q][c], ir[q][c], slack));
                if (q == 0) x = fmax(x, excess(e.q[q][c], br[c], slack));
                if (x > 0 || isnan((double)e.q[q][c])) {
                    if (t->violations < 5)
                        printf("  violation: %s piece %d box [%.17g %.17g]x[%.17g %.17g] q%d c%d "
                               "by %g\n", pt->name, pc, u0, u1, v0, v1, q, c, x);
                    t->violations++;
                    t->worst = fmax(t->worst, x);
                }
            }
        }
        t->points++;
    }
}

static void test_containment(void **state)
{
    (void)state;
    static patch P[8];
    int np = make_patches(P);
    fx_seed(7);
    const int caps[3] = { 2, AA_DEFAULT_CAPACITY, AA_MAX_SYMBOLS };
    tally all = { 0 };
    for (int k = 0; k < np; k++) {
        geom_nurbs *nb = build(&P[k]);
        tally t = { 0 };
        vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
        for (int pc = 0; pc < geom_nurbs_npieces(nb); pc++) {
            geom_surface s;
            geom_nurbs_surface(nb, pc, &s);
            vec3 a, b;
            geom_bounds(&s, &a, &b);
            lo = v3(fmin(lo.x, a.x), fmin(lo.y, a.y), fmin(lo.z, a.z));
            hi = v3(fmax(hi.x, b.x), fmax(hi.y, b.y), fmax(hi.z, b.z));
        }
        double size = v3_length(v3_sub(hi, lo));
        int per_piece = 240 / geom_nurbs_npieces(nb) + 20;
        for (int pc = 0; pc < geom_nurbs_npieces(nb); pc++)
            for (int b = 0; b < per_piece; b++) {
                double u0, u1, v0, v1;
                if (b == 0) {
                    u0 = v0 = 0, u1 = v1 = 1;
                } else if (b % 2 == 0) {          /* dyadic, as the renderer's quadtree */
                    double side = ldexp(1, -(int)(fx_unit() * 14));
                    u0 = floor(fx_unit() / side) * side, v0 = floor(fx_unit() / side) * side;
                    u1 = u0 + side, v1 = v0 + side;
                } else {
                    double su = pow(10, -5 * fx_unit()), sv = pow(10, -5 * fx_unit());
                    u0 = (1 - su) * fx_unit(), v0 = (1 - sv) * fx_unit();
                    u1 = u0 + su, v1 = v0 + sv;
                }
                contain_box(&P[k], nb, pc, u0, u1, v0, v1, caps[b % 3], size, &t);
            }
        printf("%-20s %5ld boxes %6ld points: %ld violations (worst %.2g), %ld unbounded, "
               "%ld small boxes wider than 1%%\n", P[k].name, t.boxes, t.points, t.violations,
               t.worst, t.unbounded, t.loose);
        all.violations += t.violations, all.unbounded += t.unbounded, all.loose += t.loose;
        all.boxes += t.boxes;
        geom_nurbs_destroy(&nb);
    }
    assert_true(all.boxes > 1000);
    assert_int_equal(all.violations, 0);
    assert_int_equal(all.unbounded, 0);
    assert_int_equal(all.loose, 0);
}

/* ---- intersection ---- */

static void test_intersect(void **state)
{
    (void)state;
    static patch P[8];
    int np = make_patches(P);
    fx_seed(8);
    int hits = 0, misses = 0;
    for (int k = 0; k < np; k++) {
        geom_nurbs *nb = build(&P[k]);
        for (int pc = 0; pc < geom_nurbs_npieces(nb); pc++) {
            geom_surface s;
            geom_nurbs_surface(nb, pc, &s);
            for (int i = 0; i < 12; i++) {
                double u = 0.05 + 0.9 * fx_unit(), v = 0.05 + 0.9 * fx_unit();
                exact e;
                oracle_piece(&P[k], nb, pc, u, v, &e);
                vec3 target = v3((double)e.q[0][0], (double)e.q[0][1], (double)e.q[0][2]);
                vec3 n = v3((double)e.q[3][0], (double)e.q[3][1], (double)e.q[3][2]);
                n = v3_scale(n, 1 / v3_length(n));
                /* from the front, off the normal by up to ~45 degrees */
                vec3 d = v3_neg(v3_add(n, v3_scale(fx_unit_vector(), 0.7)));
                if (v3_dot(d, n) > -0.3) continue;
                vec3 o = v3_sub(target, v3_scale(d, 3));
                geom_hit h;
                /* the nearest hit is at t = 3 or before it (the patch may
                 * fold in front of the target on curved patches) */
                assert_true(geom_intersect(&s, o, d, 1e-9, INFINITY, &h));
                assert_true(h.t <= 3 + 1e-9);
                geom_sample g;
                geom_eval(&s, h.u, h.v, &g);
                assert_true(v3_length(v3_sub(g.P, v3_add(o, v3_scale(d, h.t)))) < 1e-8);
                if (fabs(h.t - 3) < 1e-9) hits++;
                /* a ray that passes beside the piece's bounds misses */
                vec3 lo, hi;
                geom_bounds(&s, &lo, &hi);
                vec3 far = v3_add(hi, v3(1, 1, 1));
                assert_false(geom_intersect(&s, far, v3(1, 0.3, 0.2), 0, INFINITY, &h));
                misses++;
            }
        }
        geom_nurbs_destroy(&nb);
    }
    printf("intersect: %d rays hit their target, %d rays beside missed\n", hits, misses);
    assert_true(hits > 50);
}

/* ---- errors ---- */

static void expect_error(const patch *pt, const char *want)
{
    geom_nurbs_desc d = { pt->nu, pt->ou, pt->ku, pt->umin, pt->umax,
                          pt->nv, pt->ov, pt->kv, pt->vmin, pt->vmax, pt->Pw };
    char why[256] = "";
    geom_nurbs *nb = geom_nurbs_new(&d, why, sizeof why);
    assert_null(nb);
    if (!strstr(why, want))
        fail_msg("got \"%s\", want \"%s\"", why, want);
}

static void test_errors(void **state)
{
    (void)state;
    static patch P[8];
    make_patches(P);
    patch p = P[0];
    p.Pw[4 * 1 + 3] = 0;
    expect_error(&p, "control point 1 has weight 0: every weight must be > 0");
    p.Pw[4 * 1 + 3] = -0.5;
    expect_error(&p, "control point 1 has weight -0.5");
    p = P[0];
    p.ou = 1;
    expect_error(&p, "uorder must be 2 to 16, got 1");
    p = P[0];
    p.ov = 17;
    expect_error(&p, "vorder must be 2 to 16, got 17");
    p = P[0];
    for (int i = 0; i < 6; i++) {           /* every point on the x axis */
        p.Pw[4 * i + 1] = p.Pw[4 * i + 2] = 0;
        p.Pw[4 * i + 0] = i * p.Pw[4 * i + 3];
    }
    expect_error(&p, "is degenerate: its points lie on one line");
    /* 200 x 200 points of order 16, uniform knots: 185 x 185 pieces of
     * 1024 numbers each, above the limit, refused before allocating */
    enum { NP = 200, O = 16 };
    double *knots = malloc(sizeof(double) * (NP + O)), *pw = malloc(sizeof(double) * 4 * NP * NP);
    assert_non_null(knots);
    assert_non_null(pw);
    for (int k = 0; k < NP + O; k++) knots[k] = k;
    for (int k = 0; k < NP * NP; k++)
        pw[4 * k] = k % NP, pw[4 * k + 1] = k / NP, pw[4 * k + 2] = 0, pw[4 * k + 3] = 1;
    geom_nurbs_desc big = { NP, O, knots, O - 1, NP, NP, O, knots, O - 1, NP, pw };
    char why[256] = "";
    assert_null(geom_nurbs_new(&big, why, sizeof why));
    assert_non_null(strstr(why, "185 x 185 pieces of orders 16 x 16 are too many"));
    free(knots);
    free(pw);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_float),
        cmocka_unit_test(test_circle),
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_intersect),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
