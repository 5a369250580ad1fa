/*
 * tests/geom/test_geom_same_bits.c: the short paths of the polygon code
 * (issue 23: a mesh's faces are prepared and bounded millions of times)
 * give the very bits of the general ones they replace, so no image moves.
 *
 *   minmax      geom_min / geom_max against libm's fmin / fmax: signed
 *               zeros in both orders, infinities, (quiet) NaN on either side,
 *               random numbers of random signs and magnitudes, and equal
 *               pairs
 *   bounds      a polygon's geom_bounds is the hull of geom_eval_ia's P (its
 *               formula, spelled out) at its vertices' (u,v), padded as
 *               before, for random convex polygons (triangles to 12
 *               corners, random planes, sizes from 1e-140 to 1e140)
 *   ng          the polygon's Ng constants are ia_mul's products of the
 *               axes as point intervals, for the same polygons
 *   basis       geom_polygon_basis's basis and (u,v) are the prepare's, and
 *               the corners kept are those a root at every pair keeps,
 *               for polygons with corners repeated near the threshold
 *   patch slab  geom_intersect on a bilinear patch (which first rejects
 *               rays that start beyond the patch's slab and head away)
 *               gives geom_patch_solve's answer (the general solve alone)
 *               to the bit: hit or miss, t, u and v, for flat, trapezoid
 *               and twisted patches at scales 1e-3 to 1e3, on shadow-like
 *               rays leaving the patch (0 to 1e-3 of its size off it,
 *               down to 1e-9 radians off its plane), rays aimed at it and
 *               random rays (the aimed rays must hit, the leaving ones
 *               mostly miss)
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "geom_fixtures.h"
#include "geom/surface_internal.h"

static uint64_t bits_of(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static double of_bits(uint64_t b)
{
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

/* the same bits, or both NaN (fmin of two NaNs is some NaN) */
static void expect_same(double got, double want, const char *what, double x, double y)
{
    if (isnan(got) && isnan(want))
        return;
    if (bits_of(got) != bits_of(want))
        fail_msg("%s(%a, %a): %a (bits %016llx), libm gives %a (bits %016llx)", what, x, y, got,
                 (unsigned long long)bits_of(got), want, (unsigned long long)bits_of(want));
}

static void check_pair(double x, double y)
{
    expect_same(geom_min(x, y), fmin(x, y), "geom_min", x, y);
    expect_same(geom_max(x, y), fmax(x, y), "geom_max", x, y);
}

/* random bits; a NaN made quiet (arithmetic never makes a signalling one,
 * which libm's fmin turns into a NaN result) */
static uint64_t rnd_bits(void)
{
    uint64_t b = (uint64_t)(fx_unit() * 4294967296.0) << 32 | (uint64_t)(fx_unit() * 4294967296.0);
    if (isnan(of_bits(b)))
        b |= (uint64_t)1 << 51;
    return b;
}

static void test_minmax(void **state)
{
    (void)state;
    const double special[] = {0.0, -0.0, 1.0, -1.0, INFINITY, -INFINITY, NAN, -NAN,
                              0x1p-1074, -0x1p-1074, 0x1.fffffffffffffp+1023, 1e-300, -2.5};
    int ns = (int)(sizeof special / sizeof special[0]);
    for (int i = 0; i < ns; i++)
        for (int j = 0; j < ns; j++)
            check_pair(special[i], special[j]);
    fx_seed(23);
    for (int k = 0; k < 200000; k++) {
        double x = of_bits(rnd_bits()), y = of_bits(rnd_bits());
        check_pair(x, y);
        double a = fx_range(-4, 4), b = k % 3 == 0 ? a : k % 3 == 1 ? -a : fx_range(-4, 4);
        check_pair(a, b);
        check_pair(b, a);
    }
}

/* a random convex polygon of n corners: points on an ellipse in a random
 * plane, at a random place and scale (one in three from 1e-140 to 1e140:
 * products near underflow and overflow) */
static geom_surface random_polygon(int k)
{
    int n = 3 + k % 10;
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_POLYGON;
    s.nverts = n;
    vec3 e1 = fx_unit_vector(), t = fx_unit_vector();
    vec3 e2 = v3_normalize(v3_cross(e1, t));
    double scale = pow(10, k % 3 == 0 ? fx_range(-140, 140) : fx_range(-3, 3));
    double ra = scale * fx_range(0.2, 1), rb = scale * fx_range(0.2, 1);
    double far = k % 3 == 0 ? scale : 1;
    vec3 c = v3_scale(v3(fx_range(-100, 100), fx_range(-100, 100), fx_range(-100, 100)), far);
    double phase = fx_range(0, 6.283185307179586);
    for (int i = 0; i < n; i++) {
        double a = phase + 6.283185307179586 * (i + fx_range(-0.3, 0.3)) / n;
        s.verts[i] = v3_add(c, v3_add(v3_scale(e1, ra * cos(a)), v3_scale(e2, rb * sin(a))));
    }
    return s;
}

static void test_bounds(void **state)
{
    (void)state;
    fx_seed(2323);
    int tried = 0;
    for (int k = 0; k < 20000; k++) {
        geom_surface s = random_polygon(k);
        if (!geom_surface_prepare(&s, NULL, 0))
            continue;
        tried++;
        vec3 lo, hi;
        geom_bounds(&s, &lo, &hi);
        /* the old path: geom_eval_ia's polygon P (spelled out here, so
         * that a change there shows) at each vertex, fmin/fmax */
        vec3 wlo = v3(INFINITY, INFINITY, INFINITY), whi = v3(-INFINITY, -INFINITY, -INFINITY);
        for (int i = 0; i < s.nuv; i++) {
            geom_ia box;
            geom_eval_ia(&s, ia_point(s.uv[i][0]), ia_point(s.uv[i][1]), &box);
            ia_interval u = ia_point(s.uv[i][0]), v = ia_point(s.uv[i][1]);
            for (int c = 0; c < 3; c++) {
                double au = v3_comp(s.axis_u, c), av = v3_comp(s.axis_v, c);
                ia_interval P = ia_add_s(ia_add(ia_mul_s(u, au), ia_mul_s(v, av)),
                                         v3_comp(s.origin, c));
                if (bits_of(P.lo) != bits_of(box.P[c].lo) || bits_of(P.hi) != bits_of(box.P[c].hi))
                    fail_msg("polygon %d: geom_eval_ia's P[%d] at vertex %d is not the formula's",
                             k, c, i);
            }
            wlo = v3(fmin(wlo.x, box.P[0].lo), fmin(wlo.y, box.P[1].lo), fmin(wlo.z, box.P[2].lo));
            whi = v3(fmax(whi.x, box.P[0].hi), fmax(whi.y, box.P[1].hi), fmax(whi.z, box.P[2].hi));
        }
        double pad = 1e-9 * (v3_length(s.axis_u) + v3_length(s.axis_v));
        wlo = v3_sub(wlo, v3(pad, pad, pad));
        whi = v3_add(whi, v3(pad, pad, pad));
        double got[6] = {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z};
        double want[6] = {wlo.x, wlo.y, wlo.z, whi.x, whi.y, whi.z};
        for (int i = 0; i < 6; i++)
            if (bits_of(got[i]) != bits_of(want[i]))
                fail_msg("polygon %d (%d corners): bound %d is %a, the full evaluation gives %a",
                         k, s.nverts, i, got[i], want[i]);
    }
    assert_true(tried > 15000);
}

static void test_ng(void **state)
{
    (void)state;
    fx_seed(4242);
    for (int k = 0; k < 20000; k++) {
        geom_surface s = random_polygon(k);
        if (!geom_surface_prepare(&s, NULL, 0))
            continue;
        double au[3] = {s.axis_u.x, s.axis_u.y, s.axis_u.z};
        double av[3] = {s.axis_v.x, s.axis_v.y, s.axis_v.z};
        for (int c = 0; c < 3; c++) {
            int i = (c + 1) % 3, j = (c + 2) % 3;
            ia_interval want = ia_sub(ia_mul(ia_point(au[i]), ia_point(av[j])),
                                      ia_mul(ia_point(au[j]), ia_point(av[i])));
            ia_interval got = s.consts[K_NG + c];
            if (bits_of(got.lo) != bits_of(want.lo) || bits_of(got.hi) != bits_of(want.hi) ||
                got.flags != want.flags)
                fail_msg("polygon %d: Ng[%d] [%a, %a] flags %u, ia_mul gives [%a, %a] flags %u",
                         k, c, got.lo, got.hi, got.flags, want.lo, want.hi, want.flags);
        }
    }
}

/* The old test of a repeated corner (distinct_vertices), with the root
 * taken every time: how many distinct corners s has */
static int distinct_by_length(const geom_surface *s)
{
    vec3 lo = s->verts[0], hi = s->verts[0];
    for (int i = 1; i < s->nverts; i++) {
        vec3 p = s->verts[i];
        lo = v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    vec3 ext = v3_sub(hi, lo);
    double same = 1e-12 * fmax(ext.x, fmax(ext.y, ext.z));
    vec3 kept[GEOM_MAX_POLY_VERTS];
    int n = 0;
    for (int i = 0; i < s->nverts; i++) {
        vec3 p = s->verts[i];
        if (n > 0 && v3_length(v3_sub(p, kept[n - 1])) <= same) continue;
        if (i == s->nverts - 1 && n > 0 && v3_length(v3_sub(p, kept[0])) <= same) continue;
        kept[n++] = p;
    }
    return n;
}

/* geom_polygon_basis (a mesh's pass over its pieces' bounds and edges)
 * gives the basis and (u,v) of geom_surface_prepare, to the bit; and the
 * corners the prepare keeps are those the test with a root at every pair
 * keeps: random polygons (scales 1e-165 to 1e150, where 1e-12 of the size
 * squared underflows) with corners repeated at distances around the
 * threshold (1e-12 of the size) and twice it (where the squared test
 * hands over to the root) */
static void test_basis(void **state)
{
    (void)state;
    fx_seed(777);
    static const double at[] = {0, 0.5, 1 - 1e-15, 1, 1 + 1e-15, 1.5, 2 - 1e-15, 2, 2 + 1e-15, 3};
    int tried = 0, repeated = 0;
    for (int k = 0; k < 40000; k++) {
        geom_surface s = random_polygon(k);
        if (k % 4 == 1) {                  /* tiny or huge */
            double f = pow(10, k % 8 == 1 ? fx_range(-165, -150) : fx_range(100, 150));
            for (int i = 0; i < s.nverts; i++) s.verts[i] = v3_scale(s.verts[i], f);
        }
        vec3 lo = s.verts[0], hi = s.verts[0];
        for (int i = 1; i < s.nverts; i++) {
            lo = v3(fmin(lo.x, s.verts[i].x), fmin(lo.y, s.verts[i].y), fmin(lo.z, s.verts[i].z));
            hi = v3(fmax(hi.x, s.verts[i].x), fmax(hi.y, s.verts[i].y), fmax(hi.z, s.verts[i].z));
        }
        double same = 1e-12 * fmax(hi.x - lo.x, fmax(hi.y - lo.y, hi.z - lo.z));
        for (int i = 1; i < s.nverts; i++)
            if (fx_range(0, 1) < 0.3) {
                /* corner i near corner i - 1 (or the last near the first) */
                int j = i == s.nverts - 1 && fx_range(0, 1) < 0.5 ? 0 : i - 1;
                vec3 d = fx_unit_vector();
                s.verts[i] = v3_add(s.verts[j], v3_scale(d, same * at[(int)fx_range(0, 10) % 10]));
            }
        int want = distinct_by_length(&s);
        geom_surface full = s, basis = s;
        bool ok = geom_surface_prepare(&full, NULL, 0);
        char err[256];
        bool bok = geom_polygon_basis(&basis, err, sizeof err);
        if (want < 3) {
            assert_false(bok);
            assert_false(ok);
            continue;
        }
        if (bok) assert_int_equal(basis.nuv, want);
        if (!ok) continue;
        tried++;
        repeated += want < s.nverts;
        if (!bok) fail_msg("polygon %d: prepared, but its basis failed: %s", k, err);
        vec3 got[4] = {basis.origin, basis.axis_u, basis.axis_v, basis.normal};
        vec3 exp[4] = {full.origin, full.axis_u, full.axis_v, full.normal};
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++)
                if (bits_of(v3_comp(got[i], c)) != bits_of(v3_comp(exp[i], c)))
                    fail_msg("polygon %d: basis vector %d[%d] is %a, the prepare's %a", k, i, c,
                             v3_comp(got[i], c), v3_comp(exp[i], c));
        assert_int_equal(basis.nuv, full.nuv);
        for (int i = 0; i < full.nuv; i++)
            for (int c = 0; c < 2; c++)
                if (bits_of(basis.uv[i][c]) != bits_of(full.uv[i][c]))
                    fail_msg("polygon %d: uv[%d][%d] is %a, the prepare's %a", k, i, c,
                             basis.uv[i][c], full.uv[i][c]);
    }
    printf("%d polygons prepared (%d with a corner repeated): the same basis\n", tried, repeated);
    assert_true(tried > 12000 && repeated > 4000);
}

/* a bilinear patch: a parallelogram, a flat trapezoid or a twisted one
 * (corner 3 moved off the plane), in a random frame and place */
static geom_surface random_patch(int k)
{
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_PATCH;
    s.nverts = 4;
    vec3 e1 = fx_unit_vector(), t = fx_unit_vector();
    vec3 e2 = v3_normalize(v3_cross(e1, t)), e3 = v3_cross(e1, e2);
    double scale = pow(10, fx_range(-3, 3));
    vec3 c = v3_scale(v3(fx_range(-10, 10), fx_range(-10, 10), fx_range(-10, 10)), scale);
    double w = scale * fx_range(0.3, 1), h = scale * fx_range(0.3, 1), sk = fx_range(-0.5, 0.5);
    s.verts[0] = c;
    s.verts[1] = v3_add(c, v3_scale(e1, w));
    s.verts[2] = v3_add(c, v3_add(v3_scale(e2, h), v3_scale(e1, sk * w)));
    s.verts[3] = v3_add(s.verts[1], v3_sub(s.verts[2], s.verts[0]));
    if (k % 3 == 1)                        /* trapezoid: still flat */
        s.verts[3] = v3_add(s.verts[3], v3_scale(e1, fx_range(-0.4, 0.4) * w));
    else if (k % 3 == 2)                   /* twisted */
        s.verts[3] = v3_add(s.verts[3], v3_scale(e3, fx_range(-0.8, 0.8) * w));
    return s;
}

static void expect_same_hit(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                            int *hits)
{
    geom_hit a = {-1, -1, -1}, b = {-1, -1, -1};
    bool ha = geom_intersect(s, o, d, tmin, tmax, &a);
    bool hb = geom_patch_solve(s, o, d, tmin, tmax, &b);
    if (ha != hb)
        fail_msg("patch (%a %a %a ...), ray o (%a %a %a) d (%a %a %a): geom_intersect %s, "
                 "the general solve %s (t %a)", s->verts[0].x, s->verts[0].y, s->verts[0].z,
                 o.x, o.y, o.z, d.x, d.y, d.z, ha ? "hits" : "misses", hb ? "hits" : "misses",
                 ha ? a.t : b.t);
    if (ha) {
        expect_same(a.t, b.t, "patch t", o.x, d.x);
        expect_same(a.u, b.u, "patch u", o.x, d.x);
        expect_same(a.v, b.v, "patch v", o.x, d.x);
        ++*hits;
    }
}

static void test_patch_slab(void **state)
{
    (void)state;
    fx_seed(2430);
    int hits = 0, leaving = 0, leaving_hits = 0, aimed = 0, aimed_hits = 0;
    for (int k = 0; k < 6000; k++) {
        geom_surface s = random_patch(k);
        char err[128];
        assert_true(geom_surface_prepare(&s, err, sizeof err));
        double u = fx_range(0, 1), v = fx_range(0, 1);
        geom_sample g;
        geom_eval(&s, u, v, &g);
        vec3 n = v3_normalize(v3_cross(g.dPdu, g.dPdv));
        double size = v3_length(v3_sub(s.verts[3], s.verts[0])) + v3_length(g.dPdu);
        for (int j = 0; j < 8; j++) {
            /* a shadow-like ray: from just off the patch, away from it
             * (on either side), at angles down to 1e-9 of its plane */
            static const double offs[] = {0, 1e-12, 1e-9, 1e-6, 1e-3};
            double side = j % 2 ? 1.0 : -1.0;
            vec3 o = v3_add(g.P, v3_scale(n, side * offs[j % 5] * size));
            vec3 tan = v3_normalize(v3_cross(n, fx_unit_vector()));
            double lift = pow(10, fx_range(-9, 0));
            vec3 d = v3_scale(v3_add(v3_scale(n, side * lift), tan), pow(10, fx_range(-2, 2)));
            int before = hits;
            expect_same_hit(&s, o, d, 0, j % 3 ? INFINITY : fx_range(0, 10) * size, &hits);
            leaving++;
            leaving_hits += hits - before;
            /* aimed at the point from either side, and a random ray */
            vec3 toward = v3_add(v3_scale(n, -side * fx_range(0.01, 1)),
                                 v3_scale(tan, fx_range(-1, 1)));
            vec3 a = v3_scale(toward, size);
            before = hits;
            expect_same_hit(&s, v3_sub(g.P, a), a, 0, INFINITY, &hits);
            aimed++;
            aimed_hits += hits - before;
            vec3 r = v3_add(g.P, v3_scale(fx_unit_vector(), size * fx_range(0, 3)));
            expect_same_hit(&s, r, fx_unit_vector(), fx_range(-1, 0.5) * size, INFINITY, &hits);
        }
    }
    /* the aimed rays are meaningful (they hit), and the leaving ones mostly
     * miss: a flat patch is never hit again, a twisted one sometimes */
    printf("patch slab: %d rays leaving a patch (%d hit it again), %d aimed (%d hit)\n", leaving,
           leaving_hits, aimed, aimed_hits);
    assert_true(aimed_hits > aimed * 9 / 10);
    assert_true(leaving_hits < leaving / 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_minmax),
        cmocka_unit_test(test_bounds),
        cmocka_unit_test(test_ng),
        cmocka_unit_test(test_basis),
        cmocka_unit_test(test_patch_slab),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
