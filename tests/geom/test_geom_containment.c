/*
 * tests/geom/test_geom_containment.c: the interval and affine enclosures of
 * geom_eval_ia / geom_eval_aa are conservative, and affine is not wider.
 *
 * For every fixture (every kind, full and partial sweeps), 300 (u,v) boxes:
 * the full domain, and boxes whose sides are drawn from {1, 0.3, 0.05, 1e-3,
 * 1e-6, 1e-10, 0} at random places. In each box, a 7x7 grid (corners and
 * edges included) and 16 random points are evaluated by the long double
 * oracle (geom_fixtures.c, RI spec formulas). Every component of P, dPdu,
 * dPdv and Ng must lie
 *
 *   - inside the interval of geom_eval_ia,
 *   - inside aa_range of geom_eval_aa's form, and
 *   - inside the form itself at the sample's own noise values: with
 *     e_u, e_v the values of the two input symbols that give (u,v),
 *     |exact - (x0 + c0 e_u + c1 e_v)| <= sum_{i>=2} |ci| + err.
 *     This checks that the results really share u's and v's symbols.
 *
 * The oracle errs by a few long double ulps; a point counts as a violation
 * only beyond 128 long double epsilons of the quantity's scale. The affine
 * context capacity cycles through 2 (fully reduced), AA_DEFAULT_CAPACITY
 * and AA_MAX_SYMBOLS. Counts are printed; the test asserts 0 violations.
 *
 * Sharing: on boxes of sides <= 1e-3 (capacity > 2), every form depends on
 * the u and v symbols to first order: the rest (new symbols and err) is at
 * most 5% of |c0| + |c1| plus a second-order allowance.
 *
 * Width: per component, affine range width minus interval width, over the
 * component's scale, must average <= 1e-9 (the affine range is met with its
 * interval hull, so it should never lose). The ratio is printed.
 *
 * Bounds: geom_bounds contains every sample's P (polygons: inside ones).
 *
 * Unit normals and singular points: a quarter of the boxes end at v = 1,
 * a quarter start at v = 0 and a quarter hold a corner of the square, so
 * the grid samples the singular parameter values of every base exactly:
 * the sphere's poles, the disk's centre, the cone's and the paraboloid's
 * apex, and (fixtures of this test) the collapsed edges of a bilinear and
 * a bicubic patch and a hyperboloid's point on its axis, where Ng = 0. At
 * every sample the point path's unit normal (geom_normal_dual, normalised:
 * what a shader's N is) must lie inside geom_unit_normal_ia's interval and
 * geom_unit_normal_aa's range (up to its own rounding, 16 double
 * epsilons) and, on the kinds with a closed form (surface_normal.inc),
 * agree with the oracle's unit normal (that closed form in long double,
 * the limit included) to 1e-9; the oracle's (elsewhere Ng/|Ng| where
 * Ng != 0) must lie inside both too. The sharing check skips boxes at a
 * paraboloid's apex (P ~ sqrt(v) there has no first-order part).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>

#include "geom_fixtures.h"

typedef long double ld;

enum { NQ = 12, BOXES = 300, GRID = 7, RANDOM_PTS = 16 };

typedef struct stats {
    long samples, skipped, ia_bad, aa_bad, corr_bad, bounds_bad;
    long normals, normal_bad, singular;
    long small, decorrelated;
    double wdiff, wratio_num, wratio_den;
    long nwidth;
} stats;

static const char *const q_names[4] = { "P", "dPdu", "dPdv", "Ng" };

static const ld *oracle_q(const fx_exact *e, int q)
{
    switch (q / 3) {
    case 0: return &e->P[q % 3];
    case 1: return &e->Pu[q % 3];
    case 2: return &e->Pv[q % 3];
    default: return &e->Ng[q % 3];
    }
}

static ia_interval ia_q(const geom_ia *g, int q)
{
    switch (q / 3) {
    case 0: return g->P[q % 3];
    case 1: return g->dPdu[q % 3];
    case 2: return g->dPdv[q % 3];
    default: return g->Ng[q % 3];
    }
}

static const aa_form *aa_q(const geom_aa *g, int q)
{
    switch (q / 3) {
    case 0: return &g->P[q % 3];
    case 1: return &g->dPdu[q % 3];
    case 2: return &g->dPdv[q % 3];
    default: return &g->Ng[q % 3];
    }
}

/* scale of each quantity: max |component| over a grid of the domain */
static void scales(const geom_surface *s, double *S)
{
    for (int q = 0; q < NQ; q++)
        S[q] = 1e-300;
    for (int i = 0; i <= 32; i++)
        for (int j = 0; j <= 32; j++) {
            fx_exact e;
            fx_oracle(s, i / 32.0, j / 32.0, &e);
            for (int q = 0; q < NQ; q++) {
                double x = fabs((double)*oracle_q(&e, q));
                if (isfinite(x) && x > S[(q / 3) * 3])
                    S[(q / 3) * 3] = x;
            }
        }
    for (int q = 0; q < NQ; q++)
        S[q] = S[(q / 3) * 3];
}

static void random_side(double *lo, double *hi)
{
    static const double widths[] = { 1, 0.3, 0.05, 1e-3, 1e-6, 1e-10, 0 };
    double w = widths[(int)(fx_unit() * 7)];
    *lo = fx_unit() * (1 - w);
    *hi = fmin(*lo + w, 1.0);
}

static double sample_at(double lo, double hi, int i, int n)
{
    if (i < n)
        return i == n - 1 ? hi : lo + (hi - lo) * i / (n - 1);
    return lo + (hi - lo) * fx_unit();
}

static bool outside(ld x, double lo, double hi, ld tol)
{
    return x < (ld)lo - tol || x > (ld)hi + tol;
}

/* the affine form at the sample's own noise values */
static bool corr_violation(const aa_form *f, ld eu, ld ev, ld x, ld tol)
{
    if (f->flags & AA_UNBOUNDED)
        return false;
    ld c0 = f->n > 0 ? f->c[0] : 0, c1 = f->n > 1 ? f->c[1] : 0;
    ld centre = f->x0 + c0 * eu + c1 * ev, rest = f->err;
    for (int i = 2; i < f->n; i++)
        rest += fabsl((ld)f->c[i]);
    ld slack = tol + 8 * LDBL_EPSILON * (fabsl((ld)f->x0) + fabsl(c0) + fabsl(c1));
    return fabsl(x - centre) > rest + slack;
}

static void report(const char *name, const char *what, int q, double u, double v,
                   ld x, double lo, double hi)
{
    print_message("  %s: %s %s[%d] at (%.17g, %.17g): exact %.20Lg not in [%.17g, %.17g]\n",
                  name, what, q_names[q / 3], q % 3, u, v, x, lo, hi);
}

#define PI_L 3.141592653589793238462643383279502884L

static ld sgnl(ld x) { return x < 0 ? -1 : 1; }

/* The exact unit normal at (u,v), its limit where Ng = 0: the closed
 * forms of surface_normal.c (kinds that have one) in long double, else
 * Ng/|Ng|; false where that is not defined (Ng = 0 of a kind without a
 * closed form). */
static bool oracle_unit_normal(const geom_surface *s, double u, double v, const fx_exact *e,
                               ld n[3])
{
    ld th = (ld)u * s->thetamax, c = cosl(th), sn = sinl(th), k = sgnl(s->thetamax);
    switch (s->kind) {
    case GEOM_SPHERE: {
        ld dphi = (ld)s->phi1 - s->phi0;
        for (int i = 0; i < 3; i++) n[i] = e->P[i] / s->radius * k * sgnl(dphi);
        return true;
    }
    case GEOM_DISK:
        n[0] = n[1] = 0;
        n[2] = k;
        return true;
    case GEOM_CYLINDER:
        k *= sgnl((ld)s->zmax - s->zmin);
        n[0] = c * k;
        n[1] = sn * k;
        n[2] = 0;
        return true;
    case GEOM_CONE: {
        ld h = s->height, r = s->radius, l = sqrtl(h * h + r * r);
        n[0] = k * h * c / l;
        n[1] = k * h * sn / l;
        n[2] = k * r / l;
        return true;
    }
    case GEOM_TORUS: {
        ld dphi = (ld)s->phimax - s->phimin, phi = s->phimin + v * dphi;
        k *= sgnl(dphi);
        n[0] = k * cosl(phi) * c;
        n[1] = k * cosl(phi) * sn;
        n[2] = k * sinl(phi);
        return true;
    }
    default: {
        ld l = sqrtl(e->Ng[0] * e->Ng[0] + e->Ng[1] * e->Ng[1] + e->Ng[2] * e->Ng[2]);
        if (!(l > 1e-12L) || !isfinite((double)l)) return false;
        for (int i = 0; i < 3; i++) n[i] = e->Ng[i] / l;
        return true;
    }
    }
}

/* the point path's unit normal at (u,v) and the boxes' unit normals */
static void check_normal(const fx_surface *f, double u, double v, const fx_exact *e,
                         const ia_interval Ni[3], const ia_interval Na[3], stats *st)
{
    const geom_surface *s = &f->s;
    geom_sample g;
    geom_eval_dual(s, u, v, &g);
    vec3 N, dNdu, dNdv;
    geom_normal_dual(s, u, v, &g, &N, &dNdu, &dNdv);
    vec3 n = v3_normalize(N);
    ld x[3];
    bool exact = oracle_unit_normal(s, u, v, e, x);
    st->normals++;
    if (!(v3_length(g.Ng) > 0)) st->singular++;
    for (int i = 0; i < 3; i++) {
        double p = v3_comp(n, i), slack = 16 * DBL_EPSILON;
        bool bad = !(p >= Ni[i].lo - slack && p <= Ni[i].hi + slack) ||
                   !(p >= Na[i].lo - slack && p <= Na[i].hi + slack);
        if (exact) {
            ld tol = 128 * LDBL_EPSILON;
            bad |= outside(x[i], Ni[i].lo, Ni[i].hi, tol) || outside(x[i], Na[i].lo, Na[i].hi, tol);
            /* Ng/|Ng| in float loses digits close to a collapsed edge
             * (Ng's terms cancel): the direction is compared where the
             * normal has a closed form */
            if (s->kind <= GEOM_CONE || s->kind == GEOM_TORUS) bad |= fabsl((ld)p - x[i]) > 1e-9L;
        }
        if (bad && st->normal_bad++ < 5)
            print_message("  %s: unit normal[%d] at (%.17g, %.17g): point path %.17g, exact "
                          "%.20Lg; interval [%.17g, %.17g], affine [%.17g, %.17g]\n",
                          f->name, i, u, v, p, exact ? x[i] : (ld)NAN, Ni[i].lo, Ni[i].hi,
                          Na[i].lo, Na[i].hi);
    }
}

static void check_box(const fx_surface *f, const double *S, double u0, double u1,
                      double v0, double v1, int capacity, stats *st)
{
    const geom_surface *s = &f->s;
    geom_ia gi;
    geom_eval_ia(s, ia_make(u0, u1), ia_make(v0, v1), &gi);
    aa_context ctx;
    aa_context_init(&ctx, capacity);
    aa_form U, V;
    aa_input(&ctx, &U, u0, u1);
    aa_input(&ctx, &V, v0, v1);
    geom_aa ga;
    geom_eval_aa(&ctx, s, &U, &V, &ga);
    vec3 blo, bhi;
    geom_bounds(s, &blo, &bhi);
    ia_interval Ni[3], Na[3];
    aa_form Nf[3];
    geom_unit_normal_ia(s, ia_make(u0, u1), ia_make(v0, v1), &gi, Ni);
    geom_unit_normal_aa(&ctx, s, &U, &V, &ga, Nf);
    for (int i = 0; i < 3; i++) Na[i] = aa_range(&Nf[i]);

    for (int q = 0; q < NQ; q++) {
        ia_interval a = aa_range(aa_q(&ga, q)), b = ia_q(&gi, q);
        double wa = a.hi - a.lo, wb = b.hi - b.lo;
        if (isfinite(wa) && isfinite(wb)) {
            st->wdiff += (wa - wb) / S[q];
            st->wratio_num += wa / S[q];
            st->wratio_den += wb / S[q];
            st->nwidth++;
        }
    }
    /* (not at a paraboloid's apex, where P ~ sqrt(v) has no first order) */
    bool apex = s->kind == GEOM_PARABOLOID && s->zmin == 0 && v0 == 0;
    if (u1 - u0 > 0 && u1 - u0 <= 1e-3 && v1 - v0 > 0 && v1 - v0 <= 1e-3 && capacity > 2 && !apex)
        for (int q = 0; q < NQ; q++) {
            const aa_form *fq = aa_q(&ga, q);
            if (fq->flags & AA_UNBOUNDED)
                continue;
            double lin = 0, rest = fq->err;
            for (int i = 0; i < fq->n; i++)
                *(i < 2 ? &lin : &rest) += fabs(fq->c[i]);
            st->small++;
            double du = u1 - u0, dv = v1 - v0;    /* second order may stay */
            if (rest > 0.05 * lin + (100 * (du * du + dv * dv) + 1e-12) * S[q] &&
                st->decorrelated++ < 5)
                print_message("  %s: %s[%d] over [%g,%g]x[%g,%g] depends on u, v by %g, "
                              "on the rest by %g\n", f->name, q_names[q / 3], q % 3,
                              u0, u1, v0, v1, lin, rest);
        }
    int total = GRID * GRID + RANDOM_PTS;
    for (int i = 0; i < total; i++) {
        double u = i < GRID * GRID ? sample_at(u0, u1, i % GRID, GRID) : sample_at(u0, u1, GRID, GRID);
        double v = i < GRID * GRID ? sample_at(v0, v1, i / GRID, GRID) : sample_at(v0, v1, GRID, GRID);
        fx_exact e;
        fx_oracle(s, u, v, &e);
        ld eu = U.c[0] != 0 ? ((ld)u - U.x0) / U.c[0] : 0;
        ld ev = V.c[V.n - 1] != 0 ? ((ld)v - V.x0) / V.c[V.n - 1] : 0;
        if (capacity < 2)
            eu = ev = 0;
        st->samples++;
        if (fx_on_surface(s, u, v)) check_normal(f, u, v, &e, Ni, Na, st);
        for (int q = 0; q < NQ; q++) {
            ld x = *oracle_q(&e, q);
            if (!isfinite((double)x)) {
                st->skipped++;
                continue;
            }
            ld tol = 128 * LDBL_EPSILON * ((ld)S[q] + fabsl(x));
            ia_interval b = ia_q(&gi, q), a = aa_range(aa_q(&ga, q));
            if (outside(x, b.lo, b.hi, tol) && st->ia_bad++ < 5)
                report(f->name, "interval", q, u, v, x, b.lo, b.hi);
            if (outside(x, a.lo, a.hi, tol) && st->aa_bad++ < 5)
                report(f->name, "affine range", q, u, v, x, a.lo, a.hi);
            if (corr_violation(aa_q(&ga, q), eu, ev, x, tol) && st->corr_bad++ < 5)
                report(f->name, "affine form", q, u, v, x, a.lo, a.hi);
            if (q < 3 && fx_on_surface(s, u, v)) {
                double lo = v3_comp(blo, q), hi = v3_comp(bhi, q);
                if (outside(x, lo, hi, tol) && st->bounds_bad++ < 5)
                    report(f->name, "bounds", q, u, v, x, lo, hi);
            }
        }
    }
}

/* A quarter of the boxes end at v = 1, a quarter start at v = 0, a quarter
 * hold a corner (see the top of the file). */
static void snap_to_border(int b, double *u0, double *u1, double *v0, double *v1)
{
    double wu = *u1 - *u0, wv = *v1 - *v0;
    switch (b % 4) {
    case 1: *v1 = 1; *v0 = 1 - wv; break;
    case 2: *v0 = 0; *v1 = wv; break;
    case 3:
        if (b % 8 == 3) { *u0 = 0; *u1 = wu; *v1 = 1; *v0 = 1 - wv; }
        else { *u1 = 1; *u0 = 1 - wu; *v0 = 0; *v1 = wv; }
        break;
    default: break;
    }
}

/* the fixtures, and bases with collapsed edges (Ng = 0 along v = 0) */
static int surfaces(fx_surface **out)
{
    static fx_surface all[64];
    static int n;
    if (n == 0) {
        fx_surface *fx;
        int m = fx_surfaces(&fx);
        for (int k = 0; k < m; k++) all[n++] = fx[k];
        fx_surface *f = &all[n++];
        f->name = "patch collapsed";             /* P00 = P10: a triangle */
        f->s = fx_default(GEOM_PATCH);
        f->s.verts[1] = f->s.verts[0];
        f->s.verts[3] = v3(1, 1, 0.4);
        f->size = 1.5;
        f = &all[n++];
        f->name = "bicubic collapsed";           /* the first row one point */
        f->s = fx_default(GEOM_BICUBIC);
        for (int k = 0; k < 16; k++) {
            double x = (k % 4) / 1.5 - 1, y = (k / 4) / 1.5 - 1;
            f->s.verts[k] = k < 4 ? v3(0, -1, 0.3) : v3(x, y, 1.2 - 0.6 * (x * x + y * y));
        }
        f->size = 2;
        f = &all[n++];
        f->name = "hyperboloid from axis";       /* point1 on the z axis */
        f->s = fx_default(GEOM_HYPERBOLOID);
        f->s.point1 = v3(0, 0, -0.5);
        f->s.point2 = v3(0.8, 0.3, 0.7);
        f->size = 1.5;
        for (int k = m; k < n; k++) {
            char why[200];
            if (!geom_surface_prepare(&all[k].s, why, sizeof why))
                fail_msg("fixture %s: %s", all[k].name, why);
        }
    }
    *out = all;
    return n;
}

static void test_containment(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = surfaces(&fx);
    const int caps[3] = { 2, AA_DEFAULT_CAPACITY, AA_MAX_SYMBOLS };
    stats all = { 0 };
    fx_seed(11);
    for (int k = 0; k < n; k++) {
        double S[NQ];
        scales(&fx[k].s, S);
        stats st = { 0 };
        for (int b = 0; b < BOXES; b++) {
            double u0 = 0, u1 = 1, v0 = 0, v1 = 1;
            if (b > 0) {
                random_side(&u0, &u1);
                random_side(&v0, &v1);
                snap_to_border(b, &u0, &u1, &v0, &v1);
            }
            check_box(&fx[k], S, u0, u1, v0, v1, caps[b % 3], &st);
        }
        printf("%-22s %6ld samples: violations interval %ld, affine range %ld, "
               "affine form %ld, bounds %ld, unit normal %ld (of %ld, %ld where Ng = 0); "
               "width affine/interval %.3f; decorrelated %ld/%ld\n",
               fx[k].name, st.samples, st.ia_bad, st.aa_bad, st.corr_bad, st.bounds_bad,
               st.normal_bad, st.normals, st.singular,
               st.wratio_num / st.wratio_den, st.decorrelated, st.small);
        all.samples += st.samples;
        all.skipped += st.skipped;
        all.ia_bad += st.ia_bad;
        all.aa_bad += st.aa_bad;
        all.corr_bad += st.corr_bad;
        all.bounds_bad += st.bounds_bad;
        all.normals += st.normals;
        all.normal_bad += st.normal_bad;
        all.singular += st.singular;
        all.wdiff += st.wdiff;
        all.decorrelated += st.decorrelated;
        all.small += st.small;
        all.nwidth += st.nwidth;
        if (st.wdiff / st.nwidth > 1e-9)
            fail_msg("%s: affine ranges wider than interval ones on average (%g)",
                     fx[k].name, st.wdiff / st.nwidth);
    }
    printf("total %ld samples x %d quantities (%ld non-finite skipped): "
           "%ld + %ld + %ld + %ld violations\n",
           all.samples, NQ, all.skipped, all.ia_bad, all.aa_bad, all.corr_bad,
           all.bounds_bad);
    assert_int_equal(all.ia_bad, 0);
    assert_int_equal(all.aa_bad, 0);
    assert_int_equal(all.corr_bad, 0);
    printf("unit normals: %ld samples (%ld where Ng = 0), %ld violations\n", all.normals,
           all.singular, all.normal_bad);
    assert_int_equal(all.bounds_bad, 0);
    assert_int_equal(all.normal_bad, 0);
    assert_true(all.singular > 100);
    assert_int_equal(all.decorrelated, 0);
    assert_true(all.small > 1000);
    assert_true(all.samples > 100000);
}

/* The sphere's box is tight: [-1, 1]^3 up to rounding. */
static void test_bounds_tight(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_SPHERE);
    assert_true(geom_surface_prepare(&s, NULL, 0));
    vec3 lo, hi;
    geom_bounds(&s, &lo, &hi);
    assert_true(lo.x >= -1 - 1e-12 && lo.y >= -1 - 1e-12 && lo.z >= -1 - 1e-12);
    assert_true(hi.x <= 1 + 1e-12 && hi.y <= 1 + 1e-12 && hi.z <= 1 + 1e-12);
    assert_true(lo.x <= -1 && hi.z >= 1);
}

/* Symbol use: a point box of a polygon needs no new symbol; the sphere
 * shares u's and v's symbols and P.z depends on v only. */
static void test_symbols(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        aa_context ctx;
        aa_context_init(&ctx, AA_MAX_SYMBOLS);
        aa_form U, V;
        aa_input(&ctx, &U, 0.25, 0.5);
        aa_input(&ctx, &V, 0.5, 0.75);
        geom_aa g;
        geom_eval_aa(&ctx, s, &U, &V, &g);
        int fresh = ctx.used - 2;
        if (s->kind == GEOM_POLYGON)
            assert_int_equal(fresh, 0);
        if (s->kind == GEOM_PATCH)
            assert_int_equal(fresh, 1);
        if (s->kind == GEOM_SPHERE) {
            assert_true(fresh <= 11);
            assert_true(g.P[2].n >= 2 && g.P[2].c[1] != 0);
            assert_true(g.P[2].c[0] == 0);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_bounds_tight),
        cmocka_unit_test(test_symbols),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
