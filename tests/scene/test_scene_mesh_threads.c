/*
 * tests/scene/test_scene_mesh_threads.c: a polygon mesh's faces prepared
 * over threads (rib_mesh.c, scene_parse_frame_threads; issue 23) make the
 * scene one thread makes, for any number of threads.
 *
 *   same scene   a bumpy grid of 60,000 faces (several rounds of shares:
 *                quads cut into triangles with corner normals and "st",
 *                flat quads kept whole, concave faces cut, faces without
 *                area skipped) parsed over 1, 2, 3 and 5 threads: the same
 *                pieces (every piece's surface and variables, byte for byte)
 *                and the same warning
 *   same errors  bad faces (more points than a face to be cut may have)
 *                spread over the shares: the same messages in the same
 *                order, also when the diagnostics fill up after two errors
 *                (the parse stops where one thread stops)
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

typedef struct text {
    char *s;
    size_t n, cap;
} text;

static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        int k = vsnprintf(t->s + t->n, t->cap - t->n, fmt, ap);
        va_end(ap);
        if (t->n + (size_t)k < t->cap) {
            t->n += (size_t)k;
            return;
        }
        t->cap = 2 * t->cap + (size_t)k + 1024;
        t->s = realloc(t->s, t->cap);
        if (!t->s) abort();
    }
}

enum { NU = 300, NV = 200 };             /* 60,000 faces */

/* The grid's RIB: face (i, j) a quad of points on a bumpy height field
 * (flat where i < 20: whole quads), every 997th face without area (its
 * four corners one point), every 1009th concave (a dart: its third corner
 * pulled in past the diagonal, in the flat part none); bad: faces
 * 5, 20000, 40000 and 59000 have 10,001 points (an error each). */
static char *grid_rib(bool bad)
{
    text t = {0};
    put(&t, CAMERA "WorldBegin\nPointsGeneralPolygons [");
    for (int f = 0; f < NU * NV; f++) put(&t, "1 ");
    put(&t, "]\n[");
    for (int f = 0; f < NU * NV; f++) {
        bool big = bad && (f == 5 || f == 20000 || f == 40000 || f == 59000);
        put(&t, "%d ", big ? 10001 : 4);
    }
    put(&t, "]\n[");
    int np = (NU + 1) * (NV + 1);
    for (int f = 0; f < NU * NV; f++) {
        int i = f / NV, j = f % NV;
        int a = i * (NV + 1) + j, b = a + NV + 1, c = b + 1, d = a + 1;
        bool big = bad && (f == 5 || f == 20000 || f == 40000 || f == 59000);
        if (big)
            for (int k = 0; k < 10001; k++) put(&t, "%d ", (a + k) % np);
        else if (f % 997 == 0)
            put(&t, "%d %d %d %d ", a, a, a, a);
        else if (f % 1009 == 0 && i >= 20)
            put(&t, "%d %d %d %d ", a, b, np + f / 1009, d);   /* the dart's own point */
        else
            put(&t, "%d %d %d %d ", a, b, c, d);
    }
    put(&t, "]\n\"P\" [");
    for (int i = 0; i <= NU; i++)
        for (int j = 0; j <= NV; j++) {
            double z = i < 20 ? 0 : 0.05 * sin(0.3 * i) * cos(0.2 * j);
            put(&t, "%.9g %.9g %.9g ", 0.01 * i, 0.01 * j, z);
        }
    /* the darts' inner corners: near their quad's first corner */
    for (int f = 0; f < NU * NV; f += 1009) {
        int i = f / NV, j = f % NV;
        double z = i < 20 ? 0 : 0.05 * sin(0.3 * i) * cos(0.2 * j);
        put(&t, "%.9g %.9g %.9g ", 0.01 * i + 0.002, 0.01 * j + 0.002, z);
    }
    put(&t, "]\n\"st\" [");
    int nst = np + (NU * NV + 1008) / 1009;
    for (int k = 0; k < nst; k++) put(&t, "%.9g %.9g ", (k % 7) * 0.1, (k % 11) * 0.05);
    put(&t, "]\nWorldEnd\n");
    return t.s;
}

static scene *parse_threads(const char *rib, int threads, int max_errors, sl_diag **d)
{
    *d = sl_diag_new();
    if (max_errors > 0) sl_diag_set_max_errors(*d, max_errors);
    return scene_parse_frame_threads("t.rib", rib, strlen(rib), NULL, SCENE_MAX_OBJECTS, 0,
                                     threads, NULL, *d);
}

static void expect_same_diags(const sl_diag *a, const sl_diag *b, int threads)
{
    if (sl_diag_count(a) != sl_diag_count(b))
        fail_msg("%d threads: %zu messages, one thread %zu", threads, sl_diag_count(b),
                 sl_diag_count(a));
    for (size_t i = 0; i < sl_diag_count(a); i++) {
        const sl_diagnostic *x = sl_diag_get(a, i), *y = sl_diag_get(b, i);
        if (x->level != y->level || x->line != y->line || x->col != y->col ||
            strcmp(x->message, y->message) != 0)
            fail_msg("%d threads: message %zu is \"%s\" (%d:%d), one thread's \"%s\" (%d:%d)",
                     threads, i, y->message, y->line, y->col, x->message, x->line, x->col);
    }
}

static void expect_same_pieces(const scene *a, const scene *b, int threads)
{
    assert_int_equal(a->nobjects, b->nobjects);
    assert_int_equal(a->npieces, b->npieces);
    geom_surface *sa = malloc(sizeof *sa), *sb = malloc(sizeof *sb);
    scene_primvar va[SCENE_MAX_PRIMVARS], vb[SCENE_MAX_PRIMVARS];
    for (int i = 0; i < a->nobjects; i++) {
        int n = scene_object_npieces(&a->objects[i]);
        assert_int_equal(n, scene_object_npieces(&b->objects[i]));
        for (int k = 0; k < n; k++) {
            int na = 0, nb = 0;
            memset(va, 0, sizeof va);
            memset(vb, 0, sizeof vb);
            assert_true(scene_object_piece(&a->objects[i], k, sa, va, &na));
            assert_true(scene_object_piece(&b->objects[i], k, sb, vb, &nb));
            if (memcmp(sa, sb, sizeof *sa) != 0 || na != nb ||
                memcmp(va, vb, sizeof va[0] * (size_t)na) != 0)
                fail_msg("%d threads: piece %d of object %d differs from one thread's", threads,
                         k, i);
        }
    }
    free(sa);
    free(sb);
}

static void test_same_scene(void **state)
{
    (void)state;
    char *rib = grid_rib(false);
    sl_diag *d1;
    scene *one = parse_threads(rib, 1, 0, &d1);
    if (!one) sl_diag_print(d1, stderr);
    assert_non_null(one);
    /* the grid is what the test says: skipped faces (a warning), cut ones */
    assert_int_equal(sl_diag_warning_count(d1), 1);
    assert_non_null(strstr(sl_diag_get(d1, 0)->message, "faces without area skipped"));
    assert_true(one->npieces > NU * NV);
    const int counts[] = {2, 3, 5};
    for (int t = 0; t < 3; t++) {
        sl_diag *d;
        scene *s = parse_threads(rib, counts[t], 0, &d);
        assert_non_null(s);
        expect_same_diags(d1, d, counts[t]);
        expect_same_pieces(one, s, counts[t]);
        scene_destroy(&s);
        sl_diag_destroy(&d);
    }
    scene_destroy(&one);
    sl_diag_destroy(&d1);
    free(rib);
}

static void test_same_errors(void **state)
{
    (void)state;
    char *rib = grid_rib(true);
    const int max_errors[] = {0, 2};
    for (int e = 0; e < 2; e++) {
        sl_diag *d1;
        scene *one = parse_threads(rib, 1, max_errors[e], &d1);
        assert_null(one);
        assert_int_equal(sl_diag_error_count(d1), max_errors[e] ? 2 : 4);
        const sl_diagnostic *first = nth_diag(d1, SL_DIAG_ERROR, 0);
        assert_non_null(first);
        assert_non_null(strstr(first->message, "face 5 has 10001 points"));
        const int counts[] = {2, 3, 4};
        for (int t = 0; t < 3; t++) {
            sl_diag *d;
            scene *s = parse_threads(rib, counts[t], max_errors[e], &d);
            assert_null(s);
            expect_same_diags(d1, d, counts[t]);
            sl_diag_destroy(&d);
        }
        sl_diag_destroy(&d1);
    }
    free(rib);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_scene),
        cmocka_unit_test(test_same_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
