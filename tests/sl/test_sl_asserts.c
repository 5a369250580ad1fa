/*
 * test_sl_asserts.c: the shading language's death test. A compiled program
 * whose jump is moved past its end trips the bytecode invariant that
 * sl_program_assert_valid states for every program the code generator
 * hands out (slots, string slots, jumps and tables inside the program), so
 * a build that compiled common/sl's asserts away fails here. And the
 * source set's adopt wants the NUL it promises its readers.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "death.h"
#include "sl_harness.h"
#include "sl/bytecode.h"
#include "sl/source.h"
#include "util/xalloc.h"

#include <string.h>

static void assert_broken_jump(void *arg)
{
    sl_program *p = arg;
    for (int pc = 0; pc < p->ncode; pc++)
        if (p->code[pc].op == SL_OP_BR_BEGIN)
            p->code[pc].b = (uint16_t)(p->ncode + 1);    /* past END */
    sl_program_assert_valid(p);
}

static void test_jump_past_the_end(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t(float k = 1) {\n"
                              "    if (u > k) P += N; else P -= N;\n"
                              "}\n");
    assert_non_null(p);
    bool has_branch = false;
    for (int pc = 0; pc < p->ncode; pc++)
        has_branch |= p->code[pc].op == SL_OP_BR_BEGIN;
    assert_true(has_branch);
    sl_program_assert_valid(p);                  /* as generated: valid */
    assert_death(assert_broken_jump, p, "a jump lands inside the program");
    sl_program_destroy(&p);
}

/* sl_source_set_adopt takes a NUL-terminated text (a big archive is held
 * once, not copied): one without its NUL is a caller's bug. */
static void adopt_unterminated(void *arg)
{
    (void)arg;
    sl_source_set *set = sl_source_set_new();
    char *text = xmalloc(4);
    memcpy(text, "abcd", 4);
    sl_source_set_adopt(set, "a.rib", text, 3);
}

static void test_adopt_wants_a_terminated_text(void **state)
{
    (void)state;
    sl_source_set *set = sl_source_set_new();
    char *text = xstrdup("Sphere 1 -1 1 360\n");
    assert_int_equal(sl_source_set_adopt(set, "a.rib", text, strlen(text)), 0);
    assert_ptr_equal(sl_source_set_find(set, "a.rib")->text, text);   /* not copied */
    sl_source_set_destroy(&set);
    assert_death(adopt_unterminated, NULL, "text[len] == '\\0'");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_jump_past_the_end),
        cmocka_unit_test(test_adopt_wants_a_terminated_text),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
