/*
 * surface_polygon.c: convex planar polygons as parametric surfaces.
 *
 * RenderMan's Polygon (RI spec §5.1) has no (u,v) of its own; we give it
 * one so that the same box machinery (Heidrich & Seidel §3) refines it:
 * P(u,v) = origin + u*axis_u + v*axis_v over [0,1]^2, the smallest
 * rectangle in the polygon's plane that holds it. axis_u x axis_v points
 * along Newell's normal of the vertex order, so the vertices run counter-
 * clockwise in (u,v). Only part of the rectangle is polygon:
 * geom_uv_inside and geom_uv_box_cover say which.
 *
 * The rectangle's orientation is the minimum-area one; for a convex polygon
 * one of its sides lies along a polygon edge (Freeman & Shapira 1975), so
 * trying every edge direction finds it. Small polygons (<= 64 vertices)
 * make the O(n^2) search cheap, and it runs once per surface.
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "util/err.h"

#include <math.h>

/* (u,v) distance by which a point may lie outside an edge and still count
 * as inside: keeps neighbouring polygons that share an edge crack-free. */
#define UV_TOL 1e-12

/* Relative tolerances of the checks in prepare. */
#define PLANAR_TOL 1e-6
#define CONVEX_TOL 1e-9

typedef struct poly_work {
    int n;                                  /* distinct vertices */
    int index[GEOM_MAX_POLY_VERTS];         /* their index in s->verts */
    vec3 p[GEOM_MAX_POLY_VERTS];
    double size;                            /* largest extent of the vertices */
} poly_work;

static bool check_vertices(const geom_surface *s, char *err, size_t errsz)
{
    if (s->nverts < 3 || s->nverts > GEOM_MAX_POLY_VERTS)
        return err_set(err, errsz, "polygon needs 3 to %d vertices, got %d",
                         GEOM_MAX_POLY_VERTS, s->nverts);
    for (int i = 0; i < s->nverts; i++) {
        vec3 p = s->verts[i];
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return err_set(err, errsz, "polygon vertex %d must be finite numbers, got (%g %g %g)",
                             i, p.x, p.y, p.z);
    }
    return true;
}

/* v3_length(p - q) <= same, its root taken only when the squared length
 * is not clearly over (far: 4 same^2, a margin far beyond the roundings
 * of both, an underflowing same^2 included; NaN takes the root) */
static bool within(vec3 p, vec3 q, double same, double far)
{
    vec3 d = v3_sub(p, q);
    double d2 = v3_dot(d, d);
    return d2 > far ? false : sqrt(d2) <= same;
}

/* Drops repeated consecutive vertices (and a last one equal to the first). */
static bool distinct_vertices(const geom_surface *s, poly_work *w, char *err, size_t errsz)
{
    vec3 lo = s->verts[0], hi = s->verts[0];
    for (int i = 1; i < s->nverts; i++) {
        vec3 p = s->verts[i];
        lo = v3(geom_min(lo.x, p.x), geom_min(lo.y, p.y), geom_min(lo.z, p.z));
        hi = v3(geom_max(hi.x, p.x), geom_max(hi.y, p.y), geom_max(hi.z, p.z));
    }
    vec3 ext = v3_sub(hi, lo);
    w->size = geom_max(ext.x, geom_max(ext.y, ext.z));
    if (!isfinite(w->size))
        return err_set(err, errsz, "polygon vertices are too large");
    double same = 1e-12 * w->size, far = 4 * same * same;
    w->n = 0;
    for (int i = 0; i < s->nverts; i++) {
        vec3 p = s->verts[i];
        if (w->n > 0 && within(p, w->p[w->n - 1], same, far))
            continue;
        if (i == s->nverts - 1 && w->n > 0 && within(p, w->p[0], same, far))
            continue;
        w->index[w->n] = i;
        w->p[w->n++] = p;
    }
    if (w->n < 3)
        return err_set(err, errsz, "polygon needs at least 3 distinct vertices, got %d", w->n);
    return true;
}

/* Newell's normal: twice the vector area of the vertex loop. */
static vec3 newell_normal(const poly_work *w)
{
    vec3 nn = v3(0, 0, 0);
    for (int i = 0; i < w->n; i++) {
        vec3 a = w->p[i], b = w->p[(i + 1) % w->n];
        nn.x += (a.y - b.y) * (a.z + b.z);
        nn.y += (a.z - b.z) * (a.x + b.x);
        nn.z += (a.x - b.x) * (a.y + b.y);
    }
    return nn;
}

static vec3 centroid(const poly_work *w)
{
    vec3 c = v3(0, 0, 0);
    for (int i = 0; i < w->n; i++)
        c = v3_add(c, w->p[i]);
    return v3_scale(c, 1.0 / w->n);
}

/* Extents along e1 and e2 of the vertices' offsets r[0..n) from the
 * centroid. */
static inline void extents(const vec3 *r, int n, vec3 e1, vec3 e2, double *a0, double *a1,
                           double *b0, double *b1)
{
    *a0 = *b0 = INFINITY;
    *a1 = *b1 = -INFINITY;
    for (int i = 0; i < n; i++) {
        double a = v3_dot(r[i], e1), b = v3_dot(r[i], e2);
        *a0 = geom_min(*a0, a); *a1 = geom_max(*a1, a);
        *b0 = geom_min(*b0, b); *b1 = geom_max(*b1, b);
    }
}

/* The in-plane direction of the minimum-area bounding rectangle, and the
 * vertices' extents along it and nrm x it (ext: a0 a1 b0 b1; those of the
 * zero direction when no edge has one, as extents() gives them); r: the
 * vertices' offsets from the centroid. The edges' directions are made
 * first, all of them (their roots and divisions independent of one
 * another, so they overlap), then tried in order. */
static vec3 best_axis(const poly_work *w, const vec3 *r, vec3 nrm, double ext[4])
{
    vec3 best = v3(0, 0, 0), dir[GEOM_MAX_POLY_VERTS];
    for (int i = 0; i < w->n; i++) {
        vec3 e = v3_sub(w->p[(i + 1) % w->n], w->p[i]);
        dir[i] = v3_normalize(v3_sub(e, v3_scale(nrm, v3_dot(nrm, e))));
    }
    double best_area = INFINITY;
    bool found = false;
    for (int i = 0; i < w->n; i++) {
        vec3 e = dir[i];
        if (v3_dot(e, e) == 0)          /* v3_length(e) == 0, without the root */
            continue;
        double a0, a1, b0, b1;
        extents(r, w->n, e, v3_cross(nrm, e), &a0, &a1, &b0, &b1);
        double area = (a1 - a0) * (b1 - b0);
        if (area < best_area * (1 - 1e-12)) {
            best_area = area;
            best = e;
            ext[0] = a0, ext[1] = a1, ext[2] = b0, ext[3] = b1;
            found = true;
        }
    }
    if (!found)
        extents(r, w->n, best, v3_cross(nrm, best), &ext[0], &ext[1], &ext[2], &ext[3]);
    return best;
}

/* Edge i as a*u + b*v + c >= 0 inside, (a,b) of unit length. */
static void edge_lines(geom_surface *s)
{
    for (int i = 0; i < s->nuv; i++) {
        const double *p = s->uv[i], *q = s->uv[(i + 1) % s->nuv];
        double dx = q[0] - p[0], dy = q[1] - p[1], len = hypot(dx, dy);
        if (len == 0)
            len = 1;
        s->edge[i][0] = -dy / len;
        s->edge[i][1] = dx / len;
        s->edge[i][2] = (dy * p[0] - dx * p[1]) / len;
    }
}

static double edge_eval(const geom_surface *s, int i, double u, double v)
{
    return s->edge[i][0] * u + s->edge[i][1] * v + s->edge[i][2];
}

/* Convex: every vertex turns left (counter-clockwise in (u,v)), and, so
 * that stars whose every turn is a left one are caught too, every vertex
 * lies inside every edge. */
static bool check_convex(const geom_surface *s, const poly_work *w, char *err, size_t errsz)
{
    for (int i = 0; i < s->nuv; i++) {
        int prev = (i + s->nuv - 1) % s->nuv, next = (i + 1) % s->nuv;
        if (edge_eval(s, prev, s->uv[next][0], s->uv[next][1]) < -CONVEX_TOL)
            return err_set(err, errsz, "polygon is not convex: it turns the other way at vertex %d",
                             w->index[i]);
    }
    for (int i = 0; i < s->nuv; i++)
        for (int j = 0; j < s->nuv; j++)
            if (edge_eval(s, i, s->uv[j][0], s->uv[j][1]) < -CONVEX_TOL)
                return err_set(err, errsz,
                                 "polygon is not convex: its edges cross (vertex %d lies "
                                 "outside the edge from vertex %d to vertex %d)",
                                 w->index[j], w->index[i], w->index[(i + 1) % w->n]);
    return true;
}

static bool check_planar(const poly_work *w, vec3 nrm, vec3 c, char *err, size_t errsz)
{
    for (int i = 0; i < w->n; i++) {
        double off = fabs(v3_dot(nrm, v3_sub(w->p[i], c)));
        if (off > PLANAR_TOL * w->size)
            return err_set(err, errsz, "polygon is not planar: vertex %d lies %g off its plane",
                             w->index[i], off);
    }
    return true;
}

/* ia_mul(ia_point(a), ia_point(b)), the same bits */
static ia_interval point_product(double a, double b)
{
    ia_interval r;
    return geom_point_product(a, b, &r) ? r : ia_mul(ia_point(a), ia_point(b));
}

/* The plane basis and the vertices' (u,v). */
static void plane_basis(geom_surface *s, const poly_work *w, vec3 nrm, vec3 c)
{
    double ext[4] = {0, 0, 0, 0};
    vec3 r[GEOM_MAX_POLY_VERTS];
    for (int i = 0; i < w->n; i++) r[i] = v3_sub(w->p[i], c);
    vec3 e1 = best_axis(w, r, nrm, ext), e2 = v3_cross(nrm, e1);
    double a0 = ext[0], a1 = ext[1], b0 = ext[2], b1 = ext[3];
    s->normal = nrm;
    s->origin = v3_add(c, v3_add(v3_scale(e1, a0), v3_scale(e2, b0)));
    s->axis_u = v3_scale(e1, a1 - a0);
    s->axis_v = v3_scale(e2, b1 - b0);
    s->nuv = w->n;
    for (int i = 0; i < w->n; i++) {
        s->uv[i][0] = (v3_dot(r[i], e1) - a0) / (a1 - a0);
        s->uv[i][1] = (v3_dot(r[i], e2) - b0) / (b1 - b0);
    }
}

/* The enclosures of Ng, from the basis. */
static void ng_consts(geom_surface *s)
{
    double au[3] = {s->axis_u.x, s->axis_u.y, s->axis_u.z};
    double av[3] = {s->axis_v.x, s->axis_v.y, s->axis_v.z};
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        s->consts[K_NG + k] = ia_sub(point_product(au[i], av[j]), point_product(au[j], av[i]));
    }
}

/* The distinct vertices, the unit normal and the centroid of polygon s */
static bool plane_of(const geom_surface *s, poly_work *w, vec3 *nrm, vec3 *c, char *err,
                     size_t errsz)
{
    if (!check_vertices(s, err, errsz) || !distinct_vertices(s, w, err, errsz))
        return false;
    vec3 nn = newell_normal(w);
    double len = v3_length(nn);
    if (!(len > 1e-12 * w->size * w->size))
        return err_set(err, errsz, "polygon has no area: its vertices lie on one line");
    *nrm = v3_scale(nn, 1.0 / len);
    *c = centroid(w);
    return true;
}

/* geom_polygon_prepare but the enclosures of Ng and the corner normals */
static bool polygon_checked(geom_surface *s, char *err, size_t errsz)
{
    poly_work w;
    vec3 nrm, c;
    if (!plane_of(s, &w, &nrm, &c, err, errsz) || !check_planar(&w, nrm, c, err, errsz))
        return false;
    plane_basis(s, &w, nrm, c);
    edge_lines(s);
    return check_convex(s, &w, err, errsz);
}

bool geom_polygon_prepare(geom_surface *s, char *err, size_t errsz)
{
    if (!polygon_checked(s, err, errsz))
        return false;
    ng_consts(s);
    return geom_vertex_normal_prepare(s, err, errsz);
}

bool geom_polygon_check(geom_surface *s, char *err, size_t errsz)
{
    if (s->kind != GEOM_POLYGON || s->nvn != 0)
        return err_set(err, errsz, "geom_polygon_check: not a polygon without corner normals");
    return polygon_checked(s, err, errsz);
}

bool geom_polygon_basis(geom_surface *s, char *err, size_t errsz)
{
    poly_work w;
    vec3 nrm, c;
    if (s->kind != GEOM_POLYGON)
        return err_set(err, errsz, "geom_polygon_basis: not a polygon");
    if (!plane_of(s, &w, &nrm, &c, err, errsz))
        return false;
    plane_basis(s, &w, nrm, c);
    return true;
}

/* ---------------------------------------------------------------------- */
/* (u,v) coverage                                                          */
/* ---------------------------------------------------------------------- */

bool geom_uv_inside(const geom_surface *s, double u, double v)
{
    if (s->kind != GEOM_POLYGON)
        return true;
    for (int i = 0; i < s->nuv; i++)
        if (edge_eval(s, i, u, v) < -UV_TOL)
            return false;
    return true;
}

/* Separating axes (polygon and box are both convex): the box is outside when
 * one edge has all four corners beyond it, or the box misses the polygon's
 * (u,v) extent; inside when all four corners are inside (the inside set,
 * tolerance included, is convex). Otherwise partial, which is also the
 * safe answer. */
bool geom_uv_box_clear_of(const geom_surface *s, double u0, double u1, double v0, double v1,
                          uint64_t edges)
{
    if (s->kind != GEOM_POLYGON)
        return true;
    double uc = 0.5 * (u0 + u1), vc = 0.5 * (v0 + v1);
    double hu = 0.5 * (u1 - u0), hv = 0.5 * (v1 - v0);
    for (int i = 0; i < s->nuv; i++) {
        if (!((edges >> i) & 1))
            continue;
        double r = fabs(s->edge[i][0]) * hu + fabs(s->edge[i][1]) * hv;
        if (!(edge_eval(s, i, uc, vc) - r > 2 * UV_TOL))
            return false;
    }
    return true;
}

bool geom_uv_beyond(const geom_surface *s, double u, double v, uint64_t edges)
{
    if (s->kind != GEOM_POLYGON)
        return false;
    for (int i = 0; i < s->nuv; i++)
        if (((edges >> i) & 1) && edge_eval(s, i, u, v) < -UV_TOL)
            return true;
    return false;
}

vec3 geom_polygon_corner(const geom_surface *s, int i)
{
    const double *p = s->uv[i];
    return v3_add(s->origin, v3_add(v3_scale(s->axis_u, p[0]), v3_scale(s->axis_v, p[1])));
}

void geom_polygon_edge(const geom_surface *s, int i, vec3 *a, vec3 *b)
{
    *a = geom_polygon_corner(s, i);
    *b = geom_polygon_corner(s, (i + 1) % s->nuv);
}

geom_cover geom_uv_box_cover(const geom_surface *s, double u0, double u1,
                             double v0, double v1)
{
    if (s->kind != GEOM_POLYGON)
        return GEOM_INSIDE;
    const double margin = 1e-9;
    if (u1 < -margin || u0 > 1 + margin || v1 < -margin || v0 > 1 + margin)
        return GEOM_OUTSIDE;
    /* An edge function e = a u + b v + c is largest and smallest over the
     * box at the corners: e(centre) +- (|a| hu + |b| hv). One evaluation per
     * edge (this runs for every child of every node visited); its rounding
     * (a few ulps of values of order 1) is far inside the UV_TOL margins. */
    double uc = 0.5 * (u0 + u1), vc = 0.5 * (v0 + v1);
    double hu = 0.5 * (u1 - u0), hv = 0.5 * (v1 - v0);
    bool all_in = true;
    for (int i = 0; i < s->nuv; i++) {
        double ec = edge_eval(s, i, uc, vc);
        double r = fabs(s->edge[i][0]) * hu + fabs(s->edge[i][1]) * hv;
        if (ec + r < -2 * UV_TOL)          /* margins: rounding inside the box */
            return GEOM_OUTSIDE;
        if (ec - r < -0.5 * UV_TOL)
            all_in = false;
    }
    return all_in ? GEOM_INSIDE : GEOM_PARTIAL;
}
