/*
 * test_job_check.c: the master's check of a job holds little (issue 23,
 * "the master parses what it needs without holding the whole model").
 *
 * - Bytes, counted by the allocator (glibc's mallinfo2, not the code's own
 *   accounting; not in a sanitizer build, whose allocator it does not see): what job_load's check holds (scene_check_frame with
 *   job_scene_checker, then job_scene_check) for a 30,000-face mesh placed
 *   by 2,000 ObjectInstance references stays under CHECK_BYTES in all; the
 *   renderer's parse of the same scene, which the master's check used to
 *   make (job_scene_new with render = false), holds over 2 MB (the mesh's
 *   arrays and pieces, a ~560-byte scene object per instance).
 * - The check still counts what a renderer would refuse: the pieces, the
 *   references (scene.nchecked_placements) and the objects are the full
 *   parse's.
 * - A reference the renderer cannot place (its transform nearly singular)
 *   is an error of the check, at the ObjectInstance's file:line:col.
 * - A checked scene's mesh has no pieces to make: asking for one is an
 *   assert (death test).
 */
#include <malloc.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "death.h"
#include "job/job.h"
#include "job/job_scene.h"

/* what the check may hold of the scene below (a mesh of 30,000 faces, 2,000
 * instances), everything included: the scene's options, shaders, one
 * object and the counted mesh, the compiled plastic shader and the world */
enum { CHECK_BYTES = 512 * 1024 };

enum { NU = 200, NV = 150, INSTANCES = 2000 };

static size_t heap_bytes(void)
{
    struct mallinfo2 mi = mallinfo2();
    return mi.uordblks + mi.hblkhd;
}

/* A grid of NU x NV quads recorded once and placed `instances` times;
 * `bad` puts a nearly singular Scale before the last placement. */
static char *grid_rib(int instances, bool bad)
{
    size_t cap = (size_t)NU * NV * 60 + (size_t)instances * 80 + 4096, n = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    n += (size_t)snprintf(t + n, cap - n, "Format 32 32 1\nProjection \"perspective\" "
                          "\"fov\" [40]\nTranslate 0 0 40\nWorldBegin\n"
                          "ObjectBegin \"grid\"\nPointsPolygons [");
    for (int i = 0; i < NU * NV; i++) n += (size_t)snprintf(t + n, cap - n, "4 ");
    n += (size_t)snprintf(t + n, cap - n, "]\n[");
    for (int j = 0; j < NV; j++)
        for (int i = 0; i < NU; i++) {
            int a = j * (NU + 1) + i;
            n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d ", a, a + 1, a + NU + 2,
                                  a + NU + 1);
        }
    n += (size_t)snprintf(t + n, cap - n, "]\n\"P\" [");
    for (int j = 0; j <= NV; j++)
        for (int i = 0; i <= NU; i++)
            n += (size_t)snprintf(t + n, cap - n, "%g %g 0 ", i * 0.01, j * 0.01);
    n += (size_t)snprintf(t + n, cap - n, "]\nObjectEnd\n");
    for (int k = 0; k < instances; k++)
        n += (size_t)snprintf(t + n, cap - n, "AttributeBegin\n%sTranslate %d %d 0\n"
                              "ObjectInstance \"grid\"\nAttributeEnd\n",
                              bad && k == instances - 1 ? "Scale 1e7 1e-7 1\n" : "",
                              k % 50 - 25, k / 50 - 20);
    snprintf(t + n, cap - n, "WorldEnd\n");
    return t;
}

static job *grid_job(const char *rib)
{
    job_options opt;
    job_options_default(&opt);
    return job_new("grid.rib", rib, strlen(rib), &opt);
}

/* The master's check of the grid as job_load makes it. */
static job_scene *check(const job *jb, sl_diag *d)
{
    sl_source_set *archives = scene_archive_set_new();
    scene *sc = scene_check_frame(jb->scene_file, jb->scene_text, jb->scene_len, archives,
                                  SCENE_MAX_OBJECTS, 0, job_scene_checker(), NULL, d);
    sl_source_set_destroy(&archives);
    if (!sc) return NULL;
    return job_scene_check(jb, sc, NULL, d);
}

static void test_check_bytes(void **state)
{
    (void)state;
    char *rib = grid_rib(INSTANCES, false);
    job *jb = grid_job(rib);
    free(rib);
    sl_diag *d = sl_diag_new();
    /* warm up: the standard shader compiled once (its caches are the
     * process's, not the scene's) */
    job_scene *js = check(jb, d);
    job_scene_destroy(&js);

    size_t before = heap_bytes();
    js = check(jb, d);
    size_t held = heap_bytes() - before;
    if (!js) sl_diag_print(d, stderr);
    assert_non_null(js);
    assert_true(js->scene->checked);

    size_t before_full = heap_bytes();
    job_scene *full = job_scene_new(jb, 0, false, NULL, d);
    size_t held_full = heap_bytes() - before_full;
    assert_non_null(full);
    printf("the master's check of %d faces and %d instances holds %zu bytes (budget %d); "
           "the renderer's parse and world, %zu\n", NU * NV, INSTANCES, held, CHECK_BYTES,
           held_full);
#ifdef __SANITIZE_ADDRESS__
    /* ASan's allocator does not feed mallinfo2: the budget is the plain build's */
    (void)held, (void)held_full;
#else
    assert_true(held <= CHECK_BYTES);
    assert_true(held_full > 4 * (size_t)CHECK_BYTES);   /* the measure sees the model */
#endif

    /* what a renderer would refuse is counted the same */
    const scene *c = js->scene, *f = full->scene;
    assert_int_equal(c->npieces, f->npieces);
    assert_int_equal(c->npieces, NU * NV);
    assert_int_equal(c->nobjects, 1);
    assert_int_equal(f->nobjects, INSTANCES);
    assert_int_equal(c->nchecked_placements, INSTANCES - 1);
    assert_int_equal(c->nmeshes, 1);
    assert_int_equal(c->nshader_names, f->nshader_names);
    job_scene_destroy(&full);
    job_scene_destroy(&js);
    job_destroy(&jb);
    sl_diag_destroy(&d);
}

static void test_check_reports_placement(void **state)
{
    (void)state;
    char dir[] = "/tmp/aafarm_check_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/grid.rib", dir);
    char *rib = grid_rib(20, true);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(rib, f);
    fclose(f);
    /* the line of the last ObjectInstance */
    int line = 1, want = 0;
    for (const char *c = rib; *c; c++) {
        if (strncmp(c, "ObjectInstance", 14) == 0 && (c == rib || c[-1] == '\n')) want = line;
        line += *c == '\n';
    }
    free(rib);
    job_options opt;
    job_options_default(&opt);
    sl_diag *d = sl_diag_new();
    job *jb = job_load(path, &opt, NULL, d);
    assert_null(jb);
    assert_true(sl_diag_error_count(d) >= 1);
    const sl_diagnostic *e = sl_diag_get(d, 0);
    assert_non_null(e->file);
    assert_string_equal(e->file, path);
    assert_int_equal(e->line, want);
    assert_int_equal(e->col, 1);
    if (!strstr(e->message, "ObjectInstance: mesh at ") ||
        !strstr(e->message, "its transformation to camera space is not finite or nearly "
                            "singular"))
        fail_msg("unexpected message: %s", e->message);
    sl_diag_destroy(&d);
    unlink(path);
    rmdir(dir);
}

static void piece_of_checked(void *arg)
{
    (void)arg;
    const char *rib = "Format 8 8 1\nProjection \"perspective\"\nWorldBegin\n"
                      "PointsPolygons [4] [0 1 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
                      "WorldEnd\n";
    sl_diag *d = sl_diag_new();
    scene *sc = scene_check_frame("q.rib", rib, strlen(rib), NULL, SCENE_MAX_OBJECTS, 0,
                                  job_scene_checker(), NULL, d);
    if (!sc) {
        sl_diag_print(d, stderr);
        return;
    }
    geom_surface s;
    scene_primvar vars[SCENE_MAX_PRIMVARS];
    int n;
    scene_object_piece(&sc->objects[0], 0, &s, vars, &n);
}

static void test_checked_mesh_has_no_pieces(void **state)
{
    (void)state;
    assert_death(piece_of_checked, NULL, "a checked scene's mesh has no pieces to make");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checked_mesh_has_no_pieces),
        cmocka_unit_test(test_check_bytes),
        cmocka_unit_test(test_check_reports_placement),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
