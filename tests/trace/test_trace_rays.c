/*
 * test_trace_rays.c: rays traced by shaders (RI Spec 3.2 §15.6 trace,
 * §15.7 shadow). A mirror floor (Ci = trace(P, reflect(I, N))) shows a
 * displaced sphere exactly where a ray traced directly from the floor point
 * finds it, with the sphere's own shading; two facing mirrors stop after
 * TRACE_MAX_RAY_DEPTH reflections; shadow() without a shadow map, in a
 * light shader (illuminate and solar) and in a surface shader's
 * illuminance loop, darkens exactly the pixels the renderer's own shadow
 * rays darken (the built-in lights with "shadows" on).
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
#include "trace/camera.h"
#include "trace/shade.h"

#define SHADER_MIRROR \
    "surface mirror(float Kr = 1)\n" \
    "{\n" \
    "    Ci = Kr * trace(P, reflect(normalize(I), normalize(N)));\n" \
    "    Oi = 1;\n" \
    "}\n"
/* the surface's (s, t), so a colour tells where a ray hit */
#define SHADER_STCOLOR \
    "surface stcolor()\n" \
    "{\n" \
    "    Ci = color(s, t, 0.5);\n" \
    "    Oi = 1;\n" \
    "}\n"
/* a mirror that also glows: 0.25 + 0.5 * (what it reflects) */
#define SHADER_HALFMIRROR \
    "surface halfmirror()\n" \
    "{\n" \
    "    Ci = 0.25 + 0.5 * trace(P, reflect(normalize(I), normalize(N)));\n" \
    "    Oi = 1;\n" \
    "}\n"

enum { W = 48, H = 32 };

/* camera at the origin looking down +z; a mirror floor at y = -1; a
 * displaced sphere (radius 0.5 + 0.1) above it at (0, -0.2, 5) */
static const char *MIRROR_RIB =
    "Format 48 32 1\nProjection \"perspective\" \"fov\" [50]\n"
    "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
    "WorldBegin\n"
    "AttributeBegin\n"
    "  Surface \"mirror\"\n"
    "  Polygon \"P\" [-6 -1 1  -6 -1 14  6 -1 14  6 -1 1]\n"
    "AttributeEnd\n"
    "AttributeBegin\n"
    "  Surface \"stcolor\"\n"
    "  Translate 0 -0.2 5\n"
    "  Displacement \"constd\" \"float h\" [0.1]\n"
    "  Sphere 0.5 -0.5 0.5 360\n"
    "AttributeEnd\n"
    "WorldEnd\n";

static void test_mirror_floor_shows_the_sphere_where_a_direct_ray_finds_it(void **state)
{
    (void)state;
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}, {"mirror", SHADER_MIRROR},
                           {"stcolor", SHADER_STCOLOR}};
    fixture f;
    assert_true(fixture_open(&f, MIRROR_RIB, sh, 3, NULL, 0));
    const trace_renderer *r = f.js->renderer;
    const trace_world *w = &f.js->world;
    const trace_object *floor_obj = &w->objects[0];
    trace_thread *th = trace_thread_new(w), *direct = trace_thread_new(w);
    int floor_px = 0, reflected = 0, sky = 0, differ = 0;
    double worst = 0, worst_st = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double rgb[3], a, z;
            trace_render_sample(r, th, x + 0.5, y + 0.5, rgb, &a, &z);
            /* the same floor point and reflected ray, computed here */
            trace_ray ray;
            trace_camera_ray(&w->camera, x + 0.5, y + 0.5, &ray);
            trace_hit hit = {.t = ray.tmax, .obj = NULL};
            if (!trace_bvh_intersect(r->bvh, direct, &ray, &r->primary_tol, false, &hit) ||
                hit.obj != floor_obj)
                continue;
            floor_px++;
            vec3 P = trace_ray_at(&ray, hit.t), N = v3(0, 1, 0);
            vec3 In = v3_normalize(v3_sub(P, ray.o));
            vec3 R = v3_sub(In, v3_scale(N, 2 * v3_dot(In, N)));
            vec3 o = v3_add(P, v3_scale(N, 1e-9 * (1 + v3_length(P))));
            trace_ray refl;
            trace_ray_init(&refl, o, R, 0.0, INFINITY);
            trace_tolerance tol = {r->primary_tol.a + r->primary_tol.b * fabs(P.z), 0};
            trace_hit h2 = {.t = INFINITY, .obj = NULL};
            double want[3] = {0, 0, 0}, st[3] = {0, 0, 0};
            if (trace_bvh_intersect(r->bvh, direct, &refl, &tol, false, &h2)) {
                double al;
                vec3 at;
                trace_shade_hit(r, direct, &refl, &h2, want, &al, &at);
                st[0] = h2.u;
                st[1] = h2.v;
                st[2] = 0.5;
                reflected++;
            } else {
                sky++;
            }
            double d = 0, dst = 0;
            for (int k = 0; k < 3; k++) {
                d = fmax(d, fabs(rgb[k] - want[k]));
                dst = fmax(dst, fabs(rgb[k] - st[k]));
            }
            if (d > 1e-6) differ++;
            else worst = fmax(worst, d);
            if (d <= 1e-6 && dst > worst_st) worst_st = dst;
        }
    printf("mirror floor: %d pixels, %d reflect the sphere, %d the sky; %d differ from the "
           "direct trace (others by at most %.2g; from the hit's (s, t) by %.2g)\n",
           floor_px, reflected, sky, differ, worst, worst_st);
    assert_true(floor_px > W * H / 4);
    assert_true(reflected > 30);
    assert_true(sky > 30);
    /* rays that graze the silhouette may fall either way by a rounding */
    assert_true(differ <= 2);
    /* the colour is the sphere's (s, t) where the direct ray hit it (within
     * the leaf the hit was found in) */
    assert_true(worst_st < 0.02);
    trace_thread_destroy(&th);
    trace_thread_destroy(&direct);
    fixture_close(&f);
}

/* One mirror in front of the camera, one behind it: every camera ray
 * bounces between them; each level adds 0.25 * 0.5^depth, and the ray one
 * deeper than maxdepth (the RIB's Option "trace" "maxdepth", default
 * TRACE_MAX_RAY_DEPTH) sees black. */
static void facing_mirrors(const char *option, int maxdepth)
{
    char rib[1024];
    snprintf(rib, sizeof rib,
             "Format 8 8 1\nProjection \"perspective\" \"fov\" [20]\n"
             "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n%s"
             "WorldBegin\n"
             "Surface \"halfmirror\"\n"
             "Polygon \"P\" [-100 -100 6  -100 100 6  100 100 6  100 -100 6]\n"
             "Polygon \"P\" [-100 -100 -1  100 -100 -1  100 100 -1  -100 100 -1]\n"
             "WorldEnd\n", option);
    fixture_shader sh[] = {{"halfmirror", SHADER_HALFMIRROR}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    double want = 0;
    for (int d = 0; d <= maxdepth; d++) want += 0.25 * pow(0.5, d);
    trace_thread *th = trace_thread_new(&f.js->world);
    double worst = 0;
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(rgb[k] - want));
        }
    printf("facing mirrors: %g expected (%d reflections), largest difference %.2g\n", want,
           maxdepth, worst);
    assert_false(th->failed);
    assert_true(worst < 1e-12);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_facing_mirrors_stop_at_the_depth_limit(void **state)
{
    (void)state;
    facing_mirrors("", TRACE_MAX_RAY_DEPTH);
    facing_mirrors("Option \"trace\" \"maxdepth\" [2]\n", 2);
    facing_mirrors("Option \"trace\" \"maxdepth\" [0]\n", 0);
    facing_mirrors("Option \"trace\" \"maxdepth\" [9]\n", 9);
}

static void test_rays_in_loops_at_every_depth_hit_the_limit(void **state)
{
    (void)state;
    /* 40 rays per shading, 4 levels deep: 40^4 rays without the limit */
    const char *greedy =
        "surface greedy()\n"
        "{\n"
        "    color C = 0;\n"
        "    float i;\n"
        "    for (i = 0; i < 40; i += 1)\n"
        "        C += trace(P, reflect(normalize(I), normalize(N))) / 40;\n"
        "    Ci = 0.5 + 0.5 * C;\n"
        "    Oi = 1;\n"
        "}\n";
    const char *rib =
        "Format 4 4 1\nProjection \"perspective\" \"fov\" [20]\n"
        "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
        "WorldBegin\n"
        "Surface \"greedy\"\n"
        "Polygon \"P\" [-100 -100 6  -100 100 6  100 100 6  100 -100 6]\n"
        "Polygon \"P\" [-100 -100 -1  100 -100 -1  100 100 -1  -100 100 -1]\n"
        "WorldEnd\n";
    fixture_shader sh[] = {{"greedy", greedy}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    double rgb[3], a, z;
    trace_render_sample(f.js->renderer, th, 2, 2, rgb, &a, &z);
    printf("greedy shader: %s\n", th->error);
    assert_true(th->failed);
    assert_non_null(strstr(th->error, "surface shader 'greedy': more than 1024 rays traced by "
                                      "trace() and shadow() for one sample"));
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* ---- shadow() ---- */

#define SHADER_SHADOWPOINT \
    "light shadowpoint(float intensity = 1; color lightcolor = 1;\n" \
    "                  point from = point \"shader\" (0, 0, 0);\n" \
    "                  string shadowname = \"nosuchmap\")\n" \
    "{\n" \
    "    illuminate(from) {\n" \
    "        Cl = intensity * lightcolor / (L . L);\n" \
    "        Cl *= 1 - shadow(shadowname, Ps, \"blur\", 0.01);\n" \
    "    }\n" \
    "}\n"
#define SHADER_SHADOWSUN \
    "light shadowsun(float intensity = 1; color lightcolor = 1;\n" \
    "                point from = point \"shader\" (0, 0, 0);\n" \
    "                point to = point \"shader\" (0, 0, 1))\n" \
    "{\n" \
    "    solar(to - from, 0.0)\n" \
    "        Cl = intensity * lightcolor * (1 - shadow(\"sunmap\", Ps));\n" \
    "}\n"
/* mymatte's diffuse written as an illuminance loop, shadowed by shadow() */
#define SHADER_SHADOWMATTE \
    "surface shadowmatte()\n" \
    "{\n" \
    "    normal Nf = faceforward(normalize(N), I);\n" \
    "    color c = 0;\n" \
    "    illuminance(P, Nf, PI / 2)\n" \
    "        c += Cl * (1 - shadow(\"mapless\", P)) * (normalize(L) . Nf);\n" \
    "    Ci = Os * Cs * c;\n" \
    "    Oi = Os;\n" \
    "}\n"

/* a displaced wall at z = 6, a displaced sphere at z = 5 before it; the
 * light (first %s) placed by a Translate near the sphere, so that its
 * shadow on the wall shows beside it; the wall's surface (second) */
static const char *SHADOW_RIB =
    "Format 48 32 1\nProjection \"perspective\" \"fov\" [50]\n"
    "PixelSamples 1 1\nPixelFilter \"box\" 1 1\n"
    "WorldBegin\n"
    "TransformBegin\n"
    "  Translate 1.5 0 3\n"
    "  %s\n"
    "TransformEnd\n"
    "Surface \"%s\"\n"
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

/* The renderer's warnings (trace_renderer_set_log) of the last render. */
static int warnings;
static char last_warning[1024];

static void count_warning(void *user, const char *message)
{
    (void)user;
    warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", message);
}

static float *render(const char *light, const char *surface)
{
    char rib[2048];
    snprintf(rib, sizeof rib, SHADOW_RIB, light, surface);
    fixture_shader sh[] = {{"constd", SHADER_CONSTD}, {"mymatte", SHADER_MYMATTE},
                           {"shadowpoint", SHADER_SHADOWPOINT},
                           {"shadowsun", SHADER_SHADOWSUN},
                           {"shadowmatte", SHADER_SHADOWMATTE}};
    fixture f;
    assert_true(fixture_open(&f, rib, sh, 5, NULL, 0));
    warnings = 0;
    last_warning[0] = '\0';
    trace_renderer_set_log(f.js->renderer, count_warning, NULL);
    float *rgba = calloc(4 * W * H, sizeof *rgba), *z = calloc(W * H, sizeof *z);
    assert_non_null(rgba);
    assert_non_null(z);
    assert_true(fixture_render(&f, 16, 2, 0, rgba, z));
    free(z);
    fixture_close(&f);
    return rgba;
}

/* the user's shadow() image against the built-in light's with "shadows"
 * on; the same light unshadowed lights more pixels */
static void same_shadows(const char *builtin_shadowed, const char *builtin_unshadowed,
                         const char *light, const char *surface)
{
    float *a = render(builtin_shadowed, "mymatte"), *b = render(light, surface);
    float *c = render(builtin_unshadowed, "mymatte");
    double worst = 0;
    int lit_a = 0, lit_c = 0, dark_here = 0;
    for (int i = 0; i < W * H; i++) {
        for (int k = 0; k < 4; k++)
            worst = fmax(worst, fabs((double)a[4 * i + k] - (double)b[4 * i + k]));
        double la = (a[4 * i] + a[4 * i + 1] + a[4 * i + 2]) / 3.0;
        double lc = (c[4 * i] + c[4 * i + 1] + c[4 * i + 2]) / 3.0;
        double lb = (b[4 * i] + b[4 * i + 1] + b[4 * i + 2]) / 3.0;
        if (la > 1e-3) lit_a++;
        if (lc > 1e-3) lit_c++;
        if (lc > 1e-3 && lb < 1e-6) dark_here++;
    }
    printf("%s / %s: %d lit with the built-in's shadows, %d without; %d darkened by "
           "shadow(); largest difference %.3g\n", light, surface, lit_a, lit_c, dark_here,
           worst);
    assert_true(worst < 1e-5);
    assert_true(lit_a > W * H / 4);
    assert_true(lit_c > lit_a + 20);
    assert_int_equal(dark_here, lit_c - lit_a);
    free(a);
    free(b);
    free(c);
}

static void test_shadow_in_a_light_shader_is_a_traced_shadow_ray(void **state)
{
    (void)state;
    same_shadows("Attribute \"light\" \"shadows\" [\"on\"]\n"
                 "LightSource \"pointlight\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]",
                 "LightSource \"pointlight\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]",
                 "LightSource \"shadowpoint\" 1 \"intensity\" [9] \"lightcolor\" [1 0.5 0.25]",
                 "mymatte");
    /* the missing map is said once per light and render, to the log the
     * program gave (the library prints nothing itself) */
    free(render("LightSource \"shadowpoint\" 1", "mymatte"));
    assert_int_equal(warnings, 1);
    assert_string_equal(last_warning, "light 0 (shader 'shadowpoint'): shadow map 'nosuchmap' "
                        "does not exist; shadow() is answered by a traced shadow ray");
    free(render("LightSource \"pointlight\" 1", "shadowmatte"));
    assert_int_equal(warnings, 1);
    assert_string_equal(last_warning, "surface shader 'shadowmatte': shadow map 'mapless' does "
                        "not exist; shadow() is answered by a traced shadow ray");
}

static void test_shadow_under_solar_goes_to_infinity(void **state)
{
    (void)state;
    /* a short axis: the shadow ray must not stop at its length */
    same_shadows("Attribute \"light\" \"shadows\" [\"on\"]\n"
                 "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "LightSource \"shadowsun\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "mymatte");
}

static void test_shadow_in_an_illuminance_loop(void **state)
{
    (void)state;
    same_shadows("Attribute \"light\" \"shadows\" [\"on\"]\n"
                 "LightSource \"pointlight\" 1 \"intensity\" [9]",
                 "LightSource \"pointlight\" 1 \"intensity\" [9]",
                 "LightSource \"pointlight\" 1 \"intensity\" [9]", "shadowmatte");
    same_shadows("Attribute \"light\" \"shadows\" [\"on\"]\n"
                 "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0.1 0 -0.9]",
                 "shadowmatte");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_floor_shows_the_sphere_where_a_direct_ray_finds_it),
        cmocka_unit_test(test_facing_mirrors_stop_at_the_depth_limit),
        cmocka_unit_test(test_rays_in_loops_at_every_depth_hit_the_limit),
        cmocka_unit_test(test_shadow_in_a_light_shader_is_a_traced_shadow_ray),
        cmocka_unit_test(test_shadow_under_solar_goes_to_infinity),
        cmocka_unit_test(test_shadow_in_an_illuminance_loop),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
