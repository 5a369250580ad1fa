/*
 * subdiv_cache.c: the local refinements of a Catmull-Clark face, built once
 * and shared (sd_node, subdiv_local.h), with the hull of an irregular
 * sub-face: of the points its limit depends on.
 *
 * The tree. Evaluating a box or a point of an irregular face descends from
 * the face through the quadrants holding it until a sub-face is regular
 * (subdiv_eval.c); each step is a Catmull-Clark step of the 1-ring
 * (subdiv_refine.c: edge keys sorted, scratch allocated). The renderer asks
 * for thousands of boxes of the same few faces, so the sub-faces met on the
 * way are kept: node = one sub-face at one level with its 1-ring (exact
 * size, heap) or, where it is regular, its Bezier net, and four child
 * pointers built on first use. Only sub-faces touching an irregular point
 * stay irregular, so the tree stays a few chains deep per irregular corner.
 * A node never changes once published; threads race only to publish a
 * child (compare-and-swap; the loser frees its copy), so the tree is shared
 * by all render threads without locks.
 *
 * The sector hull. An infinitely sharp edge follows the boundary rules
 * (DeRose, Kass & Truong 1998 §3): nothing on its far side enters a point
 * on this side. So around each corner of the sub-face only the faces
 * reached without crossing an infinitely sharp edge (its sector) feed the
 * limit, and the limit (non-negative masks) lies in the convex hull of
 * their points. Beside a crease that hull is much flatter than the whole
 * 1-ring's.
 *
 * The normal of an irregular sub-face (issue 10 on scenes/subdiv.rib). At
 * a crease point of valence 3 (a box's corner on a creased rim) the flat
 * top has one face: a boundary point of valence 2, extraordinary at every
 * level. Its unit normal was unknown, [-1,1]^3 (subdiv_eval.c), so the
 * displaced box of the sub-face at the corner kept a size of 2 Km |h| at
 * every level and rays there walked to the depth cap. When the points of
 * the sector lie exactly in a plane x_k = c (exactly equal coordinates, as
 * a modeled flat side has), the limit surface over the sub-face lies in
 * that plane and its unit normal is +-e_k wherever it is defined. The sign
 * is that of Ng_k on every regular sub-patch of the sub-face down to level
 * SD_SIGN_LEVEL (hodograph bounds, sd_net_normal_component), which must all
 * be decided and agree. Below that level (2^-16 of the face) the nets are
 * slivers narrower than the hodographs' rounding pads and the sign is not
 * computed: the rings there are images of those above under the local
 * subdivision matrix, whose leading eigenvalues near such a point (1/2
 * along the crease, 1/4 across) are positive, so they keep the orientation
 * (an argument, not a computation: docs/geometry.md). A sub-face below
 * SD_SIGN_LEVEL takes its ancestor's normal. Anything else (a curved
 * sector) keeps the unknown normal: a finite bound there needs the
 * eigen-analysis of the subdivision matrix.
 */
#include "geom/subdiv_ev.h"
#include "geom/subdiv_local.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct sd_node {
    int level;
    int maxval;                    /* the mesh's (sd_local_init) */
    bool regular;
    vec3 net[16];                  /* regular: the Bezier net */
    sd_mesh m;                     /* irregular: the 1-ring, face 0 first */
    vec3 lo, hi;                   /* irregular: the sector hull, padded */
    int axis;                      /* the sector lies in x_axis = const, or -1 */
    _Atomic int normal;            /* 0 not known yet, 1 none, else 2 + 2 axis + (sign > 0) */
    _Atomic int ev;                /* the EV cone: 0 not known yet, 1 none, 2 evbox,
                                    * 3 being stored */
    ia_interval evbox[3];          /* the unit normal box at a smooth EV (subdiv_ev.c) */
    _Atomic(sd_node *) kid[4];
};

/* ---- sectors ---- */

static int next_c(const sd_mesh *m, int f, int c)
{
    return c + 1 < m->fo[f + 1] ? c + 1 : m->fo[f];
}

static int prev_c(const sd_mesh *m, int f, int c)
{
    return c > m->fo[f] ? c - 1 : m->fo[f + 1] - 1;
}

/* The corner of face f at point v, or -1. */
static int corner_at(const sd_mesh *m, int f, int v)
{
    for (int c = m->fo[f]; c < m->fo[f + 1]; c++)
        if (m->fv[c] == v) return c;
    return -1;
}

/* Sharpness of face f's edge between v (corner cv) and w, or -1 if f has
 * no such edge. */
static double edge_to(const sd_mesh *m, int f, int cv, int w)
{
    int cn = next_c(m, f, cv), cp = prev_c(m, f, cv);
    if (m->fv[cn] == w) return m->es[cv];
    if (m->fv[cp] == w) return m->es[cp];
    return -1;
}

/* Marks in[] the faces of face 0's sector around point v. */
static void sector(const sd_mesh *m, int v, unsigned char *in)
{
    unsigned char *here = xcalloc((size_t)m->nf, 1);
    here[0] = 1;
    for (bool grew = true; grew;) {
        grew = false;
        for (int g = 0; g < m->nf; g++) {
            int cg = corner_at(m, g, v);
            if (here[g] || cg < 0) continue;
            int ends[2] = { m->fv[next_c(m, g, cg)], m->fv[prev_c(m, g, cg)] };
            for (int h = 0; h < m->nf && !here[g]; h++) {
                int ch = here[h] ? corner_at(m, h, v) : -1;
                if (ch < 0) continue;
                for (int k = 0; k < 2; k++) {
                    double sh = edge_to(m, h, ch, ends[k]);
                    if (sh < 0) continue;
                    double sg = edge_to(m, g, cg, ends[k]);
                    if (!isinf(sh) && !isinf(sg)) here[g] = 1;
                }
            }
            grew |= here[g];
        }
    }
    for (int f = 0; f < m->nf; f++) in[f] |= here[f];
    free(here);
}

/* The sector hull (padded by 1e-12 of its size, as subdiv_eval.c's hull)
 * and the axis whose coordinate all sector points share exactly (-1). */
static void sector_bounds(const sd_mesh *m, vec3 *lo, vec3 *hi, int *axis)
{
    unsigned char *in = xcalloc((size_t)m->nf, 1);
    for (int k = 0; k < 4; k++) sector(m, m->fv[m->fo[0] + k], in);
    bool first = true, same[3] = { true, true, true };
    double big = 0;
    for (int f = 0; f < m->nf; f++) {
        if (!in[f]) continue;
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++) {
            vec3 p = m->P[m->fv[c]];
            if (first) {
                *lo = *hi = p;
                first = false;
            }
            for (int i = 0; i < 3; i++) same[i] &= v3_comp(p, i) == v3_comp(*lo, i) &&
                                                   v3_comp(p, i) == v3_comp(*hi, i);
            lo->x = fmin(lo->x, p.x), lo->y = fmin(lo->y, p.y), lo->z = fmin(lo->z, p.z);
            hi->x = fmax(hi->x, p.x), hi->y = fmax(hi->y, p.y), hi->z = fmax(hi->z, p.z);
            big = fmax(big, fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
        }
    }
    double pad = 1e-12 * (big + v3_length(v3_sub(*hi, *lo)));
    *lo = v3_sub(*lo, v3(pad, pad, pad));
    *hi = v3_add(*hi, v3(pad, pad, pad));
    *axis = same[0] ? 0 : same[1] ? 1 : same[2] ? 2 : -1;
    free(in);
}

/* ---- nodes ---- */

static sd_node *node_new(const sd_local *L, int level)
{
    sd_node *n = xcalloc(1, sizeof *n);
    n->level = level;
    n->maxval = L->maxval;
    n->axis = -1;
    n->regular = sd_regular_net(&L->m, n->net);
    if (n->regular) return n;
    int nv = L->m.nv, nf = L->m.nf, nc = L->fo[nf];
    n->m = (sd_mesh){ nv, nf, xmalloc((size_t)nv * sizeof(vec3)), xmalloc((size_t)nv * sizeof(double)),
                      xmalloc((size_t)(nf + 1) * sizeof(int)), xmalloc((size_t)nc * sizeof(int)),
                      xmalloc((size_t)nc * sizeof(double)) };
    memcpy(n->m.P, L->P, (size_t)nv * sizeof(vec3));
    memcpy(n->m.vs, L->vs, (size_t)nv * sizeof(double));
    memcpy(n->m.fo, L->fo, (size_t)(nf + 1) * sizeof(int));
    memcpy(n->m.fv, L->fv, (size_t)nc * sizeof(int));
    memcpy(n->m.es, L->es, (size_t)nc * sizeof(double));
    sector_bounds(&n->m, &n->lo, &n->hi, &n->axis);
    return n;
}

static void node_free(sd_node *n)
{
    if (!n) return;
    for (int k = 0; k < 4; k++) node_free(atomic_load(&n->kid[k]));
    free(n->m.P);
    free(n->m.vs);
    free(n->m.fo);
    free(n->m.fv);
    free(n->m.es);
    free(n);
}

int sd_node_maxval(const sd_node *n) { return n->maxval; }

void sd_node_local(const sd_node *n, sd_local *L)
{
    assert(L->maxval == n->maxval);
    int nv = n->m.nv, nf = n->m.nf, nc = n->m.fo[nf];
    L->m = (sd_mesh){ nv, nf, L->P, L->vs, L->fo, L->fv, L->es };
    memcpy(L->P, n->m.P, (size_t)nv * sizeof(vec3));
    memcpy(L->vs, n->m.vs, (size_t)nv * sizeof(double));
    memcpy(L->fo, n->m.fo, (size_t)(nf + 1) * sizeof(int));
    memcpy(L->fv, n->m.fv, (size_t)nc * sizeof(int));
    memcpy(L->es, n->m.es, (size_t)nc * sizeof(double));
}

/* publishes n in *slot unless another thread did first */
static const sd_node *publish(_Atomic(sd_node *) *slot, sd_node *n)
{
    sd_node *expected = NULL;
    if (atomic_compare_exchange_strong(slot, &expected, n)) return n;
    node_free(n);
    return expected;
}

void sd_cache_init(geom_subdiv *sd)
{
    sd->roots = xcalloc((size_t)sd->nirr + 1, sizeof *sd->roots);
}

void sd_cache_clear(geom_subdiv *sd)
{
    if (!sd->roots) return;
    for (int i = 0; i < sd->nirr; i++) node_free(atomic_load(&sd->roots[i]));
    free(sd->roots);
    sd->roots = NULL;
}

const sd_node *sd_node_root(const geom_subdiv *sd, int f)
{
    _Atomic(sd_node *) *slot = &sd->roots[sd_irregular_rank(sd, f)];
    sd_node *n = atomic_load(slot);
    if (n) return n;
    sd_local L;
    sd_local_init(&L, sd->maxval);
    sd_local_from_shared(sd, f, &L);
    n = node_new(&L, 0);
    sd_local_clear(&L);
    return publish(slot, n);
}

const sd_node *sd_node_child(const sd_node *p, int q)
{
    sd_node *n = atomic_load(&((sd_node *)p)->kid[q]);
    if (n) return n;
    sd_local L;
    sd_big big;
    sd_local_init(&L, p->maxval);
    sd_big_init(&big, p->maxval);
    sd_node_local(p, &L);
    sd_local_child(&L, q, &big);
    n = node_new(&L, p->level + 1);
    sd_big_clear(&big);
    sd_local_clear(&L);
    return publish(&((sd_node *)p)->kid[q], n);
}

bool sd_node_regular(const sd_node *n, const vec3 **net)
{
    *net = n->net;
    return n->regular;
}

void sd_node_hull(const sd_node *n, vec3 *lo, vec3 *hi)
{
    *lo = n->lo;
    *hi = n->hi;
}

/* ---- the normal of an irregular sub-face ---- */


/* The sign of Ng's component `axis` over the whole regular sub-patch (the
 * hodographs' hull, subdiv_eval.c's net_boxes), 0 when it may vanish. */
static int net_normal_sign(const vec3 net[16], int axis)
{
    ia_interval Ng = sd_net_normal_component(net, axis);
    return Ng.lo > 0 ? 1 : Ng.hi < 0 ? -1 : 0;
}

/* 1: none; else 2 + 2 axis + (sign > 0) */
static int node_normal(const sd_node *n)
{
    int state = atomic_load(&((sd_node *)n)->normal);
    if (state) return state;
    state = 1;
    if (n->axis >= 0) {
        int sign = 0;
        bool ok = true;
        for (int q = 0; q < 4 && ok; q++) {
            const sd_node *k = sd_node_child(n, q);
            int s;
            if (k->regular) {
                s = net_normal_sign(k->net, n->axis);
            } else if (k->level >= SD_SIGN_LEVEL) {
                continue;       /* the rings below: file comment */
            } else {
                int ks = node_normal(k);
                s = ks >= 2 && (ks - 2) / 2 == n->axis ? ((ks - 2) % 2 ? 1 : -1) : 0;
            }
            if (s == 0 || (sign != 0 && s != sign)) ok = false;
            sign = s;
        }
        if (ok && sign != 0) state = 2 + 2 * n->axis + (sign > 0);
    }
    atomic_store(&((sd_node *)n)->normal, state);
    return state;
}

bool sd_node_unit_normal(const sd_node *n, vec3 *N)
{
    if (n->regular) return false;
    int state = node_normal(n);
    if (state < 2) return false;
    int axis = (state - 2) / 2;
    double s = (state - 2) % 2 ? 1.0 : -1.0;
    *N = v3(axis == 0 ? s : 0, axis == 1 ? s : 0, axis == 2 ? s : 0);
    return true;
}

/* ---- the cone at a smooth extraordinary point (subdiv_ev.c) ---- */

/* The quad holding the directed edge a -> b: its two corners after b. */
static bool quad_after(const sd_mesh *m, int a, int b, int *x, int *y)
{
    for (int f = 0; f < m->nf; f++) {
        if (m->fo[f + 1] - m->fo[f] != 4) continue;
        for (int c = 0; c < 4; c++)
            if (m->fv[m->fo[f] + c] == a && m->fv[m->fo[f] + (c + 1) % 4] == b) {
                *x = m->fv[m->fo[f] + (c + 2) % 4];
                *y = m->fv[m->fo[f] + (c + 3) % 4];
                return true;
            }
    }
    return false;
}

static int faces_at(const sd_mesh *m, int v)
{
    int k = 0;
    for (int c = 0; c < m->fo[m->nf]; c++) k += m->fv[c] == v;
    return k;
}

/* The 2n+8 points the sub-face's limit depends on, in subdiv_ev.h's order,
 * when face 0 is a quad whose one irregular corner is an interior point of
 * valence n (3..SD_EV_NMAX) and no edge or point of the 1-ring is tagged
 * (so the smooth rules alone refine those points); else 0. The walk goes
 * round the EV by directed edges (faces agree on orientation), which also
 * proves it interior (the walk closes). */
static int ev_ring(const sd_mesh *m, int idxs[SD_EV_RING_MAX])
{
    if (m->fo[1] - m->fo[0] != 4) return 0;
    for (int c = 0; c < m->fo[m->nf]; c++)
        if (m->es[c] != 0) return 0;
    for (int v = 0; v < m->nv; v++)
        if (m->vs[v] != 0) return 0;
    int k = -1;
    for (int c = 0; c < 4; c++)
        if (faces_at(m, m->fv[m->fo[0] + c]) != 4) {
            if (k >= 0) return 0;
            k = c;
        }
    if (k < 0) return 0;
    int cpt = m->fv[m->fo[0] + k], n = faces_at(m, cpt);
    if (n < 3 || n > SD_EV_NMAX) return 0;
    int *e = idxs + 1, *f = idxs + 1 + n, *g = idxs + 1 + 2 * n;
    idxs[0] = cpt;
    e[0] = m->fv[m->fo[0] + (k + 1) % 4];
    f[0] = m->fv[m->fo[0] + (k + 2) % 4];
    e[1 % n] = m->fv[m->fo[0] + (k + 3) % 4];
    for (int i = 1; i < n; i++) {
        int en;
        if (!quad_after(m, cpt, e[i], &f[i], &en)) return 0;
        if (i + 1 < n) e[i + 1] = en;
        else if (en != e[0]) return 0;
    }
    int x, y;
    if (!quad_after(m, f[0], e[0], &g[0], &g[1])) return 0;
    if (!quad_after(m, e[0], f[n - 1], &g[6], &x) || x != g[0]) return 0;
    if (!quad_after(m, f[0], g[1], &g[2], &g[3])) return 0;
    if (!quad_after(m, e[1], f[0], &x, &g[4]) || x != g[3]) return 0;
    if (!quad_after(m, f[1], e[1], &y, &g[5]) || y != g[4]) return 0;
    if (faces_at(m, e[0]) != 4 || faces_at(m, e[1]) != 4 || faces_at(m, f[0]) != 4) return 0;
    return n;
}

/* The float pad of the box: the renderer's float evaluation of normals
 * near the EV tilts by the refinement's rounding amplified by the level
 * (measured: below 1e-5 down to 2^-26 from the point, test_geom_subdiv_ev,
 * which holds even that pad; nearer than 2^-26 at valence 3 up to 3e-5,
 * bench/ev_cone in session 14: so 1e-4 here, which changes no box count
 * of r0.25.rib nor its image). Not part of the proof, like the planar
 * case's 1e-6. */
#define EV_FLOAT_PAD 1e-4

static bool ev_box(const sd_node *n, double pmax, ia_interval N[3])
{
    int idxs[SD_EV_RING_MAX];
    int val = ev_ring(&n->m, idxs);
    const sd_ev_consts *K = val ? sd_ev_consts_get(val) : NULL;
    if (!K) return false;
    /* The ring's rounding: level + 1 steps of sd_refine from the control
     * points, each new point a fixed sum of at most maxval + 12 rounded
     * operations on points no larger than pmax (convex combinations), its
     * parents' errors carried with weights summing to 1: per coordinate at
     * most (level + 1) (maxval + 12) u pmax; taken twice over. */
    double steps = (double)(n->level + 1) * (2.0 * n->maxval + 24);
    double delta = fp_mul_up(fp_mul_up(steps, 0x1p-53), fp_mul_up(pmax, 1.01));
    ia_interval X[SD_EV_RING_MAX][3];
    for (int c = 0; c < 2 * val + 8; c++)
        for (int d = 0; d < 3; d++) {
            double x = v3_comp(n->m.P[idxs[c]], d);
            X[c][d] = ia_make(fp_add_dn(x, -delta), fp_add_up(x, delta));
        }
    return sd_ev_unit_normal_box(K, (const ia_interval(*)[3])X, 1.0, EV_FLOAT_PAD, N);
}

bool sd_node_ev_box(const sd_node *n, double pmax, ia_interval N[3])
{
    if (n->regular) return false;
    sd_node *w = (sd_node *)n;
    int st = atomic_load_explicit(&w->ev, memory_order_acquire);
    if (st == 1) return false;
    if (st == 2) {
        memcpy(N, w->evbox, sizeof w->evbox);
        return true;
    }
    bool ok = ev_box(n, pmax, N);
    int expected = 0;
    if (atomic_compare_exchange_strong(&w->ev, &expected, 3)) {
        if (ok) memcpy(w->evbox, N, sizeof w->evbox);
        atomic_store_explicit(&w->ev, ok ? 2 : 1, memory_order_release);
    }
    return ok;
}
