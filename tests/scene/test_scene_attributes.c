/*
 * tests/scene/test_scene_attributes.c: the attributes a run of objects
 * shares (scene_attributes, common/scene/scene.h, made in
 * common/scene/rib_geometry.c): a placement costs the scene its
 * scene_object (at most 224 bytes, issue 23), and a run of 1,000
 * instances with the same attributes points at one record, whatever
 * their transforms and colours; a change of attribute starts a new
 * record that still shares the unchanged strings and light list.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "scene_testing.h"

enum { NINSTANCES = 1000 };

/* The distinct attribute records of objects [from, to). */
static int distinct_attrs(const scene *s, int from, int to)
{
    const scene_attributes **seen = calloc((size_t)(to - from), sizeof *seen);
    assert_non_null(seen);
    int n = 0;
    for (int i = from; i < to; i++) {
        int k = 0;
        while (k < n && seen[k] != s->objects[i].attr) k++;
        if (k == n) seen[n++] = s->objects[i].attr;
    }
    free(seen);
    return n;
}

static void test_object_size(void **state)
{
    (void)state;
    /* a transform (128), the colour (24), the defining position (16),
     * five pointers and a few words: issue 23's <= 256 with room */
    assert_true(sizeof(scene_object) <= 224);
}

/* 1,000 instances of one sphere, each with its own Translate and Color;
 * Opacity changes once, half way. */
static char *instances_rib(void)
{
    size_t cap = 128 * NINSTANCES + 1024, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    len += (size_t)snprintf(text + len, cap - len, "%s",
                            CAMERA "WorldBegin\n"
                            "LightSource \"pointlight\" 1 \"from\" [0 5 0]\n"
                            "LightSource \"distantlight\" 2\n"
                            "Surface \"plastic\" \"Kd\" 0.7\n"
                            "Displacement \"bumpy\"\n"
                            "Attribute \"displacementbound\" \"sphere\" [0.25]\n"
                            "Attribute \"identifier\" \"name\" \"rock\"\n"
                            "Sides 1\n"
                            "ObjectBegin 1\n  Sphere 0.5 -0.5 0.5 360\nObjectEnd\n");
    for (int i = 0; i < NINSTANCES; i++) {
        if (i == NINSTANCES / 2)
            len += (size_t)snprintf(text + len, cap - len, "Opacity 0.5 0.5 0.5\n");
        len += (size_t)snprintf(text + len, cap - len,
                                "AttributeBegin Translate %d 0 10 Color %g 0.5 0.5 "
                                "ObjectInstance 1 AttributeEnd\n",
                                i, (double)i / NINSTANCES);
        assert_true(len < cap);
    }
    snprintf(text + len, cap - len, "WorldEnd\n");
    return text;
}

static void test_run_shares_one_record(void **state)
{
    (void)state;
    char *text = instances_rib();
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    if (!s) sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, NINSTANCES);
    int half = NINSTANCES / 2;
    /* each run of equal attributes: one record, whatever the transforms
     * and colours (kept per object) */
    assert_int_equal(distinct_attrs(s, 0, half), 1);
    assert_int_equal(distinct_attrs(s, half, NINSTANCES), 1);
    assert_int_equal(distinct_attrs(s, 0, NINSTANCES), 2);
    assert_true(s->objects[1].Cs[0] != s->objects[2].Cs[0]);
    const scene_attributes *a = s->objects[0].attr, *b = s->objects[half].attr;
    /* the record says what the RIB set */
    assert_int_equal(a->sides, 1);
    assert_true(a->Os[0] == 1 && b->Os[0] == 0.5);
    assert_string_equal(a->name, "rock");
    assert_true(a->displacement_bound == 0.25);
    assert_int_equal(a->nlights, 2);
    assert_true(a->surface_shader >= 0 && a->displacement_shader >= 0);
    assert_string_equal(scene_object_surface(s, &s->objects[0])->name, "plastic");
    assert_string_equal(scene_object_displacement(s, &s->objects[NINSTANCES - 1])->name, "bumpy");
    /* the second record shares the first's unchanged strings and lights */
    assert_ptr_equal(a->name, b->name);
    assert_ptr_equal(a->lights, b->lights);
    assert_ptr_equal(a->displacement_bound_space, b->displacement_bound_space);
    assert_true(b->surface_shader == a->surface_shader && b->sides == a->sides);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    free(text);
}

/* Objects whose attributes differ from the previous one's get a record
 * of their own, each with its values. */
static void test_changes_start_records(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(CAMERA "WorldBegin\n"
                         "Sphere 1 -1 1 360\n"
                         "Sides 1\nSphere 1 -1 1 360\n"
                         "ReverseOrientation\nSphere 1 -1 1 360\n"
                         "ShadingRate 4\nSphere 1 -1 1 360\n"
                         "Color 1 0 0\nSphere 1 -1 1 360\n"
                         "WorldEnd\n", &d);
    if (!s) sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 5);
    assert_int_equal(distinct_attrs(s, 0, 5), 4);
    assert_int_equal(s->objects[0].attr->sides, 2);
    assert_int_equal(s->objects[1].attr->sides, 1);
    assert_int_equal(s->objects[1].attr->orientation, SCENE_OUTSIDE);
    assert_int_equal(s->objects[2].attr->orientation, SCENE_INSIDE);
    assert_true(s->objects[2].reverse_normals);
    assert_true(s->objects[3].attr->shading_rate == 4);
    /* a colour is the object's own: the record is the previous one's */
    assert_ptr_equal(s->objects[4].attr, s->objects[3].attr);
    assert_true(s->objects[4].Cs[1] == 0 && s->objects[3].Cs[1] == 1);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_object_size),
        cmocka_unit_test(test_run_shares_one_record),
        cmocka_unit_test(test_changes_start_records),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
