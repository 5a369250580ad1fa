/*
 * test_worker_cli.c: `aafarm-worker --standalone` as a user runs it (a real
 * process): help, usage errors, a bad scene and a bad shader give exit 3
 * with file:line:col diagnostics, a shader over its budget gives exit 1
 * and leaves no output file, a good render leaves exactly OUT.exr (no
 * temporary file) with the scene's size and channels.
 *
 * argv[1]: the aafarm-worker binary.
 */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "image/buffer.h"

static const char *worker;
static char dir[256];

static void write_file(const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* the text of file `path` (its first cap - 1 bytes) into buf */
static void read_text(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = '\0';
    fclose(f);
}

/* runs the worker with args (a shell fragment), output in *out; returns the exit status */
static int run(const char *args, char *out, size_t outsz)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cd %s && '%s' %s 2>&1", dir, worker, args);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, outsz - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int count_files(const char *needle)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, needle)) n++;
    closedir(d);
    return n;
}

static const char *SCENE_FMT =
    "Format 24 16 1\nProjection \"perspective\" \"fov\" [40]\n"
    "Option \"searchpath\" \"shader\" [\".\"]\n"
    "WorldBegin\n"
    "Displacement \"%s\"\n"
    "Polygon \"P\" [-1 -1 5  1 -1 5  1 1 5  -1 1 5]\n"
    "WorldEnd\n";

static void scene_with(const char *name, const char *shader)
{
    char text[1024];
    snprintf(text, sizeof text, SCENE_FMT, shader);
    write_file(name, text);
}

static void test_help_and_usage(void **state)
{
    (void)state;
    char out[8192];
    assert_int_equal(run("--help", out, sizeof out), 0);
    assert_non_null(strstr(out, "--standalone"));
    /* -o may be left out when the scene names its output with Display */
    write_file("nodisplay.rib", "Format 8 8 1\nProjection \"perspective\"\nWorldBegin\n"
               "Sphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(run("--standalone nodisplay.rib", out, sizeof out), 2);
    assert_non_null(strstr(out, "needs -o OUT.exr"));
    assert_int_equal(run("--standalone nodisplay.rib --frames 1-", out, sizeof out), 2);
    assert_non_null(strstr(out, "--frames: '1-' (at character 1 of '1-') is not a frame "
                                "number 0..99999999 or a range like 5-7"));
    assert_int_equal(run("--standalone nodisplay.rib --frames 2 -o x.exr", out, sizeof out), 2);
    assert_non_null(strstr(out, "--frames: the scene has no frame 2 (its frames: 1; it has "
                                "no FrameBegin)"));
    assert_int_equal(count_files(".exr"), 0);
    assert_int_equal(run("--cache-bytes lots --standalone x.rib -o x.exr", out, sizeof out), 2);
    assert_non_null(strstr(out, "--cache-bytes"));
    /* an out-of-range number: both bounds named (issue 27) */
    assert_int_equal(run("--budget 2000000000 --standalone x.rib -o x.exr", out, sizeof out), 2);
    assert_non_null(strstr(out, "aafarm-worker: --budget wants a number 1000..1000000000, got "
                                "'2000000000'"));
}

static void test_bad_scene_and_bad_shader(void **state)
{
    (void)state;
    char out[8192];
    write_file("bad.rib", "Format 24 16 1\nProjection \"perspective\" \"fov\" [40]\nWorldBegin\nSphere 1 -1 1\nWorldEnd\n");
    assert_int_equal(run("--standalone bad.rib -o bad.exr", out, sizeof out), 3);
    assert_non_null(strstr(out, "bad.rib:4:"));
    write_file("broken.sl", "displacement broken()\n{\n    P += 0.1 * ;\n}\n");
    scene_with("uses_broken.rib", "broken");
    assert_int_equal(run("--standalone uses_broken.rib -o b.exr", out, sizeof out), 3);
    assert_non_null(strstr(out, "broken.sl:3:"));
    scene_with("missing.rib", "nosuchshader");
    assert_int_equal(run("--standalone missing.rib -o m.exr", out, sizeof out), 3);
    assert_non_null(strstr(out, "shader 'nosuchshader' not found"));
    assert_int_equal(count_files(".exr"), 0);
}

static void test_budget_exceeded_leaves_nothing(void **state)
{
    (void)state;
    char out[8192];
    write_file("spin.sl",
               "displacement spin()\n{\n    float i = 0;\n    while (i < 1e9) i += 1;\n"
               "    P += 0.01 * i * normalize(N);\n}\n");
    scene_with("spin.rib", "spin");
    assert_int_equal(run("--standalone spin.rib -o spin.exr --budget 5000 -q", out, sizeof out), 1);
    assert_non_null(strstr(out, "spin"));
    assert_non_null(strstr(out, "5000"));
    assert_int_equal(count_files("spin.exr"), 0);
}

static void test_good_render_leaves_exactly_the_output(void **state)
{
    (void)state;
    char out[8192];
    write_file("flat.sl", "displacement flat(float h = 0.1)\n{\n    P += h * normalize(N);\n"
                          "    N = calculatenormal(P);\n}\n");
    scene_with("flat.rib", "flat");
    assert_int_equal(run("--standalone flat.rib -o flat.exr --tile 7 --threads 2 "
                         "--preview flat.png --stats-json flat.json -q", out, sizeof out), 0);
    assert_int_equal(count_files(".tmp"), 0);
    assert_int_equal(count_files("flat.png"), 1);
    assert_int_equal(count_files("flat.json"), 1);
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/flat.exr", dir);
    image_buffer *b = image_buffer_read_exr(path, err, sizeof err);
    assert_non_null(b);
    assert_int_equal(b->width, 24);
    assert_int_equal(b->height, 16);
    float *z = image_buffer_channel(b, "Z");
    float *a = image_buffer_channel(b, "A");
    assert_non_null(z);
    assert_non_null(a);
    /* the centre pixel sees the displaced plane at depth 5.1 */
    size_t c = (size_t)8 * 24 + 12;
    assert_true(z[c] > 5.05f && z[c] < 5.15f);
    assert_true(a[c] > 0.99f);
    image_buffer_destroy(&b);
}

/* --stats and --stats-json say what the world holds (trace_world_count):
 * a displaced sphere recorded once and placed three times, the second
 * turned (its prototype moved: an object-space shader) and the third
 * scaled (a surface of its own), is one object and one group of two
 * instances, one moved and one own. */
static void test_stats_count_the_instances(void **state)
{
    (void)state;
    char out[16384];
    write_file("lumps.sl", "displacement lumps(float Km = 0.05)\n{\n"
                           "    point Po = transform(\"object\", P);\n"
                           "    P += Km * sin(9 * xcomp(Po)) * normalize(N);\n"
                           "    N = calculatenormal(P);\n}\n");
    write_file("inst.rib", "Format 24 16 1\nProjection \"perspective\" \"fov\" [40]\n"
               "Option \"searchpath\" \"shader\" [\".\"]\nTranslate 0 0 6\nWorldBegin\n"
               "Displacement \"lumps\"\nObjectBegin 1\nSphere 0.5 -0.5 0.5 360\nObjectEnd\n"
               "AttributeBegin\nTranslate -1.2 0 0\nObjectInstance 1\nAttributeEnd\n"
               "AttributeBegin\nRotate 40 0 1 0\nObjectInstance 1\nAttributeEnd\n"
               "AttributeBegin\nTranslate 1.2 0 0\nScale 1 1.5 1\nObjectInstance 1\nAttributeEnd\n"
               "WorldEnd\n");
    assert_int_equal(run("--standalone inst.rib -o inst.exr --stats --stats-json inst.json -q",
                         out, sizeof out), 0);
    static const char *const lines[] = {
        "world_objects      1\n", "world_meshes       0\n", "instance_groups    1\n",
        "instances          2\n", "instances_moved    1\n", "instances_own      1\n"};
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        if (!strstr(out, lines[i])) printf("missing '%s' in:\n%s\n", lines[i], out);
        assert_non_null(strstr(out, lines[i]));
    }
    char path[512];
    snprintf(path, sizeof path, "%s/inst.json", dir);
    char json[16384];
    read_text(path, json, sizeof json);
    assert_non_null(strstr(json, "\"instances\": 2"));
    assert_non_null(strstr(json, "\"instances_moved\": 1"));
    assert_non_null(strstr(json, "\"instances_own\": 1"));
}

/* An independent oracle of the tile renderer (issue 27, item 7): a plane
 * far wider than the view covers every pixel, so every pixel's alpha is 1
 * whatever the tile grid; partial tiles (37x23 in tiles of 8) and two
 * threads. A tile renderer that left a row or a column of a tile unwritten
 * (the farm's workers and the standalone share it: comparing the two
 * cannot see it) leaves alpha 0 there. */
static void test_covering_plane_gives_alpha_one_everywhere(void **state)
{
    (void)state;
    char out[8192];
    write_file("cover.rib", "Format 37 23 1\nProjection \"perspective\" \"fov\" [40]\n"
               "WorldBegin\nPolygon \"P\" [-50 -50 5  50 -50 5  50 50 5  -50 50 5]\n"
               "WorldEnd\n");
    assert_int_equal(run("--standalone cover.rib -o cover.exr --tile 8 --threads 2 -q", out,
                         sizeof out), 0);
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/cover.exr", dir);
    image_buffer *b = image_buffer_read_exr(path, err, sizeof err);
    assert_non_null(b);
    assert_int_equal(b->width, 37);
    assert_int_equal(b->height, 23);
    const float *a = image_buffer_channel(b, "A");
    assert_non_null(a);
    int off = 0;
    for (int y = 0; y < 23; y++)
        for (int x = 0; x < 37; x++)
            if (!(a[y * 37 + x] == 1.0f) && off++ < 5)
                printf("pixel (%d,%d): alpha %g\n", x, y, (double)a[y * 37 + x]);
    assert_int_equal(off, 0);
    image_buffer_destroy(&b);
}

/* The number after "key": in file `name` of dir; -1 when absent. */
static long json_number(const char *name, const char *key)
{
    char path[512], json[16384], needle[96];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    read_text(path, json, sizeof json);
    snprintf(needle, sizeof needle, "\"%s\": ", key);
    const char *at = strstr(json, needle);
    return at ? strtol(at + strlen(needle), NULL, 10) : -1;
}

/* The frame's tail (worker/standalone.c): an image of one tile leaves
 * every thread but the one that took it without a tile, so they trace
 * blocks of its samples. The image must equal the one thread's bit for
 * bit (every channel, tolerance 0), and the helpers must have traced some
 * blocks (tail_blocks, from --stats-json): 4 threads on one tile of a
 * displaced sphere at 4 samples a pixel. */
static void test_threads_without_tiles_help_the_last_tile(void **state)
{
    (void)state;
    char out[8192];
    write_file("bumps.sl", "displacement bumps(float Km = 0.08)\n{\n"
                           "    P += Km * sin(12 * xcomp(P)) * sin(10 * ycomp(P)) * normalize(N);\n"
                           "    N = calculatenormal(P);\n}\n");
    write_file("one.rib", "Format 40 40 1\nPixelSamples 2 2\nProjection \"perspective\" "
               "\"fov\" [40]\nOption \"searchpath\" \"shader\" [\".\"]\nTranslate 0 0 4\n"
               "WorldBegin\nLightSource \"distantlight\" 1\nSurface \"plastic\"\n"
               "Displacement \"bumps\"\nAttribute \"displacementbound\" \"sphere\" [0.1]\n"
               "Sphere 1 -1 1 360\nWorldEnd\n");
    assert_int_equal(run("--standalone one.rib -o one1.exr --tile 64 --threads 1 "
                         "--stats-json one1.json -q", out, sizeof out), 0);
    assert_int_equal(run("--standalone one.rib -o one4.exr --tile 64 --threads 4 "
                         "--stats-json one4.json -q", out, sizeof out), 0);
    assert_int_equal(json_number("one1.json", "tiles"), 1);
    assert_int_equal(json_number("one1.json", "tail_blocks"), 0);
    long helped = json_number("one4.json", "tail_blocks");
    printf("4 threads on one tile: %ld blocks of 8x8 pixels traced by the 3 helpers\n", helped);
    assert_true(helped > 0);
    char p1[512], p4[512], err[256];
    snprintf(p1, sizeof p1, "%s/one1.exr", dir);
    snprintf(p4, sizeof p4, "%s/one4.exr", dir);
    image_buffer *a = image_buffer_read_exr(p1, err, sizeof err);
    image_buffer *b = image_buffer_read_exr(p4, err, sizeof err);
    assert_non_null(a);
    assert_non_null(b);
    /* the sphere is there: not a comparison of two empty frames */
    assert_true(image_buffer_channel(a, "A")[20 * 40 + 20] > 0.99f);
    image_diff d;
    assert_true(image_buffer_compare(a, b, 0.0, &d, err, sizeof err));
    if (d.count)
        printf("%zu samples differ, the largest by %g in %s at (%d,%d)\n", d.count, d.max_abs,
               d.channel, d.x, d.y);
    assert_int_equal(d.count, 0);
    image_buffer_destroy(&a);
    image_buffer_destroy(&b);
}

/* Starts the worker in dir with argv (stderr into err_path, or dropped),
 * sends SIGTERM after pause_ms, and waits up to 10 s for it; a worker
 * that ignores the signal is killed (SIGKILL) and the test fails. Returns
 * its exit status; *waited_ms: about how long it took to end. */
static int sigterm_after(const char *const *args, const char *err_path, long pause_ms,
                         int *waited_ms)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (chdir(dir) != 0) _exit(127);
        if (!freopen(err_path ? err_path : "/dev/null", "w", stderr)) _exit(127);
        execv(worker, (char *const *)args);
        _exit(127);
    }
    struct timespec pause = {pause_ms / 1000, (pause_ms % 1000) * 1000000L};
    nanosleep(&pause, NULL);
    kill(pid, SIGTERM);
    int status = 0;
    pid_t r;
    *waited_ms = 0;
    while ((r = waitpid(pid, &status, WNOHANG)) == 0 && *waited_ms < 10000) {
        struct timespec tick = {0, 10 * 1000000L};
        nanosleep(&tick, NULL);
        *waited_ms += 10;
    }
    if (r == 0) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        fail_msg("aafarm-worker ignored SIGTERM for 10 s");
    }
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

/* SIGTERM during ONE long shader evaluation (a loop within a --budget of
 * 1e9 instructions, run while the world's root boxes are made, before any
 * tile) ends the worker with 130 at once, not after the budget runs out
 * (a minute; issue 27 item 3): the VM looks at the cancel flag every
 * SL_VM_CANCEL_EVERY instructions. */
static void test_sigterm_stops_one_long_evaluation(void **state)
{
    (void)state;
    /* each turn costs an affine noise (microseconds): the budget would
     * last many minutes */
    write_file("spin.sl", "displacement spin()\n{\n    float i = 0, sum = 0;\n"
               "    while (i < 1e9) {\n        sum += noise(P * (i + 1));\n        i += 1;\n"
               "    }\n    P += 0.01 * sum / 1e9 * normalize(N);\n}\n");
    write_file("spin.rib",
               "Format 32 24 1\nProjection \"perspective\" \"fov\" [40]\n"
               "Option \"searchpath\" \"shader\" [\".\"]\nTranslate 0 0 5\nWorldBegin\n"
               "Displacement \"spin\"\nSphere 1 -1 1 360\nWorldEnd\n");
    char log[600];
    snprintf(log, sizeof log, "%s/spin.log", dir);
    const char *args[] = {worker, "--standalone", "spin.rib", "-o", "spin.exr", "-t", "1", "-q",
                          "--budget", "1000000000", NULL};
    int waited_ms = 0;
    int code = sigterm_after(args, log, 500, &waited_ms);
    printf("SIGTERM in one evaluation: exited after ~%d ms\n", waited_ms);
    assert_int_equal(code, 130);
    assert_int_equal(count_files("spin.exr"), 0);
    char text[4096];
    read_text(log, text, sizeof text);
    assert_non_null(strstr(text, "interrupted"));
    assert_null(strstr(text, "budget"));
}

/* A surface shader's printf() lines reach the worker's stderr as written
 * (the sl library prints nothing itself: the worker installs the VMs'
 * print callback, trace_thread_set_print). */
static void test_shader_printf_reaches_stderr(void **state)
{
    (void)state;
    char out[8192];
    write_file("say.sl", "surface say()\n{\n    printf(\"say %d\\n\", 7);\n    Ci = Cs;\n}\n");
    write_file("say.rib", "Format 4 4 1\nProjection \"perspective\" \"fov\" [40]\n"
                          "Option \"searchpath\" \"shader\" [\".\"]\nWorldBegin\nSurface \"say\"\n"
                          "Polygon \"P\" [-1 -1 5  1 -1 5  1 1 5  -1 1 5]\nWorldEnd\n");
    assert_int_equal(run("--standalone say.rib -o say.exr --threads 1 -q", out, sizeof out), 0);
    assert_non_null(strstr(out, "say 7\n"));
}

/* A long render (400 octaves of noise per shader run) stops on SIGTERM
 * with exit 130 and leaves nothing, although each tile takes seconds. A
 * worker that ignored SIGTERM is killed by the watchdog after 10 s and
 * the test fails (issue 9: stop within 1 s). */
static void test_sigterm_stops_a_runaway_render(void **state)
{
    (void)state;
    write_file("slow.sl", "displacement slow()\n{\n    float i = 0, sum = 0;\n"
               "    while (i < 400) {\n        sum += noise(P * (i + 1));\n        i += 1;\n"
               "    }\n    P += 0.01 * sum / 400 * normalize(N);\n}\n");
    write_file("nanp.rib",
               "Format 320 240 1\nProjection \"perspective\" \"fov\" [40]\n"
               "Option \"searchpath\" \"shader\" [\".\"]\nTranslate 0 0 5\nWorldBegin\n"
               "Displacement \"slow\"\nSphere 1 -1 1 360\nWorldEnd\n");
    const char *args[] = {worker, "--standalone", "nanp.rib", "-o", "nanp.exr", "-t", "2", "-q",
                          NULL};
    int waited_ms = 0;
    int code = sigterm_after(args, NULL, 300, &waited_ms);
    printf("SIGTERM: exited after ~%d ms\n", waited_ms);
    assert_int_equal(code, 130);
    assert_int_equal(count_files("nanp.exr"), 0);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_worker_cli AAFARM_WORKER\n");
        return 2;
    }
    worker = argv[1];
    snprintf(dir, sizeof dir, "/tmp/aafarm-cli-XXXXXX");
    if (!mkdtemp(dir)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_help_and_usage),
        cmocka_unit_test(test_bad_scene_and_bad_shader),
        cmocka_unit_test(test_budget_exceeded_leaves_nothing),
        cmocka_unit_test(test_good_render_leaves_exactly_the_output),
        cmocka_unit_test(test_covering_plane_gives_alpha_one_everywhere),
        cmocka_unit_test(test_threads_without_tiles_help_the_last_tile),
        cmocka_unit_test(test_stats_count_the_instances),
        cmocka_unit_test(test_shader_printf_reaches_stderr),
        cmocka_unit_test(test_sigterm_stops_a_runaway_render),
        cmocka_unit_test(test_sigterm_stops_one_long_evaluation),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return rc;
}
