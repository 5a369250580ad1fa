/*
 * tests/sl/test_sl_parse.c: diagnostics of the parser, the checker and the
 * code generator. Each malformed source must give exactly the expected
 * text: file:line:col, level, message (what was expected), the source line
 * and the caret; several errors per run, in source order, and no cascade
 * of follow-up errors. Also: what the language accepts (both parameter
 * list styles, qualifiers, casts with spaces, comments, macros).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/ast.h"
#include "sl_harness.h"

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

static void expect_ok(const char *src)
{
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    if (!p)
        fprintf(stderr, "%s", text);
    assert_non_null(p);
    assert_string_equal(text, "");
    free(text);
    sl_program_destroy(&p);
}

/* ---------------------------------------------------------------------- */
/* syntax                                                                  */
/* ---------------------------------------------------------------------- */

static void test_missing_semicolons(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    float x = 1\n    P += x * N;\n}\n",
                  "t.sl:2:16: error: expected ';' after declaration\n"
                  "    float x = 1\n"
                  "               ^\n");
    expect_errors("displacement t() {\n    P += N\n}\n",
                  "t.sl:2:11: error: expected ';' after expression\n"
                  "    P += N\n"
                  "          ^\n");
    expect_errors("float f(float x) {\n    return x\n}\ndisplacement t() { }\n",
                  "t.sl:2:13: error: expected ';' after return statement\n"
                  "    return x\n"
                  "            ^\n");
}

static void test_brackets_and_expressions(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    P += (N * 2;\n}\n",
                  "t.sl:2:16: error: expected ')'\n"
                  "    P += (N * 2;\n"
                  "               ^\n"
                  "t.sl:2:10: note: to match this '('\n"
                  "    P += (N * 2;\n"
                  "         ^\n");
    expect_errors("displacement t() {\n    P += * N;\n}\n",
                  "t.sl:2:10: error: expected expression\n"
                  "    P += * N;\n"
                  "         ^\n");
    expect_errors("displacement t() {\n    1 = 2;\n}\n",
                  "t.sl:2:5: error: expression is not assignable\n"
                  "    1 = 2;\n"
                  "    ^\n");
    expect_errors("displacement t() {\n    P = (1, 2);\n}\n",
                  "t.sl:2:9: error: a list of 2 values is neither a triple (3 values) nor a "
                  "matrix (16)\n"
                  "    P = (1, 2);\n"
                  "        ^\n");
}

/* Several syntax errors in one run: each reported once, the parser goes
 * on after the statement, nothing else is reported. */
static void test_recovery(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n"
                  "    if (u > 0.5 {\n"
                  "        P += N;\n"
                  "    }\n"
                  "    float y = (1 + ;\n"
                  "    P += N\n"
                  "}\n",
                  "t.sl:2:17: error: expected ')'\n"
                  "    if (u > 0.5 {\n"
                  "                ^\n"
                  "t.sl:2:8: note: to match this '('\n"
                  "    if (u > 0.5 {\n"
                  "       ^\n"
                  "t.sl:5:20: error: expected expression\n"
                  "    float y = (1 + ;\n"
                  "                   ^\n"
                  "t.sl:6:11: error: expected ';' after expression\n"
                  "    P += N\n"
                  "          ^\n");
}

static void test_error_in_macro(void **state)
{
    (void)state;
    expect_errors("#define BAD (1 +)\ndisplacement t() {\n    float x = BAD;\n}\n",
                  "t.sl:3:15: error: expected expression\n"
                  "    float x = BAD;\n"
                  "              ^\n"
                  "t.sl:1:9: note: expanded from macro 'BAD'\n"
                  "#define BAD (1 +)\n"
                  "        ^\n");
}

static void test_unsupported(void **state)
{
    (void)state;
    expect_errors("volume l() { }\n",
                  "t.sl:1:1: error: 'volume' shaders are not supported (only 'surface', "
                  "'displacement' and 'light')\n"
                  "volume l() { }\n"
                  "^\n");
    expect_errors("surface s() {\n    illuminate(P) { }\n}\n",
                  "t.sl:2:5: error: 'illuminate' is only allowed in light shaders\n"
                  "    illuminate(P) { }\n"
                  "    ^\n");
    expect_errors("surface s() {\n    illuminance(P, N) { }\n}\n",
                  "t.sl:2:5: error: illuminance takes [category,] position [, axis, angle], "
                  "not 2 values\n"
                  "    illuminance(P, N) { }\n"
                  "    ^\n");
    expect_errors("displacement t() {\n    output float x = 1;\n    void y;\n}\n",
                  "t.sl:2:12: error: 'output' is only allowed on parameters\n"
                  "    output float x = 1;\n"
                  "           ^\n"
                  "t.sl:3:5: error: variable 'y' declared 'void'\n"
                  "    void y;\n"
                  "    ^\n");
}

static void test_shader_definitions(void **state)
{
    (void)state;
    expect_errors("displacement a() { }\nsurface b() { }\n",
                  "t.sl:2:9: error: more than one shader in one source ('a' and 'b')\n"
                  "surface b() { }\n"
                  "        ^\n"
                  "t.sl:1:14: note: 'a' defined here\n"
                  "displacement a() { }\n"
                  "             ^\n");
    expect_errors("float f() { return 1; }\n",
                  "t.sl: error: no shader definition (expected 'surface' or "
                  "'displacement')\n");
    expect_errors("displacement t(float a = 1; b = 2) { }\n",
                  "t.sl:1:29: error: expected type name in parameter list\n"
                  "displacement t(float a = 1; b = 2) { }\n"
                  "                            ^\n");
    expect_errors("float f(float x = 1) { return x; }\ndisplacement t() { }\n",
                  "t.sl:1:17: error: default values are only allowed for shader parameters\n"
                  "float f(float x = 1) { return x; }\n"
                  "                ^\n");
}

/* ---------------------------------------------------------------------- */
/* names and types                                                         */
/* ---------------------------------------------------------------------- */

static void test_names(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    P += foo * N;\n    P += noise * N;\n    bar(1);\n}\n",
                  "t.sl:2:10: error: use of undeclared identifier 'foo'\n"
                  "    P += foo * N;\n"
                  "         ^\n"
                  "t.sl:3:10: error: 'noise' is a function; call it with '(...)'\n"
                  "    P += noise * N;\n"
                  "         ^\n"
                  "t.sl:4:5: error: use of undeclared function 'bar'\n"
                  "    bar(1);\n"
                  "    ^\n");
    expect_errors("displacement t() {\n    float x = 1;\n    float x = 2;\n}\n"
                  "float g() { return 1; }\nfloat g() { return 2; }\n",
                  "t.sl:3:11: error: redefinition of 'x'\n"
                  "    float x = 2;\n"
                  "          ^\n"
                  "t.sl:2:11: note: previous definition is here\n"
                  "    float x = 1;\n"
                  "          ^\n"
                  "t.sl:6:7: error: redefinition of function 'g'\n"
                  "float g() { return 2; }\n"
                  "      ^\n"
                  "t.sl:5:7: note: previous definition is here\n"
                  "float g() { return 1; }\n"
                  "      ^\n");
    /* a local may shadow a predefined variable, but not twice in one scope */
    expect_errors("displacement t() {\n    float s = 1;\n    float s = 2;\n}\n",
                  "t.sl:3:11: error: redefinition of 's'\n"
                  "    float s = 2;\n"
                  "          ^\n"
                  "t.sl:2:11: note: previous definition is here\n"
                  "    float s = 1;\n"
                  "          ^\n");
    expect_errors("float f() { extern float Km; return Km; }\ndisplacement t() { }\n",
                  "t.sl:1:26: error: 'extern' may only name a predefined variable here "
                  "(pass 'Km' as a parameter instead)\n"
                  "float f() { extern float Km; return Km; }\n"
                  "                         ^\n");
}

static void test_assignability(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    u = 1;\n    PI = 3;\n}\n"
                  "float f(float x) { x = 1; return x; }\n",
                  "t.sl:2:5: error: cannot assign to 'u': it is a read-only global variable\n"
                  "    u = 1;\n"
                  "    ^\n"
                  "t.sl:3:5: error: cannot assign to 'PI': it is a constant\n"
                  "    PI = 3;\n"
                  "    ^\n"
                  "t.sl:5:20: error: cannot assign to parameter 'x': it is not declared "
                  "'output'\n"
                  "float f(float x) { x = 1; return x; }\n"
                  "                   ^\n");
    expect_errors("void twice(output float y) { y *= 2; }\ndisplacement t() {\n"
                  "    twice(u + 1);\n    setxcomp(point(1, 2, 3), 1);\n}\n",
                  "t.sl:3:13: error: argument 1 of 'twice' must be a variable (the parameter "
                  "is 'output')\n"
                  "    twice(u + 1);\n"
                  "            ^\n"
                  "t.sl:4:14: error: argument 1 of 'setxcomp' must be a variable\n"
                  "    setxcomp(point(1, 2, 3), 1);\n"
                  "             ^\n");
}

static void test_types(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    P = P + Cs;\n    color c = P;\n    float f = 1;\n"
                  "    f = point(1, 2, 3);\n    if (P) P = 0;\n}\n",
                  "t.sl:2:11: error: invalid operands to binary '+' ('point' and 'color')\n"
                  "    P = P + Cs;\n"
                  "          ^\n"
                  "t.sl:3:15: error: cannot initialize 'c' (color) with a value of type "
                  "'point'\n"
                  "    color c = P;\n"
                  "              ^\n"
                  "t.sl:5:9: error: cannot assign a value of type 'point' to 'f' (float)\n"
                  "    f = point(1, 2, 3);\n"
                  "        ^\n"
                  "t.sl:6:9: error: a value of type 'point' cannot be used as a condition\n"
                  "    if (P) P = 0;\n"
                  "        ^\n");
    expect_errors("displacement t() {\n    P = point(1, 2);\n    float x = u < 1 ? P : Cs;\n}\n",
                  "t.sl:2:9: error: a 'point' is built from 1 or 3 floats, not from 2 values\n"
                  "    P = point(1, 2);\n"
                  "        ^\n"
                  "t.sl:3:21: error: incompatible operand types ('point' and 'color') in "
                  "conditional expression\n"
                  "    float x = u < 1 ? P : Cs;\n"
                  "                    ^\n");
    /* one undeclared name: one error, its uses are silent */
    expect_errors("displacement t() {\n    float x = nope1;\n    P += x * N;\n"
                  "    P += nope2 * N + noise(nope2);\n}\n",
                  "t.sl:2:15: error: use of undeclared identifier 'nope1'\n"
                  "    float x = nope1;\n"
                  "              ^\n"
                  "t.sl:4:10: error: use of undeclared identifier 'nope2'\n"
                  "    P += nope2 * N + noise(nope2);\n"
                  "         ^\n"
                  "t.sl:4:28: error: use of undeclared identifier 'nope2'\n"
                  "    P += nope2 * N + noise(nope2);\n"
                  "                           ^\n");
}

static void test_calls(void **state)
{
    (void)state;
    expect_errors("surface t() {\n    Ci = noise(\"x\");\n}\n",
                  "t.sl:2:10: error: no matching function for call to 'noise' with arguments "
                  "(string)\n"
                  "    Ci = noise(\"x\");\n"
                  "         ^\n"
                  "t.sl:2:10: note: candidates are: noise(float), noise(float, float), "
                  "noise(point), noise(point, float)\n"
                  "    Ci = noise(\"x\");\n"
                  "         ^\n");
    expect_errors("float f(float a; float b) { return a + b; }\ndisplacement t() {\n"
                  "    P += f(1) * N;\n}\n",
                  "t.sl:3:10: error: function 'f' takes 2 arguments, but 1 was given\n"
                  "    P += f(1) * N;\n"
                  "         ^\n"
                  "t.sl:1:7: note: 'f' declared here\n"
                  "float f(float a; float b) { return a + b; }\n"
                  "      ^\n");
    expect_errors("displacement t() {\n    P = transform(\"eye\", P);\n"
                  "    P = point \"ndc\" (0, 0, 0);\n    color c = color \"cmyk\" (1, 0, 0);\n}\n",
                  "t.sl:2:19: error: unknown space 'eye' (known: \"current\", \"world\", "
                  "\"object\", \"shader\", \"camera\", \"screen\", \"NDC\", \"raster\")\n"
                  "    P = transform(\"eye\", P);\n"
                  "                  ^\n"
                  "t.sl:3:9: error: unknown space 'ndc' (known: \"current\", \"world\", "
                  "\"object\", \"shader\", \"camera\", \"screen\", \"NDC\", \"raster\")\n"
                  "    P = point \"ndc\" (0, 0, 0);\n"
                  "        ^\n"
                  "t.sl:4:15: error: unknown color space 'cmyk' (known: \"rgb\", \"hsv\", "
                  "\"hsl\", \"xyz\", \"XYZ\", \"xyY\", \"YIQ\")\n"
                  "    color c = color \"cmyk\" (1, 0, 0);\n"
                  "              ^\n");
}

static void test_control_flow_errors(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n    break;\n    while (1) { continue 2; }\n}\n",
                  "t.sl:2:5: error: 'break' statement not in loop\n"
                  "    break;\n"
                  "    ^\n"
                  "t.sl:3:17: error: 'continue 2' leaves more loops than the 1 around it\n"
                  "    while (1) { continue 2; }\n"
                  "                ^\n");
    expect_errors("float f() { }\nvoid g() { return 1; }\ndisplacement t() { return 1; }\n",
                  "t.sl:1:7: error: non-void function 'f' has no 'return' statement\n"
                  "float f() { }\n"
                  "      ^\n"
                  "t.sl:2:12: error: void function 'g' should not return a value\n"
                  "void g() { return 1; }\n"
                  "           ^\n"
                  "t.sl:3:20: error: shader 't' should not return a value\n"
                  "displacement t() { return 1; }\n"
                  "                   ^\n");
}

static void test_recursion(void **state)
{
    (void)state;
    expect_errors("float f(float x) { return x < 1 ? x : f(x - 1); }\n"
                  "displacement t() { P += f(u) * N; }\n",
                  "t.sl:1:7: error: recursion is not supported: f -> f\n"
                  "float f(float x) { return x < 1 ? x : f(x - 1); }\n"
                  "      ^\n");
    expect_errors("float g(float x);\n", "t.sl:1:17: error: expected '{' to start a block\n"
                  "float g(float x);\n"
                  "                ^\n");
    expect_errors("float f(float x) { return h(x); }\nfloat g(float x) { return f(x); }\n"
                  "float h(float x) { return g(x) + 1; }\ndisplacement t() { }\n",
                  "t.sl:1:7: error: recursion is not supported: f -> h -> g -> f\n"
                  "float f(float x) { return h(x); }\n"
                  "      ^\n");
}

/* ---------------------------------------------------------------------- */
/* what is accepted                                                        */
/* ---------------------------------------------------------------------- */

/* User functions take up to SL_MAX_FUNC_PARAMS parameters: a definition
 * or a call beyond it is one clear error; a built-in's list is shorter. */
static void test_parameter_limits(void **state)
{
    (void)state;
    static char src[1 << 14];
    size_t o = (size_t)snprintf(src, sizeof src, "float wide(float a0");
    for (int i = 1; i < SL_MAX_FUNC_PARAMS + 1; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, ", a%d", i);
    o += (size_t)snprintf(src + o, sizeof src - o, ") { return a0; }\n"
                          "displacement t() {\n    P += wide(1");
    for (int i = 1; i < SL_MAX_FUNC_PARAMS + 1; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, ", 1");
    snprintf(src + o, sizeof src - o, ") * N;\n}\n");
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    assert_null(p);
    assert_non_null(strstr(text, "t.sl:1:7: error: function 'wide' has 256 parameters; at "
                                 "most 255 are supported: pass some of them in arrays\n"));
    assert_non_null(strstr(text, "t.sl:3:10: error: too many arguments in call to 'wide' "
                                 "(256; a function takes at most 255)\n"));
    free(text);
    expect_errors("displacement t() {\n    P += sin(1, 2, 3, 4, 5, 6, 7, 8, 9) * N;\n}\n",
                  "t.sl:2:10: error: too many arguments in call to 'sin' (9; this built-in "
                  "takes at most 8)\n"
                  "    P += sin(1, 2, 3, 4, 5, 6, 7, 8, 9) * N;\n"
                  "         ^\n");
}

/* The overloads of one name nested in one block come into scope together
 * (each body may call the others); code outside them calls the group once
 * all of it is defined. */
static void test_nested_overload_group(void **state)
{
    (void)state;
    expect_errors("displacement t() {\n"
                  "    float h(float x) { float y; h(x, y); return y; }\n"
                  "    float a = h(s);\n"
                  "    void h(float x; output float y) { extern float a; y = x * a; }\n"
                  "    P += a * N;\n}\n",
                  "t.sl:3:15: error: 'h' is called before all its overloads in this block are "
                  "defined: move the call after the definition at line 4\n"
                  "    float a = h(s);\n"
                  "              ^\n");
    expect_ok("displacement t() {\n"
              "    float h(float x) { float y; h(x, y); return y; }\n"
              "    void h(float x; output float y) { y = x * 2; }\n"
              "    P += h(s) * N;\n}\n");
    /* a later definition with the same parameters is still a redefinition */
    expect_errors("displacement t() {\n"
                  "    float h(float x) { return x; }\n"
                  "    float h(float y) { return y; }\n"
                  "    P += h(s) * N;\n}\n",
                  "t.sl:3:11: error: redefinition of function 'h'\n"
                  "    float h(float y) { return y; }\n"
                  "          ^\n"
                  "t.sl:2:11: note: previous definition is here\n"
                  "    float h(float x) { return x; }\n"
                  "          ^\n");
}

/* Redefinitions among many functions (the checker finds them by sorting
 * the file's functions by signature: scanning the earlier ones for each
 * took 37 s for 80,000): every one reported, in source order, with the
 * earliest definition of the same signature; overloads (other parameter
 * types, 'output', another return type) are not redefinitions. */
static void test_redefinitions_among_many_functions(void **state)
{
    (void)state;
    enum { N = 20000 };
    size_t cap = (size_t)N * 64 + 1024, len = 0;
    char *src = malloc(cap);
    assert_non_null(src);
    /* line i + 1: f<i>; then overloads of f1 and redefinitions */
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(src + len, cap - len, "float f%d(float x) { return x; }\n", i);
    len += (size_t)snprintf(src + len, cap - len,
                            "float f1(point x) { return 1; }\n"             /* N + 1 */
                            "float f1(output float x) { return 1; }\n"      /* N + 2 */
                            "color f1(float x) { return 1; }\n"             /* N + 3 */
                            "float f%d(float y) { return y; }\n"            /* N + 4 */
                            "float f7(float z) { return z; }\n"             /* N + 5 */
                            "float f%d(float w) { return w; }\n"            /* N + 6 */
                            "float f1(point p) { return 2; }\n"             /* N + 7 */
                            "displacement t() { }\n",
                            N - 1, N - 1);
    assert_true(len < cap);
    char expected[4096];
    int n = 0;
    /* each redefinition with the earliest one of its signature */
    struct { int line, prev_line; const char *name, *text, *prev; } want[] = {
        {N + 4, N, "f19999", "float f19999(float y) { return y; }",
         "float f19999(float x) { return x; }"},
        {N + 5, 8, "f7", "float f7(float z) { return z; }", "float f7(float x) { return x; }"},
        {N + 6, N, "f19999", "float f19999(float w) { return w; }",
         "float f19999(float x) { return x; }"},
        {N + 7, N + 1, "f1", "float f1(point p) { return 2; }", "float f1(point x) { return 1; }"},
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++)
        n += snprintf(expected + n, sizeof expected - (size_t)n,
                      "t.sl:%d:7: error: redefinition of function '%s'\n%s\n      ^\n"
                      "t.sl:%d:7: note: previous definition is here\n%s\n      ^\n",
                      want[k].line, want[k].name, want[k].text, want[k].prev_line, want[k].prev);
    assert_true(n < (int)sizeof expected);
    expect_errors(src, expected);
    free(src);
}

static void test_accepted_forms(void **state)
{
    (void)state;
    /* both parameter list styles, qualifiers, C-style commas, output */
    expect_ok("displacement t(uniform float a = 1, b = 2; varying float c = 3;\n"
              "               output varying point q = 0; string s1 = \"x\", s2 = \"y\")\n"
              "{ q = P; }\n");
    expect_ok("surface t(float Ka = 1, float Kd = 0.5, color c = color \"rgb\" (1, 0, 0)) {"
              " Ci = Ka * c; }\n");
    expect_ok("displacement t() { }\n");
    /* casts with spaces, typecasts of calls, comments, extern of a global */
    expect_ok("// a comment\n"
              "float f(float x) { extern point P; return x + xcomp(P); } /* another */\n"
              "displacement t() {\n"
              "    point a = point \"object\" (P);\n"
              "    vector b = vector \"world\" (0, 0, 1);\n"
              "    normal n = normal \"shader\" (0, 1, 0);\n"
              "    color c = color noise(P) + color \"rgb\" (0.5, 0.5, 0.5);\n"
              "    float x = float noise(P) + f(1);\n"
              "    uniform float i; varying float j;\n"
              "    for (i = 0; i < 3 && j < 3; i += 1) j += 1;\n"
              "    ;\n"
              "}\n");
    /* macros and includes come from the preprocessor */
    expect_ok("#define AMP(x) (0.1 * (x))\n"
              "#if 1\n"
              "displacement t(float Km = AMP(2)) { P += Km * normalize(N); }\n"
              "#endif\n");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_semicolons),
        cmocka_unit_test(test_brackets_and_expressions),
        cmocka_unit_test(test_recovery),
        cmocka_unit_test(test_error_in_macro),
        cmocka_unit_test(test_unsupported),
        cmocka_unit_test(test_shader_definitions),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_assignability),
        cmocka_unit_test(test_types),
        cmocka_unit_test(test_calls),
        cmocka_unit_test(test_control_flow_errors),
        cmocka_unit_test(test_recursion),
        cmocka_unit_test(test_parameter_limits),
        cmocka_unit_test(test_nested_overload_group),
        cmocka_unit_test(test_redefinitions_among_many_functions),
        cmocka_unit_test(test_accepted_forms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
