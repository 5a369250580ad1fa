/*
 * test_trace_dof.c: DepthOfField as a thin lens (issue 14; RI Spec 3.2
 * §4.1.2, lens diameter focallength / fstop):
 *   - every lens ray of a pixel sample meets the pinhole ray at the focal
 *     distance, and starts on the lens disk;
 *   - an edge on the focal plane stays sharp: its alpha equals the pinhole
 *     render's;
 *   - an edge off the focal plane blurs by the thin lens's circle of
 *     confusion, 2 R |z - fd| / (z fd) at z = 1: its alpha profile across
 *     the edge follows the disk's coverage integrated over each pixel,
 *     within sampling error; the pinhole render of it is a one-pixel step;
 *   - the lens samples are deterministic: any tile size and thread order
 *     give the same image (so a farm render equals the standalone one);
 *   - DepthOfField with no arguments is a pinhole again; bad values are
 *     errors naming the request.
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
#include "trace/camera.h"
#include "trace/sampler.h"

enum { W = 64, H = 32 };

/* A wall covering x >= 0 at depth z (camera space = world space), seen
 * through a 40 degree lens, 8x8 samples, box filter: alpha is coverage. */
static char *scene_rib(double z, const char *dof)
{
    char *rib = malloc(1024);
    assert_non_null(rib);
    snprintf(rib, 1024,
             "Format %d %d 1\nProjection \"perspective\" \"fov\" [40]\n"
             "PixelSamples 8 8\nPixelFilter \"box\" 1 1\n%s\n"
             "WorldBegin\nPolygon \"P\" [0 -10 %g  10 -10 %g  10 10 %g  0 10 %g]\nWorldEnd\n",
             W, H, dof, z, z, z, z);
    return rib;
}

static void render_alpha(const char *rib, int tile, int threads, float *alpha, float *rgba_out)
{
    fixture f;
    assert_true(fixture_open(&f, rib, NULL, 0, NULL, 0));
    float *rgba = malloc(sizeof(float) * 4 * W * H), *z = malloc(sizeof(float) * W * H);
    assert_non_null(rgba);
    assert_non_null(z);
    assert_true(fixture_render(&f, tile, threads, 0, rgba, z));
    for (int i = 0; i < W * H; i++) alpha[i] = rgba[4 * i + 3];
    if (rgba_out) memcpy(rgba_out, rgba, sizeof(float) * 4 * W * H);
    free(rgba);
    free(z);
    fixture_close(&f);
}

static void test_lens_rays_meet_at_the_focal_distance(void **state)
{
    (void)state;
    trace_camera cam = {.xres = W, .yres = H, .screen = {-2, 2, -1, 1},
                        .tan_half_fov = tan(20 * M_PI / 180), .near_clip = 1e-10,
                        .far_clip = 1e30, .lens_radius = 0.25, .focal_distance = 3};
    double widest = 0;
    for (int s = 0; s < 64; s++) {
        double x = 10.3 + 0.7 * s, y = 5.2 + 0.3 * s, u, v;
        trace_sample_lens(12, 7, s, 8, 8, &u, &v);
        assert_true(u >= 0 && u < 1 && v >= 0 && v < 1);
        trace_ray pin, lens;
        trace_camera_ray(&cam, x, y, &pin);
        trace_camera_lens_ray(&cam, x, y, u, v, &lens);
        double r = hypot(lens.o.x, lens.o.y);
        assert_true(r <= cam.lens_radius * (1 + 1e-12));
        assert_true(lens.o.z == 0 && lens.d.z == 1);
        if (r > widest) widest = r;
        vec3 a = trace_ray_at(&pin, 3), b = trace_ray_at(&lens, 3);
        assert_true(fabs(a.x - b.x) < 1e-14 && fabs(a.y - b.y) < 1e-14);
    }
    assert_true(widest > 0.5 * cam.lens_radius);   /* the lens is really used */
    /* the lens centre is the pinhole */
    trace_ray pin, lens;
    trace_camera_ray(&cam, 3.5, 4.5, &pin);
    trace_camera_lens_ray(&cam, 3.5, 4.5, 0.5, 0.5, &lens);
    assert_true(lens.o.x == 0 && lens.o.y == 0 && lens.d.x == pin.d.x && lens.d.y == pin.d.y);
}

static void test_focal_plane_stays_sharp(void **state)
{
    (void)state;
    float *pin = malloc(sizeof(float) * W * H), *dof = malloc(sizeof(float) * W * H);
    assert_non_null(pin);
    assert_non_null(dof);
    char *a = scene_rib(4, ""), *b = scene_rib(4, "DepthOfField 1 0.5 4");
    render_alpha(a, 16, 1, pin, NULL);
    render_alpha(b, 16, 1, dof, NULL);
    double worst = 0;
    for (int i = 0; i < W * H; i++)
        if (fabs(pin[i] - dof[i]) > worst) worst = fabs(pin[i] - dof[i]);
    printf("edge on the focal plane: largest alpha difference to the pinhole %.4f\n", worst);
    assert_true(worst <= 1.0 / 64 + 1e-6);   /* at most one sample of 64 at the very edge */
    free(a);
    free(b);
    free(pin);
    free(dof);
}

/* Fraction of a disk of radius 1 with x <= c. */
static double disk_below(double c)
{
    if (c <= -1) return 0;
    if (c >= 1) return 1;
    return 0.5 + (c * sqrt(1 - c * c) + asin(c)) / M_PI;
}

static void test_out_of_focus_edge_blurs_by_the_circle_of_confusion(void **state)
{
    (void)state;
    const double z = 4, fd = 2, fstop = 1, flen = 0.5, R = 0.5 * flen / fstop;
    const double tanh = tan(20 * M_PI / 180);
    const double pixel = 2.0 / H * tanh;                 /* one pixel at z = 1 */
    const double coc = 2 * R * fabs(z - fd) / (z * fd);  /* diameter at z = 1 */
    char dof_text[64];
    snprintf(dof_text, sizeof dof_text, "DepthOfField %g %g %g", fstop, flen, fd);
    char *a = scene_rib(z, dof_text), *b = scene_rib(z, "");
    float *dof = malloc(sizeof(float) * W * H), *pin = malloc(sizeof(float) * W * H);
    assert_non_null(dof);
    assert_non_null(pin);
    render_alpha(a, 16, 2, dof, NULL);
    render_alpha(b, 16, 2, pin, NULL);
    /* the rows' mean alpha per column against the disk's coverage: a
     * sample at screen x sees the wall when x >= k lx, lx on the lens,
     * k = (z - fd) / (z fd) */
    double worst = 0;
    int blurred = 0, pin_blurred = 0;
    for (int col = 0; col < W; col++) {
        double mean = 0, pmean = 0;
        for (int row = 4; row < H - 4; row++) {
            mean += dof[row * W + col];
            pmean += pin[row * W + col];
        }
        mean /= H - 8;
        pmean /= H - 8;
        double want = 0;
        for (int k = 0; k < 64; k++) {   /* over the pixel's width */
            double sx = ((col + (k + 0.5) / 64) - 0.5 * W) * pixel;
            want += disk_below(sx / (0.5 * coc)) / 64;
        }
        double err = fabs(mean - want);
        if (err > worst) worst = err;
        if (mean > 0.01 && mean < 0.99) blurred++;
        if (pmean > 0.01 && pmean < 0.99) pin_blurred++;
    }
    printf("circle of confusion %.2f pixels: %d columns blurred (pinhole %d), largest "
           "difference of the mean alpha to the thin-lens profile %.4f\n", coc / pixel,
           blurred, pin_blurred, worst);
    assert_true(worst < 0.03);
    assert_true(fabs(blurred - coc / pixel) <= 1.5);
    assert_true(pin_blurred <= 1);
    free(a);
    free(b);
    free(dof);
    free(pin);
}

static void test_deterministic_across_tiles_and_threads(void **state)
{
    (void)state;
    char *rib = scene_rib(4, "DepthOfField 1.4 0.5 2.5");
    float *a = malloc(sizeof(float) * 4 * W * H), *b = malloc(sizeof(float) * 4 * W * H);
    float *alpha = malloc(sizeof(float) * W * H);
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(alpha);
    render_alpha(rib, 8, 1, alpha, a);
    render_alpha(rib, 13, 3, alpha, b);
    assert_memory_equal(a, b, sizeof(float) * 4 * W * H);
    free(rib);
    free(a);
    free(b);
    free(alpha);
}

static void test_dof_requests(void **state)
{
    (void)state;
    fixture f;
    char *rib = scene_rib(4, "DepthOfField 2.8 0.1 5\nDepthOfField");
    assert_true(fixture_open(&f, rib, NULL, 0, NULL, 0));
    assert_true(f.js->world.camera.lens_radius == 0);   /* off again */
    fixture_close(&f);
    free(rib);
    rib = scene_rib(4, "DepthOfField 2 0.1 5");
    assert_true(fixture_open(&f, rib, NULL, 0, NULL, 0));
    assert_true(fabs(f.js->world.camera.lens_radius - 0.025) < 1e-15);
    assert_true(f.js->world.camera.focal_distance == 5);
    fixture_close(&f);
    free(rib);
    rib = scene_rib(4, "DepthOfField 2 0 5");
    assert_false(fixture_open(&f, rib, NULL, 0, NULL, 0));
    assert_true(sl_diag_error_count(f.diag) == 1);
    assert_non_null(strstr(sl_diag_get(f.diag, 0)->message,
                           "DepthOfField: needs fstop, focallength and focaldistance > 0, got "
                           "2 0 5"));
    fixture_close(&f);
    free(rib);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lens_rays_meet_at_the_focal_distance),
        cmocka_unit_test(test_focal_plane_stays_sharp),
        cmocka_unit_test(test_out_of_focus_edge_blurs_by_the_circle_of_confusion),
        cmocka_unit_test(test_deterministic_across_tiles_and_threads),
        cmocka_unit_test(test_dof_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
