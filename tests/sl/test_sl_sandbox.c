/*
 * tests/sl/test_sl_sandbox.c: a shader arrives over the network, so the
 * compiler and the VM must stop every hostile one with an error that names
 * the shader and the limit, and never hang or crash:
 *
 *   instruction budget   infinite loops in all four modes
 *   loop cap             an undecided loop in interval/affine mode
 *   merge memory         undecided iterations saving too many values
 *   registers            more variables than SL_MAX_SLOTS
 *   code size            exponential inlining
 *   nesting              deep expressions, statements, call chains
 *   runtime refusals     strings differing across an undecided branch, a
 *                        varying pnoise period, an unknown space name
 *   garbage              mutated sources compile or fail, never crash
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/strbuf.h"
#include "sl_harness.h"

static sl_status run_mode(sl_program *p, const sl_limits *limits, sl_mode mode, char *error,
                          size_t size)
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(limits);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    switch (mode) {
    case SL_MODE_FLOAT: h_globals_float(vm, H_PLANE, 0.35, 0.5); break;
    case SL_MODE_DUAL: h_globals_dual(vm, H_PLANE, 0.35, 0.5); break;
    case SL_MODE_INTERVAL: h_globals_interval(vm, H_PLANE, 0.3, 0.4, 0.4, 0.6); break;
    case SL_MODE_AFFINE: h_globals_affine(vm, &ctx, H_PLANE, 0.3, 0.4, 0.4, 0.6); break;
    }
    sl_status st = sl_vm_run(vm, inst, mode, &ctx);
    snprintf(error, size, "%s", sl_vm_error(vm));
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return st;
}

/* Compiling `src` fails and the first diagnostic is `message`. */
static void expect_compile_error(const char *src, const char *message)
{
    char *text = NULL;
    sl_program *p = h_compile_named("t.sl", src, &text);
    assert_null(p);
    if (!strstr(text, message))
        fprintf(stderr, "got: %s\n", text);
    assert_non_null(strstr(text, message));
    free(text);
}

/* ---------------------------------------------------------------------- */

static void test_instruction_budget(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement spin() { float i = 0; while (1) i += 1; P += i * N; }");
    assert_non_null(p);
    sl_limits limits = { 1000, 64 };
    char error[512];
    for (int m = SL_MODE_FLOAT; m <= SL_MODE_AFFINE; m++) {
        assert_int_equal(run_mode(p, &limits, (sl_mode)m, error, sizeof error), SL_ERR_BUDGET);
        char want[256];
        static const char *const names[] = { "float", "dual", "interval", "affine" };
        snprintf(want, sizeof want, "shader 'spin': instruction budget of 1000 exceeded "
                                    "(%s mode)", names[m]);
        assert_string_equal(error, want);
    }
    /* the budget is per run and configurable: a finite loop fits a larger one */
    sl_program *q = h_compile("displacement count() { float i = 0; while (i < 400) i += 1; }");
    assert_non_null(q);
    assert_int_equal(run_mode(q, &limits, SL_MODE_FLOAT, error, sizeof error), SL_ERR_BUDGET);
    limits.max_instructions = 5000;
    assert_int_equal(run_mode(q, &limits, SL_MODE_FLOAT, error, sizeof error), SL_OK);
    assert_int_equal(run_mode(q, &limits, SL_MODE_AFFINE, error, sizeof error), SL_OK);
    sl_program_destroy(&q);
    sl_program_destroy(&p);
}

static void test_loop_cap(void **state)
{
    (void)state;
    /* u in [0.3, 0.4]: a < 1000 u is undecided for a = 300 .. 400 */
    sl_program *p = h_compile("displacement runaway() {\n"
                              "    float a = 0;\n"
                              "    while (a < u * 1000) a += 1;\n"
                              "    P += a * N;\n"
                              "}\n");
    assert_non_null(p);
    char error[512];
    assert_int_equal(run_mode(p, NULL, SL_MODE_AFFINE, error, sizeof error), SL_ERR_LOOP_CAP);
    assert_string_equal(error, "shader 'runaway': loop at t.sl:3:5 still undecided after 64 "
                               "iterations in affine mode");
    assert_int_equal(run_mode(p, NULL, SL_MODE_INTERVAL, error, sizeof error), SL_ERR_LOOP_CAP);
    assert_string_equal(error, "shader 'runaway': loop at t.sl:3:5 still undecided after 64 "
                               "iterations in interval mode");
    /* float and dual decide every test */
    assert_int_equal(run_mode(p, NULL, SL_MODE_FLOAT, error, sizeof error), SL_OK);
    /* a larger cap lets it finish */
    sl_limits limits = { 1000000, 200 };
    assert_int_equal(run_mode(p, &limits, SL_MODE_AFFINE, error, sizeof error), SL_OK);
    sl_program_destroy(&p);
}

static void test_merge_memory(void **state)
{
    (void)state;
    /* 150 variables saved per undecided iteration, 64 iterations: more
     * than the VM's merge pool */
    sl_strbuf src = { 0 };
    sl_strbuf_puts(&src, "displacement hog() {\n float a = 0;\n");
    for (int i = 0; i < 150; i++) {
        char line[64];
        snprintf(line, sizeof line, " float x%d = %d;\n", i, i);
        sl_strbuf_puts(&src, line);
    }
    sl_strbuf_puts(&src, " while (a < u * 1000) {\n  a += 1;\n");
    for (int i = 0; i < 150; i++) {
        char line[64];
        snprintf(line, sizeof line, "  x%d += a;\n", i);
        sl_strbuf_puts(&src, line);
    }
    sl_strbuf_puts(&src, " }\n P += x7 * N;\n}\n");
    sl_program *p = h_compile(src.data);
    free(src.data);
    assert_non_null(p);
    char error[512];
    assert_int_equal(run_mode(p, NULL, SL_MODE_AFFINE, error, sizeof error), SL_ERR_RUNTIME);
    assert_non_null(strstr(error, "shader 'hog': undecided branches nested too deeply at t.sl:"));
    assert_non_null(strstr(error, "(limit 512 frames, 8192 saved values)"));
    sl_program_destroy(&p);
}

static void test_register_limit(void **state)
{
    (void)state;
    sl_strbuf src = { 0 };
    sl_strbuf_puts(&src, "displacement big() {\n");
    for (int i = 0; i < 1400; i++) {
        char line[64];
        snprintf(line, sizeof line, " point p%d = P * %d;\n", i, i);
        sl_strbuf_puts(&src, line);
    }
    sl_strbuf_puts(&src, "}\n");
    /* 46 global slots + 3 per point: p1350 (line 1352) no longer fits */
    expect_compile_error(src.data, "t.sl:1352:8: error: shader needs more than 4096 registers "
                                   "(the limit per shader)");
    free(src.data);
}

static void test_code_size_limit(void **state)
{
    (void)state;
    /* each level calls the one below twice: 2^30 inlined calls */
    sl_strbuf src = { 0 };
    sl_strbuf_puts(&src, "float f0(float x) { return x * x + 1; }\n");
    for (int i = 1; i <= 30; i++) {
        char line[128];
        snprintf(line, sizeof line, "float f%d(float x) { return f%d(x) + f%d(x + 1); }\n", i,
                 i - 1, i - 1);
        sl_strbuf_puts(&src, line);
    }
    sl_strbuf_puts(&src, "displacement bomb() { P += f30(u) * N; }\n");
    expect_compile_error(src.data, "error: shader too large: more than 65534 instructions "
                                   "(after inlining functions)");
    free(src.data);
}

static void test_nesting_limits(void **state)
{
    (void)state;
    sl_strbuf src = { 0 };
    sl_strbuf_puts(&src, "displacement deep() { float x = ");
    for (int i = 0; i < 1000; i++)
        sl_strbuf_putc(&src, '(');
    sl_strbuf_puts(&src, "1");
    for (int i = 0; i < 1000; i++)
        sl_strbuf_putc(&src, ')');
    sl_strbuf_puts(&src, "; }\n");
    expect_compile_error(src.data, "error: expression nested too deeply (more than 200 levels): "
                                   "split it into statements with temporary variables");
    free(src.data);

    src = (sl_strbuf){ 0 };
    sl_strbuf_puts(&src, "displacement deep() { ");
    for (int i = 0; i < 500; i++)
        sl_strbuf_puts(&src, "{ ");
    for (int i = 0; i < 500; i++)
        sl_strbuf_puts(&src, "} ");
    sl_strbuf_puts(&src, "}\n");
    expect_compile_error(src.data, "error: statements nested too deeply (more than 200 levels): "
                                   "move the inner blocks into functions");
    free(src.data);

    src = (sl_strbuf){ 0 };
    sl_strbuf_puts(&src, "float f0(float x) { return x + 1; }\n");
    for (int i = 1; i <= 80; i++) {
        char line[96];
        snprintf(line, sizeof line, "float f%d(float x) { return f%d(x); }\n", i, i - 1);
        sl_strbuf_puts(&src, line);
    }
    sl_strbuf_puts(&src, "displacement chain() { P += f80(u) * N; }\n");
    expect_compile_error(src.data, "error: function calls nested too deeply (limit 64)");
    free(src.data);
}

static void test_runtime_refusals(void **state)
{
    (void)state;
    char error[512];
    sl_program *p = h_compile("displacement str() {\n"
                              "    string sp = \"object\";\n"
                              "    if (u > 0.35) sp = \"world\";\n"
                              "    P = transform(sp, P);\n"
                              "}\n");
    assert_non_null(p);
    assert_int_equal(run_mode(p, NULL, SL_MODE_FLOAT, error, sizeof error), SL_OK);
    assert_int_equal(run_mode(p, NULL, SL_MODE_AFFINE, error, sizeof error), SL_ERR_RUNTIME);
    assert_string_equal(error, "shader 'str': a string variable gets different values on the "
                               "two sides of an undecided condition at t.sl:3:5 (\"world\" and "
                               "\"object\")");
    sl_program_destroy(&p);

    p = h_compile("displacement per() {\n    P += pnoise(u * 4, 4 + u) * N;\n}\n");
    assert_non_null(p);
    assert_int_equal(run_mode(p, NULL, SL_MODE_FLOAT, error, sizeof error), SL_OK);
    assert_int_equal(run_mode(p, NULL, SL_MODE_INTERVAL, error, sizeof error), SL_ERR_RUNTIME);
    assert_string_equal(error, "shader 'per': the period of pnoise must not vary over the "
                               "surface (at t.sl:2:10)");
    sl_program_destroy(&p);

    p = h_compile("displacement idx() {\n    P = comp(P, u * 4);\n}\n");
    assert_non_null(p);
    assert_int_equal(run_mode(p, NULL, SL_MODE_FLOAT, error, sizeof error), SL_ERR_RUNTIME);
    assert_string_equal(error, "shader 'idx': component index out of range 0..2 at t.sl:2:9");
    sl_program_destroy(&p);
}

/* Random byte mutations of a library shader: each either compiles or
 * reports errors (the count agrees with the result); none may crash, and
 * a compiled one runs within its budget in every mode. */
static void test_mutated_sources(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/wave.sl", AAFARM_SHADER_DIR);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char base[8192];
    size_t len = fread(base, 1, sizeof base - 1, f);
    fclose(f);
    base[len] = '\0';
    static const char alphabet[] = "(){};,=+-*/<>!?:.^\"#0123456789 abcxyzPNu\n";
    unsigned long long rng = 7;
    int compiled = 0;
    for (int round = 0; round < 300; round++) {
        char text[8192];
        memcpy(text, base, len + 1);
        int edits = 1 + (int)(h_rand(&rng) * 4);
        for (int e = 0; e < edits; e++) {
            size_t at = (size_t)(h_rand(&rng) * (double)len);
            text[at] = alphabet[(int)(h_rand(&rng) * (sizeof alphabet - 1))];
        }
        sl_source_set *set = sl_source_set_new();
        sl_diag *diag = sl_diag_new();
        sl_source_set_add(set, "m.sl", text, len);
        sl_program *p = sl_compile(set, "m.sl", NULL, NULL, diag);
        assert_true((p == NULL) == (sl_diag_error_count(diag) > 0));
        if (p) {
            compiled++;
            char error[512];
            sl_limits limits = { 100000, 64 };
            for (int m = SL_MODE_FLOAT; m <= SL_MODE_AFFINE; m++) {
                sl_status st = run_mode(p, &limits, (sl_mode)m, error, sizeof error);
                assert_true(st == SL_OK || error[0] != '\0');
            }
        }
        sl_program_destroy(&p);
        sl_diag_destroy(&diag);
        sl_source_set_destroy(&set);
    }
    printf("  %d of 300 mutated sources compiled\n", compiled);
    assert_true(compiled > 0 && compiled < 300);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_instruction_budget),
        cmocka_unit_test(test_loop_cap),
        cmocka_unit_test(test_merge_memory),
        cmocka_unit_test(test_register_limit),
        cmocka_unit_test(test_code_size_limit),
        cmocka_unit_test(test_nesting_limits),
        cmocka_unit_test(test_runtime_refusals),
        cmocka_unit_test(test_mutated_sources),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
