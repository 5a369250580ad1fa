/*
 * test_trace_example_scenes.c: the example scenes of issue 14's new
 * surfaces render: scenes/subdiv.rib (a displaced Catmull-Clark box with
 * creases and extraordinary points) and scenes/knot.rib (a
 * displaced closed mesh of 2304 quads), scenes/nurbs.rib (a displaced
 * torus of one rational NuPatch, which must also render as the same scene
 * with RenderMan's quadric Torus does), read from the source tree with
 * their shaders, rendered small (Format replaced) in affine arithmetic:
 * no error, the object covers the image as its framing says, and 0
 * pinholes (pinholes.h) on these closed objects.
 *
 * The scenes folder is AAFARM_SCENES_DIR (tests/trace/CMakeLists.txt), or
 * the first argument.
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
#include "pinholes.h"
#include "trace/render.h"

static const char *scenes_dir = AAFARM_SCENES_DIR;

static char *read_text(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "rb");
    if (!fp) fail_msg("cannot read %s", path);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, fp), (size_t)n);
    s[n] = '\0';
    fclose(fp);
    return s;
}

enum { W = 64, H = 48 };

/* Renders scene `name` at W x H with shaders `names`; returns the opaque
 * pixel count, *holes the pinholes; the RGBA pixels into out (if not NULL).
 * edit, if not NULL, may change the RIB text first. */
static int render_scene_edited(const char *name, const char *const *names, int nnames,
                               int *holes, float *out, char *(*edit)(char *))
{
    char *rib = read_text(scenes_dir, name);
    if (edit) rib = edit(rib);
    char *fmt = strstr(rib, "Format 320 240 1");
    assert_non_null(fmt);
    char small[32];
    int n = snprintf(small, sizeof small, "Format %d %d 1", W, H);
    memset(fmt, ' ', strlen("Format 320 240 1"));
    memcpy(fmt, small, (size_t)n);
    char shader_dir[1024];
    snprintf(shader_dir, sizeof shader_dir, "%s/shaders", scenes_dir);
    fixture_shader sh[8];
    char *src[8];
    for (int i = 0; i < nnames; i++) {
        char file[64];
        snprintf(file, sizeof file, "%s.sl", names[i]);
        src[i] = read_text(shader_dir, file);
        sh[i] = (fixture_shader){names[i], src[i]};
    }
    fixture f;
    assert_true(fixture_open(&f, rib, sh, nnames, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    float *rgba = calloc((size_t)W * H * 4, sizeof *rgba), *z = calloc((size_t)W * H, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, W, H, rgba, z));
    *holes = count_pinholes(rgba, W, H);
    int opaque = count_opaque(rgba, W, H);
    printf("%s%s at %dx%d: %d opaque pixels, %d pinholes\n", name, edit ? " (edited)" : "", W,
           H, opaque, *holes);
    if (out) memcpy(out, rgba, sizeof *rgba * W * H * 4);
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
    for (int i = 0; i < nnames; i++) free(src[i]);
    free(rib);
    return opaque;
}

static int render_scene(const char *name, const char *const *names, int nnames, int *holes)
{
    return render_scene_edited(name, names, nnames, holes, NULL, NULL);
}

/* nurbs.rib with its NuPatch replaced by RenderMan's quadric torus of the
 * same radii */
static char *nupatch_to_torus(char *rib)
{
    char *a = strstr(rib, "\n    NuPatch "), *b = a ? strstr(a, "AttributeEnd") : NULL;
    assert_non_null(b);
    a++;                                  /* the request, not the comments */
    const char *torus = "Torus 0.75 0.3 0 360 360\n  ";
    size_t n = strlen(torus);
    memmove(a + n, b, strlen(b) + 1);
    memcpy(a, torus, n);
    return rib;
}

static void test_subdiv_scene(void **state)
{
    (void)state;
    static const char *const names[] = {"plastic", "lumpy"};
    int holes, opaque = render_scene("subdiv.rib", names, 2, &holes);
    assert_int_equal(holes, 0);
    assert_true(opaque > W * H / 6);      /* the box fills the middle of the frame */
    assert_true(opaque < W * H / 2);
}

/* The NuPatch torus renders as the quadric torus does (the same surface,
 * the same object-space displacement; the parameterisations differ, so
 * silhouette pixels may differ a little) */
static void test_nurbs_scene(void **state)
{
    (void)state;
    static const char *const names[] = {"plastic", "lumpy"};
    float *a = malloc(sizeof *a * W * H * 4), *b = malloc(sizeof *b * W * H * 4);
    assert_non_null(a);
    assert_non_null(b);
    int holes, opaque = render_scene_edited("nurbs.rib", names, 2, &holes, a, NULL);
    assert_int_equal(holes, 0);
    assert_true(opaque > W * H / 8);
    assert_true(opaque < W * H / 2);      /* a torus: its hole shows */
    int tholes, topaque = render_scene_edited("nurbs.rib", names, 2, &tholes, b, nupatch_to_torus);
    /* coverage may differ only at a silhouette (a pixel beside one of the
     * other image's coverage edges); colours are compared inside, where
     * every neighbour is covered in both */
    int differ = 0, coverage = 0, stray = 0, inside = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            bool ca = a[4 * i + 3] > 0.5f, cb = b[4 * i + 3] > 0.5f;
            bool edge = false, interior = ca && cb;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                    int j = yy * W + xx;
                    bool na = a[4 * j + 3] > 0.5f, nb = b[4 * j + 3] > 0.5f;
                    edge = edge || na != ca || nb != cb;
                    interior = interior && na && nb;
                }
            if (ca != cb) {
                coverage++;
                stray += !edge;
            }
            if (!interior) continue;
            inside++;
            float d = 0;
            for (int k = 0; k < 3; k++) d = fmaxf(d, fabsf(a[4 * i + k] - b[4 * i + k]));
            differ += d > 8.0f / 255;
        }
    printf("NuPatch torus against the quadric torus: %d of %d inner pixels differ by more "
           "than 8/255; %d differ in coverage, %d of them away from a silhouette "
           "(opaque: %d NuPatch, %d quadric)\n", differ, inside, coverage, stray, opaque,
           topaque);
    /* measured: 0 stray; the coverage differences are silhouette pixels:
     * the quadric's are exact (hit proofs, tests of the leaves whose
     * point does not settle, intersect.c), the NuPatch's leaves of a
     * pixel take near misses (no proofs on rational patches) */
    assert_int_equal(stray, 0);
    assert_true(inside > opaque / 2);
    assert_true(differ <= inside / 20);
    assert_true(coverage <= opaque / 10);
    free(a);
    free(b);
}

static void test_knot_scene(void **state)
{
    (void)state;
    static const char *const names[] = {"plastic", "dented"};
    int holes, opaque = render_scene("knot.rib", names, 2, &holes);
    assert_int_equal(holes, 0);
    assert_true(opaque > W * H / 8);
    assert_true(opaque < W * H / 2);      /* a tube: the knot's holes show */
}

int main(int argc, char **argv)
{
    if (argc > 1) scenes_dir = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_subdiv_scene),
        cmocka_unit_test(test_knot_scene),
        cmocka_unit_test(test_nurbs_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
