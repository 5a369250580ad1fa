/*
 * tests/geom/test_geom_intersect.c: exact ray intersection (geom_intersect).
 *
 *   aimed      every fixture, 400 random surface points (from geom_eval), a
 *              ray o + t d with o = P - d, so the point is at t = 1. Four ray
 *              families: steep (|cos| >= 0.2 to the normal), grazing at 1e-2
 *              and 1e-5 radians, and exactly tangent (along a direction in
 *              which the surface curves; flat kinds take 1e-3 instead). The
 *              test walks the hits in order (tmin just past the previous
 *              one): every hit must be real (P(u,v) on the ray, (u,v) in the
 *              domain) and the walk must reach t = 1 with the point's (u,v)
 *              (seams and poles allowed for). Misses are counted; 0 expected.
 *   misses     rays that miss geom_bounds' box (slab test) do not hit
 *   sweeps     rays along the normal through points of the cut-away part of
 *              a partial sweep (theta, and zmin/zmax/phi where the kind has
 *              them) or outside a polygon pass through; the complete surface
 *              is hit there (so the ray is meaningful)
 *   interval   hits honour (tmin, tmax): none at or beyond tmax, none at or
 *              before tmin
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "geom_fixtures.h"

#define TWO_PI 6.283185307179586

static bool full_sweep(double sweep)
{
    return fabs(sweep) >= TWO_PI * (1 - 1e-12);
}

/* parameter distance weighted by |dPdu|, |dPdv| (so poles and apexes,
 * where u means nothing, do not count), with the seams of full sweeps */
static double param_dist(const geom_surface *s, const geom_sample *g, double u1,
                         double v1, double u2, double v2)
{
    double du = fabs(u1 - u2), dv = fabs(v1 - v2);
    if (s->kind != GEOM_POLYGON && s->kind != GEOM_PATCH && s->kind != GEOM_BICUBIC && full_sweep(s->thetamax))
        du = fmin(du, 1 - du);
    if (s->kind == GEOM_TORUS && full_sweep(s->phimax - s->phimin))
        dv = fmin(dv, 1 - dv);
    return du * v3_length(g->dPdu) + dv * v3_length(g->dPdv);
}

static bool random_point(const geom_surface *s, double *u, double *v)
{
    for (int i = 0; i < 1000; i++) {
        *u = fx_unit();
        *v = fx_range(0.002, 0.998);
        if (geom_uv_inside(s, *u, *v))
            return true;
    }
    return false;
}

/* curvature of the surface along the unit tangent T at (u,v), numerically */
static double normal_curvature(const geom_surface *s, const geom_sample *g, vec3 N,
                               double u, double v, vec3 T)
{
    /* T = a dPdu + b dPdv: solve in the tangent plane */
    vec3 pu = g->dPdu, pv = g->dPdv;
    double e = v3_dot(pu, pu), f = v3_dot(pu, pv), gg = v3_dot(pv, pv);
    double tu = v3_dot(T, pu), tv = v3_dot(T, pv), det = e * gg - f * f;
    double a = (tu * gg - tv * f) / det, b = (tv * e - tu * f) / det, h = 1e-4;
    geom_sample p, m;
    geom_eval(s, u + a * h, v + b * h, &p);
    geom_eval(s, u - a * h, v - b * h, &m);
    vec3 second = v3_scale(v3_add(v3_sub(p.P, g->P), v3_sub(m.P, g->P)), 1 / (h * h));
    return v3_dot(second, N);
}

typedef struct walk_stats { long rays, found, missed, fake, skipped; } walk_stats;

/* all hits from tmin up to the target at t = 1 */
static void walk(const fx_surface *f, double u, double v, const geom_sample *g,
                 vec3 o, vec3 d, double tol_t, walk_stats *st)
{
    const geom_surface *s = &f->s;
    double tmin = 1e-9, tol_p = 1e-6 * f->size;
    st->rays++;
    for (int step = 0; step < 8; step++) {
        geom_hit h;
        if (!geom_intersect(s, o, d, tmin, 1 + tol_t, &h))
            break;
        geom_sample gh;
        geom_eval(s, h.u, h.v, &gh);
        vec3 on_ray = v3_add(o, v3_scale(d, h.t));
        if (!(v3_length(v3_sub(gh.P, on_ray)) <= 1e-7 * f->size) ||
            !(h.u >= 0 && h.u <= 1 && h.v >= 0 && h.v <= 1) || !geom_uv_inside(s, h.u, h.v)) {
            if (st->fake++ < 5)
                print_message("  %s: fake hit t %.17g (u,v) (%g, %g), %g off the ray\n",
                              f->name, h.t, h.u, h.v, v3_length(v3_sub(gh.P, on_ray)));
            return;
        }
        if (fabs(h.t - 1) <= tol_t &&
            (param_dist(s, g, h.u, h.v, u, v) <= tol_p ||
             v3_length(v3_sub(gh.P, g->P)) <= tol_p)) {
            st->found++;
            return;
        }
        if (!(h.t > tmin))
            break;
        tmin = h.t;
    }
    if (st->missed++ < 8)
        print_message("  %s: missed the point (u,v) = (%.17g, %.17g), o (%.17g %.17g %.17g) "
                      "d (%.17g %.17g %.17g)\n",
                      f->name, u, v, o.x, o.y, o.z, d.x, d.y, d.z);
}

/* a unit tangent at the point: the circumferential one for the quadrics
 * (never a ruling), a random one for polygons and patches */
static vec3 tangent(const geom_surface *s, const geom_sample *g, vec3 N)
{
    vec3 t = s->kind == GEOM_POLYGON || s->kind == GEOM_PATCH || s->kind == GEOM_BICUBIC
             ? v3_add(v3_scale(v3_normalize(g->dPdu), fx_range(-1, 1)),
                      v3_scale(v3_normalize(g->dPdv), fx_range(-1, 1)))
             : g->dPdu;
    t = v3_sub(t, v3_scale(N, v3_dot(N, t)));
    return v3_normalize(t);
}

static void test_aimed(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    walk_stats all[4] = { { 0 } };
    static const char *const family[4] = { "steep", "grazing 1e-2", "grazing 1e-5",
                                           "tangent" };
    fx_seed(21);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        for (int i = 0; i < 400; i++) {
            double u, v;
            assert_true(random_point(s, &u, &v));
            geom_sample g;
            geom_eval(s, u, v, &g);
            if (!(v3_length(g.Ng) > 1e-9 * fx[k].size * fx[k].size)) {
                all[i % 4].skipped++;
                continue;
            }
            vec3 N = v3_normalize(g.Ng), dir;
            double side = fx_unit() < 0.5 ? -1 : 1, tol_t = 1e-9;
            int fam = i % 4;
            if (fam == 0) {
                do
                    dir = fx_unit_vector();
                while (fabs(v3_dot(dir, N)) < 0.2);
            } else {
                vec3 T = tangent(s, &g, N);
                double eps = fam == 1 ? 1e-2 : fam == 2 ? 1e-5 : 0;
                if (fam == 3 && fabs(normal_curvature(s, &g, N, u, v, T)) < 0.05 / fx[k].size)
                    eps = 1e-3;                  /* flat in that direction */
                dir = v3_normalize(v3_add(T, v3_scale(N, side * eps)));
                tol_t = fam == 3 ? 1e-5 : 1e-7;
            }
            vec3 d = v3_scale(dir, fx[k].size * fx_range(0.5, 4));
            walk(&fx[k], u, v, &g, v3_sub(g.P, d), d, tol_t, &all[fam]);
        }
    }
    long missed = 0, fake = 0;
    for (int f = 0; f < 4; f++) {
        printf("%-13s rays %5ld: found %5ld, missed %ld, fake hits %ld (degenerate skipped %ld)\n",
               family[f], all[f].rays, all[f].found, all[f].missed, all[f].fake,
               all[f].skipped);
        missed += all[f].missed;
        fake += all[f].fake;
        assert_true(all[f].rays > 1000);
    }
    assert_int_equal(missed, 0);
    assert_int_equal(fake, 0);
}

/* slab test: does o + t d, t > 0, meet the box? */
static bool ray_meets_box(vec3 o, vec3 d, vec3 lo, vec3 hi)
{
    double t0 = 0, t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double oi = v3_comp(o, i), di = v3_comp(d, i);
        double a = v3_comp(lo, i), b = v3_comp(hi, i);
        if (di == 0) {
            if (oi < a || oi > b)
                return false;
            continue;
        }
        double ta = (a - oi) / di, tb = (b - oi) / di;
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        t0 = fmax(t0, ta);
        t1 = fmin(t1, tb);
    }
    return t0 <= t1;
}

static void test_misses(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    long tried = 0, hits_outside = 0, real_hits = 0;
    fx_seed(22);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        vec3 lo, hi;
        geom_bounds(s, &lo, &hi);
        vec3 c = v3_scale(v3_add(lo, hi), 0.5);
        double diag = v3_length(v3_sub(hi, lo));
        int misses = 0;
        for (int i = 0; i < 2000 && misses < 200; i++) {
            vec3 o = v3_add(c, v3_scale(fx_unit_vector(), diag * fx_range(0.6, 3)));
            vec3 d = v3_scale(fx_unit_vector(), fx_range(0.1, 10));
            if (i % 2)                    /* aimed into the box: hits to check */
                d = v3_sub(v3(fx_range(lo.x, hi.x), fx_range(lo.y, hi.y),
                              fx_range(lo.z, hi.z)), o);
            geom_hit h;
            bool hit = geom_intersect(s, o, d, 0, INFINITY, &h);
            if (ray_meets_box(o, d, lo, hi)) {
                real_hits += hit;
                continue;
            }
            misses++;
            tried++;
            if (hit && hits_outside++ < 5)
                print_message("  %s: hit at t %g although the ray misses the bounds\n",
                              fx[k].name, h.t);
        }
        assert_true(misses >= 100);
    }
    printf("%ld rays missing the bounds: %ld hits (and %ld hits of rays meeting them)\n",
           tried, hits_outside, real_hits);
    assert_int_equal(hits_outside, 0);
    assert_true(real_hits > 500);
}

/* (u,v) on the complete surface `full` of a point in the part that `s`
 * cuts away, or false when s cuts nothing of that kind */
static bool cut_point(const geom_surface *s, geom_surface *full, int mode, double *u,
                      double *v)
{
    const double m = 0.03;
    *full = *s;
    if (mode == 0) {                               /* theta */
        if (s->kind == GEOM_POLYGON || s->kind == GEOM_PATCH || s->kind == GEOM_BICUBIC || full_sweep(s->thetamax))
            return false;
        full->thetamax = s->thetamax > 0 ? TWO_PI : -TWO_PI;
        double a = fabs(s->thetamax) / TWO_PI;
        *u = fx_range(a + m, 1 - m);
        *v = fx_range(m, 1 - m);
        return true;
    }
    *u = fx_range(m, 1 - m);                       /* inside the theta sweep */
    switch (s->kind) {
    case GEOM_SPHERE: {                            /* outside zmin..zmax */
        full->zmin = -s->radius;
        full->zmax = s->radius;
        /* the ends in either order (RI spec §5.2: zmin > zmax sweeps down) */
        double lo = (fmin(s->phi0, s->phi1) + M_PI_2) / M_PI;
        double hi = (fmax(s->phi0, s->phi1) + M_PI_2) / M_PI;
        if (lo < m && hi > 1 - m)
            return false;
        *v = lo >= m && (hi > 1 - m || fx_unit() < 0.5) ? fx_range(0, lo - m)
                                                          : fx_range(hi + m, 1);
        return *v >= 0 && *v <= 1;
    }
    case GEOM_CYLINDER: {                          /* beyond zmax, below zmin */
        double lo = fmin(s->zmin, s->zmax), hi = fmax(s->zmin, s->zmax);
        full->zmin = lo - 1;
        full->zmax = hi + 1;
        *v = fx_unit() < 0.5 ? fx_range(0, 1 / (hi - lo + 2) - m)
                             : fx_range(1 - 1 / (hi - lo + 2) + m, 1);
        return true;
    }
    case GEOM_PARABOLOID: {                        /* below the lower end */
        double lo = fmin(s->zmin, s->zmax);
        if (lo == 0)
            return false;
        full->zmin = 0;
        *v = fx_range(0.01, lo / s->zmax - m);
        return true;
    }
    case GEOM_TORUS: {                             /* outside phimin..phimax */
        if (full_sweep(s->phimax - s->phimin))
            return false;
        full->phimin = s->phimin;
        full->phimax = s->phimin + (s->phimax > s->phimin ? TWO_PI : -TWO_PI);
        double a = fabs(s->phimax - s->phimin) / TWO_PI;
        *v = fx_range(a + m, 1 - m);
        return true;
    }
    default:
        return false;
    }
}

static void test_sweeps(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    long rays = 0, wrong = 0, poly_rays = 0;
    fx_seed(23);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        for (int i = 0; i < 200; i++) {
            geom_surface full;
            double u, v;
            if (s->kind == GEOM_POLYGON) {             /* outside the polygon */
                full = *s;
                u = fx_unit();
                v = fx_unit();
                bool near = false;
                for (int e = 0; e < s->nuv; e++)       /* keep a margin */
                    for (double du = -0.02; du <= 0.02; du += 0.02)
                        for (double dv = -0.02; dv <= 0.02; dv += 0.02)
                            near |= geom_uv_inside(s, u + du, v + dv);
                if (near)
                    continue;
                poly_rays++;
            } else {
                if (!cut_point(s, &full, i % 2, &u, &v))
                    continue;
                char why[200];
                assert_true(geom_surface_prepare(&full, why, sizeof why));
            }
            geom_sample g;
            geom_eval(&full, u, v, &g);
            vec3 d = v3_scale(v3_normalize(g.Ng), (fx_unit() < 0.5 ? -1 : 1) * fx[k].size);
            vec3 o = v3_sub(g.P, d);
            geom_hit h;
            rays++;
            bool through = !geom_intersect(s, o, d, 0.98, 1.02, &h);
            if (s->kind != GEOM_POLYGON && !geom_intersect(&full, o, d, 0.98, 1.02, &h))
                fail_msg("%s: the complete surface is not hit at (%g, %g)", fx[k].name, u, v);
            if (!through && wrong++ < 5)
                print_message("  %s: hit at t %g in the cut-away part (%g, %g)\n",
                              fx[k].name, h.t, u, v);
        }
    }
    printf("%ld rays through cut-away parts (%ld outside polygons): %ld hit\n", rays,
           poly_rays, wrong);
    assert_int_equal(wrong, 0);
    assert_true(rays > 1000 && poly_rays > 50);
}

static void test_interval(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    long checked = 0;
    fx_seed(24);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        for (int i = 0; i < 200; i++) {
            double u, v;
            assert_true(random_point(s, &u, &v));
            geom_sample g;
            geom_eval(s, u, v, &g);
            vec3 d = v3_scale(fx_unit_vector(), fx[k].size);
            vec3 o = v3_sub(g.P, d);
            geom_hit h, h2;
            if (!geom_intersect(s, o, d, 0, INFINITY, &h))
                continue;
            checked++;
            assert_true(h.t > 0 && h.t <= 1 + 1e-9);
            double below = h.t * (1 - 1e-9), above = h.t * (1 + 1e-9);
            if (geom_intersect(s, o, d, 0, below, &h2))      /* nothing nearer */
                fail_msg("%s: a hit at t %.17g before the nearest one at %.17g",
                         fx[k].name, h2.t, h.t);
            if (geom_intersect(s, o, d, above, INFINITY, &h2)) /* strictly farther */
                assert_true(h2.t > above);
            if (geom_intersect(s, o, d, 0, h.t, &h2))        /* tmax is exclusive */
                assert_true(h2.t < h.t);
            assert_false(geom_intersect(s, o, d, 2, 1, &h2)); /* empty interval */
        }
    }
    printf("%ld rays checked against their (tmin, tmax)\n", checked);
    assert_true(checked > 1000);
}

static void test_bad_rays(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    for (int k = 0; k < n; k++) {
        geom_hit h;
        assert_false(geom_intersect(&fx[k].s, v3(0, 0, 5), v3(0, 0, 0), 0, INFINITY, &h));
        assert_false(geom_intersect(&fx[k].s, v3(NAN, 0, 5), v3(0, 0, -1), 0, INFINITY, &h));
        assert_false(geom_intersect(&fx[k].s, v3(0, 0, 5), v3(INFINITY, 0, -1), 0, INFINITY, &h));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_aimed),
        cmocka_unit_test(test_misses),
        cmocka_unit_test(test_sweeps),
        cmocka_unit_test(test_interval),
        cmocka_unit_test(test_bad_rays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
