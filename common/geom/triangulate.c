/*
 * triangulate.c: polygons with holes cut into triangles (see
 * triangulate.h): projection to the dominant plane, hole bridges, ear
 * clipping. O(n^2) in the points of one face, which is small.
 */
#include "geom/triangulate.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct pt2 { double x, y; } pt2;

static double cross3(pt2 a, pt2 b, pt2 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static double loop_area(const pt2 *p, const int *idx, int n)
{
    double a = 0;
    for (int i = 0; i < n; i++) {
        pt2 u = p[idx[i]], v = p[idx[(i + 1) % n]];
        a += u.x * v.y - v.x * u.y;
    }
    return a / 2;
}

/* Whether segments ab and cd cross properly (touching ends excluded). */
static bool segments_cross(pt2 a, pt2 b, pt2 c, pt2 d)
{
    double d1 = cross3(a, b, c), d2 = cross3(a, b, d);
    double d3 = cross3(c, d, a), d4 = cross3(c, d, b);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) &&
           ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

static bool same(pt2 a, pt2 b) { return a.x == b.x && a.y == b.y; }

/* Whether segment a-b crosses an edge of loop idx[0..n) (cyclic). */
static bool crosses_loop(const pt2 *p, pt2 a, pt2 b, const int *idx, int n)
{
    for (int i = 0; i < n; i++) {
        pt2 c = p[idx[i]], d = p[idx[(i + 1) % n]];
        if (same(c, a) || same(c, b) || same(d, a) || same(d, b))
            continue;
        if (segments_cross(a, b, c, d))
            return true;
    }
    return false;
}

/* Inside triangle abc (counter-clockwise) or on its edges: a vertex on
 * the cut edge ca would be cut off too. */
static bool inside_triangle(pt2 q, pt2 a, pt2 b, pt2 c)
{
    return cross3(a, b, q) >= 0 && cross3(b, c, q) >= 0 && cross3(c, a, q) >= 0;
}

/* Whether q lies in the interior angle of the ring at its r-th corner
 * (the ring counter-clockwise): where a bridge from that corner may go.
 * A point repeated by an earlier bridge has one corner per copy, and only
 * one of them faces q. */
static bool in_wedge(const pt2 *p, const int *ring, int n, int r, pt2 q)
{
    pt2 a = p[ring[(r + n - 1) % n]], v = p[ring[r]], c = p[ring[(r + 1) % n]];
    bool left_in = cross3(a, v, q) >= 0, left_out = cross3(v, c, q) >= 0;
    return cross3(a, v, c) >= 0 ? left_in && left_out : left_in || left_out;
}

int geom_triangulate(const vec3 *pts, const int *loop_sizes, int nloops, int (*tris)[3],
                     int max_tris, char *err, size_t errsz)
{
    if (nloops < 1) {
        err_set(err, errsz, "no loops");
        return -1;
    }
    int total = 0;
    for (int l = 0; l < nloops; l++) {
        if (loop_sizes[l] < 3) {
            err_set(err, errsz, "loop %d has %d points, at least 3 are needed",
                     l, loop_sizes[l]);
            return -1;
        }
        total += loop_sizes[l];
    }
    /* Newell normal of the outer loop: the plane to project to */
    vec3 nrm = v3(0, 0, 0);
    for (int i = 0; i < loop_sizes[0]; i++) {
        vec3 a = pts[i], b = pts[(i + 1) % loop_sizes[0]];
        nrm.x += (a.y - b.y) * (a.z + b.z);
        nrm.y += (a.z - b.z) * (a.x + b.x);
        nrm.z += (a.x - b.x) * (a.y + b.y);
    }
    double ax = fabs(nrm.x), ay = fabs(nrm.y), az = fabs(nrm.z);
    if (!(ax + ay + az > 0)) {
        err_set(err, errsz, "the polygon has no area");
        return -1;
    }
    pt2 *p = xmalloc((size_t)total * sizeof *p);
    /* the combined loop: the outer loop plus, per hole, its points and two
     * bridge ends, repeated */
    int cap = total + 2 * nloops + 2;
    int *ring = xmalloc((size_t)cap * sizeof *ring);
    int *tmp = xmalloc((size_t)cap * sizeof *tmp);
    int *hole = xmalloc((size_t)total * sizeof *hole);
    for (int i = 0; i < total; i++) {
        vec3 q = pts[i];
        if (az >= ax && az >= ay) p[i] = (pt2){ q.x, q.y };
        else if (ax >= ay)        p[i] = (pt2){ q.y, q.z };
        else                      p[i] = (pt2){ q.z, q.x };
    }
    /* corners with less area than this count as straight (slivers are
     * dropped, not emitted: a surface needs a normal) */
    double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
    for (int i = 0; i < total; i++) {
        lo[0] = fmin(lo[0], p[i].x), hi[0] = fmax(hi[0], p[i].x);
        lo[1] = fmin(lo[1], p[i].y), hi[1] = fmax(hi[1], p[i].y);
    }
    double eps = 1e-12 * ((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]));
    int n = loop_sizes[0];
    for (int i = 0; i < n; i++)
        ring[i] = i;
    double outer = loop_area(p, ring, n);
    bool flipped = outer < 0;       /* work counter-clockwise */
    int count = -1;
    if (!(fabs(outer) > eps)) {
        err_set(err, errsz, "the polygon has no area");
        goto done;
    }
    if (flipped)
        for (int i = 0; i < n / 2; i++) {
            int t = ring[i]; ring[i] = ring[n - 1 - i]; ring[n - 1 - i] = t;
        }
    /* bridge each hole (clockwise) to the nearest ring vertex it sees */
    int first = loop_sizes[0];
    for (int l = 1; l < nloops; l++) {
        int m = loop_sizes[l];
        for (int i = 0; i < m; i++)
            hole[i] = first + i;
        if (loop_area(p, hole, m) > 0)
            for (int i = 0; i < m / 2; i++) {
                int t = hole[i]; hole[i] = hole[m - 1 - i]; hole[m - 1 - i] = t;
            }
        int best_h = -1, best_r = -1;
        double best_d = INFINITY;
        for (int h = 0; h < m; h++)
            for (int r = 0; r < n; r++) {
                pt2 a = p[hole[h]], b = p[ring[r]];
                double d = (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y);
                if (d >= best_d || !in_wedge(p, ring, n, r, a) ||
                    crosses_loop(p, a, b, ring, n) || crosses_loop(p, a, b, hole, m))
                    continue;
                /* also no later hole in the way */
                bool blocked = false;
                int f2 = first + m;
                for (int l2 = l + 1; l2 < nloops && !blocked; l2++) {
                    int m2 = loop_sizes[l2];
                    for (int i = 0; i < m2; i++)
                        tmp[i] = f2 + i;
                    blocked = crosses_loop(p, a, b, tmp, m2);
                    f2 += m2;
                }
                if (!blocked)
                    best_d = d, best_h = h, best_r = r;
            }
        if (best_h < 0) {
            err_set(err, errsz, "hole %d cannot be joined to the boundary "
                     "(does it lie outside, or do loops cross?)", l);
            goto done;
        }
        /* ring[0..r], hole[h..h+m] (m+1 points), ring[r..n) */
        int k = 0;
        for (int i = 0; i <= best_r; i++)
            tmp[k++] = ring[i];
        for (int i = 0; i <= m; i++)
            tmp[k++] = hole[(best_h + i) % m];
        for (int i = best_r; i < n; i++)
            tmp[k++] = ring[i];
        memcpy(ring, tmp, (size_t)k * sizeof *ring);
        n = k;
        first += m;
    }
    /* ear clipping */
    count = 0;
    while (n > 3) {
        int ear = -1;
        for (int i = 0; i < n && ear < 0; i++) {
            int ia = ring[(i + n - 1) % n], ib = ring[i], ic = ring[(i + 1) % n];
            pt2 a = p[ia], b = p[ib], c = p[ic];
            if (!(cross3(a, b, c) > eps))
                continue;
            bool empty = true;
            for (int j = 0; j < n && empty; j++) {
                pt2 q = p[ring[j]];
                if (same(q, a) || same(q, b) || same(q, c))
                    continue;
                empty = !inside_triangle(q, a, b, c);
            }
            if (empty)
                ear = i;
        }
        if (ear < 0) {
            /* only degenerate corners left (collinear points): drop one
             * with no area, else the loops cross */
            for (int i = 0; i < n && ear < 0; i++)
                if (fabs(cross3(p[ring[(i + n - 1) % n]], p[ring[i]],
                                p[ring[(i + 1) % n]])) <= eps)
                    ear = i;
            if (ear < 0) {
                err_set(err, errsz, "the polygon cannot be cut into triangles "
                         "(do its edges cross?)");
                count = -1;
                goto done;
            }
            memmove(ring + ear, ring + ear + 1, (size_t)(n - ear - 1) * sizeof *ring);
            n--;
            continue;
        }
        if (count >= max_tris) {
            err_set(err, errsz, "more than %d triangles", max_tris);
            count = -1;
            goto done;
        }
        int ia = ring[(ear + n - 1) % n], ib = ring[ear], ic = ring[(ear + 1) % n];
        tris[count][0] = ia;
        tris[count][1] = flipped ? ic : ib;
        tris[count][2] = flipped ? ib : ic;
        count++;
        memmove(ring + ear, ring + ear + 1, (size_t)(n - ear - 1) * sizeof *ring);
        n--;
    }
    if (cross3(p[ring[0]], p[ring[1]], p[ring[2]]) > eps) {
        if (count >= max_tris) {
            err_set(err, errsz, "more than %d triangles", max_tris);
            count = -1;
            goto done;
        }
        tris[count][0] = ring[0];
        tris[count][1] = flipped ? ring[2] : ring[1];
        tris[count][2] = flipped ? ring[1] : ring[2];
        count++;
    }
done:
    free(p);
    free(ring);
    free(tmp);
    free(hole);
    return count;
}
