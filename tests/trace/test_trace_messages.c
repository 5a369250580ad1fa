/*
 * test_trace_messages.c: message passing through a real render (RI Spec
 * 3.2 §15.7). The displacement shader's output parameter at the hit is
 * what the surface shader reads with displacement("height", x); the
 * object's Sides with attribute(), the image size with option("Format"),
 * and RIB Clipping reaches depth(). The surface shader writes what it
 * read into Ci, compared here with the render's own s and z.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "fixture.h"

#define SHADER_LIFT \
    "displacement lift(float h = 0.25; output varying float height = 0)\n" \
    "{\n" \
    "    height = h * s;\n" \
    "    P += height * normalize(N);\n" \
    "    N = calculatenormal(P);\n" \
    "}\n"
#define SHADER_FLAT \
    "displacement flat(float h = 0.25)\n" \
    "{\n" \
    "    P += h * s * normalize(N);\n" \
    "}\n"
/* red: the height read (-1: none); green: height - 0.25 s, plus 100 when
 * an attribute or option is missing or wrong; blue: depth(P) */
#define SHADER_SHOWMSG \
    "surface showmsg()\n" \
    "{\n" \
    "    float hh = -1, sides = 0;\n" \
    "    point fmt = 0;\n" \
    "    float ok = attribute(\"Sides\", sides) * option(\"Format\", fmt);\n" \
    "    if (sides != 1 || xcomp(fmt) != 24 || ycomp(fmt) != 16) ok = 0;\n" \
    "    displacement(\"height\", hh);\n" \
    "    Ci = color(hh, (hh - 0.25 * s) + 100 * (1 - ok), depth(P));\n" \
    "    Oi = 1;\n" \
    "}\n"

/* the camera's projective spaces at the hit: raster x / 24, raster y / 16,
 * NDC z (screen z: 0 at the near plane, 1 at the far one) */
#define SHADER_SHOWRASTER \
    "surface showraster()\n" \
    "{\n" \
    "    point r = transform(\"raster\", P);\n" \
    "    point ndc = transform(\"NDC\", P);\n" \
    "    Ci = color(xcomp(r) / 24, ycomp(r) / 16, zcomp(ndc));\n" \
    "    Oi = 1;\n" \
    "}\n"

enum { W = 24, H = 16 };

static void render_with(const char *surface, const char *displacement, float *rgba, float *z)
{
    char rib[1024];
    snprintf(rib, sizeof rib,
             "Format 24 16 1\nProjection \"perspective\" \"fov\" [40]\nClipping 1 11\n"
             "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
             "WorldBegin\nSides 1\nSurface \"%s\"\nDisplacement \"%s\"\n"
             "Attribute \"displacementbound\" \"sphere\" [0.3]\n"
             "Patch \"bilinear\" \"P\" [-4 -4 6  4 -4 6  -4 4 6  4 4 6]\n"
             "WorldEnd\n", surface, displacement);
    fixture_shader sh[] = {{"lift", SHADER_LIFT}, {"flat", SHADER_FLAT},
                           {"showmsg", SHADER_SHOWMSG}, {"showraster", SHADER_SHOWRASTER}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 4, NULL, 0));
    assert_true(fixture_render(&f, 8, 2, 0, rgba, z));
    fixture_close(&f);
}

static void render(const char *displacement, float *rgba, float *z)
{
    render_with("showmsg", displacement, rgba, z);
}

/* transform("raster", P) at each pixel's hit is inside that pixel (its one
 * sample's raster position, to within the hit's leaf: 0.01 camera units,
 * 0.04 pixels here), and NDC z is the perspective's screen z of the
 * z channel: 11 (z - 1) / (10 z) for Clipping 1 11. */
static void test_raster_and_ndc_spaces_match_the_camera(void **state)
{
    (void)state;
    float *rgba = calloc(4 * W * H, sizeof *rgba), *z = calloc(W * H, sizeof *z);
    assert_non_null(rgba);
    assert_non_null(z);
    render_with("showraster", "flat", rgba, z);
    double worst_xy = 0, worst_z = 0;
    for (int j = 0; j < H; j++) {
        for (int i = 0; i < W; i++) {
            const float *px = &rgba[4 * (j * W + i)];
            assert_true(px[3] > 0.99f);
            double rx = px[0] * W - (i + 0.5), ry = px[1] * H - (j + 0.5);
            double dxy = fmax(fabs(rx), fabs(ry));
            double zc = z[j * W + i], sz = 11 * (zc - 1) / (10 * zc);
            worst_xy = fmax(worst_xy, dxy);
            worst_z = fmax(worst_z, fabs(px[2] - sz));
        }
    }
    printf("raster position of the hit - pixel centre <= %.3f pixels, |NDC z - screen z of "
           "the z channel| <= %.2g\n", worst_xy, worst_z);
    assert_true(worst_xy < 0.55);
    assert_true(worst_z < 1e-3);
    free(rgba);
    free(z);
}

static void test_surface_reads_displacement_outputs_attributes_options_depth(void **state)
{
    (void)state;
    float *rgba = calloc(4 * W * H, sizeof *rgba), *z = calloc(W * H, sizeof *z);
    assert_non_null(rgba);
    assert_non_null(z);
    render("lift", rgba, z);
    double worst_msg = 0, worst_depth = 0, lo = 1, hi = 0;
    int covered = 0;
    for (int i = 0; i < W * H; i++) {
        if (!(rgba[4 * i + 3] > 0.99)) continue;
        covered++;
        double height = rgba[4 * i], diff = fabs(rgba[4 * i + 1]);
        double depth = (z[i] - 1.0) / 10.0;
        if (height < lo) lo = height;
        if (height > hi) hi = height;
        if (diff > worst_msg) worst_msg = diff;
        if (fabs(rgba[4 * i + 2] - depth) > worst_depth) worst_depth = fabs(rgba[4 * i + 2] - depth);
    }
    printf("%d pixels: height read %.3f .. %.3f, |height - 0.25 s| <= %.2g, "
           "|depth(P) - (z - 1)/10| <= %.2g\n", covered, lo, hi, worst_msg, worst_depth);
    assert_int_equal(covered, W * H);
    assert_true(worst_msg < 1e-5);      /* the message is the hit's value; Sides, Format found */
    assert_true(lo >= 0 && hi <= 0.25 && hi - lo > 0.1);   /* varies with s */
    /* the z channel and the shaded P agree to within the hit's leaf size
     * (0.01 camera units here); without Clipping depth(P) would be ~0 */
    assert_true(worst_depth < 1e-3);
    free(rgba);
    free(z);
}

static void test_no_output_no_message(void **state)
{
    (void)state;
    float *rgba = calloc(4 * W * H, sizeof *rgba), *z = calloc(W * H, sizeof *z);
    assert_non_null(rgba);
    assert_non_null(z);
    render("flat", rgba, z);
    for (int i = 0; i < W * H; i++) assert_true(rgba[4 * i] == -1.0f);   /* hh unchanged */
    free(rgba);
    free(z);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_surface_reads_displacement_outputs_attributes_options_depth),
        cmocka_unit_test(test_no_output_no_message),
        cmocka_unit_test(test_raster_and_ndc_spaces_match_the_camera),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
