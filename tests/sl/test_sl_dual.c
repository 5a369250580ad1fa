/*
 * tests/sl/test_sl_dual.c: the dual (automatic differentiation) mode of the
 * VM against central finite differences of the float mode.
 *
 *   operations   d/du and d/dv of expressions using every differentiable
 *                operation (arithmetic, math, noise in 1-4 D, periodic and
 *                vector noise, geometry, transforms), on the plane and on
 *                the sphere, at points away from kinks
 *   Du Dv Deriv  the built-ins read the derivative parts
 *   shaders      P of the smooth library displacement shaders, and N =
 *                calculatenormal(P) = dP/du x dP/dv, against differences
 *                of the float run
 *
 * Step h = 1e-6 (central): difference error ~ h^2 f''' + eps/h, so the
 * tolerance is 2e-5 (1 + |derivative|).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl_harness.h"

static const double H = 1e-6;
static const double UV[][2] = {
    { 0.13, 0.21 }, { 0.37, 0.64 }, { 0.71, 0.83 }, { 0.58, 0.33 },
};
enum { NUV = sizeof UV / sizeof UV[0] };

static void float_P(sl_vm *vm, const sl_instance *inst, h_surface s, double u, double v,
                    double P[3])
{
    h_globals_float(vm, s, u, v);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
}

static bool near(double got, double want)
{
    return fabs(got - want) <= 2e-5 * (1 + fabs(want));
}

/* The dual run's P against differences of the float runs, for all 3
 * components at every sample point. Returns the number of mismatches. */
static int check_program(sl_program *p, h_surface s, const char *what)
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    int bad = 0;
    for (int k = 0; k < NUV; k++) {
        double u = UV[k][0], v = UV[k][1];
        h_globals_dual(vm, s, u, v);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
        sl_dual D[3];
        sl_vm_get_dual(vm, SL_G_P, D);
        double f0[3], fu1[3], fu0[3], fv1[3], fv0[3];
        float_P(vm, inst, s, u, v, f0);
        float_P(vm, inst, s, u + H, v, fu1);
        float_P(vm, inst, s, u - H, v, fu0);
        float_P(vm, inst, s, u, v + H, fv1);
        float_P(vm, inst, s, u, v - H, fv0);
        for (int i = 0; i < 3; i++) {
            double du = (fu1[i] - fu0[i]) / (2 * H), dv = (fv1[i] - fv0[i]) / (2 * H);
            bool ok = near(D[i].v, f0[i]) && near(D[i].du, du) && near(D[i].dv, dv);
            if (!ok && bad < 4)
                fprintf(stderr, "%s (%s) at u=%g v=%g [%d]: dual (%.9g, %.9g, %.9g), "
                        "differences (%.9g, %.9g, %.9g)\n", what,
                        s == H_PLANE ? "plane" : "sphere", u, v, i, D[i].v, D[i].du, D[i].dv,
                        f0[i], du, dv);
            bad += !ok;
        }
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return bad;
}

static void check_expr(const char *expr)
{
    char src[2048];
    snprintf(src, sizeof src, "displacement t() { P = point(%s, 0, 0); }", expr);
    sl_program *p = h_compile(src);
    assert_non_null(p);
    int bad = check_program(p, H_PLANE, expr) + check_program(p, H_SPHERE, expr);
    sl_program_destroy(&p);
    assert_int_equal(bad, 0);
}

static void check_body(const char *body)
{
    char src[2048];
    snprintf(src, sizeof src, "displacement t() { %s }", body);
    sl_program *p = h_compile(src);
    assert_non_null(p);
    int bad = check_program(p, H_PLANE, body) + check_program(p, H_SPHERE, body);
    sl_program_destroy(&p);
    assert_int_equal(bad, 0);
}

/* ---------------------------------------------------------------------- */

static void test_arithmetic(void **state)
{
    (void)state;
    check_expr("u * v + u - v / (v + 1)");
    check_expr("-u * u * u + 2 * v * v");
    check_expr("(u + 1) / (v * v + 0.5)");
    check_expr("xcomp(P) * ycomp(P) + zcomp(P)");
}

static void test_math(void **state)
{
    (void)state;
    check_expr("sin(u * 3) * cos(v * 2) + tan(u)");
    check_expr("exp(-u) * v + log(u + 1) / (v + 1)");
    check_expr("log(u + 2, v + 3)");
    check_expr("pow(u + 1, v + 0.5) + pow(v + 0.2, 3)");
    check_expr("sqrt(u * u + v * v) + inversesqrt(1 + u)");
    check_expr("atan(u, v + 1) + atan(u * 2) + asin(u * 0.5) + acos(v * 0.5)");
    check_expr("smoothstep(0, 1, u) + smoothstep(v * 0.1, 0.9, u * v + 0.2)");
    check_expr("mix(u, v, u * v) + clamp(u * 3, 0.5, 1) + min(u, v * 0.5) + max(u, 0.9 * v)");
    check_expr("abs(u - 0.5) + mod(u * 5, 1) + floor(u * 3) + step(0.5, v) + sign(u)");
    check_expr("radians(u * 90) + degrees(v)");
}

static void test_noise(void **state)
{
    (void)state;
    check_expr("noise(u * 4) + noise(u * 4, v * 3)");
    check_expr("noise(P * 3) + noise(P * 2, u)");
    check_expr("pnoise(u * 3, 4) + pnoise(P * 2, point(4, 4, 4))");
    check_body("P = vector noise(P * 2);");
    check_body("color c = noise(u * 3, v * 5); P = point(comp(c, 0), comp(c, 1), comp(c, 2));");
    check_expr("cellnoise(P * 0.1)");
}

static void test_geometry(void **state)
{
    (void)state;
    check_expr("length(P) + distance(P, point(1, 2, 3))");
    check_body("P = normalize(P + point(0.1, 0.2, 0.3));");
    check_body("P = P ^ vector(1, 2, 3) + reflect(P, normalize(N + vector(0.3, 0, 0)));");
    check_body("P = transform(\"object\", P) * 2;");
}

static void test_derivative_builtins(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t() {\n"
                              "  P = point(Du(u * u), Dv(v * v * v), Deriv(u * u, u));\n"
                              "  N = point(Deriv(v, v * v), area(point(u * 2, v * 3, 0)), Du(v));\n"
                              "}\n");
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    double u = 0.3, v = 0.6;
    h_globals_dual(vm, H_PLANE, u, v);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
    sl_dual P[3], N[3];
    sl_vm_get_dual(vm, SL_G_P, P);
    sl_vm_get_dual(vm, SL_G_N, N);
    assert_true(near(P[0].v, 2 * u));
    assert_true(near(P[1].v, 3 * v * v));
    assert_true(near(P[2].v, 2 * u));
    assert_true(near(N[0].v, 1 / (2 * v)));   /* dv / d(v^2) */
    assert_true(near(N[1].v, 6));              /* |(2,0,0) x (0,3,0)| */
    assert_true(N[2].v == 0);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* filterstep over the filter width of x: with du = dv = 0.05 set by the
 * renderer, fw = |Du(x)| du + |Dv(x)| dv; the box-filtered step is
 * clamp((x - edge) / fw + 1/2, 0, 1). The interval run over a box holds
 * the dual values at its points. */
static void test_filterstep(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t() {\n"
                              "  P = point(filterstep(0.5, u * 4 - 1.2),\n"
                              "            filterstep(0.3, v, \"width\", 2), 0);\n"
                              "}\n");
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    for (int k = 0; k < 4; k++) {
        double u = 0.40 + 0.02 * k, v = 0.27 + 0.03 * k;
        h_globals_dual(vm, H_PLANE, u, v);
        sl_dual w = { 0.05, 0, 0 };
        sl_vm_set_dual(vm, SL_G_du, &w);
        sl_vm_set_dual(vm, SL_G_dv, &w);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
        sl_dual P[3];
        sl_vm_get_dual(vm, SL_G_P, P);
        double a = (4 * u - 1.2 - 0.5) / (4 * 0.05) + 0.5, b = (v - 0.3) / (2 * 0.05) + 0.5;
        a = a < 0 ? 0 : a > 1 ? 1 : a;
        b = b < 0 ? 0 : b > 1 ? 1 : b;
        assert_true(near(P[0].v, a));
        assert_true(near(P[1].v, b));
        /* an interval run over a box around (u, v) */
        h_globals_interval(vm, H_PLANE, u - 0.01, u + 0.01, v - 0.01, v + 0.01);
        ia_interval wi = ia_point(0.05);
        sl_vm_set_interval(vm, SL_G_du, &wi);
        sl_vm_set_interval(vm, SL_G_dv, &wi);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL), SL_OK);
        ia_interval I[3];
        sl_vm_get_interval(vm, SL_G_P, I);
        assert_true(I[0].lo <= a + 1e-12 && a <= I[0].hi + 1e-12);
        assert_true(I[1].lo <= b + 1e-12 && b <= I[1].hi + 1e-12);
        assert_true(I[0].hi - I[0].lo < 1);    /* narrower than the step's [0, 1] */
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* The displaced P and N = calculatenormal(P) of a library shader. */
static void check_shader(const char *name)
{
    sl_program *p = h_compile_library(name);
    assert_non_null(p);
    int bad = check_program(p, H_PLANE, name) + check_program(p, H_SPHERE, name);
    assert_int_equal(bad, 0);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    for (int s = H_PLANE; s <= H_SPHERE; s++) {
        for (int k = 0; k < NUV; k++) {
            double u = UV[k][0], v = UV[k][1];
            h_globals_dual(vm, (h_surface)s, u, v);
            assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
            sl_dual N[3];
            sl_vm_get_dual(vm, SL_G_N, N);
            double a[3], b[3], c[3], d[3];
            float_P(vm, inst, (h_surface)s, u + H, v, a);
            float_P(vm, inst, (h_surface)s, u - H, v, b);
            float_P(vm, inst, (h_surface)s, u, v + H, c);
            float_P(vm, inst, (h_surface)s, u, v - H, d);
            vec3 pu = v3_scale(v3_sub(v3(a[0], a[1], a[2]), v3(b[0], b[1], b[2])), 1 / (2 * H));
            vec3 pv = v3_scale(v3_sub(v3(c[0], c[1], c[2]), v3(d[0], d[1], d[2])), 1 / (2 * H));
            vec3 n = v3_cross(pu, pv);
            double scale = v3_length(n);
            assert_true(fabs(N[0].v - n.x) <= 1e-4 * (1 + scale));
            assert_true(fabs(N[1].v - n.y) <= 1e-4 * (1 + scale));
            assert_true(fabs(N[2].v - n.z) <= 1e-4 * (1 + scale));
        }
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_wave(void **state) { (void)state; check_shader("wave"); }
static void test_ufo(void **state) { (void)state; check_shader("ufo"); }
static void test_threads(void **state) { (void)state; check_shader("threads"); }
static void test_lumpy(void **state) { (void)state; check_shader("lumpy"); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arithmetic),
        cmocka_unit_test(test_math),
        cmocka_unit_test(test_noise),
        cmocka_unit_test(test_geometry),
        cmocka_unit_test(test_derivative_builtins),
        cmocka_unit_test(test_filterstep),
        cmocka_unit_test(test_wave),
        cmocka_unit_test(test_ufo),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_lumpy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
