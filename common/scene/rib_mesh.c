/*
 * rib_mesh.c: polygon meshes (RI Specification 3.2 §5.1): PointsPolygons
 * (convex faces sharing points), PointsGeneralPolygons (faces that may
 * be concave and hold holes: loops of points, the outer one first) and
 * GeneralPolygon (one such face with its own points).
 *
 * Each face becomes base surfaces of common/geom: a convex planar face is
 * one GEOM_POLYGON (its parametrisation is the polygon's own, docs/
 * geometry.md); a concave, holed or non-planar face, or one with more than
 * GEOM_MAX_POLY_VERTS points, is cut into triangles (geom/triangulate.h),
 * each a GEOM_POLYGON. Faces without area are skipped, with one warning
 * per request. Only "P" is used: other primitive variables ("N", "st",
 * "Cs", ...) are read and checked like any parameter, then ignored with
 * one warning per scene.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"

#ifdef SCENE_HAVE_GEOM
#include "geom/triangulate.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { RIB_MAX_FACE_POINTS = 10000 };

/* The integers of a numeric argument (an array of whole numbers >= min);
 * NULL with an error naming `what`. The caller frees. */
static int *read_ints(rib_parser *p, const rib_request *req, int i, int min, int *count,
                      const char *what)
{
    if (i >= req->nargs || !rib_arg_is_numeric(&req->args[i])) {
        rib_error(p, req, i < req->nargs ? req->args[i].pos : req->pos,
                  "missing %s (an array of whole numbers)", what);
        return NULL;
    }
    int n;
    const double *v = rib_arg_numbers(req, &req->args[i], &n);
    if (n == 0) {
        rib_error(p, req, req->args[i].pos, "%s is empty", what);
        return NULL;
    }
    int *out = sl_xrealloc(NULL, (size_t)n * sizeof *out);
    for (int k = 0; k < n; k++) {
        if (!(v[k] == floor(v[k]) && v[k] >= min && v[k] <= 1e9)) {
            rib_error(p, req, req->args[i].pos, "%s: entry %d is %g, expected a whole number "
                      ">= %d", what, k, v[k], min);
            free(out);
            return NULL;
        }
        out[k] = (int)v[k];
    }
    *count = n;
    return out;
}

static long sum(const int *v, int n)
{
    long s = 0;
    for (int i = 0; i < n; i++)
        s += v[i];
    return s;
}

/* A mesh being cut into surfaces. */
typedef struct mesh {
    const rib_request *req;
    const double *P;               /* npoints * 3 */
    int npoints;
    int skipped;                   /* faces without area */
    sl_pos vertices_pos;
} mesh;

static void warn_ignored(rib_parser *p, const rib_request *req, const rib_params *params)
{
    if (p->warned_mesh_vars)
        return;
    char names[512] = "";
    for (int i = 0; i < params->count; i++) {
        if (strcmp(params->items[i].name, "P") == 0)
            continue;
        size_t used = strlen(names);
        snprintf(names + used, sizeof names - used, "%s\"%s\"", used ? ", " : "",
                 params->items[i].name);
    }
    if (!names[0])
        return;
    rib_warning(p, req, req->pos, "only \"P\" is used on meshes: %s ignored (and on the "
                "meshes that follow)", names);
    p->warned_mesh_vars = true;
}

static vec3 point(const mesh *m, int i)
{
    return v3(m->P[3 * i], m->P[3 * i + 1], m->P[3 * i + 2]);
}

/* Adds triangle (a, b, c) of points pts; false when it has no area. */
static bool add_triangle(rib_parser *p, const mesh *m, vec3 a, vec3 b, vec3 c)
{
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_POLYGON;
    s.nverts = 3;
    s.verts[0] = a, s.verts[1] = b, s.verts[2] = c;
#ifdef SCENE_HAVE_GEOM
    char why[256];
    if (!geom_surface_prepare(&s, why, sizeof why))
        return false;
#endif
    rib_add_surface(p, m->req, &s);
    return true;
}

/* One face: loops[0..nloops) of point indices idx (outer loop first). */
static bool add_face(rib_parser *p, mesh *m, int face, const int *loop_sizes, int nloops,
                     const int *idx)
{
    int total = (int)sum(loop_sizes, nloops);
    if (nloops == 1 && total <= GEOM_MAX_POLY_VERTS) {
        geom_surface s;
        memset(&s, 0, sizeof s);
        s.kind = GEOM_POLYGON;
        s.nverts = total;
        for (int i = 0; i < total; i++)
            s.verts[i] = point(m, idx[i]);
#ifdef SCENE_HAVE_GEOM
        char why[256];
        if (geom_surface_prepare(&s, why, sizeof why)) {
            rib_add_surface(p, m->req, &s);
            return true;
        }
#else
        rib_add_surface(p, m->req, &s);
        return true;
#endif
    }
#ifdef SCENE_HAVE_GEOM
    if (total > RIB_MAX_FACE_POINTS) {      /* cutting is quadratic in them */
        rib_error(p, m->req, m->vertices_pos, "face %d has %d points; faces to be cut into "
                  "triangles may have at most %d", face, total, RIB_MAX_FACE_POINTS);
        return false;
    }
    vec3 *pts = sl_xrealloc(NULL, (size_t)total * sizeof *pts);
    for (int i = 0; i < total; i++)
        pts[i] = point(m, idx[i]);
    int max = total + 2 * nloops;
    int (*tris)[3] = sl_xrealloc(NULL, (size_t)max * sizeof *tris);
    char why[256];
    int n = geom_triangulate(pts, loop_sizes, nloops, tris, max, why, sizeof why);
    bool ok = true;
    if (n < 0 && strcmp(why, "the polygon has no area") == 0) {
        m->skipped++;
    } else if (n < 0) {
        rib_error(p, m->req, m->vertices_pos, "face %d: %s", face, why);
        ok = false;
    } else {
        int added = 0;
        for (int t = 0; t < n; t++)
            added += add_triangle(p, m, pts[tris[t][0]], pts[tris[t][1]], pts[tris[t][2]]);
        if (added == 0)
            m->skipped++;
    }
    free(pts);
    free(tris);
    return ok;
#else
    (void)face;
    m->skipped++;
    return true;
#endif
}

/* The shared part of both requests: nloops per face (NULL: one loop per
 * face), nverts per loop, the vertex indices, then the parameters. */
static void read_mesh(rib_parser *p, const rib_request *req, const int *nloops, int nfaces,
                      const int *nverts, int nnverts, int first_vertices)
{
    int nidx;
    int *idx = read_ints(p, req, first_vertices, 0, &nidx, "the vertex indices");
    if (!idx)
        return;
    rib_params params = { 0 };
    if (sum(nverts, nnverts) != nidx) {
        rib_error(p, req, req->args[first_vertices].pos, "the loops have %ld points in all, "
                  "but %d vertex indices are given", sum(nverts, nnverts), nidx);
        goto out;
    }
    if (!rib_params_read(p, req, first_vertices + 1, RIB_PARAMS_VARYING, &params))
        goto out;
    const scene_param *P = rib_params_find(&params, "P");
    if (!P) {
        rib_error(p, req, req->pos, "missing the points: add \"P\" [x y z x y z ...]");
        goto out;
    }
    if (P->type != SL_TYPE_POINT) {
        rib_error(p, req, P->pos, "\"P\" must be declared as a point, not a %s",
                  rib_type_name(P->type));
        goto out;
    }
    int maxidx = 0;
    for (int i = 0; i < nidx; i++)
        maxidx = idx[i] > maxidx ? idx[i] : maxidx;
    if (P->count / 3 <= maxidx) {
        rib_error(p, req, P->pos, "\"P\" has %d points, but the vertex indices go up to %d",
                  P->count / 3, maxidx);
        goto out;
    }
    warn_ignored(p, req, &params);
    mesh m = { req, P->values, P->count / 3, 0, req->args[first_vertices].pos };
    const int *loop = nverts, *vi = idx;
    for (int f = 0; f < nfaces && !sl_diag_full(p->diag); f++) {
        int nl = nloops ? nloops[f] : 1;
        int npts = (int)sum(loop, nl);
        add_face(p, &m, f, loop, nl, vi);
        loop += nl;
        vi += npts;
    }
    if (m.skipped > 0)
        rib_warning(p, req, req->pos, "%d face%s without area skipped", m.skipped,
                    m.skipped == 1 ? "" : "s");
out:
    rib_params_free(&params);
    free(idx);
}

void rib_points_polygons(rib_parser *p, const rib_request *req)
{
    int nfaces;
    int *nverts = read_ints(p, req, 0, 3, &nfaces, "the vertex counts (nvertices)");
    if (!nverts)
        return;
    read_mesh(p, req, NULL, nfaces, nverts, nfaces, 1);
    free(nverts);
}

/* GeneralPolygon nvertices "P" [...]: one face, its loops' points in
 * order. */
void rib_general_polygon(rib_parser *p, const rib_request *req)
{
    int nloops;
    int *nverts = read_ints(p, req, 0, 3, &nloops, "the vertex counts (nvertices)");
    if (!nverts)
        return;
    rib_params params;
    if (rib_params_read(p, req, 1, RIB_PARAMS_VARYING, &params)) {
        const scene_param *P = rib_params_find(&params, "P");
        long n = sum(nverts, nloops);
        if (!P)
            rib_error(p, req, req->pos, "missing the points: add \"P\" [x y z x y z ...]");
        else if (P->type != SL_TYPE_POINT)
            rib_error(p, req, P->pos, "\"P\" must be declared as a point, not a %s",
                      rib_type_name(P->type));
        else if (P->count / 3 != n)
            rib_error(p, req, P->pos, "the loops have %ld points in all, but \"P\" has %d",
                      n, P->count / 3);
        else {
            warn_ignored(p, req, &params);
            int *idx = sl_xrealloc(NULL, (size_t)n * sizeof *idx);
            for (int i = 0; i < n; i++)
                idx[i] = i;
            mesh m = { req, P->values, (int)n, 0, req->args[0].pos };
            add_face(p, &m, 0, nverts, nloops, idx);
            if (m.skipped)
                rib_warning(p, req, req->pos, "the polygon has no area: skipped");
            free(idx);
        }
        rib_params_free(&params);
    }
    free(nverts);
}

void rib_points_general_polygons(rib_parser *p, const rib_request *req)
{
    int nfaces, nnverts;
    int *nloops = read_ints(p, req, 0, 1, &nfaces, "the loop counts (nloops)");
    if (!nloops)
        return;
    int *nverts = read_ints(p, req, 1, 3, &nnverts, "the vertex counts (nvertices)");
    if (nverts && sum(nloops, nfaces) != nnverts)
        rib_error(p, req, req->args[1].pos, "the faces have %ld loops in all, but %d vertex "
                  "counts are given", sum(nloops, nfaces), nnverts);
    else if (nverts)
        read_mesh(p, req, nloops, nfaces, nverts, nnverts, 2);
    free(nloops);
    free(nverts);
}
