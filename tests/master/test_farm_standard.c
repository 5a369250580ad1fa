/*
 * test_farm_standard.c: the RI Specification's standard shaders, built in
 * (common/sl/standard, sl/standard.h; docs/shading-language.md "Standard
 * shaders"), rendered by real aafarm-worker --standalone and aafarm-master
 * processes from RIB files in a folder with no shader in it and no shader
 * search path:
 *   - every built-in shader renders (exit 0, no "not found");
 *   - each surface's pixels match the RI Spec's formula computed here, on
 *     a plane facing an orthographic camera, lit by one distant light at
 *     60 degrees from the normal (so diffuse = cos 60 = 0.5 and the
 *     highlight is cos(30)^(1/roughness)): constant is exactly Os * Cs;
 *     matte, metal, plastic, and shinymetal / paintedplastic with no map;
 *   - bumpy with a map of constant value h moves the plane by Km * h
 *     along its normal (the Z channel says so), with no map it moves
 *     nothing;
 *   - a user's plastic.sl on the search path wins over the built-in one;
 *   - through the farm (a master and one worker over tcp://127.0.0.1), a
 *     scene of built-in shaders equals the standalone render bit for bit.
 * Every process is bounded by a wait with a timeout and killed by PID.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "farm_testutil.h"
#include "image/buffer.h"
#include "sl/standard.h"

static char *dir;

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    assert_true(fputs(text, f) >= 0);
    assert_int_equal(fclose(f), 0);
}

/* A 16x12 image of the plane z = 3 (facing the camera) filling an
 * orthographic view, lit by one distant light whose direction makes 60
 * degrees with the plane's normal, and `ambient` of ambient light (0:
 * none). `before` comes first (options), `attrs` just before the plane. */
static void write_scene(const char *name, const char *before, double ambient,
                        const char *attrs)
{
    char amb[128] = "", text[4096];
    if (ambient > 0)
        snprintf(amb, sizeof amb, "LightSource \"ambientlight\" 2 \"intensity\" [%.17g]\n",
                 ambient);
    snprintf(text, sizeof text,
             "%s"
             "Format 16 12 1\nPixelSamples 1 1\n"
             "Projection \"orthographic\"\nScreenWindow -1 1 -0.75 0.75\n"
             "WorldBegin\n"
             "LightSource \"distantlight\" 1 \"from\" [0 0 0] "
             "\"to\" [0.86602540378443865 0 0.5]\n"
             "%s"
             "AttributeBegin\n%s\n"
             "Polygon \"P\" [-5 -5 3  5 -5 3  5 5 3  -5 5 3]\n"
             "AttributeEnd\n"
             "WorldEnd\n",
             before, amb, attrs);
    write_file(ft_path(dir, name), text);
}

/* Renders dir/rib into dir/exr with the standalone worker; its exit
 * status (the log is dir/rib.log). */
static int standalone(const char *rib, const char *exr)
{
    char log[512];
    snprintf(log, sizeof log, "%s/%s.log", dir, rib);
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/%s", dir, rib);
    snprintf(out, sizeof out, "%s/%s", dir, exr);
    const char *argv[] = {ft_worker, "--standalone", in, "-o", out, "--tile", "8",
                          "--threads", "2", NULL};
    int rc = ft_wait(ft_spawn(log, argv), 120);
    if (rc != 0) fprintf(stderr, "%s:\n%s\n", rib, ft_read(log));
    return rc;
}

/* Channel `ch` of pixel (8, 6), the middle of the image, of dir/exr. */
static float pixel(const char *exr, const char *ch)
{
    char err[256];
    image_buffer *b = image_buffer_read_exr(ft_path(dir, exr), err, sizeof err);
    if (!b) fail_msg("%s", err);
    float *plane = image_buffer_channel(b, ch);
    assert_non_null(plane);
    float v = plane[6 * b->width + 8];
    image_buffer_destroy(&b);
    return v;
}

/* Renders a scene with `attrs` and checks the middle pixel's R, G, B
 * against rgb: equal, when exact is true, else within the rounding of the
 * file's HALF colour channels (half an ulp: 2^-11 relative). */
static void expect_rgb(const char *attrs, double ambient, const double rgb[3], bool exact)
{
    write_scene("s.rib", "", ambient, attrs);
    assert_int_equal(standalone("s.rib", "s.exr"), 0);
    static const char *const ch[] = {"R", "G", "B"};
    for (int c = 0; c < 3; c++) {
        float v = pixel("s.exr", ch[c]);
        double tol = exact ? 0 : fabs(rgb[c]) * 0x1p-11;
        if (!(fabs(v - rgb[c]) <= tol))
            fail_msg("%s: %s is %.9g, expected %.9g", attrs, ch[c], v, rgb[c]);
    }
}

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_NONE, 0);
}

static const char *const spec_names[] = {"constant", "matte", "metal", "shinymetal",
                                         "plastic", "paintedplastic", "bumpy"};

static void test_every_standard_shader_renders_with_no_shader_folder(void **state)
{
    (void)state;
    /* the RI Spec's list is built in ... */
    for (size_t i = 0; i < sizeof spec_names / sizeof spec_names[0]; i++)
        if (!sl_standard_find(spec_names[i])) fail_msg("'%s' is not built in", spec_names[i]);
    assert_null(sl_standard_find("wood"));
    /* ... and every built-in one renders from a folder holding only the RIB */
    for (int i = 0; i < sl_standard_nshaders; i++) {
        const char *name = sl_standard_shaders[i].name;
        char attrs[256];
        if (strcmp(name, "bumpy") == 0)
            snprintf(attrs, sizeof attrs, "Displacement \"bumpy\"\nSurface \"matte\"");
        else
            snprintf(attrs, sizeof attrs, "Surface \"%s\"", name);
        write_scene("all.rib", "", 0.1, attrs);
        if (standalone("all.rib", "all.exr") != 0) fail_msg("'%s' did not render", name);
        assert_int_equal(ft_count(ft_path(dir, "all.rib.log"), "not found"), 0);
    }
}

/* what the formulas give on this plane (diffuse 0.5, highlight
 * cos(30 deg)^(1/roughness)) */
static const double cs[3] = {1, 0.5, 0.25};
#define COLOR "Color [1 0.5 0.25]\n"

static void test_constant_is_exactly_os_times_cs(void **state)
{
    (void)state;
    const double want[3] = {0.25, 0.125, 0.5};   /* Os 0.5 * Cs (0.5 0.25 1) */
    expect_rgb("Color [0.5 0.25 1]\nOpacity [0.5 0.5 0.5]\nSurface \"constant\"", 0, want, true);
    assert_true(pixel("s.exr", "A") == 0.5f);
}

static void test_matte_is_ka_ambient_plus_kd_cos(void **state)
{
    (void)state;
    double want[3];
    for (int c = 0; c < 3; c++) want[c] = cs[c] * (0.5 * 0.2 + 0.8 * 0.5);
    expect_rgb(COLOR "Surface \"matte\" \"Ka\" [0.5] \"Kd\" [0.8]", 0.2, want, false);
    /* the defaults: Ka 1, Kd 1 */
    for (int c = 0; c < 3; c++) want[c] = cs[c] * (0.2 + 0.5);
    expect_rgb(COLOR "Surface \"matte\"", 0.2, want, false);
}

static void test_metal_and_shinymetal_are_tinted_highlights(void **state)
{
    (void)state;
    double hl = pow(cos(M_PI / 6), 10), want[3];   /* roughness 0.1 */
    for (int c = 0; c < 3; c++) want[c] = cs[c] * (0.1 + hl);
    expect_rgb(COLOR "Surface \"metal\"", 0.1, want, false);
    expect_rgb(COLOR "Surface \"shinymetal\"", 0.1, want, false);   /* no map: metal */
    double hl4 = pow(cos(M_PI / 6), 4);                               /* roughness 0.25 */
    for (int c = 0; c < 3; c++) want[c] = cs[c] * 0.5 * hl4;
    expect_rgb(COLOR "Surface \"metal\" \"Ks\" [0.5] \"roughness\" [0.25]", 0, want, false);
}

static void test_plastic_has_an_untinted_highlight(void **state)
{
    (void)state;
    double hl = pow(cos(M_PI / 6), 10), want[3];
    /* defaults: Ka 1, Kd 0.5, Ks 0.5, specularcolor 1 */
    for (int c = 0; c < 3; c++) want[c] = cs[c] * (0.1 + 0.5 * 0.5) + 0.5 * hl;
    expect_rgb(COLOR "Surface \"plastic\"", 0.1, want, false);
    expect_rgb(COLOR "Surface \"paintedplastic\"", 0.1, want, false);   /* no map */
    const double sc[3] = {0, 1, 0.5};
    for (int c = 0; c < 3; c++) want[c] = cs[c] * 0.25 + sc[c] * 0.25 * hl;
    expect_rgb(COLOR "Surface \"plastic\" \"Ks\" [0.25] \"specularcolor\" [0 1 0.5]", 0, want,
               false);
}

static void test_bumpy_moves_the_plane_by_km_times_the_map(void **state)
{
    (void)state;
    /* the map: a constant render of Cs 0.5 (every channel but A and Z
     * 0.5), made by the built-in constant shader itself */
    write_scene("map.rib", "", 0, "Color [0.5 0.5 0.5]\nSurface \"constant\"");
    assert_int_equal(standalone("map.rib", "map.exr"), 0);
    const char *flat = "Surface \"matte\"";
    write_scene("flat.rib", "", 0, flat);
    assert_int_equal(standalone("flat.rib", "flat.exr"), 0);
    assert_true(fabsf(pixel("flat.exr", "Z") - 3.0f) < 1e-6f);
    /* no map named: nothing moves */
    write_scene("nomap.rib", "", 0, "Displacement \"bumpy\"\nSurface \"matte\"");
    assert_int_equal(standalone("nomap.rib", "nomap.exr"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "flat.exr"), ft_path(dir, "nomap.exr")), 0);
    /* Km 0.4 * 0.5: 0.2 along the polygon's normal N (+z here, away from
     * the camera: the RI Spec's orientation of a polygon; bumpy moves along
     * N itself, not a faceforwarded one) */
    write_scene("bumpy.rib", "", 0,
                "Attribute \"displacementbound\" \"sphere\" [0.5]\n"
                "Displacement \"bumpy\" \"Km\" [0.4] \"texturename\" [\"map.exr\"]\n"
                "Surface \"matte\"");
    assert_int_equal(standalone("bumpy.rib", "bumpy.exr"), 0);
    float z = pixel("bumpy.exr", "Z");
    if (!(fabsf(z - 3.2f) < 1e-5f)) fail_msg("bumpy: Z is %.9g, expected 3.2", z);
    /* a plane moved along its normal shades as before */
    assert_true(pixel("bumpy.exr", "R") == pixel("flat.exr", "R"));
}

static void test_a_plastic_sl_on_the_search_path_wins(void **state)
{
    (void)state;
    char shaders[512];
    snprintf(shaders, sizeof shaders, "%s/mine", dir);
    assert_true(mkdir(shaders, 0755) == 0);
    write_file(ft_path(shaders, "plastic.sl"),
               "surface plastic(float Ks = 0.5) { Oi = 1; Ci = color(0, Ks, 1); }\n");
    write_scene("mine.rib", "Option \"searchpath\" \"shader\" [\"mine\"]\n", 0.1,
                COLOR "Surface \"plastic\" \"Ks\" [0.75]");
    assert_int_equal(standalone("mine.rib", "mine.exr"), 0);
    assert_true(pixel("mine.exr", "R") == 0.0f);   /* the built-in gives 0.35 + ... */
    assert_true(pixel("mine.exr", "G") == 0.75f);
    assert_true(pixel("mine.exr", "B") == 1.0f);
    /* the same RIB without the search path: the built-in one */
    write_scene("builtin.rib", "", 0.1, COLOR "Surface \"plastic\" \"Ks\" [0.75]");
    assert_int_equal(standalone("builtin.rib", "builtin.exr"), 0);
    assert_true(pixel("builtin.exr", "R") > 0.3f);
    assert_true(ft_exr_diff(ft_path(dir, "mine.exr"), ft_path(dir, "builtin.exr")) > 0);
}

static void test_the_farm_renders_standard_shaders_as_standalone(void **state)
{
    (void)state;
    const char *scene =
        "Format 48 36 1\nPixelSamples 2 2\n"
        "Projection \"perspective\" \"fov\" [40]\n"
        "Translate 0 -0.2 3.5\nRotate -30 1 0 0\n"
        "WorldBegin\n"
        "  LightSource \"ambientlight\" 1 \"intensity\" [0.1]\n"
        "  LightSource \"distantlight\" 2 \"from\" [1 2 -1] \"to\" [0 0 0]\n"
        "  AttributeBegin\n    Color [0.6 0.7 0.8]\n    Surface \"matte\"\n"
        "    Polygon \"P\" [-2 0 -2  -2 0 2  2 0 2  2 0 -2]\n  AttributeEnd\n"
        "  AttributeBegin\n    Translate -0.6 0.4 0\n    Color [0.9 0.5 0.3]\n"
        "    Surface \"plastic\"\n    Sphere 0.35 -0.35 0.35 360\n  AttributeEnd\n"
        "  AttributeBegin\n    Translate 0.6 0.4 0\n    Color [0.8 0.7 0.3]\n"
        "    Surface \"shinymetal\" \"roughness\" [0.2]\n"
        "    Displacement \"bumpy\"\n    Sphere 0.35 -0.35 0.35 360\n  AttributeEnd\n"
        "WorldEnd\n";
    write_file(ft_path(dir, "scene.rib"), scene);
    assert_int_equal(ft_standalone(dir, 8), 0);
    const char *log = ft_path(dir, "master.log"), *wlog = ft_path(dir, "worker.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "farm.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "8", NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 30));
    const char *wargv[] = {ft_worker, "--connect", ep, "--threads", "2", NULL};
    pid_t worker = ft_spawn(wlog, wargv);
    int rc = ft_wait(master, 120);
    if (rc != 0) fprintf(stderr, "master:\n%s\nworker:\n%s\n", ft_read(log), ft_read(wlog));
    assert_int_equal(rc, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "farm.exr")), 0);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_standard_shader_renders_with_no_shader_folder),
        cmocka_unit_test(test_constant_is_exactly_os_times_cs),
        cmocka_unit_test(test_matte_is_ka_ambient_plus_kd_cos),
        cmocka_unit_test(test_metal_and_shinymetal_are_tinted_highlights),
        cmocka_unit_test(test_plastic_has_an_untinted_highlight),
        cmocka_unit_test(test_bumpy_moves_the_plane_by_km_times_the_map),
        cmocka_unit_test(test_a_plastic_sl_on_the_search_path_wins),
        cmocka_unit_test(test_the_farm_renders_standard_shaders_as_standalone),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
