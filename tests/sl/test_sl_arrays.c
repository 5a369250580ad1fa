/*
 * tests/sl/test_sl_arrays.c: fixed-size arrays of the shading language
 * (locals, function parameters sized and unsized, shader parameters with
 * defaults, initialisers, indexing, element assignment, arraylength):
 *
 *   float      values against hand computations
 *   ranges     an index that varies over a (u,v) box reads the merge of
 *              exactly the elements it can reach, and a store merges each
 *              reachable element with the stored value (interval and
 *              affine mode), containing float samples
 *   errors     exact diagnostics at compile time; an index out of range
 *              at run time stops the run with the shader position
 *
 * Globals are those of the plane at (u, v) = (0.25, 0.75) unless a range
 * is given: P = (-0.5, 0.5, 0), s = u, t = v.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl_harness.h"

static const double U = 0.25, V = 0.75;

static sl_program *compile_ok(const char *src)
{
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    if (!p || text[0])
        fprintf(stderr, "%s", text);
    assert_non_null(p);
    assert_string_equal(text, "");
    free(text);
    return p;
}

static void run_float(const sl_program *p, double u, double v, double P[3])
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    h_globals_float(vm, H_PLANE, u, v);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL);
    if (st != SL_OK)
        fprintf(stderr, "%s\n", sl_vm_error(vm));
    assert_int_equal(st, SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
}

static void close_to(double got, double want, const char *what)
{
    if (!(fabs(got - want) <= 1e-12 * (1 + fabs(want)))) {
        fprintf(stderr, "%s\n: got %.17g, want %.17g\n", what, got, want);
        fail();
    }
}

static void expect_src(const char *src, double x, double y, double z)
{
    sl_program *p = compile_ok(src);
    double P[3];
    run_float(p, U, V, P);
    close_to(P[0], x, src);
    close_to(P[1], y, src);
    close_to(P[2], z, src);
    sl_program_destroy(&p);
}

static void expect_errors(const char *src, const char *expected)
{
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    if (strcmp(text, expected) != 0)
        fprintf(stderr, "--- got:\n%s--- expected:\n%s", text, expected);
    assert_null(p);
    assert_string_equal(text, expected);
    free(text);
}

/* Interval and affine enclosures of P over [u0,u1] x [v0,v1] of the plane. */
static void run_ranges(const sl_program *p, double u0, double u1, double v0, double v1,
                       ia_interval I[3], ia_interval A[3])
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    h_globals_interval(vm, H_PLANE, u0, u1, v0, v1);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL), SL_OK);
    sl_vm_get_interval(vm, SL_G_P, I);
    h_globals_affine(vm, &ctx, H_PLANE, u0, u1, v0, v1);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx), SL_OK);
    aa_form a[3];
    sl_vm_get_affine(vm, SL_G_P, a);
    for (int k = 0; k < 3; k++)
        A[k] = aa_range(&a[k]);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
}

static void assert_hull(ia_interval r, double lo, double hi)
{
    if (!(r.lo <= lo && r.hi >= hi && r.lo >= lo - 1e-9 && r.hi <= hi + 1e-9)) {
        fprintf(stderr, "[%.17g, %.17g], want [%g, %g]\n", r.lo, r.hi, lo, hi);
        fail();
    }
}

/* ---------------------------------------------------------------------- */

static void test_array_values(void **state)
{
    (void)state;
    /* locals with initialisers, element updates by constant and by varying
     * index, an unsized parameter, a shader parameter with a default,
     * arrays of colours, arraylength */
    expect_src("float sum(float a[]) {\n"
               "    float i, t = 0;\n"
               "    for (i = 0; i < arraylength(a); i += 1) t += a[i];\n"
               "    return t;\n"
               "}\n"
               "displacement d(float knots[4] = {0, 0.25, 0.5, 1}) {\n"
               "    float a[3] = {1, 2, 3};\n"
               "    color c[2] = {(1, 0, 0), color(0, 1, 0)};\n"
               "    a[1] += 10;\n"
               "    a[t * 3] = 7;\n"                      /* index 2.25: element 2 */
               "    c[1] = c[0] * 2;\n"
               "    P = point(knots[s * 4] + sum(a), arraylength(knots), comp(c[1], 0));\n"
               "}\n",
               0.25 + 1 + 12 + 7, 4, 2);
    /* the size from the initializer; whole-array copy; a sized parameter
     * written through 'output'; points */
    expect_src("void fill(output float a[3]; float x) { a[0] = x; a[1] = 2 * x; a[2] = 3 * x; }\n"
               "displacement d() {\n"
               "    float a[] = {5, 6, 7}, b[3];\n"
               "    point p[2] = {(1, 2, 3), (4, 5, 6)};\n"
               "    b = a;\n"
               "    fill(a, s);\n"
               "    P = point(a[2] + b[0], arraylength(a), ycomp(p[u * 8 - 1]));\n"
               "}\n",
               3 * U + 5, 3, 5);
    /* a nested function reaching an enclosing array through extern */
    expect_src("displacement d() {\n"
               "    float w[4] = {1, 2, 4, 8};\n"
               "    float weight(float i) { extern float w[]; return w[i]; }\n"
               "    P = point(weight(0) + weight(3), weight(s * 8), 0);\n"
               "}\n",
               9, 4, 0);
}

static void test_array_ranges(void **state)
{
    (void)state;
    /* s in [0.2, 0.3]: s * 4 in [0.8, 1.2] reaches elements 0 and 1 only */
    sl_program *p = compile_ok("displacement d() {\n"
                               "    float a[4] = {1, 5, 2, 8};\n"
                               "    float b[4] = {1, 5, 2, 8};\n"
                               "    b[s * 4] = 10;\n"
                               "    P = point(a[s * 4], b[0] + 100 * b[2], b[1]);\n"
                               "}\n");
    ia_interval I[3], A[3];
    run_ranges(p, 0.2, 0.3, 0.4, 0.5, I, A);
    assert_hull(I[0], 1, 5);
    assert_hull(A[0], 1, 5);
    assert_hull(I[1], 1 + 200, 10 + 200);   /* element 2 untouched */
    assert_hull(A[1], 1 + 200, 10 + 200);
    assert_hull(I[2], 5, 10);
    assert_hull(A[2], 5, 10);
    /* float samples lie inside */
    for (double u = 0.2; u <= 0.3; u += 0.01) {
        double F[3];
        run_float(p, u, 0.45, F);
        for (int k = 0; k < 3; k++)
            assert_true(F[k] >= I[k].lo && F[k] <= I[k].hi && F[k] >= A[k].lo &&
                        F[k] <= A[k].hi);
    }
    /* a decided index is exact: [0.3, 0.4] * 4 stays in element 1 */
    run_ranges(p, 0.3, 0.4, 0.4, 0.5, I, A);
    assert_true(I[0].lo == 5 && I[0].hi == 5 && A[0].lo == 5 && A[0].hi == 5);
    assert_true(A[2].lo == 10 && A[2].hi == 10);
    sl_program_destroy(&p);

    /* a loop filling an array under an undecided condition, read back by a
     * varying index */
    p = compile_ok("displacement d() {\n"
                   "    float a[4], i;\n"
                   "    for (i = 0; i < 4; i += 1) {\n"
                   "        if (u > 0.25 * i) a[i] = i * i; else a[i] = -1;\n"
                   "    }\n"
                   "    P = point(a[v * 4], a[2], 0);\n"
                   "}\n");
    run_ranges(p, 0.4, 0.6, 0.3, 0.6, I, A);
    for (double u = 0.4; u <= 0.6; u += 0.02) {
        for (double v = 0.3; v <= 0.6; v += 0.03) {
            double F[3];
            run_float(p, u, v, F);
            for (int k = 0; k < 2; k++)
                assert_true(F[k] >= I[k].lo - 1e-12 && F[k] <= I[k].hi + 1e-12 &&
                            F[k] >= A[k].lo - 1e-12 && F[k] <= A[k].hi + 1e-12);
        }
    }
    assert_hull(A[1], -1, 4);
    sl_program_destroy(&p);
}

static void test_array_errors(void **state)
{
    (void)state;
    expect_errors("displacement d() {\n"
                  "    float a[4], x;\n"
                  "    a[4] = 1;\n"
                  "    x[0] = 1;\n"
                  "    P += a;\n"
                  "}\n",
                  "t.sl:3:7: error: array index 4 is out of range for 'a' (float[4]: 0 to 3)\n"
                  "    a[4] = 1;\n"
                  "      ^\n"
                  "t.sl:4:6: error: 'x' is not an array (it is a 'float')\n"
                  "    x[0] = 1;\n"
                  "     ^\n"
                  "t.sl:5:7: error: invalid operands to binary '+' ('point' and 'float[4]')\n"
                  "    P += a;\n"
                  "      ^\n");
    /* (a local 'float b[];' is an RSL 2 resizable array; a shader
     * parameter needs a size or a default) */
    expect_errors("displacement d(float b[]) {\n"
                  "    float a[3] = {1, 2};\n"
                  "    float c = {1};\n"
                  "}\n",
                  "t.sl:1:22: error: array 'b' needs a size or an initializer\n"
                  "displacement d(float b[]) {\n"
                  "                     ^\n"
                  "t.sl:2:18: error: 'a' has 3 elements, but 2 values are given\n"
                  "    float a[3] = {1, 2};\n"
                  "                 ^\n"
                  "t.sl:3:15: error: cannot initialize 'c' (float) with a list in braces\n"
                  "    float c = {1};\n"
                  "              ^\n");
    expect_errors("displacement d() {\n    float a[0];\n}\n",
                  "t.sl:2:13: error: array size must be an integer from 1 to 4095\n"
                  "    float a[0];\n"
                  "            ^\n");
    expect_errors("displacement d() {\n    string a[2];\n}\n",
                  "t.sl:2:13: error: arrays of strings are not supported\n"
                  "    string a[2];\n"
                  "            ^\n");
    expect_errors("float f(float a[3]) { return a[0]; }\n"
                  "displacement d() {\n"
                  "    float b[4];\n"
                  "    P += f(b);\n"
                  "}\n",
                  "t.sl:4:12: error: argument 1 of 'f': cannot pass a 'float[4]' to a "
                  "parameter of type 'float[3]'\n"
                  "    P += f(b);\n"
                  "           ^\n");

    /* at run time: an index outside the array stops the run */
    sl_program *p = compile_ok("displacement d() {\n"
                               "    float a[2] = {1, 2};\n"
                               "    P = point(a[s * 10], 0, 0);\n"
                               "}\n");
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    h_globals_float(vm, H_PLANE, U, V);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_ERR_RUNTIME);
    assert_non_null(strstr(sl_vm_error(vm), "array index out of range 0..1 at t.sl:3:"));
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_array_values),
        cmocka_unit_test(test_array_ranges),
        cmocka_unit_test(test_array_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
