/*
 * test_trace_light_memo.c: a shading point's light samples are made once
 * (shade.c, LIGHT_MEMO) for all the light calls of its surface shader:
 * ambient(), diffuse(), specular() and an illuminance loop each ask for
 * them, and each would trace the shadow rays again. The memo must change
 * no pixel: the scene (a displaced wall and sphere, shadows from a distant
 * light, a point light and a light shader, a plastic sphere and a wall
 * whose shader mixes an illuminance loop with diffuse() and ambient()) is
 * rendered with the world option light_memo on and off, and the images
 * (RGBA and depth) must be the same to the bit, while the shadow rays
 * traced fall to at most 1/2.5 (the wall asks three times, the sphere
 * three).
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
#include "trace/render.h"
#include "trace/thread.h"

/* an illuminance loop beside diffuse() and ambient(): three light calls */
#define SHADER_LOOPLIT \
    "surface looplit(float Kd = 1)\n" \
    "{\n" \
    "    normal Nf = faceforward(normalize(N), I);\n" \
    "    color c = 0;\n" \
    "    illuminance(P, Nf, PI / 2)\n" \
    "        c += Cl * (normalize(L) . Nf);\n" \
    "    Ci = Os * Cs * (0.5 * c + 0.5 * Kd * diffuse(Nf) + 0.2 * ambient());\n" \
    "    Oi = Os;\n" \
    "}\n"

/* RenderMan's plastic as a user writes it: three more light calls */
#define SHADER_MYPLASTIC \
    "surface myplastic(float Ka = 1, Kd = 0.5, Ks = 0.5, roughness = 0.1)\n" \
    "{\n" \
    "    normal Nf = faceforward(normalize(N), I);\n" \
    "    vector V = -normalize(I);\n" \
    "    Ci = Cs * (Ka * ambient() + Kd * diffuse(Nf)) + Ks * specular(Nf, V, roughness);\n" \
    "    Oi = Os;\n" \
    "    Ci *= Oi;\n" \
    "}\n"

enum { W = 48, H = 32 };

/* camera at the origin looking down +z; a displaced wall at z = 6 behind
 * a displaced sphere at z = 5 */
static const char *RIB_FMT =
    "Format 48 32 1\nProjection \"perspective\" \"fov\" [50]\n"
    "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
    "WorldBegin\n"
    "Attribute \"light\" \"shadows\" [\"%s\"]\n"
    "LightSource \"ambientlight\" 1 \"intensity\" [0.2]\n"
    "LightSource \"distantlight\" 2 \"from\" [0 0 0] \"to\" [1 0.3 1]\n"
    "LightSource \"pointlight\" 3 \"from\" [-1.5 1 3.5] \"intensity\" [6]\n"
    "TransformBegin\n"
    "  Translate 0.5 0 1\n"
    "  LightSource \"mysun\" 4 \"from\" [0 0 0] \"to\" [-0.6 -0.4 1]\n"
    "TransformEnd\n"
    "AttributeBegin\n"
    "  Surface \"looplit\"\n"
    "  Displacement \"constd\" \"float h\" [0.05]\n"
    "  Polygon \"P\" [-4 -3 6  -4 3 6  4 3 6  4 -3 6]\n"
    "AttributeEnd\n"
    "AttributeBegin\n"
    "  Surface \"myplastic\" \"Ks\" [0.6] \"roughness\" [0.2]\n"
    "  Translate 0 0 5\n"
    "  Displacement \"constd\" \"float h\" [0.1]\n"
    "  Sphere 0.5 -0.5 0.5 360\n"
    "AttributeEnd\n"
    "WorldEnd\n";

/* the whole image on one thread, tiles of 16; its shadow rays */
static long render(const char *shadows, bool memo, float *rgba, float *z)
{
    char rib[2048];
    snprintf(rib, sizeof rib, RIB_FMT, shadows);
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}, {"looplit", SHADER_LOOPLIT},
                           {"mysun", SHADER_MYSUN}, {"myplastic", SHADER_MYPLASTIC}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 4, NULL, 0));
    f.js->world.options.light_memo = memo;
    trace_thread *th = trace_thread_new(&f.js->world);
    assert_non_null(th);
    enum { T = 16 };
    float trgba[4 * T * T], tz[T * T];
    for (int y0 = 0; y0 < H; y0 += T)
        for (int x0 = 0; x0 < W; x0 += T) {
            assert_true(trace_render_tile(f.js->renderer, th, x0, y0, T, T, trgba, tz));
            for (int y = 0; y < T; y++) {
                memcpy(&rgba[((size_t)(y0 + y) * W + (size_t)x0) * 4], &trgba[y * T * 4],
                       sizeof(float) * 4 * T);
                memcpy(&z[(size_t)(y0 + y) * W + (size_t)x0], &tz[y * T], sizeof(float) * T);
            }
        }
    long rays = th->stats.shadow_rays;
    trace_thread_destroy(&th);
    fixture_close(&f);
    return rays;
}

static double lum(const float *px)
{
    return (px[0] + px[1] + px[2]) / 3.0;
}

static void test_same_pixels_fewer_rays(void **state)
{
    (void)state;
    static float a[4 * W * H], b[4 * W * H], c[4 * W * H], za[W * H], zb[W * H], zc[W * H];
    long on = render("on", true, a, za), off = render("on", false, b, zb);
    render("off", true, c, zc);
    int differ = 0, shadowed = 0;
    for (int i = 0; i < W * H; i++) {
        if (memcmp(&a[4 * i], &b[4 * i], 4 * sizeof(float)) != 0 ||
            memcmp(&za[i], &zb[i], sizeof(float)) != 0)
            differ++;
        if (lum(&a[4 * i]) < lum(&c[4 * i]) - 0.02)
            shadowed++;
    }
    printf("light memo: %ld shadow rays (off: %ld, %.2fx), %d of %d pixels differ; "
           "%d pixels darker than without shadows\n", on, off,
           on > 0 ? (double)off / (double)on : 0.0, differ, W * H, shadowed);
    assert_int_equal(differ, 0);
    /* the shadows show (the comparison means something) */
    assert_true(shadowed > 50);
    assert_true(on > 1000);
    assert_true((double)off >= 2.5 * (double)on);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_pixels_fewer_rays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
