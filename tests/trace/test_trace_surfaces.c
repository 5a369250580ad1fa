/*
 * test_trace_surfaces.c: the displaced-surface intersector against closed
 * forms (issue 4 "Tests"): a constant displacement on a plane gives the
 * plane at that height; zero displacement on a sphere gives the analytic
 * silhouette; a spike much thinner than a pixel is hit by every ray through
 * it (the guarantee of conservative boxes, Heidrich & Seidel §3); the
 * vertical walls of a discontinuous displacement are found (§5). Each in
 * affine and in interval arithmetic.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "fixture.h"
#include "shaders.h"
#include "trace/camera.h"

static const trace_arith ARITHS[] = {TRACE_ARITH_AFFINE, TRACE_ARITH_INTERVAL};

static bool open_with(fixture *f, const char *rib, const fixture_shader *sh, int n,
                      trace_arith arith)
{
    job_options opt;
    job_options_default(&opt);
    opt.arith = arith;
    return fixture_open(f, rib, sh, n, &opt, 0);
}

/* raster coordinates of camera-space direction (dx, dy, 1) */
static void raster_of(const trace_camera *c, double dx, double dy, double *x, double *y)
{
    double sx = dx / c->tan_half_fov, sy = dy / c->tan_half_fov;
    *x = (sx - c->screen[0]) / (c->screen[1] - c->screen[0]) * c->xres;
    *y = (c->screen[3] - sy) / (c->screen[3] - c->screen[2]) * c->yres;
}

static double primary_depth(fixture *f, trace_thread *th, double dx, double dy)
{
    double x, y, rgb[3], a, z;
    raster_of(&f->js->world.camera, dx, dy, &x, &y);
    trace_render_sample(f->js->renderer, th, x, y, rgb, &a, &z);
    return z;
}

static void test_constant_displacement_plane(void **state)
{
    (void)state;
    const char *rib =
        "Format 64 48 1\nProjection \"perspective\" \"fov\" [40]\n"
        "WorldBegin\n"
        "Displacement \"constd\" \"float h\" [0.1]\n"
        "Polygon \"P\" [-1 -1 5  1 -1 5  1 1 5  -1 1 5]\n"
        "WorldEnd\n";
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}};
    for (int a = 0; a < 2; a++) {
        fixture f;
        assert_true(open_with(&f, rib, sh, 1, ARITHS[a]));
        trace_thread *th = trace_thread_new(&f.js->world);
        trace_tolerance tol = f.js->renderer->primary_tol;
        int n = 0;
        double worst = 0;
        for (int j = -10; j <= 10; j++)
            for (int i = -10; i <= 10; i++) {
                double dx = i * 0.015, dy = j * 0.015;   /* within the polygon at z = 5.1 */
                double z = primary_depth(&f, th, dx, dy);
                double err = fabs(z - 5.1);
                if (err > worst) worst = err;
                assert_true(err <= tol.b * 5.1 + 1e-9);
                n++;
            }
        printf("constant displacement, %s: %d rays, worst depth error %.2e (pixel footprint %.2e)\n",
               trace_arith_name(ARITHS[a]), n, worst, tol.b * 5.1);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

static void test_zero_displacement_sphere_silhouette(void **state)
{
    (void)state;
    const char *rib =
        "Format 48 48 1\nProjection \"perspective\" \"fov\" [30]\n"
        "WorldBegin\n"
        "Translate 0 0 5\n"
        "Displacement \"constd\" \"float h\" [0]\n"
        "Sphere 1 -1 1 360\n"
        "WorldEnd\n";
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}};
    for (int a = 0; a < 2; a++) {
        fixture f;
        assert_true(open_with(&f, rib, sh, 1, ARITHS[a]));
        trace_thread *th = trace_thread_new(&f.js->world);
        double margin = f.js->renderer->primary_tol.b * 5.0;
        int hits = 0, misses = 0, near = 0;
        for (int j = 0; j < 48; j++)
            for (int i = 0; i < 48; i++) {
                double dx = (i - 23.5) * 0.012, dy = (j - 23.5) * 0.012;
                /* distance of the ray (t*(dx,dy,1)) from the centre (0,0,5) */
                double dd = dx * dx + dy * dy + 1;
                double tc = 5.0 / dd;
                double px = tc * dx - 0, py = tc * dy, pz = tc - 5;
                double dist = sqrt(px * px + py * py + pz * pz);
                double z = primary_depth(&f, th, dx, dy);
                if (dist < 1 - margin) {
                    double th_ = sqrt(1 - dist * dist) / sqrt(dd);
                    double z_exact = tc - th_;
                    assert_true(fabs(z - z_exact) <= margin * 1.5);
                    hits++;
                } else if (dist > 1 + margin) {
                    assert_true(isinf(z));
                    misses++;
                } else {
                    near++;
                }
            }
        printf("sphere silhouette, %s: %d hits, %d misses checked, %d within a footprint of the edge\n",
               trace_arith_name(ARITHS[a]), hits, misses, near);
        assert_true(hits > 100 && misses > 100);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

/* ground plane y = -0.25 in camera space, centre (0, -0.25, 5) */
static const char *GROUND_RIB_FMT =
    "Format 64 48 1\nProjection \"perspective\" \"fov\" [40]\n"
    "WorldBegin\n"
    "Displacement \"%s\" %s\n"
    "Polygon \"P\" [-1 -0.25 4  -1 -0.25 6  1 -0.25 6  1 -0.25 4]\n"
    "WorldEnd\n";

static void test_thin_spike_is_always_hit(void **state)
{
    (void)state;
    char rib[1024];
    snprintf(rib, sizeof rib, GROUND_RIB_FMT, "spike", "\"float r0\" [0.001] \"float h\" [0.5]");
    fixture_shader sh[] = {{"spike", SHADER_SPIKE}};
    for (int a = 0; a < 2; a++) {
        fixture f;
        assert_true(open_with(&f, rib, sh, 1, ARITHS[a]));
        trace_thread *th = trace_thread_new(&f.js->world);
        double footprint = f.js->renderer->primary_tol.b * 5.0;
        /* horizontal rays at camera height 0 = 0.25 above the ground: the
         * spike's radius there is r0/2 in (s,t) = 0.001 in space */
        double r_half = 0.001;
        int inside = 0, outside = 0;
        for (int k = -60; k <= 60; k++) {
            double dx = k * 0.000005;          /* lateral offset 5 * dx at the spike */
            double lateral = fabs(5 * dx) / sqrt(1 + dx * dx);
            double z = primary_depth(&f, th, dx, 0.0);
            if (lateral < 0.8 * r_half) {
                assert_true(isfinite(z) && fabs(z - 5.0) < 0.01);
                inside++;
            } else if (lateral > r_half + 2 * footprint) {
                assert_true(isinf(z));
                outside++;
            }
        }
        for (int k = 1; k < 40; k++) {
            double dx = k * 0.01;
            double z = primary_depth(&f, th, dx, 0.0);
            assert_true(isinf(z));
            outside++;
        }
        printf("thin spike (%.0fx thinner than a pixel), %s: %d rays through it all hit, %d beside it all missed\n",
               footprint / (2 * r_half), trace_arith_name(ARITHS[a]), inside, outside);
        assert_true(inside >= 20);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

static void test_vertical_walls_are_found(void **state)
{
    (void)state;
    char rib[1024];
    snprintf(rib, sizeof rib, GROUND_RIB_FMT, "stepcyl", "\"float r0\" [0.25] \"float h\" [0.3]");
    fixture_shader sh[] = {{"stepcyl", SHADER_STEPCYL}};
    for (int a = 0; a < 2; a++) {
        fixture f;
        assert_true(open_with(&f, rib, sh, 1, ARITHS[a]));
        trace_thread *th = trace_thread_new(&f.js->world);
        double footprint = f.js->renderer->primary_tol.b * 5.0;
        double R = 0.5;   /* (s,t) radius 0.25 on a 2-unit polygon */
        int wall = 0, beside = 0;
        long walls_before = th->stats.wall_leaves;
        for (int k = -80; k <= 80; k++) {
            double dx = k * 0.002;
            /* ray t*(dx, -0.02, 1): about 0.15 above the ground near z = 5 */
            double dy = -0.1 / 5.0;
            /* the cylinder x^2 + (z-5)^2 = R^2 with the ray x = dx t, z = t */
            double A = dx * dx + 1, B = -10, C = 25 - R * R;
            double disc = B * B - 4 * A * C;
            double z = primary_depth(&f, th, dx, dy);
            double lateral = fabs(5 * dx) / sqrt(1 + dx * dx);
            if (disc > 0 && lateral < R - 2 * footprint) {
                double t = (-B - sqrt(disc)) / (2 * A);
                /* the ray is at height -0.25 + 0.1 + ... inside the wall's span */
                assert_true(fabs(z - t) <= 2 * footprint);
                wall++;
            } else if (lateral > R + 2 * footprint) {
                assert_true(!(z < 5.0 - R + footprint));
                beside++;
            }
        }
        long walls = th->stats.wall_leaves - walls_before;
        printf("vertical walls, %s: %d rays on the wall within 2 footprints of the analytic depth, "
               "%d beside it, %ld wall leaves (paper §5)\n",
               trace_arith_name(ARITHS[a]), wall, beside, walls);
        assert_true(wall > 30 && beside > 0);
        assert_true(walls > 0);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant_displacement_plane),
        cmocka_unit_test(test_zero_displacement_sphere_silhouette),
        cmocka_unit_test(test_thin_spike_is_always_hit),
        cmocka_unit_test(test_vertical_walls_are_found),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
