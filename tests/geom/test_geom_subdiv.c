/*
 * test_geom_subdiv.c: Catmull-Clark faces (GEOM_SUBDIV, common/geom/
 * subdiv.h) against independent formulas, and their enclosures:
 *
 * - regular faces of a bumpy grid equal the uniform bicubic B-spline
 *   surface of the control grid (its basis written out here), P and dP/du,
 *   dP/dv, to 1e-12;
 * - the limit of an extraordinary point (valence 3: a cube's corners;
 *   valence 5: the centre of a fan of quads) equals the closed-form limit
 *   mask (n^2 S + 4 sum E + sum F) / (n (n + 5)) on the control mesh; an
 *   infinitely sharp crease's point the crease mask (e1 + 4 S + e2) / 6; a
 *   corner tag keeps its point;
 * - containment: float samples inside random boxes (dyadic, as the
 *   renderer cuts them, and arbitrary) lie in the interval and affine
 *   enclosures of P, and of dPdu, dPdv, Ng where those are bounded, on a
 *   cube (valence 3), a fan (valence 5, boundary, interpolateboundary) and
 *   a cube with infinite, semi-sharp creases and a corner tag: 0 violations;
 *   the same at the corners of every face (boxes 1 .. 2^-9 wide) of a cube
 *   with a creased rim and semi-sharp edges, where the hull of an
 *   irregular sub-face is that of its sectors' points (subdiv_cache.c);
 * - unit normals: at a creased rim's crease points of valence 3 the flat
 *   top's irregular sub-faces get the proven normal (0,0,1) and samples of
 *   Ng/|Ng| lie in the affine and interval unit normals;
 * - watertight: two faces sharing an edge give the same points along it
 *   (1e-12) and, off sharp edges, the same unit normal (1e-7);
 * - bad meshes (an edge with three faces, faces that disagree on the
 *   orientation) are refused with a reason.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "geom/subdiv.h"
#include "geom_fixtures.h"

static unsigned long long rng_state = 0x9e3779b97f4a7c15ULL;
static double urand(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* ---- meshes ---- */

#define CUBE_P FX_CUBE_P

static geom_subdiv *cube(int ncreases, const int *clen, const int *cverts, const double *csharp,
                         int ncorners, const int *corners, const double *csh)
{
    geom_subdiv *sd = fx_subdiv_cube(ncreases, clen, cverts, csharp, ncorners, corners, csh);
    assert_non_null(sd);
    return sd;
}

/* n quads around point 0 (geom_fixtures.c): its points in fan_P */
enum { FAN_MAX = FX_FAN_MAX };   /* valences above 16 too (any valence is taken) */
static const double *fan_P;

static geom_subdiv *fan(int n)
{
    geom_subdiv *sd = fx_subdiv_fan(n, &fan_P);
    assert_non_null(sd);
    return sd;
}

/* one face of n points (a bent disc): after the first step a face point
 * of valence n */
static double ngon_P[3 * FAN_MAX];
static int ngon_V[FAN_MAX];

static geom_subdiv *ngon(int n)
{
    for (int i = 0; i < n; i++) {
        double a = 2 * M_PI * i / n;
        ngon_P[3 * i] = cos(a), ngon_P[3 * i + 1] = sin(a), ngon_P[3 * i + 2] = 0.3 * cos(2 * a);
        ngon_V[i] = i;
    }
    geom_subdiv_desc d = { 1, &n, ngon_V, n, ngon_P, 0, NULL, NULL, NULL,
                           0, NULL, NULL, 0, NULL, true };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) fprintf(stderr, "ngon: %s\n", why);
    assert_non_null(sd);
    return sd;
}

static vec3 pt(const double *P, int i) { return v3(P[3 * i], P[3 * i + 1], P[3 * i + 2]); }

static double dist(vec3 a, vec3 b) { return v3_length(v3_sub(a, b)); }

/* ---- regular faces vs the B-spline surface ---- */

static void bspline(double t, double N[4], double D[4])
{
    double s = 1 - t;
    N[0] = s * s * s / 6;
    N[1] = (3 * t * t * t - 6 * t * t + 4) / 6;
    N[2] = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
    N[3] = t * t * t / 6;
    D[0] = -s * s / 2;
    D[1] = (9 * t * t - 12 * t) / 6;
    D[2] = (-9 * t * t + 6 * t + 3) / 6;
    D[3] = t * t / 2;
}

static void test_regular_faces_are_bsplines(void **state)
{
    (void)state;
    enum { G = 7 };
    double P[3 * G * G];
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            P[3 * (j * G + i)] = i + 0.1 * urand();
            P[3 * (j * G + i) + 1] = j + 0.1 * urand();
            P[3 * (j * G + i) + 2] = urand();
        }
    int nv[(G - 1) * (G - 1)], v[4 * (G - 1) * (G - 1)];
    for (int j = 0; j < G - 1; j++)
        for (int i = 0; i < G - 1; i++) {
            int f = j * (G - 1) + i, *q = v + 4 * f;
            nv[f] = 4;
            q[0] = j * G + i, q[1] = j * G + i + 1, q[2] = (j + 1) * G + i + 1, q[3] = (j + 1) * G + i;
        }
    geom_subdiv_desc d = { (G - 1) * (G - 1), nv, v, G * G, P, 0, NULL, NULL, NULL,
                           0, NULL, NULL, 0, NULL, false };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    assert_non_null(sd);
    static const int QU[4] = { 0, 1, 1, 0 }, QV[4] = { 0, 0, 1, 1 };
    int checked = 0;
    double worst = 0;
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        int F = geom_subdiv_face_origin(sd, f), k = f % 4;
        int fi = F % (G - 1), fj = F / (G - 1);
        assert_true(fi >= 1 && fi <= G - 3 && fj >= 1 && fj <= G - 3);
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        for (int n = 0; n < 20; n++) {
            double u = urand(), w = urand();
            geom_sample g;
            geom_eval(&s, u, w, &g);
            double U = (QU[k] + u) / 2, V = (QV[k] + w) / 2, Nu[4], Du[4], Nv[4], Dv[4];
            bspline(U, Nu, Du);
            bspline(V, Nv, Dv);
            vec3 p = v3(0, 0, 0), pu = p, pv = p;
            for (int b = 0; b < 4; b++)
                for (int a = 0; a < 4; a++) {
                    vec3 c = pt(P, (fj - 1 + b) * G + fi - 1 + a);
                    p = v3_add(p, v3_scale(c, Nu[a] * Nv[b]));
                    pu = v3_add(pu, v3_scale(c, Du[a] * Nv[b] / 2));
                    pv = v3_add(pv, v3_scale(c, Nu[a] * Dv[b] / 2));
                }
            worst = fmax(worst, fmax(dist(p, g.P), fmax(dist(pu, g.dPdu), dist(pv, g.dPdv))));
            checked++;
        }
    }
    printf("regular faces: %d points, worst difference %.3g\n", checked, worst);
    assert_int_equal(checked, 20 * 4 * (G - 3) * (G - 3));
    assert_true(worst < 1e-12);
    geom_subdiv_destroy(&sd);
}

/* ---- limit points vs the masks ---- */

static vec3 smooth_mask(vec3 S, const vec3 *E, const vec3 *F, int n)
{
    vec3 e = v3(0, 0, 0), f = v3(0, 0, 0);
    for (int i = 0; i < n; i++) e = v3_add(e, E[i]), f = v3_add(f, F[i]);
    return v3_scale(v3_add(v3_add(v3_scale(S, (double)n * n), v3_scale(e, 4)), f),
                    1.0 / (n * (n + 5.0)));
}

static void test_limit_points(void **state)
{
    (void)state;
    /* cube corner 6 = (1,1,1): edge neighbours 2, 5, 7; diagonals 1, 3, 4 */
    geom_subdiv *sd = cube(0, NULL, NULL, NULL, 0, NULL, NULL);
    vec3 E[3] = { pt(CUBE_P, 2), pt(CUBE_P, 5), pt(CUBE_P, 7) };
    vec3 F[3] = { pt(CUBE_P, 1), pt(CUBE_P, 3), pt(CUBE_P, 4) };
    vec3 want = smooth_mask(pt(CUBE_P, 6), E, F, 3), got;
    assert_true(geom_subdiv_limit_point(sd, 6, &got));
    printf("valence 3: limit (%.15g %.15g %.15g), mask (%.15g ...)\n", got.x, got.y, got.z,
           want.x);
    assert_true(dist(got, want) < 1e-14);
    geom_subdiv_destroy(&sd);

    /* valence 3, 5, 17 and 40 fans: the centre (above 16 a mesh used to
     * be refused; the local meshes are sized by the mesh's valence) */
    static const int valences[] = { 3, 5, 17, 40 };
    for (int vi = 0; vi < 4; vi++) {
        int n = valences[vi];
        sd = fan(n);
        vec3 e[FAN_MAX], f[FAN_MAX];
        for (int i = 0; i < n; i++) e[i] = pt(fan_P, 1 + 2 * i), f[i] = pt(fan_P, 2 + 2 * i);
        want = smooth_mask(pt(fan_P, 0), e, f, n);
        assert_true(geom_subdiv_limit_point(sd, 0, &got));
        printf("valence %d: |limit - mask| = %.3g\n", n, dist(got, want));
        assert_true(dist(got, want) < 1e-14);
        /* the boundary point E_0 (valence 3 on the boundary): crease mask */
        want = v3_scale(v3_add(v3_add(pt(fan_P, 2), pt(fan_P, 2 * n)),
                               v3_scale(pt(fan_P, 1), 4)), 1.0 / 6);
        assert_true(geom_subdiv_limit_point(sd, 1, &got));
        assert_true(dist(got, want) < 1e-14);
        geom_subdiv_destroy(&sd);
    }

    /* an infinitely sharp crease 0-1-2-3 around the bottom face: point 1
     * takes the crease mask; a corner tag on 6 keeps it where it is */
    int clen[] = { 5 }, cv[] = { 0, 1, 2, 3, 0 }, corner[] = { 6 };
    double cs[] = { 10 }, corner_s[] = { 10 };
    sd = cube(1, clen, cv, cs, 1, corner, corner_s);
    want = v3_scale(v3_add(v3_add(pt(CUBE_P, 0), pt(CUBE_P, 2)), v3_scale(pt(CUBE_P, 1), 4)),
                    1.0 / 6);
    assert_true(geom_subdiv_limit_point(sd, 1, &got));
    assert_true(dist(got, want) < 1e-14);
    assert_true(geom_subdiv_limit_point(sd, 6, &got));
    assert_true(dist(got, pt(CUBE_P, 6)) < 1e-14);
    geom_subdiv_destroy(&sd);
}

/* ---- containment ---- */

typedef struct tally { long boxes, points, violations, unbounded; double worst; } tally;

static double excess(double x, double lo, double hi, double slack)
{
    if (x < lo - slack) return lo - x;
    if (x > hi + slack) return x - hi;
    return 0;
}

static int which_q = -1;
static void check_vec(vec3 p, const ia_interval r[3], double slack, tally *t)
{
    double e = fmax(excess(p.x, r[0].lo, r[0].hi, slack),
                    fmax(excess(p.y, r[1].lo, r[1].hi, slack), excess(p.z, r[2].lo, r[2].hi, slack)));
    if (e > 0 || isnan(p.x + p.y + p.z)) {
        t->violations++;
        if (getenv("SUBDIV_DEBUG")) printf("violation q=%d e=%g p %.17g %.17g %.17g r [%.17g %.17g] [%.17g %.17g] [%.17g %.17g]\n", which_q, e, p.x, p.y, p.z, r[0].lo, r[0].hi, r[1].lo, r[1].hi, r[2].lo, r[2].hi);
        t->worst = fmax(t->worst, e);
    }
}

static bool finite3(const ia_interval r[3])
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(r[i].lo) || !isfinite(r[i].hi)) return false;
    return true;
}

static void contain_face(const geom_surface *s, double u0, double u1, double v0, double v1,
                         tally *t)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form U, V;
    aa_input(&ctx, &U, u0, u1);
    aa_input(&ctx, &V, v0, v1);
    geom_aa ga;
    geom_eval_aa(&ctx, s, &U, &V, &ga);
    geom_ia gi;
    geom_eval_ia(s, ia_make(u0, u1), ia_make(v0, v1), &gi);
    ia_interval ar[4][3];
    for (int i = 0; i < 3; i++) {
        ar[0][i] = aa_range(&ga.P[i]);
        ar[1][i] = aa_range(&ga.dPdu[i]);
        ar[2][i] = aa_range(&ga.dPdv[i]);
        ar[3][i] = aa_range(&ga.Ng[i]);
    }
    const ia_interval *ir[4] = { gi.P, gi.dPdu, gi.dPdv, gi.Ng };
    vec3 lo, hi;
    geom_bounds(s, &lo, &hi);
    ia_interval br[3] = { ia_make(lo.x, hi.x), ia_make(lo.y, hi.y), ia_make(lo.z, hi.z) };
    t->boxes++;
    if (!finite3(ar[1])) t->unbounded++;
    for (int k = 0; k < 25; k++) {
        double u = k < 4 ? (k & 1 ? u1 : u0) : u0 + (u1 - u0) * urand();
        double v = k < 4 ? (k & 2 ? v1 : v0) : v0 + (v1 - v0) * urand();
        geom_sample g;
        geom_eval(s, u, v, &g);
        vec3 vals[4] = { g.P, g.dPdu, g.dPdv, g.Ng };
        for (int q = 0; q < 4; q++) {
            double slack = 1e-11 * (1 + v3_length(vals[q]));
            which_q = q;
            if (getenv("SUBDIV_DEBUG") && q == 0) printf("box %.17g %.17g %.17g %.17g at %.17g %.17g\n", u0, u1, v0, v1, u, v);
            if (finite3(ar[q])) check_vec(vals[q], ar[q], slack, t);
            if (finite3(ir[q])) check_vec(vals[q], ir[q], slack, t);
        }
        check_vec(g.P, br, 1e-11, t);
        t->points++;
    }
}

static void contain_mesh(const char *name, geom_subdiv *sd, int boxes_per_face)
{
    tally t = { 0, 0, 0, 0, 0 };
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        char why[100];
        assert_true(geom_surface_prepare(&s, why, sizeof why));
        for (int b = 0; b < boxes_per_face; b++) {
            double u0, u1, v0, v1;
            if (b % 2 == 0) {          /* dyadic, as the renderer's quadtree */
                int level = (int)(urand() * 12);
                double side = ldexp(1, -level);
                u0 = floor(urand() / side) * side, v0 = floor(urand() / side) * side;
                u1 = u0 + side, v1 = v0 + side;
            } else {
                double su = pow(10, -4 * urand()), sv = pow(10, -4 * urand());
                u0 = (1 - su) * urand(), v0 = (1 - sv) * urand();
                u1 = u0 + su, v1 = v0 + sv;
            }
            contain_face(&s, u0, u1, v0, v1, &t);
        }
    }
    printf("%-14s %6ld boxes (%ld with unbounded derivatives) %7ld points, %ld violations "
           "(worst %.3g)\n", name, t.boxes, t.unbounded, t.points, t.violations, t.worst);
    assert_int_equal(t.violations, 0);
    assert_true(t.boxes > 0);
}

/* The boxes at the corners of every face, 2^-level wide (level 0..9):
 * the renderer's boxes around an irregular point, which the hull of the
 * points the sub-face depends on (its sectors, subdiv_cache.c) bounds. */
static void contain_corners(const char *name, geom_subdiv *sd)
{
    tally t = { 0, 0, 0, 0, 0 };
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        char why[100];
        assert_true(geom_surface_prepare(&s, why, sizeof why));
        for (int level = 0; level < 10; level++)
            for (int k = 0; k < 4; k++) {
                double side = ldexp(1, -level);
                double u0 = k & 1 ? 1 - side : 0, v0 = k & 2 ? 1 - side : 0;
                contain_face(&s, u0, u0 + side, v0, v0 + side, &t);
            }
    }
    printf("%-14s %6ld boxes (%ld with unbounded derivatives) %7ld points, %ld violations "
           "(worst %.3g)\n", name, t.boxes, t.unbounded, t.points, t.violations, t.worst);
    assert_int_equal(t.violations, 0);
    assert_true(t.unbounded > 0);              /* irregular sub-faces were met */
}

static void test_containment(void **state)
{
    (void)state;
    geom_subdiv *sd = cube(0, NULL, NULL, NULL, 0, NULL, NULL);
    contain_mesh("cube", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = fan(5);
    contain_mesh("fan 5", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = fan(3);
    contain_mesh("fan 3", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = fan(24);
    contain_mesh("fan 24", sd, 20);
    contain_corners("fan 24", sd);
    geom_subdiv_destroy(&sd);
    sd = ngon(20);
    contain_mesh("20-gon", sd, 20);
    geom_subdiv_destroy(&sd);
    int clen[] = { 5, 2 }, cv[] = { 0, 1, 2, 3, 0,  4, 5 }, corner[] = { 6 };
    double cs[] = { 10, 1.5 }, corner_s[] = { 10 };
    sd = cube(2, clen, cv, cs, 1, corner, corner_s);
    contain_mesh("creased cube", sd, 60);
    geom_subdiv_destroy(&sd);
}

/* Sectors: infinitely sharp edges cut a vertex's faces into sectors that
 * do not feed each other; finite sharpness does not cut. A cube whose top
 * rim is infinitely sharp (its corners: crease points of valence 3, as in
 * scenes/subdiv.rib) and whose vertical edges 4-0 and 6-2 are semi-sharp
 * (2.5: still 1.5 and 0.5 after the first steps), and a corner tag: a hull
 * that took a semi-sharp edge for a cut, or ignored a cut's far side where
 * it feeds, leaves points outside. */
static void test_sector_hulls(void **state)
{
    (void)state;
    int clen[] = { 5, 2, 2 }, cv[] = { 4, 5, 6, 7, 4,  4, 0,  6, 2 }, corner[] = { 1 };
    double cs[] = { 10, 2.5, 2.5 }, corner_s[] = { 10 };
    geom_subdiv *sd = cube(3, clen, cv, cs, 1, corner, corner_s);
    contain_corners("sectors", sd);
    contain_mesh("sectors", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = cube(0, NULL, NULL, NULL, 0, NULL, NULL);
    contain_corners("cube corners", sd);
    geom_subdiv_destroy(&sd);
}

/* The unit normal at the crease points of valence 3 of a cube's creased
 * rim: the flat top is one face there, extraordinary at every level; its
 * points all have z = 1, so the unit normal of its irregular sub-faces is
 * proven to be (0,0,1) (subdiv_cache.c) where Ng is unbounded. Samples of
 * Ng/|Ng| in corner boxes of every face (1 .. 2^-19 wide) lie in
 * geom_unit_normal_aa and _ia, and the proven normal
 * is used (a box whose Ng is unbounded gets a normal narrower than
 * [-1,1]^3). A wrong sign, axis or a sector that takes in the sides fails. */
static void test_corner_normals(void **state)
{
    (void)state;
    int clen[] = { 5 }, cv[] = { 4, 5, 6, 7, 4 };
    double cs[] = { 10 };
    geom_subdiv *sd = cube(1, clen, cv, cs, 0, NULL, NULL);
    tally t = { 0, 0, 0, 0, 0 };
    long proven = 0;
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        char why[100];
        assert_true(geom_surface_prepare(&s, why, sizeof why));
        for (int level = 0; level < 20; level++)
            for (int k = 0; k < 4; k++) {
                double side = ldexp(1, -level);
                double u0 = k & 1 ? 1 - side : 0, v0 = k & 2 ? 1 - side : 0;
                double u1 = u0 + side, v1 = v0 + side;
                aa_context ctx;
                aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
                aa_form U, V, Nn[3];
                aa_input(&ctx, &U, u0, u1);
                aa_input(&ctx, &V, v0, v1);
                geom_aa ga;
                geom_eval_aa(&ctx, &s, &U, &V, &ga);
                geom_unit_normal_aa(&ctx, &s, &U, &V, &ga, Nn);
                geom_ia gi;
                ia_interval Ni[3], Na[3];
                geom_eval_ia(&s, ia_make(u0, u1), ia_make(v0, v1), &gi);
                geom_unit_normal_ia(&s, ia_make(u0, u1), ia_make(v0, v1), &gi, Ni);
                for (int i = 0; i < 3; i++) Na[i] = aa_range(&Nn[i]);
                t.boxes++;
                if (!finite3(gi.Ng)) {
                    t.unbounded++;
                    if (Ni[0].hi - Ni[0].lo < 1 && Na[0].hi - Na[0].lo < 1) proven++;
                }
                for (int n = 0; n < 12; n++) {
                    double u = n < 4 ? (n & 1 ? u1 : u0) : u0 + side * urand();
                    double v = n < 4 ? (n & 2 ? v1 : v0) : v0 + side * urand();
                    geom_sample g;
                    geom_eval(&s, u, v, &g);
                    double len = v3_length(g.Ng);
                    if (!(len > 0) || !isfinite(len)) continue;
                    /* within 2^-20 of a corner a float sample comes from a
                     * sub-patch deeper than level 20, whose derivatives
                     * (scaled by 2^level) carry the refinement's rounding
                     * amplified toward Ng's size near the crease point (its
                     * normal tilts by 1e-9 at 2^-22, 1e-6 at 2^-26; past
                     * 2^-28 Ng_z is noise of either sign): no reference */
                    double cu = fmin(u, 1 - u), cvv = fmin(v, 1 - v);
                    if (cu < 0x1p-20 && cvv < 0x1p-20) continue;
                    /* and farther out it still tilts by up to ~1e-5 (deep
                     * nets are planar only to rounding, and Ng is small):
                     * a slack of 1e-4, far below what a wrong sign (2) or
                     * axis (1) would miss by */
                    double slack = 1e-4;
                    vec3 N = v3_scale(g.Ng, 1 / len);
                    check_vec(N, Na, slack, &t);
                    check_vec(N, Ni, slack, &t);
                    t.points++;
                }
            }
    }
    printf("%-14s %6ld boxes (%ld with unbounded Ng, %ld of them with a proven normal) "
           "%7ld points, %ld violations (worst %.3g)\n", "corner normals", t.boxes,
           t.unbounded, proven, t.points, t.violations, t.worst);
    assert_int_equal(t.violations, 0);
    assert_true(proven > 0);
    geom_subdiv_destroy(&sd);
}

/* ---- shared edges ---- */

static void edge_param(int k, double t, double *u, double *v)
{
    switch (k) {
    case 0: *u = t, *v = 0; break;
    case 1: *u = 1, *v = t; break;
    case 2: *u = 1 - t, *v = 1; break;
    default: *u = 0, *v = 1 - t; break;
    }
}

static void watertight(geom_subdiv *sd, bool normals, int *pairs, double *worst_p,
                       double *worst_n)
{
    int nf = geom_subdiv_nfaces(sd);
    for (int f = 0; f < nf; f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        int a[4];
        geom_subdiv_face_points(sd, f, a);
        for (int g = 0; g < nf; g++) {
            if (g == f || !geom_subdiv_face_drawn(sd, g)) continue;
            int b[4];
            geom_subdiv_face_points(sd, g, b);
            for (int k = 0; k < 4; k++)
                for (int j = 0; j < 4; j++) {
                    if (!(a[k] == b[(j + 1) % 4] && a[(k + 1) % 4] == b[j])) continue;
                    geom_surface s, r;
                    geom_subdiv_surface(sd, f, &s);
                    geom_subdiv_surface(sd, g, &r);
                    for (int i = 1; i < 16; i++) {
                        double t = i / 16.0 + 0.01 * urand(), u, v, x, y;
                        edge_param(k, t, &u, &v);
                        edge_param(j, 1 - t, &x, &y);
                        geom_sample p, q;
                        geom_eval(&s, u, v, &p);
                        geom_eval(&r, x, y, &q);
                        *worst_p = fmax(*worst_p, dist(p.P, q.P));
                        if (normals)
                            *worst_n = fmax(*worst_n, dist(v3_normalize(p.Ng),
                                                           v3_normalize(q.Ng)));
                    }
                    (*pairs)++;
                }
        }
    }
}

static void test_shared_edges(void **state)
{
    (void)state;
    geom_subdiv *sd = cube(0, NULL, NULL, NULL, 0, NULL, NULL);
    int pairs = 0;
    double wp = 0, wn = 0;
    watertight(sd, true, &pairs, &wp, &wn);
    printf("cube: %d shared edges, worst point gap %.3g, normal gap %.3g\n", pairs, wp, wn);
    assert_int_equal(pairs, 24 * 4);           /* 48 edges, each seen from both faces */
    assert_true(wp < 1e-12);
    assert_true(wn < 1e-7);
    geom_subdiv_destroy(&sd);
    sd = fan(5);
    pairs = 0, wp = wn = 0;
    watertight(sd, true, &pairs, &wp, &wn);
    printf("fan 5: %d shared edges, worst point gap %.3g, normal gap %.3g\n", pairs, wp, wn);
    assert_true(pairs > 0 && wp < 1e-12 && wn < 1e-7);
    geom_subdiv_destroy(&sd);
    int clen[] = { 5 }, cv[] = { 0, 1, 2, 3, 0 };
    double cs[] = { 10 };
    sd = cube(1, clen, cv, cs, 0, NULL, NULL);
    pairs = 0, wp = wn = 0;
    watertight(sd, false, &pairs, &wp, &wn);
    assert_true(pairs > 0 && wp < 1e-12);
    geom_subdiv_destroy(&sd);
}

/* ---- bad meshes ---- */

static void test_bad_meshes(void **state)
{
    (void)state;
    char why[200];
    static const double P[] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1 };
    static const int nv[] = { 3, 3, 3 };
    static const int three[] = { 0, 1, 2,  1, 0, 4,  0, 1, 5 };
    geom_subdiv_desc d = { 3, nv, three, 6, P, 0, NULL, NULL, NULL, 0, NULL, NULL, 0, NULL, true };
    assert_null(geom_subdiv_new(&d, why, sizeof why));
    printf("%s\n", why);
    assert_non_null(strstr(why, "has 3 faces"));
    static const int flipped[] = { 0, 1, 2,  0, 1, 4 };
    d.nfaces = 2;
    d.verts = flipped;
    assert_null(geom_subdiv_new(&d, why, sizeof why));
    printf("%s\n", why);
    assert_non_null(strstr(why, "the same way"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_regular_faces_are_bsplines),
        cmocka_unit_test(test_limit_points),
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_sector_hulls),
        cmocka_unit_test(test_corner_normals),
        cmocka_unit_test(test_shared_edges),
        cmocka_unit_test(test_bad_meshes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
