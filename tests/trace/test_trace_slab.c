/*
 * test_trace_slab.c: the slab of a box (trace/box.h, issue 10). A box of a
 * displaced surface may carry the range [slo, shi] of n . P over its cell;
 * trace_box_slab_hit narrows a ray's [t0, t1] to where the ray lies between
 * those planes. Never wrongly: for random slabs and rays (steep, grazing,
 * and nearly parallel to the planes), every t whose point lies between the
 * planes (decided in long double, away from the planes by 1e-18 of the
 * magnitudes: points just inside them included, where rounding decides)
 * stays inside the narrowed range; and the test is not idle:
 * it drops rays that pass beside the slab and narrows the ones that cross
 * it. The boxes themselves carry slabs that hold (test_corpus_containment
 * checks every sampled surface point against them).
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "trace/box.h"

static uint64_t rng = 0x51ab5eedULL;
static double uniform(void)
{
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng >> 11) * 0x1p-53;
}
static double symmetric(void) { return 2.0 * uniform() - 1.0; }

/* a unit normal stored as floats (as displace.c stores it) and a slab */
static void random_slab(trace_box *b, double scale)
{
    trace_box_no_slab(b);
    double n[3] = {symmetric(), symmetric(), symmetric()};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++) {
        /* cut to float bits first: a (float) conversion stored and read
         * back in one function may be forwarded unrounded (GCC 12 -O2,
         * see displace.c's float_grid) */
        double x = n[i] / len;
        uint64_t bits;
        memcpy(&bits, &x, sizeof bits);
        bits &= ~((UINT64_C(1) << 29) - 1);
        memcpy(&x, &bits, sizeof x);
        b->sn[i] = (float)x;
    }
    double c = scale * symmetric(), w = scale * pow(10.0, -6.0 * uniform());
    b->slo = c - w;
    b->shi = c + w;
}

static long double along(const trace_box *b, const trace_ray *r, long double t)
{
    long double s = 0;
    const double *o = &r->o.x, *d = &r->d.x;
    for (int i = 0; i < 3; i++) s += (long double)b->sn[i] * ((long double)o[i] + t * d[i]);
    return s;
}

static void test_slab_never_drops_a_point_between_its_planes(void **state)
{
    (void)state;
    long rays = 0, inside = 0, dropped = 0, narrowed = 0;
    for (int k = 0; k < 20000; k++) {
        double scale = pow(10.0, 3.0 * symmetric());
        trace_box b;
        random_slab(&b, scale);
        vec3 o = v3(scale * 4 * symmetric(), scale * 4 * symmetric(), scale * 4 * symmetric());
        vec3 d = v3(symmetric(), symmetric(), symmetric());
        if (k % 4 == 0) {
            /* nearly parallel to the planes: d minus its part along n,
             * plus a part of 1e-3 .. 1e-15 */
            double nd = b.sn[0] * d.x + b.sn[1] * d.y + b.sn[2] * d.z;
            double eps = pow(10.0, -3.0 - 12.0 * uniform());
            d = v3(d.x - (nd - eps) * b.sn[0], d.y - (nd - eps) * b.sn[1],
                   d.z - (nd - eps) * b.sn[2]);
        }
        trace_ray r;
        trace_ray_init(&r, o, d, 0.0, INFINITY);
        double tmin = 0.0, tmax = 16.0 * scale, t0 = tmin, t1 = tmax;
        rays++;
        bool hit = trace_box_slab_hit(&b, &r, &t0, &t1);
        if (!hit) dropped++;
        else if (t1 - t0 < tmax - tmin) narrowed++;
        /* where the ray crosses the slab's mid-plane, and around it */
        long double s0 = along(&b, &r, 0), s1 = along(&b, &r, 1);
        long double rate = s1 - s0;
        if (rate == 0) continue;
        long double mid = 0.5L * ((long double)b.slo + b.shi);
        long double tc = (mid - s0) / rate, half = 0.5L * ((long double)b.shi - b.slo) / fabsl(rate);
        for (int j = -10; j <= 10; j++) {
            /* through the slab, and just inside each plane */
            long double t = j == -10 ? tc - half * (1 - 1e-12L)
                            : j == 10 ? tc + half * (1 - 1e-12L)
                                      : tc + half * j / 9.0L;
            if (!(t >= tmin && t <= tmax)) continue;
            long double s = along(&b, &r, t);
            long double hair = 1e-18L * (fabsl(s0) + fabsl(s) + fabs(b.slo) + fabs(b.shi));
            if (!(s > b.slo + hair && s < b.shi - hair)) continue;
            inside++;
            if (!hit || t < t0 || t > t1) {
                fail_msg("ray %d: t = %.17Lg lies between the planes, but the test gives %s "
                         "[%.17g, %.17g]", k, t, hit ? "" : "a miss,", t0, t1);
            }
        }
    }
    printf("%ld rays: %ld points between the planes kept, %ld rays dropped, %ld narrowed\n",
           rays, inside, dropped, narrowed);
    assert_true(inside > rays);
    assert_true(dropped > rays / 4);    /* not idle: rays beside the slab go */
    assert_true(narrowed > rays / 4);   /* and crossing ones are narrowed */
}

/* A box without a slab leaves the range alone; a ray between the planes
 * or parallel to them is not narrowed; one crossing them is narrowed to
 * where it is between them */
static void test_slab_edge_cases(void **state)
{
    (void)state;
    trace_box b;
    trace_box_no_slab(&b);
    trace_ray r;
    trace_ray_init(&r, v3(0, 0, 0), v3(1, 0, 0), 0.0, INFINITY);
    double t0 = 1, t1 = 2;
    assert_true(trace_box_slab_hit(&b, &r, &t0, &t1));
    assert_true(t0 == 1 && t1 == 2);
    b.sn[1] = 1.0f;                     /* planes y = -1 and y = 1 */
    b.slo = -1;
    b.shi = 1;
    assert_true(trace_box_slab_hit(&b, &r, &t0, &t1));
    assert_true(t0 == 1 && t1 == 2);
    trace_ray_init(&r, v3(0, 3, 0), v3(1, 0, 0), 0.0, INFINITY);
    assert_true(trace_box_slab_hit(&b, &r, &t0, &t1));   /* parallel: not narrowed */
    trace_ray_init(&r, v3(0, 3, 0), v3(0, -1, 0), 0.0, INFINITY);
    t0 = 0;
    t1 = 100;
    assert_true(trace_box_slab_hit(&b, &r, &t0, &t1));
    assert_true(t0 <= 2 && t0 > 1.999999 && t1 >= 4 && t1 < 4.000001);
    t0 = 0;
    t1 = 1.5;                           /* ends before the slab */
    assert_false(trace_box_slab_hit(&b, &r, &t0, &t1));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab_never_drops_a_point_between_its_planes),
        cmocka_unit_test(test_slab_edge_cases),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
