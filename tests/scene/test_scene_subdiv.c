/*
 * tests/scene/test_scene_subdiv.c: SubdivisionMesh (common/scene/
 * rib_subdiv.c): a mesh becomes one shared geom_subdiv and one GEOM_SUBDIV
 * object per drawn face of its once-refined mesh (4 per quad, n per
 * n-gon); holes and, without interpolateboundary, boundary faces are not
 * drawn; the tag arrays may be left out; unsupported tags warn; bad
 * meshes and tags are errors with file:line:col.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "geom/subdiv.h"
#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

/* a cube of six quads, and a 3 x 1 strip of quads (8 points) */
#define CUBE_FACES "[4 4 4 4 4 4] [0 3 2 1  4 5 6 7  0 1 5 4  1 2 6 5  2 3 7 6  3 0 4 7]"
#define CUBE_P "\"P\" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]"
#define STRIP "[4 4 4] [0 1 5 4  1 2 6 5  2 3 7 6]"
#define STRIP_P "\"P\" [0 0 0  1 0 0  2 0 0  3 0 0  0 1 0  1 1 0  2 1 0  3 1 0]"

/* pieces of kind k (a subdivision mesh is one object, issue 23) */
static int count_kind(const scene *s, geom_kind k)
{
    int n = 0, np;
    test_piece *pc = scene_pieces(s, &np);
    for (int i = 0; i < np; i++) n += pc[i].surface.kind == k;
    free(pc);
    return n;
}

static void test_faces(void **state)
{
    (void)state;
    sl_diag *d;
    /* a cube, no tags: 24 faces; with a triangle added to nothing: the
     * tags left out */
    scene *s = parse_rib(WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES " " CUBE_P "\n"), &d);
    assert_non_null(s);
    assert_int_equal(s->nsubdivs, 1);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 24);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    /* a hole: 4 faces fewer; two meshes: two geom_subdivs */
    s = parse_rib(WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES
                        " [\"hole\"] [1 0] [2] [] " CUBE_P "\n"
                        "SubdivisionMesh \"catmull-clark\" " CUBE_FACES
                        " [\"crease\" \"corner\"] [2 1 1 1] [0 1 6] [10 3] " CUBE_P "\n"), &d);
    assert_non_null(s);
    assert_int_equal(s->nsubdivs, 2);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 20 + 24);
    assert_int_equal(s->nobjects, 2);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_ptr_equal(pc[0].surface.subdiv, s->subdivs[0]);
    assert_ptr_equal(pc[20].surface.subdiv, s->subdivs[1]);
    /* the holed mesh's 20 pieces are its 20 drawn faces, each once (its
     * pieces name their faces; the other mesh's are faces 0..23) */
    unsigned char seen[24] = {0};
    for (int i = 0; i < 20; i++) {
        int f = pc[i].surface.subdiv_face;
        assert_true(f >= 0 && f < 24 && !seen[f]);
        assert_true(geom_subdiv_face_drawn(s->subdivs[0], f));
        seen[f] = 1;
    }
    for (int i = 20; i < 44; i++) assert_int_equal(pc[i].surface.subdiv_face, i - 20);
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    /* an open strip: with interpolateboundary all 12 faces are drawn */
    s = parse_rib(WORLD("SubdivisionMesh \"catmull-clark\" " STRIP
                        " [\"interpolateboundary\"] [0 0] [] [] " STRIP_P "\n"), &d);
    assert_non_null(s);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 12);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_warnings(void **state)
{
    (void)state;
    sl_diag *d;
    /* without interpolateboundary every face of the strip touches the
     * boundary: nothing to draw (a warning; the world is then empty) */
    scene *s = parse_rib(WORLD("SubdivisionMesh \"catmull-clark\" " STRIP " " STRIP_P "\n"
                               "Sphere 1 -1 1 360\n"), &d);
    assert_non_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:4:1: SubdivisionMesh: no face to draw (every face is a hole or "
                        "touches the boundary: add the tag \"interpolateboundary\")");
    scene_destroy(&s);
    sl_diag_destroy(&d);
    s = parse_rib(WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES
                        " [\"creasemethod\"] [0 0] [] [] " CUBE_P "\n"), &d);
    assert_non_null(s);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 24);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                           "tag \"creasemethod\" is not supported: ignored"));
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case cases[] = {
    { WORLD("SubdivisionMesh \"loop\" [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:17: SubdivisionMesh: scheme \"loop\" is not supported (only \"catmull-clark\")" },
    { WORLD("SubdivisionMesh \"catmull-clark\" [3 3 3] [0 1 2  1 0 3  0 1 4] "
            "\"P\" [0 0 0 1 0 0 0 1 0 0 -1 0 0 0 1]\n"),
      "t.rib:4:1: SubdivisionMesh: the edge 0-1 has 3 faces (at most 2: the mesh must be a "
      "manifold)" },
    { WORLD("SubdivisionMesh \"catmull-clark\" [3 3] [0 1 2  0 1 3] "
            "\"P\" [0 0 0 1 0 0 0 1 0 0 -1 0]\n"),
      "t.rib:4:1: SubdivisionMesh: faces 0 and 1 run the edge 0-1 the same way (orient all "
      "faces alike)" },
    { WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES " [\"crease\"] [2 1] [0 6] [10] "
            CUBE_P "\n"),
      "t.rib:4:1: SubdivisionMesh: crease 0: points 0 and 6 share no edge" },
    { WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES " [\"crease\"] [2 2] [0 1] [10] "
            CUBE_P "\n"),
      "t.rib:4:113: SubdivisionMesh: nargs asks for 2 integers and 2 floats, but intargs has "
      "2 and floatargs 1" },
    { WORLD("SubdivisionMesh \"catmull-clark\" " CUBE_FACES " [\"hole\"] [1 0] [6] [] "
            CUBE_P "\n"),
      "t.rib:4:102: SubdivisionMesh: tag 0 \"hole\": face 6, but the mesh has 6 faces" },
    { WORLD("SubdivisionMesh \"catmull-clark\" [4] [0 1 2 9] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"),
      "t.rib:4:47: SubdivisionMesh: \"P\" has 4 points, but the vertex indices go up to 9" },
};

static void test_errors(void **state)
{
    (void)state;
    expect_first_errors(cases, sizeof cases / sizeof cases[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_faces),
        cmocka_unit_test(test_warnings),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
