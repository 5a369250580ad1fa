/*
 * tests/scene/test_scene_limits.c: the limits on a scene received from
 * outside (issue 12): the number of objects (primitives and meshes,
 * instances apart; more is one error naming
 * the request that passes the limit, with file:line:col, and no scene) and the size of the scene text
 * read from disk (the source size limit, a clear error naming the file).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <unistd.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"
#define SPHERE "Sphere 1 -1 1 360\n"

static scene *parse_limited(const char *text, int max_objects, sl_diag **d)
{
    *d = sl_diag_new();
    return scene_parse_limited("t.rib", text, strlen(text), NULL, max_objects, *d);
}

static void test_objects_at_the_limit(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_limited(WORLD(SPHERE SPHERE SPHERE), 3, &d);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 3);
    assert_int_equal(sl_diag_error_count(d), 0);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_objects_over_the_limit(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_limited(WORLD(SPHERE SPHERE SPHERE SPHERE SPHERE), 3, &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 1);      /* reported once */
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:7:1: Sphere: too many objects (the limit is 3 per scene, "
                        "instances apart): split the scene into several renders, "
                        "use fewer, larger primitives, or place repeated ones with "
                        "ObjectInstance");
    sl_diag_destroy(&d);
}

/* Instancing multiplies objects cheaply: ten instances of a definition
 * of four surfaces are forty objects. They are references in the
 * renderer (a few hundred bytes each: trace/group.h), displaced or not,
 * meshes too, and have their own limit (SCENE_MAX_INSTANCES): the
 * objects' limit counts only the definition's first placement. */
static void test_instances_count(void **state)
{
    (void)state;
    char text[4096];
    static const char *const kinds[] = {"", "Displacement \"dented\"\n", "Displacement \"dented\"\n"};
#define QUAD "PointsPolygons [4] [0 1 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
    for (int kind = 0; kind < 3; kind++) {
        bool mesh = kind == 2;
        size_t o = (size_t)snprintf(text, sizeof text, CAMERA "WorldBegin\n%sObjectBegin 1\n%s%s%s%s"
                                    "ObjectEnd\n", kinds[kind], mesh ? QUAD : SPHERE,
                                    mesh ? QUAD : SPHERE, mesh ? QUAD : SPHERE,
                                    mesh ? QUAD : SPHERE);
        for (int i = 0; i < 10; i++)
            o += (size_t)snprintf(text + o, sizeof text - o, "ObjectInstance 1\n");
        snprintf(text + o, sizeof text - o, "WorldEnd\n");
        sl_diag *d;
        scene *s = parse_limited(text, 4, &d);
        assert_non_null(s);
        assert_int_equal(s->nobjects, 40);
        scene_destroy(&s);
        sl_diag_destroy(&d);
        /* references: the first placement's four are objects */
        s = parse_limited(text, 3, &d);
        assert_null(s);
        assert_int_equal(sl_diag_error_count(d), 1);
        const sl_diagnostic *e = nth_diag(d, SL_DIAG_ERROR, 0);
        assert_non_null(e);
        /* the tenth instance, or the first (after a Displacement line) */
        assert_int_equal(e->line, kind >= 1 ? 11 : 10);
        assert_non_null(strstr(e->message, "ObjectInstance: too many objects (the limit is 3"));
        sl_diag_destroy(&d);
    }
#undef QUAD
}

/* The pieces a renderer keeps boxes for (scene.npieces, against
 * SCENE_MAX_PIECES): an undisplaced mesh's once, a displaced mesh's again
 * for each instance that does not move the first placement rigidly (a
 * rigid one may be the first moved: trace/group.h). */
static void test_displaced_mesh_pieces_count(void **state)
{
    (void)state;
    /* times the mesh's pieces (the first case's count) */
    static const struct { const char *disp, *motion; long times; } cases[] = {
        {"", "Translate 1 0 0 Rotate 30 0 1 0", 1},                 /* shared */
        {"Displacement \"dented\"\n", "Translate 1 0 0 Rotate 30 0 1 0", 1},   /* moved */
        {"Displacement \"dented\"\n", "Translate 1 0 0 Scale 2 2 2", 6},      /* own */
        {"Displacement \"dented\"\n", "Scale 1 1 -1", 6},           /* mirrored */
    };
    long mesh = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char text[4096];
        size_t o = (size_t)snprintf(text, sizeof text, CAMERA "WorldBegin\n%sObjectBegin 1\n"
                                    "PointsPolygons [4 4 4 4] [0 1 2 3 1 4 5 2 4 6 7 5 6 0 3 7] "
                                    "\"P\" [0 0 0 1 0 0 1 1 0 0 1 0 2 0 0 2 1 0 3 0 0 3 1 0]\n"
                                    "ObjectEnd\nObjectInstance 1\n", cases[c].disp);
        for (int i = 0; i < 5; i++)
            o += (size_t)snprintf(text + o, sizeof text - o,
                                  "AttributeBegin %s ObjectInstance 1 AttributeEnd\n",
                                  cases[c].motion);
        snprintf(text + o, sizeof text - o, "WorldEnd\n");
        sl_diag *d;
        scene *sc = parse_limited(text, 100, &d);
        assert_non_null(sc);
        assert_int_equal(sc->nobjects, 6);
        if (c == 0) mesh = sc->npieces;
        assert_true(mesh >= 4);
        assert_int_equal(sc->npieces, cases[c].times * mesh);
        scene_destroy(&sc);
        sl_diag_destroy(&d);
    }
}

/* scene_parse uses the default limit. */
static void test_default_limit(void **state)
{
    (void)state;
    assert_true(SCENE_MAX_OBJECTS >= 100000);
    sl_diag *d;
    scene *s = parse_rib(WORLD(SPHERE SPHERE), &d);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 2);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* A scene file larger than the source limit is refused by name, before
 * it is parsed. */
static void test_scene_file_too_large(void **state)
{
    (void)state;
    char path[] = "/tmp/aafarm-scene-limit-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(WORLD(SPHERE), f);
    for (size_t n = 0; n <= (size_t)SL_SOURCE_DEFAULT_MAX_SIZE; n += 64)
        fputs("# padding padding padding padding padding padding padding paddin\n", f);
    assert_int_equal(fclose(f), 0);

    sl_diag *d = sl_diag_new();
    scene *s = scene_load(path, d);
    unlink(path);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 1);
    const sl_diagnostic *e = nth_diag(d, SL_DIAG_ERROR, 0);
    assert_non_null(e);
    assert_non_null(strstr(e->message, path));
    assert_non_null(strstr(e->message, "too large"));
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_objects_at_the_limit),
        cmocka_unit_test(test_objects_over_the_limit),
        cmocka_unit_test(test_instances_count),
        cmocka_unit_test(test_displaced_mesh_pieces_count),
        cmocka_unit_test(test_default_limit),
        cmocka_unit_test(test_scene_file_too_large),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
