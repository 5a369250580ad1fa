/*
 * test_trace_shadows.c: ray-traced shadows with displaced objects on both
 * sides: a displaced sphere (occluder) between a distant light and a
 * displaced wall (receiver). A wall point inside the shadow is dark, one
 * outside it is lit with the Lambert value N.L; with "shadows" off the
 * shadowed point is lit too.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "fixture.h"
#include "shaders.h"

/* camera at the origin looking down +z; wall at z = 6 facing the camera
 * (displaced 0.05 towards it), sphere of radius 0.3 (+0.1 displaced) at
 * z = 5; light travelling along (1, 0, 1)/sqrt(2): the shadow's centre on
 * the wall is about (1, 0, 5.95). */
static const char *RIB_FMT =
    "Format 96 48 1\nProjection \"perspective\" \"fov\" [40]\n"
    "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
    "WorldBegin\n"
    "Attribute \"light\" \"shadows\" [\"%s\"]\n"
    "LightSource \"distantlight\" 1 \"from\" [0 0 0] \"to\" [1 0 1]\n"
    "Surface \"mymatte\"\n"
    "AttributeBegin\n"
    "  Displacement \"constd\" \"float h\" [0.05]\n"
    "  Polygon \"P\" [-3 -3 6  -3 3 6  3 3 6  3 -3 6]\n"
    "AttributeEnd\n"
    "AttributeBegin\n"
    "  Translate 0 0 5\n"
    "  Displacement \"constd\" \"float h\" [0.1]\n"
    "  Sphere 0.3 -0.3 0.3 360\n"
    "AttributeEnd\n"
    "WorldEnd\n";

/* shade the wall point (x, y, 5.95) seen from the camera */
static double lum_at(fixture *f, trace_thread *th, double x, double y)
{
    const trace_camera *c = &f->js->world.camera;
    double z = 5.95, sx = x / z / c->tan_half_fov, sy = y / z / c->tan_half_fov;
    double rx = (sx - c->screen[0]) / (c->screen[1] - c->screen[0]) * c->xres;
    double ry = (c->screen[3] - sy) / (c->screen[3] - c->screen[2]) * c->yres;
    double rgb[3], a, d;
    trace_render_sample(f->js->renderer, th, rx, ry, rgb, &a, &d);
    if (!(fabs(d - 5.95) < 0.1)) printf("depth at (%g, %g): %g\n", x, y, d);
    assert_true(fabs(d - 5.95) < 0.1);      /* we did see the wall */
    return (rgb[0] + rgb[1] + rgb[2]) / 3.0;
}

static void run(const char *shadows, double *in_shadow, double *lit)
{
    char rib[2048];
    snprintf(rib, sizeof rib, RIB_FMT, shadows);
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}, {"mymatte", SHADER_MYMATTE}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 2, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    *in_shadow = lum_at(&f, th, 1.0, 0.0);
    *lit = lum_at(&f, th, -1.0, 0.5);
    printf("shadows %s: wall in the sphere's shadow %.3f, outside it %.3f, %ld shadow rays\n",
           shadows, *in_shadow, *lit, th->stats.shadow_rays);
    if (shadows[1] == 'n') assert_true(th->stats.shadow_rays >= 2);   /* "on" */
    else assert_int_equal(th->stats.shadow_rays, 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_displaced_occluder_casts_shadow_on_displaced_wall(void **state)
{
    (void)state;
    double dark, lit;
    run("on", &dark, &lit);
    assert_true(dark < 1e-6);
    /* Lambert: the wall's normal (0,0,-1) against L = -(1,0,1)/sqrt(2) */
    assert_true(fabs(lit - M_SQRT1_2) < 0.02);
}

static void test_shadows_off_lights_everything(void **state)
{
    (void)state;
    double dark, lit;
    run("off", &dark, &lit);
    assert_true(fabs(dark - M_SQRT1_2) < 0.02);
    assert_true(fabs(lit - M_SQRT1_2) < 0.02);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_displaced_occluder_casts_shadow_on_displaced_wall),
        cmocka_unit_test(test_shadows_off_lights_everything),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
