/*
 * tests/sl/test_sl_lexer.c: the lexical layer of the shading language:
 * common/sl/diag.c, common/sl/source.c and common/sl/lexer.c.
 *
 *   tokens        every keyword and operator, maximal munch, numbers (kinds
 *                 and values), strings (escapes), identifiers (interned)
 *   positions     1-based line:col in bytes, tabs, CR-LF, line splices,
 *                 comments, the position of EOF
 *   lookahead     sl_lexer_peek up to SL_LEXER_LOOKAHEAD, then next
 *   errors        unexpected characters, unterminated strings and comments,
 *                 unknown escapes, malformed numbers, '#'/'%' outside the
 *                 preprocessor: exact message, line:col and caret line
 *   diagnostics   the printed format (source line, caret under tabs and
 *                 UTF-8), notes, the error cap, FILE and string output agree
 *   source set    name normalization, add/find/replace rules, size limit,
 *                 line lookup, loading from disk, the loader callback
 *
 * Expected strings are written out in full: a diagnostic test compares the
 * whole rendered text, caret line included.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sl/diag.h"
#include "sl/lexer.h"
#include "sl/source.h"

/* ---------------------------------------------------------------------- */
/* helpers                                                                 */
/* ---------------------------------------------------------------------- */

static sl_source_set *set;
static sl_diag *diag;
static char out[1 << 16];
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
    assert_null(diag);
    assert_null(set);
    return 0;
}

static void add(const char *name, const char *text)
{
    assert_int_equal(sl_source_set_add(set, name, text, strlen(text)), 0);
}

/* Lexes main.sl = text; returns the tokens as "spelling@line:col" joined by
 * spaces (strings in double quotes, their decoded value inside). */
static const char *lex(const char *text)
{
    add("main.sl", text);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    size_t o = 0;
    out[0] = '\0';
    sl_token t;
    while (sl_lexer_next(lx, &t)) {
        const char *q = t.kind == SL_TOK_STRING ? "\"" : "";
        o += (size_t)snprintf(out + o, sizeof out - o, "%s%s%s%s@%d:%d", o ? " " : "",
                              q, t.text, q, t.pos.line, t.pos.col);
    }
    assert_int_equal(t.kind, SL_TOK_EOF);
    sl_lexer_destroy(&lx);
    assert_null(lx);
    return out;
}

static const char *diags(void)
{
    char *s = sl_diag_to_string(diag);
    snprintf(diag_text, sizeof diag_text, "%s", s);
    free(s);
    return diag_text;
}

/* ---------------------------------------------------------------------- */
/* tokens                                                                  */
/* ---------------------------------------------------------------------- */

static void test_keywords(void **state)
{
    (void)state;
    static const char *const words[] = {
        "float", "point", "vector", "normal", "color", "string", "matrix", "void",
        "uniform", "varying", "output", "extern", "if", "else", "for", "while",
        "break", "continue", "return", "surface", "displacement", "light",
        "volume", "imager", "illuminate", "illuminance", "solar",
    };
    enum { N = sizeof words / sizeof words[0] };
    assert_int_equal(N, SL_KW_SOLAR - SL_KW_FLOAT + 1);
    char src[1024] = "";
    for (int i = 0; i < N; i++) {
        strcat(src, words[i]);
        strcat(src, "\n");
    }
    strcat(src, "Float floats _if if_ texture P");
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    for (int i = 0; i < N; i++) {
        assert_true(sl_lexer_next(lx, &t));
        assert_int_equal(t.kind, SL_KW_FLOAT + i);
        assert_string_equal(t.text, words[i]);
        assert_int_equal(t.len, strlen(words[i]));
        assert_int_equal(t.pos.line, i + 1);
        assert_int_equal(t.pos.col, 1);
        assert_string_equal(t.pos.file, "main.sl");
        assert_null(t.macro);
    }
    static const char *const idents[] = { "Float", "floats", "_if", "if_", "texture", "P" };
    for (int i = 0; i < 6; i++) {
        assert_true(sl_lexer_next(lx, &t));
        assert_int_equal(t.kind, SL_TOK_IDENT);
        assert_string_equal(t.text, idents[i]);
    }
    assert_false(sl_lexer_next(lx, &t));
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");
}

static void test_operators(void **state)
{
    (void)state;
    static const struct { const char *text; sl_token_kind kind; } ops[] = {
        { "+", SL_TOK_PLUS }, { "-", SL_TOK_MINUS }, { "*", SL_TOK_STAR },
        { "/", SL_TOK_SLASH }, { "=", SL_TOK_ASSIGN }, { "+=", SL_TOK_PLUS_ASSIGN },
        { "-=", SL_TOK_MINUS_ASSIGN }, { "*=", SL_TOK_STAR_ASSIGN },
        { "/=", SL_TOK_SLASH_ASSIGN }, { "==", SL_TOK_EQ }, { "!=", SL_TOK_NE },
        { "<", SL_TOK_LT }, { ">", SL_TOK_GT }, { "<=", SL_TOK_LE }, { ">=", SL_TOK_GE },
        { "&&", SL_TOK_AND }, { "||", SL_TOK_OR }, { "!", SL_TOK_NOT },
        { "?", SL_TOK_QUESTION }, { ":", SL_TOK_COLON }, { ";", SL_TOK_SEMICOLON },
        { ",", SL_TOK_COMMA }, { ".", SL_TOK_DOT }, { "^", SL_TOK_CARET },
        { "(", SL_TOK_LPAREN }, { ")", SL_TOK_RPAREN }, { "{", SL_TOK_LBRACE },
        { "}", SL_TOK_RBRACE }, { "[", SL_TOK_LBRACKET }, { "]", SL_TOK_RBRACKET },
    };
    enum { N = sizeof ops / sizeof ops[0] };
    char src[256] = "";
    for (int i = 0; i < N; i++) {
        strcat(src, ops[i].text);
        strcat(src, " ");
    }
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    int col = 1;
    for (int i = 0; i < N; i++) {
        assert_true(sl_lexer_next(lx, &t));
        assert_int_equal(t.kind, ops[i].kind);
        assert_string_equal(t.text, ops[i].text);
        assert_int_equal(t.pos.line, 1);
        assert_int_equal(t.pos.col, col);
        assert_string_equal(sl_token_kind_spelling(t.kind), ops[i].text);
        col += (int)strlen(ops[i].text) + 1;
    }
    assert_false(sl_lexer_next(lx, &t));
    assert_int_equal(t.pos.col, col);
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");
}

static void test_maximal_munch(void **state)
{
    (void)state;
    assert_string_equal(lex("a+=b==c!==d<=>e&&!f||g-=-h"),
                        "a@1:1 +=@1:2 b@1:4 ==@1:5 c@1:7 !=@1:8 =@1:10 d@1:11 <=@1:12 "
                        ">@1:14 e@1:15 &&@1:16 !@1:18 f@1:19 ||@1:20 g@1:22 -=@1:23 "
                        "-@1:25 h@1:26");
    assert_string_equal(diags(), "");
}

static void test_dot_and_numbers(void **state)
{
    (void)state;
    /* '.' is the dot operator unless a digit follows */
    assert_string_equal(lex("N.I a . .5 x.y"),
                        "N@1:1 .@1:2 I@1:3 a@1:5 .@1:7 .5@1:9 x@1:12 .@1:13 y@1:14");
    assert_string_equal(diags(), "");
}

static void test_numbers(void **state)
{
    (void)state;
    static const struct { const char *text; sl_token_kind kind; double value; } nums[] = {
        { "0", SL_TOK_INT, 0 },           { "42", SL_TOK_INT, 42 },
        { "007", SL_TOK_INT, 7 },         { "1.5", SL_TOK_FLOAT, 1.5 },
        { ".5", SL_TOK_FLOAT, 0.5 },      { "5.", SL_TOK_FLOAT, 5 },
        { "1e-3", SL_TOK_FLOAT, 1e-3 },   { "2.5E+4", SL_TOK_FLOAT, 2.5e4 },
        { "1e10", SL_TOK_FLOAT, 1e10 },   { "3.25e2", SL_TOK_FLOAT, 325 },
        { "0.1", SL_TOK_FLOAT, 0.1 },     { "123456789012", SL_TOK_INT, 123456789012.0 },
    };
    enum { N = sizeof nums / sizeof nums[0] };
    char src[256] = "";
    for (int i = 0; i < N; i++) {
        strcat(src, nums[i].text);
        strcat(src, "\n");
    }
    add("main.sl", src);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    for (int i = 0; i < N; i++) {
        assert_true(sl_lexer_next(lx, &t));
        assert_int_equal(t.kind, nums[i].kind);
        assert_string_equal(t.text, nums[i].text);
        assert_true(t.number == nums[i].value);
        assert_int_equal(t.pos.line, i + 1);
    }
    assert_false(sl_lexer_next(lx, &t));
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");

    assert_int_equal(sl_number_kind("1", 1), SL_TOK_INT);
    assert_int_equal(sl_number_kind("1.", 2), SL_TOK_FLOAT);
    assert_int_equal(sl_number_kind(".", 1), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("1e", 2), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("1e+", 3), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("1.2.3", 5), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("12abc", 5), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("0x10", 4), SL_TOK_EOF);
    assert_int_equal(sl_number_kind("1.5f", 4), SL_TOK_EOF);
}

static void test_strings(void **state)
{
    (void)state;
    add("main.sl", "\"plain\" \"a\\nb\\tc\\\"d\\\\e\" \"\" \"x\\'y\\r\"");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_STRING);
    assert_string_equal(t.text, "plain");
    assert_int_equal(t.len, 5);
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_STRING);
    assert_string_equal(t.text, "a\nb\tc\"d\\e");
    assert_int_equal(t.len, 9);
    assert_int_equal(t.pos.col, 9);
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "");
    assert_int_equal(t.len, 0);
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "x'y\r");
    assert_false(sl_lexer_next(lx, &t));
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "");
}

static void test_interned_identifiers(void **state)
{
    (void)state;
    add("main.sl", "alpha beta alpha");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token a, b, c;
    assert_true(sl_lexer_next(lx, &a));
    assert_true(sl_lexer_next(lx, &b));
    assert_true(sl_lexer_next(lx, &c));
    assert_ptr_equal(a.text, c.text);
    assert_ptr_not_equal(a.text, b.text);
    assert_ptr_equal(sl_lexer_intern(lx, "alpha", 5), a.text);
    assert_ptr_equal(sl_lexer_intern(lx, "betamax", 4), b.text);
    sl_lexer_destroy(&lx);
}

static void test_kind_names(void **state)
{
    (void)state;
    assert_string_equal(sl_token_kind_name(SL_TOK_SEMICOLON), "';'");
    assert_string_equal(sl_token_kind_name(SL_TOK_PLUS_ASSIGN), "'+='");
    assert_string_equal(sl_token_kind_name(SL_KW_ELSE), "'else'");
    assert_string_equal(sl_token_kind_name(SL_TOK_IDENT), "identifier");
    assert_string_equal(sl_token_kind_name(SL_TOK_INT), "number");
    assert_string_equal(sl_token_kind_name(SL_TOK_FLOAT), "number");
    assert_string_equal(sl_token_kind_name(SL_TOK_STRING), "string");
    assert_string_equal(sl_token_kind_name(SL_TOK_EOF), "end of file");
    assert_null(sl_token_kind_spelling(SL_TOK_IDENT));
    assert_string_equal(sl_token_kind_spelling(SL_KW_ILLUMINANCE), "illuminance");
}

/* ---------------------------------------------------------------------- */
/* positions                                                               */
/* ---------------------------------------------------------------------- */

static void test_positions_tabs_and_lines(void **state)
{
    (void)state;
    /* columns count bytes; a tab is one column */
    assert_string_equal(lex("a\n\tb  c\n\n  \t d"),
                        "a@1:1 b@2:2 c@2:5 d@4:5");
}

static void test_positions_crlf(void **state)
{
    (void)state;
    assert_string_equal(lex("x = 1;\r\ny\r\n  z"),
                        "x@1:1 =@1:3 1@1:5 ;@1:6 y@2:1 z@3:3");
}

/* classic Mac files end lines in a lone CR; a file may mix all three */
static void test_positions_cr(void **state)
{
    (void)state;
    assert_string_equal(lex("x = 1;\ry\r  z"),
                        "x@1:1 =@1:3 1@1:5 ;@1:6 y@2:1 z@3:3");
    teardown(NULL);
    setup(NULL);
    assert_string_equal(lex("a\rb\r\nc\nd\r\re // f\rg"),
                        "a@1:1 b@2:1 c@3:1 d@4:1 e@6:1 g@7:1");
    teardown(NULL);
    setup(NULL);
    /* a splice before a lone CR, and a comment ended by one */
    assert_string_equal(lex("ab\\\rcd ef\\\r\ngh /* x\r */ i"),
                        "abcd@1:1 efgh@2:4 i@4:5");
}

static void test_positions_line_splices(void **state)
{
    (void)state;
    /* a backslash-newline joins lines anywhere, even inside a token; the
     * next token's position is still where it was written */
    assert_string_equal(lex("abc\\\ndef gh\\\r\ni j\\\n k"),
                        "abcdef@1:1 ghi@2:5 j@3:3 k@4:2");
}

static void test_comments(void **state)
{
    (void)state;
    assert_string_equal(lex("a // one /* two\n"
                            "b /* three\n"
                            "   four */ c /**/d/ /e\n"
                            "// last, no newline"),
                        "a@1:1 b@2:1 c@3:12 d@3:18 /@3:19 /@3:21 e@3:22");
}

static void test_eof_position(void **state)
{
    (void)state;
    add("main.sl", "x\ny;\n");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    while (sl_lexer_next(lx, &t))
        ;
    assert_int_equal(t.kind, SL_TOK_EOF);
    assert_string_equal(t.text, "");
    assert_string_equal(t.pos.file, "main.sl");
    assert_int_equal(t.pos.line, 3);
    assert_int_equal(t.pos.col, 1);
    /* EOF repeats */
    assert_false(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_EOF);
    assert_int_equal(sl_lexer_peek(lx, 2)->kind, SL_TOK_EOF);
    sl_lexer_destroy(&lx);
}

static void test_empty_source(void **state)
{
    (void)state;
    assert_string_equal(lex(""), "");
    assert_string_equal(diags(), "");
}

/* ---------------------------------------------------------------------- */
/* lookahead                                                               */
/* ---------------------------------------------------------------------- */

static void test_peek(void **state)
{
    (void)state;
    add("main.sl", "a b c d e f");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    assert_string_equal(sl_lexer_peek(lx, 1)->text, "b");
    assert_string_equal(sl_lexer_peek(lx, 0)->text, "a");
    assert_string_equal(sl_lexer_peek(lx, 3)->text, "d");
    sl_token t;
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "a");
    assert_string_equal(sl_lexer_peek(lx, 3)->text, "e");
    const char *expect[] = { "b", "c", "d", "e", "f" };
    for (int i = 0; i < 5; i++) {
        assert_string_equal(sl_lexer_peek(lx, 0)->text, expect[i]);
        assert_true(sl_lexer_next(lx, &t));
        assert_string_equal(t.text, expect[i]);
        assert_int_equal(t.pos.col, 3 + 2 * i);
    }
    assert_int_equal(sl_lexer_peek(lx, 0)->kind, SL_TOK_EOF);
    assert_int_equal(sl_lexer_peek(lx, 1)->kind, SL_TOK_EOF);
    assert_false(sl_lexer_next(lx, &t));
    sl_lexer_destroy(&lx);
}

/* ---------------------------------------------------------------------- */
/* lexical errors                                                          */
/* ---------------------------------------------------------------------- */

static void test_error_unexpected_character(void **state)
{
    (void)state;
    assert_string_equal(lex("float x = 1 @ 2;\n\tP $ 3;\ny = \"\xc3\xa9\" \xc3\xa9;"),
                        "float@1:1 x@1:7 =@1:9 1@1:11 2@1:15 ;@1:16 P@2:2 3@2:6 ;@2:7 "
                        "y@3:1 =@3:3 \"\xc3\xa9\"@3:5 ;@3:12");
    assert_string_equal(diags(),
                        "main.sl:1:13: error: unexpected character '@'\n"
                        "float x = 1 @ 2;\n"
                        "            ^\n"
                        "main.sl:2:4: error: unexpected character '$'\n"
                        "\tP $ 3;\n"
                        "\t  ^\n"
                        "main.sl:3:10: error: unexpected character '\\xc3\\xa9'\n"
                        "y = \"\xc3\xa9\" \xc3\xa9;\n"
                        "        ^\n");
    assert_int_equal(sl_diag_error_count(diag), 3);
}

static void test_error_control_and_nul_bytes(void **state)
{
    (void)state;
    static const char src[] = "a\x01" "b\0c";
    assert_int_equal(sl_source_set_add(set, "main.sl", src, sizeof src - 1), 0);
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "a");
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "b");
    assert_int_equal(t.pos.col, 3);
    assert_true(sl_lexer_next(lx, &t));
    assert_string_equal(t.text, "c");
    assert_int_equal(t.pos.col, 5);
    assert_false(sl_lexer_next(lx, &t));
    sl_lexer_destroy(&lx);
    const sl_diagnostic *d = sl_diag_get(diag, 0);
    assert_string_equal(d->message, "unexpected character '\\x01'");
    assert_int_equal(d->col, 2);
    d = sl_diag_get(diag, 1);
    assert_string_equal(d->message, "unexpected character '\\x00'");
    assert_int_equal(d->col, 4);
    assert_int_equal(sl_diag_count(diag), 2);
}

static void test_error_unterminated_string(void **state)
{
    (void)state;
    assert_string_equal(lex("string s = \"abc;\nx = \"ok\";"),
                        "string@1:1 s@1:8 =@1:10 \"abc;\"@1:12 x@2:1 =@2:3 \"ok\"@2:5 ;@2:9");
    assert_string_equal(diags(),
                        "main.sl:1:12: error: missing terminating '\"' character\n"
                        "string s = \"abc;\n"
                        "           ^\n");
}

static void test_error_unterminated_string_at_eof(void **state)
{
    (void)state;
    assert_string_equal(lex("\t\"abc\\"), "\"abc\\\"@1:2");
    assert_string_equal(diags(),
                        "main.sl:1:2: error: missing terminating '\"' character\n"
                        "\t\"abc\\\n"
                        "\t^\n");
}

static void test_error_unknown_escape(void **state)
{
    (void)state;
    assert_string_equal(lex("s = \"a\\qb\\n\";"), "s@1:1 =@1:3 \"aqb\n\"@1:5 ;@1:13");
    assert_string_equal(diags(),
                        "main.sl:1:7: error: unknown escape sequence '\\q'\n"
                        "s = \"a\\qb\\n\";\n"
                        "      ^\n");
}

static void test_error_unterminated_comment(void **state)
{
    (void)state;
    assert_string_equal(lex("a;\n  /* never\nclosed"), "a@1:1 ;@1:2");
    assert_string_equal(diags(),
                        "main.sl:2:3: error: unterminated /* comment\n"
                        "  /* never\n"
                        "  ^\n");
}

static void test_error_malformed_numbers(void **state)
{
    (void)state;
    assert_string_equal(lex("x = 1e + 1.2.3 + 12abc + 1e+;\ny = 1e999;"),
                        "x@1:1 =@1:3 1e@1:5 +@1:8 1.2.3@1:10 +@1:16 12abc@1:18 +@1:24 "
                        "1e+@1:26 ;@1:29 y@2:1 =@2:3 1e999@2:5 ;@2:10");
    assert_string_equal(diags(),
                        "main.sl:1:5: error: malformed number '1e'\n"
                        "x = 1e + 1.2.3 + 12abc + 1e+;\n"
                        "    ^\n"
                        "main.sl:1:10: error: malformed number '1.2.3'\n"
                        "x = 1e + 1.2.3 + 12abc + 1e+;\n"
                        "         ^\n"
                        "main.sl:1:18: error: malformed number '12abc'\n"
                        "x = 1e + 1.2.3 + 12abc + 1e+;\n"
                        "                 ^\n"
                        "main.sl:1:26: error: malformed number '1e+'\n"
                        "x = 1e + 1.2.3 + 12abc + 1e+;\n"
                        "                         ^\n"
                        "main.sl:2:5: error: number '1e999' is too large\n"
                        "y = 1e999;\n"
                        "    ^\n");
}

static void test_error_malformed_number_value(void **state)
{
    (void)state;
    /* a malformed number still reaches the parser, as a float 0 */
    add("main.sl", "1.2.3");
    sl_lexer *lx = sl_lexer_new(set, "main.sl", NULL, diag);
    sl_token t;
    assert_true(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_FLOAT);
    assert_true(t.number == 0);
    sl_lexer_destroy(&lx);
    assert_int_equal(sl_diag_error_count(diag), 1);
}

static void test_error_preprocessor_only_tokens(void **state)
{
    (void)state;
    assert_string_equal(lex("a % b & c | d ~e << f >> g; x # y ## z"),
                        "a@1:1 b@1:5 c@1:9 d@1:13 e@1:16 f@1:21 g@1:26 ;@1:27 x@1:29 "
                        "y@1:33 z@1:38");
    const char *expect[] = {
        "operator '%' is not part of the shading language",
        "operator '&' is not part of the shading language",
        "operator '|' is not part of the shading language",
        "operator '~' is not part of the shading language",
        "operator '<<' is not part of the shading language",
        "operator '>>' is not part of the shading language",
        "stray '#' in program",
        "stray '##' in program",
    };
    const int cols[] = { 3, 7, 11, 15, 18, 23, 31, 35 };
    assert_int_equal(sl_diag_count(diag), 8);
    for (int i = 0; i < 8; i++) {
        const sl_diagnostic *d = sl_diag_get(diag, (size_t)i);
        assert_int_equal(d->level, SL_DIAG_ERROR);
        assert_string_equal(d->message, expect[i]);
        assert_int_equal(d->line, 1);
        assert_int_equal(d->col, cols[i]);
    }
}

static void test_error_missing_main_file(void **state)
{
    (void)state;
    sl_lexer *lx = sl_lexer_new(set, "nowhere.sl", NULL, diag);
    sl_token t;
    assert_false(sl_lexer_next(lx, &t));
    assert_int_equal(t.kind, SL_TOK_EOF);
    sl_lexer_destroy(&lx);
    assert_string_equal(diags(), "error: cannot find source 'nowhere.sl'\n");
}

/* ---------------------------------------------------------------------- */
/* the diagnostics object                                                  */
/* ---------------------------------------------------------------------- */

static void test_diag_format(void **state)
{
    (void)state;
    add("wave.sl", "surface wave()\n{\n\t\tx = 1\n    y\xc3\xa9 = 2;\n}\n");
    sl_diag_set_sources(diag, set);
    sl_pos p1 = { "wave.sl", 3, 6 };
    sl_diag_error(diag, p1, "expected ';' after expression");
    sl_pos p2 = { "wave.sl", 4, 8 };
    sl_diag_warning(diag, p2, "'%s' is never used", "y\xc3\xa9");
    sl_pos p3 = { "wave.sl", 1, 9 };
    sl_diag_note(diag, p3, "in shader '%s'", "wave");
    sl_pos p4 = { "other.sl", 7, 2 };   /* not in the set: no source line */
    sl_diag_error(diag, p4, "unknown");
    sl_pos p5 = { NULL, 0, 0 };
    sl_diag_error(diag, p5, "no position");
    sl_pos p6 = { "wave.sl", 0, 0 };
    sl_diag_warning(diag, p6, "whole file");
    sl_pos p7 = { "wave.sl", 99, 1 };   /* no such line */
    sl_diag_error(diag, p7, "past the end");
    const char *expect =
        "wave.sl:3:6: error: expected ';' after expression\n"
        "\t\tx = 1\n"
        "\t\t   ^\n"
        "wave.sl:4:8: warning: 'y\xc3\xa9' is never used\n"
        "    y\xc3\xa9 = 2;\n"
        "      ^\n"
        "wave.sl:1:9: note: in shader 'wave'\n"
        "surface wave()\n"
        "        ^\n"
        "other.sl:7:2: error: unknown\n"
        "error: no position\n"
        "wave.sl: warning: whole file\n"
        "wave.sl:99:1: error: past the end\n";
    assert_string_equal(diags(), expect);
    assert_int_equal(sl_diag_error_count(diag), 4);
    assert_int_equal(sl_diag_warning_count(diag), 2);
    assert_int_equal(sl_diag_count(diag), 7);
    assert_false(sl_diag_full(diag));

    /* printing to a FILE gives the same bytes */
    FILE *f = tmpfile();
    assert_non_null(f);
    sl_diag_print(diag, f);
    rewind(f);
    char buf[2048];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    assert_string_equal(buf, expect);

    /* the copies outlive the sources */
    sl_diag_set_sources(diag, NULL);
    sl_source_set_destroy(&set);
    set = sl_source_set_new();
    assert_string_equal(diags(), expect);

    sl_diag_clear(diag);
    assert_string_equal(diags(), "");
    assert_int_equal(sl_diag_error_count(diag), 0);
    assert_int_equal(sl_diag_count(diag), 0);
}

static void test_diag_caret_at_end_of_line(void **state)
{
    (void)state;
    add("a.sl", "x = 1\n");
    sl_diag_set_sources(diag, set);
    sl_pos p = { "a.sl", 1, 6 };
    sl_diag_error(diag, p, "expected ';'");
    sl_pos q = { "a.sl", 1, 9 };          /* beyond the line: no caret */
    sl_diag_error(diag, q, "far");
    assert_string_equal(diags(),
                        "a.sl:1:6: error: expected ';'\n"
                        "x = 1\n"
                        "     ^\n"
                        "a.sl:1:9: error: far\n");
}

static void test_diag_error_cap(void **state)
{
    (void)state;
    sl_diag_set_max_errors(diag, 3);
    sl_pos p = { "f.sl", 1, 1 };
    sl_diag_error(diag, p, "e%d", 1);
    sl_diag_note(diag, p, "n1");
    sl_diag_error(diag, p, "e%d", 2);
    assert_false(sl_diag_full(diag));
    sl_diag_error(diag, p, "e%d", 3);
    assert_true(sl_diag_full(diag));
    sl_diag_note(diag, p, "n3");          /* belongs to the error at the cap */
    sl_diag_error(diag, p, "e%d", 4);
    sl_diag_note(diag, p, "n4");
    sl_diag_warning(diag, p, "w");
    assert_string_equal(diags(),
                        "f.sl:1:1: error: e1\n"
                        "f.sl:1:1: note: n1\n"
                        "f.sl:1:1: error: e2\n"
                        "f.sl:1:1: error: e3\n"
                        "note: too many errors emitted, stopping now (limit 3)\n");
    assert_int_equal(sl_diag_error_count(diag), 4);
    assert_int_equal(sl_diag_warning_count(diag), 1);
}

static void test_diag_cap_stops_lexer(void **state)
{
    (void)state;
    /* 100 bad characters: the lexer stops at the default cap of 20 */
    char src[201];
    for (int i = 0; i < 100; i++) {
        src[2 * i] = '@';
        src[2 * i + 1] = ' ';
    }
    src[200] = '\0';
    lex(src);
    assert_int_equal(sl_diag_error_count(diag), SL_DIAG_DEFAULT_MAX_ERRORS);
    assert_true(sl_diag_full(diag));
    assert_int_equal(sl_diag_count(diag), SL_DIAG_DEFAULT_MAX_ERRORS + 1);
    const sl_diagnostic *last = sl_diag_get(diag, SL_DIAG_DEFAULT_MAX_ERRORS);
    assert_int_equal(last->level, SL_DIAG_NOTE);
    assert_string_equal(last->message, "too many errors emitted, stopping now (limit 20)");
    assert_null(sl_diag_get(diag, SL_DIAG_DEFAULT_MAX_ERRORS + 1));
}

/* ---------------------------------------------------------------------- */
/* the source set                                                          */
/* ---------------------------------------------------------------------- */

static void check_normalize(const char *in, const char *expect)
{
    char *got = sl_source_normalize(in);
    assert_string_equal(got, expect);
    free(got);
}

static void test_source_normalize(void **state)
{
    (void)state;
    check_normalize("wave.sl", "wave.sl");
    check_normalize("./wave.sl", "wave.sl");
    check_normalize("shaders//lib/./noise.h", "shaders/lib/noise.h");
    check_normalize("shaders/lib/../wave.sl", "shaders/wave.sl");
    check_normalize("../common/x.h", "../common/x.h");
    check_normalize("a/../../x.h", "../x.h");
    check_normalize("a/b/../../..", "..");
    check_normalize("/usr/../share/./sl/", "/share/sl");
    check_normalize("/..", "/");
    check_normalize("", ".");
    check_normalize(".", ".");
    check_normalize("a/..", ".");
}

static void test_source_set_add_find(void **state)
{
    (void)state;
    assert_int_equal(sl_source_set_add(set, "shaders/./wave.sl", "abc", 3), 0);
    const sl_source *s = sl_source_set_find(set, "shaders/lib/../wave.sl");
    assert_non_null(s);
    assert_string_equal(s->name, "shaders/wave.sl");
    assert_int_equal(s->len, 3);
    assert_memory_equal(s->text, "abc", 4);   /* NUL-terminated */
    assert_null(sl_source_set_find(set, "wave.sl"));

    /* same text again: fine; different text: EEXIST; empty name: EINVAL */
    assert_int_equal(sl_source_set_add(set, "shaders/wave.sl", "abc", 3), 0);
    errno = 0;
    assert_int_equal(sl_source_set_add(set, "shaders/wave.sl", "abd", 3), -1);
    assert_int_equal(errno, EEXIST);
    errno = 0;
    assert_int_equal(sl_source_set_add(set, "", "x", 1), -1);
    assert_int_equal(errno, EINVAL);
    assert_int_equal(sl_source_set_count(set), 1);

    /* size limit */
    sl_source_set_set_max_size(set, 4);
    assert_int_equal(sl_source_set_max_size(set), 4);
    assert_int_equal(sl_source_set_add(set, "four", "1234", 4), 0);
    errno = 0;
    assert_int_equal(sl_source_set_add(set, "five", "12345", 5), -1);
    assert_int_equal(errno, EFBIG);

    assert_int_equal(sl_source_set_count(set), 2);
    assert_string_equal(sl_source_set_at(set, 0)->name, "shaders/wave.sl");
    assert_string_equal(sl_source_set_at(set, 1)->name, "four");
    assert_null(sl_source_set_at(set, 2));
}

static void test_source_set_lines(void **state)
{
    (void)state;
    add("l.sl", "one\r\ntwo\n\nfour");
    size_t len;
    const char *p = sl_source_set_line(set, "l.sl", 1, &len);
    assert_int_equal(len, 3);
    assert_memory_equal(p, "one", 3);
    p = sl_source_set_line(set, "l.sl", 2, &len);
    assert_int_equal(len, 3);
    assert_memory_equal(p, "two", 3);
    p = sl_source_set_line(set, "l.sl", 3, &len);
    assert_non_null(p);
    assert_int_equal(len, 0);
    p = sl_source_set_line(set, "l.sl", 4, &len);
    assert_int_equal(len, 4);
    assert_memory_equal(p, "four", 4);
    assert_null(sl_source_set_line(set, "l.sl", 5, &len));
    assert_null(sl_source_set_line(set, "l.sl", 0, &len));
    assert_null(sl_source_set_line(set, "m.sl", 1, &len));
    add("cr.sl", "one\rtwo\r\rfour\r\nfive");
    p = sl_source_set_line(set, "cr.sl", 2, &len);
    assert_int_equal(len, 3);
    assert_memory_equal(p, "two", 3);
    p = sl_source_set_line(set, "cr.sl", 3, &len);
    assert_int_equal(len, 0);
    p = sl_source_set_line(set, "cr.sl", 4, &len);
    assert_int_equal(len, 4);
    assert_memory_equal(p, "four", 4);
    p = sl_source_set_line(set, "cr.sl", 5, &len);
    assert_int_equal(len, 4);
    assert_memory_equal(p, "five", 4);
    assert_null(sl_source_set_line(set, "cr.sl", 6, &len));
}

static void test_source_load_file(void **state)
{
    (void)state;
    char path[] = "/tmp/test_sl_lexer_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "float x;\n", 9), 9);
    close(fd);

    assert_int_equal(sl_source_set_load_file(set, path, "disk.sl", diag), 0);
    const sl_source *s = sl_source_set_find(set, "disk.sl");
    assert_non_null(s);
    assert_int_equal(s->len, 9);
    assert_memory_equal(s->text, "float x;\n", 9);

    sl_source_set_set_max_size(set, 8);
    assert_int_equal(sl_source_set_load_file(set, path, "big.sl", diag), -1);
    unlink(path);
    assert_int_equal(sl_source_set_load_file(set, path, NULL, diag), -1);
    char expect[512];
    snprintf(expect, sizeof expect,
             "error: '%s' is too large (more than 8 bytes)\n"
             "error: cannot open '%s': No such file or directory\n", path, path);
    assert_string_equal(diags(), expect);
}

static int loader_calls;

static int table_loader(sl_source_set *s, const char *name, sl_diag *d, void *arg)
{
    (void)d;
    (void)arg;
    loader_calls++;
    if (strcmp(name, "lib/noise.h") == 0)
        return sl_source_set_add(s, name, "N", 1) == 0 ? 0 : -1;
    return 1;
}

static void test_source_loader_and_resolve(void **state)
{
    (void)state;
    add("shaders/wave.sl", "");
    add("shaders/local.h", "");
    add("inc/common.h", "");
    const char *const path[] = { "inc", "lib", NULL };
    char *searched = (char *)"unset";

    /* relative to the includer first, then the search path */
    const sl_source *s = sl_source_set_resolve(set, "local.h", "shaders/wave.sl", path,
                                               true, diag, &searched);
    assert_non_null(s);
    assert_string_equal(s->name, "shaders/local.h");
    assert_null(searched);
    s = sl_source_set_resolve(set, "common.h", "shaders/wave.sl", path, true, diag, NULL);
    assert_string_equal(s->name, "inc/common.h");
    s = sl_source_set_resolve(set, "../inc/common.h", "shaders/wave.sl", NULL, true,
                              diag, NULL);
    assert_string_equal(s->name, "inc/common.h");
    /* <x> skips the includer's directory */
    assert_null(sl_source_set_resolve(set, "local.h", "shaders/wave.sl", path, false,
                                      diag, &searched));
    assert_string_equal(searched, "inc, lib");
    free(searched);

    /* no loader: not found, directories listed as written */
    assert_null(sl_source_set_resolve(set, "noise.h", "wave.sl", path, true, diag,
                                      &searched));
    assert_string_equal(searched, "., inc, lib");
    free(searched);

    /* with a loader: asked once per candidate until one loads */
    sl_source_set_set_loader(set, table_loader, NULL);
    loader_calls = 0;
    s = sl_source_set_resolve(set, "noise.h", "wave.sl", path, true, diag, NULL);
    assert_non_null(s);
    assert_string_equal(s->name, "lib/noise.h");
    assert_int_equal(loader_calls, 3);          /* noise.h, inc/noise.h, lib/noise.h */
    loader_calls = 0;
    s = sl_source_set_resolve(set, "noise.h", "wave.sl", path, true, diag, NULL);
    assert_non_null(s);
    assert_int_equal(loader_calls, 2);          /* now in the set at the third try */
    assert_non_null(sl_source_set_get(set, "lib/noise.h", diag));
    assert_null(sl_source_set_get(set, "none.sl", diag));
    assert_string_equal(diags(), "");
}

static void test_source_disk_loader(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_sl_lexer_dir_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char file[256];
    snprintf(file, sizeof file, "%s/main.sl", dir);
    FILE *f = fopen(file, "w");
    assert_non_null(f);
    fputs("surface s() {}\n", f);
    fclose(f);

    sl_source_set_set_loader(set, sl_source_load_from_disk, NULL);
    sl_lexer *lx = sl_lexer_new(set, file, NULL, diag);
    sl_token t;
    int n = 0;
    while (sl_lexer_next(lx, &t))
        n++;
    sl_lexer_destroy(&lx);
    assert_int_equal(n, 6);
    assert_int_equal(sl_source_set_count(set), 1);
    assert_int_equal(sl_source_load_from_disk(set, "/nonexistent/x.sl", diag, NULL), 1);
    unlink(file);
    rmdir(dir);
    assert_string_equal(diags(), "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_keywords, setup, teardown),
        cmocka_unit_test_setup_teardown(test_operators, setup, teardown),
        cmocka_unit_test_setup_teardown(test_maximal_munch, setup, teardown),
        cmocka_unit_test_setup_teardown(test_dot_and_numbers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_numbers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_strings, setup, teardown),
        cmocka_unit_test_setup_teardown(test_interned_identifiers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_kind_names, setup, teardown),
        cmocka_unit_test_setup_teardown(test_positions_tabs_and_lines, setup, teardown),
        cmocka_unit_test_setup_teardown(test_positions_cr, setup, teardown),
        cmocka_unit_test_setup_teardown(test_positions_crlf, setup, teardown),
        cmocka_unit_test_setup_teardown(test_positions_line_splices, setup, teardown),
        cmocka_unit_test_setup_teardown(test_comments, setup, teardown),
        cmocka_unit_test_setup_teardown(test_eof_position, setup, teardown),
        cmocka_unit_test_setup_teardown(test_empty_source, setup, teardown),
        cmocka_unit_test_setup_teardown(test_peek, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unexpected_character, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_control_and_nul_bytes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_string, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_string_at_eof, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unknown_escape, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_unterminated_comment, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_malformed_numbers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_malformed_number_value, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_preprocessor_only_tokens, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_missing_main_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_diag_format, setup, teardown),
        cmocka_unit_test_setup_teardown(test_diag_caret_at_end_of_line, setup, teardown),
        cmocka_unit_test_setup_teardown(test_diag_error_cap, setup, teardown),
        cmocka_unit_test_setup_teardown(test_diag_cap_stops_lexer, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_normalize, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_set_add_find, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_set_lines, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_load_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_loader_and_resolve, setup, teardown),
        cmocka_unit_test_setup_teardown(test_source_disk_loader, setup, teardown),
    };
    return cmocka_run_group_tests_name("sl_lexer", tests, NULL, NULL);
}
