/*
 * test_trace_float_bvh.c: the BVH over float boxes that meshes and groups
 * share (trace/mesh.h), whose elements' boxes it keeps in 6 bytes on its
 * leaves' grids. The oracle is the plain slab test of each element's own
 * float box (trace_box_hit, which the walk uses too): every element whose
 * box a ray meets must reach the walk's leaf callback, for boxes of every
 * size (tiny, flat, huge, not finite) and rays aimed at their corners and
 * faces, where a box rounded the wrong way would be missed.
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "trace/mesh.h"

/* more boxes than one subtree task of the build holds (mesh.c TASK_MAX):
 * the tree is joined from several */
enum { NBOXES = 20000, NRAYS = 1500 };

static uint64_t rng = 0x9e3779b97f4a7c15ull;

static double uniform(void)           /* [0, 1) */
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}

/* random boxes: most small or medium, some flat on an axis, some huge, a
 * few copies and a few without end */
static void make_boxes(float (*b)[6], int n)
{
    for (int k = 0; k < n; k++) {
        int kind = (int)(uniform() * 20);
        if (kind == 0 && k > 0) {
            memcpy(b[k], b[k - 1], sizeof b[k]);
            continue;
        }
        for (int a = 0; a < 3; a++) {
            double c = -10 + 20 * uniform();
            double e = pow(10.0, -6 + 7 * uniform());
            if (kind == 1 && a == 1) e = 0;             /* flat */
            if (kind == 2) e = pow(10.0, 2 + 4 * uniform());   /* huge */
            b[k][a] = (float)(c - e);
            b[k][3 + a] = (float)(c + e);
        }
        if (kind == 3 && k % 7 == 0) b[k][3] = INFINITY;   /* without end */
    }
}

static bool exact_hit(const float *f, const trace_ray *ray, double tmax)
{
    trace_box b = {.lo = v3(f[0], f[1], f[2]), .hi = v3(f[3], f[4], f[5])};
    double t0, t1;
    return trace_box_hit(&b, ray, ray->tmin, tmax, &t0, &t1, NULL);
}

typedef struct visits {
    unsigned char *seen;
    long calls;
} visits;

static int record(void *ctx, int k)
{
    visits *v = ctx;
    v->seen[k] = 1;
    v->calls++;
    return 0;
}

static void test_walk_reaches_every_box_a_ray_meets(void **state)
{
    (void)state;
    float (*b)[6] = malloc(sizeof *b * NBOXES);
    assert_non_null(b);
    make_boxes(b, NBOXES);
    struct trace_mesh_bvh *t = trace_float_bvh_build((const float (*)[6])b, NBOXES, 3);
    /* its root is the union of the boxes */
    trace_box root;
    assert_true(trace_float_bvh_root(t, &root));
    float u[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < NBOXES; k++)
        for (int a = 0; a < 3; a++) {
            u[a] = fminf(u[a], b[k][a]);
            u[3 + a] = fmaxf(u[3 + a], b[k][3 + a]);
        }
    assert_true(root.lo.x == u[0] && root.lo.y == u[1] && root.lo.z == u[2]);
    assert_true(root.hi.x == u[3] && root.hi.y == u[4] && root.hi.z == u[5]);

    visits v = {calloc(NBOXES, 1), 0};
    assert_non_null(v.seen);
    long met = 0, missed = 0;
    for (int r = 0; r < NRAYS; r++) {
        /* aimed at a corner, an edge or a face of a box of finite extent */
        int k = (int)(uniform() * NBOXES);
        if (!isfinite(b[k][3])) k = (k + 1) % NBOXES;
        double p[3];
        for (int a = 0; a < 3; a++) {
            double s = uniform();
            p[a] = s < 0.4 ? b[k][a] : s < 0.8 ? b[k][3 + a] : b[k][a] + (b[k][3 + a] - b[k][a]) * uniform();
        }
        double d[3] = {uniform() - 0.5, uniform() - 0.5, uniform() - 0.5};
        double far = 5 + 100 * uniform();
        trace_ray ray;
        trace_ray_init(&ray, v3(p[0] - far * d[0], p[1] - far * d[1], p[2] - far * d[2]),
                       v3(d[0], d[1], d[2]), 0.0, INFINITY);
        trace_hit best = {.t = INFINITY};
        memset(v.seen, 0, NBOXES);
        trace_float_bvh_walk(t, &ray, &best, false, record, &v);
        for (int j = 0; j < NBOXES; j++) {
            if (!exact_hit(b[j], &ray, INFINITY)) continue;
            met++;
            if (!v.seen[j]) {
                if (missed < 5)
                    fprintf(stderr, "ray %d: box %d [%a %a %a | %a %a %a] met, not visited\n",
                            r, j, b[j][0], b[j][1], b[j][2], b[j][3], b[j][4], b[j][5]);
                missed++;
            }
        }
    }
    printf("%d boxes, %d rays: %ld boxes met, %ld visits (%.2f per box met), %ld missed\n",
           NBOXES, NRAYS, met, v.calls, (double)v.calls / (double)(met ? met : 1), missed);
    assert_true(met > NRAYS);          /* the rays were aimed at boxes */
    assert_int_equal(missed, 0);
    free(v.seen);
    trace_float_bvh_free(&t);
    free(b);
}

/* The same boxes built twice give the same tree, to the bit; another set
 * of boxes does not. */
static void test_build_is_a_function_of_the_boxes(void **state)
{
    (void)state;
    float (*b)[6] = malloc(sizeof *b * NBOXES);
    assert_non_null(b);
    make_boxes(b, NBOXES);
    struct trace_mesh_bvh *x = trace_float_bvh_build((const float (*)[6])b, NBOXES, 1);
    struct trace_mesh_bvh *y = trace_float_bvh_build((const float (*)[6])b, NBOXES, 1);
    assert_true(trace_float_bvh_equal(x, y, NBOXES));
    /* and over threads: the subtrees built apart and joined */
    for (int threads = 2; threads <= 5; threads += 3) {
        struct trace_mesh_bvh *p = trace_float_bvh_build((const float (*)[6])b, NBOXES, threads);
        assert_true(trace_float_bvh_equal(x, p, NBOXES));
        trace_float_bvh_free(&p);
    }
    b[NBOXES / 2][4] = nextafterf(b[NBOXES / 2][4], INFINITY) + 1.0f;
    struct trace_mesh_bvh *z = trace_float_bvh_build((const float (*)[6])b, NBOXES, 1);
    assert_false(trace_float_bvh_equal(x, z, NBOXES));
    trace_float_bvh_free(&x);
    trace_float_bvh_free(&y);
    trace_float_bvh_free(&z);
    free(b);
}

/* trace_float_down/up (the pieces' boxes in float, rounded outward)
 * without nextafterf: the same floats as the call, over zeros, the
 * largest floats, overflow, subnormals, infinities, NaN and random
 * doubles of every magnitude */
static void test_float_rounding(void **state)
{
    (void)state;
    static const double special[] = {
        0.0, -0.0, 1.0, -1.0, FLT_MAX, -FLT_MAX, 0x1p-149, -0x1p-149, 0x1p-150, -0x1p-150,
        0x1p-160, -0x1p-160, 0x1p-126, (double)FLT_MAX * (1 + 0x1p-30),
        -(double)FLT_MAX * (1 + 0x1p-30), 1e300, -1e300, INFINITY, -INFINITY, NAN,
        1.0 + 0x1p-40, -1.0 - 0x1p-40};
    int n = 0;
    for (int k = 0; k < 400000; k++) {
        double x;
        if (k < (int)(sizeof special / sizeof special[0])) {
            x = special[k];
        } else {
            uint64_t b = ((uint64_t)(uniform() * 4294967296.0) << 32) |
                         (uint64_t)(uniform() * 4294967296.0);
            memcpy(&x, &b, sizeof x);
            if (k % 2) x = ldexp(uniform() - 0.5, (int)(uniform() * 300) - 160);
        }
        float f = (float)x;
        float dn = (double)f > x ? nextafterf(f, -INFINITY) : f;
        float up = (double)f < x ? nextafterf(f, INFINITY) : f;
        float gd = trace_float_down(x), gu = trace_float_up(x);
        if (memcmp(&gd, &dn, sizeof gd) != 0 || memcmp(&gu, &up, sizeof gu) != 0)
            fail_msg("%a: down %a up %a, nextafterf gives %a and %a", x, gd, gu, dn, up);
        n++;
    }
    printf("%d doubles rounded to floats as nextafterf rounds them\n", n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_float_rounding),
        cmocka_unit_test(test_walk_reaches_every_box_a_ray_meets),
        cmocka_unit_test(test_build_is_a_function_of_the_boxes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
