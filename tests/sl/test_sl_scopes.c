/*
 * tests/sl/test_sl_scopes.c: the scoping rules of the shading language
 * (RI Spec 3.2 §14, Shaders and Functions), in float mode against values
 * computed here, and the diagnostics of what stays an error:
 *
 *   shadowing     locals, function and shader parameters named like the
 *                 predefined variables (s, t, u, P, PI) and like built-in
 *                 functions, which stay callable
 *
 * Globals are those of the plane at (u, v) = (0.25, 0.75):
 * P = (-0.5, 0.5, 0), N = (0, 0, 1), s = u, t = v.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl_harness.h"

static const double U = 0.25, V = 0.75;

/* Compiles and runs `src` in float mode; P out. */
static void run_src(const char *src, double P[3])
{
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    h_globals_float(vm, H_PLANE, U, V);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL);
    if (st != SL_OK)
        fprintf(stderr, "%s\n", sl_vm_error(vm));
    assert_int_equal(st, SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void close_to(double got, double want, const char *what)
{
    double tol = 1e-12 * (1 + fabs(want));
    if (!(fabs(got - want) <= tol)) {
        fprintf(stderr, "%s\n: got %.17g, want %.17g\n", what, got, want);
        fail();
    }
}

/* A whole source whose shader sets P to (x, y, z). */
static void expect_src(const char *src, double x, double y, double z)
{
    double P[3];
    run_src(src, P);
    close_to(P[0], x, src);
    close_to(P[1], y, src);
    close_to(P[2], z, src);
}

/* Compiling `src` fails with exactly `expected` as diagnostics. */
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

/* ---------------------------------------------------------------------- */
/* shadowing                                                               */
/* ---------------------------------------------------------------------- */

static void test_shadow_globals(void **state)
{
    (void)state;
    /* a local s hides the global s (0.25) until its block ends */
    expect_src("displacement d() {\n"
               "    float a = s;\n"
               "    {\n"
               "        float s = 10;\n"
               "        s += 1;\n"
               "        a += s;\n"
               "    }\n"
               "    P = point(a, s, 0);\n"
               "}\n",
               0.25 + 11, U, 0);
    /* function parameters named t and P; the global P is untouched */
    expect_src("float f(float t; point P) { return t * xcomp(P); }\n"
               "displacement d() { P = point(f(3, point(2, 0, 0)), t, 0); }\n",
               6, V, 0);
    /* shader parameters u and N: the default of u reads the global v */
    expect_src("displacement d(float u = v; normal N = 2) {\n"
               "    P = point(u, ycomp(N), 0);\n"
               "}\n",
               V, 2, 0);
    /* PI may be shadowed too */
    expect_src("displacement d() { float PI = 3; P = point(PI, 0, 0); }\n", 3, 0, 0);
}

static void test_shadow_builtins(void **state)
{
    (void)state;
    /* variables named like built-in functions; the functions stay callable */
    expect_src("displacement d() {\n"
               "    float mix = 0.5, area = 2;\n"
               "    float sin = sin(mix);\n"
               "    P = point(mix(0, area, mix), sin, area);\n"
               "}\n",
               1, sin(0.5), 2);
    /* a parameter named like a built-in */
    expect_src("float g(float noise; float step) { return noise + step(0.5, step); }\n"
               "displacement d() { P = point(g(2, 0.7), g(2, 0.3), 0); }\n",
               3, 2, 0);
}

static void test_shadow_errors(void **state)
{
    (void)state;
    /* still one definition per scope, parameters included */
    expect_errors("float f(float s; float s) { return s; }\n"
                  "displacement d() { }\n",
                  "t.sl:1:24: error: redefinition of 's'\n"
                  "float f(float s; float s) { return s; }\n"
                  "                       ^\n"
                  "t.sl:1:15: note: previous definition is here\n"
                  "float f(float s; float s) { return s; }\n"
                  "              ^\n");
    /* a read-only global stays read-only where it is not shadowed */
    expect_errors("displacement d() {\n    { float s = 1; s = 2; }\n    s = 3;\n}\n",
                  "t.sl:3:5: error: cannot assign to 's': it is a read-only global variable\n"
                  "    s = 3;\n"
                  "    ^\n");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadow_globals),
        cmocka_unit_test(test_shadow_builtins),
        cmocka_unit_test(test_shadow_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
