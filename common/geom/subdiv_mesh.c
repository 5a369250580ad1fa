/*
 * subdiv_mesh.c: building a Catmull-Clark mesh (geom_subdiv) from a
 * SubdivisionMesh: the topology checks, the tags (RI Specification 3.2
 * §5.5: crease, corner, hole, interpolateboundary), one global refinement
 * step so that every face is a quad (subdiv_refine.c), the point -> faces
 * table for 1-rings, and the Bezier nets of the faces that are regular
 * from the start (most of them), so that they cost no refinement later.
 */
#include "geom/subdiv_local.h"
#include "geom/surface_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
        int ne = sd_edge_count(&m0);
        int nv1 = nv + nf + ne, nf1 = nc;
        sd->m = (sd_mesh){ 0, 0, xmalloc((size_t)nv1 * sizeof(vec3)),
                           xmalloc((size_t)nv1 * sizeof(double)),
                           xmalloc((size_t)(nf1 + 1) * sizeof(int)),
                           xmalloc((size_t)(4 * nf1 + 1) * sizeof(int)),
                           xmalloc((size_t)(4 * nf1 + 1) * sizeof(double)) };
        sd_refine(&m0, &sd->m);
        sd->origin = xmalloc((size_t)(nf1 + 1) * sizeof(int));
        sd->drawn = xcalloc((size_t)nf1 + 1, 1);
        sd->net_of = xmalloc((size_t)(nf1 + 1) * sizeof(int));
        sd->vf_off = xcalloc((size_t)nv1 + 2, sizeof(int));
        sd->vf = xmalloc((size_t)(4 * nf1 + 1) * sizeof(int));
        sd_cache_init(sd);
        for (int c = 0; c < 4 * nf1; c++) sd->vf_off[sd->m.fv[c] + 1]++;
        for (int i = 0; i < nv1; i++) sd->vf_off[i + 1] += sd->vf_off[i];
        int *fill = xcalloc((size_t)nv1 + 1, sizeof(int));
        for (int c = 0; c < 4 * nf1; c++) {
            int v = sd->m.fv[c];
            sd->vf[sd->vf_off[v] + fill[v]++] = c;
        }
        free(fill);
        sd->maxval = 4;
        for (int v = 0; v < nv1; v++)
            if (sd->vf_off[v + 1] - sd->vf_off[v] > sd->maxval)
                sd->maxval = sd->vf_off[v + 1] - sd->vf_off[v];
        int nnets = 0;
        sd->nets = NULL;
        sd_local L;
        sd_local_init(&L, sd->maxval);
        for (int f = 0; f < nf1; f++) {
            sd->origin[f] = face_of[f];
            sd->drawn[f] = !hole0[face_of[f]] && (d->interpolateboundary || !open0[face_of[f]]);
            sd->net_of[f] = -1;
            if (!sd->drawn[f]) continue;
            vec3 net[16];
            sd_local_from_shared(sd, f, &L);
            if (sd_regular_net(&L.m, net)) {
                if ((nnets & (nnets - 1)) == 0) {
                    sd->nets = xrealloc(sd->nets, (size_t)(nnets ? 2 * nnets : 1) * 16 * sizeof(vec3));
                }
                memcpy(sd->nets + 16 * nnets, net, sizeof net);
                sd->net_of[f] = nnets++;
            }
        }
        sd_local_clear(&L);
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
    free(sd->m.P);
    free(sd->m.vs);
    free(sd->m.fo);
    free(sd->m.fv);
    free(sd->m.es);
    free(sd->vf_off);
    free(sd->vf);
    free(sd->drawn);
    free(sd->origin);
    free(sd->net_of);
    free(sd->nets);
    sd_cache_clear(sd);
    free(sd);
    *self_p = NULL;
}

int geom_subdiv_nfaces(const geom_subdiv *self) { return self->m.nf; }

bool geom_subdiv_face_drawn(const geom_subdiv *self, int f) { return self->drawn[f] != 0; }

int geom_subdiv_face_origin(const geom_subdiv *self, int f) { return self->origin[f]; }

void geom_subdiv_face_points(const geom_subdiv *self, int f, int out[4])
{
    for (int k = 0; k < 4; k++) out[k] = self->m.fv[4 * f + k];
}

void geom_subdiv_surface(const geom_subdiv *self, int f, geom_surface *out)
{
    memset(out, 0, sizeof *out);
    out->kind = GEOM_SUBDIV;
    out->subdiv = self;
    out->subdiv_face = f;
}

bool geom_subdiv_limit_point(const geom_subdiv *self, int point, vec3 *out)
{
    if (point < 0 || point >= self->m.nv || self->vf_off[point] == self->vf_off[point + 1])
        return false;
    int c = self->vf[self->vf_off[point]];
    static const double U[4] = { 0, 1, 1, 0 }, V[4] = { 0, 0, 1, 1 };
    geom_surface s;
    geom_subdiv_surface(self, c / 4, &s);
    geom_sample g;
    geom_eval(&s, U[c % 4], V[c % 4], &g);
    *out = g.P;
    return true;
}
