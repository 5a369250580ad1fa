/*
 * surface_affine.c: affine forms of P, dPdu, dPdv, Ng over a (u,v) box
 * (geom_eval_aa), the first half of Heidrich & Seidel §3-4: the base
 * surface in affine arithmetic, whose results the displacement shader then
 * takes as its inputs. u and v are the caller's forms (aa_input, the
 * query's first two noise symbols); everything here is built from them with
 * common/aa operations only, so the results share those symbols and are
 * conservative including rounding.
 *
 * Tightness. Each non-affine step costs a noise symbol (and, once the
 * context's capacity is spent, correlation), so the formulas are chosen to
 * need few of them, and to reuse products:
 *
 *   surfaces of revolution   cos and sin of theta once each; dPdu is
 *                            thetamax (-P.y, P.x, 0), affine in P
 *   sphere, torus            cos, sin of phi once; P, dPdv and Ng share the
 *                            products a*cos(theta), a*sin(theta) (a = r cos
 *                            phi): Ng = thetamax dphi (R + a) (a cos theta,
 *                            a sin theta, r sin phi)
 *   disk, cone, cylinder     Ng affine in P or in the radius: no product
 *   paraboloid               Ng affine in P: r r' is the constant
 *                            (zmax - zmin) rmax^2 / (2 zmax)
 *   hyperboloid              Ng.z = -(qx dx + qy dy) is affine in v
 *   polygon                  everything affine
 *   patch                    one product u*v; Ng = n0 + u n1 + v n2 affine
 *
 * Sphere: 11 non-affine operations, torus 11, paraboloid 8, hyperboloid 6,
 * disk and cone 4, cylinder 2, patch 1, polygon 0.
 *
 * Constants. Exact derived constants (zmax - zmin, rmax^2/zmax, ...) are
 * intervals in s->consts[]. Multiplying by one (scale) goes through a private
 * context of capacity 0, so its rounding-level width lands on the result's
 * own error term instead of costing one of the query's noise symbols.
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"

#include <stddef.h>

typedef aa_form form;

/* z = the constant k (an interval) as a form without noise symbols */
static void kform(form *z, ia_interval k)
{
    if (k.lo == k.hi) {
        aa_const(z, k.lo);
        return;
    }
    aa_context none;
    aa_context_init(&none, 0);
    aa_from_interval(&none, z, k);
}

/* z = x * k for every k in the interval k */
static void scale(form *z, const form *x, ia_interval k)
{
    aa_context none;
    aa_context_init(&none, 0);
    if (k.lo == k.hi) {
        aa_mul_s(&none, z, x, k.lo);
        return;
    }
    form kf;
    kform(&kf, k);
    aa_mul(&none, z, x, &kf);
}

/* z = x * k + c, k an interval, c a double */
static void scale_add(form *z, const form *x, ia_interval k, double c)
{
    aa_context none;
    aa_context_init(&none, 0);
    scale(z, x, k);
    aa_add_s(&none, z, z, c);
}

/* z = x + k, k an interval */
static void add_k(form *z, const form *x, ia_interval k)
{
    aa_context none;
    aa_context_init(&none, 0);
    form kf;
    kform(&kf, k);
    aa_add(&none, z, x, &kf);
}

typedef struct sweep_forms { form c, s; } sweep_forms;

static void sweep(aa_context *ctx, const geom_surface *s, const form *u, sweep_forms *t)
{
    form theta;
    aa_mul_s(ctx, &theta, u, s->thetamax);
    aa_cos(ctx, &t->c, &theta);
    aa_sin(ctx, &t->s, &theta);
}

static void dPdu_of_revolution(aa_context *ctx, const geom_surface *s, geom_aa *o)
{
    aa_mul_s(ctx, &o->dPdu[0], &o->P[1], -s->thetamax);
    aa_mul_s(ctx, &o->dPdu[1], &o->P[0], s->thetamax);
    aa_const(&o->dPdu[2], 0);
}

/* sphere (R = 0) and torus */
static void eval_circle(aa_context *ctx, const geom_surface *s, const form *u,
                        const form *v, double R, double r, geom_aa *o)
{
    double pa, pb;
    geom_phi_range(s, &pa, &pb);
    ia_interval dphi = s->consts[K_DPHI];
    sweep_forms t;
    sweep(ctx, s, u, &t);
    form phi, a, z, ac, as, tmp;
    scale_add(&phi, v, dphi, pa);
    aa_cos(ctx, &a, &phi);
    aa_sin(ctx, &z, &phi);
    aa_mul_s(ctx, &a, &a, r);
    aa_mul_s(ctx, &z, &z, r);
    aa_mul(ctx, &ac, &a, &t.c);
    aa_mul(ctx, &as, &a, &t.s);
    if (R == 0) {
        o->P[0] = ac;
        o->P[1] = as;
    } else {
        aa_lincomb(ctx, &o->P[0], R, &t.c, 1, &ac, 0);
        aa_lincomb(ctx, &o->P[1], R, &t.s, 1, &as, 0);
    }
    o->P[2] = z;
    dPdu_of_revolution(ctx, s, o);
    ia_interval ndphi = ia_neg(dphi);
    aa_mul(ctx, &tmp, &z, &t.c);
    scale(&o->dPdv[0], &tmp, ndphi);
    aa_mul(ctx, &tmp, &z, &t.s);
    scale(&o->dPdv[1], &tmp, ndphi);
    scale(&o->dPdv[2], &a, dphi);
    form k;                                   /* thetamax dphi (R + a) */
    aa_add_s(ctx, &k, &a, R);
    aa_mul_s(ctx, &k, &k, s->thetamax);
    scale(&k, &k, dphi);
    aa_mul(ctx, &o->Ng[0], &k, &ac);
    aa_mul(ctx, &o->Ng[1], &k, &as);
    aa_mul(ctx, &o->Ng[2], &k, &z);
}

static void eval_disk(aa_context *ctx, const geom_surface *s, const form *u,
                      const form *v, geom_aa *o)
{
    double r = s->radius;
    sweep_forms t;
    sweep(ctx, s, u, &t);
    form rho;
    aa_lincomb(ctx, &rho, -r, v, 0, NULL, r);
    aa_mul(ctx, &o->P[0], &rho, &t.c);
    aa_mul(ctx, &o->P[1], &rho, &t.s);
    aa_const(&o->P[2], s->height);
    dPdu_of_revolution(ctx, s, o);
    aa_mul_s(ctx, &o->dPdv[0], &t.c, -r);
    aa_mul_s(ctx, &o->dPdv[1], &t.s, -r);
    aa_const(&o->dPdv[2], 0);
    aa_const(&o->Ng[0], 0);
    aa_const(&o->Ng[1], 0);
    aa_mul_s(ctx, &o->Ng[2], &rho, r);
    aa_mul_s(ctx, &o->Ng[2], &o->Ng[2], s->thetamax);
}

static void eval_cylinder(aa_context *ctx, const geom_surface *s, const form *u,
                          const form *v, geom_aa *o)
{
    ia_interval dz = s->consts[K_DZ];
    sweep_forms t;
    sweep(ctx, s, u, &t);
    aa_mul_s(ctx, &o->P[0], &t.c, s->radius);
    aa_mul_s(ctx, &o->P[1], &t.s, s->radius);
    scale_add(&o->P[2], v, dz, s->zmin);
    dPdu_of_revolution(ctx, s, o);
    aa_const(&o->dPdv[0], 0);
    aa_const(&o->dPdv[1], 0);
    kform(&o->dPdv[2], dz);
    for (int i = 0; i < 2; i++) {
        aa_mul_s(ctx, &o->Ng[i], &o->P[i], s->thetamax);
        scale(&o->Ng[i], &o->Ng[i], dz);
    }
    aa_const(&o->Ng[2], 0);
}

static void eval_cone(aa_context *ctx, const geom_surface *s, const form *u,
                      const form *v, geom_aa *o)
{
    double r = s->radius, h = s->height, tm = s->thetamax;
    sweep_forms t;
    sweep(ctx, s, u, &t);
    form rho;
    aa_lincomb(ctx, &rho, -r, v, 0, NULL, r);
    aa_mul(ctx, &o->P[0], &rho, &t.c);
    aa_mul(ctx, &o->P[1], &rho, &t.s);
    aa_mul_s(ctx, &o->P[2], v, h);
    dPdu_of_revolution(ctx, s, o);
    aa_mul_s(ctx, &o->dPdv[0], &t.c, -r);
    aa_mul_s(ctx, &o->dPdv[1], &t.s, -r);
    aa_const(&o->dPdv[2], h);
    for (int i = 0; i < 2; i++) {
        aa_mul_s(ctx, &o->Ng[i], &o->P[i], h);
        aa_mul_s(ctx, &o->Ng[i], &o->Ng[i], tm);
    }
    aa_mul_s(ctx, &o->Ng[2], &rho, r);
    aa_mul_s(ctx, &o->Ng[2], &o->Ng[2], tm);
}

static void eval_paraboloid(aa_context *ctx, const geom_surface *s, const form *u,
                            const form *v, geom_aa *o)
{
    double tm = s->thetamax;
    ia_interval dz = s->consts[K_DZ];
    sweep_forms t;
    sweep(ctx, s, u, &t);
    form z, rho, rho1;
    scale_add(&z, v, dz, s->zmin);
    scale(&rho, &z, s->consts[K_PK]);
    aa_sqrt(ctx, &rho, &rho);                 /* rho = sqrt(z rmax^2/zmax) */
    aa_mul(ctx, &o->P[0], &rho, &t.c);
    aa_mul(ctx, &o->P[1], &rho, &t.s);
    o->P[2] = z;
    dPdu_of_revolution(ctx, s, o);
    aa_recip(ctx, &rho1, &rho);               /* rho' = dz rmax^2/(2 zmax rho) */
    scale(&rho1, &rho1, s->consts[K_PC]);
    aa_mul(ctx, &o->dPdv[0], &rho1, &t.c);
    aa_mul(ctx, &o->dPdv[1], &rho1, &t.s);
    kform(&o->dPdv[2], dz);
    for (int i = 0; i < 2; i++) {
        aa_mul_s(ctx, &o->Ng[i], &o->P[i], tm);
        scale(&o->Ng[i], &o->Ng[i], dz);
    }
    kform(&o->Ng[2], ia_mul_s(s->consts[K_PC], -tm));
}

static void eval_hyperboloid(aa_context *ctx, const geom_surface *s, const form *u,
                             const form *v, geom_aa *o)
{
    double tm = s->thetamax;
    const ia_interval *d = &s->consts[K_D];
    sweep_forms t;
    sweep(ctx, s, u, &t);
    form qx, qy, m1, m2;
    scale_add(&qx, v, d[0], s->point1.x);
    scale_add(&qy, v, d[1], s->point1.y);
    scale_add(&o->P[2], v, d[2], s->point1.z);
    aa_mul(ctx, &m1, &qx, &t.c);              /* P = Rz(theta) q */
    aa_mul(ctx, &m2, &qy, &t.s);
    aa_sub(ctx, &o->P[0], &m1, &m2);
    aa_mul(ctx, &m1, &qx, &t.s);
    aa_mul(ctx, &m2, &qy, &t.c);
    aa_add(ctx, &o->P[1], &m1, &m2);
    dPdu_of_revolution(ctx, s, o);
    scale(&m1, &t.c, d[0]);                   /* dPdv = Rz(theta) (point2 - point1) */
    scale(&m2, &t.s, d[1]);
    aa_sub(ctx, &o->dPdv[0], &m1, &m2);
    scale(&m1, &t.s, d[0]);
    scale(&m2, &t.c, d[1]);
    aa_add(ctx, &o->dPdv[1], &m1, &m2);
    kform(&o->dPdv[2], d[2]);
    for (int i = 0; i < 2; i++) {
        aa_mul_s(ctx, &o->Ng[i], &o->P[i], tm);
        scale(&o->Ng[i], &o->Ng[i], d[2]);
    }
    scale(&m1, &qx, d[0]);
    scale(&m2, &qy, d[1]);
    aa_lincomb(ctx, &o->Ng[2], -tm, &m1, -tm, &m2, 0);
}

static void eval_polygon(aa_context *ctx, const geom_surface *s, const form *u,
                         const form *v, geom_aa *o)
{
    for (int i = 0; i < 3; i++) {
        double au = v3_comp(s->axis_u, i), av = v3_comp(s->axis_v, i);
        aa_lincomb(ctx, &o->P[i], au, u, av, v, v3_comp(s->origin, i));
        aa_const(&o->dPdu[i], au);
        aa_const(&o->dPdv[i], av);
        kform(&o->Ng[i], s->consts[K_NG + i]);
    }
}

static void eval_patch(aa_context *ctx, const geom_surface *s, const form *u,
                       const form *v, geom_aa *o)
{
    const ia_interval *k = s->consts;
    form uv, m1, m2;
    aa_mul(ctx, &uv, u, v);
    for (int i = 0; i < 3; i++) {
        scale(&m1, u, k[K_B + i]);            /* P = P00 + u b + v c + uv a */
        scale(&m2, v, k[K_C + i]);
        aa_add(ctx, &m1, &m1, &m2);
        scale(&m2, &uv, k[K_A + i]);
        aa_lincomb(ctx, &o->P[i], 1, &m1, 1, &m2, v3_comp(s->verts[0], i));
        scale(&m1, v, k[K_A + i]);            /* dPdu = b + v a */
        add_k(&o->dPdu[i], &m1, k[K_B + i]);
        scale(&m1, u, k[K_A + i]);            /* dPdv = c + u a */
        add_k(&o->dPdv[i], &m1, k[K_C + i]);
        scale(&m1, u, k[K_N1 + i]);           /* Ng = n0 + u n1 + v n2 */
        scale(&m2, v, k[K_N2 + i]);
        aa_add(ctx, &m1, &m1, &m2);
        add_k(&o->Ng[i], &m1, k[K_N0 + i]);
    }
}

void geom_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                  const aa_form *v, geom_aa *out)
{
    switch (s->kind) {
    case GEOM_SPHERE:      eval_circle(ctx, s, u, v, 0, s->radius, out); break;
    case GEOM_TORUS:       eval_circle(ctx, s, u, v, s->majorrad, s->minorrad, out); break;
    case GEOM_DISK:        eval_disk(ctx, s, u, v, out); break;
    case GEOM_CYLINDER:    eval_cylinder(ctx, s, u, v, out); break;
    case GEOM_CONE:        eval_cone(ctx, s, u, v, out); break;
    case GEOM_PARABOLOID:  eval_paraboloid(ctx, s, u, v, out); break;
    case GEOM_HYPERBOLOID: eval_hyperboloid(ctx, s, u, v, out); break;
    case GEOM_POLYGON:     eval_polygon(ctx, s, u, v, out); break;
    case GEOM_PATCH:       eval_patch(ctx, s, u, v, out); break;
    case GEOM_BICUBIC:
        if (!geom_bicubic_net_aa(ctx, s, u, v, out)) geom_bicubic_eval_aa(ctx, s, u, v, out);
        break;
    case GEOM_SUBDIV:      geom_subdiv_eval_aa(ctx, s, u, v, out); break;
    case GEOM_NURBS:       geom_nurbs_eval_aa(ctx, s, u, v, out); break;
    default:
        for (int i = 0; i < 3; i++) {
            aa_unbounded(&out->P[i], 0);
            aa_unbounded(&out->dPdu[i], 0);
            aa_unbounded(&out->dPdv[i], 0);
            aa_unbounded(&out->Ng[i], 0);
        }
        break;
    }
}

void geom_eval_aa_range_P(aa_context *ctx, const geom_surface *s, const aa_form *u,
                          const aa_form *v, ia_interval P[3])
{
    if (s->kind == GEOM_SUBDIV) {
        geom_subdiv_range_P_aa(ctx, s, u, v, P);
        return;
    }
    if (s->kind == GEOM_BICUBIC && geom_bicubic_net_range_P(s, u, v, P)) return;
    geom_aa g;
    geom_eval_aa(ctx, s, u, v, &g);
    for (int i = 0; i < 3; i++) P[i] = aa_range(&g.P[i]);
}

void geom_ng_aa(aa_context *ctx, geom_aa *o)
{
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        aa_form x, y;
        aa_mul(ctx, &x, &o->dPdu[a], &o->dPdv[b]);
        aa_mul(ctx, &y, &o->dPdu[b], &o->dPdv[a]);
        aa_sub(ctx, &o->Ng[c], &x, &y);
    }
}
