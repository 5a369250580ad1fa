/*
 * surface_interval.c: enclosures of P, dPdu, dPdv, Ng over a (u,v) box in
 * interval arithmetic (geom_eval_ia), the peer of the affine evaluation that
 * Heidrich & Seidel compare against in §7.1 (--arith interval).
 *
 * Every kind is written as the same expression tree as its affine twin in
 * surface_affine.c (which says why each formula is the one chosen), so the
 * two arithmetics differ only in how they bound each step. All arithmetic on
 * ranges goes through common/aa's rounding-safe ia_* operations; exact
 * derived constants (zmax - zmin, ...) come as intervals from s->consts[]
 * (surface_internal.h).
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"

typedef ia_interval ia;

static ia mul(ia a, ia b) { return ia_mul(a, b); }
static ia add(ia a, ia b) { return ia_add(a, b); }
static ia sub(ia a, ia b) { return ia_sub(a, b); }
static ia pt(double x) { return ia_point(x); }

/* theta = u*thetamax and its cosine and sine; dPdu from P (surfaces of
 * revolution: dPdu = thetamax (-P.y, P.x, 0)). */
static void sweep(const geom_surface *s, ia u, ia *c, ia *sn)
{
    ia theta = ia_mul_s(u, s->thetamax);
    *c = ia_cos(theta);
    *sn = ia_sin(theta);
}

static void dPdu_of_revolution(const geom_surface *s, geom_ia *o)
{
    o->dPdu[0] = ia_mul_s(o->P[1], -s->thetamax);
    o->dPdu[1] = ia_mul_s(o->P[0], s->thetamax);
    o->dPdu[2] = pt(0);
}

/* sphere (R = 0) and torus: profile (R + a, r sin phi), a = r cos phi */
static void eval_circle(const geom_surface *s, ia u, ia v, double R, double r, geom_ia *o)
{
    double pa, pb;
    geom_phi_range(s, &pa, &pb);
    ia dphi = s->consts[K_DPHI], c, sn;
    sweep(s, u, &c, &sn);
    ia phi = ia_add_s(mul(v, dphi), pa);
    ia a = ia_mul_s(ia_cos(phi), r), z = ia_mul_s(ia_sin(phi), r);
    ia ac = mul(a, c), as = mul(a, sn);
    o->P[0] = R == 0 ? ac : add(ia_mul_s(c, R), ac);
    o->P[1] = R == 0 ? as : add(ia_mul_s(sn, R), as);
    o->P[2] = z;
    dPdu_of_revolution(s, o);
    ia ndphi = ia_neg(dphi);
    o->dPdv[0] = mul(mul(z, c), ndphi);
    o->dPdv[1] = mul(mul(z, sn), ndphi);
    o->dPdv[2] = mul(a, dphi);
    ia k = mul(ia_mul_s(ia_add_s(a, R), s->thetamax), dphi);
    o->Ng[0] = mul(k, ac);
    o->Ng[1] = mul(k, as);
    o->Ng[2] = mul(k, z);
}

static void eval_disk(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    double r = s->radius;
    ia c, sn;
    sweep(s, u, &c, &sn);
    ia rho = ia_add_s(ia_mul_s(v, -r), r);
    o->P[0] = mul(rho, c);
    o->P[1] = mul(rho, sn);
    o->P[2] = pt(s->height);
    dPdu_of_revolution(s, o);
    o->dPdv[0] = ia_mul_s(c, -r);
    o->dPdv[1] = ia_mul_s(sn, -r);
    o->dPdv[2] = pt(0);
    o->Ng[0] = o->Ng[1] = pt(0);
    o->Ng[2] = ia_mul_s(ia_mul_s(rho, r), s->thetamax);
}

static void eval_cylinder(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    ia c, sn, dz = s->consts[K_DZ];
    sweep(s, u, &c, &sn);
    o->P[0] = ia_mul_s(c, s->radius);
    o->P[1] = ia_mul_s(sn, s->radius);
    o->P[2] = ia_add_s(mul(v, dz), s->zmin);
    dPdu_of_revolution(s, o);
    o->dPdv[0] = o->dPdv[1] = pt(0);
    o->dPdv[2] = dz;
    o->Ng[0] = mul(ia_mul_s(o->P[0], s->thetamax), dz);
    o->Ng[1] = mul(ia_mul_s(o->P[1], s->thetamax), dz);
    o->Ng[2] = pt(0);
}

static void eval_cone(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    double r = s->radius, h = s->height, tm = s->thetamax;
    ia c, sn;
    sweep(s, u, &c, &sn);
    ia rho = ia_add_s(ia_mul_s(v, -r), r);
    o->P[0] = mul(rho, c);
    o->P[1] = mul(rho, sn);
    o->P[2] = ia_mul_s(v, h);
    dPdu_of_revolution(s, o);
    o->dPdv[0] = ia_mul_s(c, -r);
    o->dPdv[1] = ia_mul_s(sn, -r);
    o->dPdv[2] = pt(h);
    o->Ng[0] = ia_mul_s(ia_mul_s(o->P[0], h), tm);
    o->Ng[1] = ia_mul_s(ia_mul_s(o->P[1], h), tm);
    o->Ng[2] = ia_mul_s(ia_mul_s(rho, r), tm);
}

static void eval_paraboloid(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    double tm = s->thetamax;
    ia c, sn, dz = s->consts[K_DZ];
    sweep(s, u, &c, &sn);
    ia z = ia_add_s(mul(v, dz), s->zmin);
    ia rho = ia_sqrt(mul(z, s->consts[K_PK]));
    o->P[0] = mul(rho, c);
    o->P[1] = mul(rho, sn);
    o->P[2] = z;
    dPdu_of_revolution(s, o);
    ia rho1 = ia_div(s->consts[K_PC], rho);
    o->dPdv[0] = mul(rho1, c);
    o->dPdv[1] = mul(rho1, sn);
    o->dPdv[2] = dz;
    o->Ng[0] = mul(ia_mul_s(o->P[0], tm), dz);
    o->Ng[1] = mul(ia_mul_s(o->P[1], tm), dz);
    o->Ng[2] = ia_mul_s(s->consts[K_PC], -tm);
}

static void eval_hyperboloid(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    double tm = s->thetamax;
    const ia *d = &s->consts[K_D];
    ia c, sn;
    sweep(s, u, &c, &sn);
    ia qx = ia_add_s(mul(v, d[0]), s->point1.x);
    ia qy = ia_add_s(mul(v, d[1]), s->point1.y);
    o->P[0] = sub(mul(qx, c), mul(qy, sn));
    o->P[1] = add(mul(qx, sn), mul(qy, c));
    o->P[2] = ia_add_s(mul(v, d[2]), s->point1.z);
    dPdu_of_revolution(s, o);
    o->dPdv[0] = sub(mul(c, d[0]), mul(sn, d[1]));
    o->dPdv[1] = add(mul(sn, d[0]), mul(c, d[1]));
    o->dPdv[2] = d[2];
    o->Ng[0] = mul(ia_mul_s(o->P[0], tm), d[2]);
    o->Ng[1] = mul(ia_mul_s(o->P[1], tm), d[2]);
    o->Ng[2] = ia_mul_s(add(mul(qx, d[0]), mul(qy, d[1])), -tm);
}

static void eval_polygon(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    for (int i = 0; i < 3; i++) {
        double au = v3_comp(s->axis_u, i), av = v3_comp(s->axis_v, i);
        o->P[i] = ia_add_s(add(ia_mul_s(u, au), ia_mul_s(v, av)), v3_comp(s->origin, i));
        o->dPdu[i] = pt(au);
        o->dPdv[i] = pt(av);
        o->Ng[i] = s->consts[K_NG + i];
    }
}

static void eval_patch(const geom_surface *s, ia u, ia v, geom_ia *o)
{
    ia uv = mul(u, v);
    const ia *k = s->consts;
    for (int i = 0; i < 3; i++) {
        ia lin = add(mul(u, k[K_B + i]), mul(v, k[K_C + i]));
        o->P[i] = ia_add_s(add(lin, mul(uv, k[K_A + i])), v3_comp(s->verts[0], i));
        o->dPdu[i] = add(k[K_B + i], mul(v, k[K_A + i]));
        o->dPdv[i] = add(k[K_C + i], mul(u, k[K_A + i]));
        o->Ng[i] = add(k[K_N0 + i], add(mul(u, k[K_N1 + i]), mul(v, k[K_N2 + i])));
    }
}

void geom_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out)
{
    switch (s->kind) {
    case GEOM_SPHERE:      eval_circle(s, u, v, 0, s->radius, out); break;
    case GEOM_TORUS:       eval_circle(s, u, v, s->majorrad, s->minorrad, out); break;
    case GEOM_DISK:        eval_disk(s, u, v, out); break;
    case GEOM_CYLINDER:    eval_cylinder(s, u, v, out); break;
    case GEOM_CONE:        eval_cone(s, u, v, out); break;
    case GEOM_PARABOLOID:  eval_paraboloid(s, u, v, out); break;
    case GEOM_HYPERBOLOID: eval_hyperboloid(s, u, v, out); break;
    case GEOM_POLYGON:     eval_polygon(s, u, v, out); break;
    case GEOM_PATCH:       eval_patch(s, u, v, out); break;
    case GEOM_BICUBIC:     geom_bicubic_eval_ia(s, u, v, out); break;
    case GEOM_SUBDIV:      geom_subdiv_eval_ia(s, u, v, out); break;
    case GEOM_NURBS:       geom_nurbs_eval_ia(s, u, v, out); break;
    default:
        for (int i = 0; i < 3; i++)
            out->P[i] = out->dPdu[i] = out->dPdv[i] = out->Ng[i] = ia_entire();
        break;
    }
}

void geom_eval_ia_tight(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out)
{
    geom_eval_ia(s, u, v, out);
    if (s->kind == GEOM_BICUBIC) geom_bicubic_tighten_ia(s, u, v, out);
}
