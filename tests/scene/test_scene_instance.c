/*
 * tests/scene/test_scene_instance.c: ObjectBegin / ObjectEnd /
 * ObjectInstance (common/scene/rib_instance.c). Instances place every
 * surface of a definition with the transform inside the definition
 * composed after the one current at ObjectInstance, and take the
 * attributes current at ObjectInstance; number and string handles,
 * redefinition; errors with file:line:col (unknown handle, nesting,
 * unclosed definitions, instances inside definitions).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

static vec3 origin_of(const scene_object *o, vec3 p)
{
    return mat4_xform_point(&o->object_to_world, p);
}

static void test_instances_compose(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "ObjectBegin 7\n"
        "  Translate 0 1 0\n"
        "  Sphere 0.5 -0.5 0.5 360\n"
        "  TransformBegin\n    Rotate 90 0 0 1\n    Disk 0 1 360\n  TransformEnd\n"
        "ObjectEnd\n"
        "AttributeBegin\n  Translate 10 0 0\n  Color 1 0 0\n  ObjectInstance 7\nAttributeEnd\n"
        "AttributeBegin\n  Scale 2 2 2\n  Color 0 0 1\n  ObjectInstance 7\nAttributeEnd\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 0);
    assert_int_equal(s->nobjects, 4);
    /* instance 1: sphere centre at (10,1,0), disk: rotate then translate */
    assert_int_equal(s->objects[0].surface->kind, GEOM_SPHERE);
    assert_true(vec_dist(origin_of(&s->objects[0], v3(0, 0, 0)), v3(10, 1, 0)) < 1e-12);
    assert_int_equal(s->objects[1].surface->kind, GEOM_DISK);
    /* the disk's (1,0,0) is rotated to (0,1,0), then moved by (0,1,0) and (10,0,0) */
    assert_true(vec_dist(origin_of(&s->objects[1], v3(1, 0, 0)), v3(10, 2, 0)) < 1e-12);
    assert_true(s->objects[0].Cs[0] == 1 && s->objects[0].Cs[2] == 0);
    /* instance 2: scaled by 2 */
    assert_true(vec_dist(origin_of(&s->objects[2], v3(0, 0, 0)), v3(0, 2, 0)) < 1e-12);
    assert_true(vec_dist(origin_of(&s->objects[3], v3(1, 0, 0)), v3(0, 4, 0)) < 1e-12);
    assert_true(s->objects[3].Cs[2] == 1 && s->objects[3].Cs[0] == 0);
    /* positions point at the definition's surfaces */
    assert_int_equal(s->objects[0].pos.line, 6);
    assert_int_equal(s->objects[3].pos.line, 9);
    /* each placed surface names the first object placed from it */
    assert_int_equal(s->objects[0].instance_of, 0);
    assert_int_equal(s->objects[1].instance_of, 1);
    assert_int_equal(s->objects[2].instance_of, 0);
    assert_int_equal(s->objects[3].instance_of, 1);
    /* the definition's transform did not leak past ObjectEnd */
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_string_handles_and_redefinition(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "ObjectBegin \"ball\"\nSphere 1 -1 1 360\nObjectEnd\n"
        "ObjectInstance \"ball\"\n"
        "ObjectBegin \"ball\"\nSphere 2 -2 2 360\nColor 1 0 0\nObjectEnd\n"
        "ObjectInstance \"ball\"\n"
        "Translate 5 0 0\nSphere 3 -3 3 360\n"), &d);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 3);
    assert_true(s->objects[0].surface->radius == 1);
    assert_true(s->objects[1].surface->radius == 2);
    /* a redefined handle is another object; a plain surface no instance */
    assert_int_equal(s->objects[1].instance_of, 1);
    assert_int_equal(s->objects[2].instance_of, -1);
    /* Color inside the definition does not travel: a warning says so */
    assert_true(s->objects[1].Cs[1] == 1);
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                           "t.rib:10:1: Color: inside an object definition only surfaces"));
    /* after the definitions, the world's transform is as before */
    assert_true(vec_dist(origin_of(&s->objects[2], v3(0, 0, 0)), v3(5, 0, 0)) < 1e-12);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case cases[] = {
    { WORLD("Sphere 1 -1 1 360\nObjectInstance 3\n"),
      "t.rib:5:16: ObjectInstance: no object has the handle 3 (define it first with "
      "ObjectBegin 3 ... ObjectEnd)" },
    { WORLD("ObjectBegin 1\nObjectBegin 2\nObjectEnd\nObjectEnd\nSphere 1 -1 1 360\n"),
      "t.rib:5:1: ObjectBegin: object definitions cannot nest: the ObjectBegin at t.rib:4:1 "
      "is still open (missing ObjectEnd)" },
    { WORLD("ObjectBegin 1\nSphere 1 -1 1 360\nObjectInstance 1\nObjectEnd\nObjectInstance 1\n"),
      "t.rib:6:1: ObjectInstance: cannot be used inside an object definition (instances of "
      "instances are not supported)" },
    { WORLD("Sphere 1 -1 1 360\nObjectBegin 1\nSphere 1 -1 1 360\n"),
      "t.rib:7:1: WorldEnd: the ObjectBegin opened at t.rib:5:1 is not closed (missing "
      "ObjectEnd)" },
    { CAMERA "ObjectBegin 1\nObjectEnd\nWorldBegin\nSphere 1 -1 1 360\nWorldEnd\n",
      "t.rib:3:1: ObjectBegin: must come between WorldBegin and WorldEnd" },
    { WORLD("ObjectBegin\nObjectEnd\nSphere 1 -1 1 360\n"),
      "t.rib:4:1: ObjectBegin: missing the object handle (a number or a string)" },
    { WORLD("ObjectBegin 1\nSphere -1 -1 1 360\nObjectEnd\nObjectInstance 1\n"),
      "t.rib:5:1: Sphere: sphere radius must be > 0, got -1" },
    { WORLD("ObjectBegin 1\nObjectEnd\nObjectInstance 1\n"),
      "t.rib:7:1: WorldEnd: the world has no objects (add a surface between WorldBegin and "
      "WorldEnd, e.g. Sphere 1 -1 1 360)" },
};

static void test_errors(void **state)
{
    (void)state;
    expect_first_errors(cases, sizeof cases / sizeof cases[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_instances_compose),
        cmocka_unit_test(test_string_handles_and_redefinition),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
