/*
 * scene_testing.h: helpers shared by the tests of common/scene: parse a
 * RIB text from memory into a scene with a fresh diagnostics object, find
 * diagnostics, read a file, compare transformed points.
 */
#ifndef TESTS_SCENE_TESTING_H
#define TESTS_SCENE_TESTING_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

/* One piece of a scene's objects: a mesh's face or triangle
 * (scene_mesh_piece_surface), or an object's own surface, with its
 * primitive variables and the object it belongs to. */
typedef struct test_piece {
    geom_surface surface;
    scene_primvar primvars[SCENE_MAX_PRIMVARS];
    int nprimvars;
    int object;
} test_piece;

/* Every piece of every object of s, in order: what each object of a scene
 * was before a mesh became one object (issue 23). *n of them; the caller
 * frees. */
static inline test_piece *scene_pieces(const scene *s, int *n)
{
    int total = 0;
    for (int i = 0; i < s->nobjects; i++) total += scene_object_npieces(&s->objects[i]);
    test_piece *pc = calloc((size_t)(total > 0 ? total : 1), sizeof *pc);
    int k = 0;
    for (int i = 0; i < s->nobjects; i++)
        for (int j = 0; j < scene_object_npieces(&s->objects[i]); j++, k++) {
            if (!scene_object_piece(&s->objects[i], j, &pc[k].surface, pc[k].primvars,
                                    &pc[k].nprimvars))
                abort();
            pc[k].object = i;
        }
    *n = total;
    return pc;
}

/* The smallest camera a scene needs. */
#define CAMERA "Format 64 32 1\nProjection \"perspective\" \"fov\" [45]\n"

/* Parses `text` as file "t.rib" into *s; the diagnostics stay in *d. */
static inline scene *parse_rib(const char *text, sl_diag **d)
{
    *d = sl_diag_new();
    return scene_parse("t.rib", text, strlen(text), *d);
}

/* The index-th diagnostic of this level, or NULL. */
static inline const sl_diagnostic *nth_diag(const sl_diag *d, sl_diag_level level, int index)
{
    for (size_t i = 0; i < sl_diag_count(d); i++) {
        const sl_diagnostic *x = sl_diag_get(d, i);
        if (x->level == level && index-- == 0)
            return x;
    }
    return NULL;
}

/* "file:line:col: message" of a diagnostic, in a static buffer. */
static inline const char *diag_line(const sl_diagnostic *x)
{
    static char buf[2048];
    if (!x)
        return "(none)";
    snprintf(buf, sizeof buf, "%s:%d:%d: %s", x->file ? x->file : "-", x->line, x->col,
             x->message);
    return buf;
}

/* The whole file in a malloc'd NUL-terminated buffer (NULL on failure). */
static inline char *read_whole_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) {
        buf[n] = '\0';
        *len = (size_t)n;
    }
    return buf;
}

static inline double vec_dist(vec3 a, vec3 b)
{
    return v3_length(v3_sub(a, b));
}

#ifdef cmocka_unit_test
/* A table of scenes that must fail, each with its first error exactly
 * ("file:line:col: message"); prints the scene and its diagnostics when one
 * does not. */
typedef struct error_case {
    const char *text;
    const char *first_error;
} error_case;

static inline void expect_first_errors(const error_case *cases, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        sl_diag *d;
        scene *s = parse_rib(cases[i].text, &d);
        const char *got = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
        if (s || strcmp(got, cases[i].first_error) != 0) {
            fprintf(stderr, "case %zu:\n%s\n", i, cases[i].text);
            sl_diag_print(d, stderr);
        }
        assert_null(s);
        assert_string_equal(got, cases[i].first_error);
        sl_diag_destroy(&d);
    }
}
#endif

#endif
