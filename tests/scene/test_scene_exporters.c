/*
 * tests/scene/test_scene_exporters.c: the RIB that exporters write
 * (issue 26), in their idioms: inline archives (ArchiveBegin "name" ...
 * ArchiveEnd, replayed by ReadArchive "name", ahead of a file of that
 * name; errors point inside the block), unknown requests inside blocks
 * (warned once, the block's contents never leak), HierarchicalSubdivisionMesh
 * (a SubdivisionMesh with a fifth tag array), TextureCoordinates (s, t
 * bilinear over (u,v) of quadrics and patches), quadrics with reversed
 * ends (RI Spec 3.2 §5.2).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"
#include "sl/source.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

static scene *parse_ok(const char *text, sl_diag **d)
{
    scene *s = parse_rib(text, d);
    if (!s)
        sl_diag_print(*d, stderr);
    assert_non_null(s);
    return s;
}

static int count_level(const sl_diag *d, sl_diag_level level)
{
    int n = 0;
    for (size_t i = 0; i < sl_diag_count(d); i++)
        n += sl_diag_get(d, i)->level == level;
    return n;
}

/* ---- inline archives ------------------------------------------------------ */

/* a Maya exporter's layout: archives defined before the world, read in it */
static const char *const DEFINED_FIRST =
    CAMERA
    "ArchiveBegin \"geo/ball\"\n"
    "  AttributeBegin\n"
    "    Color [1 0 0]\n"
    "    Sphere 0.5 -0.5 0.5 360\n"
    "  AttributeEnd\n"
    "ArchiveEnd\n"
    "WorldBegin\n"
    "  ReadArchive \"geo/ball\"\n"
    "  Translate 2 0 0\n"
    "  ReadArchive \"geo/ball\"\n"
    "  Disk 0 1 360\n"
    "WorldEnd\n";

static void test_archive_replayed(void **state)
{
    (void)state;
    sl_diag *d;
    /* the Sphere is not run at its definition (it would be an error
     * outside the world); each ReadArchive places it, in the transform
     * current there; the color stays inside the archive's block */
    scene *s = parse_ok(DEFINED_FIRST, &d);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(s->nobjects, 3);
    assert_int_equal(s->objects[0].surface->kind, GEOM_SPHERE);
    assert_int_equal(s->objects[1].surface->kind, GEOM_SPHERE);
    assert_true(s->objects[0].Cs[1] == 0 && s->objects[1].Cs[1] == 0);
    assert_true(s->objects[1].object_to_world.m[0][3] == 2);
    assert_int_equal(s->objects[2].surface->kind, GEOM_DISK);
    assert_true(s->objects[2].Cs[1] == 1);
    /* positions stay inside the block */
    assert_int_equal(s->objects[0].pos.line, 6);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* defined inside the world and never read: nothing of it leaks (its
     * Color would turn the Sphere after it green) */
    s = parse_ok(WORLD("ArchiveBegin \"unused\"\n"
                       "  Color [0 1 0]\n"
                       "  Translate 0 0 5\n"
                       "  Cylinder 1 -1 1 360\n"
                       "ArchiveEnd\n"
                       "Sphere 1 -1 1 360\n"), &d);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(s->objects[0].surface->kind, GEOM_SPHERE);
    assert_true(s->objects[0].Cs[0] == 1 && s->objects[0].Cs[1] == 1);
    assert_true(s->objects[0].object_to_world.m[2][3] == 0);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* nested: the inner archive is defined when the outer one is read;
     * defining a name again replaces it for what follows */
    s = parse_ok(WORLD("ArchiveBegin \"outer\"\n"
                       "  ArchiveBegin \"inner\"\n"
                       "    Disk 0 1 360\n"
                       "  ArchiveEnd\n"
                       "  Sphere 1 -1 1 360\n"
                       "ArchiveEnd\n"
                       "ReadArchive \"outer\"\n"
                       "ReadArchive \"inner\"\n"
                       "ArchiveBegin \"inner\" \"string note\" [\"v2\"]\n"
                       "  Cone 1 1 360\n"
                       "ArchiveEnd\n"
                       "ReadArchive \"inner\"\n"), &d);
    assert_int_equal(s->nobjects, 3);
    assert_int_equal(s->objects[0].surface->kind, GEOM_SPHERE);
    assert_int_equal(s->objects[1].surface->kind, GEOM_DISK);
    assert_int_equal(s->objects[2].surface->kind, GEOM_CONE);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* A name defined inline wins over a file of that name; before the
 * definition, ReadArchive reads the file. */
static void test_archive_before_file(void **state)
{
    (void)state;
    const char *text = WORLD("ReadArchive \"part.rib\"\n"
                             "ArchiveBegin \"part.rib\"\n"
                             "  Sphere 1 -1 1 360\n"
                             "ArchiveEnd\n"
                             "ReadArchive \"part.rib\"\n");
    sl_source_set *set = sl_source_set_new();
    assert_int_equal(sl_source_set_add(set, "part.rib", "Disk 0 1 360\n", 13), 0);
    sl_diag *d = sl_diag_new();
    scene *s = scene_parse_archives("t.rib", text, strlen(text), set, d);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 2);
    assert_int_equal(s->objects[0].surface->kind, GEOM_DISK);
    assert_int_equal(s->objects[1].surface->kind, GEOM_SPHERE);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    sl_source_set_destroy(&set);
}

static const error_case archive_errors[] = {
    /* an error inside the block: its own place, and the ReadArchive's */
    { WORLD("ArchiveBegin \"a\"\n"
            "  Sphere 1 2\n"
            "ArchiveEnd\n"
            "ReadArchive \"a\"\n"),
      "t.rib:5:3: Sphere: expected 4 numbers (radius zmin zmax thetamax), got 2 (in archive a "
      "read at t.rib:7:1)" },
    { WORLD("ArchiveBegin \"a\"\n"
            "  ReadArchive \"a\"\n"
            "ArchiveEnd\n"
            "Sphere 1 -1 1 360\n"
            "ReadArchive \"a\"\n"),
      "t.rib:5:15: ReadArchive: archive \"a\" (defined at t.rib:4:1) reads itself: it is "
      "already being read (in archive a read at t.rib:8:1)" },
    { WORLD("Sphere 1 -1 1 360\n"
            "ArchiveEnd\n"),
      "t.rib:5:1: ArchiveEnd: there is no open ArchiveBegin to close" },
    { WORLD("Sphere 1 -1 1 360\n"
            "ArchiveBegin \"never\"\n"
            "  Disk 0 1 360\n"),
      "t.rib:5:1: ArchiveBegin: this block is never closed in its file (missing ArchiveEnd)" },
    { WORLD("ArchiveBegin [1]\n"
            "ArchiveEnd\n"
            "Sphere 1 -1 1 360\n"),
      "t.rib:4:14: ArchiveBegin: the archive name must be a string, got an array of numbers" },
    /* a misspelt block request is read as the block it is closest to, so
     * the block's contents are recorded, not placed */
    { WORLD("ArchiveBegn \"a\"\n"
            "  Translate 0 0 -10\n"
            "ArchiveEnd\n"
            "Sphere 1 -1 1 360\n"),
      "t.rib:4:1: ArchiveBegn: unknown request (did you mean ArchiveBegin?); read as "
      "ArchiveBegin for the rest of the checks" },
};

static void test_archive_errors(void **state)
{
    (void)state;
    expect_first_errors(archive_errors, sizeof archive_errors / sizeof archive_errors[0]);
}

/* ---- unknown requests inside blocks -------------------------------------- */

static void test_unknown_in_blocks(void **state)
{
    (void)state;
    sl_diag *d;
    /* an unknown request with arguments of every kind inside an attribute
     * block, an object definition and an archive: one warning per name,
     * the blocks close where they should and nothing set inside leaks */
    scene *s = parse_ok(WORLD("AttributeBegin\n"
                              "  Frobnicate \"mode\" [1 2 3] 4 [\"a\" \"b\"]\n"
                              "  Color [0 1 0]\n"
                              "  Sphere 1 -1 1 360\n"
                              "  Frobnicate\n"
                              "AttributeEnd\n"
                              "ObjectBegin 1\n"
                              "  Frobnicate 7\n"
                              "  Disk 0 1 360\n"
                              "ObjectEnd\n"
                              "ArchiveBegin \"x\"\n"
                              "  Frobnicate \"AttributeEnd\"\n"
                              "ArchiveEnd\n"
                              "ReadArchive \"x\"\n"
                              "ObjectInstance 1\n"
                              "Sphere 2 -2 2 360\n"), &d);
    assert_int_equal(sl_diag_error_count(d), 0);
    assert_int_equal(count_level(d, SL_DIAG_WARNING), 1);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:5:3: Frobnicate: unknown request, ignored with its arguments");
    assert_int_equal(s->nobjects, 3);
    assert_true(s->objects[0].Cs[0] == 0);          /* green inside the block */
    assert_int_equal(s->objects[1].surface->kind, GEOM_DISK);
    assert_true(s->objects[1].Cs[0] == 1);          /* white after it */
    assert_true(s->objects[2].Cs[0] == 1 && s->objects[2].surface->radius == 2);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* ---- HierarchicalSubdivisionMesh ----------------------------------------- */

#define CUBE_FACES "[4 4 4 4 4 4] [0 3 2 1  4 5 6 7  0 1 5 4  1 2 6 5  2 3 7 6  3 0 4 7]"
#define CUBE_P "\"P\" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]"

static int count_kind(const scene *s, geom_kind k)
{
    int n = 0, np;
    test_piece *pc = scene_pieces(s, &np);
    for (int i = 0; i < np; i++) n += pc[i].surface.kind == k;
    free(pc);
    return n;
}

static void test_hierarchical_subdivision(void **state)
{
    (void)state;
    sl_diag *d;
    /* three counts per tag, a string array; a hole and a crease as in
     * SubdivisionMesh; the edit tags warned and ignored */
    scene *s = parse_ok(WORLD("HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES
                              " [\"crease\" \"hole\" \"vertexedit\"] [2 1 0  1 0 0  2 0 2]"
                              " [0 1  5  1 0] [10] [\"value\" \"add\"] " CUBE_P "\n"), &d);
    assert_int_equal(s->nsubdivs, 1);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 20);
    assert_int_equal(count_level(d, SL_DIAG_WARNING), 1);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                           "HierarchicalSubdivisionMesh: tag \"vertexedit\" is not supported: "
                           "ignored"));
    scene_destroy(&s);
    sl_diag_destroy(&d);
    /* the tag arrays left out, and empty */
    s = parse_ok(WORLD("HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES " " CUBE_P "\n"
                       "HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES
                       " [] [] [] [] [] " CUBE_P "\n"), &d);
    assert_int_equal(count_kind(s, GEOM_SUBDIV), 48);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case hsm_errors[] = {
    { WORLD("HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES
            " [\"crease\"] [2 1] [0 1] [10] [] " CUBE_P "\n"),
      "t.rib:4:125: HierarchicalSubdivisionMesh: nargs has 2 numbers, expected 3 per tag "
      "(1 tags)" },
    { WORLD("HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES
            " [\"vertexedit\"] [0 0 2] [] [] [\"a\"] " CUBE_P "\n"),
      "t.rib:4:129: HierarchicalSubdivisionMesh: nargs asks for 0 integers, 0 floats and 2 "
      "strings, but intargs has 0, floatargs 0 and stringargs 1" },
    { WORLD("HierarchicalSubdivisionMesh \"catmull-clark\" " CUBE_FACES
            " [\"crease\"] [2 1 0] [0 1] [10] " CUBE_P "\n"),
      "t.rib:4:114: HierarchicalSubdivisionMesh: the tags need four more arrays: [nargs] "
      "[intargs] [floatargs] [stringargs]" },
};

static void test_hierarchical_errors(void **state)
{
    (void)state;
    expect_first_errors(hsm_errors, sizeof hsm_errors / sizeof hsm_errors[0]);
}

/* ---- TextureCoordinates --------------------------------------------------- */

static const scene_primvar *find_var(const scene_object *o, const char *name)
{
    for (int i = 0; i < o->nprimvars; i++)
        if (strcmp(o->primvars[i].name, name) == 0)
            return &o->primvars[i];
    return NULL;
}

/* a primitive variable's value at (u,v) */
static double var_at(const scene_primvar *v, double u, double w)
{
    double sum = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            sum += v->c[i + 4 * j][0] * pow(u, i) * pow(w, j);
    return sum;
}

static void test_texture_coordinates(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_ok(WORLD("AttributeBegin\n"
                              "  TextureCoordinates 0 1  2 1  0 0  2 0\n"   /* t flipped, s x2 */
                              "  Sphere 1 -1 1 360\n"
                              "  Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0] "
                              "\"st\" [5 5 6 5 5 6 6 6]\n"
                              "  Polygon \"P\" [0 0 0 1 0 0 1 1 0]\n"
                              "AttributeEnd\n"
                              "Sphere 1 -1 1 360\n"
                              "TextureCoordinates [0 0 1 0 0 1 1 1]\n"
                              "Cylinder 1 -1 1 360\n"), &d);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(s->nobjects, 5);
    const scene_primvar *vs = find_var(&s->objects[0], "s");
    const scene_primvar *vt = find_var(&s->objects[0], "t");
    assert_non_null(vs);
    assert_non_null(vt);
    double corners[4][4] = { { 0, 0, 0, 1 }, { 1, 0, 2, 1 }, { 0, 1, 0, 0 }, { 1, 1, 2, 0 } };
    for (int k = 0; k < 4; k++) {
        assert_true(fabs(var_at(vs, corners[k][0], corners[k][1]) - corners[k][2]) < 1e-12);
        assert_true(fabs(var_at(vt, corners[k][0], corners[k][1]) - corners[k][3]) < 1e-12);
    }
    assert_true(fabs(var_at(vs, 0.25, 0.5) - 0.5) < 1e-12);
    /* the patch's own st wins: s is 5 at (0,0) */
    assert_true(fabs(var_at(find_var(&s->objects[1], "s"), 0, 0) - 5) < 1e-12);
    assert_null(find_var(&s->objects[2], "s"));    /* polygons keep their own */
    assert_int_equal(s->objects[3].nprimvars, 0);  /* restored by AttributeEnd */
    assert_int_equal(s->objects[4].nprimvars, 0);  /* the default: s = u, t = v */
    scene_destroy(&s);
    sl_diag_destroy(&d);

    s = parse_rib(WORLD("TextureCoordinates 0 0 1 0 0 1 1\nSphere 1 -1 1 360\n"), &d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:4:1: TextureCoordinates: expected 8 numbers (s1 t1 s2 t2 s3 t3 "
                        "s4 t4), got 7");
    sl_diag_destroy(&d);
}

/* ---- quadrics with the parameters the specification allows ---------------- */

static void test_quadrics_reversed(void **state)
{
    (void)state;
    sl_diag *d;
    /* RI Spec 3.2 §5.2: the ends in either order, negative sweeps */
    scene *s = parse_ok(WORLD("Cylinder 0.5 1 -1 360\n"
                              "Sphere 1 0.5 -1 -270\n"
                              "Paraboloid 1 1 0.25 360\n"
                              "Torus 1 0.25 270 -90 360\n"
                              "Hyperboloid 1 0 1  0.5 0 -1 -360\n"), &d);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(s->nobjects, 5);
    assert_true(s->objects[0].surface->zmin == 1 && s->objects[0].surface->zmax == -1);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    s = parse_rib(WORLD("Cylinder 0.5 1 1 360\n"), &d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:4:1: Cylinder: cylinder zmin and zmax must differ, both are 1 "
                        "(nothing left)");
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_archive_replayed),
        cmocka_unit_test(test_archive_before_file),
        cmocka_unit_test(test_archive_errors),
        cmocka_unit_test(test_unknown_in_blocks),
        cmocka_unit_test(test_hierarchical_subdivision),
        cmocka_unit_test(test_hierarchical_errors),
        cmocka_unit_test(test_texture_coordinates),
        cmocka_unit_test(test_quadrics_reversed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
