/*
 * tests/scene/test_scene_mesh.c: polygon meshes (common/scene/rib_mesh.c).
 * A mesh is one scene object whose pieces (scene_pieces) are what the
 * faces became. A cube of shared-point quads gives twelve triangles with the right
 * corners, each carrying area-weighted vertex normals (the corner's
 * direction from the centre, shared by every face at that corner); a flat
 * mesh stays one polygon per face; a given "N" of each class (vertex,
 * facevarying, uniform) lands on the right corners, and a wrong count is
 * an error; a non-planar quad, a concave face and a face with a hole are
 * cut into triangles whose areas add up to the face's; primitive
 * variables other than P give one warning per scene; faces without area
 * are skipped with a warning; meshes work inside object definitions; and
 * malformed meshes give errors with file:line:col.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

#define CUBE_P "\"P\" [-1 -1 -1  1 -1 -1  -1 1 -1  1 1 -1  -1 -1 1  1 -1 1  -1 1 1  1 1 1]"
#define CUBE "PointsPolygons [4 4 4 4 4 4]\n" \
    "  [0 2 3 1  4 5 7 6  0 1 5 4  2 6 7 3  0 4 6 2  1 3 7 5]\n  " CUBE_P "\n"

/* Sum of the areas of the pieces' polygons. */
static double polygon_area(const test_piece *pc, int from, int to)
{
    double a = 0;
    for (int i = from; i < to; i++) {
        const geom_surface *g = &pc[i].surface;
        assert_int_equal(g->kind, GEOM_POLYGON);
        vec3 n = v3(0, 0, 0);
        for (int k = 1; k + 1 < g->nverts; k++)
            n = v3_add(n, v3_cross(v3_sub(g->verts[k], g->verts[0]),
                                   v3_sub(g->verts[k + 1], g->verts[0])));
        a += v3_length(n) / 2;
    }
    return a;
}

static void test_cube(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(CUBE), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 0);
    /* one object, twelve pieces (issue 23: a mesh is one object) */
    assert_int_equal(s->nobjects, 1);
    assert_non_null(s->objects[0].mesh);
    assert_int_equal(s->npieces, 12);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 12);
    for (int i = 0; i < 12; i++) {
        const geom_surface *g = &pc[i].surface;
        assert_int_equal(g->kind, GEOM_POLYGON);
        assert_int_equal(g->nverts, 3);
        assert_int_equal(g->nvn, 3);
        /* every corner is a cube corner, and the face is one side; its
         * normal is the average of the three sides there: the corner's
         * own direction */
        for (int k = 0; k < 3; k++) {
            assert_true(fabs(fabs(g->verts[k].x) - 1) + fabs(fabs(g->verts[k].y) - 1) +
                        fabs(fabs(g->verts[k].z) - 1) == 0);
            assert_true(vec_dist(v3_normalize(g->vn[k]), v3_normalize(g->verts[k])) < 1e-12);
        }
        /* the corners keep the order written: every face of CUBE winds
         * outward by the right-hand rule */
        vec3 n = v3_cross(v3_sub(g->verts[1], g->verts[0]), v3_sub(g->verts[2], g->verts[0]));
        vec3 c = v3_scale(v3_add(v3_add(g->verts[0], g->verts[1]), g->verts[2]), 1 / 3.0);
        assert_true(v3_dot(n, c) > 0);
    }
    assert_true(fabs(polygon_area(pc, 0, 12) - 24) < 1e-12);
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_cut_faces(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        /* a non-planar quad: two triangles */
        "PointsPolygons [4] [0 1 2 3] \"P\" [0 0 0  1 0 0  1 1 0.5  0 1 0]\n"
        /* an L (area 3) and a 4x4 square with a 2x2 hole (area 12) */
        "PointsGeneralPolygons [1 2] [6 4 4] [0 1 2 3 4 5  6 7 8 9  10 11 12 13]\n"
        "  \"P\" [0 0 0  2 0 0  2 1 0  1 1 0  1 2 0  0 2 0\n"
        "        0 0 1  4 0 1  4 4 1  0 4 1  1 1 1  3 1 1  3 3 1  1 3 1]\n"
        "GeneralPolygon [4 3] \"P\" [0 0 2  4 0 2  4 4 2  0 4 2  1 1 2  2 1 2  1 2 2]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    /* two meshes, then the GeneralPolygon's 7 triangles as objects */
    assert_int_equal(s->nobjects, 2 + 7);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 2 + 4 + 8 + 7);
    for (int i = 0; i < np; i++)
        assert_int_equal(pc[i].surface.nverts, 3);
    assert_true(fabs(polygon_area(pc, 2, 6) - 3) < 1e-12);
    assert_true(fabs(polygon_area(pc, 6, 14) - 12) < 1e-12);
    assert_true(fabs(polygon_area(pc, 14, 21) - 15.5) < 1e-12);
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* The corner normals of the triangle pieces [from, to) that hold point
 * p: all equal n (up to length). Returns how many corners were found. */
static int corners_at(const test_piece *s, int from, int to, vec3 p, vec3 n)
{
    int found = 0;
    for (int i = from; i < to; i++) {
        const geom_surface *g = &s[i].surface;
        assert_int_equal(g->nvn, 3);
        for (int k = 0; k < 3; k++)
            if (vec_dist(g->verts[k], p) == 0) {
                assert_true(vec_dist(v3_normalize(g->vn[k]), v3_normalize(n)) < 1e-12);
                found++;
            }
    }
    return found;
}

static void test_normals(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        /* flat: two quads in z = 0 stay two polygons */
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 0  2 0 0  0 1 0  1 1 0  2 1 0]\n"
        /* a roof folded along x = 1: vertex normals given */
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 1  2 0 0  0 1 0  1 1 1  2 1 0]\n"
        "  \"N\" [-1 0 1  0 0 1  1 0 1  -1 0 1  0 0 1  1 0 1]\n"
        /* the same roof, facevarying: every corner its face's normal */
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 1  2 0 0  0 1 0  1 1 1  2 1 0]\n"
        "  \"facevarying normal N\" [-1 0 1  -1 0 1  -1 0 1  -1 0 1  1 0 1  1 0 1  1 0 1  1 0 1]\n"
        /* the same roof, computed: the ridge gets (0 0 1) */
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 1  2 0 0  0 1 0  1 1 1  2 1 0]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 0);
    assert_int_equal(s->nobjects, 4);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 2 + 4 + 2 + 4);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(pc[i].surface.nverts, 4);
        assert_int_equal(pc[i].surface.nvn, 0);
    }
    assert_int_equal(corners_at(pc, 2, 6, v3(1, 0, 1), v3(0, 0, 1)), 3);
    assert_true(corners_at(pc, 2, 6, v3(0, 0, 0), v3(-1, 0, 1)) >= 1);
    assert_true(corners_at(pc, 2, 6, v3(2, 1, 0), v3(1, 0, 1)) >= 1);
    /* facevarying: flat faces stay polygons without corner normals */
    for (int i = 6; i < 8; i++) {
        assert_int_equal(pc[i].surface.nverts, 4);
        assert_int_equal(pc[i].surface.nvn, 0);
    }
    assert_int_equal(corners_at(pc, 8, 12, v3(1, 1, 1), v3(0, 0, 1)), 3);
    assert_true(corners_at(pc, 8, 12, v3(0, 1, 0), v3(-1, 0, 1)) >= 1);
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    s = parse_rib(WORLD("PointsPolygons [3] [0 1 2] \"P\" [0 0 0  1 0 0  0 1 0]\n"
                        "  \"N\" [0 0 1  0 0 1]\n"), &d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:5:3: PointsPolygons: \"N\" has 2 normals; give one per point "
                        "(3), per face corner (3), per face (1) or one");
    sl_diag_destroy(&d);
}

/* The value of primitive variable k of piece pc at its corner i: the
 * polynomial in (u,v) (scene.h) at that corner's (u,v) */
static double corner_value(const test_piece *pc, int k, int comp, int i)
{
    const scene_primvar *v = &pc->primvars[k];
    double u = pc->surface.uv[i][0], w = pc->surface.uv[i][1], sum = 0;
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++)
            sum += v->c[a + 4 * b][comp] * pow(u, a) * pow(w, b);
    return sum;
}

/* Flat faces whose variables differ at their corners ("st" across a wall
 * of quads): where the variables are affine in the face's (u,v), it stays
 * one polygon with them linear over it (at each corner its given value);
 * where they are not, it is cut into triangles, flat ones without corner
 * normals (its corners' normals are its own: crack-free as it is). Either
 * way a displacement along N moves them by a constant that the renderer
 * intersects exactly. A folded face's triangles keep their corner normals. */
static void test_flat_faces_with_variables(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 0  2 0 0  0 1 0  1 1 0  2 1 0]\n"
        "  \"st\" [0 0  0.5 0  1 0  0 1  0.5 1  1 1]\n"
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 0  2 0 0  0 1 0  1 1 0  2 1 0]\n"
        "  \"st\" [0 0  0.5 0  1 0  0 1  0.7 1  1 1]\n"
        "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
        "  \"P\" [0 0 0  1 0 1  2 0 0  0 1 0  1 1 1  2 1 0]\n"
        "  \"st\" [0 0  0.5 0  1 0  0 1  0.5 1  1 1]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 2 + 4 + 4);
    /* affine st: two polygons, st at every corner as given */
    const double st[6][2] = {{0, 0}, {0.5, 0}, {1, 0}, {0, 1}, {0.5, 1}, {1, 1}};
    const int quad[2][4] = {{0, 1, 4, 3}, {1, 2, 5, 4}};
    for (int f = 0; f < 2; f++) {
        const geom_surface *g = &pc[f].surface;
        assert_int_equal(g->nverts, 4);
        assert_int_equal(g->nvn, 0);
        assert_int_equal(pc[f].nprimvars, 2);        /* s and t */
        for (int i = 0; i < 4; i++) {
            /* the corner of the polygon at this point of the face */
            int c = -1;
            for (int k = 0; k < 4; k++)
                if (g->verts[i].x == (quad[f][k] % 3) && g->verts[i].y == (quad[f][k] / 3)) c = k;
            assert_true(c >= 0);
            for (int k = 0; k < 2; k++)
                assert_true(fabs(corner_value(&pc[f], k, 0, i) - st[quad[f][c]][k]) < 1e-12);
        }
    }
    /* st not affine on the first quad: triangles, flat */
    for (int i = 2; i < 6; i++) {
        assert_int_equal(pc[i].surface.nverts, 3);
        assert_int_equal(pc[i].surface.nvn, 0);
    }
    assert_true(fabs(polygon_area(pc, 2, 6) - 2) < 1e-12);
    /* folded: triangles with corner normals */
    for (int i = 6; i < 10; i++) {
        assert_int_equal(pc[i].surface.nverts, 3);
        assert_int_equal(pc[i].surface.nvn, 3);
    }
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* A flat face kept whole starts at the corner whose edge runs along s or
 * t, since a polygon's (u,v) follow its first edge: a wall's triangle whose
 * first edge is the quad's diagonal would get quadtree cells at 45 degrees
 * to its bricks. The mesh's pieces and a lone Polygon alike; st stays its
 * given value at every corner. */
static void test_faces_start_along_st(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "PointsPolygons [3 3] [0 1 3  0 3 2]\n"
        "  \"P\" [0 0 0  1 0 0  0 1 0  1 1 0]  \"st\" [0 0  1 0  0 1  1 1]\n"
        "Polygon \"P\" [0 0 0  1 1 0  0 1 0] \"st\" [0 0  1 1  0 1]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 3);
    for (int f = 0; f < 3; f++) {
        const geom_surface *g = &pc[f].surface;
        assert_int_equal(g->nverts, 3);
        /* the first edge: along x (s) or y (t), never the diagonal */
        vec3 e = v3_sub(g->verts[1], g->verts[0]);
        printf("piece %d: first edge (%g, %g, %g)\n", f, e.x, e.y, e.z);
        assert_true(e.x == 0 || e.y == 0);
        /* st at each corner is the point's own (s = x, t = y here) */
        for (int i = 0; i < 3; i++) {
            assert_true(fabs(corner_value(&pc[f], 0, 0, i) - g->verts[i].x) < 1e-12);
            assert_true(fabs(corner_value(&pc[f], 1, 0, i) - g->verts[i].y) < 1e-12);
        }
    }
    free(pc);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_variables_degenerate_instances(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "ObjectBegin 1\n"
        "PointsPolygons [3 3] [0 1 2  0 1 3] \"P\" [0 0 0  1 0 0  0 1 0  2 0 0]\n"
        "  \"N\" [0 0 1  0 0 1  0 0 1  0 0 1] \"facevarying float[2] st\" [0 0 1 0 0 1 0 0 1 1 0 0]\n"
        "ObjectEnd\n"
        "ObjectInstance 1\nTranslate 0 0 5\nObjectInstance 1\n"
        "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"Cs\" [1 0 0 1 0 0 1 0 0]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 3);
    /* both instances place the one recorded mesh: no copy */
    assert_true(s->objects[0].mesh && s->objects[0].mesh == s->objects[1].mesh);
    assert_int_equal(s->nmeshes, 2);
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:5:1: PointsPolygons: 1 face without area skipped");
    /* the variables travel with the recorded face to both instances: st
     * as s and t; the vertex Cs, the same at every corner, is constant */
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 3);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(pc[i].object, i);
        assert_int_equal(pc[i].nprimvars, 2);
        assert_string_equal(pc[i].primvars[0].name, "s");
        assert_string_equal(pc[i].primvars[1].name, "t");
    }
    assert_int_equal(pc[2].nprimvars, 1);
    assert_string_equal(pc[2].primvars[0].name, "Cs");
    assert_true(pc[2].primvars[0].c[0][0] == 1 && pc[2].primvars[0].c[1][0] == 0 &&
                pc[2].primvars[0].c[4][0] == 0);
    free(pc);
    vec3 o = mat4_xform_point(&s->objects[1].object_to_world, v3(0, 0, 0));
    assert_true(vec_dist(o, v3(0, 0, 5)) < 1e-12);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case cases[] = {
    { WORLD("PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"vertex color Cs\" [1 0 0]\n"),
      "t.rib:4:52: PointsPolygons: \"Cs\" is vertex: it needs 3 values, got 1" },
    { WORLD("PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"float foo\" [1 2]\n"),
      "t.rib:4:52: PointsPolygons: \"foo\" has 2 values; give one per vertex (3), per varying "
      "point (3), per face corner (3), per face (1) or one" },
    { WORLD("PointsPolygons [3 2] [0 1 2 0 1] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:16: PointsPolygons: the vertex counts (nvertices): entry 1 is 2, expected a "
      "whole number >= 3" },
    { WORLD("PointsPolygons [3] [0 1 2 0] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:20: PointsPolygons: the loops have 3 points in all, but 4 vertex indices are "
      "given" },
    { WORLD("PointsPolygons [3] [0 1 3] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:28: PointsPolygons: \"P\" has 3 points, but the vertex indices go up to 3" },
    { WORLD("PointsPolygons [3] [0 1 -2] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:20: PointsPolygons: the vertex indices: entry 2 is -2, expected a whole "
      "number >= 0" },
    { WORLD("PointsPolygons [3] [0 1 2]\n"),
      "t.rib:4:1: PointsPolygons: missing the points: add \"P\" [x y z x y z ...]" },
    /* every kind of geometry checks its "P" the same way (rib_params_points) */
    { WORLD("PointsPolygons [3] [0 1 2] \"vertex float P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:28: PointsPolygons: \"P\" must be declared as a point, not a float" },
    { WORLD("PointsGeneralPolygons [1] [3] [0 1 2]\n"),
      "t.rib:4:1: PointsGeneralPolygons: missing the points: add \"P\" [x y z x y z ...]" },
    { WORLD("GeneralPolygon [3] \"vertex color P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:20: GeneralPolygon: \"P\" must be declared as a point, not a color" },
    { WORLD("PatchMesh \"bilinear\" 2 \"nonperiodic\" 2 \"nonperiodic\" \"constant color Cs\" [1 0 0]\n"),
      "t.rib:4:1: PatchMesh: missing the points: add \"P\" [x y z x y z ...]" },
    { WORLD("SubdivisionMesh \"catmull-clark\" [3] [0 1 2] \"vertex normal P\" [0 0 1 0 0 1 0 0 1]\n"),
      "t.rib:4:45: SubdivisionMesh: \"P\" must be declared as a point, not a normal" },
    { WORLD("PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1]\n"),
      "t.rib:4:32: PointsPolygons: parameter \"P\" is a point and needs a multiple of 3 "
      "numbers, got 8" },
    { WORLD("PointsGeneralPolygons [2] [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:27: PointsGeneralPolygons: the faces have 2 loops in all, but 1 vertex counts "
      "are given" },
    /* a bow tie with its loops crossing: cannot be cut */
    { WORLD("PointsGeneralPolygons [2] [4 3] [0 1 2 3 4 5 6] \"P\" [0 0 0  4 0 0  4 4 0  0 4 0"
            "  -1 1 0  5 1 0  2 3 0]\n"),
      "t.rib:4:33: PointsGeneralPolygons: face 0: the polygon cannot be cut into triangles "
      "(do its edges cross?)" },
    /* a hole outside its face */
    { WORLD("GeneralPolygon [3 3] \"P\" [0 0 0  1 0 0  0 1 0   5 5 0  6 5 0  5 6 0]\n"),
      "t.rib:4:16: GeneralPolygon: face 0: hole 1 cannot be joined to the boundary (does it "
      "lie outside, or do loops cross?)" },
};

static void test_errors(void **state)
{
    (void)state;
    expect_first_errors(cases, sizeof cases / sizeof cases[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube),
        cmocka_unit_test(test_normals),
        cmocka_unit_test(test_flat_faces_with_variables),
        cmocka_unit_test(test_faces_start_along_st),
        cmocka_unit_test(test_cut_faces),
        cmocka_unit_test(test_variables_degenerate_instances),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
