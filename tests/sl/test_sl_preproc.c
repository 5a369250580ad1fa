/*
 * tests/sl/test_sl_preproc.c: the preprocessor of the shading language
 * (common/sl/preproc.c), through sl_lexer and directly.
 *
 *   macros        object-like, function-like, nesting, rescanning, no
 *                 recursive self-expansion (incl. the C standard's example),
 *                 # and ##, placemarkers, -D/-U, redefinition, and the
 *                 positions of expanded tokens (invocation for body tokens,
 *                 own position for argument tokens, macro name and
 *                 definition recorded)
 *   #if           arithmetic and precedence table, short-circuit, defined,
 *                 #elif/#else chains, nesting, skipped groups stay silent
 *   #include      relative to the including file, search path, <x>, guards,
 *                 the loader, cycles, the depth limit, per-file conditionals
 *   errors        every directive error with exact text, position and
 *                 (where shown) the caret line
 *   limits        token budget, argument nesting, #if nesting
 *   robustness    random bytes and random mutations of a valid shader
 *                 (fixed seed): each run ends, and "no errors" agrees with
 *                 the diagnostics
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl/diag.h"
#include "sl/lexer.h"
#include "sl/preproc.h"
#include "sl/source.h"

/* ---------------------------------------------------------------------- */
/* helpers                                                                 */
/* ---------------------------------------------------------------------- */

static sl_source_set *set;
static sl_diag *diag;
static char out[1 << 17];
static char diag_text[1 << 16];

static int setup(void **state)
{
    (void)state;
    set = sl_source_set_new();
    diag = sl_diag_new();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return 0;
}

static void reset(void)
{
    teardown(NULL);
    setup(NULL);
}

static void add(const char *name, const char *text)
{
    assert_int_equal(sl_source_set_add(set, name, text, strlen(text)), 0);
}

/* Formats the tokens of a lexer: spellings (strings quoted) joined by
 * spaces; with positions "@line:col", prefixed by the file unless it is
 * main.sl. */
static const char *drain(sl_lexer *lx, bool positions)
{
    size_t o = 0;
    out[0] = '\0';
    sl_token t;
    while (sl_lexer_next(lx, &t)) {
        const char *q = t.kind == SL_TOK_STRING ? "\"" : "";
        o += (size_t)snprintf(out + o, sizeof out - o, "%s%s%s%s", o ? " " : "", q, t.text, q);
        if (positions) {
            bool other = strcmp(t.pos.file, "main.sl") != 0;
            o += (size_t)snprintf(out + o, sizeof out - o, "@%s%s%d:%d",
                                  other ? t.pos.file : "", other ? ":" : "",
                                  t.pos.line, t.pos.col);
        }
    }
    return out;
}

static const char *run(const char *main_file, const char *const *search, bool positions)
{
    sl_lexer *lx = sl_lexer_new(set, main_file, search, diag);
    drain(lx, positions);
    sl_lexer_destroy(&lx);
    return out;
}

static const char *expand(const char *text)
{
    add("main.sl", text);
    return run("main.sl", NULL, false);
}

static const char *expand_pos(const char *text)
{
    add("main.sl", text);
    return run("main.sl", NULL, true);
}

static const char *diags(void)
{
    char *s = sl_diag_to_string(diag);
    snprintf(diag_text, sizeof diag_text, "%s", s);
    free(s);
    return diag_text;
}

/* Preprocessing tokens straight from sl_preproc (no lexer checks), for
 * texts that use operators the shading language does not have. */
static const char *pp_raw(const char *text)
{
    add("main.sl", text);
    sl_preproc *pp = sl_preproc_new(set, "main.sl", NULL, diag);
    size_t o = 0;
    out[0] = '\0';
    sl_pptoken t;
    while (sl_preproc_next(pp, &t))
        o += (size_t)snprintf(out + o, sizeof out - o, "%s%.*s", o ? " " : "",
                              (int)t.len, t.text);
    sl_preproc_destroy(&pp);
    assert_null(pp);
    return out;
}

typedef struct expect_diag {
    sl_diag_level level;
    int line, col;
    const char *message;
} expect_diag;

static void check_diags(const expect_diag *e, size_t n)
{
    for (size_t i = 0; i < n && i < sl_diag_count(diag); i++) {
        const sl_diagnostic *d = sl_diag_get(diag, i);
        if (d->level != e[i].level || d->line != e[i].line || d->col != e[i].col ||
            strcmp(d->message, e[i].message) != 0)
            fail_msg("diagnostic %zu: got %d %d:%d '%s', expected %d %d:%d '%s'", i,
                     d->level, d->line, d->col, d->message, e[i].level, e[i].line,
                     e[i].col, e[i].message);
    }
    assert_int_equal(sl_diag_count(diag), n);
}

/* ---------------------------------------------------------------------- */
/* macros                                                                  */
/* ---------------------------------------------------------------------- */

static void test_object_like(void **state)
{
    (void)state;
    add("main.sl",
        "#define PI 3.14159\n"
        "#define TWO_PI (2 * PI)\n"
        "float a = TWO_PI;\n");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    assert_string_equal(drain(lx, true),
                        "float@3:1 a@3:7 =@3:9 (@3:11 2@3:11 *@3:11 3.14159@3:11 )@3:11 ;@3:17");
    sl_lexer_destroy(&lx);

    /* body tokens name the macro whose body they come from */
    reset();
    add("main.sl",
        "#define PI 3.14159\n"
        "#define TWO_PI (2 * PI)\n"
        "float a = TWO_PI;\n");
    lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    for (int i = 0; i < 4; i++)
        assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_LPAREN);
    assert_string_equal(t.macro, "TWO_PI");
    assert_string_equal(t.macro_pos.file, "main.sl");
    assert_int_equal(t.macro_pos.line, 2);
    assert_int_equal(t.macro_pos.col, 9);
    assert_true(sl_lexer_next(lx, &t));
    assert_true(sl_lexer_next(lx, &t));
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_FLOAT);
    assert_true(t.number == 3.14159);
    assert_string_equal(t.macro, "PI");
    assert_int_equal(t.macro_pos.line, 1);
    assert_int_equal(t.macro_pos.col, 9);
    assert_true(sl_lexer_next(lx, &t));
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_SEMICOLON);
    assert_null(t.macro);
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");
}

static void test_note_macro(void **state)
{
    (void)state;
    /* what the parser does for an error at a token from a macro body */
    add("main.sl", "#define SET(v) v = 1 +\nSET(x) ;\n");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    for (int i = 0; i < 4; i++)
        assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_PLUS);
    sl_diag_error(diag, t.pos, "expected expression after '+'");
    sl_token_note_macro(&t, diag);
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_SEMICOLON);
    sl_token_note_macro(&t, diag);               /* not from a macro: nothing */
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(),
                        "main.sl:2:1: error: expected expression after '+'\n"
                        "SET(x) ;\n"
                        "^\n"
                        "main.sl:1:9: note: expanded from macro 'SET'\n"
                        "#define SET(v) v = 1 +\n"
                        "        ^\n");
}

static void test_function_like_positions(void **state)
{
    (void)state;
    /* body tokens at the invocation, argument tokens where written */
    assert_string_equal(expand_pos("#define SQ(x) ((x) * (x))\n"
                                   "y = SQ(a + 1);\n"),
                        "y@2:1 =@2:3 (@2:5 (@2:5 a@2:8 +@2:10 1@2:12 )@2:5 *@2:5 "
                        "(@2:5 a@2:8 +@2:10 1@2:12 )@2:5 )@2:5 ;@2:14");
    assert_string_equal(diags(), "");
}

static void test_invocation_across_lines(void **state)
{
    (void)state;
    assert_string_equal(expand_pos("#define add(a, b) a + b\n"
                                   "x = add(1,\n"
                                   "        2);\n"),
                        "x@2:1 =@2:3 1@2:9 +@2:5 2@3:9 ;@3:11");
}

static void test_nested_and_rescanning(void **state)
{
    (void)state;
    assert_string_equal(expand("#define A B + 1\n"
                               "#define B 2\n"
                               "#define f(x) x(1)\n"
                               "#define g(y) y * 2\n"
                               "#define h f\n"
                               "A; f(g); h(g); g(A)\n"),
                        "2 + 1 ; 1 * 2 ; 1 * 2 ; 2 + 1 * 2");
    assert_string_equal(diags(), "");
}

static void test_nested_positions(void **state)
{
    (void)state;
    /* a macro inside a macro body: still the outer invocation's position */
    assert_string_equal(expand_pos("#define A B + 1\n"
                                   "#define B 2\n"
                                   "  A\n"),
                        "2@3:3 +@3:3 1@3:3");
}

static void test_self_reference(void **state)
{
    (void)state;
    assert_string_equal(expand("#define x x + 1\n"
                               "#define a b\n"
                               "#define b a\n"
                               "#define f(n) f(n) + n\n"
                               "#define g(n) h(n)\n"
                               "#define h(n) g(n)\n"
                               "x; a; b; f(2); g(3); f(f(1))\n"),
                        "x + 1 ; a ; b ; f ( 2 ) + 2 ; g ( 3 ) ; "
                        "f ( f ( 1 ) + 1 ) + f ( 1 ) + 1");
    assert_string_equal(diags(), "");
}

static void test_c_standard_example(void **state)
{
    (void)state;
    /* ISO C11 6.10.3.5, EXAMPLE 3 and 4 (the parts without variadics) */
    assert_string_equal(pp_raw("#define x 3\n"
                               "#define f(a) f(x * (a))\n"
                               "#undef x\n"
                               "#define x 2\n"
                               "#define g f\n"
                               "#define z z[0]\n"
                               "#define h g(~\n"
                               "#define m(a) a(w)\n"
                               "#define w 0,1\n"
                               "#define t(a) a\n"
                               "#define p() int\n"
                               "#define q(x) x\n"
                               "#define r(x,y) x ## y\n"
                               "#define str(x) # x\n"
                               "f(y+1) + f(f(z)) % t(t(g)(0) + t)(1);\n"
                               "g(x+(3,4)-w) | h 5) & m\n"
                               "(f)^m(m);\n"
                               "p() i[q()] = { q(1), r(2,3), r(4,), r(,5), r(,) };\n"
                               "char c[2][6] = { str(hello), str() };\n"),
                        "f ( 2 * ( y + 1 ) ) + f ( 2 * ( f ( 2 * ( z [ 0 ] ) ) ) ) % "
                        "f ( 2 * ( 0 ) ) + t ( 1 ) ; "
                        "f ( 2 * ( 2 + ( 3 , 4 ) - 0 , 1 ) ) | f ( 2 * ( ~ 5 ) ) & "
                        "f ( 2 * ( 0 , 1 ) ) ^ m ( 0 , 1 ) ; "
                        "int i [ ] = { 1 , 23 , 4 , 5 , } ; "
                        "char c [ 2 ] [ 6 ] = { \"hello\" , \"\" } ;");
    assert_string_equal(diags(), "");
}

static void test_stringize_and_paste(void **state)
{
    (void)state;
    add("main.sl",
        "#define str(x) #x\n"
        "#define xstr(x) str(x)\n"
        "#define cat(a, b) a ## b\n"
        "#define V 42\n"
        "str(a  \"b\\n\"   c); xstr(V); str(V); cat(x, 1); cat(1, 2); cat(, y); "
        "cat(z, ); cat(,); cat(V, V); cat(+, =)\n");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    assert_string_equal(drain(lx, false),
                        "\"a \"b\\n\" c\" ; \"42\" ; \"V\" ; x1 ; 12 ; y ; z ; ; VV ; +=");
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");

    reset();
    add("main.sl", "#define cat(a, b) a ## b\ncat(1, 2) cat(x, 1) cat(+, =)");
    lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_INT);
    assert_true(t.number == 12);
    assert_string_equal(t.macro, "cat");
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_IDENT);
    assert_ptr_equal(t.text, sl_lexer_intern(lx, "x1", 2));
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_PLUS_ASSIGN);
    assert_int_equal(t.pos.col, 21);
    sl_lexer_destroy(&lx);
}

static void test_paste_then_expand(void **state)
{
    (void)state;
    /* a pasted name is a macro name again; ## chains; # and ## together */
    assert_string_equal(expand("#define cat(a, b) a ## b\n"
                               "#define cat3(a, b, c) a ## b ## c\n"
                               "#define xy 7\n"
                               "cat(x, y) cat3(1, , 3) cat3(, , w) cat3(a, b, c)\n"),
                        "7 13 w abc");
    assert_string_equal(diags(), "");
}

static void test_arguments_with_parens_and_commas(void **state)
{
    (void)state;
    assert_string_equal(expand("#define first(a, b) a\n"
                               "#define second(a, b) b\n"
                               "first((1, 2), 3) second(f(x, y), { 4 })\n"),
                        "( 1 , 2 ) { 4 }");
    assert_string_equal(diags(), "");
}

static void test_name_without_parens(void **state)
{
    (void)state;
    /* a function-like macro's name alone is not an invocation; a space
     * before '(' in a #define makes an object-like macro */
    assert_string_equal(expand("#define f(x) [x]\n"
                               "#define g (x) x\n"
                               "f + f (1) f\n"
                               "(2) g f\n"),
                        "f + [ 1 ] [ 2 ] ( x ) x f");
    assert_string_equal(diags(), "");
}

static void test_undef_and_redefine(void **state)
{
    (void)state;
    assert_string_equal(expand("#define X 1\n"
                               "X\n"
                               "#undef X\n"
                               "X\n"
                               "#define X 2\n"
                               "X\n"
                               "#undef NEVER_DEFINED\n"),
                        "1 X 2");
    assert_string_equal(diags(), "");
}

static void test_redefinition_warning(void **state)
{
    (void)state;
    assert_string_equal(expand("#define Y 1\n"
                               "#define Y 1\n"
                               "#define Y   1 // same tokens, same spacing: fine\n"
                               "#define Y 2\n"
                               "Y\n"),
                        "2");
    assert_string_equal(diags(),
                        "main.sl:4:9: warning: 'Y' macro redefined\n"
                        "#define Y 2\n"
                        "        ^\n"
                        "main.sl:3:9: note: previous definition is here\n"
                        "#define Y   1 // same tokens, same spacing: fine\n"
                        "        ^\n");
    assert_int_equal(sl_diag_error_count(diag), 0);
    assert_int_equal(sl_diag_warning_count(diag), 1);
}

static void test_predefined_macros(void **state)
{
    (void)state;
    add("main.sl",
        "#if DEBUG && LEVEL == 3\n"
        "SQ(LEVEL) EMPTY x\n"
        "#else\n"
        "release\n"
        "#endif\n");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    assert_true(sl_lexer_define(lx, "DEBUG"));
    assert_true(sl_lexer_define(lx, "LEVEL=3"));
    assert_true(sl_lexer_define(lx, "SQ(x)=((x)*(x))"));
    assert_true(sl_lexer_define(lx, "EMPTY="));
    const sl_token *t = sl_lexer_peek(lx, 0);
    assert_string_equal(t->macro, "SQ");
    assert_string_equal(t->macro_pos.file, "<command line>");
    assert_int_equal(t->macro_pos.line, 1);
    assert_int_equal(t->macro_pos.col, 1);
    assert_string_equal(drain(lx, true),
                        "(@2:1 (@2:1 3@2:4 )@2:1 *@2:1 (@2:1 3@2:4 )@2:1 )@2:1 x@2:17");
    sl_lexer_destroy(&lx);

    lx = sl_lexer_new(set, "main.sl", NULL, diag);
    assert_true(sl_lexer_define(lx, "DEBUG"));
    sl_lexer_undefine(lx, "DEBUG");
    assert_string_equal(drain(lx, false), "release");
    assert_false(sl_lexer_define(lx, "3X=1"));
    assert_false(sl_lexer_define(lx, "F(x=1"));
    assert_false(sl_lexer_define(lx, ""));
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(),
                        "<command line>:1:1: error: macro names must be identifiers\n"
                        "<command line>:1:5: error: expected ',' or ')' in macro parameter list\n"
                        "<command line>:1:2: error: macro names must be identifiers\n");
}

/* ---------------------------------------------------------------------- */
/* #if                                                                     */
/* ---------------------------------------------------------------------- */

/* Evaluates `#if expr` in a fresh context. */
static bool if_true(const char *expr, const char *defines)
{
    reset();
    char src[1024];
    snprintf(src, sizeof src, "%s#if %s\nyes\n#else\nno\n#endif\n", defines, expr);
    const char *r = expand(src);
    if (strcmp(r, "yes") != 0 && strcmp(r, "no") != 0)
        fail_msg("#if %s: got '%s'", expr, r);
    if (sl_diag_count(diag) != 0)
        fail_msg("#if %s: %s", expr, diags());
    return strcmp(r, "yes") == 0;
}

static void test_if_arithmetic(void **state)
{
    (void)state;
    static const struct { const char *expr; bool value; } cases[] = {
        { "1", true }, { "0", false }, { "42", true }, { "-1", true },
        { "1 + 2 * 3 == 7", true }, { "(1 + 2) * 3 == 9", true },
        { "10 / 3 == 3", true }, { "-10 / 3 == -3", true }, { "-10 % 3 == -1", true },
        { "7 % 4 == 3", true }, { "1 << 4 == 16", true }, { "-16 >> 2 == -4", true },
        { "1 << 64 == 0", true }, { "~0 == -1", true }, { "!0", true }, { "!5", false },
        { "- - 3 == 3", true }, { "+3 == 3", true },
        { "3 > 2 > 1", false }, { "1 < 2 && 2 <= 2 && 3 >= 3 && 4 != 5", true },
        { "(5 & 3) == 1", true }, { "5 & 3 == 1", false }, { "(5 | 2) == 7", true },
        { "(5 ^ 1) == 4", true }, { "1 | 2 ^ 3 & 4", true },
        { "1 ? 2 : 0", true }, { "0 ? 1 : 0", false }, { "0 ? 1 : 2 ? 3 : 0", true },
        { "1 ? 0 : 1 ? 1 : 1", false }, { "(0 ? 1 : 0) || 1", true },
        { "0 && 1 / 0", false }, { "1 || 1 / 0", true }, { "0 ? 1 / 0 : 1", true },
        { "1 ? 1 : 1 % 0", true },
        { "UNDEFINED == 0", true }, { "UNDEFINED", false }, { "float", false },
        { "defined X", true }, { "defined(X)", true }, { "defined ( X )", true },
        { "defined Y", false }, { "!defined(Y) && defined X", true },
        { "TWO * TWO == 4", true }, { "SQ(TWO + 1) == 9", true }, { "X", true },
        { "9223372036854775807 + 1 < 0", true }, { "007 == 7", true },
        { "-9223372036854775807 - 1 == (-9223372036854775807 - 1) / -1", true },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        bool got = if_true(cases[i].expr,
                           "#define X 1\n#define TWO 2\n#define SQ(a) ((a) * (a))\n");
        if (got != cases[i].value)
            fail_msg("#if %s: got %d, expected %d", cases[i].expr, got, cases[i].value);
    }
}

static void test_if_elif_else_chains(void **state)
{
    (void)state;
    const char *src =
        "#ifdef A\n"
        "a\n"
        "#elif defined B\n"
        "b\n"
        "#elif C > 1\n"
        "c\n"
        "#else\n"
        "none\n"
        "#endif\n";
    char buf[512];
    snprintf(buf, sizeof buf, "#define A\n#define B\n%s", src);
    assert_string_equal(expand(buf), "a");
    reset();
    snprintf(buf, sizeof buf, "#define B\n%s", src);
    assert_string_equal(expand(buf), "b");
    reset();
    snprintf(buf, sizeof buf, "#define C 2\n%s", src);
    assert_string_equal(expand(buf), "c");
    reset();
    assert_string_equal(expand(src), "none");
    reset();
    assert_string_equal(expand("#ifndef A\nnot_a\n#endif\n#define A\n#ifndef A\nnever\n#endif\n"),
                        "not_a");
    assert_string_equal(diags(), "");
}

static void test_skipped_groups_are_silent(void **state)
{
    (void)state;
    assert_string_equal(expand("#if 0\n"
                               "#if 1 / 0\n"
                               "#foo bar\n"
                               "\"unterminated @ $ 1e+ \\q\n"
                               "#include \"missing.h\"\n"
                               "#error not reached\n"
                               "#else\n"
                               "x\n"
                               "#endif\n"
                               "#elif 1\n"
                               "y\n"
                               "#elif 1 / 0\n"
                               "z\n"
                               "#else\n"
                               "w\n"
                               "#endif\n"
                               "#if 1\n"
                               "v\n"
                               "#elif 1 / 0\n"
                               "#endif\n"),
                        "y v");
    assert_string_equal(diags(), "");
}

static void test_directive_layout(void **state)
{
    (void)state;
    /* spaces around '#', comments, splices and the null directive */
    assert_string_equal(expand("  #  define A 1\n"
                               "/* c */ # define B 2\n"
                               "#\n"
                               "#define C \\\n"
                               "  3 /* multi\n"
                               "  line */ + 4\n"
                               "x # define D 5\n"
                               "A B C\n"),
                        "x define D 5 1 2 3 + 4");
    /* the '#' after x is not a directive: "stray '#'" */
    assert_string_equal(diags(),
                        "main.sl:7:3: error: stray '#' in program\n"
                        "x # define D 5\n"
                        "  ^\n");
}

static void test_pragma_ignored(void **state)
{
    (void)state;
    assert_string_equal(expand("#pragma once\n#pragma anything (at all)\nx\n"), "x");
    assert_string_equal(diags(), "");
}

/* ---------------------------------------------------------------------- */
/* #include                                                                */
/* ---------------------------------------------------------------------- */

static void test_include_relative_and_search_path(void **state)
{
    (void)state;
    add("shaders/main.sl",
        "#include \"common.h\"\n"
        "#include \"lib.h\"\n"
        "#include <lib.h>\n"
        "main_tok\n");
    add("shaders/common.h", "shaders_common\n");
    add("inc/common.h", "inc_common\n");
    add("shaders/lib.h", "shaders_lib\n");
    add("inc/lib.h", "inc_lib\n");
    const char *const path[] = { "inc", NULL };
    assert_string_equal(run("shaders/main.sl", path, true),
                        "shaders_common@shaders/common.h:1:1 shaders_lib@shaders/lib.h:1:1 "
                        "inc_lib@inc/lib.h:1:1 main_tok@shaders/main.sl:4:1");
    assert_string_equal(diags(), "");
}

static void test_include_nested_relative(void **state)
{
    (void)state;
    /* each #include is relative to the file that contains it */
    add("main.sl", "#include \"a/x.h\"\nend");
    add("a/x.h", "#include \"y.h\"\n#include \"../top.h\"\n  x");
    add("a/y.h", "ay");
    add("y.h", "wrong");
    add("top.h", "top");
    assert_string_equal(run("main.sl", NULL, true),
                        "ay@a/y.h:1:1 top@top.h:1:1 x@a/x.h:3:3 end@2:1");
    assert_string_equal(diags(), "");
}

/* A classic Mac header (lone CR line ends) included from a CR-LF file:
 * each directive ends at its line, a #define continues over a backslash
 * before CR, and positions and the quoted source line stay right. */
static void test_include_cr_line_ends(void **state)
{
    (void)state;
    add("main.sl", "#include \"mac.h\"\r\n#define TWICE(x) \\\r\n    ((x) * 2)\r\n"
                   "TWICE(HALF) after\r\n");
    add("mac.h", "#ifndef MAC_H\r#define MAC_H\r#define HALF \\\r  0.5\r"
                 "float mac;\r#endif\r  $\r");
    assert_string_equal(run("main.sl", NULL, true),
                        "float@mac.h:5:1 mac@mac.h:5:7 ;@mac.h:5:10 (@4:1 (@4:1 0.5@4:7 "
                        ")@4:1 *@4:1 2@4:1 )@4:1 after@4:13");
    assert_string_equal(diags(), "mac.h:7:3: error: unexpected character '$'\n"
                                 "  $\n"
                                 "  ^\n");
}

static void test_include_guard(void **state)
{
    (void)state;
    add("guard.h", "#ifndef GUARD_H\n#define GUARD_H\nonce\n#endif\n");
    add("main.sl", "#include \"guard.h\"\n#include \"guard.h\"\n#include \"./guard.h\"\nx");
    assert_string_equal(run("main.sl", NULL, false), "once x");
    assert_string_equal(diags(), "");
}

static void test_include_macros_cross_files(void **state)
{
    (void)state;
    add("defs.h", "#define SCALE(x) ((x) * K)\n#define K 2\n");
    add("main.sl", "#include \"defs.h\"\nSCALE(3)");
    assert_string_equal(run("main.sl", NULL, true),
                        "(@2:1 (@2:1 3@2:7 )@2:1 *@2:1 2@2:1 )@2:1");
    assert_string_equal(diags(), "");
}

static void test_include_missing(void **state)
{
    (void)state;
    add("shaders/main.sl", "#include \"noise.h\"\n  #include <noise.h>\nx\n");
    const char *const path[] = { "lib", "/usr/share/sl", NULL };
    assert_string_equal(run("shaders/main.sl", path, false), "x");
    assert_string_equal(diags(),
                        "shaders/main.sl:1:10: error: cannot find include file 'noise.h' "
                        "(searched: shaders, lib, /usr/share/sl)\n"
                        "#include \"noise.h\"\n"
                        "         ^\n"
                        "shaders/main.sl:2:12: error: cannot find include file 'noise.h' "
                        "(searched: lib, /usr/share/sl)\n"
                        "  #include <noise.h>\n"
                        "           ^\n");
}

static void test_include_syntax_errors(void **state)
{
    (void)state;
    add("a.h", "a");
    assert_string_equal(expand("#include noise.h\n"
                               "#include\n"
                               "#include \"\"\n"
                               "#include <x.h\n"
                               "#include \"x.h\n"
                               "#include \"a.h\" extra\n"
                               "z\n"),
                        "a z");
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 1, 10, "'#include' expects \"FILENAME\" or <FILENAME>" },
        { SL_DIAG_ERROR, 2, 9, "'#include' expects \"FILENAME\" or <FILENAME>" },
        { SL_DIAG_ERROR, 3, 10, "empty filename in '#include'" },
        { SL_DIAG_ERROR, 4, 10, "missing terminating '>' character" },
        { SL_DIAG_ERROR, 5, 10, "missing terminating '\"' character" },
        { SL_DIAG_WARNING, 6, 16, "extra tokens at end of '#include' directive" },
    };
    check_diags(e, sizeof e / sizeof e[0]);
}

static void test_include_cycle(void **state)
{
    (void)state;
    add("main.sl", "#include \"a.h\"\nmain");
    add("a.h", "#include \"b.h\"\na");
    add("b.h", "b1\n#include \"a.h\"\nb2");
    assert_string_equal(run("main.sl", NULL, false), "b1 b2 a main");
    assert_string_equal(diags(),
                        "b.h:2:10: error: include cycle: a.h -> b.h -> a.h\n"
                        "#include \"a.h\"\n"
                        "         ^\n");

    reset();
    assert_string_equal(expand("#include \"main.sl\"\nx"), "x");
    assert_string_equal(diags(),
                        "main.sl:1:10: error: include cycle: main.sl -> main.sl\n"
                        "#include \"main.sl\"\n"
                        "         ^\n");
}

/* main.sl includes d0.h, d0.h includes d1.h, ... d(n-1).h includes nothing */
static void make_chain(int n)
{
    add("main.sl", "#include \"d0.h\"\nmain");
    for (int i = 0; i < n; i++) {
        char name[32], text[64];
        snprintf(name, sizeof name, "d%d.h", i);
        if (i + 1 < n)
            snprintf(text, sizeof text, "#include \"d%d.h\"\nt%d", i + 1, i);
        else
            snprintf(text, sizeof text, "t%d", i);
        add(name, text);
    }
}

static void test_include_depth_limit(void **state)
{
    (void)state;
    /* 64 nested levels are fine */
    make_chain(SL_PP_MAX_INCLUDE_DEPTH);
    run("main.sl", NULL, false);
    assert_true(strncmp(out, "t63 t62 ", 8) == 0);
    assert_string_equal(diags(), "");

    /* the 65th is refused, in the file that asks for it */
    reset();
    make_chain(SL_PP_MAX_INCLUDE_DEPTH + 5);
    run("main.sl", NULL, false);
    assert_true(strncmp(out, "t63 t62 ", 8) == 0);
    assert_non_null(strstr(out, " t0 main"));
    assert_string_equal(diags(),
                        "d63.h:1:10: error: #include nested too deeply (limit 64 levels)\n"
                        "#include \"d64.h\"\n"
                        "         ^\n");
}

static void test_include_conditionals_per_file(void **state)
{
    (void)state;
    /* an #if left open in a header is reported there and closed there; an
     * #endif in a header cannot close the includer's #if */
    add("open.h", "#if 1\ninside");
    add("end.h", "#endif");
    add("main.sl", "#include \"open.h\"\n#if 1\n#include \"end.h\"\nx\n#endif\nafter");
    assert_string_equal(run("main.sl", NULL, false), "inside x after");
    assert_string_equal(diags(),
                        "open.h:1:1: error: unterminated '#if'\n"
                        "#if 1\n"
                        "^\n"
                        "end.h:1:1: error: '#endif' without '#if'\n"
                        "#endif\n"
                        "^\n");
}

static int loader_calls;

static int table_loader(sl_source_set *s, const char *name, sl_diag *d, void *arg)
{
    (void)d;
    (void)arg;
    loader_calls++;
    if (strcmp(name, "lib/noise.h") == 0)
        return sl_source_set_add(s, name, "noise_tok", 9) == 0 ? 0 : -1;
    if (strcmp(name, "lib/broken.h") == 0) {
        sl_pos none = { NULL, 0, 0 };
        sl_diag_error(d, none, "cannot read 'lib/broken.h': Permission denied");
        return -1;
    }
    return 1;
}

static void test_include_loader(void **state)
{
    (void)state;
    /* the master loads headers on demand; afterwards the set holds exactly
     * what the worker will need */
    add("main.sl", "#include \"noise.h\"\n#include \"broken.h\"\nx");
    sl_source_set_set_loader(set, table_loader, NULL);
    const char *const path[] = { "lib", NULL };
    loader_calls = 0;
    assert_string_equal(run("main.sl", path, true), "noise_tok@lib/noise.h:1:1 x@3:1");
    assert_int_equal(loader_calls, 4);     /* noise.h lib/noise.h broken.h lib/broken.h */
    assert_int_equal(sl_source_set_count(set), 2);
    assert_string_equal(diags(),
                        "error: cannot read 'lib/broken.h': Permission denied\n"
                        "main.sl:2:10: error: cannot find include file 'broken.h' "
                        "(searched: ., lib)\n"
                        "#include \"broken.h\"\n"
                        "         ^\n");
}

/* ---------------------------------------------------------------------- */
/* errors                                                                  */
/* ---------------------------------------------------------------------- */

static void test_error_unterminated_if(void **state)
{
    (void)state;
    assert_string_equal(expand("#if 1\nx\n  #  ifdef Y\n#else\n"), "x");
    assert_string_equal(diags(),
                        "main.sl:1:1: error: unterminated '#if'\n"
                        "#if 1\n"
                        "^\n"
                        "main.sl:3:3: error: unterminated '#ifdef'\n"
                        "  #  ifdef Y\n"
                        "  ^\n");
}

static void test_error_stray_conditionals(void **state)
{
    (void)state;
    assert_string_equal(expand("#endif\n  #else\n#elif 1\nx\n"), "x");
    assert_string_equal(diags(),
                        "main.sl:1:1: error: '#endif' without '#if'\n"
                        "#endif\n"
                        "^\n"
                        "main.sl:2:3: error: '#else' without '#if'\n"
                        "  #else\n"
                        "  ^\n"
                        "main.sl:3:1: error: '#elif' without '#if'\n"
                        "#elif 1\n"
                        "^\n");
}

static void test_error_else_after_else(void **state)
{
    (void)state;
    assert_string_equal(expand("#if 0\na\n#else\nb\n#else\nc\n#elif 1\nd\n#endif\ne"), "b e");
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 5, 1, "'#else' after '#else'" },
        { SL_DIAG_ERROR, 7, 1, "'#elif' after '#else'" },
    };
    check_diags(e, 2);
}

static void test_error_bad_directive(void **state)
{
    (void)state;
    assert_string_equal(expand("#foo bar\n# 12\n#line 3\n#\nx"), "x");
    assert_string_equal(diags(),
                        "main.sl:1:2: error: invalid preprocessing directive '#foo'\n"
                        "#foo bar\n"
                        " ^\n"
                        "main.sl:2:3: error: invalid preprocessing directive '#12'\n"
                        "# 12\n"
                        "  ^\n"
                        "main.sl:3:2: error: invalid preprocessing directive '#line'\n"
                        "#line 3\n"
                        " ^\n");
}

static void test_error_and_warning_directives(void **state)
{
    (void)state;
    assert_string_equal(expand("#error shader \"x\"   needs /* c */ FOO\n"
                               "#warning careful\n"
                               "#error\n"
                               "x\n"),
                        "x");
    assert_string_equal(diags(),
                        "main.sl:1:1: error: #error shader \"x\" needs FOO\n"
                        "#error shader \"x\"   needs /* c */ FOO\n"
                        "^\n"
                        "main.sl:2:1: warning: #warning careful\n"
                        "#warning careful\n"
                        "^\n"
                        "main.sl:3:1: error: #error\n"
                        "#error\n"
                        "^\n");
    assert_int_equal(sl_diag_error_count(diag), 2);
    assert_int_equal(sl_diag_warning_count(diag), 1);
}

static void test_error_macro_argument_count(void **state)
{
    (void)state;
    assert_string_equal(expand("#define F(a, b) a + b\n"
                               "#define G() 1\n"
                               "#define H(x) [x]\n"
                               "F(1)\n"
                               "F(1, 2, 3)\n"
                               "G(1)\n"
                               "H() G()\n"
                               "H(1, 2)\n"
                               "ok\n"),
                        "[ ] 1 ok");
    assert_string_equal(diags(),
                        "main.sl:4:1: error: macro 'F' requires 2 arguments, but only 1 given\n"
                        "F(1)\n"
                        "^\n"
                        "main.sl:1:9: note: macro 'F' defined here\n"
                        "#define F(a, b) a + b\n"
                        "        ^\n"
                        "main.sl:5:1: error: macro 'F' passed 3 arguments, but takes just 2\n"
                        "F(1, 2, 3)\n"
                        "^\n"
                        "main.sl:1:9: note: macro 'F' defined here\n"
                        "#define F(a, b) a + b\n"
                        "        ^\n"
                        "main.sl:6:1: error: macro 'G' passed 1 argument, but takes just 0\n"
                        "G(1)\n"
                        "^\n"
                        "main.sl:2:9: note: macro 'G' defined here\n"
                        "#define G() 1\n"
                        "        ^\n"
                        "main.sl:8:1: error: macro 'H' passed 2 arguments, but takes just 1\n"
                        "H(1, 2)\n"
                        "^\n"
                        "main.sl:3:9: note: macro 'H' defined here\n"
                        "#define H(x) [x]\n"
                        "        ^\n");
}

static void test_error_unterminated_invocation(void **state)
{
    (void)state;
    assert_string_equal(expand("#define F(a) a\nx F(1, (2)\n"), "x");
    assert_string_equal(diags(),
                        "main.sl:2:3: error: unterminated argument list invoking macro 'F'\n"
                        "x F(1, (2)\n"
                        "  ^\n");

    /* an invocation cannot run past the end of an included file */
    reset();
    add("inc.h", "#define F(a) a\nF(1");
    assert_string_equal(expand("#include \"inc.h\"\n)"), ")");
    assert_string_equal(diags(),
                        "inc.h:2:1: error: unterminated argument list invoking macro 'F'\n"
                        "F(1\n"
                        "^\n");
}

static void test_error_if_expressions(void **state)
{
    (void)state;
    expand("#if\n#endif\n"
           "#if 1 +\n#endif\n"
           "#if (1\n#endif\n"
           "#if 1 / 0\n#endif\n"
           "#if defined\n#endif\n"
           "#if defined(X\n#endif\n"
           "#if 1.5\n#endif\n"
           "#if 1 2\n#endif\n"
           "#if \"s\"\n#endif\n"
           "#if 1 ? 2\n#endif\n"
           "#if 99999999999999999999\n#endif\n"
           "#if 1)\n#endif\n"
           "#if 2 = 1\n#endif\n"
           "#define EMPTY\n"
           "#if EMPTY\n#endif\n"
           "#if 1 % 0 || 1\n#endif\n"
           "#if 3 @\n#endif\n"
           "#if 12abc\n#endif\n");
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 1, 2, "'#if' with no expression" },
        { SL_DIAG_ERROR, 3, 8, "expected value in expression" },
        { SL_DIAG_ERROR, 5, 7, "missing ')' in expression" },
        { SL_DIAG_ERROR, 7, 7, "division by zero in #if" },
        { SL_DIAG_ERROR, 9, 12, "operator 'defined' requires an identifier" },
        { SL_DIAG_ERROR, 11, 14, "missing ')' after 'defined'" },
        { SL_DIAG_ERROR, 13, 5, "floating constant in preprocessor expression" },
        { SL_DIAG_ERROR, 15, 7, "missing binary operator before token '2'" },
        { SL_DIAG_ERROR, 17, 5, "token '\"s\"' is not valid in preprocessor expressions" },
        { SL_DIAG_ERROR, 19, 10, "'?' without following ':'" },
        { SL_DIAG_ERROR, 21, 5, "integer constant is too large" },
        { SL_DIAG_ERROR, 23, 6, "missing '(' in expression" },
        { SL_DIAG_ERROR, 25, 7, "missing binary operator before token '='" },
        { SL_DIAG_ERROR, 28, 2, "'#if' with no expression" },
        { SL_DIAG_ERROR, 30, 7, "division by zero in #if" },
        { SL_DIAG_ERROR, 32, 7, "missing binary operator before token '@'" },
        { SL_DIAG_ERROR, 34, 5, "malformed number '12abc'" },
    };
    check_diags(e, sizeof e / sizeof e[0]);
}

static void test_error_define_syntax(void **state)
{
    (void)state;
    assert_string_equal(expand("#define\n"
                               "#define 3 x\n"
                               "#define defined 1\n"
                               "#define F(a, a) a\n"
                               "#define G(a b) a\n"
                               "#define H(a, ...) a\n"
                               "#define I(a) # b\n"
                               "#define J ## x\n"
                               "#define K x ##\n"
                               "#define L(\n"
                               "#undef\n"
                               "#undef 3\n"
                               "#ifdef\n"
                               "#endif\n"
                               "#ifdef 4\n"
                               "#endif\n"
                               "#undef defined\n"
                               "F G H I J K L\n"),
                        "F G H I J K L");
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 1, 2, "no macro name given in '#define' directive" },
        { SL_DIAG_ERROR, 2, 9, "macro names must be identifiers" },
        { SL_DIAG_ERROR, 3, 9, "'defined' cannot be used as a macro name" },
        { SL_DIAG_ERROR, 4, 14, "duplicate macro parameter 'a'" },
        { SL_DIAG_ERROR, 5, 13, "expected ',' or ')' in macro parameter list" },
        { SL_DIAG_ERROR, 6, 14, "variadic macros are not supported" },
        { SL_DIAG_ERROR, 7, 14, "'#' is not followed by a macro parameter" },
        { SL_DIAG_ERROR, 8, 11, "'##' cannot appear at either end of a macro expansion" },
        { SL_DIAG_ERROR, 9, 13, "'##' cannot appear at either end of a macro expansion" },
        { SL_DIAG_ERROR, 10, 11, "expected parameter name in macro parameter list" },
        { SL_DIAG_ERROR, 11, 2, "no macro name given in '#undef' directive" },
        { SL_DIAG_ERROR, 12, 8, "macro names must be identifiers" },
        { SL_DIAG_ERROR, 13, 2, "no macro name given in '#ifdef' directive" },
        { SL_DIAG_ERROR, 15, 8, "macro names must be identifiers" },
        { SL_DIAG_ERROR, 17, 8, "'defined' cannot be used as a macro name" },
    };
    check_diags(e, sizeof e / sizeof e[0]);
}

static void test_warning_extra_tokens(void **state)
{
    (void)state;
    assert_string_equal(expand("#ifdef A B\n#else C\nx\n#endif D\n#undef A B\n"), "x");
    static const expect_diag e[] = {
        { SL_DIAG_WARNING, 1, 10, "extra tokens at end of '#ifdef' directive" },
        { SL_DIAG_WARNING, 2, 7, "extra tokens at end of '#else' directive" },
        { SL_DIAG_WARNING, 4, 8, "extra tokens at end of '#endif' directive" },
        { SL_DIAG_WARNING, 5, 10, "extra tokens at end of '#undef' directive" },
    };
    check_diags(e, sizeof e / sizeof e[0]);
    assert_int_equal(sl_diag_error_count(diag), 0);
}

static void test_error_bad_paste(void **state)
{
    (void)state;
    assert_string_equal(expand("#define cat(a, b) a ## b\n"
                               "#define str(x) #x ## _\n"
                               "  cat(+, -) cat(/, /) str(q)\n"),
                        "+ - / / \"q\" _");
    assert_string_equal(diags(),
                        "main.sl:3:3: error: pasting '+' and '-' does not give a valid "
                        "preprocessing token\n"
                        "  cat(+, -) cat(/, /) str(q)\n"
                        "  ^\n"
                        "main.sl:3:13: error: pasting '/' and '/' does not give a valid "
                        "preprocessing token\n"
                        "  cat(+, -) cat(/, /) str(q)\n"
                        "            ^\n"
                        "main.sl:3:23: error: pasting '\"q\"' and '_' does not give a valid "
                        "preprocessing token\n"
                        "  cat(+, -) cat(/, /) str(q)\n"
                        "                      ^\n");
}

static void test_error_unterminated_comment_in_skipped_group(void **state)
{
    (void)state;
    assert_string_equal(expand("x\n#if 0\n/* never closed\n"), "x");
    assert_string_equal(diags(),
                        "main.sl:3:1: error: unterminated /* comment\n"
                        "/* never closed\n"
                        "^\n"
                        "main.sl:2:1: error: unterminated '#if'\n"
                        "#if 0\n"
                        "^\n");
}

/* ---------------------------------------------------------------------- */
/* limits                                                                  */
/* ---------------------------------------------------------------------- */

static void test_limit_exponential_expansion(void **state)
{
    (void)state;
    /* a30 would expand to 2^31 tokens: stopped by the token budget */
    char src[4096];
    size_t o = (size_t)snprintf(src, sizeof src, "#define a0 x x\n");
    for (int i = 1; i <= 30; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, "#define a%d a%d a%d\n", i, i - 1, i - 1);
    snprintf(src + o, sizeof src - o, "y a30 z\n");
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    long n = 0;
    while (sl_lexer_next(lx, &t))
        n++;
    sl_lexer_destroy(&lx);
    assert_true(n > 1000 && n < SL_PP_MAX_TOKENS);
    assert_int_equal(sl_diag_count(diag), 1);
    const sl_diagnostic *d = sl_diag_get(diag, 0);
    assert_string_equal(d->message,
                        "too many tokens (more than 2097152 scanned or produced by macro "
                        "expansion): simplify the macros expanded here");
    assert_int_equal(d->line, 32);
    assert_int_equal(d->col, 3);
}

/* The bomb of issue 12: a chain of object-like macros, each expanding to
 * two of the next, 30 deep (2^30 tokens), used where the parser would
 * take every token. Each expansion is charged as it is built, so it stops
 * at the budget; the error names the use. */
static void test_limit_macro_bomb_chain(void **state)
{
    (void)state;
    char src[4096];
    size_t o = 0;
    for (int i = 0; i < 30; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, "#define M%d M%d M%d\n", i, i + 1, i + 1);
    o += (size_t)snprintf(src + o, sizeof src - o, "#define M30 +1\n");
    snprintf(src + o, sizeof src - o, "float x = 0 M0;\n");
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    long n = 0;
    while (sl_lexer_next(lx, &t))
        n++;
    sl_lexer_destroy(&lx);
    assert_true(n <= SL_PP_MAX_TOKENS);
    assert_int_equal(sl_diag_error_count(diag), 1);
    const sl_diagnostic *d = sl_diag_get(diag, 0);
    assert_non_null(strstr(d->message, "too many tokens"));
    assert_non_null(strstr(d->message, "simplify the macros"));
    assert_string_equal(d->file, "main.sl");
    assert_int_equal(d->line, 32);
    assert_int_equal(d->col, 13);
}

/* Pasting doubles a token's spelling at each level: 40 levels would make a
 * terabyte-long identifier out of a few tokens, so the byte budget, not the
 * token budget, stops it. */
static void test_limit_paste_bomb_bytes(void **state)
{
    (void)state;
    char src[1024];
    size_t o = (size_t)snprintf(src, sizeof src, "#define C(x) x ## x\n#define E(x) C(x)\nfloat ");
    for (int i = 0; i < 40; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, "E(");
    o += (size_t)snprintf(src + o, sizeof src - o, "a");
    for (int i = 0; i < 40; i++)
        o += (size_t)snprintf(src + o, sizeof src - o, ")");
    snprintf(src + o, sizeof src - o, " = 1;\n");
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    while (sl_lexer_next(lx, &t))
        assert_true(t.len <= 2 * (size_t)SL_PP_MAX_BYTES);
    sl_lexer_destroy(&lx);
    assert_int_equal(sl_diag_error_count(diag), 1);
    const sl_diagnostic *d = sl_diag_get(diag, 0);
    assert_string_equal(d->message,
                        "macro expansion too large (more than 67108864 bytes of preprocessor "
                        "storage): simplify the macros expanded here");
    assert_int_equal(d->line, 3);
}

static void test_limit_argument_nesting(void **state)
{
    (void)state;
    enum { DEPTH = 300 };
    static char src[64 + 3 * DEPTH];
    size_t o = (size_t)sprintf(src, "#define f(x) x\n");
    for (int i = 0; i < DEPTH; i++)
        o += (size_t)sprintf(src + o, "f(");
    o += (size_t)sprintf(src + o, "1");
    for (int i = 0; i < DEPTH; i++)
        o += (size_t)sprintf(src + o, ")");
    add("main.sl", src);
    run("main.sl", NULL, false);
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 2, 401, "macro invocations nested too deeply in arguments (limit 200)" },
    };
    check_diags(e, 1);

    /* 150 levels are fine */
    reset();
    o = (size_t)sprintf(src, "#define f(x) x\n");
    for (int i = 0; i < 150; i++)
        o += (size_t)sprintf(src + o, "f(");
    o += (size_t)sprintf(src + o, "1");
    for (int i = 0; i < 150; i++)
        o += (size_t)sprintf(src + o, ")");
    assert_string_equal(expand(src), "1");
    assert_string_equal(diags(), "");
}

static void test_limit_if_nesting(void **state)
{
    (void)state;
    static char src[1024];
    size_t o = (size_t)sprintf(src, "#if ");
    for (int i = 0; i < 300; i++)
        src[o++] = '(';
    src[o++] = '1';
    for (int i = 0; i < 300; i++)
        src[o++] = ')';
    strcpy(src + o, "\nx\n#endif\ny");
    assert_string_equal(expand(src), "y");
    static const expect_diag e[] = {
        { SL_DIAG_ERROR, 1, 133, "#if expression nested too deeply (more than 256 levels): simplify it" },
    };
    check_diags(e, 1);

    reset();
    o = (size_t)sprintf(src, "#if ");
    for (int i = 0; i < 100; i++)
        src[o++] = '(';
    src[o++] = '1';
    for (int i = 0; i < 100; i++)
        src[o++] = ')';
    strcpy(src + o, "\nx\n#endif\ny");
    assert_string_equal(expand(src), "x y");
}

static void test_long_macro_chain(void **state)
{
    (void)state;
    /* m0 -> m1 -> ... -> m1999 -> end: hide sets grow, all fine */
    enum { N = 2000 };
    static char src[N * 32];
    size_t o = 0;
    for (int i = 0; i < N; i++) {
        if (i + 1 < N)
            o += (size_t)sprintf(src + o, "#define m%d m%d\n", i, i + 1);
        else
            o += (size_t)sprintf(src + o, "#define m%d end\n", i);
    }
    strcpy(src + o, "m0 m1000");
    assert_string_equal(expand_pos(src), "end@2001:1 end@2001:4");
    assert_string_equal(diags(), "");
}

/* ---------------------------------------------------------------------- */
/* robustness                                                              */
/* ---------------------------------------------------------------------- */

static uint64_t rng = 0x5eed5eed12345678u;

static uint32_t rnd(void)
{
    rng ^= rng << 13;                    /* xorshift64 */
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 32);
}

static const char *const fragments[] = {
    "#", "##", "#define ", "#undef ", "#if ", "#ifdef ", "#ifndef ", "#elif ", "#else",
    "#endif", "#include \"noise.h\"", "#include <", "#error ", "#pragma ", "defined(",
    "/*", "*/", "//", "\"", "\\", "\\\n", "\n", "\r\n", "(", ")", ",", "1e", ".5",
    "F(", "G(x)", "AMP", "displacement", "float", "\t", "@", "\xc3\xa9", "\0", "?:",
    "<<", ">>", "&&", "||", "1/0", "0x", "9999999999999999999999",
};
enum { NFRAGMENTS = sizeof fragments / sizeof fragments[0] };

static const char valid_shader[] =
    "/* wave.sl: a displacement shader */\n"
    "#include \"noise.h\"\n"
    "#define AMP 0.1\n"
    "#define WAVE(u, f) (AMP * sin((u) * (f)))\n"
    "#if defined(AMP) && NOISE_OCTAVES > 1\n"
    "#define ROUGH 1\n"
    "#else\n"
    "#define ROUGH 0\n"
    "#endif\n"
    "displacement wave(float Km = 0.5, freq = 8; string space = \"shader\\n\";)\n"
    "{\n"
    "    float h = WAVE(s, freq) + ROUGH * fbm(P, NOISE_OCTAVES);\n"
    "    if (h >= 0 && h != 1e-3) {\n"
    "        P += Km * h * normalize(N);\n"
    "    } else\n"
    "        P -= .5 * N;\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char noise_header[] =
    "#ifndef NOISE_H\n"
    "#define NOISE_H\n"
    "#define NOISE_OCTAVES 4\n"
    "float fbm(point p; float n) { return noise(p) * n; }\n"
    "#endif\n";

/* Runs the lexer over main.sl and checks the invariants every run must
 * keep, whatever the input: it ends; only tokens of the language reach
 * the parser, each with a position; the error count agrees with the stored
 * error diagnostics (all of them up to the cap), so that success (no
 * errors) means no error diagnostics; the rendered text is empty exactly
 * when nothing was reported. */
static void lex_and_check(const char *text, size_t len)
{
    reset();
    assert_int_equal(sl_source_set_add(set, "main.sl", text, len), 0);
    add("noise.h", noise_header);
    const char *const path[] = { "lib", NULL };
    sl_lexer *lx = sl_lexer_new(set, "main.sl", path, diag);
    sl_token t;
    long n = 0;
    for (;;) {
        if ((rnd() & 7) == 0)
            (void)sl_lexer_peek(lx, (int)(rnd() % SL_LEXER_LOOKAHEAD));
        if (!sl_lexer_next(lx, &t))
            break;
        assert_true(t.kind > SL_TOK_EOF && t.kind <= SL_TOK_RBRACKET);
        assert_non_null(t.text);
        assert_non_null(t.pos.file);
        assert_true(t.pos.line >= 1 && t.pos.col >= 1);
        n++;
    }
    assert_int_equal(t.kind, SL_TOK_EOF);
    sl_lexer_destroy(&lx);
    assert_true(n < SL_PP_MAX_TOKENS);

    int errors = sl_diag_error_count(diag);
    int stored_errors = 0;
    for (size_t i = 0; i < sl_diag_count(diag); i++) {
        const sl_diagnostic *d = sl_diag_get(diag, i);
        assert_non_null(d->message);
        if (d->level == SL_DIAG_ERROR)
            stored_errors++;
    }
    int cap = SL_DIAG_DEFAULT_MAX_ERRORS;
    assert_int_equal(stored_errors, errors < cap ? errors : cap);
    char *s = sl_diag_to_string(diag);
    assert_int_equal(s[0] != '\0', sl_diag_count(diag) > 0);
    free(s);
}

static void test_fuzz_random_bytes(void **state)
{
    (void)state;
    static char buf[1024];
    for (int iter = 0; iter < 3000; iter++) {
        size_t len = 0, target = rnd() % 300;
        while (len < target) {
            uint32_t r = rnd() % 4;
            if (r == 0) {
                buf[len++] = (char)(rnd() & 0xff);
            } else if (r == 1) {
                const char *alpha = "abcxyzFGN_019eE.+-*/=<>!&|^~%?:;,()[]{}\"'\\# \t\n";
                buf[len++] = alpha[rnd() % strlen(alpha)];
            } else {
                size_t k = rnd() % NFRAGMENTS;
                const char *f = fragments[k];
                size_t fl = f[0] ? strlen(f) : 1;   /* "" stands for a NUL byte */
                if (len + fl > sizeof buf)
                    break;
                memcpy(buf + len, f, fl);
                len += fl;
            }
        }
        lex_and_check(buf, len);
    }
}

static void test_fuzz_mutated_shader(void **state)
{
    (void)state;
    /* the shader itself is clean */
    lex_and_check(valid_shader, sizeof valid_shader - 1);
    assert_int_equal(sl_diag_count(diag), 0);

    static char buf[4096];
    int failed = 0;
    for (int iter = 0; iter < 3000; iter++) {
        size_t len = sizeof valid_shader - 1;
        memcpy(buf, valid_shader, len);
        int mutations = 1 + (int)(rnd() % 4);
        for (int m = 0; m < mutations; m++) {
            size_t at = rnd() % (len + 1);
            switch (rnd() % 5) {
            case 0: {                                 /* delete a range */
                size_t n = rnd() % 16;
                if (at + n > len)
                    n = len - at;
                memmove(buf + at, buf + at + n, len - at - n);
                len -= n;
                break;
            }
            case 1: {                                 /* insert a fragment */
                const char *f = fragments[rnd() % NFRAGMENTS];
                size_t n = f[0] ? strlen(f) : 1;
                if (len + n > sizeof buf)
                    break;
                memmove(buf + at + n, buf + at, len - at);
                memcpy(buf + at, f, n);
                len += n;
                break;
            }
            case 2:                                   /* replace a byte */
                if (at < len)
                    buf[at] = (char)(rnd() & 0xff);
                break;
            case 3: {                                 /* duplicate a range */
                size_t n = rnd() % 64;
                if (at + n > len)
                    n = len - at;
                if (len + n > sizeof buf)
                    break;
                memmove(buf + at + n, buf + at, len - at);
                len += n;
                break;
            }
            default:                                  /* swap two bytes */
                if (len > 1) {
                    size_t b = rnd() % len;
                    if (at >= len)
                        at = len - 1;
                    char c = buf[at];
                    buf[at] = buf[b];
                    buf[b] = c;
                }
                break;
            }
        }
        lex_and_check(buf, len);
        failed += sl_diag_error_count(diag) > 0;
    }
    /* the mutations do break the shader, and not always */
    assert_true(failed > 300 && failed < 2900);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_object_like, setup, teardown),
        cmocka_unit_test_setup_teardown(test_note_macro, setup, teardown),
        cmocka_unit_test_setup_teardown(test_function_like_positions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_invocation_across_lines, setup, teardown),
        cmocka_unit_test_setup_teardown(test_nested_and_rescanning, setup, teardown),
        cmocka_unit_test_setup_teardown(test_nested_positions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_self_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(test_c_standard_example, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stringize_and_paste, setup, teardown),
        cmocka_unit_test_setup_teardown(test_paste_then_expand, setup, teardown),
        cmocka_unit_test_setup_teardown(test_arguments_with_parens_and_commas, setup, teardown),
        cmocka_unit_test_setup_teardown(test_name_without_parens, setup, teardown),
        cmocka_unit_test_setup_teardown(test_undef_and_redefine, setup, teardown),
        cmocka_unit_test_setup_teardown(test_redefinition_warning, setup, teardown),
        cmocka_unit_test_setup_teardown(test_predefined_macros, setup, teardown),
        cmocka_unit_test_setup_teardown(test_if_arithmetic, setup, teardown),
        cmocka_unit_test_setup_teardown(test_if_elif_else_chains, setup, teardown),
        cmocka_unit_test_setup_teardown(test_skipped_groups_are_silent, setup, teardown),
        cmocka_unit_test_setup_teardown(test_directive_layout, setup, teardown),
        cmocka_unit_test_setup_teardown(test_pragma_ignored, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_relative_and_search_path, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_nested_relative, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_cr_line_ends, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_guard, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_macros_cross_files, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_missing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_syntax_errors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_cycle, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_depth_limit, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_conditionals_per_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_include_loader, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_if, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_stray_conditionals, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_else_after_else, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_bad_directive, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_and_warning_directives, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_macro_argument_count, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_invocation, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_if_expressions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_define_syntax, setup, teardown),
        cmocka_unit_test_setup_teardown(test_warning_extra_tokens, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_bad_paste, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_comment_in_skipped_group,
                                        setup, teardown),
        cmocka_unit_test_setup_teardown(test_limit_exponential_expansion, setup, teardown),
        cmocka_unit_test_setup_teardown(test_limit_macro_bomb_chain, setup, teardown),
        cmocka_unit_test_setup_teardown(test_limit_paste_bomb_bytes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_limit_argument_nesting, setup, teardown),
        cmocka_unit_test_setup_teardown(test_limit_if_nesting, setup, teardown),
        cmocka_unit_test_setup_teardown(test_long_macro_chain, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fuzz_random_bytes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fuzz_mutated_shader, setup, teardown),
    };
    return cmocka_run_group_tests_name("sl_preproc", tests, NULL, NULL);
}
