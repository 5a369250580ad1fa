/*
 * tests/scene/test_scene_examples.c: the example scenes in scenes/ parse,
 * and the parser reads them as the RIB says: object and light counts,
 * camera values, shader calls, the search path, and transforms checked on
 * points whose image was computed by hand from the RIB's Translate/Rotate
 * requests (RenderMan's Rotate about x by a: y' = y cos a - z sin a,
 * z' = y sin a + z cos a).
 *
 * Argument: the scenes folder (tests/scene/CMakeLists.txt passes
 * ${PROJECT_SOURCE_DIR}/scenes).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

static const char *scenes_dir = "scenes";
static const double eps = 1e-12;

static scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", scenes_dir, name);
    sl_diag *d = sl_diag_new();
    scene *s = scene_load(path, d);
    if (!s || sl_diag_warning_count(d) > 0)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(sl_diag_warning_count(d), 0);
    sl_diag_destroy(&d);
    return s;
}

static double rad(double deg) { return deg * M_PI / 180; }

static void assert_vec(vec3 got, vec3 want, double tol)
{
    if (vec_dist(got, want) > tol)
        fail_msg("got (%.15g %.15g %.15g), want (%.15g %.15g %.15g)", got.x, got.y, got.z,
                 want.x, want.y, want.z);
}

static const scene_object *object_named(const scene *s, const char *name)
{
    for (int i = 0; i < s->nobjects; i++)
        if (s->objects[i].attr->name && strcmp(s->objects[i].attr->name, name) == 0)
            return &s->objects[i];
    fail_msg("no object named %s", name);
    return NULL;
}

/* camera and options */
static void test_wave_camera(void **state)
{
    (void)state;
    scene *s = load("wave.rib");
    const scene_camera *c = &s->camera;
    assert_int_equal(c->xres, 512);
    assert_int_equal(c->yres, 256);
    assert_true(c->pixel_aspect == 1);
    assert_int_equal(c->projection, SCENE_PERSPECTIVE);
    assert_true(c->fov == 25);
    /* frame aspect 2: the screen window is [-2,2] x [-1,1] */
    assert_true(c->screen[0] == -2 && c->screen[1] == 2);
    assert_true(c->screen[2] == -1 && c->screen[3] == 1);
    assert_true(c->near_clip == 0.1 && c->far_clip == 100);
    assert_int_equal(s->pixel_samples[0], 2);
    assert_int_equal(s->pixel_samples[1], 2);
    assert_true(s->shading_rate == 1);
    assert_int_equal(s->filter.kind, SCENE_FILTER_GAUSSIAN);
    assert_true(s->filter.xwidth == 2 && s->filter.ywidth == 2);
    assert_true(s->exposure_gain == 1 && s->exposure_gamma == 1);
    assert_string_equal(s->display_name, "wave.exr");
    assert_string_equal(s->display_type, "file");
    assert_string_equal(s->display_mode, "rgba");

    /* Translate 0 0.08 3.5, Rotate -35 1 0 0: world (0,0,1) -> camera
     * (0, 0.08 + sin 35, 3.5 + cos 35); the origin -> (0, 0.08, 3.5) */
    vec3 p = mat4_xform_point(&c->camera_from_world, v3(0, 0, 1));
    assert_vec(p, v3(0, 0.08 + sin(rad(35)), 3.5 + cos(rad(35))), eps);
    p = mat4_xform_point(&c->camera_from_world, v3(0, 0, 0));
    assert_vec(p, v3(0, 0.08, 3.5), eps);
    p = mat4_xform_point(&c->world_from_camera, v3(0, 0.08, 3.5));
    assert_vec(p, v3(0, 0, 0), 1e-12);
    scene_destroy(&s);
    assert_null(s);
}

static void test_wave_objects(void **state)
{
    (void)state;
    scene *s = load("wave.rib");
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(s->nlights, 2);
    const scene_object *o = &s->objects[0];
    assert_string_equal(o->attr->name, "wave");
    assert_int_equal(o->surface->kind, GEOM_POLYGON);
    assert_int_equal(o->surface->nverts, 4);
    assert_vec(o->surface->verts[0], v3(-1, 0, -1), 0);
    assert_vec(o->surface->verts[2], v3(1, 0, 1), 0);
    assert_int_equal(o->attr->sides, 2);
    assert_true(o->attr->displacement_bound == 0.25);
    assert_string_equal(o->attr->displacement_bound_space, "object");
    assert_true(o->Cs[0] == 0.8 && o->Cs[1] == 0.75 && o->Cs[2] == 0.6);
    assert_int_equal(o->pos.line, 32);   /* the Polygon line of wave.rib */
    assert_int_equal(o->pos.col, 5);
    assert_string_equal(o->pos.file, s->file);

    /* the vertex (-1,0,-1) seen from the camera, by hand */
    mat4 to_camera, from_camera;
    scene_object_transforms(s, o, &to_camera, &from_camera);
    vec3 p = mat4_xform_point(&to_camera, o->surface->verts[0]);
    assert_vec(p, v3(-1, 0.08 - sin(rad(35)), 3.5 - cos(rad(35))), eps);
    vec3 back = mat4_xform_point(&from_camera, p);
    assert_vec(back, v3(-1, 0, -1), 1e-12);

    const scene_shader *disp = scene_object_displacement(s, o);
    const scene_shader *surf = scene_object_surface(s, o);
    assert_non_null(disp);
    assert_non_null(surf);
    assert_string_equal(disp->name, "wave");
    assert_int_equal(disp->kind, SL_SHADER_DISPLACEMENT);
    const scene_param *km = scene_shader_param(disp, "Km");
    assert_non_null(km);
    assert_int_equal(km->type, SL_TYPE_FLOAT);
    assert_int_equal(km->count, 1);
    assert_true(km->values[0] == 0.1);
    assert_string_equal(surf->name, "plastic");
    assert_int_equal(surf->nparams, 4);
    assert_true(scene_shader_param(surf, "roughness")->values[0] == 0.1);

    assert_int_equal(s->nshader_names, 2);
    assert_string_equal(s->shader_names[0], "plastic");
    assert_string_equal(s->shader_names[1], "wave");

    assert_int_equal(s->lights[0].kind, SCENE_AMBIENT_LIGHT);
    assert_true(s->lights[0].intensity == 0.15);
    const scene_light *l = &s->lights[1];
    assert_int_equal(l->kind, SCENE_DISTANT_LIGHT);
    assert_string_equal(l->handle, "2");
    assert_vec(l->from_world, v3(-1, 2, -2), 0);
    assert_vec(l->to_world, v3(0, 0, 0), 0);
    /* world (-1,2,-2) by Rotate -35 1 0 0, then Translate 0 0.08 3.5 */
    vec3 want = v3(-1, 0.08 + 2 * cos(rad(35)) - 2 * sin(rad(35)),
                   3.5 - 2 * sin(rad(35)) - 2 * cos(rad(35)));
    assert_vec(l->from_camera, want, eps);
    assert_false(l->shadows);
    assert_int_equal(o->attr->nlights, 2);
    scene_destroy(&s);
}

static void test_wave_search_path(void **state)
{
    (void)state;
    scene *s = load("wave.rib");
    char want[1100];
    assert_int_equal(s->nsearch_path, 2);
    snprintf(want, sizeof want, "%s/shaders", scenes_dir);
    char *norm = sl_source_normalize(want);
    assert_string_equal(s->search_path[0], norm);
    free(norm);
    norm = sl_source_normalize(scenes_dir);
    assert_string_equal(s->search_path[1], norm);
    assert_null(s->search_path[2]);
    assert_ptr_equal(scene_search_path(s)[1], s->search_path[1]);
    free(norm);
    scene_destroy(&s);
}

/* scene_find_shader asks the callback about "<dir>/<name>.sl" in order */
typedef struct probe { int calls; char wanted[1100]; char last[1100]; } probe;

static bool probe_exists(const char *path, void *arg)
{
    probe *pr = arg;
    pr->calls++;
    snprintf(pr->last, sizeof pr->last, "%s", path);
    return strcmp(path, pr->wanted) == 0;
}

static void test_find_shader(void **state)
{
    (void)state;
    scene *s = load("wave.rib");
    probe pr = { 0, "", "" };
    snprintf(pr.wanted, sizeof pr.wanted, "%s/wave.sl", s->search_path[1]);
    char *path = scene_find_shader(s, "wave", probe_exists, &pr);
    assert_non_null(path);
    assert_string_equal(path, pr.wanted);
    assert_int_equal(pr.calls, 2);
    free(path);

    pr.calls = 0;
    assert_null(scene_find_shader(s, "nothing", probe_exists, &pr));
    assert_int_equal(pr.calls, 2);
    char want[1100];
    snprintf(want, sizeof want, "%s/nothing.sl", s->search_path[1]);
    assert_string_equal(pr.last, want);
    scene_destroy(&s);
}

static void test_nail(void **state)
{
    (void)state;
    scene *s = load("nail.rib");
    assert_int_equal(s->camera.xres, 256);
    assert_int_equal(s->camera.yres, 512);
    /* portrait: x spans [-1,1], y [-2,2] */
    assert_true(s->camera.screen[0] == -1 && s->camera.screen[1] == 1);
    assert_true(s->camera.screen[2] == -2 && s->camera.screen[3] == 2);
    assert_int_equal(s->nobjects, 1);
    const scene_object *o = &s->objects[0];
    assert_int_equal(o->surface->kind, GEOM_DISK);
    assert_true(o->surface->height == 0 && o->surface->radius == 0.5);
    assert_true(fabs(o->surface->thetamax - 2 * M_PI) < 1e-15);
    /* Rotate -90 1 0 0: the disk's normal axis +z becomes world +y */
    assert_vec(mat4_xform_vector(&o->object_to_world, v3(0, 0, 1)), v3(0, 1, 0), 1e-15);
    assert_string_equal(scene_object_displacement(s, o)->name, "nail");
    assert_string_equal(scene_object_surface(s, o)->name, "metal");
    assert_true(o->attr->displacement_bound == 1.5);
    scene_destroy(&s);
}

static void test_ufo(void **state)
{
    (void)state;
    scene *s = load("ufo.rib");
    assert_int_equal(s->camera.xres, 256);
    assert_int_equal(s->camera.yres, 256);
    assert_true(s->camera.fov == 40);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(s->nlights, 3);
    const scene_object *o = &s->objects[0];
    assert_int_equal(o->surface->kind, GEOM_SPHERE);
    assert_true(o->surface->radius == 1 && o->surface->zmin == -1 && o->surface->zmax == 1);
    const scene_shader *surf = scene_object_surface(s, o);
    assert_string_equal(surf->name, "wood");
    assert_int_equal(surf->nparams, 0);
    assert_string_equal(scene_object_displacement(s, o)->name, "ufo");
    const scene_light *pl = &s->lights[2];
    assert_int_equal(pl->kind, SCENE_POINT_LIGHT);
    assert_true(pl->intensity == 6);
    assert_true(pl->lightcolor[0] == 1 && pl->lightcolor[1] == 1 && pl->lightcolor[2] == 1);
    assert_vec(pl->from_world, v3(3, 2, -3), 0);
    /* the sphere's centre is the world origin: 5 units ahead */
    mat4 to_camera, from_camera;
    scene_object_transforms(s, o, &to_camera, &from_camera);
    assert_vec(mat4_xform_point(&to_camera, v3(0, 0, 0)), v3(0, 0, 5), eps);
    scene_destroy(&s);
}

static void test_gallery(void **state)
{
    (void)state;
    scene *s = load("gallery.rib");
    assert_int_equal(s->nobjects, 6);
    assert_int_equal(s->nlights, 3);
    const scene_object *ground = object_named(s, "ground");
    assert_int_equal(ground->surface->kind, GEOM_PATCH);
    assert_int_equal(ground->surface->nverts, 4);
    assert_vec(ground->surface->verts[3], v3(5, 0, -5), 0);
    int spheres = 0;
    for (int i = 0; i < s->nobjects; i++) {
        spheres += s->objects[i].surface->kind == GEOM_SPHERE;
        /* light 2 went off at its AttributeEnd and Illuminate turned it on */
        assert_int_equal(s->objects[i].attr->nlights, 3);
    }
    assert_int_equal(spheres, 5);
    /* Translate 0 0.5 -0.5, Rotate -90 1 0 0: object (0,0,0.5) (the north
     * pole) -> world (0, 1, -0.5) */
    const scene_object *threads = object_named(s, "threads");
    assert_vec(mat4_xform_point(&threads->object_to_world, v3(0, 0, 0.5)), v3(0, 1, -0.5), 1e-15);
    /* shadows: the Attribute form (light 2) and the parameter form (3) */
    assert_false(s->lights[0].shadows);
    assert_true(s->lights[1].shadows);
    assert_true(s->lights[2].shadows);
    const scene_light *spot = &s->lights[2];
    assert_int_equal(spot->kind, SCENE_SPOT_LIGHT);
    assert_true(spot->coneangle == 0.6 && spot->conedeltaangle == 0.1);
    assert_true(spot->beamdistribution == 2);
    assert_true(spot->intensity == 25);
    assert_int_equal(s->nshader_names, 9);
    scene_destroy(&s);
}

static void test_surfaces(void **state)
{
    (void)state;
    scene *s = load("surfaces.rib");
    /* one of each kind up to the bilinear patch (bicubic patches have
     * their own scene, bicubic.rib) */
    assert_int_equal(s->nobjects, GEOM_BICUBIC);
    int seen[GEOM__COUNT] = { 0 };
    for (int i = 0; i < s->nobjects; i++)
        seen[s->objects[i].surface->kind]++;
    for (int k = 0; k < GEOM_BICUBIC; k++)
        assert_int_equal(seen[k], 1);
    const scene_object *torus = object_named(s, "torus");
    assert_true(torus->surface->majorrad == 0.6 && torus->surface->minorrad == 0.25);
    assert_true(fabs(torus->surface->phimax - 2 * M_PI) < 1e-15);
    const scene_object *hyp = object_named(s, "hyperboloid");
    assert_vec(hyp->surface->point1, v3(0.5, 0, -0.6), 0);
    assert_vec(hyp->surface->point2, v3(0, 0.5, 0.6), 0);
    /* the shared Surface call before the objects */
    for (int i = 0; i < s->nobjects; i++) {
        assert_string_equal(scene_object_surface(s, &s->objects[i])->name, "plastic");
        assert_int_equal(s->objects[i].attr->sides, 2);
    }
    assert_null(scene_object_displacement(s, object_named(s, "cylinder")));
    assert_int_equal(s->nshader_names, 3);
    scene_destroy(&s);
}

/* vase.rib: 8 x 4 b-spline patches from an archive, three instanced
 * catmull-rom leaves, a ground patch; the body is closed around (periodic
 * in u): each patch's u = 1 edge is its neighbour's u = 0 edge. */
static void test_vase(void **state)
{
    (void)state;
    scene *s = load("vase.rib");
    assert_int_equal(s->nobjects, 32 + 3 + 1);
    assert_int_equal(s->narchives, 1);
    assert_non_null(strstr(s->archives[0], "scenes/archives/vase_body.rib"));
    for (int i = 0; i < 35; i++)
        assert_int_equal(s->objects[i].surface->kind, GEOM_BICUBIC);
    for (int pv = 0; pv < 4; pv++)
        for (int pu = 0; pu < 8; pu++) {
            geom_sample a, b;
            geom_eval(s->objects[pv * 8 + pu].surface, 1, 0.5, &a);
            geom_eval(s->objects[pv * 8 + (pu + 1) % 8].surface, 0, 0.5, &b);
            assert_true(vec_dist(a.P, b.P) < 1e-12);
        }
    assert_non_null(scene_object_displacement(s, &s->objects[0]));
    assert_null(scene_object_displacement(s, &s->objects[32]));
    scene_destroy(&s);
}

/* meshes.rib: 1920 terrain quads from an archive, three stars (a concave
 * 10-gon with a pentagonal hole: 10 + 5 + 2 - 2 = 15 triangles each), a
 * bent quad cut in two. */
static void test_meshes(void **state)
{
    (void)state;
    scene *s = load("meshes.rib");
    /* each PointsPolygons is one object (issue 23): the terrain, three
     * stars, the bent quad */
    assert_int_equal(s->nobjects, 1 + 3 + 1);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 1920 + 3 * 15 + 2);
    for (int i = 0; i < np; i++)
        assert_int_equal(pc[i].surface.kind, GEOM_POLYGON);
    for (int i = 0; i < 1920; i++)
        assert_int_equal(pc[i].surface.nverts, 4);
    for (int i = 1920; i < np; i++)
        assert_int_equal(pc[i].surface.nverts, 3);
    free(pc);
    scene_destroy(&s);
}

/* ripples.rib: three frames, each its own world, the wave's phase a third
 * of a period further in each; the options before the frames hold in all */
static void test_ripples_frames(void **state)
{
    (void)state;
    char path[1024];
    size_t len = 0;
    snprintf(path, sizeof path, "%s/ripples.rib", scenes_dir);
    char *text = read_whole_file(path, &len);
    assert_non_null(text);
    for (int k = 0; k < 3; k++) {
        sl_diag *d = sl_diag_new();
        scene *s = scene_parse_frame(path, text, len, NULL, SCENE_MAX_OBJECTS, k, NULL, d);
        if (!s || sl_diag_count(d) > 0) sl_diag_print(d, stderr);
        assert_non_null(s);
        assert_int_equal(sl_diag_count(d), 0);
        assert_int_equal(s->nframes, 3);
        assert_int_equal(s->frame_number, k + 1);
        assert_int_equal(s->camera.xres, 160);
        assert_int_equal(s->nobjects, 1);
        char want[32];
        snprintf(want, sizeof want, "ripples.%04d.exr", k + 1);
        assert_string_equal(s->display_name, want);
        const scene_shader *disp = scene_object_displacement(s, &s->objects[0]);
        assert_non_null(disp);
        const scene_param *phase = scene_shader_param(disp, "phase");
        assert_non_null(phase);
        assert_true(fabs(phase->values[0] + k * 2 * M_PI / 3) < 1e-4);
        scene_destroy(&s);
        sl_diag_destroy(&d);
    }
    free(text);
}

/* subdiv.rib: one SubdivisionMesh of 96 quads, refined once: 384
 * Catmull-Clark faces, all sharing the scene's one mesh. */
static void test_subdiv(void **state)
{
    (void)state;
    scene *s = load("subdiv.rib");
    assert_int_equal(s->nsubdivs, 1);
    assert_int_equal(s->nobjects, 1);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 384);
    for (int i = 0; i < np; i++) {
        assert_int_equal(pc[i].surface.kind, GEOM_SUBDIV);
        assert_ptr_equal(pc[i].surface.subdiv, s->subdivs[0]);
        assert_int_equal(pc[i].surface.subdiv_face, i);
    }
    free(pc);
    assert_non_null(object_named(s, "box"));
    scene_destroy(&s);
}

/* knot.rib: a closed tube of 192 x 12 quads; curved, so each quad is cut
 * into two triangles with vertex normals. */
static void test_knot(void **state)
{
    (void)state;
    scene *s = load("knot.rib");
    assert_int_equal(s->nobjects, 1);
    int np;
    test_piece *pc = scene_pieces(s, &np);
    assert_int_equal(np, 2 * 192 * 12);
    for (int i = 0; i < np; i++) {
        assert_int_equal(pc[i].surface.kind, GEOM_POLYGON);
        assert_int_equal(pc[i].surface.nvn, 3);
    }
    free(pc);
    scene_destroy(&s);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        scenes_dir = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wave_camera),
        cmocka_unit_test(test_wave_objects),
        cmocka_unit_test(test_wave_search_path),
        cmocka_unit_test(test_find_shader),
        cmocka_unit_test(test_nail),
        cmocka_unit_test(test_ufo),
        cmocka_unit_test(test_gallery),
        cmocka_unit_test(test_surfaces),
        cmocka_unit_test(test_vase),
        cmocka_unit_test(test_meshes),
        cmocka_unit_test(test_ripples_frames),
        cmocka_unit_test(test_subdiv),
        cmocka_unit_test(test_knot),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
