/*
 * tests/sl/test_sl_deep.c: sources a million deep, through every pass of
 * the compiler (issue 27, item 1). A chain of binary operators is a tree as
 * deep as it is long, which overflowed the stack in the code generator at
 * 20,000 terms; nesting (parentheses, unary operators, blocks, ?:, #if
 * parentheses, inlined calls) stops at a documented limit with an error at
 * file:line:col (docs/shading-language.md, Limits). Each case either
 * compiles or ends with its exact message; none may crash. The time is not
 * asserted (each case takes well under 2 s in a release build).
 *
 *   preprocessor   #if chain of 1e6 terms, 1e6 parentheses, 3e5 nested #if,
 *                  1e6 #elif links, 1e6 nested #ifdef, a #if ?: chain of
 *                  1e6, 1e6 macros each naming the one before (budgets)
 *   parser         1e6 parentheses, unary minus, blocks, assignments, ?:,
 *                  else-if links, nested ifs, whiles and fors, call
 *                  arguments (each a level of nesting; the message names
 *                  the chain or the statements, not their conditions)
 *   checker        100,000 functions each calling the one before (the
 *                  inlining limit; the lookup of a function by name was a
 *                  scan of every function: 150 s)
 *   checker        a 1e6-term chain ending in an undeclared name
 *   codegen        a folded 1e6-term chain (compiled), a 1e6-term chain
 *                  of variables (the register limit), 2e5 statements that
 *                  may return (the code size limit), nesting through 63
 *                  inlined calls (SL_CG_MAX_DEPTH), a class method (RSL 2)
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/bytecode.h"
#include "sl/codegen.h"
#include "sl/parser.h"
#include "sl/strbuf.h"
#include "sl_harness.h"

enum { MILLION = 1000000 };

static void repeat(sl_strbuf *b, const char *s, int n)
{
    for (int i = 0; i < n; i++)
        sl_strbuf_puts(b, s);
}

/* head, n times open, middle, n times close, tail. */
static sl_strbuf nest(const char *head, const char *open, int n, const char *middle,
                      const char *close, const char *tail)
{
    sl_strbuf b = { 0 };
    sl_strbuf_puts(&b, head);
    repeat(&b, open, n);
    sl_strbuf_puts(&b, middle);
    repeat(&b, close, n);
    sl_strbuf_puts(&b, tail);
    return b;
}

/* `src` (freed) fails to compile; its first diagnostic is exactly `first`,
 * or with first NULL, some diagnostic holds `part`. Sources over the 4 MiB
 * of sl_source_set (a million else-ifs) are compiled with the limit raised:
 * the passes, not the size check, are under test. */
static char *compile_text(const char *src, sl_program **out)
{
    sl_source_set *set = sl_source_set_new();
    sl_source_set_set_max_size(set, (size_t)1 << 30);
    sl_diag *diag = sl_diag_new();
    sl_source_set_add(set, "t.sl", src, strlen(src));
    *out = sl_compile(set, "t.sl", NULL, NULL, diag);
    char *text = sl_diag_to_string(diag);
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return text;
}

/* `src` (freed) fails to compile; its first diagnostic is exactly `first`,
 * or with first NULL, some diagnostic holds `part`. */
static void expect_error(sl_strbuf src, const char *first, const char *part)
{
    sl_program *p = NULL;
    char *text = compile_text(src.data, &p);
    assert_null(p);
    size_t len = strcspn(text, "\n");
    if (first && (strlen(first) != len || strncmp(text, first, len) != 0))
        fprintf(stderr, "got: %.*s\nwanted: %s\n", (int)len, text, first);
    if (first) {
        assert_int_equal(len, strlen(first));
        assert_memory_equal(text, first, len);
    } else {
        assert_non_null(strstr(text, part));
    }
    free(text);
    free(src.data);
}

/* `src` (freed) compiles; the program has fewer than `max_code` instructions. */
static void expect_compiled(sl_strbuf src, int max_code)
{
    sl_program *p = NULL;
    char *text = compile_text(src.data, &p);
    if (!p)
        fprintf(stderr, "%.300s\n", text);
    assert_non_null(p);
    assert_true(p->ncode < max_code);
    sl_program_destroy(&p);
    free(text);
    free(src.data);
}

/* ---------------------------------------------------------------------- */
/* preprocessor                                                            */
/* ---------------------------------------------------------------------- */

static void test_pp_if_chain(void **state)
{
    (void)state;
    /* iterative: precedence climbing */
    expect_compiled(nest("#if 1", "+1", MILLION - 1, "", "",
                         " == 1000000\ndisplacement d() { }\n#endif\n"), 8);
}

static void test_pp_if_parens(void **state)
{
    (void)state;
    /* ex_cond and ex_unary count 2 levels a parenthesis: the 129th */
    expect_error(nest("#if ", "(", MILLION, "1", ")", "\n#endif\ndisplacement d() { }\n"),
                 "t.sl:1:133: error: #if expression nested too deeply (more than 256 levels): "
                 "simplify it", NULL);
}

static void test_pp_nested_if(void **state)
{
    (void)state;
    /* a stack of conditions, no recursion */
    expect_compiled(nest("", "#if 1\n", 300000, "displacement d() { }\n", "#endif\n", ""), 8);
}

static void test_pp_elif_chain(void **state)
{
    (void)state;
    /* a million #elif links: one condition frame, no recursion */
    expect_compiled(nest("#if 0\n", "#elif 0\n", MILLION, "#else\ndisplacement d() { }\n#endif\n",
                         "", ""), 8);
}

static const char too_many_tokens[] = "error: too many tokens (more than 2097152 scanned or "
                                      "produced by macro expansion)";

static void test_pp_million_deep(void **state)
{
    (void)state;
    /* nested #ifdef, a #if ?: chain, a chain of a million macros each
     * naming the one before: each stops at a budget, none recurses */
    expect_error(nest("", "#ifdef X\n", MILLION, "", "#endif\n", "displacement d() { }\n"), NULL,
                 too_many_tokens);
    expect_error(nest("#if ", "1?1:", MILLION, "0", "", "\n#endif\ndisplacement d() { }\n"), NULL,
                 too_many_tokens);
    sl_strbuf b = { 0 };
    sl_strbuf_puts(&b, "#define M0 1\n");
    char line[64];
    for (int i = 1; i < MILLION; i++) {
        snprintf(line, sizeof line, "#define M%d M%d\n", i, i - 1);
        sl_strbuf_puts(&b, line);
    }
    snprintf(line, sizeof line, "displacement d() { float x = M%d; }\n", MILLION - 1);
    sl_strbuf_puts(&b, line);
    expect_error(b, NULL, "error: macro expansion too large (more than 67108864 bytes of "
                          "preprocessor storage)");
}

/* ---------------------------------------------------------------------- */
/* parser                                                                  */
/* ---------------------------------------------------------------------- */

static const char expr_deep[] = "error: expression nested too deeply (more than 200 levels): "
                                "split it into statements with temporary variables";

static void expect_expr_deep(sl_strbuf src, int col)
{
    char want[256];
    snprintf(want, sizeof want, "t.sl:1:%d: %s", col, expr_deep);
    expect_error(src, want, NULL);
}

static void test_parse_parens(void **state)
{
    (void)state;
    /* one level for the initializer, two per parenthesis (expression and
     * unary): the 100th parenthesis, at column 30 + 99 */
    expect_expr_deep(nest("displacement d() { float x = ", "(", MILLION, "s", ")", "; }\n"),
                     129);
}

static void test_parse_unary(void **state)
{
    (void)state;
    expect_expr_deep(nest("displacement d() { float x = ", "-", MILLION, "s; }\n", "", ""),
                     29 + 199);
}

static void test_parse_assignments(void **state)
{
    (void)state;
    expect_error(nest("displacement d() { float x; ", "x=", MILLION, "s; }\n", "", ""), NULL,
                 expr_deep);
}

static void test_parse_conditionals(void **state)
{
    (void)state;
    expect_error(nest("displacement d() { float x = ", "s>0?1:", 600000, "s; }\n", "", ""),
                 NULL, expr_deep);
}

static void test_parse_blocks(void **state)
{
    (void)state;
    /* the shader's own block is no statement: the 201st '{' */
    expect_error(nest("displacement d() { ", "{", MILLION, "float x = s;", "}", " }\n"),
                 "t.sl:1:220: error: statements nested too deeply (more than 200 levels): "
                 "move the inner blocks into functions", NULL);
}

static const char stmt_deep[] = "error: statements nested too deeply (more than 200 levels): "
                                "move the inner blocks into functions";

static void test_parse_else_if_chain(void **state)
{
    (void)state;
    /* a link a level, its condition two more: the 198th link's '(' */
    expect_error(nest("displacement d() { float x = 0; if (s>0) x=1;", " else if (s>0) x=1;",
                      MILLION, "", "", " }\n"),
                 "t.sl:1:3768: error: 'else if' chain too long (more than 200 levels of "
                 "nesting, each 'else if' one): split it into several if statements", NULL);
}

static void test_parse_nested_ifs(void **state)
{
    (void)state;
    char want[256];
    snprintf(want, sizeof want, "t.sl:1:1819: %s", stmt_deep);
    expect_error(nest("displacement d() { float x = 0; ", "if (s>0) ", MILLION, "x=1;", "",
                      " }\n"), want, NULL);
}

static void test_parse_nested_loops(void **state)
{
    (void)state;
    char want[256];
    snprintf(want, sizeof want, "t.sl:1:2416: %s", stmt_deep);
    expect_error(nest("displacement d() { float x = 0; ", "while (s>0) ", MILLION, "x=0;", "",
                      " }\n"), want, NULL);
    snprintf(want, sizeof want, "t.sl:1:2415: %s", stmt_deep);
    expect_error(nest("displacement d() { float x = 0; ", "for (;s>0;) ", MILLION, "x=0;", "",
                      " }\n"), want, NULL);
}

static void test_parse_nested_calls(void **state)
{
    (void)state;
    expect_expr_deep(nest("displacement d() { float x = ", "abs(", MILLION, "s", ")", "; }\n"),
                     426);
    expect_expr_deep(nest("displacement d() { float x = ", "float(", MILLION, "s", ")",
                          "; }\n"), 624);
}

/* ---------------------------------------------------------------------- */
/* checker and code generator                                              */
/* ---------------------------------------------------------------------- */

static void test_chain_folded(void **state)
{
    (void)state;
    /* folds to 1: every pass walks it */
    expect_compiled(nest("displacement d() { P += (1", "*1", MILLION - 1, ") * N; }\n", "", ""),
                    16);
}

static void test_chain_logical(void **state)
{
    (void)state;
    /* + binds tighter than && */
    expect_error(nest("displacement d() { float x = 0; if (0", "+0", 300000, "", "&&u>0",
                      ") x = 1; }\n"),
                 NULL, "error: shader needs more than 4096 registers (the limit per shader)");
}

static void test_chain_registers(void **state)
{
    (void)state;
    /* each partial sum takes a register: the 4096 are full at the 4050th '+' */
    expect_error(nest("displacement d() { float x = s", "+s", MILLION - 1, "; }\n", "", ""),
                 "t.sl:1:8129: error: shader needs more than 4096 registers (the limit per "
                 "shader)", NULL);
}

static void test_chain_checked(void **state)
{
    (void)state;
    char want[128];
    snprintf(want, sizeof want, "t.sl:1:%d: error: use of undeclared identifier 'q'",
             30 + 2 * MILLION);
    expect_error(nest("displacement d() { float x = ", "0+", MILLION, "q; }\n", "", ""), want,
                 NULL);
}

static void test_chain_in_class(void **state)
{
    (void)state;
    expect_compiled(nest("class c() { public void displacement(output point P; output normal N) "
                         "{ P += (0", "+0", MILLION - 1, ") * N; } }\n", "", ""), 16);
}

static void test_many_escapes(void **state)
{
    (void)state;
    /* each guards the rest: thousands of guards open (not nested calls)
     * when the code is full */
    expect_error(nest("float f(float a) { ", "if(a>0)return 1;", 200000,
                      "return 0; }\ndisplacement d() { P += f(u) * N; }\n", "", ""),
                 "t.sl:1:131076: error: shader too large: more than 65534 instructions (after "
                 "inlining functions)", NULL);
}

static void test_function_chain(void **state)
{
    (void)state;
    /* 100,000 definitions (4 MiB of source at most): the lookup by name
     * is a hash chain; the call depth stops at the 64th inlined call */
    sl_strbuf b = { 0 };
    sl_strbuf_puts(&b, "float f0(float x) { return x; }\n");
    char line[96];
    for (int i = 1; i < 100000; i++) {
        snprintf(line, sizeof line, "float f%d(float x) { return f%d(x); }\n", i, i - 1);
        sl_strbuf_puts(&b, line);
    }
    sl_strbuf_puts(&b, "displacement d() { P += f99999(u) * N; }\n");
    expect_error(b, "t.sl:99937:32: error: function calls nested too deeply (limit 64)", NULL);
}

/* 63 functions each calling the previous one from inside `blocks` nested
 * blocks and `minus` unary minus signs: each within the parser's limit,
 * SL_CG_MAX_DEPTH levels after inlining. */
static void nested_calls(sl_strbuf *src, int blocks, int minus)
{
    sl_strbuf_puts(src, "float f0(float x) { return x; }\n");
    for (int i = 1; i < 64; i++) {
        char head[96];
        snprintf(head, sizeof head, "float f%d(float x) { float r = 0; ", i);
        sl_strbuf_puts(src, head);
        repeat(src, "{", blocks);
        sl_strbuf_puts(src, " r = ");
        repeat(src, "-", minus);
        snprintf(head, sizeof head, "f%d(x); ", i - 1);
        sl_strbuf_puts(src, head);
        repeat(src, "}", blocks);
        sl_strbuf_puts(src, " return r; }\n");
    }
    sl_strbuf_puts(src, "displacement d() { P += f63(u) * N; }\n");
}

static void test_inlined_nesting(void **state)
{
    (void)state;
    assert_true(SL_CG_MAX_DEPTH < SL_MAX_INLINE_DEPTH * SL_PARSE_MAX_DEPTH);
    sl_strbuf src = { 0 };
    nested_calls(&src, 150, 40);
    expect_error(src, NULL, "error: expressions and statements nested too deeply once function "
                            "calls are inlined (more than 1000 levels): call the functions here "
                            "less deeply, or split their nested code into statements");
    src = (sl_strbuf){ 0 };
    nested_calls(&src, 2, 2);                  /* the same calls, shallow: compiles */
    expect_compiled(src, 60000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pp_if_chain),
        cmocka_unit_test(test_pp_if_parens),
        cmocka_unit_test(test_pp_nested_if),
        cmocka_unit_test(test_pp_elif_chain),
        cmocka_unit_test(test_pp_million_deep),
        cmocka_unit_test(test_parse_parens),
        cmocka_unit_test(test_parse_unary),
        cmocka_unit_test(test_parse_assignments),
        cmocka_unit_test(test_parse_conditionals),
        cmocka_unit_test(test_parse_blocks),
        cmocka_unit_test(test_parse_else_if_chain),
        cmocka_unit_test(test_parse_nested_ifs),
        cmocka_unit_test(test_parse_nested_loops),
        cmocka_unit_test(test_parse_nested_calls),
        cmocka_unit_test(test_function_chain),
        cmocka_unit_test(test_chain_folded),
        cmocka_unit_test(test_chain_logical),
        cmocka_unit_test(test_chain_registers),
        cmocka_unit_test(test_chain_checked),
        cmocka_unit_test(test_chain_in_class),
        cmocka_unit_test(test_many_escapes),
        cmocka_unit_test(test_inlined_nesting),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
