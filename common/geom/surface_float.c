/*
 * surface_float.c: P, dPdu, dPdv, Ng at one (u,v) in plain double
 * (geom_eval), and with the (u,v)-derivatives of Ng (geom_eval_dual), which
 * calculatenormal of a displaced point needs (Heidrich & Seidel §4.1:
 * derivatives of shader expressions by automatic differentiation start from
 * these).
 *
 * The seven quadrics are surfaces of revolution (RI spec §5.2): a profile
 * curve q(v) in the xz plane (the hyperboloid's also leaves it) turned by
 * theta = u*thetamax about z:
 *
 *     P = Rz(theta) q(v)          dPdu = thetamax (-P.y, P.x, 0)
 *     dPdv = Rz(theta) q'(v)      Ng = dPdu x dPdv = thetamax Rz(theta) n(v)
 *     n = (qx q'z, qy q'z, -(qx q'x + qy q'y))
 *     dNg/du = thetamax (-Ng.y, Ng.x, 0),  dNg/dv = thetamax Rz(theta) n'(v)
 *
 * so each kind only supplies q, q', q'' (profile_* below). Polygons are
 * planes; bilinear patches have dNg/du = dPdu x Puv, dNg/dv = Puv x dPdv
 * with Puv = P11 - P10 - P01 + P00 (Puu = Pvv = 0).
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"

#include <math.h>

typedef struct profile {
    vec3 q, q1, q2;        /* the profile curve and its first two v-derivatives */
    vec3 n, n1;            /* the normal's profile and its v-derivative */
} profile;

/* A circle of radius r about (R, 0, 0) in the xz plane, phi from pa to pb:
 * R = 0 is RenderMan's sphere, R = majorradius its torus. */
static void profile_circle(double R, double r, double pa, double pb, double v, profile *p)
{
    double dphi = pb - pa, phi = pa + v * dphi, c = cos(phi), sn = sin(phi);
    p->q = v3(R + r * c, 0, r * sn);
    p->q1 = v3(-dphi * r * sn, 0, dphi * r * c);
    p->q2 = v3(-dphi * dphi * r * c, 0, -dphi * dphi * r * sn);
}

/* r = rmax sqrt(z/zmax): r r' = dz rmax^2/(2 zmax) is constant, which keeps
 * Ng finite at the apex (z = 0) where r' is not. */
static void profile_paraboloid(const geom_surface *s, double v, profile *p)
{
    double dz = s->zmax - s->zmin, z = s->zmin + v * dz;
    double k = s->rmax * s->rmax / s->zmax, r = sqrt(z * k);
    double r1 = dz * k / (2 * r), r2 = -r1 * r1 / r;
    p->q = v3(r, 0, z);
    p->q1 = v3(r1, 0, dz);
    p->q2 = v3(r2, 0, 0);
}

static void profile_of(const geom_surface *s, double v, profile *p)
{
    switch (s->kind) {
    case GEOM_SPHERE:
        profile_circle(0, s->radius, s->phi0, s->phi1, v, p);
        break;
    case GEOM_TORUS:
        profile_circle(s->majorrad, s->minorrad, s->phimin, s->phimax, v, p);
        break;
    case GEOM_DISK:
        p->q = v3(s->radius * (1 - v), 0, s->height);
        p->q1 = v3(-s->radius, 0, 0);
        p->q2 = v3(0, 0, 0);
        break;
    case GEOM_CYLINDER:
        p->q = v3(s->radius, 0, s->zmin + v * (s->zmax - s->zmin));
        p->q1 = v3(0, 0, s->zmax - s->zmin);
        p->q2 = v3(0, 0, 0);
        break;
    case GEOM_CONE:
        p->q = v3(s->radius * (1 - v), 0, v * s->height);
        p->q1 = v3(-s->radius, 0, s->height);
        p->q2 = v3(0, 0, 0);
        break;
    case GEOM_PARABOLOID:
        profile_paraboloid(s, v, p);
        break;
    default:                                  /* GEOM_HYPERBOLOID */
        p->q1 = v3_sub(s->point2, s->point1);
        p->q = v3_add(s->point1, v3_scale(p->q1, v));
        p->q2 = v3(0, 0, 0);
        break;
    }
    vec3 q = p->q, a = p->q1, b = p->q2;
    p->n = v3(q.x * a.z, q.y * a.z, -(q.x * a.x + q.y * a.y));
    p->n1 = v3(a.x * a.z + q.x * b.z, a.y * a.z + q.y * b.z,
               -(a.x * a.x + q.x * b.x + a.y * a.y + q.y * b.y));
    if (s->kind == GEOM_PARABOLOID) {        /* r r' is constant */
        p->n.z = -(s->zmax - s->zmin) * s->rmax * s->rmax / (2 * s->zmax);
        p->n1.z = 0;
    }
}

static vec3 rotate_z(double c, double sn, vec3 a)
{
    return v3(a.x * c - a.y * sn, a.x * sn + a.y * c, a.z);
}

static void eval_revolution(const geom_surface *s, double u, double v,
                            geom_sample *out)
{
    profile p;
    profile_of(s, v, &p);
    double tm = s->thetamax, theta = u * tm, c = cos(theta), sn = sin(theta);
    out->P = rotate_z(c, sn, p.q);
    out->dPdu = v3(-tm * out->P.y, tm * out->P.x, 0);
    out->dPdv = rotate_z(c, sn, p.q1);
    out->Ng = v3_scale(rotate_z(c, sn, p.n), tm);
    out->dNgdu = v3(-tm * out->Ng.y, tm * out->Ng.x, 0);
    out->dNgdv = v3_scale(rotate_z(c, sn, p.n1), tm);
}

static void eval_polygon(const geom_surface *s, double u, double v, geom_sample *out)
{
    out->P = v3_add(s->origin, v3_add(v3_scale(s->axis_u, u), v3_scale(s->axis_v, v)));
    out->dPdu = s->axis_u;
    out->dPdv = s->axis_v;
    out->Ng = v3_cross(s->axis_u, s->axis_v);
    out->dNgdu = out->dNgdv = v3(0, 0, 0);
}

static void eval_patch(const geom_surface *s, double u, double v, geom_sample *out)
{
    const vec3 *p = s->verts;
    vec3 b = v3_sub(p[1], p[0]), c = v3_sub(p[2], p[0]);
    vec3 a = v3_add(v3_sub(p[3], p[1]), v3_sub(p[0], p[2]));
    vec3 bottom = v3_lerp(p[0], p[1], u), top = v3_lerp(p[2], p[3], u);
    out->P = v3_lerp(bottom, top, v);
    out->dPdu = v3_add(b, v3_scale(a, v));
    out->dPdv = v3_add(c, v3_scale(a, u));
    out->Ng = v3_cross(out->dPdu, out->dPdv);
    out->dNgdu = v3_cross(out->dPdu, a);
    out->dNgdv = v3_cross(a, out->dPdv);
}

void geom_eval_dual(const geom_surface *s, double u, double v, geom_sample *out)
{
    switch (s->kind) {
    case GEOM_POLYGON:
        eval_polygon(s, u, v, out);
        break;
    case GEOM_PATCH:
        eval_patch(s, u, v, out);
        break;
    case GEOM_BICUBIC:
        geom_bicubic_eval_dual(s, u, v, out);
        break;
    case GEOM_SUBDIV:
        geom_subdiv_eval_dual(s, u, v, out);
        break;
    case GEOM_NURBS:
        geom_nurbs_eval_dual(s, u, v, out);
        break;
    case GEOM_SPHERE: case GEOM_DISK: case GEOM_CYLINDER: case GEOM_CONE:
    case GEOM_PARABOLOID: case GEOM_HYPERBOLOID: case GEOM_TORUS:
        eval_revolution(s, u, v, out);
        break;
    default: {                                /* not a kind: nothing is known */
        vec3 nan3 = v3(NAN, NAN, NAN);
        out->P = out->dPdu = out->dPdv = out->Ng = out->dNgdu = out->dNgdv = nan3;
        break;
    }
    }
}

void geom_eval(const geom_surface *s, double u, double v, geom_sample *out)
{
    geom_eval_dual(s, u, v, out);
    out->dNgdu = out->dNgdv = v3(0, 0, 0);
}

vec3 geom_eval_point(const geom_surface *s, double u, double v)
{
    switch (s->kind) {
    case GEOM_BICUBIC: return geom_bicubic_eval_point(s, u, v);
    case GEOM_SUBDIV:  return geom_subdiv_eval_point(s, u, v);
    default: {
        geom_sample g;
        geom_eval(s, u, v, &g);
        return g.P;
    }
    }
}
