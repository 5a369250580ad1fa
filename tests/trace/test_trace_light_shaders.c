/*
 * test_trace_light_shaders.c: a RIB LightSource naming a light shader
 * (RI Spec 3.2 §9.3) runs that shader through the renderer's light
 * callback. A user-written pointlight (illuminate) and distantlight (solar)
 * render the same images as the built-in lights, shadows included (a
 * displaced sphere shadows a wall); a light shader given to Surface, or a
 * surface shader given to LightSource, is an error naming file:line:col.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fixture.h"
#include "shaders.h"

enum { W = 48, H = 32 };

/* camera at the origin looking down +z; a displaced wall at z = 6 and a
 * displaced sphere at z = 5 in front of it; the light (%s: its request)
 * placed by a Translate, so its space is not the world's */
static const char *RIB_FMT =
    "Format 48 32 1\nProjection \"perspective\" \"fov\" [50]\n"
    "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
    "WorldBegin\n"
    "Attribute \"light\" \"shadows\" [\"on\"]\n"
    "TransformBegin\n"
    "  Translate 0.5 0 1\n"
    "  %s\n"
    "TransformEnd\n"
    "Surface \"mymatte\"\n"
    "AttributeBegin\n"
    "  Displacement \"constd\" \"float h\" [0.05]\n"
    "  Polygon \"P\" [-4 -4 6  -4 4 6  4 4 6  4 -4 6]\n"
    "AttributeEnd\n"
    "AttributeBegin\n"
    "  Translate 0 0 5\n"
    "  Displacement \"constd\" \"float h\" [0.1]\n"
    "  Sphere 0.5 -0.5 0.5 360\n"
    "AttributeEnd\n"
    "WorldEnd\n";

static float *render(const char *light)
{
    char rib[2048];
    snprintf(rib, sizeof rib, RIB_FMT, light);
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}, {"mymatte", SHADER_MYMATTE},
                           {"mypoint", SHADER_MYPOINT}, {"mysun", SHADER_MYSUN}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 4, NULL, 0));
    float *rgba = calloc(4 * W * H, sizeof *rgba), *z = calloc(W * H, sizeof *z);
    assert_non_null(rgba);
    assert_non_null(z);
    assert_true(fixture_render(&f, 16, 2, 0, rgba, z));
    free(z);
    fixture_close(&f);
    return rgba;
}

/* largest difference between two images; counts lit and dark wall pixels
 * of the first */
static double compare(const float *a, const float *b, int *lit, int *dark)
{
    double worst = 0;
    *lit = *dark = 0;
    for (int i = 0; i < W * H; i++) {
        for (int k = 0; k < 4; k++) {
            double d = fabs((double)a[4 * i + k] - (double)b[4 * i + k]);
            if (d > worst) worst = d;
        }
        double lum = (a[4 * i] + a[4 * i + 1] + a[4 * i + 2]) / 3.0;
        if (lum > 1e-3) (*lit)++;
        else if (a[4 * i + 3] > 0.5) (*dark)++;
    }
    return worst;
}

static void same_as_builtin(const char *builtin, const char *user, const char *noshadow)
{
    float *a = render(builtin), *b = render(user), *c = render(noshadow);
    int lit, dark, lit_c, dark_c;
    double worst = compare(a, b, &lit, &dark);
    compare(c, c, &lit_c, &dark_c);
    printf("%s vs the light shader: %d lit, %d dark pixels, largest difference %.3g; "
           "without shadows %d lit\n", builtin, lit, dark, worst, lit_c);
    /* the images are the same (float tolerance) and not trivially so */
    assert_true(worst < 1e-5);
    assert_true(lit > W * H / 4);
    /* the sphere's shadow darkens wall pixels that are lit without shadows */
    assert_true(lit_c > lit);
    free(a);
    free(b);
    free(c);
}

static void test_user_pointlight_renders_as_builtin_pointlight(void **state)
{
    (void)state;
    same_as_builtin(
        "LightSource \"pointlight\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]",
        "LightSource \"mypoint\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]",
        "Attribute \"light\" \"shadows\" [\"off\"]\n"
        "LightSource \"mypoint\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]");
}

static void test_user_solar_light_renders_as_builtin_distantlight(void **state)
{
    (void)state;
    /* a short axis (length 0.1): the shadow rays must go on to infinity */
    same_as_builtin(
        "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.03 0.01 -0.9]",
        "LightSource \"mysun\" 1 \"from\" [0 0 -1] \"to\" [0.03 0.01 -0.9]",
        "Attribute \"light\" \"shadows\" [\"off\"]\n"
        "LightSource \"mysun\" 1 \"from\" [0 0 -1] \"to\" [0.03 0.01 -0.9]");
}

static void expect_error(const char *light, const char *surface, const char *want)
{
    char rib[1024];
    snprintf(rib, sizeof rib,
             "Format 8 8 1\nProjection \"perspective\"\nWorldBegin\n%s\nSurface \"%s\"\nSphere 1 -1 1 360\nWorldEnd\n",
             light, surface);
    fixture_shader sh[] = {{"mymatte", SHADER_MYMATTE}, {"mypoint", SHADER_MYPOINT}};
    fixture f;
    assert_false(fixture_open(&f, rib, sh, 2, NULL, 0));
    char *text = sl_diag_to_string(f.diag);
    if (!strstr(text, want)) printf("got: %s\nwanted: %s\n", text, want);
    assert_non_null(strstr(text, want));
    free(text);
    fixture_close(&f);
}

static void test_shader_of_the_wrong_kind_is_an_error(void **state)
{
    (void)state;
    expect_error("LightSource \"pointlight\" 1", "mypoint",
                 "test.rib:5:1: error: 'mypoint' is a light shader, used here as a surface "
                 "shader (give it to LightSource instead)");
    expect_error("LightSource \"mymatte\" 1", "mymatte",
                 "test.rib:4:1: error: 'mymatte' is a surface shader, used here as a light "
                 "shader (give it to Surface instead)");
    expect_error("LightSource \"nosuchlight\" 1", "mymatte",
                 "test.rib:4:1: error: shader 'nosuchlight' is not part of the job");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_user_pointlight_renders_as_builtin_pointlight),
        cmocka_unit_test(test_user_solar_light_renders_as_builtin_distantlight),
        cmocka_unit_test(test_shader_of_the_wrong_kind_is_an_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
