/*
 * test_trace_float_box.c: the box cache's float boxes (box.h, trace_fbox):
 * a box stored as floats contains the double box it came from (lo and slo
 * rounded down, hi and shi up) for random boxes of every magnitude (huge,
 * beyond FLT_MAX, tiny, subnormal, zeros, +-inf); an empty box stays empty;
 * NaN stays NaN; a box already in floats comes back bit for bit; offsets
 * from a parent box (near, far, infinite) contain too, and a flat child of
 * a flat parent is exact; and the box cache gives back the rounded box (a
 * hit equals a recomputation). The linear bounds of issue 24's lazy
 * children (lin_bound.h): in floats they hold what the doubles held, as
 * codes what the floats held within the box, and a child cell's
 * restricted bound holds the points of the child.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "trace/box.h"
#include "trace/boxcache.h"
#include "test_rng.h"

/* the tests' fixed-seed generator (test_rng.h) */
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint64_t next(void) { return test_rng_next(&rng); }

/* a double of any kind: random bits (every exponent, subnormals), ones
 * near float boundaries, +-inf, zeros */
static double any_double(void)
{
    uint64_t k = next() % 16;
    double sign = (next() & 1) ? -1.0 : 1.0;
    double m = (double)(next() >> 11) * 0x1p-53;          /* [0, 1) */
    switch (k) {
    case 0: return sign * INFINITY;
    case 1: return sign * 0.0;
    case 2: return sign * (double)FLT_MAX * (1.0 + m * 0x1p-20);   /* just above FLT_MAX */
    case 3: return sign * 0x1p-149 * m * 2.0;                       /* below/at float subnormal */
    case 4: return sign * 0x1p-126 * m;                             /* float subnormal range */
    case 5: return sign * ldexp(1.0 + m, (int)(next() % 2000) - 1000);   /* huge and tiny */
    case 6: { /* a float exactly */
        float f = (float)(sign * ldexp(1.0 + m, (int)(next() % 200) - 100));
        return f;
    }
    default: {
        uint64_t b = next();
        double x;
        memcpy(&x, &b, sizeof x);
        if (x != x) x = sign * m * 1e10;    /* NaN handled apart */
        return x;
    }
    }
}

static void random_box(trace_box *b)
{
    memset(b, 0, sizeof *b);
    double *lo = &b->lo.x, *hi = &b->hi.x;
    for (int i = 0; i < 3; i++) {
        double a = any_double(), c = any_double();
        lo[i] = fmin(a, c);
        hi[i] = fmax(a, c);
    }
    double a = any_double(), c = any_double();
    b->slo = fmin(a, c);
    b->shi = fmax(a, c);
    b->sn[0] = 0.6f;
    b->sn[2] = -0.8f;
    b->flags = (unsigned)(next() & 0x7ff);
    b->bend = (float)(next() % 1000) * 0.25f;
}

/* a base box: none, one of any kind, or one near b (a parent) */
static const trace_box *random_base(const trace_box *b, trace_box *base)
{
    switch (next() % 3) {
    case 0: return NULL;
    case 1: random_box(base); return base;
    default: {
        *base = *b;
        double *lo = &base->lo.x, *hi = &base->hi.x;
        for (int i = 0; i < 3; i++) {
            double w = fabs(hi[i] - lo[i]) * (double)(next() % 5) * 0.3;
            lo[i] -= w;
            hi[i] += w * 0.7;
        }
        return base;
    }
    }
}

static void test_float_box_contains_the_double_box(void **state)
{
    (void)state;
    long widened = 0;
    for (int n = 0; n < 300000; n++) {
        trace_box b, r, bb;
        random_box(&b);
        const trace_box *base = random_base(&b, &bb);
        r = b;
        trace_box_round_float(&r, base);
        const double *lo = &b.lo.x, *hi = &b.hi.x, *rlo = &r.lo.x, *rhi = &r.hi.x;
        for (int i = 0; i < 3; i++) {
            assert_true(rlo[i] <= lo[i]);
            assert_true(rhi[i] >= hi[i]);
            if (isinf(lo[i])) assert_true(rlo[i] == lo[i]);
            if (isinf(hi[i])) assert_true(rhi[i] == hi[i]);
            widened += rlo[i] < lo[i];
            widened += rhi[i] > hi[i];
        }
        assert_true(r.slo <= b.slo);
        assert_true(r.shi >= b.shi);
        assert_int_equal(r.flags, b.flags);
        assert_true(r.bend == b.bend);
        assert_memory_equal(r.sn, b.sn, sizeof b.sn);
        assert_false(trace_box_is_empty(&r));
        if (!base) {
            /* without a base: floats, and a box in floats comes back bit for bit */
            for (int i = 0; i < 3; i++) {
                assert_true((double)(float)rlo[i] == rlo[i] || isinf(rlo[i]));
                assert_true((double)(float)rhi[i] == rhi[i] || isinf(rhi[i]));
            }
            trace_box again = r;
            trace_box_round_float(&again, NULL);
            assert_memory_equal(&again, &r, sizeof r);
        }
    }
    assert_true(widened > 0);
}

static void test_edges(void **state)
{
    (void)state;
    trace_box b;
    memset(&b, 0, sizeof b);
    /* beyond FLT_MAX: outward to inf; an unbounded box stays unbounded */
    b.lo = v3(-1e300, -INFINITY, -0.0);
    b.hi = v3(1e300, INFINITY, 0.0);
    b.slo = -1e-300;
    b.shi = 1e-300;
    b.flags = 1u << 1;
    trace_box r = b;
    trace_box_round_float(&r, NULL);
    assert_true(r.lo.x == -INFINITY && r.hi.x == INFINITY);
    assert_true(r.lo.y == -INFINITY && r.hi.y == INFINITY);
    assert_true(r.lo.z == 0.0 && r.hi.z == 0.0);
    assert_true(r.slo == -0x1p-149 && r.shi == 0x1p-149);
    /* just below the smallest subnormal float */
    b.lo = v3(0x1p-150, -0x1p-150, 0x1p-149);
    b.hi = v3(0x1p-149 * 1.5, 0x1p-200, 0x1p-149);
    r = b;
    trace_box_round_float(&r, NULL);
    assert_true(r.lo.x == 0.0 && r.hi.x == 0x1p-148);
    assert_true(r.lo.y == -0x1p-149 && r.hi.y == 0x1p-149);
    assert_true(r.lo.z == 0x1p-149 && r.hi.z == 0x1p-149);
    /* FLT_MAX itself and just above: the box stays finite only where it was */
    b.lo = v3(-(double)FLT_MAX, (double)FLT_MAX, 1.0);
    b.hi = v3((double)FLT_MAX, (double)FLT_MAX * (1.0 + 0x1p-40), 1.0 + 0x1p-30);
    r = b;
    trace_box_round_float(&r, NULL);
    assert_true(r.lo.x == -(double)FLT_MAX && r.hi.x == (double)FLT_MAX);
    assert_true(r.lo.y == (double)FLT_MAX && r.hi.y == INFINITY);
    assert_true(r.lo.z == 1.0 && r.hi.z == 1.0 + 0x1p-23);
}

static void test_empty_stays_empty_and_nan_stays_nan(void **state)
{
    (void)state;
    trace_box b;
    memset(&b, 0, sizeof b);
    /* lo above hi by less than a float step: outward would make it a point */
    b.lo = v3(0.0, 1.0 + 0x1p-40, 0.0);
    b.hi = v3(1.0, 1.0, 1.0);
    assert_true(trace_box_is_empty(&b));
    trace_box r = b;
    trace_box_round_float(&r, NULL);
    assert_true(trace_box_is_empty(&r));
    assert_true(r.lo.y > r.hi.y);
    /* the empty box of unions */
    b.lo = v3(INFINITY, INFINITY, INFINITY);
    b.hi = v3(-INFINITY, -INFINITY, -INFINITY);
    r = b;
    trace_box_round_float(&r, NULL);
    assert_memory_equal(&r.lo, &b.lo, sizeof b.lo);
    assert_memory_equal(&r.hi, &b.hi, sizeof b.hi);
    /* NaN: still NaN, still empty */
    b.lo = v3(NAN, 0.0, 0.0);
    b.hi = v3(1.0, 1.0, 1.0);
    b.slo = 0.3;
    b.shi = NAN;
    r = b;
    trace_box_round_float(&r, NULL);
    assert_true(isnan(r.lo.x) && r.hi.x == 1.0);
    assert_true(isnan(r.shi) && r.slo == 0.3f);
    assert_true(trace_box_is_empty(&r));
    /* an inverted slab stays inverted */
    b.lo = v3(0.0, 0.0, 0.0);
    b.slo = 2.0 + 0x1p-40;
    b.shi = 2.0;
    r = b;
    trace_box_round_float(&r, NULL);
    assert_true(r.slo > r.shi);
}

static void test_offsets_from_the_parent(void **state)
{
    (void)state;
    /* a flat child of a flat parent at a height that is no float: exact */
    trace_box p, b;
    memset(&p, 0, sizeof p);
    p.lo = v3(0.1, 0.2, 0.3);
    p.hi = v3(0.7, 0.2, 1e-300);
    b = p;
    b.lo.x = 0.1 + 0x1p-40;
    trace_box r = b;
    trace_box_round_float(&r, &p);
    assert_true(r.lo.y == 0.2 && r.hi.y == 0.2);
    assert_true(r.lo.z == 0.3 && r.hi.z == 1e-300);
    assert_true(r.lo.x <= b.lo.x && r.lo.x >= 0.1 && b.lo.x - r.lo.x < 0x1p-60);
    assert_true(r.hi.x == 0.7);
    /* offsets a float step cannot move past the base's own rounding, and
     * subtractions that round: still contained */
    p.lo = v3(1e10, -1e10, 1.0);
    p.hi = v3(1e10, -1e10, 1.0);
    b.lo = v3(1e10 - 1e-7, -1e10 - 3e-7, 1.0 - 0x1p-53);
    b.hi = v3(1e10 + 1e-7, -1e10 + 3e-7, 1.0 + 0x1p-52);
    r = b;
    trace_box_round_float(&r, &p);
    assert_true(r.lo.x <= b.lo.x && r.hi.x >= b.hi.x);
    assert_true(r.lo.y <= b.lo.y && r.hi.y >= b.hi.y);
    assert_true(r.lo.z <= b.lo.z && r.hi.z >= b.hi.z);
    /* a base far away, of the other sign: the offset overflows outward;
     * bases that are not finite count as 0 */
    p.lo = v3(-1.5e308, -INFINITY, NAN);
    p.hi = v3(-1.6e308, INFINITY, 0.0);
    b.lo = v3(1.5e308, 2.0, 3.0);
    b.hi = v3(1.6e308, 2.5, 3.5);
    r = b;
    trace_box_round_float(&r, &p);
    assert_true(r.lo.x <= b.lo.x && r.hi.x == INFINITY);
    assert_true(r.lo.y == 2.0 && r.hi.y == 2.5 && r.lo.z == 3.0 && r.hi.z == 3.5);
}

static void test_cache_gives_back_the_rounded_box(void **state)
{
    (void)state;
    trace_boxcache *c = trace_boxcache_new(0, 1);
    assert_true(sizeof(trace_fbox) < sizeof(trace_box) * 3 / 4);
    assert_int_equal(sizeof(trace_qlin), 12);
    /* boxes with linear bounds inside them, as the intersector has them */
    trace_box in[4], want[4], out[4];
    trace_lin lins[4];
    trace_qlin codes[4], got[4];
    for (int i = 0; i < 4; i++) {
        random_box(&in[i]);
        for (int k = 0; k < 3; k++) {
            double lo = (&in[i].lo.x)[k], hi = (&in[i].hi.x)[k];
            double mid = 0.5 * lo + 0.5 * hi, q = 0.125 * (hi - lo);
            if (!trace_lin_set(&lins[i], k, mid, q, -q, q))     /* beyond the floats */
                assert_true(trace_lin_set(&lins[i], k, 0, 0, 0, 0));
        }
        in[i].flags |= TRACE_BOX_LIN;
        trace_fbox f;
        trace_fbox_pack_lin(&in[i], &lins[i], NULL, &f);
        trace_fbox_unpack(&f, NULL, &want[i]);
        codes[i] = f.qlin;
    }
    trace_box kept[4];
    memcpy(kept, in, sizeof kept);
    trace_brood_id id = trace_boxcache_insert_kept(c, 0, TRACE_BROOD_NONE, 0, NULL, kept, lins, got);
    assert_true(id >= 0);
    /* given back as kept, and a lookup gives the same; the codes kept too */
    assert_memory_equal(kept, want, sizeof want);
    assert_memory_equal(got, codes, sizeof codes);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), id);
    assert_memory_equal(out, want, sizeof want);
    for (int i = 0; i < 4; i++)
        assert_memory_equal(trace_boxcache_qlin(c, id, i), &codes[i], sizeof(trace_qlin));
    /* a brood that is not stored: the same boxes and codes */
    trace_boxcache *none = trace_boxcache_new(1, 1);        /* no room for one brood */
    memcpy(kept, in, sizeof kept);
    memset(got, 0, sizeof got);
    assert_int_equal(trace_boxcache_insert_kept(none, 0, TRACE_BROOD_NONE, 0, NULL, kept, lins, got),
                     TRACE_BROOD_UNCACHED);
    assert_memory_equal(kept, want, sizeof want);
    assert_memory_equal(got, codes, sizeof codes);
    trace_boxcache_destroy(&none);
    /* against a base, without linear bounds: the flag goes */
    trace_box base;
    random_box(&base);
    for (int i = 0; i < 4; i++) {
        want[i] = in[i];
        trace_box_round_float(&want[i], &base);
        assert_false(want[i].flags & TRACE_BOX_LIN);
    }
    trace_brood_id kid = trace_boxcache_insert_at(c, 0, id, 1, &base, in);
    assert_int_equal(trace_boxcache_lookup_at(c, 0, id, 1, &base, out), kid);
    assert_memory_equal(out, want, sizeof want);
    /* a lazy child evaluated: its slot replaced, the others kept, and
     * the box given back is the one a lookup gives (stored or not) */
    trace_box now, now2;
    random_box(&now);
    now.flags |= TRACE_BOX_LIN;
    now2 = now;
    trace_qlin q1, q2;
    trace_boxcache_update_kept(c, kid, 2, &base, &now, &lins[0], &q1);
    trace_boxcache_update_kept(c, TRACE_BROOD_UNCACHED, 2, &base, &now2, &lins[0], &q2);
    assert_memory_equal(&now, &now2, sizeof now);
    assert_memory_equal(&q1, &q2, sizeof q1);
    assert_memory_equal(trace_boxcache_qlin(c, kid, 2), &q1, sizeof q1);
    trace_box again[4];
    assert_int_equal(trace_boxcache_lookup_at(c, 0, id, 1, &base, again), kid);
    want[2] = now;
    assert_memory_equal(again, want, sizeof want);
    trace_boxcache_destroy(&c);
}

/* A linear bound in floats (trace_lin_set) holds what the doubles held:
 * at every corner (eu, ev in -1, 0, 1) and either end of the radius the
 * doubles' point, in long double (the differences of a double and its
 * float are exact there), lies within the float bound's radius */
static void test_linear_bound_in_floats(void **state)
{
    (void)state;
    long checked = 0, dropped = 0;
    for (int n = 0; n < 20000; n++) {
        double x = any_double(), u = any_double(), v = any_double();
        double r = fabs(any_double());
        if (n % 3 == 0) {                  /* and ordinary magnitudes */
            x = ldexp((double)(next() >> 11) * 0x1p-53 - 0.5, (int)(next() % 40) - 20);
            u = x * 0x1p-10 * ((double)(next() >> 11) * 0x1p-53 - 0.5);
            v = u * 3.1;
            r = fabs(u) * 0.01;
        }
        trace_lin l;
        if (!trace_lin_set(&l, 0, x, u, v, r)) {
            dropped++;
            continue;
        }
        if (!isfinite(x) || !isfinite(u) || !isfinite(v) || !isfinite(r)) fail();
        for (int a = -1; a <= 1; a++)
            for (int b = -1; b <= 1; b++)
                for (int s = -1; s <= 1; s += 2) {
                    long double d = ((long double)x - l.x[0]) + ((long double)u - l.u[0]) * a +
                                    ((long double)v - l.v[0]) * b + (long double)r * s;
                    if (!(fabsl(d) <= (long double)l.r[0])) {
                        print_error("x %a u %a v %a r %a: off by %La, radius %a\n", x, u, v, r,
                                    d, (double)l.r[0]);
                        fail();
                    }
                    checked++;
                }
    }
    printf("linear bounds: %ld corners inside, %ld bounds not finite (dropped)\n", checked,
           dropped);
    assert_true(checked > 100000);
}

/* A linear bound as codes against its box (trace_qlin_encode) holds what
 * the floats held within the box: points of the float bound at the
 * corners (eu, ev in -1, 0, 1) and random inside, those that lie in the
 * box, lie in the decoded bound (long double); a side of length 0 is the
 * box itself; a radius wider than the box is refused */
static void test_linear_bound_codes(void **state)
{
    (void)state;
    long checked = 0, refused = 0, encoded = 0;
    for (int n = 0; n < 20000; n++) {
        trace_lin l;
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            double x = ldexp((double)(next() >> 11) * 0x1p-53 - 0.5, (int)(next() % 60) - 30);
            double w = fabs(x) * ldexp(1.0, -(int)(next() % 30)) + 0x1p-60;
            double u = w * ((double)(next() >> 11) * 0x1p-53 - 0.5);
            double v = w * ((double)(next() >> 11) * 0x1p-53 - 0.5);
            double r = w * (double)(next() % 100) * 0.002;
            assert_true(trace_lin_set(&l, k, x, u, v, r));
            /* the box: the bound's range, cut by up to a third on each side
             * (a hull may be narrower), sometimes flat */
            double a = (double)l.x[k] - fabs(l.u[k]) - fabs(l.v[k]) - l.r[k];
            double b = (double)l.x[k] + fabs(l.u[k]) + fabs(l.v[k]) + l.r[k];
            double cut = (b - a) * (double)(next() % 4) / 12.0;
            lo[k] = a + cut * (double)(next() % 2);
            hi[k] = b - cut * (double)(next() % 2);
            if (next() % 16 == 0) hi[k] = lo[k];
        }
        trace_qlin q;
        if (!trace_qlin_encode(&l, lo, hi, &q)) {
            refused++;
            continue;
        }
        encoded++;
        trace_dlin d;
        trace_qlin_decode(&q, lo, hi, &d);
        for (int j = 0; j < 40; j++) {
            double eu = j < 9 ? (double)(j % 3 - 1) : 2 * ((double)(next() >> 11) * 0x1p-53) - 1;
            double ev = j < 9 ? (double)(j / 3 - 1) : 2 * ((double)(next() >> 11) * 0x1p-53) - 1;
            double er = j < 9 ? (double)(j % 2 ? 1 : -1) : 2 * ((double)(next() >> 11) * 0x1p-53) - 1;
            for (int k = 0; k < 3; k++) {
                long double p = (long double)l.x[k] + (long double)l.u[k] * eu +
                                (long double)l.v[k] * ev + (long double)l.r[k] * er;
                if (p < lo[k] || p > hi[k]) continue;        /* not the surface */
                long double c = (long double)d.x[k] + (long double)d.u[k] * eu +
                                (long double)d.v[k] * ev;
                if (!(fabsl(p - c) <= d.r[k])) {
                    print_error("axis %d: %La off the decoded %La by more than %a\n", k, p, c,
                                d.r[k]);
                    fail();
                }
                checked++;
            }
        }
    }
    printf("linear bound codes: %ld encoded (%ld points inside), %ld refused\n", encoded,
           checked, refused);
    assert_true(encoded > 10000 && checked > 500000);
    /* a radius wider than the box is refused */
    trace_lin wide;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    for (int k = 0; k < 3; k++) assert_true(trace_lin_set(&wide, k, 0.5, 0, 0, k == 1 ? 2.0 : 0.1));
    trace_qlin q;
    assert_false(trace_qlin_encode(&wide, lo, hi, &q));
}

/* The restricted bound of a child cell (trace_lin_restrict) against points
 * of the child mapped to eu, ev independently (long double, from the
 * symbol's centre and radius), at the corners of the radius; a child's
 * bound is narrower than the whole cell's where its terms are; and the
 * box's (trace_box_restrict) lies within its node's box, flagged lazy */
static void test_restricted_bound(void **state)
{
    (void)state;
    long checked = 0;
    for (int n = 0; n < 4000; n++) {
        double u0 = (double)(next() >> 11) * 0x1p-53, v0 = (double)(next() >> 11) * 0x1p-53;
        double w = ldexp(1.0 + (double)(next() >> 11) * 0x1p-53, -(int)(next() % 30));
        double r[4] = {u0, u0 + w, v0, v0 + w * 0.75};
        trace_dlin l;
        for (int k = 0; k < 3; k++) {
            l.x[k] = (double)(next() >> 11) * 0x1p-50 - 4.0;
            l.u[k] = w * ((double)(next() >> 11) * 0x1p-53 - 0.5);
            l.v[k] = w * ((double)(next() >> 11) * 0x1p-53 - 0.5);
            l.r[k] = fabs(l.u[k]) * 0.01;
        }
        /* the symbols as aa_input defines them: u = mid + rad eu, mid its
         * centre (a double), rad at least the larger side (exact here) */
        long double um = aa_input_mid(r[0], r[1]), vm = aa_input_mid(r[2], r[3]);
        long double ur = fmaxl(r[1] - um, um - r[0]), vr = fmaxl(r[3] - vm, vm - r[2]);
        double wlo[3], whi[3];
        trace_lin_restrict(&l, r, r, wlo, whi);
        for (int i = 0; i < 4; i++) {
            double c[4] = {r[0], r[1], r[2], r[3]};
            double cu = 0.5 * (r[0] + r[1]), cv = 0.5 * (r[2] + r[3]);
            if (i & 1) c[0] = cu; else c[1] = cu;
            if (i & 2) c[2] = cv; else c[3] = cv;
            double lo[3], hi[3];
            trace_lin_restrict(&l, r, c, lo, hi);
            for (int j = 0; j < 25; j++) {
                long double uu = c[0] + (c[1] - c[0]) * (j % 5) / 4.0L;
                long double vv = c[2] + (c[3] - c[2]) * (j / 5) / 4.0L;
                long double eu = (uu - um) / ur, ev = (vv - vm) / vr;
                for (int k = 0; k < 3; k++)
                    for (int s = -1; s <= 1; s += 2) {
                        long double p = (long double)l.x[k] + (long double)l.u[k] * eu +
                                        (long double)l.v[k] * ev + (long double)l.r[k] * s;
                        if (!(p >= lo[k] && p <= hi[k])) {
                            print_error("child %d point %d axis %d: %La not in [%a, %a]\n", i,
                                        j, k, p, lo[k], hi[k]);
                            fail();
                        }
                        checked++;
                    }
            }
            /* the child's u and v terms are halves of the cell's */
            for (int k = 0; k < 3; k++) {
                double cw = hi[k] - lo[k], ww = whi[k] - wlo[k];
                assert_true(cw <= ww);
                if (fabs(l.u[k]) + fabs(l.v[k]) > 8 * l.r[k]) assert_true(cw < 0.8 * ww);
            }
            /* as a box: within its node's, lazy */
            trace_box node, b;
            memset(&node, 0, sizeof node);
            node.lo = v3(wlo[0] + 0.1 * (whi[0] - wlo[0]), wlo[1], wlo[2]);
            node.hi = v3(whi[0], whi[1] - 0.1 * (whi[1] - wlo[1]), whi[2]);
            trace_box_restrict(&l, &node, r, c, &b);
            assert_int_equal(b.flags, TRACE_BOX_LAZY);
            assert_true(b.lo.x >= node.lo.x && b.hi.y <= node.hi.y);
            assert_true(b.lo.z == lo[2] && b.hi.z == hi[2]);
        }
    }
    printf("restricted bounds: %ld points inside\n", checked);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_float_box_contains_the_double_box),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_empty_stays_empty_and_nan_stays_nan),
        cmocka_unit_test(test_offsets_from_the_parent),
        cmocka_unit_test(test_cache_gives_back_the_rounded_box),
        cmocka_unit_test(test_linear_bound_in_floats),
        cmocka_unit_test(test_linear_bound_codes),
        cmocka_unit_test(test_restricted_bound),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
