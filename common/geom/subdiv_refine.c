/*
 * subdiv_refine.c: one Catmull-Clark step (Catmull & Clark 1978) on a mesh
 * of polygons with edge and corner sharpness, with the rules of DeRose,
 * Kass & Truong 1998 ("Subdivision surfaces in character animation", §3):
 *
 *   face point   the average of the face's points
 *   edge point   smooth (a + b + f0 + f1) / 4; sharp (s >= 1) the midpoint;
 *                0 < s < 1 the blend (1 - s) smooth + s sharp;
 *                an edge with one face: the midpoint
 *   vertex point smooth (Q + 2 R + (n - 3) S) / n (Q: mean of the face
 *                points, R: mean of the edge midpoints, n edges); with two
 *                sharp edges the crease rule (e1 + 6 S + e2) / 8; with more,
 *                or a corner sharpness, S stays; the strength (mean of the
 *                sharp edges' sharpness, or the corner's) blends with the
 *                smooth rule below 1
 *
 * and sharpness decays by 1 per step (infinite stays infinite). The new
 * faces are quads, numbered by the parent's corners; a quad's children keep
 * its (u,v) directions (subdiv_internal.h).
 */
#include "geom/subdiv_internal.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct sd_ekey { int a, b, c; } sd_ekey;

static int ekey_cmp(const void *x, const void *y)
{
    const sd_ekey *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return (p->c > q->c) - (p->c < q->c);
}

static int next_corner(const sd_mesh *m, int f, int c)
{
    return c + 1 < m->fo[f + 1] ? c + 1 : m->fo[f];
}

/* Corner -> edge id; per edge its first and second corner (-1). Returns the
 * number of edges. face_of: per corner its face. */
static int build_edges(const sd_mesh *m, const int *face_of, int *cedge, int (*ec)[2])
{
    int nc = m->fo[m->nf];
    sd_ekey stack[64];
    sd_ekey *k = nc <= 64 ? stack : xmalloc((size_t)nc * sizeof *k);
    for (int c = 0; c < nc; c++) {
        int a = m->fv[c], b = m->fv[next_corner(m, face_of[c], c)];
        k[c] = (sd_ekey){ a < b ? a : b, a < b ? b : a, c };
    }
    if (nc <= 64) {                    /* the local meshes: a few dozen corners */
        for (int i = 1; i < nc; i++) {
            sd_ekey x = k[i];
            int j = i;
            for (; j > 0 && ekey_cmp(&k[j - 1], &x) > 0; j--) k[j] = k[j - 1];
            k[j] = x;
        }
    } else {
        qsort(k, (size_t)nc, sizeof *k, ekey_cmp);
    }
    int ne = 0;
    for (int i = 0; i < nc; i++) {
        if (i > 0 && k[i].a == k[i - 1].a && k[i].b == k[i - 1].b) {
            ec[ne - 1][1] = k[i].c;        /* a third face is refused earlier */
        } else {
            ec[ne][0] = k[i].c;
            ec[ne][1] = -1;
            ne++;
        }
        cedge[k[i].c] = ne - 1;
    }
    if (k != stack) free(k);
    return ne;
}

static double decay(double s)
{
    if (isinf(s)) return s;
    return s > 1 ? s - 1 : 0;
}

static vec3 lerp3(vec3 a, vec3 b, double t)
{
    return v3_add(v3_scale(a, 1 - t), v3_scale(b, t));
}

void sd_refine(const sd_mesh *m, sd_mesh *out)
{
    int nv = m->nv, nf = m->nf, nc = m->fo[nf];
    /* the scratch in one block (this runs for every face's 1-ring) */
    size_t nc1 = (size_t)nc + 1, nv1 = (size_t)nv + 1;
    char *block = xcalloc(1, 3 * nv1 * sizeof(vec3) + nv1 * sizeof(double) +
                             (3 * nc1 + 3 * nv1) * sizeof(int) + nc1 * 2 * sizeof(int));
    vec3 *fsum = (vec3 *)block, *rsum = fsum + nv1, *esum = rsum + nv1;
    double *ssum = (double *)(esum + nv1);
    int (*ec)[2] = (int (*)[2])(ssum + nv1);
    int *face_of = (int *)(ec + nc1), *cedge = face_of + nc1;
    int *nfc = cedge + nc1, *nec = nfc + nv1, *nsh = nec + nv1;
    /* per point: face point sum, faces, midpoint sum, edges, sharp edges,
     * their sharpness sum, their far ends' sum */
    for (int f = 0; f < nf; f++)
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++) face_of[c] = f;
    int ne = build_edges(m, face_of, cedge, ec);

    int fp0 = nv, ep0 = nv + nf;
    out->nv = nv + nf + ne;
    /* face points */
    for (int f = 0; f < nf; f++) {
        vec3 s = v3(0, 0, 0);
        int n = m->fo[f + 1] - m->fo[f];
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++) s = v3_add(s, m->P[m->fv[c]]);
        out->P[fp0 + f] = v3_scale(s, 1.0 / n);
        out->vs[fp0 + f] = 0;
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++) {
            fsum[m->fv[c]] = v3_add(fsum[m->fv[c]], out->P[fp0 + f]);
            nfc[m->fv[c]]++;
        }
    }
    /* edge points, and the sums of the vertex rule */
    for (int e = 0; e < ne; e++) {
        int c0 = ec[e][0], c1 = ec[e][1];
        int a = m->fv[c0], b = m->fv[next_corner(m, face_of[c0], c0)];
        double s = m->es[c0];
        if (c1 >= 0 && m->es[c1] > s) s = m->es[c1];
        vec3 mid = v3_scale(v3_add(m->P[a], m->P[b]), 0.5);
        vec3 p = mid;
        if (c1 >= 0 && s < 1) {
            vec3 sm = v3_scale(v3_add(v3_add(m->P[a], m->P[b]),
                                      v3_add(out->P[fp0 + face_of[c0]],
                                             out->P[fp0 + face_of[c1]])), 0.25);
            p = s > 0 ? lerp3(sm, mid, s) : sm;
        }
        out->P[ep0 + e] = p;
        out->vs[ep0 + e] = 0;
        int ends[2] = { a, b };
        for (int k = 0; k < 2; k++) {
            int v = ends[k], w = ends[1 - k];
            rsum[v] = v3_add(rsum[v], mid);
            nec[v]++;
            if (s > 0) {
                nsh[v]++;
                ssum[v] += s;
                esum[v] = v3_add(esum[v], m->P[w]);
            }
        }
    }
    /* vertex points */
    for (int v = 0; v < nv; v++) {
        vec3 S = m->P[v];
        int n = nec[v];
        vec3 smooth = S;
        if (n >= 2 && nfc[v] == n) {
            vec3 Q = v3_scale(fsum[v], 1.0 / n), R = v3_scale(rsum[v], 1.0 / n);
            smooth = v3_scale(v3_add(v3_add(Q, v3_scale(R, 2)), v3_scale(S, n - 3)), 1.0 / n);
        }
        vec3 p = smooth;
        double strength = nsh[v] > 0 ? ssum[v] / nsh[v] : 0;
        if (m->vs[v] > 0 || nsh[v] > 2) {
            double k = m->vs[v] > strength ? m->vs[v] : strength;
            p = k >= 1 ? S : lerp3(smooth, S, k);
        } else if (nsh[v] == 2) {
            vec3 crease = v3_scale(v3_add(esum[v], v3_scale(S, 6)), 0.125);
            p = strength >= 1 ? crease : lerp3(smooth, crease, strength);
        }
        out->P[v] = p;
        out->vs[v] = decay(m->vs[v]);
    }
    /* child quads, one per corner, in the parent's (u,v) directions */
    out->nf = nc;
    for (int f = 0; f < nf; f++) {
        int n = m->fo[f + 1] - m->fo[f];
        for (int k = 0; k < n; k++) {
            int c = m->fo[f] + k, cp = m->fo[f] + (k + n - 1) % n;
            int g[4] = { m->fv[c], ep0 + cedge[c], fp0 + f, ep0 + cedge[cp] };
            double gs[4] = { decay(m->es[c]), 0, 0, decay(m->es[cp]) };
            int start = n == 4 ? (4 - k) % 4 : 0;
            out->fo[c] = 4 * c;
            for (int j = 0; j < 4; j++) {
                out->fv[4 * c + j] = g[(j + start) % 4];
                out->es[4 * c + j] = gs[(j + start) % 4];
            }
        }
    }
    out->fo[nc] = 4 * nc;
    free(block);
}
