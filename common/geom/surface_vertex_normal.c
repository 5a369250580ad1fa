/*
 * surface_vertex_normal.c: the interpolated shading normal of a triangle
 * polygon that carries corner normals (a face of a mesh, common/scene/
 * rib_mesh.c), see geom_vertex_normal in surface.h.
 *
 * Heidrich & Seidel §3 displace along the surface normal; on a faceted mesh
 * the face normal jumps at every edge, so P + h N opens cracks there. With
 * corner normals shared by the faces around a vertex, the normal is
 * continuous: over a triangle with corners (u_i, v_i) in its (u,v)
 * rectangle and corner normals n_i, the barycentric interpolation is
 * linear in (u,v):
 *
 *   N(u,v) = C + u A + v B,   A = (e1 d2v - e2 d1v) / det,
 *                             B = (e2 d1u - e1 d2u) / det,
 *                             C = n0 - u0 A - v0 B,
 *
 * with d1 = uv1 - uv0, d2 = uv2 - uv0, e1 = n1 - n0, e2 = n2 - n0 and
 * det = d1 x d2 (> 0: the corners run counter-clockwise in (u,v)). The
 * double coefficients computed here DEFINE the normal (a point (u,v) of the
 * rectangle outside the triangle gets the linear extension), so the
 * interval and affine evaluations (surface_normal.c) enclose it exactly,
 * rounding included. Along an edge N depends only on that edge's two
 * corners (up to the rounding of the coefficients), so two faces sharing
 * an edge and its corner normals give the same N there.
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "util/err.h"

#include <math.h>

bool geom_vertex_normal_prepare(geom_surface *s, char *err, size_t errsz)
{
    if (s->nvn == 0)
        return true;
    if (s->nvn != 3 || s->nverts != 3 || s->nuv != 3)
        return err_set(err, errsz, "vertex normals need a triangle with 3 distinct "
                         "corners and 3 normals (got %d corners, %d normals)", s->nuv, s->nvn);
    for (int i = 0; i < 3; i++) {
        vec3 n = s->vn[i];
        if (!isfinite(n.x) || !isfinite(n.y) || !isfinite(n.z))
            return err_set(err, errsz, "vertex normal %d must be finite numbers, got "
                             "(%g %g %g)", i, n.x, n.y, n.z);
    }
    const double (*uv)[2] = (const double (*)[2])s->uv;
    double d1u = uv[1][0] - uv[0][0], d1v = uv[1][1] - uv[0][1];
    double d2u = uv[2][0] - uv[0][0], d2v = uv[2][1] - uv[0][1];
    double det = d1u * d2v - d1v * d2u;
    if (!(fabs(det) > 0))
        return err_set(err, errsz, "vertex normals: the triangle has no area in (u,v)");
    for (int i = 0; i < 3; i++) {
        double n0 = v3_comp(s->vn[0], i);
        double e1 = v3_comp(s->vn[1], i) - n0, e2 = v3_comp(s->vn[2], i) - n0;
        double a = (e1 * d2v - e2 * d1v) / det;
        double b = (e2 * d1u - e1 * d2u) / det;
        double c = n0 - uv[0][0] * a - uv[0][1] * b;
        if (!isfinite(a) || !isfinite(b) || !isfinite(c))
            return err_set(err, errsz, "vertex normals: the triangle is too thin to "
                             "interpolate them");
        s->consts[K_VNU + i] = ia_point(a);
        s->consts[K_VNV + i] = ia_point(b);
        s->consts[K_VNC + i] = ia_point(c);
    }
    return true;
}

bool geom_has_vertex_normals(const geom_surface *s)
{
    return s->kind == GEOM_POLYGON && s->nvn == 3;
}

bool geom_vertex_normal(const geom_surface *s, double u, double v, vec3 *N, vec3 *dNdu,
                        vec3 *dNdv)
{
    if (!geom_has_vertex_normals(s))
        return false;
    const ia_interval *k = s->consts;
    *N = v3(k[K_VNC].lo + u * k[K_VNU].lo + v * k[K_VNV].lo,
            k[K_VNC + 1].lo + u * k[K_VNU + 1].lo + v * k[K_VNV + 1].lo,
            k[K_VNC + 2].lo + u * k[K_VNU + 2].lo + v * k[K_VNV + 2].lo);
    *dNdu = v3(k[K_VNU].lo, k[K_VNU + 1].lo, k[K_VNU + 2].lo);
    *dNdv = v3(k[K_VNV].lo, k[K_VNV + 1].lo, k[K_VNV + 2].lo);
    return true;
}
