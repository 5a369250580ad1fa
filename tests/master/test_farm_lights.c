/*
 * test_farm_lights.c: the shading language's lights and rays reach the
 * workers (issue 15): a scene lit by a user-written light shader
 * (illuminate, shadow() answered by a traced shadow ray) over a floor whose
 * surface shader loops over the lights with illuminance and reflects the
 * scene with trace(), and a displaced sphere; rendered by a master and one
 * worker over tcp://127.0.0.1, it equals `aafarm-worker --standalone`
 * pixel for pixel, and the worker says that shadow() found no shadow map.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "farm_testutil.h"

static char *dir;

static const char spot_sl[] =
    "/* a point light whose shadows come from shadow() */\n"
    "light tshadowpoint(float intensity = 1; color lightcolor = 1;\n"
    "                   point from = point \"shader\" (0, 0, 0);\n"
    "                   string shadowname = \"spot.shd\")\n"
    "{\n"
    "    illuminate(from) {\n"
    "        Cl = intensity * lightcolor / (L . L);\n"
    "        Cl *= 1 - shadow(shadowname, Ps);\n"
    "    }\n"
    "}\n";

static const char glossy_sl[] =
    "/* diffuse through an illuminance loop, plus a traced reflection */\n"
    "surface tglossy(float Kd = 0.7; float Kr = 0.3)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    color C = 0;\n"
    "    illuminance(P, Nf, PI / 2)\n"
    "        C += Cl * normalize(L) . Nf;\n"
    "    Ci = Cs * Kd * C + Kr * trace(P, reflect(normalize(I), Nf));\n"
    "    Oi = 1;\n"
    "}\n";

static const char matte_sl[] =
    "surface tmatte(float Kd = 1)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    Ci = Cs * Kd * diffuse(Nf);\n"
    "    Oi = 1;\n"
    "}\n";

static const char bumps_sl[] =
    "displacement tbumps(float Km = 0.04; float freq = 6)\n"
    "{\n"
    "    P += Km * sin(freq * 2 * PI * s) * sin(freq * PI * t) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char scene_rib[] =
    "Option \"searchpath\" \"shader\" [\"shaders:&\"]\n"
    "Format 48 36 1\n"
    "PixelSamples 1 1\n"
    "Projection \"perspective\" \"fov\" [40]\n"
    "Translate 0 -0.2 3\n"
    "Rotate -30 1 0 0\n"
    "WorldBegin\n"
    "  LightSource \"tshadowpoint\" 1 \"intensity\" [5] \"from\" [1 2 -1]\n"
    "  AttributeBegin\n"
    "    Color [0.6 0.7 0.8]\n"
    "    Surface \"tglossy\"\n"
    "    Polygon \"P\" [-2 0 -2  -2 0 2  2 0 2  2 0 -2]\n"
    "  AttributeEnd\n"
    "  AttributeBegin\n"
    "    Color [0.9 0.5 0.3]\n"
    "    Translate 0 0.5 0\n"
    "    Surface \"tmatte\"\n"
    "    Displacement \"tbumps\"\n"
    "    Sphere 0.4 -0.4 0.4 360\n"
    "  AttributeEnd\n"
    "WorldEnd\n";

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    assert_true(fputs(text, f) >= 0);
    assert_int_equal(fclose(f), 0);
}

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_NONE, 0) != 0) return -1;
    char shaders[4096];
    snprintf(shaders, sizeof shaders, "%s/shaders", dir);
    mkdir(shaders, 0755);
    write_file(ft_path(shaders, "tshadowpoint.sl"), spot_sl);
    write_file(ft_path(shaders, "tglossy.sl"), glossy_sl);
    write_file(ft_path(shaders, "tmatte.sl"), matte_sl);
    write_file(ft_path(shaders, "tbumps.sl"), bumps_sl);
    write_file(ft_path(dir, "scene.rib"), scene_rib);
    return ft_standalone(dir, 8) == 0 ? 0 : -1;
}

static void test_light_shader_and_rays_render_on_workers_as_standalone(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "master.log"), *wlog = ft_path(dir, "worker.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "farm.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "8", NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 30));
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "lit", "--threads", "2",
                           NULL};
    pid_t worker = ft_spawn(wlog, wargv);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "farm.exr")), 0);
    /* shadow() ran on the worker: its warning, once per light and render
     * (the worker's two threads share the renderer) */
    const char *warning = "light 0 (shader 'tshadowpoint'): shadow map 'spot.shd' does not "
                          "exist; shadow() is answered by a traced shadow ray";
    assert_int_equal(ft_count(wlog, warning), 1);
    assert_int_equal(ft_count(ft_path(dir, "standalone.log"), warning), 1);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_shader_and_rays_render_on_workers_as_standalone),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}
