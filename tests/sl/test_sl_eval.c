/*
 * tests/sl/test_sl_eval.c: the shading language in float mode, against
 * values computed by hand (or by the C library / sl/noise.h directly):
 *
 *   expressions   precedence (RenderMan's: '.' over '*' over '^' over
 *                 '+'), triples and promotion, casts, comparisons, logic
 *   built-ins     math, geometry, components, noise, random, lights,
 *                 spaces and transforms, matrices
 *   statements    declarations, assignments, if/else, for, while, break,
 *                 continue (also leaving two loops), return, user
 *                 functions with output parameters, inlined calls
 *   parameters    defaults in both list styles, instances overriding
 *                 them, strings, the errors of sl_instance_set
 *   the VM        run errors, instruction counts, the bytecode listing
 *
 * Globals are those of the plane at (u, v) = (0.25, 0.75):
 * P = (-0.5, 0.5, 0), N = (0, 0, 1), s = u, t = v.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/noise.h"
#include "sl/strmatch.h"
#include "sl_harness.h"

#include <unistd.h>

static const double U = 0.25, V = 0.75;

/* Compiles and runs a whole source in float mode; P out. */
static sl_status run_src_vm(sl_vm *vm, const char *src, double P[3])
{
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    h_globals_float(vm, H_PLANE, U, V);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL);
    if (st != SL_OK)
        fprintf(stderr, "%s\n", sl_vm_error(vm));
    sl_vm_get_float(vm, SL_G_P, P);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
    return st;
}

static void run_src(const char *src, double P[3])
{
    sl_vm *vm = sl_vm_new(NULL);
    assert_int_equal(run_src_vm(vm, src, P), SL_OK);
    sl_vm_destroy(&vm);
}

static void close_to(double got, double want, const char *what)
{
    double tol = 1e-12 * (1 + fabs(want));
    if (!(fabs(got - want) <= tol)) {
        fprintf(stderr, "%s: got %.17g, want %.17g\n", what, got, want);
        fail();
    }
}

/* body of a displacement shader; P must become (x, y, z) */
static void expect3(const char *body, double x, double y, double z)
{
    char src[4096];
    snprintf(src, sizeof src, "displacement t() {\n%s\n}\n", body);
    double P[3];
    run_src(src, P);
    close_to(P[0], x, body);
    close_to(P[1], y, body);
    close_to(P[2], z, body);
}

/* a float expression */
static void expect1(const char *expr, double x)
{
    char body[2048];
    snprintf(body, sizeof body, "P = point(%s, 0, 0);", expr);
    expect3(body, x, 0, 0);
}

/* ---------------------------------------------------------------------- */

static void test_arithmetic_and_precedence(void **state)
{
    (void)state;
    expect1("1 + 2 * 3", 7);
    expect1("(1 + 2) * 3", 9);
    expect1("2 - 3 - 4", -5);
    expect1("24 / 4 / 2", 3);
    expect1("-2 * 3", -6);
    expect1("-(2 + 3)", -5);
    expect1("10 / 4", 2.5);
    expect1("+5 - -1", 6);
    /* '.' binds tighter than '*' */
    expect1("vector(1, 2, 3) . vector(4, 5, 6) * 2", 64);
    /* '^' binds looser than '*' and tighter than '+' */
    expect3("P = vector(1, 0, 0) ^ vector(0, 1, 0) * 2;", 0, 0, 2);
    expect3("P = 1 + vector(1, 0, 0) ^ vector(0, 1, 0);", 1, 1, 2);
    expect1("1 + 2 == 3 && 4 > 3 || 0 > 1 ? 10 : 20", 10);
    expect1("!(1 > 2) ? 5 : 6", 5);
    expect1("1 < 2 ? 2 < 1 ? 7 : 8 : 9", 8);
    expect1("2 <= 2 && 2 >= 2 && 2 != 3 && !(2 == 3) ? 1 : 0", 1);
    expect1("u + v * 2", U + V * 2);
    expect1("s * 10 + t", U * 10 + V);
    expect1("PI", M_PI);
}

static void test_triples(void **state)
{
    (void)state;
    expect3("P = point(1, 2, 3) + 1;", 2, 3, 4);
    expect3("P = 2 * vector(1, 2, 3) - point(1, 1, 1);", 1, 3, 5);
    expect3("color c = color(1, 2, 3) * color(2, 2, 2); P = point(comp(c, 0), comp(c, 1), comp(c, 2));",
            2, 4, 6);
    expect3("P = point(6, 8, 10) / 2;", 3, 4, 5);
    expect3("P = -point(1, -2, 3);", -1, 2, -3);
    expect3("P = point(0.5);", 0.5, 0.5, 0.5);
    expect3("vector w = 3; P = w;", 3, 3, 3);
    expect3("P = P + N;", -0.5, 0.5, 1);
    expect3("P += 2 * N; P *= 2; P -= 1; P /= 2;", -1, 0, 1.5);
    expect1("point(1, 2, 3) == point(1, 2, 3) ? 1 : 0", 1);
    expect1("point(1, 2, 3) != point(1, 2, 4) ? 1 : 0", 1);
    expect1("color(1, 2, 3) == color(1, 5, 3) ? 1 : 0", 0);
    /* v = v.x * v: the broadcast lane is read before it is overwritten */
    expect3("vector w = vector(2, 3, 4); w = xcomp(w) * w; P = w;", 4, 6, 8);
    expect3("point q = point(1, 2, 3); q = point(zcomp(q), xcomp(q), ycomp(q)); P = q;", 3, 1, 2);
}

static void test_math_builtins(void **state)
{
    (void)state;
    expect1("sin(PI / 6)", sin(M_PI / 6));
    expect1("cos(0)", 1);
    expect1("tan(PI / 4)", tan(M_PI / 4));
    expect1("asin(1)", M_PI / 2);
    expect1("acos(0)", M_PI / 2);
    expect1("atan(1)", M_PI / 4);
    expect1("atan(1, -1)", 3 * M_PI / 4);
    expect1("exp(1)", M_E);
    expect1("log(exp(2))", 2);
    expect1("log(8, 2)", 3);
    expect1("pow(2, 10)", 1024);
    expect1("sqrt(16)", 4);
    expect1("inversesqrt(4)", 0.5);
    expect1("abs(-3)", 3);
    expect1("sign(-2) + 10 * sign(0) + 100 * sign(5)", 99);
    expect1("floor(-1.5)", -2);
    expect1("ceil(-1.5)", -1);
    expect1("round(2.5)", 3);
    expect1("round(-2.5)", -3);
    expect1("mod(-1, 3)", 2);
    expect1("mod(7, 3)", 1);
    expect1("mod(7, -3)", -2);
    expect1("min(2, 3) + max(2, 3)", 5);
    expect1("clamp(5, 0, 1) + clamp(-5, 0, 1) + clamp(0.5, 0, 1)", 1.5);
    expect1("step(0.5, 0.4)", 0);
    expect1("step(0.5, 0.5)", 1);
    expect1("smoothstep(0, 1, 0.25)", 0.15625);
    expect1("smoothstep(0, 1, -1) + smoothstep(0, 1, 2)", 1);
    expect1("mix(2, 4, 0.25)", 2.5);
    expect1("radians(180)", M_PI);
    expect1("degrees(PI)", 180);
    expect3("P = abs(vector(-1, 2, -3));", 1, 2, 3);
    expect3("P = min(point(1, 5, 3), point(2, 2, 2));", 1, 2, 2);
    expect3("P = max(point(1, 5, 3), 2);", 2, 5, 3);
    expect3("P = clamp(point(-1, 0.5, 2), 0, 1);", 0, 0.5, 1);
    expect3("color c = mix(color(0, 0, 0), color(2, 4, 6), 0.5); P = point(comp(c, 0), comp(c, 1), comp(c, 2));",
            1, 2, 3);
    expect3("P = floor(point(1.5, -1.5, 2));", 1, -2, 2);
}

static void test_geometry_builtins(void **state)
{
    (void)state;
    expect1("length(vector(3, 4, 0))", 5);
    expect3("P = normalize(vector(0, 3, 4));", 0, 0.6, 0.8);
    expect1("distance(point(1, 1, 1), point(4, 5, 1))", 5);
    expect1("dot(vector(1, 2, 3), vector(4, 5, 6))", 32);
    expect3("P = cross(vector(0, 1, 0), vector(0, 0, 1));", 1, 0, 0);
    expect3("P = reflect(vector(1, -1, 0), normal(0, 1, 0));", 1, 1, 0);
    expect3("P = faceforward(normal(0, 0, 1), vector(0, 0, 1));", 0, 0, -1);
    expect3("P = faceforward(normal(0, 0, 1), vector(0, 0, -1));", 0, 0, 1);
    expect3("P = faceforward(normal(0, 0, 1), vector(0, 0, 1), normal(0, 0, -1));", 0, 0, 1);
    expect3("P = point(xcomp(P) * 2, ycomp(P) * 2, zcomp(N));", -1, 1, 1);
    expect3("point q = 0; setxcomp(q, 1); setycomp(q, 2); setzcomp(q, 3); P = q;", 1, 2, 3);
    expect3("float i = 2; vector w = vector(7, 8, 9); setcomp(w, i - 1, 5);"
            " P = point(comp(w, i), comp(w, 1), comp(w, 0));", 9, 5, 7);
    /* float mode: no derivatives; calculatenormal gives the current N */
    expect3("N = normal(1, 2, 3); P = calculatenormal(P);", 1, 2, 3);
    expect1("Du(u) + Dv(v) + Deriv(u, v) + area(P)", 0);
}

static void test_statements(void **state)
{
    (void)state;
    expect1("1", 1);
    expect3("float a = 0, i;\n"
            "for (i = 0; i < 5; i += 1) { if (i == 3) continue; a += i * i; }\n"
            "P = point(a, i, 0);", 21, 5, 0);
    expect3("float a = 21;\n"
            "while (a > 10) { a -= 1; if (a < 12) break; }\n"
            "P = point(a, 0, 0);", 11, 0, 0);
    /* break 2 leaves both loops */
    expect3("float i, j, n = 0;\n"
            "for (i = 0; i < 10; i += 1)\n"
            "  for (j = 0; j < 10; j += 1) { n += 1; if (i * 10 + j >= 23) break 2; }\n"
            "P = point(n, i, j);", 24, 2, 3);
    /* continue 2 goes on with the outer loop */
    expect3("float i, j, n = 0;\n"
            "for (i = 0; i < 3; i += 1)\n"
            "  for (j = 0; j < 10; j += 1) { if (j == 2) continue 2; n += 1; }\n"
            "P = point(n, i, 0);", 6, 3, 0);
    expect3("float x = 5;\n"
            "if (x > 3) { if (x > 4) x = 1; else x = 2; } else x = 3;\n"
            "P = point(x, 0, 0);", 1, 0, 0);
    expect3("float a, b; a = b = 3; P = point(a, b, a + b);", 3, 3, 6);
    expect3("float x = 1; { float x = 2; P = point(x, 0, 0); } P += point(0, x, 0);", 2, 1, 0);
    expect3("float n = 0; while (n < 100) n += 7; P = point(n, 0, 0);", 105, 0, 0);
    expect3("float x = 1; if (1) x = 2; if (0.0) x = 3; P = point(x, 0, 0);", 2, 0, 0);
    /* return in the shader body ends it */
    expect3("P = point(1, 0, 0); if (u < 1) return; P = point(2, 0, 0);", 1, 0, 0);
}

static void test_user_functions(void **state)
{
    (void)state;
    double P[3];
    run_src("float f(float x) { if (x > 1) return 10; else if (x > 0) return 5; return 1; }\n"
            "float sq(float x) { return x * x; }\n"
            "void twice(output float y; float k) { y = 2 * y + k; }\n"
            "point mid(point a, b) { return (a + b) / 2; }\n"
            "displacement t() {\n"
            "  float y = 3;\n"
            "  twice(y, 1);\n"
            "  P = point(f(2) + f(0.5) * 100 + f(-1) * 10000, sq(sq(3)), y);\n"
            "  P += mid(point(0, 0, 2), point(0, 0, 4)) - point(0, 0, 3);\n"
            "}\n", P);
    close_to(P[0], 10 + 500 + 10000, "f");
    close_to(P[1], 81, "sq(sq(3))");
    close_to(P[2], 7, "twice");
    /* functions see the globals; a call in a loop is inlined once per call site */
    run_src("float height() { return zcomp(N) + u; }\n"
            "displacement t() { float i, sum = 0; for (i = 0; i < 3; i += 1) sum += height();"
            " P = point(sum, 0, 0); }\n", P);
    close_to(P[0], 3 * (1 + U), "height");
    /* string parameters of functions */
    run_src("float pick(string which) { if (which == \"two\") return 2; return 1; }\n"
            "displacement t() { string w = \"two\"; P = point(pick(w), pick(\"one\"), 0); }\n", P);
    close_to(P[0], 2, "pick two");
    close_to(P[1], 1, "pick one");
}

static void test_parameters(void **state)
{
    (void)state;
    const char *src =
        "displacement t(float a = 1, b = 2; float c = a + 10;\n"
        "               output float o = 0; point q = point(1, 2, 3); string mode = \"x\")\n"
        "{ o = a + b; P = point(a + b + c, mode == \"y\" ? 1 : 0, xcomp(q)); }\n";
    sl_program *p = h_compile(src);
    assert_non_null(p);
    assert_string_equal(sl_program_name(p), "t");
    assert_int_equal(sl_program_kind(p), SL_SHADER_DISPLACEMENT);
    assert_int_equal(sl_program_param_count(p), 6);
    sl_param_info info;
    sl_program_param(p, 3, &info);
    assert_string_equal(info.name, "o");
    assert_int_equal(info.type, SL_TYPE_FLOAT);
    assert_true(info.output);
    sl_program_param(p, 4, &info);
    assert_int_equal(info.type, SL_TYPE_POINT);
    assert_false(info.output);
    assert_int_equal(sl_program_find_param(p, "mode"), 5);
    assert_int_equal(sl_program_find_param(p, "nope"), -1);

    sl_instance *inst = sl_instance_new(p);
    assert_ptr_equal(sl_instance_program(inst), p);
    sl_vm *vm = sl_vm_new(NULL);
    double P[3];
    h_globals_float(vm, H_PLANE, U, V);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    close_to(P[0], 1 + 2 + 11, "defaults");
    close_to(P[1], 0, "string default");
    close_to(P[2], 1, "point default");

    double a = 5, q[3] = { 7, 8, 9 };
    char why[128];
    assert_true(sl_instance_set(inst, "a", SL_TYPE_FLOAT, &a, 1, why, sizeof why));
    assert_true(sl_instance_set(inst, "q", SL_TYPE_VECTOR, q, 3, why, sizeof why));
    assert_true(sl_instance_set_string(inst, "mode", "y", why, sizeof why));
    h_globals_float(vm, H_PLANE, U, V);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    close_to(P[0], 5 + 2 + 15, "set a (c = a + 10 follows)");
    close_to(P[1], 1, "set string");
    close_to(P[2], 7, "set point");

    assert_false(sl_instance_set(inst, "zz", SL_TYPE_FLOAT, &a, 1, why, sizeof why));
    assert_string_equal(why, "shader 't' has no parameter 'zz'");
    assert_false(sl_instance_set(inst, "a", SL_TYPE_COLOR, q, 3, why, sizeof why));
    assert_string_equal(why, "parameter 'a' of shader 't' is a float, not a color");
    assert_false(sl_instance_set(inst, "q", SL_TYPE_POINT, q, 2, why, sizeof why));
    assert_string_equal(why, "parameter 'q' of shader 't' takes 3 values, got 2");
    assert_false(sl_instance_set(inst, "mode", SL_TYPE_FLOAT, &a, 1, why, sizeof why));
    assert_string_equal(why, "parameter 'mode' of shader 't' is a string");
    assert_false(sl_instance_set_string(inst, "a", "x", why, sizeof why));
    assert_string_equal(why, "parameter 'a' of shader 't' is a float, not a string");
    double bad = NAN;
    assert_false(sl_instance_set(inst, "a", SL_TYPE_FLOAT, &bad, 1, why, sizeof why));
    assert_string_equal(why, "parameter 'a' of shader 't': value 1 is not a finite number");

    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_noise_and_random(void **state)
{
    (void)state;
    double p3[3] = { 0.1, 0.2, 0.3 }, p4[4] = { 0.1, 0.2, 0.3, 0.7 }, c[3];
    expect3("P = point(noise(0.3), noise(0.3, 0.7), noise(point(0.1, 0.2, 0.3)));",
            sl_noise1(0.3), sl_noise2(0.3, 0.7), sl_noise3(p3));
    expect1("noise(point(0.1, 0.2, 0.3), 0.7)", sl_noise4(p4));
    sl_vnoise(3, p3, c);
    expect3("color c = noise(point(0.1, 0.2, 0.3)); P = point(comp(c, 0), comp(c, 1), comp(c, 2));",
            c[0], c[1], c[2]);
    expect3("P = point noise(point(0.1, 0.2, 0.3));", c[0], c[1], c[2]);
    expect1("cellnoise(1.5) + 10 * cellnoise(point(1.5, 2.5, 3.5))",
            sl_cellnoise1(1.5) + 10 * sl_cellnoise3((double[3]){ 1.5, 2.5, 3.5 }));
    expect1("pnoise(0.3, 4) - pnoise(4.3, 4)", 0);
    expect1("pnoise(0.3, 4)", sl_pnoise1(0.3, 4));
    expect1("pnoise(point(0.1, 0.2, 0.3), point(2, 2, 2)) -"
            " pnoise(point(2.1, 4.2, 0.3), point(2, 2, 2))", 0);

    /* random: deterministic per seed, in [0, 1) */
    const char *src = "displacement t() { P = point(random(), random(), random()); }";
    double a[3], b[3];
    sl_vm *vm = sl_vm_new(NULL);
    run_src_vm(vm, src, a);
    run_src_vm(vm, src, b);
    for (int i = 0; i < 3; i++) {
        assert_true(a[i] == b[i]);
        assert_true(a[i] >= 0 && a[i] < 1);
    }
    assert_true(a[0] != a[1]);
    sl_vm_set_seed(vm, 42);
    run_src_vm(vm, src, b);
    assert_true(a[0] != b[0]);
    sl_vm_destroy(&vm);
}

static int test_lights_fn(void *user, const double P[3], sl_light_sample *out, int max)
{
    (void)user;
    (void)P;
    assert_true(max >= 2);
    sl_light_sample amb = { { 0, 0, 0 }, { 0.1, 0.2, 0.3 }, true, false };
    sl_light_sample dir = { { 0, 3, 4 }, { 1, 0.5, 0.25 }, false, false };   /* 5 long */
    out[0] = amb;
    out[1] = dir;
    return 2;
}

static void test_lights(void **state)
{
    (void)state;
    const char *src =
        "surface t(float which = 0) {\n"
        "  normal n = normal(0, 0, 1); vector V = vector(0, 0, 1);\n"
        "  if (which == 0) Ci = ambient();\n"
        "  else if (which == 1) Ci = diffuse(n);\n"
        "  else if (which == 2) Ci = specular(n, V, 0.5);\n"
        "  else Ci = phong(n, V, 3);\n"
        "}\n";
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_lights(vm, test_lights_fn, NULL);
    /* L = (0, 0.6, 0.8) normalised; N = V = (0, 0, 1) */
    double ln = 0.8;
    double hz = (0.8 + 1) / sqrt(0.36 + 3.24);                 /* H = normalize(L + V) */
    double rz = 2 * 1 * 1 - 0;                                 /* R = 2 (V.N) N - V = (0,0,1) */
    double expect[4][3] = {
        { 0.1, 0.2, 0.3 },
        { 1 * ln, 0.5 * ln, 0.25 * ln },
        { pow(hz, 2), 0.5 * pow(hz, 2), 0.25 * pow(hz, 2) },
        { pow(ln * (rz - 1), 3), 0.5 * pow(ln * (rz - 1), 3), 0.25 * pow(ln * (rz - 1), 3) },
    };
    for (int w = 0; w < 4; w++) {
        double which = w, Ci[3];
        assert_true(sl_instance_set(inst, "which", SL_TYPE_FLOAT, &which, 1, NULL, 0));
        h_globals_float(vm, H_PLANE, U, V);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
        sl_vm_get_float(vm, SL_G_Ci, Ci);
        for (int i = 0; i < 3; i++)
            close_to(Ci[i], expect[w][i], "light");
    }
    /* no lights: all zero; the same sums from fixed lights */
    sl_vm_set_lights(vm, NULL, NULL);
    sl_light_sample fixed[2];
    test_lights_fn(NULL, NULL, fixed, 2);
    sl_vm_set_fixed_lights(vm, fixed, 2);
    double which = 1, Ci[3];
    assert_true(sl_instance_set(inst, "which", SL_TYPE_FLOAT, &which, 1, NULL, 0));
    h_globals_float(vm, H_PLANE, U, V);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    close_to(Ci[1], 0.5 * ln, "fixed diffuse");
    sl_vm_set_fixed_lights(vm, NULL, 0);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    close_to(Ci[0] + Ci[1] + Ci[2], 0, "no lights");
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_spaces_and_matrices(void **state)
{
    (void)state;
    const char *src =
        "displacement t(float which = 0) {\n"
        "  if (which == 0) P = transform(\"object\", point(1, 2, 3));\n"
        "  else if (which == 1) P = point \"object\" (0, 0, 0);\n"
        "  else if (which == 2) P = vtransform(\"object\", vector(1, 1, 1));\n"
        "  else if (which == 3) P = ntransform(\"object\", normal(1, 0, 0));\n"
        "  else if (which == 4) P = transform(\"object\", \"world\", point(0, 0, 0));\n"
        "  else if (which == 5) { string sp = \"object\"; P = transform(sp, point(1, 1, 1)); }\n"
        "  else if (which == 6) P = transform(\"current\", point(1, 2, 3));\n"
        "  else { string sp = \"nowhere\"; P = transform(sp, point(1, 1, 1)); }\n"
        "}\n";
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    /* object -> current: scale by 2 then translate by (1, 2, 3); world: identity */
    sl_spaces sp;
    for (int k = 0; k < SL_SPACE__COUNT; k++)
        sp.to_current[k] = sp.from_current[k] = mat4_identity();
    sp.to_current[SL_SPACE_OBJECT] = mat4_mul(mat4_translate(1, 2, 3), mat4_scale(2, 2, 2));
    mat4_invert(&sp.to_current[SL_SPACE_OBJECT], &sp.from_current[SL_SPACE_OBJECT]);
    sl_vm_set_spaces(vm, &sp);
    double expect[7][3] = {
        { 0, 0, 0 },          /* (p - t) / 2 */
        { 1, 2, 3 },          /* the object origin in current space */
        { 0.5, 0.5, 0.5 },    /* vectors ignore the translation */
        { 2, 0, 0 },          /* normals: inverse transpose of the point transform */
        { 1, 2, 3 },          /* object -> world(= current) */
        { 0, -0.5, -1 },
        { 1, 2, 3 },
    };
    for (int w = 0; w < 8; w++) {
        double which = w, P[3];
        assert_true(sl_instance_set(inst, "which", SL_TYPE_FLOAT, &which, 1, NULL, 0));
        h_globals_float(vm, H_PLANE, U, V);
        sl_status st = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL);
        if (w == 7) {
            assert_int_equal(st, SL_ERR_RUNTIME);
            assert_string_equal(sl_vm_error(vm), "shader 't': unknown space 'nowhere' at t.sl:9:37");
            continue;
        }
        assert_int_equal(st, SL_OK);
        sl_vm_get_float(vm, SL_G_P, P);
        for (int i = 0; i < 3; i++)
            close_to(P[i], expect[w][i], "space");
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);

    /* matrices in RenderMan's order: translation in elements 12..14 */
    expect3("matrix m = matrix(2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  1, 2, 3, 1);\n"
            "P = transform(m, point(1, 1, 1));", 3, 4, 5);
    expect3("matrix m = matrix(2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  1, 2, 3, 1);\n"
            "P = vtransform(m, vector(1, 1, 1));", 2, 2, 2);
    expect3("matrix m = matrix(2, 0, 0, 0,  0, 4, 0, 0,  0, 0, 8, 0,  1, 2, 3, 1);\n"
            "P = ntransform(m, normal(1, 1, 1));", 0.5, 0.25, 0.125);
    /* a * b applies a first: translate, then scale */
    expect3("matrix a = matrix(1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  1, 0, 0, 1);\n"
            "matrix b = matrix(2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  0, 0, 0, 1);\n"
            "P = transform(a * b, point(1, 1, 1));", 4, 2, 2);
    /* a float is the diagonal: points are homogeneous, vectors are not */
    expect3("matrix m = 3; P = vtransform(m, vector(1, 2, 3));", 3, 6, 9);
    expect3("matrix m = 3; P = transform(m, point(1, 2, 3));", 1, 2, 3);
    /* a perspective row divides by w */
    expect3("matrix m = matrix(1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 1,  0, 0, 0, 0);\n"
            "P = transform(m, point(2, 4, 2));", 1, 2, 1);
}

static void test_vm_errors_and_counts(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t() { P += N; }");
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    assert_int_equal(sl_vm_run(vm, NULL, SL_MODE_FLOAT, NULL), SL_ERR_RUNTIME);
    assert_string_equal(sl_vm_error(vm), "shader '?': no shader instance to run");
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_AFFINE, NULL), SL_ERR_RUNTIME);
    assert_string_equal(sl_vm_error(vm), "shader 't': affine mode needs an aa_context");
    h_globals_float(vm, H_PLANE, U, V);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    assert_string_equal(sl_vm_error(vm), "");
    /* 3 adds and the end */
    assert_int_equal(sl_vm_instructions(vm), 4);
    /* globals not set since clear are 0 */
    sl_vm_clear_globals(vm);
    double P[3];
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    assert_true(P[0] == 0 && P[1] == 0 && P[2] == 0);
    sl_vm_destroy(&vm);
    assert_null(vm);
    sl_instance_destroy(&inst);
    assert_null(inst);
    sl_program_destroy(&p);
    assert_null(p);
    /* a matrix row past 3 with a varying index stops the run (it would
     * otherwise name another element); rows 0..3 read what they name */
    p = h_compile("displacement t() {\n"
                  "  matrix m = matrix (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16);\n"
                  "  float row = floor(u * 8);\n"
                  "  P = point(comp(m, row, 1), 0, 0);\n"
                  "}\n");
    assert_non_null(p);
    inst = sl_instance_new(p);
    vm = sl_vm_new(NULL);
    h_globals_float(vm, H_PLANE, 0.3, 0.5);          /* row 2: element (2, 1) */
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_P, P);
    assert_true(P[0] == 10);
    h_globals_float(vm, H_PLANE, 0.55, 0.5);         /* row 4 */
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_ERR_RUNTIME);
    assert_non_null(strstr(sl_vm_error(vm), "array index"));
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* match()'s regular expressions, bounded on a hostile pattern; printf
 * writes a line per float run to stderr, at most SL_VM_MAX_PRINTS (100)
 * and then one note, and nothing in the other modes. */
/* The printf lines a VM hands to its print callback. */
typedef struct print_log {
    int lines, notes, bad;
} print_log;

static void collect_print(void *ctx, const char *text)
{
    print_log *log = ctx;
    log->lines++;
    log->notes += strstr(text, "more than 100 printf lines") != NULL;
    log->bad += !(strcmp(text, "u=0.25 x\n") == 0 || strstr(text, "printf lines"));
}

static void test_strings(void **state)
{
    (void)state;
    assert_int_equal(sl_match("^a.c$", "abc"), 1);
    assert_int_equal(sl_match("^a.c$", "abcd"), 0);
    assert_int_equal(sl_match("a*", ""), 1);
    assert_int_equal(sl_match("[^0-9]+$", "12ab"), 1);
    assert_int_equal(sl_match("^[0-9]+$", "12ab"), 0);
    assert_int_equal(sl_match("x+y?z", "wxxz"), 1);
    assert_int_equal(sl_match("\\.tx$", "a.tx"), 1);
    assert_int_equal(sl_match("\\.tx$", "atx"), 0);
    assert_true(sl_match_check("[abc") != 0);
    assert_true(sl_match_check("*a") != 0);
    assert_int_equal(sl_match("a*a*a*a*a*a*a*a*a*a*a*a*a*b", "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"), 0);
    sl_program *p = h_compile("displacement t() { printf(\"u=%.2f %s\\n\", u, \"x\"); }");
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    print_log log = { 0 };
    sl_vm_set_print(vm, collect_print, &log);
    for (int i = 0; i < 150; i++) {
        h_globals_float(vm, H_PLANE, 0.25, 0.5);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
        h_globals_dual(vm, H_PLANE, 0.25, 0.5);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
    }
    int lines = log.lines, notes = log.notes;
    assert_int_equal(log.bad, 0);
    assert_int_equal(lines, 101);
    assert_int_equal(notes, 1);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_dump(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement bump(float Km = 0.5) {\n"
                              "  if (u > 0.5) P += Km * N;\n"
                              "}\n");
    assert_non_null(p);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    sl_program_dump(p, f);
    fclose(f);
    assert_non_null(strstr(text, "shader 'bump' (displacement)"));
    assert_non_null(strstr(text, "float  Km"));
    assert_non_null(strstr(text, "param       r46, Km, @0001, #0.5"));
    assert_non_null(strstr(text, "t.sl:2:9"));
    assert_non_null(strstr(text, "gt          r"));
    assert_non_null(strstr(text, "br.begin"));
    assert_non_null(strstr(text, "[P.x P.y P.z]"));
    assert_non_null(strstr(text, "#0.5"));
    assert_non_null(strstr(text, " end"));
    free(text);
    sl_program_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arithmetic_and_precedence),
        cmocka_unit_test(test_triples),
        cmocka_unit_test(test_math_builtins),
        cmocka_unit_test(test_geometry_builtins),
        cmocka_unit_test(test_statements),
        cmocka_unit_test(test_user_functions),
        cmocka_unit_test(test_parameters),
        cmocka_unit_test(test_noise_and_random),
        cmocka_unit_test(test_lights),
        cmocka_unit_test(test_spaces_and_matrices),
        cmocka_unit_test(test_vm_errors_and_counts),
        cmocka_unit_test(test_strings),
        cmocka_unit_test(test_dump),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
