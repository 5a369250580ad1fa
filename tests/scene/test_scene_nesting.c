/*
 * tests/scene/test_scene_nesting.c: deep AttributeBegin/TransformBegin
 * nesting (issue 27, item 2). A push or a pop costs O(1) at any depth (the
 * parser used to scan the whole block stack for an open ObjectBegin at
 * every request, and copied the light switches at every push: 100,000
 * levels took minutes), and more than RIB_MAX_BLOCKS open blocks stop the
 * parse with one error at file:line:col (docs/scenes.md, Limits). The time
 * is not asserted: a million levels end in a fraction of a second. So do
 * a million nested SolidBegin and ArchiveBegin blocks, and a chain of
 * 100,000 archives stops at the archive depth limit.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene/rib_parser.h"
#include "scene_testing.h"
#include "sl/strbuf.h"

static void repeat(sl_strbuf *b, const char *s, int n)
{
    for (int i = 0; i < n; i++)
        sl_strbuf_puts(b, s);
}

/* Parses text (freed) without errors into a scene of nobjects objects. */
static scene *parse_ok(sl_strbuf *text, int nobjects)
{
    sl_diag *d;
    scene *s = parse_rib(text->data, &d);
    assert_int_equal(sl_diag_error_count(d), 0);
    assert_non_null(s);
    assert_int_equal(s->nobjects, nobjects);
    sl_diag_destroy(&d);
    free(text->data);
    *text = (sl_strbuf){ 0 };
    return s;
}

/* 10,000 attribute blocks, each moving, colouring and lighting: the
 * innermost sphere has them all, the one after the blocks none. */
static void test_attributes_10000_deep(void **state)
{
    (void)state;
    enum { DEPTH = 10000 };
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\nColor [0.1 0.2 0.3]\n");
    for (int i = 0; i < DEPTH; i++) {
        char level[160];
        snprintf(level, sizeof level, "AttributeBegin\nTranslate 0 0 1\nColor [%d 0 0]\n"
                 "LightSource \"ambientlight\" %d\n", i + 1, i + 1);
        sl_strbuf_puts(&text, level);
    }
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\n");
    repeat(&text, "AttributeEnd\n", DEPTH);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\nWorldEnd\n");
    scene *s = parse_ok(&text, 2);
    assert_int_equal(s->nlights, DEPTH);
    const scene_object *inner = &s->objects[0], *outer = &s->objects[1];
    assert_true(inner->object_to_world.m[2][3] == DEPTH);
    assert_true(inner->Cs[0] == DEPTH && inner->Cs[1] == 0);
    assert_int_equal(inner->attr->nlights, DEPTH);
    assert_true(outer->object_to_world.m[2][3] == 0);
    assert_true(outer->Cs[0] == 0.1 && outer->Cs[1] == 0.2 && outer->Cs[2] == 0.3);
    assert_int_equal(outer->attr->nlights, 0);
    scene_destroy(&s);
}

/* Transform blocks restore the transform alone: the colour set inside
 * them stays. */
static void test_transforms_10000_deep(void **state)
{
    (void)state;
    enum { DEPTH = 10000 };
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\n");
    repeat(&text, "TransformBegin\nTranslate 1 0 0\n", DEPTH);
    sl_strbuf_puts(&text, "Color [0 1 0]\nSphere 1 -1 1 360\n");
    repeat(&text, "TransformEnd\n", DEPTH);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\nWorldEnd\n");
    scene *s = parse_ok(&text, 2);
    assert_true(s->objects[0].object_to_world.m[0][3] == DEPTH);
    assert_true(s->objects[1].object_to_world.m[0][3] == 0);
    assert_true(s->objects[1].Cs[1] == 1);
    scene_destroy(&s);
}

/* An object definition inside deep blocks: found at once by each request
 * inside it (rib_defining), and instanced after the blocks close. */
static void test_object_inside_deep_blocks(void **state)
{
    (void)state;
    enum { DEPTH = 50000 };
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\n");
    repeat(&text, "AttributeBegin\n", DEPTH);
    sl_strbuf_puts(&text, "ObjectBegin 1\n");
    repeat(&text, "TransformBegin\nTransformEnd\n", DEPTH);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\nObjectEnd\n");
    repeat(&text, "AttributeEnd\n", DEPTH);
    sl_strbuf_puts(&text, "ObjectInstance 1\nWorldEnd\n");
    scene *s = parse_ok(&text, 1);
    scene_destroy(&s);
}

/* A million nested blocks: one error at the block past the limit, and
 * no scene. */
static void test_million_deep_stops_at_the_limit(void **state)
{
    (void)state;
    enum { DEPTH = 1000000 };
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\n");
    repeat(&text, "AttributeBegin\n", DEPTH);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\n");
    repeat(&text, "AttributeEnd\n", DEPTH);
    sl_strbuf_puts(&text, "WorldEnd\n");
    sl_diag *d;
    scene *s = parse_rib(text.data, &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 1);
    /* CAMERA is 2 lines, WorldBegin the first block: the limit is passed
     * by the AttributeBegin on line 3 + RIB_MAX_BLOCKS */
    char want[256];
    snprintf(want, sizeof want, "t.rib:%d:1: AttributeBegin: blocks nested too deeply (more "
             "than %d open at once): flatten the nesting of AttributeBegin/TransformBegin "
             "blocks", 3 + RIB_MAX_BLOCKS, RIB_MAX_BLOCKS);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), want);
    sl_diag_destroy(&d);
    free(text.data);
}

/* The other blocks a million deep (issue 27): nested SolidBegin (not
 * rendered: its surfaces as a union) and ArchiveBegin blocks parse with a
 * loop, into a scene; a chain of 100,000 archives, each reading the one
 * before, stops at the archive depth limit (16) with one error. */
static void test_other_blocks_million_deep(void **state)
{
    (void)state;
    enum { DEPTH = 1000000 };
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\n");
    repeat(&text, "SolidBegin \"union\"\n", DEPTH);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\n");
    repeat(&text, "SolidEnd\n", DEPTH);
    sl_strbuf_puts(&text, "WorldEnd\n");
    scene *s = parse_ok(&text, 1);
    scene_destroy(&s);

    sl_strbuf_puts(&text, CAMERA);
    repeat(&text, "ArchiveBegin \"x\"\n", DEPTH);
    repeat(&text, "ArchiveEnd\n", DEPTH);
    sl_strbuf_puts(&text, "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n");
    s = parse_ok(&text, 1);
    scene_destroy(&s);

    /* the chain: 100,000 archives (5 MB, past the 4 MiB a scene file
     * may have: a million would only add parsing time) */
    enum { CHAIN = 100000 };
    sl_strbuf_puts(&text, CAMERA "ArchiveBegin \"a0\"\nSphere 1 -1 1 360\nArchiveEnd\n");
    char line[96];
    for (int i = 1; i < CHAIN; i++) {
        snprintf(line, sizeof line, "ArchiveBegin \"a%d\"\nReadArchive \"a%d\"\nArchiveEnd\n", i,
                 i - 1);
        sl_strbuf_puts(&text, line);
    }
    snprintf(line, sizeof line, "WorldBegin\nReadArchive \"a%d\"\nWorldEnd\n", CHAIN - 1);
    sl_strbuf_puts(&text, line);
    sl_diag *d;
    s = parse_rib(text.data, &d);
    assert_null(s);
    const char *got = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
    assert_non_null(strstr(got, "ReadArchive: archives nested more than 16 deep (is there a "
                                "cycle?)"));
    sl_diag_destroy(&d);
    free(text.data);
}

/* At the limit exactly: a scene. */
static void test_at_the_limit(void **state)
{
    (void)state;
    sl_strbuf text = { 0 };
    sl_strbuf_puts(&text, CAMERA "WorldBegin\n");
    repeat(&text, "TransformBegin\n", RIB_MAX_BLOCKS - 1);
    sl_strbuf_puts(&text, "Sphere 1 -1 1 360\n");
    repeat(&text, "TransformEnd\n", RIB_MAX_BLOCKS - 1);
    sl_strbuf_puts(&text, "WorldEnd\n");
    scene *s = parse_ok(&text, 1);
    scene_destroy(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_attributes_10000_deep),
        cmocka_unit_test(test_transforms_10000_deep),
        cmocka_unit_test(test_object_inside_deep_blocks),
        cmocka_unit_test(test_million_deep_stops_at_the_limit),
        cmocka_unit_test(test_at_the_limit),
        cmocka_unit_test(test_other_blocks_million_deep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
