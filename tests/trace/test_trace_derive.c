/*
 * test_trace_derive.c: what the renderer derives of an object from its
 * transforms (trace_object_derive, world.c), which every placement's view
 * derives again (trace/group.c):
 *
 * - its largest stretch (scale) is the 64-step power iteration's, to the
 *   bit, though the code stops at a fixed point (the oracle here is the
 *   plain 64 steps, written again), on rotations times uniform scales
 *   (fixed points in a few steps), uneven scales, shears and mirrors;
 * - the normal-length bounds hold for unit normals of random directions;
 * - a nearly singular or non-finite transform is refused with the
 *   object's name.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "trace/world.h"
#include "util/err.h"

/* the oracle: 64 steps of power iteration on M^T M, no early stop */
static double stretch_64(const mat4 *m)
{
    vec3 x = v3(1, 1, 1);
    double s = 0;
    for (int it = 0; it < 64; it++) {
        vec3 y = mat4_xform_vector(m, x);
        vec3 z = v3(m->m[0][0] * y.x + m->m[1][0] * y.y + m->m[2][0] * y.z,
                    m->m[0][1] * y.x + m->m[1][1] * y.y + m->m[2][1] * y.z,
                    m->m[0][2] * y.x + m->m[1][2] * y.y + m->m[2][2] * y.z);
        double l = v3_length(z);
        if (!(l > 0)) break;
        s = sqrt(l / v3_length(x));
        x = v3_scale(z, 1.0 / l);
    }
    return s * (1.0 + 1e-6);
}

static double rnd(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return (*seed >> 8) / (double)(1u << 24);
}

/* kind 0: rotation x uniform scale; 1: uneven scale; 2: shear; 3: mirror */
static mat4 random_transform(unsigned *seed, int kind)
{
    double tx = rnd(seed) * 10 - 5, ty = rnd(seed) * 10 - 5, tz = rnd(seed) * 10;
    double a = rnd(seed) * 360, ax = rnd(seed) - 0.5, ay = rnd(seed) - 0.5, az = rnd(seed) + 0.1;
    mat4 m = mat4_mul(mat4_translate(tx, ty, tz), mat4_rotate(a, ax, ay, az));
    double k = 0.1 + 3 * rnd(seed);
    if (kind == 0) return mat4_mul(m, mat4_scale(k, k, k));
    double e = 0.2 + rnd(seed);
    if (kind == 1) return mat4_mul(m, mat4_scale(k, e, 1.5 * k));
    if (kind == 3) return mat4_mul(m, mat4_scale(-k, k, k));
    mat4 shear = mat4_identity();
    shear.m[0][1] = rnd(seed) - 0.5;
    shear.m[1][2] = rnd(seed) - 0.5;
    return mat4_mul(m, shear);
}

static void test_scale_is_the_64_steps(void **state)
{
    (void)state;
    trace_world world;
    memset(&world, 0, sizeof world);
    trace_object *obj = calloc(1, sizeof *obj);
    assert_non_null(obj);
    snprintf(obj->name, sizeof obj->name, "probe");
    unsigned seed = 7;
    int early = 0;
    for (int i = 0; i < 4000; i++) {
        mat4 m = random_transform(&seed, i % 4);
        obj->to_camera = m;
        assert_true(mat4_invert(&m, &obj->from_camera));
        char err[ERR_LEN];
        assert_true(trace_object_derive(&world, obj, false, err, sizeof err));
        double want = stretch_64(&obj->to_camera), want_inv = stretch_64(&obj->from_camera);
        assert_memory_equal(&obj->scale, &want, sizeof want);
        /* normal bounds: |from_camera^T n|^2 of unit n within them */
        double lo = 1.0 / want;
        assert_true(obj->normal_len2[0] == lo * lo * (1.0 - 1e-9));
        assert_true(obj->normal_len2[1] == want_inv * want_inv * (1.0 + 1e-9));
        vec3 n = v3_normalize(v3(rnd(&seed) - 0.5, rnd(&seed) - 0.5, rnd(&seed) - 0.5));
        mat4 t = mat4_transpose(obj->from_camera);
        double l2 = v3_dot(mat4_xform_vector(&t, n), mat4_xform_vector(&t, n));
        assert_true(l2 >= obj->normal_len2[0] && l2 <= obj->normal_len2[1]);
        early += i % 4 == 0;
    }
    printf("4000 transforms (%d rotations x uniform scales): the scale is the 64 steps' to the "
           "bit\n", early);
    free(obj);
}

static void test_singular_is_refused(void **state)
{
    (void)state;
    trace_world world;
    memset(&world, 0, sizeof world);
    trace_object *obj = calloc(1, sizeof *obj);
    assert_non_null(obj);
    snprintf(obj->name, sizeof obj->name, "sphere at t.rib:9");
    obj->to_camera = mat4_scale(1, 1, 1e-13);
    obj->from_camera = mat4_scale(1, 1, 1e13);
    char err[ERR_LEN];
    assert_false(trace_object_derive(&world, obj, false, err, sizeof err));
    assert_non_null(strstr(err, "sphere at t.rib:9"));
    assert_non_null(strstr(err, "nearly singular"));
    obj->to_camera = mat4_identity();
    obj->to_camera.m[0][0] = NAN;
    obj->from_camera = mat4_identity();
    assert_false(trace_object_derive(&world, obj, false, err, sizeof err));
    free(obj);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scale_is_the_64_steps),
        cmocka_unit_test(test_singular_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
