/*
 * tests/sl/test_sl_scopes.c: the scoping rules of the shading language
 * (RI Spec 3.2 §14, Shaders and Functions), in float mode against values
 * computed here, and the diagnostics of what stays an error:
 *
 *   shadowing     locals, function and shader parameters named like the
 *                 predefined variables (s, t, u, P, PI) and like built-in
 *                 functions, which stay callable
 *   nested        functions defined inside functions and the shader body
 *                 (the patterns.h idiom), scoped like variables, seeing
 *                 enclosing variables through 'extern' (also writing
 *                 them, also two levels out), recursion and misuse
 *   overloading   one name for several argument types, by return type
 *                 from the context, nested overloads hiding file-level
 *                 ones, user overloads beside built-ins, ambiguity
 *   untyped lists (x, y, z) and 16 values typed by a declaration, an
 *                 assignment, an argument (user, built-in, overloaded), a
 *                 return, ?:, the other operand; what stays untyped
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

/* ---------------------------------------------------------------------- */
/* nested functions                                                        */
/* ---------------------------------------------------------------------- */

static double sgn(double x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }

/* The integral of |x| over [x - dx/2, x + dx/2], divided by dx. */
static double filteredabs(double x, double dx)
{
    double x0 = x - 0.5 * dx, x1 = x0 + dx;
    return (sgn(x1) * 0.5 * x1 * x1 - sgn(x0) * 0.5 * x0 * x0) / dx;
}

static void test_nested_functions(void **state)
{
    (void)state;
    /* the widely copied idiom: a helper inside the function using it */
    expect_src("float filteredabs(float x, dx) {\n"
               "    float integral(float t) { return sign(t) * 0.5 * t * t; }\n"
               "    float x0 = x - 0.5 * dx;\n"
               "    float x1 = x0 + dx;\n"
               "    return (integral(x1) - integral(x0)) / dx;\n"
               "}\n"
               "displacement d() {\n"
               "    P = point(filteredabs(s - 0.5, 0.1), filteredabs(t - 0.5, 0.3), 0);\n"
               "}\n",
               filteredabs(U - 0.5, 0.1), filteredabs(V - 0.5, 0.3), 0);
    /* in the shader body, writing a local and reading a parameter of the
     * shader through extern */
    expect_src("displacement d(float Km = 2) {\n"
               "    float acc = 1;\n"
               "    void bump(float x) { extern float acc, Km; acc += Km * x; }\n"
               "    bump(s);\n"
               "    bump(t);\n"
               "    P = point(acc, 0, 0);\n"
               "}\n",
               1 + 2 * (U + V), 0, 0);
    /* two levels: the innermost reaches the outermost's local */
    expect_src("float outer(float a) {\n"
               "    float b = a * 2;\n"
               "    float mid(float c) {\n"
               "        float inner(float d) { extern float b; return b + d; }\n"
               "        return inner(c) * 10;\n"
               "    }\n"
               "    return mid(a + 1);\n"
               "}\n"
               "displacement d() { P = point(outer(1), outer(s), 0); }\n",
               40, (2 * U + U + 1) * 10, 0);
    /* extern s names the enclosing local s; without extern, s is the global
     * (with a warning, once) */
    const char *src = "displacement d() {\n"
                      "    float s = 5;\n"
                      "    float f() { extern float s; return s; }\n"
                      "    float g() { return s + s; }\n"
                      "    P = point(f(), g(), 0);\n"
                      "}\n";
    expect_src(src, 5, 2 * U, 0);
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    assert_non_null(p);
    assert_string_equal(text,
                        "t.sl:4:24: warning: 's' in function 'g' is the predefined variable, "
                        "not the enclosing scope's; declare 'extern float s;' to use that "
                        "one\n"
                        "    float g() { return s + s; }\n"
                        "                       ^\n"
                        "t.sl:2:11: note: the enclosing 's' is declared here\n"
                        "    float s = 5;\n"
                        "          ^\n");
    free(text);
    sl_program_destroy(&p);
    /* one name, two blocks, two functions; a nested one hides a file-level one */
    expect_src("float h(float x) { return x - 1; }\n"
               "displacement d() {\n"
               "    float a, b;\n"
               "    { float h(float x) { return x + 1; } a = h(1); }\n"
               "    { float h(float x) { return x * 3; } b = h(1); }\n"
               "    P = point(a, b, h(1));\n"
               "}\n",
               2, 3, 0);
    /* a nested function with a loop and an early return, called in a loop */
    expect_src("displacement d() {\n"
               "    float total = 0;\n"
               "    float firstabove(float lim) {\n"
               "        float i;\n"
               "        for (i = 0; i < 10; i += 1) {\n"
               "            if (i * i > lim) return i;\n"
               "        }\n"
               "        return -1;\n"
               "    }\n"
               "    float k;\n"
               "    for (k = 0; k < 3; k += 1) total += firstabove(k * 10);\n"
               "    P = point(total, firstabove(1000), 0);\n"
               "}\n",
               1 + 4 + 5, -1, 0);
}

static void test_nested_errors(void **state)
{
    (void)state;
    expect_errors("float f(float a) {\n"
                  "    float g() { return a; }\n"
                  "    return g();\n"
                  "}\n"
                  "displacement d() { }\n",
                  "t.sl:2:24: error: 'a' belongs to an enclosing scope; declare it "
                  "'extern float a;' in function 'g' to use it here\n"
                  "    float g() { return a; }\n"
                  "                       ^\n");
    /* scoped like a variable: not before its definition, not after its block */
    expect_errors("displacement d() {\n"
                  "    float a = h(1);\n"
                  "    { float h(float x) { return x; } }\n"
                  "    a = h(2);\n"
                  "}\n",
                  "t.sl:2:15: error: use of undeclared function 'h'\n"
                  "    float a = h(1);\n"
                  "              ^\n"
                  "t.sl:4:9: error: use of undeclared function 'h'\n"
                  "    a = h(2);\n"
                  "        ^\n");
    expect_errors("displacement d() {\n"
                  "    float h(float x) { return x; }\n"
                  "    float h(float x) { return x + 1; }\n"
                  "}\n",
                  "t.sl:3:11: error: redefinition of function 'h'\n"
                  "    float h(float x) { return x + 1; }\n"
                  "          ^\n"
                  "t.sl:2:11: note: previous definition is here\n"
                  "    float h(float x) { return x; }\n"
                  "          ^\n");
    expect_errors("displacement d() {\n"
                  "    float h(float x) { return x > 0 ? h(x - 1) : 0; }\n"
                  "    P += h(3);\n"
                  "}\n",
                  "t.sl:2:11: error: recursion is not supported: h -> h\n"
                  "    float h(float x) { return x > 0 ? h(x - 1) : 0; }\n"
                  "          ^\n");
    /* break cannot leave a function; extern must name something */
    expect_errors("displacement d() {\n"
                  "    while (1) {\n"
                  "        void stop() { break; }\n"
                  "        float q() { extern float zz; extern color P; return 1; }\n"
                  "    }\n"
                  "}\n",
                  "t.sl:3:23: error: 'break' statement not in loop\n"
                  "        void stop() { break; }\n"
                  "                      ^\n"
                  "t.sl:4:34: error: 'extern' names no variable 'zz' of an enclosing scope\n"
                  "        float q() { extern float zz; extern color P; return 1; }\n"
                  "                                 ^\n"
                  "t.sl:4:51: error: 'extern' declaration of 'P' as 'color' does not match "
                  "its type 'point'\n"
                  "        float q() { extern float zz; extern color P; return 1; }\n"
                  "                                                  ^\n");
}

/* ---------------------------------------------------------------------- */
/* overloading                                                             */
/* ---------------------------------------------------------------------- */

static void test_overloading(void **state)
{
    (void)state;
    /* by argument type: exact first, then point/vector/normal, then float */
    expect_src("float twice(float x) { return 2 * x; }\n"
               "color twice(color c) { return c * 2; }\n"
               "point twice(point p) { return p * 3; }\n"
               "displacement d() {\n"
               "    color c = twice(color(1, 2, 3));\n"
               "    point q = twice(vector(1, 0, 0));\n"
               "    P = point(twice(s), comp(c, 1), xcomp(q));\n"
               "}\n",
               2 * U, 4, 3);
    /* by return type, from a declaration, a cast, and a convertible target */
    expect_src("float pick(point p) { return xcomp(p); }\n"
               "color pick(point p) { return color(ycomp(p)); }\n"
               "displacement d() {\n"
               "    float f = pick(P);\n"
               "    color c = pick(P);\n"
               "    vector w = pick(P);\n"
               "    P = point(f + 10 * comp(c, 0), float pick(P), ycomp(w));\n"
               "}\n",
               -0.5 + 10 * 0.5, -0.5, -0.5);
    /* a nested definition hides the file-level one of the same signature
     * only; output parameters select by the variable's type */
    expect_src("float f(float x) { return x + 1; }\n"
               "float f(color c) { return comp(c, 0) + 100; }\n"
               "void setv(output float x) { x = 1; }\n"
               "void setv(output color c) { c = color(2); }\n"
               "displacement d() {\n"
               "    float f(float x) { return x + 2; }\n"
               "    float a; color b;\n"
               "    setv(a); setv(b);\n"
               "    P = point(f(1), f(color(5)), a + comp(b, 2));\n"
               "}\n",
               3, 105, 3);
    /* user overloads beside built-ins: a new signature adds to the
     * built-in's, an equal one replaces it */
    expect_src("float length(color c) { return comp(c, 0) + comp(c, 1) + comp(c, 2); }\n"
               "float step(float a, x) { return 42; }\n"
               "displacement d() {\n"
               "    P = point(length(color(3, 4, 0)), length(vector(3, 4, 0)), step(0, 1));\n"
               "}\n",
               7, 5, 42);
}

static void test_overloading_errors(void **state)
{
    (void)state;
    expect_errors("float pick(point p) { return xcomp(p); }\n"
                  "color pick(point p) { return color(ycomp(p)); }\n"
                  "displacement d() {\n"
                  "    float x = 1 + pick(P);\n"
                  "}\n",
                  "t.sl:4:19: error: call to 'pick' is ambiguous\n"
                  "    float x = 1 + pick(P);\n"
                  "                  ^\n"
                  "t.sl:1:7: note: candidate: float pick(point)\n"
                  "float pick(point p) { return xcomp(p); }\n"
                  "      ^\n"
                  "t.sl:2:7: note: candidate: color pick(point)\n"
                  "color pick(point p) { return color(ycomp(p)); }\n"
                  "      ^\n");
    expect_errors("float g(point p) { return 1; }\n"
                  "float g(color c) { return 2; }\n"
                  "displacement d() {\n"
                  "    float x = g(1);\n"
                  "    x = g(\"a\");\n"
                  "}\n",
                  "t.sl:4:15: error: call to 'g' is ambiguous\n"
                  "    float x = g(1);\n"
                  "              ^\n"
                  "t.sl:1:7: note: candidate: float g(point)\n"
                  "float g(point p) { return 1; }\n"
                  "      ^\n"
                  "t.sl:2:7: note: candidate: float g(color)\n"
                  "float g(color c) { return 2; }\n"
                  "      ^\n"
                  "t.sl:5:9: error: no matching function for call to 'g' with arguments "
                  "(string)\n"
                  "    x = g(\"a\");\n"
                  "        ^\n"
                  "t.sl:1:7: note: candidate: float g(point)\n"
                  "float g(point p) { return 1; }\n"
                  "      ^\n"
                  "t.sl:2:7: note: candidate: float g(color)\n"
                  "float g(color c) { return 2; }\n"
                  "      ^\n");
    /* the same signature twice is a redefinition, whatever the parameter names */
    expect_errors("float g(point p) { return 1; }\n"
                  "float g(point q) { return 2; }\n"
                  "displacement d() { }\n",
                  "t.sl:2:7: error: redefinition of function 'g'\n"
                  "float g(point q) { return 2; }\n"
                  "      ^\n"
                  "t.sl:1:7: note: previous definition is here\n"
                  "float g(point p) { return 1; }\n"
                  "      ^\n");
}

/* ---------------------------------------------------------------------- */
/* untyped lists                                                           */
/* ---------------------------------------------------------------------- */

static void test_untyped_lists(void **state)
{
    (void)state;
    expect_src("displacement d() { P = (1, 2, 3); }\n", 1, 2, 3);
    expect_src("float f(color c) { return comp(c, 1); }\n"
               "vector up() { return (0, 0, 1); }\n"
               "displacement d() {\n"
               "    color c = (0.5, 0.25, 1);\n"
               "    P = point(comp(c, 0), f((1, 2, 3)), zcomp(up()));\n"
               "}\n",
               0.5, 2, 1);
    /* ?: and the other operand of + */
    expect_src("displacement d() {\n"
               "    point q = u > 0.5 ? (1, 0, 0) : (0, 1, 0);\n"
               "    P = P + (0, 0, 1) + q;\n"
               "}\n",
               -0.5, 1.5, 1);
    /* arithmetic among lists and floats stays untyped until assigned */
    expect_src("displacement d() { P = -(1, 2, 3) * 2 + (0.5, 0, 0); }\n", -1.5, -4, -6);
    /* built-ins: a point where a spatial type is wanted, the context's
     * type for a generic one */
    expect_src("displacement d() {\n"
               "    color c = mix((1, 0, 0), (0, 0, 1), 0.25);\n"
               "    P = point(length((3, 4, 0)), distance((0, 0, 0), (0, 0, 2)), "
               "comp(c, 0) + 10 * comp(c, 2));\n"
               "}\n",
               5, 2, 0.75 + 2.5);
    /* 16 values in a matrix context (the translation in elements 12..14) */
    expect_src("displacement d() {\n"
               "    matrix m = (1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  2, 3, 4, 1);\n"
               "    P = transform(m, point(0, 0, 0));\n"
               "}\n",
               2, 3, 4);
    /* an overloaded function: the list matches the triple overload */
    expect_src("float h(float x) { return x; }\n"
               "float h(color c) { return comp(c, 2); }\n"
               "displacement d() { P = point(h((1, 2, 3)), h(5), 0); }\n",
               3, 5, 0);
}

static void test_untyped_list_errors(void **state)
{
    (void)state;
    expect_errors("displacement d() {\n"
                  "    float f = (1, 2, 3);\n"
                  "    f = (1, 2, 3) . (4, 5, 6);\n"
                  "}\n",
                  "t.sl:2:15: error: cannot initialize 'f' (float) with a value of type "
                  "'untyped triple'\n"
                  "    float f = (1, 2, 3);\n"
                  "              ^\n"
                  "t.sl:3:9: error: cannot tell the type of this list of 3 values here; put a "
                  "type in front, as in 'point (...)'\n"
                  "    f = (1, 2, 3) . (4, 5, 6);\n"
                  "        ^\n");
    expect_errors("float g(point p) { return 1; }\n"
                  "float g(color c) { return 2; }\n"
                  "displacement d() { P += g((1, 2, 3)); }\n",
                  "t.sl:3:25: error: call to 'g' is ambiguous\n"
                  "displacement d() { P += g((1, 2, 3)); }\n"
                  "                        ^\n"
                  "t.sl:1:7: note: candidate: float g(point)\n"
                  "float g(point p) { return 1; }\n"
                  "      ^\n"
                  "t.sl:2:7: note: candidate: float g(color)\n"
                  "float g(color c) { return 2; }\n"
                  "      ^\n");
    expect_errors("displacement d() { P = (1, \"a\", 3); }\n",
                  "t.sl:1:28: error: component 2 of a list must be a float, not 'string'\n"
                  "displacement d() { P = (1, \"a\", 3); }\n"
                  "                           ^\n");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadow_globals),
        cmocka_unit_test(test_shadow_builtins),
        cmocka_unit_test(test_shadow_errors),
        cmocka_unit_test(test_nested_functions),
        cmocka_unit_test(test_nested_errors),
        cmocka_unit_test(test_overloading),
        cmocka_unit_test(test_overloading_errors),
        cmocka_unit_test(test_untyped_lists),
        cmocka_unit_test(test_untyped_list_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
