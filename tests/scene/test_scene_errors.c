/*
 * tests/scene/test_scene_errors.c: malformed scenes. Each case is a short
 * RIB text and the exact first diagnostic it must give, as
 * "file:line:col: message"; every message names the request. Also: the
 * rendered form with the source line and caret, unknown requests (one
 * warning per name, then skipped with their arguments), recovery (one
 * typo gives one error, later requests still parse), and that warnings
 * alone do not fail a parse.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"
#define SPHERE "Sphere 1 -1 1 360\n"

/* error_case: scene_testing.h */
static const error_case cases[] = {
    /* lexical */
    { WORLD("Translate 1.2.3 0 0\n" SPHERE),
      "t.rib:4:11: Translate: bad number '1.2.3'" },
    { WORLD("Surface \"plastic\n" SPHERE),
      "t.rib:4:9: Surface: unterminated string (missing '\"' before the end of the line)" },
    { WORLD("Scale 1 1 1e999\n" SPHERE),
      "t.rib:4:11: Scale: number '1e999' is out of range" },
    { WORLD("Color 1 0 % 0\n" SPHERE),
      "t.rib:4:11: Color: unexpected character '%'" },
    { WORLD("Translate [1 2 3\n" SPHERE),
      "t.rib:4:11: Translate: '[' is never closed (missing ']')" },
    { WORLD("Translate [1 [2] 3]\n" SPHERE),
      "t.rib:4:14: Translate: arrays cannot be nested ('[' inside '[')" },
    { WORLD("Surface \"s\" \"a\" [1 \"x\"]\n" SPHERE),
      "t.rib:4:20: Surface: an array cannot mix numbers and strings" },
    { WORLD("Sphere 1 -1 1 360 ]\n"),
      "t.rib:4:19: Sphere: ']' without a matching '['" },
    { "1 2 3\n" WORLD(SPHERE),
      "t.rib:1:1: expected a request name, got a number" },
    /* argument counts and values */
    { WORLD("Basis \"bezier\" [] \"bezier\" 3\n" SPHERE),     /* found by fuzz_rib */
      "t.rib:4:16: Basis: the u step must be a whole number from 1 to 4" },
    { "Option \"trace\" \"maxdepth\" [40]\n" WORLD(SPHERE),
      "t.rib:1:16: Option: \"maxdepth\" must be a whole number from 0 to 16, got 40" },
    { WORLD("Shader \"layer\" \"base\"\n" SPHERE),
      "t.rib:4:1: Shader: RSL 2 co-shaders are not supported: aafarm compiles each shader "
      "on its own; put the co-shader's code in a function of the shader that uses it" },
    { WORLD("Sphere 1 -1 1\n"),
      "t.rib:4:1: Sphere: expected 4 numbers (radius zmin zmax thetamax), got 3" },
    { WORLD("Translate 1 2 3 4\n" SPHERE),
      "t.rib:4:1: Translate: expected 3 numbers (dx dy dz), got 4" },
    { WORLD("Rotate 30 0 0 0\n" SPHERE),
      "t.rib:4:1: Rotate: the rotation axis is (0, 0, 0)" },
    { WORLD("Color 1 0 0 \"red\"\n" SPHERE),
      "t.rib:4:13: Color: unexpected extra argument (a string)" },
    { "Format 640.5 480 1\n" "Projection \"perspective\"\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:1:1: Format: the image size must be whole numbers from 1 to 65536, got 640.5 x 480" },
    { "Format 64 32 1\nProjection \"fisheye\"\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:2:12: Projection: unsupported projection \"fisheye\" (supported: \"perspective\", "
      "\"orthographic\")" },
    { "Format 64 32 1\nProjection \"perspective\" \"fov\" 180\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:2:26: Projection: \"fov\" must be between 0 and 180 degrees, got 180" },
    { WORLD("Sides 3\n" SPHERE),
      "t.rib:4:1: Sides: must be 1 or 2, got 3" },
    { WORLD("Orientation \"up\"\n" SPHERE),
      "t.rib:4:13: Orientation: unknown orientation \"up\" (expected \"outside\", \"inside\", "
      "\"lh\" or \"rh\")" },
    { CAMERA "PixelFilter \"mitchell\" 2 2\n" "WorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:3:13: PixelFilter: unknown filter \"mitchell\" (supported: box, gaussian, "
      "triangle, catmull-rom, sinc)" },
    /* blocks */
    { WORLD("AttributeEnd\n" SPHERE),
      "t.rib:4:1: AttributeEnd: there is no open AttributeBegin to close" },
    { WORLD("AttributeBegin\n" SPHERE),
      "t.rib:6:1: WorldEnd: the AttributeBegin opened at t.rib:4:1 is not closed "
      "(missing AttributeEnd)" },
    { WORLD("AttributeBegin\n  TransformBegin\n" SPHERE "AttributeEnd\n"),
      "t.rib:7:1: AttributeEnd: the TransformBegin opened at t.rib:5:3 is not closed "
      "(missing TransformEnd)" },
    { CAMERA "WorldBegin\n" SPHERE "  AttributeBegin\n",
      "t.rib:5:3: AttributeBegin: this block is never closed (missing AttributeEnd)" },
    { CAMERA "WorldBegin\n" SPHERE,
      "t.rib:3:1: WorldBegin: this block is never closed (missing WorldEnd)" },
    { WORLD("WorldBegin\n" SPHERE),
      "t.rib:4:1: WorldBegin: the world opened at t.rib:3:1 is still open (missing WorldEnd)" },
    { WORLD(SPHERE) "WorldBegin\nWorldEnd\n",
      "t.rib:6:1: WorldBegin: a scene has one world, and the one at t.rib:3:1 is closed "
      "(put all objects in it)" },
    { WORLD("TransformEnd\n" SPHERE),
      "t.rib:4:1: TransformEnd: there is no open TransformBegin to close" },
    /* where requests may appear */
    { CAMERA SPHERE "WorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:3:1: Sphere: must come between WorldBegin and WorldEnd" },
    { WORLD("MotionEnd\n" SPHERE),
      "t.rib:4:1: MotionEnd: there is no open MotionBegin to close" },
    { WORLD("MotionBegin [0 1]\nMotionBegin [0 1]\n" SPHERE "MotionEnd\n"),
      "t.rib:5:1: MotionBegin: the MotionBegin at t.rib:4:1 is still open (missing MotionEnd)" },
    { WORLD(SPHERE "MotionBegin [0 1]\n"),
      "t.rib:5:1: MotionBegin: this block is never closed (missing MotionEnd)" },
    { CAMERA "WorldBegin\n" SPHERE "WorldEnd\nLightSource \"pointlight\" 1\n",
      "t.rib:6:1: LightSource: must come between WorldBegin and WorldEnd" },
    /* the scene as a whole */
    { "Format 64 32 1\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:2:1: WorldBegin: the scene has no camera: add Projection \"perspective\" "
      "\"fov\" [45] (or Projection \"orthographic\") before WorldBegin" },
    { "Projection \"perspective\"\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:2:1: WorldBegin: the image has no size: add Format <xresolution> <yresolution> "
      "1 before WorldBegin, e.g. Format 640 480 1" },
    { WORLD("LightSource \"ambientlight\" 1\n"),
      "t.rib:5:1: WorldEnd: the world has no objects (add a surface between WorldBegin and "
      "WorldEnd, e.g. Sphere 1 -1 1 360)" },
    { CAMERA,
      "t.rib:0:0: the scene has no world (add WorldBegin, then the lights and objects, then "
      "WorldEnd)" },
    { CAMERA "Scale 1 0 1\nWorldBegin\n" SPHERE "WorldEnd\n",
      "t.rib:4:1: WorldBegin: the camera transform is singular (check the Scale, Transform "
      "and ConcatTransform requests before WorldBegin)" },
    { WORLD("Scale 0 0 0\n" SPHERE),
      "t.rib:5:1: Sphere: the current transform is singular (a Scale by 0?)" },
    /* shaders, lights, parameters */
    { WORLD("Surface \"plastic\" \"frequency\" 3\n" SPHERE),
      "t.rib:4:19: Surface: parameter \"frequency\" is not declared (add Declare "
      "\"frequency\" \"float\" before it, or write the type in the name: \"float frequency\")" },
    { WORLD("Surface \"../lib/plastic\"\n" SPHERE),
      "t.rib:4:9: Surface: the shader name \"../lib/plastic\" must be a plain name (letters, "
      "digits, '_'); put its folder on the search path with Option \"searchpath\" \"shader\" "
      "[\"dir:&\"]" },
    { WORLD("LightSource \"../lamps/arealight\" 1\n" SPHERE),
      "t.rib:4:13: LightSource: the shader name \"../lamps/arealight\" must be a plain name "
      "(letters, digits, '_'); put its folder on the search path with Option \"searchpath\" "
      "\"shader\" [\"dir:&\"]" },
    { WORLD("LightSource \"pointlight\" 1 \"from\" [1 2]\n" SPHERE),
      "t.rib:4:35: LightSource: parameter \"from\" is a point and needs 3 numbers, got 2" },
    { WORLD("Illuminate 7 1\n" SPHERE),
      "t.rib:4:12: Illuminate: no light has the handle 7" },
    { WORLD("CoordSysTransform \"lamp\"\n" SPHERE),
      "t.rib:4:19: CoordSysTransform: no coordinate system named \"lamp\" (define it first "
      "with CoordinateSystem \"lamp\")" },
    /* base surfaces */
    { WORLD("Polygon \"P\" [0 0 0 1 0 0]\n"),
      "t.rib:4:9: Polygon: a polygon needs at least 3 vertices, got 2" },
    { WORLD("Polygon \"P\" [0 0 0 1 0 0 1 1]\n"),
      "t.rib:4:13: Polygon: parameter \"P\" is a point and needs a multiple of 3 numbers, got 8" },
    { WORLD("Polygon \"N\" [0 0 1 0 0 1 0 0 1]\n"),
      "t.rib:4:1: Polygon: missing the vertices: add \"P\" [x y z x y z ...]" },
    { WORLD("Patch \"biquadratic\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"),
      "t.rib:4:7: Patch: unknown patch type \"biquadratic\" (expected \"bilinear\" or "
      "\"bicubic\")" },
    { WORLD("Patch \"bicubic\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n"),
      "t.rib:4:17: Patch: a bicubic patch needs 16 points in \"P\" (48 numbers), got 12 "
      "numbers" },
    { WORLD("Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0]\n"),
      "t.rib:4:18: Patch: a bilinear patch needs 4 points in \"P\" (12 numbers), got 9 numbers" },
    { WORLD("Attribute \"displacementbound\" \"sphere\" [-1]\n" SPHERE),
      "t.rib:4:31: Attribute: \"sphere\" must be >= 0, got -1" },
};

static void test_error_cases(void **state)
{
    (void)state;
    int n = (int)(sizeof cases / sizeof cases[0]), failed = 0;
    for (int i = 0; i < n; i++) {
        sl_diag *d;
        scene *s = parse_rib(cases[i].text, &d);
        const char *got = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
        if (s || strcmp(got, cases[i].first_error) != 0) {
            print_error("case %d:\n  got  %s\n  want %s\n  scene %s\n", i, got,
                        cases[i].first_error, s ? "returned" : "NULL");
            failed++;
        }
        scene_destroy(&s);
        sl_diag_destroy(&d);
    }
    assert_int_equal(failed, 0);
}

/* Too many vertices: at most GEOM_MAX_POLY_VERTS. */
static void test_polygon_too_many_vertices(void **state)
{
    (void)state;
    char text[8192];
    int len = snprintf(text, sizeof text, CAMERA "WorldBegin\nPolygon \"P\" [");
    for (int i = 0; i < GEOM_MAX_POLY_VERTS + 1; i++) {
        double a = 2 * M_PI * i / (GEOM_MAX_POLY_VERTS + 1);
        len += snprintf(text + len, sizeof text - (size_t)len, " %.6f %.6f 0", cos(a), sin(a));
    }
    snprintf(text + len, sizeof text - (size_t)len, "]\nWorldEnd\n");
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    assert_null(s);
    char want[256];
    snprintf(want, sizeof want, "t.rib:4:9: Polygon: at most %d vertices are supported, got %d",
             GEOM_MAX_POLY_VERTS, GEOM_MAX_POLY_VERTS + 1);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), want);
    sl_diag_destroy(&d);
}

/* Invalid surface parameters: the reason comes from the surface check
 * (geom_surface_prepare); the message names the request and its place. */
static void test_invalid_surface_parameters(void **state)
{
    (void)state;
    static const char *const texts[] = {
        WORLD("Sphere -1 -1 1 360\n"),
        WORLD("Cylinder 1 1 1 360\n"),              /* equal ends: nothing */
        WORLD("Torus 1 0 0 360 360\n"),
        WORLD("Hyperboloid 1 0 0 1 0 0 360\n"),
        WORLD("Polygon \"P\" [0 0 0  1 0 0  1 1 1  0 1 0]\n"),   /* not planar */
    };
    static const char *const prefixes[] = { "Sphere: ", "Cylinder: ", "Torus: ", "Hyperboloid: ",
                                            "Polygon: " };
#ifdef SCENE_HAVE_GEOM
    int ncases = 5;
#else
    int ncases = 4;   /* the stand-in checks do not test planarity */
#endif
    for (int i = 0; i < ncases; i++) {
        sl_diag *d;
        scene *s = parse_rib(texts[i], &d);
        assert_null(s);
        const sl_diagnostic *e = nth_diag(d, SL_DIAG_ERROR, 0);
        assert_non_null(e);
        /* one error: no "the world has no objects" after it */
        assert_int_equal(sl_diag_error_count(d), 1);
        assert_int_equal(e->line, 4);
        assert_int_equal(e->col, 1);
        size_t n = strlen(prefixes[i]);
        assert_memory_equal(e->message, prefixes[i], n);
        assert_true(strlen(e->message) > n + 5);
        sl_diag_destroy(&d);
    }
}

/* The printed form: position, message, source line, caret. */
static void test_rendered_diagnostic(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD("\tTranslate 1 2 $3\n" SPHERE), &d);
    assert_null(s);
    char *text = sl_diag_to_string(d);
    assert_string_equal(text, "t.rib:4:16: error: Translate: unexpected character '$'\n"
                              "\tTranslate 1 2 $3\n"
                              "\t              ^\n");
    free(text);
    sl_diag_destroy(&d);
}

/* Unknown requests: one warning per name, skipped with their arguments;
 * the scene still parses. Requests a ray tracer has no use for say so. */
static void test_unknown_requests(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(CAMERA "Hider \"hidden\" \"jitter\" [1]\nWorldBegin\n"
        "Frobnicate \"a.tif\" \"a.tx\" \"periodic\" [1 2 3]\nsphere 1 -1 1 360\n"
        "Frobnicate \"b.tif\" \"b.tx\"\nSphere 1 -1 1 360\nHider \"x\"\nWorldEnd\n", &d);
    assert_non_null(s);
    assert_int_equal(sl_diag_error_count(d), 0);
    assert_int_equal(sl_diag_warning_count(d), 3);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:3:1: Hider: has no use in aafarm's ray tracer; ignored (every "
                        "pixel is ray-traced)");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 1)),
                        "t.rib:5:1: Frobnicate: unknown request, ignored with its arguments");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 2)),
                        "t.rib:6:1: sphere: unknown request, ignored with its arguments "
                        "(did you mean Sphere?)");
    assert_int_equal(s->nobjects, 1);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* "did you mean WorldBegin?" (issue 26): an unknown request near a known
 * one names it; a misspelt block opener or closer is the first error and
 * is read as the block it is closest to, so no cascade follows it. */
static void test_did_you_mean(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(CAMERA "WorldBegn\nSpere 1 -1 1 360\nAttributeBegin\n"
        "Sphere 1 -1 1 360\nAtributeEnd\nWorldEnd\n", &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 2);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:3:1: WorldBegn: unknown request (did you mean WorldBegin?); "
                        "read as WorldBegin for the rest of the checks");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 1)),
                        "t.rib:7:1: AtributeEnd: unknown request (did you mean AttributeEnd?); "
                        "read as AttributeEnd for the rest of the checks");
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:4:1: Spere: unknown request, ignored with its arguments "
                        "(did you mean Sphere?)");
    sl_diag_destroy(&d);

    /* a case-only difference of a block request is read as it too;
     * Frobnicate is too far from every name for a suggestion (the one
     * later error is the empty world's: the sphere was skipped) */
    s = parse_rib(CAMERA "worldbegin\nSphear 1 -1 1 360\nFrobnicate\nWorldEnd\n", &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 2);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:3:1: worldbegin: unknown request (did you mean WorldBegin?); "
                        "read as WorldBegin for the rest of the checks");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                        "t.rib:4:1: Sphear: unknown request, ignored with its arguments "
                        "(did you mean Sphere?)");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 1)),
                        "t.rib:5:1: Frobnicate: unknown request, ignored with its arguments");
    sl_diag_destroy(&d);
}

/* Lenient where other renderers are (issue 14): requests of scanline
 * renderers and primitives aafarm does not render are warned about once
 * per name with file:line and skipped; options inside the world are
 * warned about and ignored; a motion block uses its first time sample. */
static void test_lenient_requests(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(
        "Format 64 32 1\nHider \"hidden\"\nProjection \"perspective\"\n"     /* 1-3 */
        "MakeShadow \"a.z\" \"a.shd\"\nShadingInterpolation \"smooth\"\n"   /* 4-5 */
        "WorldBegin\nGeometricApproximation \"motionfactor\" 1\n"               /* 6-7 */
        "Format 10 10 1\nPixelSamples 9 9\nFormat 20 20 1\n"                     /* 8-10 */
        "Atmosphere \"fog\"\nInterior \"x\"\nExterior \"y\"\n"                 /* 11-13 */
        "Blobby 2 [1001 0 1001 16 0 2] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1  "
        "1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 1] [\"\"]\n"                                 /* 14 */
        "Curves \"cubic\" [4] \"nonperiodic\" \"P\" [0 0 0 1 1 1 2 2 2 3 3 3] "
        "\"constantwidth\" [0.1]\n"                                               /* 15 */
        "Points \"P\" [0 0 0 1 1 1] \"width\" [0.1 0.1]\n"                          /* 16 */
        "Blobby 1 [1001 0] [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1] [\"\"]\n"              /* 17 */
        "MotionBegin [0 1]\nTranslate 1 0 0\nTranslate 5 0 0\nMotionEnd\n"       /* 18-21 */
        "Sphere 1 -1 1 360\nSystem \"rm -rf /\"\nWorldEnd\n", &d);               /* 22-24 */
    if (!s) sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_error_count(d), 0);
    static const char *const want[] = {
        "t.rib:2:1: Hider: has no use in aafarm's ray tracer; ignored (every pixel is "
        "ray-traced)",
        "t.rib:4:1: MakeShadow: has no use in aafarm's ray tracer; ignored (shadows are "
        "ray-traced)",
        "t.rib:5:1: ShadingInterpolation: has no use in aafarm's ray tracer; ignored (shaders "
        "run at every hit)",
        "t.rib:7:1: GeometricApproximation: has no use in aafarm's ray tracer; ignored "
        "(surfaces are intersected directly, not diced)",
        "t.rib:8:1: Format: options are fixed at WorldBegin; ignored inside the world (move "
        "it before WorldBegin)",
        "t.rib:9:1: PixelSamples: options are fixed at WorldBegin; ignored inside the world "
        "(move it before WorldBegin)",
        "t.rib:11:1: Atmosphere: has no use in aafarm's ray tracer; ignored (no volume "
        "shaders)",
        "t.rib:12:1: Interior: has no use in aafarm's ray tracer; ignored (no volume shaders)",
        "t.rib:13:1: Exterior: has no use in aafarm's ray tracer; ignored (no volume shaders)",
        "t.rib:14:1: Blobby: blobby implicit surfaces are not rendered; skipped",
        "t.rib:15:1: Curves: curves are not rendered; skipped",
        "t.rib:16:1: Points: point clouds are not rendered; skipped",
        "t.rib:18:1: MotionBegin: motion blur is not rendered: each motion block uses its "
        "first time sample",
        "t.rib:23:1: System: runs no commands; ignored (a scene cannot run programs on the "
        "farm)",
    };
    int n = (int)(sizeof want / sizeof want[0]);
    assert_int_equal(sl_diag_warning_count(d), n);   /* one per name */
    for (int i = 0; i < n; i++)
        assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, i)), want[i]);
    /* the options inside the world changed nothing */
    assert_int_equal(s->camera.xres, 64);
    assert_int_equal(s->pixel_samples[0], 2);
    /* only the sphere is an object, moved by the first time sample */
    assert_int_equal(s->nobjects, 1);
    vec3 c = mat4_xform_point(&s->objects[0].object_to_world, v3(0, 0, 0));
    assert_true(vec_dist(c, v3(1, 0, 0)) < 1e-15);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* Garbage with many distinct names: at most 100 warnings and a last one
 * that says no more come. */
static void test_many_unknown_requests(void **state)
{
    (void)state;
    char text[8192];
    int len = snprintf(text, sizeof text, "%s", CAMERA "WorldBegin\n" SPHERE);
    for (int i = 0; i < 150; i++)
        len += snprintf(text + len, sizeof text - (size_t)len, "Unknown%d 1 \"a\"\n", i);
    snprintf(text + len, sizeof text - (size_t)len, "WorldEnd\n");
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 101);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 100)),
                        "t.rib:105:1: Unknown100: unknown request, ignored with its arguments; "
                        "100 unknown names so far: not reporting more");
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* One typo, one error: the broken request is dropped, the rest parses and
 * reports its own errors. */
static void test_recovery(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD("Translate 1 2 3q\nSphere 1 -1 1\nAttributeBegin\n"
                               "Sphere 1 -1 1 360\nAttributeEnd\nDisk 0 0 0\n"), &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 3);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
                        "t.rib:4:15: Translate: bad number '3q'");
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 1)),
                        "t.rib:5:1: Sphere: expected 4 numbers (radius zmin zmax thetamax), got 3");
    const sl_diagnostic *third = nth_diag(d, SL_DIAG_ERROR, 2);
    assert_int_equal(third->line, 9);
    assert_memory_equal(third->message, "Disk: ", 6);
    sl_diag_destroy(&d);
}

/* Errors that were in the diag before do not count against this parse;
 * the source set the parser attached is removed again. */
static void test_earlier_errors_and_sources(void **state)
{
    (void)state;
    sl_diag *d = sl_diag_new();
    sl_pos none = { NULL, 0, 0 };
    sl_diag_error(d, none, "an earlier error");
    const char *text = WORLD(SPHERE);
    scene *s = scene_parse("t.rib", text, strlen(text), d);
    assert_non_null(s);
    scene_destroy(&s);
    /* no carets after the parse: the private source set is gone */
    sl_pos pos = { "t.rib", 1, 1 };
    sl_diag_error(d, pos, "later");
    assert_null(sl_diag_get(d, sl_diag_count(d) - 1)->source_line);
    sl_diag_destroy(&d);
}

static void test_load_missing_file(void **state)
{
    (void)state;
    sl_diag *d = sl_diag_new();
    assert_null(scene_load("/nonexistent/dir/x.rib", d));
    assert_int_equal(sl_diag_error_count(d), 1);
    assert_non_null(strstr(sl_diag_get(d, 0)->message, "/nonexistent/dir/x.rib"));
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_cases),
        cmocka_unit_test(test_polygon_too_many_vertices),
        cmocka_unit_test(test_invalid_surface_parameters),
        cmocka_unit_test(test_rendered_diagnostic),
        cmocka_unit_test(test_unknown_requests),
        cmocka_unit_test(test_did_you_mean),
        cmocka_unit_test(test_lenient_requests),
        cmocka_unit_test(test_many_unknown_requests),
        cmocka_unit_test(test_recovery),
        cmocka_unit_test(test_earlier_errors_and_sources),
        cmocka_unit_test(test_load_missing_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
