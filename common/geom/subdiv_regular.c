/*
 * subdiv_regular.c: where a Catmull-Clark face is a bicubic patch, and the
 * limit positions of its corners.
 *
 * Regular faces. Away from extraordinary points Catmull-Clark subdivision
 * is the knot insertion of the uniform bicubic B-spline (Catmull & Clark
 * 1978), so a quad whose 1-ring is a 4x4 grid of points with no sharpness
 * is the B-spline patch of that grid. An infinitely sharp edge (a crease,
 * or the boundary with interpolateboundary) follows the cubic B-spline
 * curve rules along it and ignores the other side (DeRose et al. 1998),
 * which is what the B-spline patch does when the row beyond the edge is
 * the mirror image 2 B - I of the row inside (and a corner vertex, kept
 * fixed, by mirroring twice: 4 C - 2 E1 - 2 E2 + I). So a corner of the
 * face is regular when it is (a) smooth: 4 faces, 4 edges, no sharpness;
 * (b) on a crease along one of the face's edges: exactly two infinitely
 * sharp edges there, the other one bounding the face's neighbour across
 * the face's other edge, no corner tag; (c) a corner: both of the face's
 * edges there infinitely sharp and the corner rule applies (a corner tag
 * or more than two sharp edges). Semi-sharp tags make a face irregular
 * until they have decayed.
 *
 * The B-spline net becomes a Bezier net (1D per row: (p0 + 4 p1 + p2)/6,
 * (2 p1 + p2)/3, (p1 + 2 p2)/3, (p1 + 4 p2 + p3)/6), the GEOM_BICUBIC form.
 *
 * Corner limits (Halstead, Kass & DeRose 1993 for the smooth mask): smooth
 * (n^2 S + 4 sum E + sum F) / (n (n + 5)), E the edge neighbours and F the
 * opposite points of the (quad) faces; crease (e1 + 4 S + e2) / 6; corner
 * S. (A dart, one sharp edge, takes the smooth mask: approximate.)
 */
#include "geom/subdiv_local.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>

#include "util/xalloc.h"

static int next_of(const sd_mesh *m, int f, int c)
{
    return c + 1 < m->fo[f + 1] ? c + 1 : m->fo[f];
}

static int prev_of(const sd_mesh *m, int f, int c)
{
    return c > m->fo[f] ? c - 1 : m->fo[f + 1] - 1;
}

/* The corner (and its face) whose edge runs from -> to; -1 if none. */
static int find_edge(const sd_mesh *m, int from, int to, int *face)
{
    for (int f = 0; f < m->nf; f++)
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++)
            if (m->fv[c] == from && m->fv[next_of(m, f, c)] == to) {
                *face = f;
                return c;
            }
    return -1;
}

static double edge_sharp(const sd_mesh *m, int a, int b)
{
    int f, s = 0;
    double r = 0;
    int c = find_edge(m, a, b, &f);
    if (c >= 0) r = m->es[c], s++;
    c = find_edge(m, b, a, &f);
    if (c >= 0 && m->es[c] > r) r = m->es[c];
    return r;
}

static bool tag_ok(double s) { return s == 0 || isinf(s); }

/* The ring of point v: its faces, and the points across its edges
 * (other, at most two per face: ring_clear frees it). */
typedef struct vring {
    int nfaces, nedges, ninf;
    bool ok;                       /* every sharpness 0 or infinite */
    int *other;
    int stack[64];                 /* other, when it fits */
} vring;

static void ring_clear(vring *r)
{
    if (r->other != r->stack) free(r->other);
    r->other = NULL;
}

static void ring_of(const sd_mesh *m, int v, vring *r)
{
    r->nfaces = r->nedges = r->ninf = 0;
    r->ok = tag_ok(m->vs[v]);
    int cap = 2 * m->nf;
    double sh_stack[64];
    r->other = cap <= 64 ? r->stack : xmalloc((size_t)cap * sizeof *r->other);
    double *sh = cap <= 64 ? sh_stack : xmalloc((size_t)cap * sizeof *sh);
    for (int f = 0; f < m->nf; f++)
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++) {
            if (m->fv[c] != v) continue;
            r->nfaces++;
            int cn = next_of(m, f, c), cp = prev_of(m, f, c);
            int ends[2] = { m->fv[cn], m->fv[cp] };
            double s[2] = { m->es[c], m->es[cp] };
            for (int k = 0; k < 2; k++) {
                int i = 0;
                while (i < r->nedges && r->other[i] != ends[k]) i++;
                if (i == r->nedges) {
                    assert(r->nedges < cap);   /* two new ends at most per face */
                    r->other[r->nedges] = ends[k];
                    sh[r->nedges++] = s[k];
                } else if (s[k] > sh[i]) {
                    sh[i] = s[k];
                }
            }
        }
    for (int i = 0; i < r->nedges; i++) {
        if (!tag_ok(sh[i])) r->ok = false;
        if (isinf(sh[i])) r->ninf++;
    }
    if (sh != sh_stack) free(sh);
}

/* grid positions (i along u, j along v) of the face's corners */
static const int CI[4] = { 1, 2, 2, 1 }, CJ[4] = { 1, 1, 2, 2 };
/* outward step of side s (edge corner s -> s+1) */
static const int OI[4] = { 0, 1, 0, -1 }, OJ[4] = { -1, 0, 1, 0 };

static vec3 mirror(vec3 a, vec3 b) { return v3_sub(v3_scale(a, 2), b); }

/* check: whether face 0 is regular (else known, and only its net made) */
static bool face_net(const sd_mesh *m, bool check, vec3 net[16])
{
    if (m->nf < 1 || m->fo[1] - m->fo[0] != 4) return false;
    int c[4];
    for (int k = 0; k < 4; k++) c[k] = m->fv[m->fo[0] + k];
    bool sharp[4];
    for (int s = 0; s < 4; s++) {
        double e = edge_sharp(m, c[s], c[(s + 1) % 4]);
        if (!tag_ok(e)) return false;
        sharp[s] = isinf(e);
    }
    for (int k = 0; k < 4 && check; k++) {
        vring r;
        ring_of(m, c[k], &r);
        ring_clear(&r);    /* its counts are all this test needs */
        if (!r.ok) return false;
        bool sn = sharp[k], sp = sharp[(k + 3) % 4];
        double vs = m->vs[c[k]];
        if (!sn && !sp) {
            if (!(r.ninf == 0 && vs == 0 && r.nfaces == 4 && r.nedges == 4)) return false;
        } else if (sn != sp) {
            if (!(vs == 0 && r.ninf == 2)) return false;
            int f, cc;
            if (sp) {      /* neighbour across side k: (c[k+1], c[k], x, y) */
                cc = find_edge(m, c[(k + 1) % 4], c[k], &f);
                if (cc < 0) return false;
                int ca = next_of(m, f, cc);                 /* c[k] */
                if (!isinf(m->es[ca])) return false;        /* c[k] -> x */
            } else {       /* across side k-1: (c[k], c[k-1], x, y) */
                cc = find_edge(m, c[k], c[(k + 3) % 4], &f);
                if (cc < 0) return false;
                if (!isinf(m->es[prev_of(m, f, cc)])) return false;   /* y -> c[k] */
            }
        } else {
            if (!(isinf(vs) || r.ninf > 2)) return false;
        }
    }
    vec3 G[4][4];
    bool have[4][4] = { { false } };
    for (int k = 0; k < 4; k++) {
        G[CI[k]][CJ[k]] = m->P[c[k]];
        have[CI[k]][CJ[k]] = true;
    }
    for (int s = 0; s < 4; s++) {
        if (sharp[s]) continue;
        int a = c[s], b = c[(s + 1) % 4], f;
        int cb = find_edge(m, b, a, &f);
        if (cb < 0) return false;
        int ca = next_of(m, f, cb), cx = next_of(m, f, ca), cy = next_of(m, f, cx);
        int ka = s, kb = (s + 1) % 4;
        G[CI[ka] + OI[s]][CJ[ka] + OJ[s]] = m->P[m->fv[cx]];
        G[CI[kb] + OI[s]][CJ[kb] + OJ[s]] = m->P[m->fv[cy]];
        have[CI[ka] + OI[s]][CJ[ka] + OJ[s]] = have[CI[kb] + OI[s]][CJ[kb] + OJ[s]] = true;
        /* the diagonal at corner ka when it is smooth: the face across
         * a -> x, (x, a, p, q), q opposite a */
        int kprev = (ka + 3) % 4;
        if (!sharp[kprev]) {
            int f2;
            int c2 = find_edge(m, m->fv[cx], a, &f2);
            if (c2 < 0) return false;
            int q = m->fv[prev_of(m, f2, c2)];
            G[CI[ka] + OI[s] + OI[kprev]][CJ[ka] + OJ[s] + OJ[kprev]] = m->P[q];
            have[CI[ka] + OI[s] + OI[kprev]][CJ[ka] + OJ[s] + OJ[kprev]] = true;
        }
    }
    /* ghosts across sharp sides, edge rows first, then the corners */
    if (sharp[3]) for (int j = 1; j <= 2; j++) G[0][j] = mirror(G[1][j], G[2][j]);
    if (sharp[1]) for (int j = 1; j <= 2; j++) G[3][j] = mirror(G[2][j], G[1][j]);
    if (sharp[0]) for (int i = 1; i <= 2; i++) G[i][0] = mirror(G[i][1], G[i][2]);
    if (sharp[2]) for (int i = 1; i <= 2; i++) G[i][3] = mirror(G[i][2], G[i][1]);
    if (sharp[0] || sharp[3])
        G[0][0] = sharp[0] ? mirror(G[0][1], G[0][2]) : mirror(G[1][0], G[2][0]);
    if (sharp[0] || sharp[1])
        G[3][0] = sharp[0] ? mirror(G[3][1], G[3][2]) : mirror(G[2][0], G[1][0]);
    if (sharp[1] || sharp[2])
        G[3][3] = sharp[2] ? mirror(G[3][2], G[3][1]) : mirror(G[2][3], G[1][3]);
    if (sharp[2] || sharp[3])
        G[0][3] = sharp[2] ? mirror(G[0][2], G[0][1]) : mirror(G[1][3], G[2][3]);
    (void)have;
    /* B-spline -> Bezier, rows (u) then columns (v) */
    vec3 H[4][4];
    for (int j = 0; j < 4; j++) {
        vec3 p0 = G[0][j], p1 = G[1][j], p2 = G[2][j], p3 = G[3][j];
        H[0][j] = v3_scale(v3_add(v3_add(p0, v3_scale(p1, 4)), p2), 1.0 / 6);
        H[1][j] = v3_scale(v3_add(v3_scale(p1, 2), p2), 1.0 / 3);
        H[2][j] = v3_scale(v3_add(p1, v3_scale(p2, 2)), 1.0 / 3);
        H[3][j] = v3_scale(v3_add(v3_add(p1, v3_scale(p2, 4)), p3), 1.0 / 6);
    }
    for (int i = 0; i < 4; i++) {
        vec3 p0 = H[i][0], p1 = H[i][1], p2 = H[i][2], p3 = H[i][3];
        net[4 * 0 + i] = v3_scale(v3_add(v3_add(p0, v3_scale(p1, 4)), p2), 1.0 / 6);
        net[4 * 1 + i] = v3_scale(v3_add(v3_scale(p1, 2), p2), 1.0 / 3);
        net[4 * 2 + i] = v3_scale(v3_add(p1, v3_scale(p2, 2)), 1.0 / 3);
        net[4 * 3 + i] = v3_scale(v3_add(v3_add(p1, v3_scale(p2, 4)), p3), 1.0 / 6);
    }
    return true;
}

bool sd_regular_net(const sd_mesh *m, vec3 net[16]) { return face_net(m, true, net); }

void sd_known_regular_net(const sd_mesh *m, vec3 net[16])
{
    bool made = face_net(m, false, net);
    assert(made && "a face flagged regular has its net");
    (void)made;
}

/* The limit mask of point v given its ring (sd_corner_limit). */
static bool corner_mask(const sd_mesh *m, int v, const vring *r, vec3 *out)
{
    if (!r->ok) return false;
    vec3 S = m->P[v];
    if (isinf(m->vs[v]) || r->ninf > 2) {
        *out = S;
        return true;
    }
    if (r->ninf == 2) {
        vec3 e = v3(0, 0, 0);
        for (int i = 0; i < r->nedges; i++)
            if (isinf(edge_sharp(m, v, r->other[i]))) e = v3_add(e, m->P[r->other[i]]);
        *out = v3_scale(v3_add(e, v3_scale(S, 4)), 1.0 / 6);
        return true;
    }
    if (r->nfaces != r->nedges) return false;      /* an open ring: no mask */
    int n = r->nedges;
    vec3 E = v3(0, 0, 0), F = v3(0, 0, 0);
    for (int i = 0; i < n; i++) E = v3_add(E, m->P[r->other[i]]);
    for (int f = 0; f < m->nf; f++)
        for (int c = m->fo[f]; c < m->fo[f + 1]; c++)
            if (m->fv[c] == v && m->fo[f + 1] - m->fo[f] == 4)
                F = v3_add(F, m->P[m->fv[next_of(m, f, next_of(m, f, c))]]);
    *out = v3_scale(v3_add(v3_add(v3_scale(S, (double)n * n), v3_scale(E, 4)), F),
                    1.0 / (n * (n + 5.0)));
    return true;
}

bool sd_corner_limit(const sd_mesh *m, int k, vec3 *out)
{
    int v = m->fv[m->fo[0] + k];
    vring r;
    ring_of(m, v, &r);
    bool ok = corner_mask(m, v, &r, out);
    ring_clear(&r);
    return ok;
}
