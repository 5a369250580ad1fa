/*
 * tests/scene/test_scene_params.c: what the parser records from small RIB
 * texts written for each feature:
 *
 *   typing     predeclared names, inline declarations, Declare, arrays,
 *              strings, matrices; a Declare changing a standard name
 *   transforms the order of Translate/Scale/Rotate, ConcatTransform and
 *              Transform (RIB row-vector matrices), Identity, the
 *              Attribute/Transform stacks, "shader" space, named spaces
 *   lights     RenderMan defaults, light space, scope of lights declared
 *              in an attribute block, Illuminate, shadows
 *   attributes Sides, Orientation/ReverseOrientation and the normal flip,
 *              displacementbound, identifier, unknown attributes
 *   options    search path with '&' and '@', orthographic projection,
 *              ScreenWindow, frames (each one by its index)
 *
 * Expected values are written from the RIB text by hand.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

/* Parses text that must be valid (no errors, no warnings). */
static scene *parse_ok(const char *text)
{
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    if (!s || sl_diag_count(d) > 0)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_count(d), 0);
    sl_diag_destroy(&d);
    return s;
}

/* The first error's "file:line:col: message" of a text that must fail. */
static const char *parse_error(const char *text)
{
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    assert_null(s);
    assert_true(sl_diag_error_count(d) > 0);
    static char buf[2048];
    snprintf(buf, sizeof buf, "%s", diag_line(nth_diag(d, SL_DIAG_ERROR, 0)));
    sl_diag_destroy(&d);
    return buf;
}

static void assert_vec(vec3 got, vec3 want, double tol)
{
    if (vec_dist(got, want) > tol)
        fail_msg("got (%.15g %.15g %.15g), want (%.15g %.15g %.15g)", got.x, got.y, got.z,
                 want.x, want.y, want.z);
}

/* ---------------------------------------------------------------------- */
/* typing                                                                  */
/* ---------------------------------------------------------------------- */

static void test_param_typing(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\n"
        "Declare \"freq\" \"uniform float\"\n"
        "Declare \"tint\" \"color\"\n"
        "Surface \"custom\" \"Ks\" [0.5] \"uniform float amp\" 3 \"color specularcolor\" [1 0 0]\n"
        "  \"float[2] pair\" [1 2] \"string texname\" \"a.tex\" \"point center\" [1 2 3]\n"
        "  \"freq\" [7] \"tint\" [0.1 0.2 0.3] \"texturename\" [\"b.tex\"]\n"
        "  \"matrix m\" [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1] \"integer n\" 4\n"
        "Sphere 1 -1 1 360\nWorldEnd\n");
    const scene_shader *sh = scene_object_surface(s, &s->objects[0]);
    assert_int_equal(sh->nparams, 11);
    static const struct { const char *name; sl_type type; int count, arraylen; } want[] = {
        { "Ks", SL_TYPE_FLOAT, 1, 1 },       { "amp", SL_TYPE_FLOAT, 1, 1 },
        { "specularcolor", SL_TYPE_COLOR, 3, 1 }, { "pair", SL_TYPE_FLOAT, 2, 2 },
        { "texname", SL_TYPE_STRING, 1, 1 }, { "center", SL_TYPE_POINT, 3, 1 },
        { "freq", SL_TYPE_FLOAT, 1, 1 },     { "tint", SL_TYPE_COLOR, 3, 1 },
        { "texturename", SL_TYPE_STRING, 1, 1 }, { "m", SL_TYPE_MATRIX, 16, 1 },
        { "n", SL_TYPE_FLOAT, 1, 1 },
    };
    for (int i = 0; i < 11; i++) {
        const scene_param *p = &sh->params[i];
        assert_string_equal(p->name, want[i].name);
        assert_int_equal(p->type, want[i].type);
        assert_int_equal(p->count, want[i].count);
        assert_int_equal(p->arraylen, want[i].arraylen);
    }
    assert_true(scene_shader_param(sh, "amp")->values[0] == 3);
    assert_true(scene_shader_param(sh, "pair")->values[1] == 2);
    assert_string_equal(scene_shader_param(sh, "texname")->string, "a.tex");
    assert_null(scene_shader_param(sh, "texname")->values);
    assert_string_equal(scene_shader_param(sh, "texturename")->string, "b.tex");
    assert_true(scene_shader_param(sh, "tint")->values[2] == 0.3);
    assert_true(scene_shader_param(sh, "m")->values[15] == 1);
    assert_int_equal(scene_shader_param(sh, "amp")->pos.line, 6);
    assert_null(scene_shader_param(sh, "missing"));
    scene_destroy(&s);
}

static void test_declare_overrides_standard(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "Declare \"Km\" \"color\"\nWorldBegin\n"
                        "Displacement \"d\" \"Km\" [1 2 3]\nSphere 1 -1 1 360\nWorldEnd\n");
    const scene_param *km = &scene_object_displacement(s, &s->objects[0])->params[0];
    assert_int_equal(km->type, SL_TYPE_COLOR);
    assert_int_equal(km->count, 3);
    scene_destroy(&s);
}

static void test_param_errors(void **state)
{
    (void)state;
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" \"Km\" [1 2]\n"),
        "t.rib:4:18: Surface: parameter \"Km\" is a float and needs 1 number, got 2");
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" \"Km\" \"x\"\n"),
        "t.rib:4:18: Surface: parameter \"Km\" is a float and needs numbers, got a string");
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" \"texturename\" 1\n"),
        "t.rib:4:27: Surface: parameter \"texturename\" is a string and needs one string, "
        "got a number");
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" \"flaot x\" 1\n"),
        "t.rib:4:13: Surface: cannot read the declaration \"flaot x\": unknown type 'flaot'");
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" \"Km\"\n"),
        "t.rib:4:13: Surface: parameter \"Km\" has no value");
    assert_string_equal(parse_error(CAMERA "WorldBegin\nSurface \"s\" 1 2\n"),
        "t.rib:4:13: Surface: expected a parameter name (a string), got a number");
    assert_string_equal(parse_error(CAMERA "Declare \"x\" \"float[0]\"\n"),
        "t.rib:3:13: Declare: cannot read the declaration \"float[0]\": bad array size "
        "'[0]' (expected [1] to [4096]) (expected [class] type [n], e.g. \"uniform float\")");
    assert_string_equal(parse_error(CAMERA "Declare \"x\" \"uniform\"\n"),
        "t.rib:3:13: Declare: cannot read the declaration \"uniform\": missing type after "
        "'uniform' (expected [class] type [n], e.g. \"uniform float\")");
}

/* ---------------------------------------------------------------------- */
/* transforms                                                              */
/* ---------------------------------------------------------------------- */

static void test_transform_order(void **state)
{
    (void)state;
    /* Translate then Scale: the scale applies to points first */
    scene *s = parse_ok(CAMERA "WorldBegin\nTranslate 1 0 0\nScale 2 2 2\nSphere 1 -1 1 360\n"
                        "WorldEnd\n");
    assert_vec(mat4_xform_point(&s->objects[0].object_to_world, v3(1, 0, 0)), v3(3, 0, 0), 0);
    scene_destroy(&s);

    /* Rotate 90 about z (x -> y), then Translate 1 0 0 in the rotated frame */
    s = parse_ok(CAMERA "WorldBegin\nRotate 90 0 0 1\nTranslate 1 0 0\nSphere 1 -1 1 360\n"
                 "WorldEnd\n");
    assert_vec(mat4_xform_point(&s->objects[0].object_to_world, v3(0, 0, 0)), v3(0, 1, 0), 1e-15);
    scene_destroy(&s);

    /* RIB matrices are row vectors: the translation is in the last row */
    s = parse_ok(CAMERA "WorldBegin\nTranslate 1 1 1\n"
                 "ConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  5 6 7 1]\nSphere 1 -1 1 360\n"
                 "Transform [1 0 0 0  0 1 0 0  0 0 1 0  -1 -2 -3 1]\nSphere 1 -1 1 360\n"
                 "Identity\nSphere 1 -1 1 360\nWorldEnd\n");
    assert_vec(mat4_xform_point(&s->objects[0].object_to_world, v3(1, 0, 0)), v3(8, 7, 8), 0);
    assert_vec(mat4_xform_point(&s->objects[1].object_to_world, v3(0, 0, 0)), v3(-1, -2, -3), 0);
    assert_vec(mat4_xform_point(&s->objects[2].object_to_world, v3(4, 5, 6)), v3(4, 5, 6), 0);
    scene_destroy(&s);
}

static void test_camera_transform(void **state)
{
    (void)state;
    /* before WorldBegin the transform is world -> camera; the object's
     * to_camera is camera_from_world * to_world */
    scene *s = parse_ok(CAMERA "Translate 0 0 10\nRotate 90 0 1 0\nWorldBegin\n"
                        "Translate 1 0 0\nSphere 1 -1 1 360\nWorldEnd\n");
    const scene_object *o = &s->objects[0];
    assert_vec(mat4_xform_point(&o->object_to_world, v3(0, 0, 0)), v3(1, 0, 0), 0);
    /* Rotate 90 about y: x -> -z, so world (1,0,0) -> camera (0,0,-1+10) */
    mat4 to_camera, from_camera;
    scene_object_transforms(s, o, &to_camera, &from_camera);
    assert_vec(mat4_xform_point(&to_camera, v3(0, 0, 0)), v3(0, 0, 9), 1e-14);
    assert_vec(mat4_xform_point(&s->camera.camera_from_world, v3(1, 0, 0)), v3(0, 0, 9), 1e-14);
    scene_destroy(&s);
}

static void test_stacks(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\nColor 1 0 0\n"
        "AttributeBegin\nTranslate 1 0 0\nColor 0 1 0\nSides 1\nSphere 1 -1 1 360\nAttributeEnd\n"
        "TransformBegin\nTranslate 0 2 0\nColor [0 0 1]\nSphere 1 -1 1 360\nTransformEnd\n"
        "Sphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(s->nobjects, 3);
    assert_vec(mat4_xform_point(&s->objects[0].object_to_world, v3(0, 0, 0)), v3(1, 0, 0), 0);
    assert_true(s->objects[0].Cs[1] == 1 && s->objects[0].Cs[0] == 0);
    assert_int_equal(s->objects[0].attr->sides, 1);
    assert_vec(mat4_xform_point(&s->objects[1].object_to_world, v3(0, 0, 0)), v3(0, 2, 0), 0);
    assert_true(s->objects[1].Cs[2] == 1);
    assert_int_equal(s->objects[1].attr->sides, 2);
    /* TransformEnd restores the transform only: the blue stays */
    assert_vec(mat4_xform_point(&s->objects[2].object_to_world, v3(0, 0, 0)), v3(0, 0, 0), 0);
    assert_true(s->objects[2].Cs[2] == 1 && s->objects[2].Cs[0] == 0);
    scene_destroy(&s);
}

static void test_shader_space_and_named_spaces(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "Translate 0 0 5\nSurface \"early\"\nWorldBegin\n"
        "Translate 0 3 0\nCoordinateSystem \"lamp\"\nDisplacement \"d\"\nTranslate 7 0 0\n"
        "Sphere 1 -1 1 360\nCoordSysTransform \"lamp\"\nSphere 1 -1 1 360\n"
        "CoordSysTransform \"world\"\nSphere 1 -1 1 360\nWorldEnd\n");
    const scene_object *o = &s->objects[0];
    const scene_shader *d = scene_object_displacement(s, o);
    assert_vec(mat4_xform_point(&d->shader_to_world, v3(0, 0, 0)), v3(0, 3, 0), 0);
    assert_vec(mat4_xform_point(&d->shader_to_camera, v3(0, 0, 0)), v3(0, 3, 5), 0);
    /* a Surface before WorldBegin: its space is the camera's frame at that
     * point, i.e. the world origin moved... world_from_camera * (0,0,5) */
    const scene_shader *e = scene_object_surface(s, o);
    assert_vec(mat4_xform_point(&e->shader_to_camera, v3(0, 0, 0)), v3(0, 0, 5), 0);
    assert_vec(mat4_xform_point(&e->shader_to_world, v3(0, 0, 0)), v3(0, 0, 0), 0);
    assert_vec(mat4_xform_point(&o->object_to_world, v3(0, 0, 0)), v3(7, 3, 0), 0);
    assert_int_equal(s->nspaces, 1);
    assert_string_equal(s->spaces[0].name, "lamp");
    assert_vec(mat4_xform_point(&s->spaces[0].to_camera, v3(0, 0, 0)), v3(0, 3, 5), 0);
    assert_vec(mat4_xform_point(&s->objects[1].object_to_world, v3(0, 0, 0)), v3(0, 3, 0), 0);
    assert_vec(mat4_xform_point(&s->objects[2].object_to_world, v3(0, 0, 0)), v3(0, 0, 0), 0);
    scene_destroy(&s);
}

/* ---------------------------------------------------------------------- */
/* lights                                                                  */
/* ---------------------------------------------------------------------- */

static void test_light_defaults(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\nTranslate 0 1 0\n"
        "LightSource \"spotlight\" 1\nLightSource \"pointlight\" \"lightcolor\" [1 0.5 0]\n"
        "LightSource \"distantlight\" \"light2\" \"to\" [0 -1 0]\nSphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(s->nlights, 3);
    const scene_light *spot = &s->lights[0];
    assert_int_equal(spot->kind, SCENE_SPOT_LIGHT);
    assert_string_equal(spot->handle, "1");
    assert_true(spot->intensity == 1);
    assert_true(fabs(spot->coneangle - M_PI / 6) < 1e-15);
    assert_true(fabs(spot->conedeltaangle - M_PI / 36) < 1e-15);
    assert_true(spot->beamdistribution == 2);
    assert_vec(spot->from, v3(0, 0, 0), 0);
    assert_vec(spot->to, v3(0, 0, 1), 0);
    /* light space: the Translate before it */
    assert_vec(spot->from_world, v3(0, 1, 0), 0);
    assert_vec(spot->to_world, v3(0, 1, 1), 0);
    assert_null(s->lights[1].handle);
    assert_true(s->lights[1].lightcolor[1] == 0.5);
    assert_string_equal(s->lights[2].handle, "light2");
    assert_vec(s->lights[2].to_world, v3(0, 0, 0), 0);
    scene_destroy(&s);
}

static void test_light_scope_and_illuminate(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\nLightSource \"ambientlight\" 1\n"
        "AttributeBegin\nLightSource \"pointlight\" 2\nSphere 1 -1 1 360\nAttributeEnd\n"
        "Sphere 1 -1 1 360\n"
        "Illuminate 1 0\nIlluminate 2 1\nSphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(s->objects[0].attr->nlights, 2);
    /* the point light is off after its AttributeEnd */
    assert_int_equal(s->objects[1].attr->nlights, 1);
    assert_int_equal(s->objects[1].attr->lights[0], 0);
    assert_int_equal(s->objects[2].attr->nlights, 1);
    assert_int_equal(s->objects[2].attr->lights[0], 1);
    scene_destroy(&s);
}

static void test_shadows(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\nAttribute \"light\" \"shadows\" [\"on\"]\n"
        "LightSource \"distantlight\" 1\nLightSource \"pointlight\" 2 \"shadows\" \"off\"\n"
        "Attribute \"light\" \"shadows\" \"off\"\nLightSource \"pointlight\" 3\n"
        "LightSource \"pointlight\" 4 \"__shadows\" [\"on\"]\nSphere 1 -1 1 360\nWorldEnd\n");
    assert_true(s->lights[0].shadows);
    assert_false(s->lights[1].shadows);
    assert_false(s->lights[2].shadows);
    assert_true(s->lights[3].shadows);
    scene_destroy(&s);
    assert_string_equal(parse_error(CAMERA "WorldBegin\nLightSource \"pointlight\" 1 "
                                    "\"shadows\" \"maybe\"\n"),
        "t.rib:4:28: LightSource: \"shadows\" must be \"on\" or \"off\", got \"maybe\"");
}

/* ---------------------------------------------------------------------- */
/* attributes                                                              */
/* ---------------------------------------------------------------------- */

static void test_orientation(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\nSphere 1 -1 1 360\n"
        "AttributeBegin\nReverseOrientation\nSphere 1 -1 1 360\nAttributeEnd\n"
        "AttributeBegin\nOrientation \"lh\"\nSphere 1 -1 1 360\nScale -1 1 1\n"
        "Sphere 1 -1 1 360\nOrientation \"rh\"\nSphere 1 -1 1 360\nAttributeEnd\nWorldEnd\n");
    assert_int_equal(s->objects[0].attr->orientation, SCENE_OUTSIDE);
    assert_false(s->objects[0].reverse_normals);
    assert_int_equal(s->objects[1].attr->orientation, SCENE_INSIDE);
    assert_true(s->objects[1].reverse_normals);
    /* lh in a left-handed space: no flip; mirrored by Scale -1: flip */
    assert_int_equal(s->objects[2].attr->orientation, SCENE_LH);
    assert_false(s->objects[2].reverse_normals);
    assert_true(s->objects[3].reverse_normals);
    assert_false(s->objects[4].reverse_normals);
    assert_string_equal(scene_orientation_name(SCENE_RH), "rh");
    scene_destroy(&s);
}

static void test_attributes(void **state)
{
    (void)state;
    scene *s = parse_ok(CAMERA "WorldBegin\n"
        "Attribute \"displacementbound\" \"sphere\" [0.5] \"coordinatesystem\" [\"shader\"]\n"
        "Attribute \"identifier\" \"name\" \"ball\"\n"
        "Attribute \"visibility\" \"camera\" [1] \"whatever\" \"x\"\n"
        "Attribute \"user\" \"from\" \"not a point\" \"to\"\n"
        "Attribute \"identifier\" \"unknownparam\" 3\n"
        "Opacity [1 1 0.5]\nShadingRate 0.5\nSphere 1 -1 1 360\n"
        "AttributeBegin\nAttribute \"identifier\" \"name\" \"inner\"\nSphere 1 -1 1 360\n"
        "AttributeEnd\nSphere 1 -1 1 360\nWorldEnd\n");
    const scene_object *o = &s->objects[0];
    assert_true(o->attr->displacement_bound == 0.5);
    assert_string_equal(o->attr->displacement_bound_space, "shader");
    assert_string_equal(o->attr->name, "ball");
    assert_true(o->attr->Os[2] == 0.5);
    assert_true(o->attr->shading_rate == 0.5);
    assert_string_equal(s->objects[1].attr->name, "inner");
    assert_string_equal(s->objects[2].attr->name, "ball");
    /* the scene's shading rate is the one current at WorldBegin */
    assert_true(s->shading_rate == 1);
    scene_destroy(&s);
}

/* ---------------------------------------------------------------------- */
/* options                                                                 */
/* ---------------------------------------------------------------------- */

static void test_search_path(void **state)
{
    (void)state;
    const char *text = "Option \"searchpath\" \"shader\" \"a:@\"\n"
        "Option \"searchpath\" \"shader\" [\"b:/abs/lib:&\"]\n"
        "Option \"searchpath\" \"texture\" [\"ignored\"]\n"
        "Option \"limits\" \"bucketsize\" [16 16]\nOption \"user\" \"P\" \"x\"\n"
        CAMERA "WorldBegin\nSurface \"s1\"\nSphere 1 -1 1 360\nWorldEnd\n";
    sl_diag *d = sl_diag_new();
    scene *s = scene_parse("proj/scenes/x.rib", text, strlen(text), d);
    assert_non_null(s);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(s->nsearch_path, 4);
    assert_string_equal(s->search_path[0], "proj/scenes/b");
    assert_string_equal(s->search_path[1], "/abs/lib");
    assert_string_equal(s->search_path[2], "proj/scenes/a");
    assert_string_equal(s->search_path[3], "proj/scenes");
    assert_null(s->search_path[4]);
    assert_int_equal(s->nshader_names, 1);
    assert_string_equal(s->shader_names[0], "s1");
    assert_string_equal(s->objects[0].pos.file, "proj/scenes/x.rib");
    scene_destroy(&s);

    /* a RIB in the current folder: "." only */
    s = parse_ok(CAMERA "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(s->nsearch_path, 1);
    assert_string_equal(s->search_path[0], ".");
    assert_int_equal(s->nshader_names, 0);
    sl_diag_destroy(&d);
    scene_destroy(&s);
}

static void test_camera_options_values(void **state)
{
    (void)state;
    const char *text = "Format 100 400 2\nProjection \"orthographic\"\n"
        "ScreenWindow -3 3 -1.5 1.5\nClipping 0.5 50\nPixelSamples 3 4\n"
        "PixelFilter \"catmull-rom\" 3 3\nExposure 1.5 2.2\nDisplay \"out.exr\" \"file\" \"rgb\"\n"
        "Display \"+extra.exr\" \"file\" \"rgb\"\n"
        "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n";
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
        "t.rib:9:1: Display: only one image is written; the extra display \"+extra.exr\" "
        "is ignored");
    const scene_camera *c = &s->camera;
    assert_int_equal(c->projection, SCENE_ORTHOGRAPHIC);
    assert_true(c->pixel_aspect == 2);
    assert_true(c->screen[0] == -3 && c->screen[3] == 1.5);
    assert_true(c->near_clip == 0.5 && c->far_clip == 50);
    assert_int_equal(s->pixel_samples[0], 3);
    assert_int_equal(s->pixel_samples[1], 4);
    assert_int_equal(s->filter.kind, SCENE_FILTER_CATMULL_ROM);
    assert_string_equal(scene_filter_name(s->filter.kind), "catmull-rom");
    assert_true(s->exposure_gain == 1.5 && s->exposure_gamma == 2.2);
    assert_string_equal(s->display_name, "out.exr");
    assert_string_equal(s->display_mode, "rgb");
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* default screen window, frame aspect 100*2/400 = 0.5 < 1 */
    s = parse_ok("Format 100 400 2\nProjection \"perspective\"\nWorldBegin\n"
                 "Sphere 1 -1 1 360\nWorldEnd\n");
    assert_true(s->camera.screen[0] == -1 && s->camera.screen[1] == 1);
    assert_true(s->camera.screen[2] == -2 && s->camera.screen[3] == 2);
    assert_true(s->camera.fov == 90);
    assert_null(s->display_name);
    scene_destroy(&s);
}

/* A light before WorldBegin (accepted with one warning, as other renderers
 * do) sits in the space current there: the camera transform built so far. */
static void test_light_before_world(void **state)
{
    (void)state;
    const char *text = CAMERA "Translate 0 0 5\n"
        "LightSource \"pointlight\" 1 \"from\" [0 0 1]\nLightSource \"ambientlight\" 2\n"
        "Rotate 90 0 1 0\nWorldBegin\nSphere 1 -1 1 360\nWorldEnd\n";
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                           "t.rib:4:1: LightSource: a light before WorldBegin is placed"));
    assert_int_equal(s->nlights, 2);
    const scene_light *l = &s->lights[0];
    assert_true(vec_dist(l->from_camera, v3(0, 0, 6)) < 1e-12);
    /* world = camera rotated back by -90 about y after the translation */
    assert_true(vec_dist(l->from_world, v3(-1, 0, 0)) < 1e-12);
    assert_int_equal(s->objects[0].attr->nlights, 2);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* Every FrameBegin block is a frame: one parse reads the frame it is
 * asked for (the options outside the frames hold for all of them, those
 * inside the others are skipped) and tells every frame's number. */
static void test_frames(void **state)
{
    (void)state;
    const char *text = "Declare \"k\" \"float\"\n" CAMERA "FrameBegin 1\n"
        "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\nFrameEnd\n"
        "FrameBegin 5\nFormat 16 8 1\nWorldBegin\nSphere 2 -2 2 360\nWorldEnd\n"
        "FrameEnd\nFrameBegin\nWorldBegin\nWorldEnd\nFrameEnd\n";
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    assert_non_null(s);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(s->frame, 0);
    assert_int_equal(s->frame_number, 1);
    assert_int_equal(s->nframes, 3);
    /* a FrameBegin without a number follows the previous one */
    assert_int_equal(s->frame_numbers[0], 1);
    assert_int_equal(s->frame_numbers[1], 5);
    assert_int_equal(s->frame_numbers[2], 6);
    assert_int_equal(s->nobjects, 1);
    assert_true(s->objects[0].surface->radius == 1);
    assert_int_equal(s->camera.xres, 64);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* the second frame: its own Format and sphere, nothing of the first */
    d = sl_diag_new();
    s = scene_parse_frame("t.rib", text, strlen(text), NULL, SCENE_MAX_OBJECTS, 1, NULL, d);
    assert_non_null(s);
    assert_int_equal(s->frame, 1);
    assert_int_equal(s->frame_number, 5);
    assert_int_equal(s->nframes, 3);
    assert_int_equal(s->nobjects, 1);
    assert_true(s->objects[0].surface->radius == 2);
    assert_int_equal(s->camera.xres, 16);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* the third frame's world is empty: that frame's error */
    d = sl_diag_new();
    s = scene_parse_frame("t.rib", text, strlen(text), NULL, SCENE_MAX_OBJECTS, 2, NULL, d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
        "t.rib:17:1: WorldEnd: the world has no objects (add a surface between WorldBegin "
        "and WorldEnd, e.g. Sphere 1 -1 1 360)");
    sl_diag_destroy(&d);

    /* the frames, none read */
    d = sl_diag_new();
    int *numbers = NULL;
    assert_int_equal(scene_scan_frames("t.rib", text, strlen(text), NULL, &numbers, NULL, d), 3);
    assert_int_equal(sl_diag_count(d), 0);
    assert_int_equal(numbers[1], 5);
    free(numbers);
    sl_diag_destroy(&d);

    /* past the last frame */
    d = sl_diag_new();
    s = scene_parse_frame("t.rib", text, strlen(text), NULL, SCENE_MAX_OBJECTS, 3, NULL, d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
        "t.rib:0:0: frame index 3 asked for, but the file has 3 frames (FrameBegin blocks)");
    sl_diag_destroy(&d);

    /* a bad frame number */
    s = parse_rib("FrameBegin 1.5\n" CAMERA "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n"
                  "FrameEnd\n", &d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
        "t.rib:1:12: FrameBegin: the frame number must be a whole number 0..99999999, got 1.5");
    sl_diag_destroy(&d);
}

static void test_comments_and_layout(void **state)
{
    (void)state;
    /* comments, structural comments, tabs, CR-LF, arguments over lines,
     * escapes in strings, numbers in every form */
    const char *text = "##RenderMan RIB-Structure 1.1\r\n# a comment\r\n"
        "Format\t64\n32 1 # trailing comment\nProjection \"perspective\" \"fov\" 45.\n"
        "WorldBegin\nAttribute \"identifier\" \"name\" \"a\\\"b\\101\"\n"
        "Sphere +1 -1e0 .1E1\n  3.6e2\nWorldEnd";
    scene *s = parse_ok(text);
    assert_int_equal(s->camera.yres, 32);
    assert_true(s->camera.fov == 45);
    assert_string_equal(s->objects[0].attr->name, "a\"bA");
    assert_true(s->objects[0].surface->zmax == 1);
    assert_true(fabs(s->objects[0].surface->thetamax - 2 * M_PI) < 1e-15);
    assert_int_equal(s->objects[0].pos.line, 8);
    scene_destroy(&s);
}

/* Classic Mac RIB files end lines in a lone CR: comments end there, a
 * string continues over a backslash before CR or CR-LF, and positions
 * (line:col) count CR, CR-LF and LF alike. */
static void test_cr_line_ends(void **state)
{
    (void)state;
    const char *text = "##RenderMan RIB-Structure 1.1\r# a comment Format 1 1 1\r"
        "Format 64 32 1\rProjection \"perspective\" \"fov\" 45\r\n"
        "WorldBegin\rAttribute \"identifier\" \"name\" \"a\\\rb\\\r\nc\"\r"
        "Sphere 1 -1 1 360\rWorldEnd\r";
    scene *s = parse_ok(text);
    assert_int_equal(s->camera.xres, 64);
    assert_true(s->camera.fov == 45);
    assert_string_equal(s->objects[0].attr->name, "abc");
    assert_int_equal(s->objects[0].pos.line, 9);
    assert_int_equal(s->objects[0].pos.col, 1);
    scene_destroy(&s);
    sl_diag *d;
    s = parse_rib("# frames\rFormat 64 32 1\r\n  FrameBegin 1.5\r", &d);
    assert_null(s);
    assert_string_equal(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)),
        "t.rib:3:14: FrameBegin: the frame number must be a whole number 0..99999999, got 1.5");
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_param_typing),
        cmocka_unit_test(test_declare_overrides_standard),
        cmocka_unit_test(test_param_errors),
        cmocka_unit_test(test_transform_order),
        cmocka_unit_test(test_camera_transform),
        cmocka_unit_test(test_stacks),
        cmocka_unit_test(test_shader_space_and_named_spaces),
        cmocka_unit_test(test_light_defaults),
        cmocka_unit_test(test_light_scope_and_illuminate),
        cmocka_unit_test(test_shadows),
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_attributes),
        cmocka_unit_test(test_search_path),
        cmocka_unit_test(test_camera_options_values),
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_light_before_world),
        cmocka_unit_test(test_comments_and_layout),
        cmocka_unit_test(test_cr_line_ends),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
