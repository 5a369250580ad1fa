/*
 * test_geom_subdiv_rings.c: a refined face's 1-ring made again from the
 * control mesh (subdiv_mesh.c: the control faces around its control face,
 * refined) is the same, bit for bit, as the 1-ring cut out of the whole
 * mesh refined at once (what geom_subdiv kept until session 13), so images
 * do not change with the storage:
 *
 * - every drawn face of cages with triangles among quads, a hole, a
 *   semi-sharp crease, a corner tag, with and without
 *   "interpolateboundary", and of fans of valence 5 and 60 (a ring too big
 *   for a thread's cached buffer, made on the heap): the same points,
 *   sharpness, faces and corners (memcmp);
 * - a regular face's surface carries the Bezier net of that 1-ring, and
 *   an irregular face's carries none; its bounds are that 1-ring's hull.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "geom/subdiv_local.h"

/* The 1-ring of refined face f cut out of the whole refined mesh W (as
 * geom_subdiv once did: the face, then the faces holding each of its
 * corner points by ascending index). */
static void whole_ring(const sd_mesh *W, const int *vf_off, const int *vf, int f, sd_local *L)
{
    int list[1024], n = 0;
    list[n++] = f;
    for (int k = 0; k < 4; k++) {
        int p = W->fv[W->fo[f] + k];
        for (int i = vf_off[p]; i < vf_off[p + 1]; i++) {
            int g = vf[i] / 4, j = 0;
            while (j < n && list[j] != g) j++;
            if (j == n) list[n++] = g;
        }
    }
    sd_local_take(L, W, list, n);
}

static void check_rings(geom_subdiv *sd)
{
    const sd_mesh *m0 = &sd->m0;
    int nv = m0->nv, nf = m0->nf, nc = m0->fo[nf];
    /* the control mesh with its tags (zeros where none are kept) */
    sd_mesh m = *m0;
    m.vs = calloc((size_t)nv, sizeof *m.vs);
    m.es = calloc((size_t)nc, sizeof *m.es);
    assert_non_null(m.vs);
    assert_non_null(m.es);
    if (m0->vs) memcpy(m.vs, m0->vs, (size_t)nv * sizeof *m.vs);
    if (m0->es) memcpy(m.es, m0->es, (size_t)nc * sizeof *m.es);
    int nv1 = nv + nf + nc;
    sd_mesh W = { 0, 0, malloc((size_t)nv1 * sizeof(vec3)), malloc((size_t)nv1 * sizeof(double)),
                  malloc((size_t)(nc + 1) * sizeof(int)), malloc((size_t)4 * nc * sizeof(int)),
                  malloc((size_t)4 * nc * sizeof(double)) };
    sd_refine(&m, &W);
    int *vf_off = calloc((size_t)W.nv + 2, sizeof(int)), *vf = malloc((size_t)4 * nc * sizeof(int));
    int *fill = calloc((size_t)W.nv + 1, sizeof(int));
    for (int c = 0; c < 4 * nc; c++) vf_off[W.fv[c] + 1]++;
    for (int i = 0; i < W.nv; i++) vf_off[i + 1] += vf_off[i];
    for (int c = 0; c < 4 * nc; c++) vf[vf_off[W.fv[c]] + fill[W.fv[c]]++] = c;
    sd_local a, b;
    sd_local_init(&a, sd->maxval);
    sd_local_init(&b, sd->maxval);
    int drawn = 0, regular = 0;
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        drawn++;
        whole_ring(&W, vf_off, vf, f, &a);
        sd_local_from_shared(sd, f, &b);
        assert_int_equal(a.m.nv, b.m.nv);
        assert_int_equal(a.m.nf, b.m.nf);
        int lc = a.fo[a.m.nf];
        assert_memory_equal(a.fo, b.fo, (size_t)(a.m.nf + 1) * sizeof(int));
        assert_memory_equal(a.fv, b.fv, (size_t)lc * sizeof(int));
        assert_memory_equal(a.es, b.es, (size_t)lc * sizeof(double));
        assert_memory_equal(a.vs, b.vs, (size_t)a.m.nv * sizeof(double));
        assert_memory_equal(a.P, b.P, (size_t)a.m.nv * sizeof(vec3));
        /* the surface: the net of that ring where regular, its hull */
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        vec3 net[16];
        bool reg = sd_regular_net(&a.m, net);
        regular += reg;
        assert_int_equal(s.nverts, reg ? 16 : 0);
        if (reg) assert_memory_equal(s.verts, net, sizeof net);
        vec3 lo, hi, blo, bhi;
        sd_local_hull(&a.m, &lo, &hi);
        geom_bounds(&s, &blo, &bhi);
        assert_memory_equal(&lo, &blo, sizeof lo);
        assert_memory_equal(&hi, &bhi, sizeof hi);
    }
    printf("%d drawn faces (%d regular): rings equal to the whole refinement's\n", drawn,
           regular);
    assert_true(drawn > 0);
    sd_local_clear(&a);
    sd_local_clear(&b);
    free(vf_off);
    free(vf);
    free(fill);
    free(W.P);
    free(W.vs);
    free(W.fo);
    free(W.fv);
    free(W.es);
    free(m.vs);
    free(m.es);
}

/* A bumpy 6 x 6 grid of points (26 faces) whose middle quad is two
 * triangles, with a hole, a semi-sharp crease along a row and a corner. */
static geom_subdiv *grid(bool interpolate, double crease)
{
    enum { N = 6 };
    static double P[3 * N * N];
    static int nv[26], v[4 * 26];
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double *p = P + 3 * (j * N + i);
            p[0] = i + 0.1 * sin(3.0 * j), p[1] = j, p[2] = 0.3 * sin(1.7 * i + 0.9 * j);
        }
    int nf = 0, c = 0;
    for (int j = 0; j + 1 < N; j++)
        for (int i = 0; i + 1 < N; i++) {
            int a = j * N + i, b = a + 1, d = a + N, e = d + 1;
            if (i == 2 && j == 2) {
                nv[nf++] = 3, v[c++] = a, v[c++] = b, v[c++] = e;
                nv[nf++] = 3, v[c++] = a, v[c++] = e, v[c++] = d;
            } else {
                nv[nf++] = 4, v[c++] = a, v[c++] = b, v[c++] = e, v[c++] = d;
            }
        }
    static const int clen[] = { 5 }, cverts[] = { 3 * N, 3 * N + 1, 3 * N + 2, 3 * N + 3,
                                                  3 * N + 4 };
    double csharp[] = { crease };
    static const int corners[] = { 0 }, holes[] = { 7 };
    static const double corner_sharp[] = { 10 };
    geom_subdiv_desc desc = { nf, nv, v, N * N, P, 1, clen, cverts, csharp, 1, corners,
                              corner_sharp, 1, holes, interpolate };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&desc, why, sizeof why);
    if (!sd) fprintf(stderr, "%s\n", why);
    assert_non_null(sd);
    return sd;
}

/* a closed fan: n quads around point 0, their outer points joined by a
 * ring of quads to a cap point of valence n too */
static geom_subdiv *fan(int n)
{
    double *P = malloc(sizeof(double) * 3 * (3 * n + 2));
    int *nv = malloc(sizeof(int) * (size_t)3 * n), *v = malloc(sizeof(int) * (size_t)12 * n);
    assert_true(P && nv && v);
    /* points: 0 the centre, 1 + 2i the spokes, 2 + 2i between, then the
     * outer ring 2n + 1 + i, the cap 3n + 1 */
    P[0] = 0.1, P[1] = -0.05, P[2] = 0.3;
    for (int i = 0; i < n; i++) {
        double a = 2 * M_PI * i / n, b = 2 * M_PI * (i + 0.5) / n;
        double *E = P + 3 * (1 + 2 * i), *F = P + 3 * (2 + 2 * i), *O = P + 3 * (2 * n + 1 + i);
        E[0] = cos(a), E[1] = sin(a), E[2] = 0.2 * sin(3 * a);
        F[0] = 1.5 * cos(b), F[1] = 1.5 * sin(b), F[2] = -0.3 + 0.01 * i;
        O[0] = 1.2 * cos(a), O[1] = 1.2 * sin(a), O[2] = -1.5;
    }
    double *cap = P + 3 * (3 * n + 1);
    cap[0] = 0, cap[1] = 0, cap[2] = -2;
    int nf = 0, c = 0;
    for (int i = 0; i < n; i++) {
        int e0 = 1 + 2 * i, f0 = 2 + 2 * i, e1 = 1 + 2 * ((i + 1) % n);
        nv[nf++] = 4, v[c++] = 0, v[c++] = e0, v[c++] = f0, v[c++] = e1;
    }
    for (int i = 0; i < n; i++) {      /* the rim: spoke, between, next spoke, down */
        int e0 = 1 + 2 * i, f0 = 2 + 2 * i, e1 = 1 + 2 * ((i + 1) % n);
        int o0 = 2 * n + 1 + i, o1 = 2 * n + 1 + (i + 1) % n;
        nv[nf++] = 5, v[c++] = e0, v[c++] = o0, v[c++] = o1, v[c++] = e1, v[c++] = f0;
    }
    for (int i = 0; i < n; i++) {
        int o0 = 2 * n + 1 + i, o1 = 2 * n + 1 + (i + 1) % n;
        nv[nf++] = 3, v[c++] = o1, v[c++] = o0, v[c++] = 3 * n + 1;
    }
    geom_subdiv_desc desc = { nf, nv, v, 3 * n + 2, P, 0, NULL, NULL, NULL, 0, NULL, NULL,
                              0, NULL, false };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&desc, why, sizeof why);
    if (!sd) fprintf(stderr, "%s\n", why);
    assert_non_null(sd);
    free(P);
    free(nv);
    free(v);
    return sd;
}

static void test_grid_rings(void **state)
{
    (void)state;
    const double sharp[] = { 2.5, 0.5, 10 };
    for (int k = 0; k < 3; k++)
        for (int ib = 0; ib < 2; ib++) {
            geom_subdiv *sd = grid(ib, sharp[k]);
            check_rings(sd);
            geom_subdiv_destroy(&sd);
        }
}

static void test_fan_rings(void **state)
{
    (void)state;
    const int n[] = { 5, 60 };
    for (int k = 0; k < 2; k++) {
        geom_subdiv *sd = fan(n[k]);
        check_rings(sd);
        geom_subdiv_destroy(&sd);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_rings),
        cmocka_unit_test(test_fan_rings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
