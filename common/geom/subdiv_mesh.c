/*
 * subdiv_mesh.c: building a Catmull-Clark mesh (geom_subdiv) from a
 * SubdivisionMesh: the topology checks, the tags (RI Specification 3.2
 * §5.5: crease, corner, hole, interpolateboundary), one global refinement
 * step so that every face is a quad (subdiv_refine.c), made again around
 * a face whenever its 1-ring is asked for, not kept (issue 23: what a
 * worker keeps is the control mesh, its point -> faces table and a byte
 * of flags per refined face, subdiv_internal.h), and a refined face's
 * surface with its Bezier net where the face is regular.
 *
 * The 1-ring of refined face f (the child of control corner f, of
 * control face F) lies in the refinement of the control faces that share a
 * point with F: its points are the vertex points of F's points (their
 * rings of faces and edges all there), the edge points of edges at F's
 * points (both faces there) and the face points of those faces. Those
 * faces, in the order of the whole mesh, with their points numbered in the
 * whole mesh's order, refine (sd_refine: faces in order, edges sorted by
 * their points, each sum in that order) to the same numbers, bit for bit,
 * as the whole mesh refined at once; and the 1-ring is copied out of it in
 * the order the whole refined mesh would give (faces holding each corner
 * point by ascending index).
 */
#include "geom/subdiv_local.h"
#include "geom/surface_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the meshes' serial numbers (ring_of_face's cache below) */
static _Atomic unsigned long next_serial = 1;

static double tag_sharpness(double s)
{
    return s >= GEOM_SUBDIV_INFINITE ? INFINITY : (s > 0 ? s : 0);
}

typedef struct dir_edge { int a, b, c; } dir_edge;

static int dir_cmp(const void *x, const void *y)
{
    const dir_edge *p = x, *q = y;
    int pa = p->a < p->b ? p->a : p->b, pb = p->a < p->b ? p->b : p->a;
    int qa = q->a < q->b ? q->a : q->b, qb = q->a < q->b ? q->b : q->a;
    if (pa != qa) return pa < qa ? -1 : 1;
    if (pb != qb) return pb < qb ? -1 : 1;
    return (p->c > q->c) - (p->c < q->c);
}

static int find_corner(const dir_edge *e, int ne, int a, int b)
{
    int lo = 0, hi = ne;
    dir_edge key = { a, b, -1 };
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (dir_cmp(&e[mid], &key) < 0) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

geom_subdiv *geom_subdiv_new(const geom_subdiv_desc *d, char *err, size_t errsz)
{
    int nf = d->nfaces, nv = d->npoints, nc = 0;
    for (int f = 0; f < nf; f++) {
        if (d->nverts[f] < 3) {
            err_set(err, errsz, "face %d has %d points (at least 3 are needed)", f,
                    d->nverts[f]);
            return NULL;
        }
        nc += d->nverts[f];
    }
    for (int i = 0; i < 3 * nv; i++)
        if (!isfinite(d->P[i]) || fabs(d->P[i]) > 1e150) {
            err_set(err, errsz, "point %d is not finite", i / 3);
            return NULL;
        }
    sd_mesh m0 = { nv, nf, xmalloc((size_t)(nv + 1) * sizeof(vec3)),
                   xcalloc((size_t)nv + 1, sizeof(double)), xmalloc((size_t)(nf + 1) * sizeof(int)),
                   xmalloc((size_t)(nc + 1) * sizeof(int)), xcalloc((size_t)nc + 1, sizeof(double)) };
    dir_edge *e = xmalloc((size_t)(nc + 1) * sizeof *e);
    int *face_of = xmalloc((size_t)(nc + 1) * sizeof *face_of);
    int *count = xcalloc((size_t)nv + 1, sizeof *count);
    unsigned char *hole0 = xcalloc((size_t)nf + 1, 1);
    geom_subdiv *sd = xcalloc(1, sizeof *sd);
    sd->serial = atomic_fetch_add(&next_serial, 1);
    bool ok = true;
    for (int i = 0; i < nv; i++) m0.P[i] = v3(d->P[3 * i], d->P[3 * i + 1], d->P[3 * i + 2]);
    m0.fo[0] = 0;
    for (int f = 0, c = 0; f < nf; f++) {
        for (int k = 0; k < d->nverts[f]; k++, c++) {
            m0.fv[c] = d->verts[c];
            face_of[c] = f;
        }
        m0.fo[f + 1] = c;
    }
    for (int f = 0; f < nf && ok; f++)
        for (int c = m0.fo[f]; c < m0.fo[f + 1]; c++) {
            int nx = c + 1 < m0.fo[f + 1] ? c + 1 : m0.fo[f];
            e[c] = (dir_edge){ m0.fv[c], m0.fv[nx], c };
            if (m0.fv[c] == m0.fv[nx]) {
                ok = err_set(err, errsz, "face %d repeats point %d", f, m0.fv[c]);
                break;
            }
        }
    if (ok) qsort(e, (size_t)nc, sizeof *e, dir_cmp);
    /* each edge: one face, or two that run it in opposite directions */
    for (int i = 0; i < nc && ok; ) {
        int j = i + 1;
        while (j < nc && ((e[j].a == e[i].a && e[j].b == e[i].b) ||
                          (e[j].a == e[i].b && e[j].b == e[i].a)))
            j++;
        if (j - i > 2)
            ok = err_set(err, errsz, "the edge %d-%d has %d faces (at most 2: the mesh "
                           "must be a manifold)", e[i].a, e[i].b, j - i);
        else if (j - i == 2 && e[i].a == e[i + 1].a)
            ok = err_set(err, errsz, "faces %d and %d run the edge %d-%d the same way "
                           "(orient all faces alike)", face_of[e[i].c], face_of[e[i + 1].c],
                           e[i].a, e[i].b);
        else if (j - i == 1) {
            count[e[i].a]++;           /* boundary edges per point */
            count[e[i].b]++;
            if (d->interpolateboundary) m0.es[e[i].c] = INFINITY;
        }
        i = j;
    }
    int *val = xcalloc((size_t)nv + 1, sizeof *val);
    for (int c = 0; c < nc; c++) val[m0.fv[c]]++;
    for (int i = 0; i < nv && ok; i++)
        if (d->interpolateboundary && val[i] == 1 && count[i] == 2)
            m0.vs[i] = INFINITY;       /* a corner of the boundary */
    free(val);
    /* tags */
    const int *cv = d->crease_verts;
    for (int k = 0; k < d->ncreases && ok; k++) {
        double s = tag_sharpness(d->crease_sharp[k]);
        for (int i = 0; i + 1 < d->crease_len[k]; i++) {
            int a = cv[i], b = cv[i + 1], found = 0;
            for (int dir = 0; dir < 2; dir++) {
                int x = dir ? b : a, y = dir ? a : b;
                int at = find_corner(e, nc, x, y);
                for (int j = at; j < nc && j < at + 2; j++)
                    if (e[j].a == x && e[j].b == y) {
                        m0.es[e[j].c] = fmax(m0.es[e[j].c], s);
                        found = 1;
                    }
            }
            if (!found)
                ok = err_set(err, errsz, "crease %d: points %d and %d share no edge", k, a, b);
        }
        cv += d->crease_len[k];
    }
    for (int k = 0; k < d->ncorners && ok; k++) {
        double s = tag_sharpness(d->corner_sharp[k]);
        if (s > m0.vs[d->corner_verts[k]]) m0.vs[d->corner_verts[k]] = s;
    }
    for (int k = 0; k < d->nholes && ok; k++) hole0[d->holes[k]] = 1;
    /* without interpolateboundary the faces at a boundary point are
     * control only (their 1-rings are not complete) */
    unsigned char *open0 = xcalloc((size_t)nf + 1, 1);
    for (int c = 0; c < nc; c++)
        if (count[m0.fv[c]] > 0) open0[face_of[c]] = 1;
    free(e);
    free(count);
    if (ok) {
        int nf1 = nc;
        sd->nf1 = nf1;
        sd->vf_off = xcalloc((size_t)nv + 2, sizeof(int));
        sd->vf = xmalloc((size_t)(nc + 1) * sizeof(int));
        for (int c = 0; c < nc; c++) sd->vf_off[m0.fv[c] + 1]++;
        for (int i = 0; i < nv; i++) sd->vf_off[i + 1] += sd->vf_off[i];
        int *fill = xcalloc((size_t)nv + 1, sizeof(int));
        for (int c = 0; c < nc; c++) {
            int v = m0.fv[c];
            sd->vf[sd->vf_off[v] + fill[v]++] = face_of[c];
        }
        free(fill);
        /* the refined mesh's valences: a vertex point's (its point's
         * corners), a face point's (its face's size), an edge point's (4) */
        sd->maxval = 4;
        for (int v = 0; v < nv; v++)
            if (sd->vf_off[v + 1] - sd->vf_off[v] > sd->maxval)
                sd->maxval = sd->vf_off[v + 1] - sd->vf_off[v];
        for (int f = 0; f < nf; f++)
            if (m0.fo[f + 1] - m0.fo[f] > sd->maxval) sd->maxval = m0.fo[f + 1] - m0.fo[f];
        sd->pmax = 0;
        for (int v = 0; v < nv; v++)
            sd->pmax = fmax(sd->pmax, fmax(fabs(m0.P[v].x), fmax(fabs(m0.P[v].y), fabs(m0.P[v].z))));
        /* tags that are all 0 are not kept */
        bool tagged = false;
        for (int c = 0; c < nc && !tagged; c++) tagged = m0.es[c] != 0;
        if (!tagged) {
            free(m0.es);
            m0.es = NULL;
        }
        tagged = false;
        for (int v = 0; v < nv && !tagged; v++) tagged = m0.vs[v] != 0;
        if (!tagged) {
            free(m0.vs);
            m0.vs = NULL;
        }
        sd->m0 = m0;
        m0 = (sd_mesh){ 0 };
        sd->flags = xcalloc((size_t)nf1 + 1, 1);
        sd->irr_base = xcalloc((size_t)nf1 / 64 + 2, sizeof(int));
        sd_local L;
        sd_local_init(&L, sd->maxval);
        sd_ring R;
        for (int f = 0; f < nf; f++) {
            bool drawn = !hole0[f] && (d->interpolateboundary || !open0[f]);
            if (!drawn) continue;
            sd_ring_make(sd, f, &R);
            for (int c = sd->m0.fo[f]; c < sd->m0.fo[f + 1]; c++) {
                vec3 net[16];
                sd_ring_child(&R, c - sd->m0.fo[f], &L);
                sd->flags[c] = SD_DRAWN | (sd_regular_net(&L.m, net) ? SD_REGULAR : 0);
            }
            sd_ring_clear(&R);
        }
        sd_local_clear(&L);
        for (int f = 0; f < nf1; f++) {
            if ((f & 63) == 0) sd->irr_base[f >> 6] = sd->nirr;
            if (sd->flags[f] == SD_DRAWN) sd->nirr++;
        }
        sd_cache_init(sd);
    }
    free(m0.P);
    free(m0.vs);
    free(m0.fo);
    free(m0.fv);
    free(m0.es);
    free(face_of);
    free(hole0);
    free(open0);
    if (!ok) {
        geom_subdiv_destroy(&sd);
        return NULL;
    }
    return sd;
}

void geom_subdiv_destroy(geom_subdiv **self_p)
{
    geom_subdiv *sd = *self_p;
    if (!sd) return;
    sd_cache_clear(sd);
    free(sd->m0.P);
    free(sd->m0.vs);
    if (!sd->faces_shared) {
        free(sd->m0.fo);
        free(sd->m0.fv);
    }
    free(sd->m0.es);
    free(sd->vf_off);
    free(sd->vf);
    free(sd->flags);
    free(sd->irr_base);
    free(sd);
    *self_p = NULL;
}

void geom_subdiv_share_faces(geom_subdiv *self, const int *fo, const int *verts)
{
    assert(!self->faces_shared);
    assert(memcmp(fo, self->m0.fo, (size_t)(self->m0.nf + 1) * sizeof *fo) == 0);
    assert(memcmp(verts, self->m0.fv, (size_t)self->m0.fo[self->m0.nf] * sizeof *verts) == 0);
    free(self->m0.fo);
    free(self->m0.fv);
    /* never written through: the control mesh is read only once made */
    self->m0.fo = (int *)fo;
    self->m0.fv = (int *)verts;
    self->faces_shared = true;
}

size_t geom_subdiv_bytes(const geom_subdiv *self, size_t *points)
{
    int nv = self->m0.nv, nf = self->m0.nf, nc = self->nf1;
    *points = (size_t)(nv + 1) * sizeof(vec3);
    return sizeof *self + *points + (self->m0.vs ? (size_t)(nv + 1) * sizeof(double) : 0) +
           (self->faces_shared ? 0 : (size_t)(nf + 1 + nc + 1) * sizeof(int)) +
           (self->m0.es ? (size_t)(nc + 1) * sizeof(double) : 0) +
           (size_t)(nv + 2 + nc + 1) * sizeof(int) + (size_t)nc + 1 +
           (size_t)(nc / 64 + 2) * sizeof(int) + (size_t)(self->nirr + 1) * sizeof(*self->roots);
}

int sd_irregular_rank(const geom_subdiv *sd, int f)
{
    assert(f >= 0 && f < sd->nf1 && sd->flags[f] == SD_DRAWN);
    int r = sd->irr_base[f >> 6];
    for (int g = f & ~63; g < f; g++) r += sd->flags[g] == SD_DRAWN;
    return r;
}

int geom_subdiv_nfaces(const geom_subdiv *self) { return self->nf1; }

bool geom_subdiv_face_drawn(const geom_subdiv *self, int f) { return self->flags[f] & SD_DRAWN; }

/* the control face holding corner c */
static int face_of_corner(const sd_mesh *m, int c)
{
    int lo = 0, hi = m->nf - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (m->fo[mid] <= c) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

int geom_subdiv_face_origin(const geom_subdiv *self, int f) { return face_of_corner(&self->m0, f); }

static int next_in(const sd_mesh *m, int F, int c) { return c + 1 < m->fo[F + 1] ? c + 1 : m->fo[F]; }
static int prev_in(const sd_mesh *m, int F, int c) { return c > m->fo[F] ? c - 1 : m->fo[F + 1] - 1; }

/* the corner of control face G at point v (G holds v) */
static int corner_at(const sd_mesh *m, int G, int v)
{
    int c = m->fo[G];
    while (m->fv[c] != v) c++;
    assert(c < m->fo[G + 1]);
    return c;
}

/* A name for the edge of control corner c (from its point to the next):
 * the smaller of its corner and the corner running it the other way */
static int edge_name(const geom_subdiv *sd, int c)
{
    const sd_mesh *m = &sd->m0;
    int F = face_of_corner(m, c), a = m->fv[c], b = m->fv[next_in(m, F, c)];
    for (int i = sd->vf_off[b]; i < sd->vf_off[b + 1]; i++) {
        int G = sd->vf[i], cb = corner_at(m, G, b);
        if (m->fv[next_in(m, G, cb)] == a) return cb < c ? cb : c;
    }
    return c;
}

void geom_subdiv_face_points(const geom_subdiv *self, int f, int out[4])
{
    const sd_mesh *m = &self->m0;
    int F = face_of_corner(m, f), n = m->fo[F + 1] - m->fo[F], k = f - m->fo[F];
    int g[4] = { m->fv[f], m->nv + m->nf + edge_name(self, f), m->nv + F,
                 m->nv + m->nf + edge_name(self, prev_in(m, F, f)) };
    int start = n == 4 ? (4 - k) % 4 : 0;     /* as sd_refine turns the child */
    for (int j = 0; j < 4; j++) out[j] = g[(j + start) % 4];
}

/* ---- 1-rings made again (the comment at the top) ---- */

static int int_cmp(const void *x, const void *y)
{
    int a = *(const int *)x, b = *(const int *)y;
    return (a > b) - (a < b);
}

/* sorts a[0..n) and drops repeats; the new count */
static int sort_unique(int *a, int n)
{
    if (n <= 64) {                     /* a control face's ring: a few dozen */
        for (int i = 1; i < n; i++) {
            int x = a[i], j = i;
            for (; j > 0 && a[j - 1] > x; j--) a[j] = a[j - 1];
            a[j] = x;
        }
    } else {
        qsort(a, (size_t)n, sizeof *a, int_cmp);
    }
    int m = 0;
    for (int i = 0; i < n; i++)
        if (m == 0 || a[m - 1] != a[i]) a[m++] = a[i];
    return m;
}

static int find_sorted(const int *a, int n, int x)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (a[mid] < x) lo = mid + 1;
        else hi = mid;
    }
    assert(n > 0 && a[lo] == x);
    return lo;
}

/* sd_ring_make into buf when its arrays fit in cap bytes (false if they
 * do not: R untouched), or on the heap (buf NULL) */
static bool ring_build(const geom_subdiv *sd, int F, sd_ring *R, void *buf, size_t cap)
{
    const sd_mesh *m = &sd->m0;
    int nfc = 0;
    for (int c = m->fo[F]; c < m->fo[F + 1]; c++) nfc += sd->vf_off[m->fv[c] + 1] - sd->vf_off[m->fv[c]];
    int stack[256];
    int *faces = nfc <= 256 ? stack : xmalloc((size_t)nfc * sizeof *faces);
    nfc = 0;
    for (int c = m->fo[F]; c < m->fo[F + 1]; c++)
        for (int i = sd->vf_off[m->fv[c]]; i < sd->vf_off[m->fv[c] + 1]; i++)
            faces[nfc++] = sd->vf[i];
    int nf = sort_unique(faces, nfc), nc = 0;
    for (int i = 0; i < nf; i++) nc += m->fo[faces[i] + 1] - m->fo[faces[i]];
    /* one block: the control faces (nv <= nc points), their refinement
     * (nv + nf + nc points, nc faces, 4 nc corners), the points' names and
     * the children's list */
    size_t c1 = (size_t)nc, f1 = (size_t)nf, v1 = (size_t)(nc + nf + nc);
    size_t bytes = (c1 + v1) * (sizeof(vec3) + sizeof(double)) + c1 * sizeof(double) +
                   4 * c1 * sizeof(double) +
                   (f1 + 1 + c1 + c1 + 1 + 4 * c1 + c1 + c1 + 1 + v1) * sizeof(int);
    if (buf && bytes > cap) {
        if (faces != stack) free(faces);
        return false;
    }
    char *b = buf ? buf : xmalloc(bytes);
    sd_mesh *lm = &R->ctl, *lr = &R->ref;
    vec3 *P0 = (vec3 *)b, *P1 = P0 + c1;
    double *vs0 = (double *)(P1 + v1), *vs1 = vs0 + c1, *es0 = vs1 + v1, *es1 = es0 + c1;
    int *fo0 = (int *)(es1 + 4 * c1), *fv0 = fo0 + f1 + 1, *fo1 = fv0 + c1, *fv1 = fo1 + c1 + 1;
    int *pts = fv1 + 4 * c1;
    R->list = pts + c1;
    R->local = R->list + c1 + 1;
    for (size_t i = 0; i < v1; i++) R->local[i] = -1;
    R->block = buf ? NULL : b;
    nc = 0;
    for (int i = 0; i < nf; i++)
        for (int c = m->fo[faces[i]]; c < m->fo[faces[i] + 1]; c++) pts[nc++] = m->fv[c];
    int nv = sort_unique(pts, nc);
    /* the control faces, their points numbered in the mesh's order */
    *lm = (sd_mesh){ nv, nf, P0, vs0, fo0, fv0, es0 };
    for (int i = 0; i < nv; i++) {
        lm->P[i] = m->P[pts[i]];
        lm->vs[i] = m->vs ? m->vs[pts[i]] : 0;
    }
    lm->fo[0] = 0;
    for (int i = 0, lc = 0; i < nf; i++) {
        if (faces[i] == F) R->base = lc;
        for (int c = m->fo[faces[i]]; c < m->fo[faces[i] + 1]; c++, lc++) {
            lm->fv[lc] = find_sorted(pts, nv, m->fv[c]);
            lm->es[lc] = m->es ? m->es[c] : 0;
        }
        lm->fo[i + 1] = lc;
    }
    *lr = (sd_mesh){ 0, 0, P1, vs1, fo1, fv1, es1 };
    sd_refine(lm, lr);
    if (faces != stack) free(faces);
    return true;
}

void sd_ring_make(const geom_subdiv *sd, int F, sd_ring *R)
{
    ring_build(sd, F, R, NULL, 0);
}

/* The last rings a thread made, in buffers of its own (no heap, so
 * nothing is left when the thread ends): the children of a control face
 * come one after the other in the world's pass over the pieces, and close
 * together in the mesh's BVH order (its regions' pass, a ray's
 * neighbouring faces), and share them. 16 ways of 12 KiB (a quad's ring
 * at valences up to 6 or so), replaced in turn, and one of 32 KiB for the
 * larger rings: on the asset's rocks (43,200 cage faces) 115,620 rings
 * made for 490,541 faces' surfaces, against 215,618 with one way. Keyed
 * by the mesh's serial number, never reused; a ring is a pure function of
 * the mesh and the face, so the cache changes no bit. */
enum { RING_WAY_BYTES = 12288, RING_BIG_BYTES = 32768, RING_WAYS = 16 };
typedef struct ring_way {
    unsigned long serial;
    int F;
    sd_ring R;
} ring_way;
static _Thread_local struct {
    ring_way way[RING_WAYS], big;
    int next;                          /* the way to replace next */
    _Alignas(16) char buf[RING_WAYS][RING_WAY_BYTES];
    _Alignas(16) char big_buf[RING_BIG_BYTES];
} ring_cache;

/* F's ring made into way w's buffer buf of cap bytes; false if it does
 * not fit (w then empty) */
static bool ring_into(const geom_subdiv *sd, int F, ring_way *w, void *buf, size_t cap)
{
    w->serial = 0;
    if (!ring_build(sd, F, &w->R, buf, cap)) return false;
    w->serial = sd->serial;
    w->F = F;
    return true;
}

/* F's ring: the thread's cached one, or made into *heap (then freed by
 * the caller with sd_ring_clear) */
static const sd_ring *ring_of_face(const geom_subdiv *sd, int F, sd_ring *heap)
{
    for (int w = 0; w < RING_WAYS; w++)
        if (ring_cache.way[w].serial == sd->serial && ring_cache.way[w].F == F)
            return &ring_cache.way[w].R;
    if (ring_cache.big.serial == sd->serial && ring_cache.big.F == F) return &ring_cache.big.R;
    int w = ring_cache.next;
    if (ring_into(sd, F, &ring_cache.way[w], ring_cache.buf[w], RING_WAY_BYTES)) {
        ring_cache.next = (w + 1) % RING_WAYS;
        return &ring_cache.way[w].R;
    }
    if (ring_into(sd, F, &ring_cache.big, ring_cache.big_buf, RING_BIG_BYTES))
        return &ring_cache.big.R;
    ring_build(sd, F, heap, NULL, 0);
    return heap;
}

void sd_ring_child(const sd_ring *R, int k, sd_local *L)
{
    const sd_mesh *lr = &R->ref;
    int f = R->base + k, n = 0, *list = R->list;
    list[n++] = f;
    for (int j = 0; j < 4; j++) {
        int p = lr->fv[4 * f + j];
        for (int g = 0; g < lr->nf; g++) {
            const int *q = lr->fv + 4 * g;
            if (q[0] != p && q[1] != p && q[2] != p && q[3] != p) continue;
            int i = 0;
            while (i < n && list[i] != g) i++;
            if (i == n) list[n++] = g;
        }
    }
    assert(n <= sd_lf(L->maxval));
    /* sd_local_take's copy (points numbered as they come), its search for a
     * point by the ring's table of local numbers */
    L->m = (sd_mesh){ 0, 0, L->P, L->vs, L->fo, L->fv, L->es };
    int nc = 0, *local = R->local;
    L->fo[0] = 0;
    for (int i = 0; i < n; i++) {
        int g = list[i];
        assert(nc + 4 <= sd_lc(L->maxval));
        for (int c = 4 * g; c < 4 * g + 4; c++) {
            int v = lr->fv[c];
            if (local[v] < 0) {
                int j = L->m.nv++;
                local[v] = j;
                L->src[j] = v;
                L->P[j] = lr->P[v];
                L->vs[j] = lr->vs[v];
            }
            L->fv[nc] = local[v];
            L->es[nc] = lr->es[c];
            nc++;
        }
        L->fo[++L->m.nf] = nc;
    }
    for (int j = 0; j < L->m.nv; j++) local[L->src[j]] = -1;
}

void sd_ring_clear(sd_ring *R)
{
    free(R->block);
    *R = (sd_ring){ 0 };
}

void sd_local_from_shared(const geom_subdiv *sd, int f, sd_local *L)
{
    assert(L->maxval == sd->maxval);
    int F = face_of_corner(&sd->m0, f);
    sd_ring heap = { 0 };
    const sd_ring *R = ring_of_face(sd, F, &heap);
    sd_ring_child(R, f - sd->m0.fo[F], L);
    sd_ring_clear(&heap);
}

void geom_subdiv_surface(const geom_subdiv *self, int f, geom_surface *out)
{
    memset(out, 0, sizeof *out);
    out->kind = GEOM_SUBDIV;
    out->subdiv = self;
    out->subdiv_face = f;
    sd_local L;
    sd_local_init(&L, self->maxval);
    sd_local_from_shared(self, f, &L);
    /* a regular face's net, in verts (subdiv_eval.c reads it there) */
    if (self->flags[f] & SD_REGULAR) {
        sd_known_regular_net(&L.m, out->verts);
        out->nverts = 16;
    }
    sd_local_hull(&L.m, &out->subdiv_lo, &out->subdiv_hi);
    sd_local_clear(&L);
}

bool geom_subdiv_limit_point(const geom_subdiv *self, int point, vec3 *out)
{
    if (point < 0 || point >= self->m0.nv || self->vf_off[point] == self->vf_off[point + 1])
        return false;
    /* the child of a corner at the point: its corner at the vertex point */
    int F = self->vf[self->vf_off[point]], c = corner_at(&self->m0, F, point);
    int n = self->m0.fo[F + 1] - self->m0.fo[F], k = c - self->m0.fo[F];
    int j = n == 4 ? k : 0;
    static const double U[4] = { 0, 1, 1, 0 }, V[4] = { 0, 0, 1, 1 };
    geom_surface s;
    geom_subdiv_surface(self, c, &s);
    geom_sample g;
    geom_eval(&s, U[j], V[j], &g);
    *out = g.P;
    return true;
}
