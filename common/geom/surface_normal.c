/*
 * surface_normal.c: the unit normal of a base surface over a (u,v) box, in
 * affine and interval arithmetic (see geom_unit_normal_aa in surface.h),
 * and at one (u,v) for the point path (geom_normal_dual).
 *
 * Why: displacement shaders move P along normalize(N). Normalising Ng over
 * a box that touches a point where Ng = 0 (a sphere's pole, a disk's
 * centre, a cone's apex: RenderMan's parameterisations all have them)
 * divides by a range containing 0, the box becomes unbounded, and the
 * subdivision around that point never ends (Heidrich & Seidel §3 assume
 * bounded boxes). The closed forms of surface_normal.inc (sphere, torus,
 * disk, cylinder, cone) have no such points; polygons use the constant
 * Ng / |Ng|, or with vertex normals the interpolated N = C + u A + v B
 * (surface_vertex_normal.c), normalised. Paraboloids, hyperboloids and
 * patches normalise Ng. Constant factors are applied as intervals on a
 * context of capacity 0, so rounding lands in the result's own error term
 * and the enclosures hold for the exact real values.
 *
 * Singular points (Ng = 0 exactly). The point path gives a shader Ng
 * itself where Ng != 0 (normalised by the caller) and the LIMIT normal
 * where Ng = 0: the closed form (surface_normal.inc, the same definition
 * the boxes use) and its derivatives; for a kind without one, the limit
 * of Ng/|Ng| as (u,v) moves into the square along v (or u), the direction
 * of dNg/dv (or dNg/du), with derivatives 0. The boxes of those kinds
 * bound it: a box holding such a point normalises a range of Ng that holds
 * 0, which is unbounded, and one over which Ng is exactly 0 (a box of one
 * point) is [-1, 1]^3.
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "geom/subdiv.h"

#include <math.h>

static double sgn(double x) { return x < 0 ? -1.0 : 1.0; }

/* 1 / sqrt(a^2 + b^2) as an enclosing interval */
static ia_interval inv_hypot(double a, double b)
{
    ia_interval n2 = ia_add(ia_sqr(ia_point(a)), ia_sqr(ia_point(b)));
    return ia_recip(ia_sqrt(n2));
}

static double dphi_sign(const geom_surface *s)
{
    double a, b;
    geom_phi_range(s, &a, &b);
    return sgn(b - a);
}

/* ---- the closed forms, in each arithmetic (surface_normal.inc) ---- */

/* z = x * k for every k in the interval k, no new noise symbol */
static void scale_k(aa_form *z, const aa_form *x, ia_interval k)
{
    aa_context none;
    aa_context_init(&none, 0);
    if (k.lo == k.hi) {
        aa_mul_s(&none, z, x, k.lo);
        return;
    }
    aa_form kf;
    aa_from_interval(&none, &kf, k);
    aa_mul(&none, z, x, &kf);
}

static void const_form(aa_form *z, ia_interval k)
{
    aa_context none;
    aa_context_init(&none, 0);
    if (k.lo == k.hi) aa_const(z, k.lo);
    else aa_from_interval(&none, z, k);
}

#define NT aa_form
#define NT_FN(name) NT_CAT2(name, aa)
#define NT_MUL_S(z, x, d) aa_mul_s(ctx, z, x, d)
#define NT_MUL_S0(z, x, d) aa_mul_s(none, z, x, d)
#define NT_SCALE_K(z, x, k) scale_k(z, x, k)
#define NT_CONST_K(z, k) const_form(z, k)
#define NT_ADD_S0(z, x, d) aa_add_s(none, z, x, d)
#define NT_MUL(z, x, y) aa_mul(ctx, z, x, y)
#define NT_COS(z, x) aa_cos(ctx, z, x)
#define NT_SIN(z, x) aa_sin(ctx, z, x)
#include "surface_normal.inc"

#define NT ia_interval
#define NT_FN(name) NT_CAT2(name, ia)
#define NT_MUL_S(z, x, d) (*(z) = ia_mul_s(*(x), d))
#define NT_MUL_S0 NT_MUL_S
#define NT_SCALE_K(z, x, k) (*(z) = ia_mul(*(x), k))
#define NT_CONST_K(z, k) (*(z) = (k))
#define NT_ADD_S0(z, x, d) (*(z) = ia_add_s(*(x), d))
#define NT_MUL(z, x, y) (*(z) = ia_mul(*(x), *(y)))
#define NT_COS(z, x) (*(z) = ia_cos(*(x)))
#define NT_SIN(z, x) (*(z) = ia_sin(*(x)))
#include "surface_normal.inc"

/* a value with its d/du and d/dv (forward-mode differentiation) */
typedef struct dual { double v, du, dv; } dual;

static double mid(ia_interval k) { return k.lo == k.hi ? k.lo : 0.5 * (k.lo + k.hi); }
static dual d_mul_s(dual x, double d) { return (dual){x.v * d, x.du * d, x.dv * d}; }
static dual d_mul(dual x, dual y)
{
    return (dual){x.v * y.v, x.du * y.v + x.v * y.du, x.dv * y.v + x.v * y.dv};
}
static dual d_cos(dual x) { double s = -sin(x.v); return (dual){cos(x.v), s * x.du, s * x.dv}; }
static dual d_sin(dual x) { double c = cos(x.v); return (dual){sin(x.v), c * x.du, c * x.dv}; }

#define NT dual
#define NT_FN(name) NT_CAT2(name, dual)
#define NT_MUL_S(z, x, d) (*(z) = d_mul_s(*(x), d))
#define NT_MUL_S0 NT_MUL_S
#define NT_SCALE_K(z, x, k) (*(z) = d_mul_s(*(x), mid(k)))
#define NT_CONST_K(z, k) (*(z) = (dual){mid(k), 0, 0})
#define NT_ADD_S0(z, x, d) (*(z) = (dual){(x)->v + (d), (x)->du, (x)->dv})
#define NT_MUL(z, x, y) (*(z) = d_mul(*(x), *(y)))
#define NT_COS(z, x) (*(z) = d_cos(*(x)))
#define NT_SIN(z, x) (*(z) = d_sin(*(x)))
#include "surface_normal.inc"

/* ---- affine ---- */

static void normalize_ia(const ia_interval Ng[3], ia_interval Nn[3]);

static void normalize_aa(aa_context *ctx, const aa_form Ng[3], aa_form Nn[3])
{
    aa_form n2, t, inv;
    aa_sqr(ctx, &n2, &Ng[0]);
    aa_sqr(ctx, &t, &Ng[1]);
    aa_add(ctx, &n2, &n2, &t);
    aa_sqr(ctx, &t, &Ng[2]);
    aa_add(ctx, &n2, &n2, &t);
    if (aa_range(&n2).hi == 0) {          /* Ng = 0 over the box: a limit */
        for (int i = 0; i < 3; i++) const_form(&Nn[i], ia_make(-1, 1));
        return;
    }
    aa_invsqrt(ctx, &inv, &n2);
    for (int i = 0; i < 3; i++) aa_mul(ctx, &Nn[i], &Ng[i], &inv);
}

void geom_unit_normal_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                         const aa_form *v, const geom_aa *g, aa_form Nn[3])
{
    aa_context none;
    aa_context_init(&none, 0);
    if (closed_normal_aa(ctx, &none, s, u, v, g->P, Nn)) return;
    switch (s->kind) {
    case GEOM_POLYGON: {
        if (geom_has_vertex_normals(s)) {
            aa_form Nv[3];
            for (int i = 0; i < 3; i++)
                aa_lincomb(ctx, &Nv[i], s->consts[K_VNU + i].lo, u, s->consts[K_VNV + i].lo,
                           v, s->consts[K_VNC + i].lo);
            normalize_aa(ctx, Nv, Nn);
            return;
        }
        ia_interval n[3];
        geom_ia gi;
        for (int i = 0; i < 3; i++) gi.Ng[i] = aa_range(&g->Ng[i]);
        ia_interval n2 = ia_add(ia_add(ia_sqr(gi.Ng[0]), ia_sqr(gi.Ng[1])), ia_sqr(gi.Ng[2]));
        ia_interval inv = ia_recip(ia_sqrt(n2));
        for (int i = 0; i < 3; i++) {
            n[i] = ia_mul(gi.Ng[i], inv);
            const_form(&Nn[i], n[i]);
        }
        return;
    }
    case GEOM_SUBDIV:
    case GEOM_NURBS:
        /* near an extraordinary point (a collapsed edge of a NuPatch) Ng
         * may be unbounded or hold 0: the unit normal is then only known
         * to lie in [-1,1]^3 */
        normalize_aa(ctx, g->Ng, Nn);
        for (int i = 0; i < 3; i++) {
            ia_interval r = aa_range(&Nn[i]);
            if (!isfinite(r.lo) || !isfinite(r.hi) || (Nn[i].flags & AA_UNBOUNDED)) {
                /* the ranges of Ng (met with the net's bounds) may still
                 * keep away from 0 where the forms do not */
                ia_interval ng[3], n[3];
                for (int k = 0; k < 3; k++) ng[k] = aa_range(&g->Ng[k]);
                normalize_ia(ng, n);
                /* an irregular sub-face whose normal is proven constant */
                geom_subdiv_unit_normal_box(s, aa_range(u), aa_range(v), n);
                for (int k = 0; k < 3; k++) {
                    if (!isfinite(n[k].lo) || !isfinite(n[k].hi) || (n[k].flags & AA_UNBOUNDED))
                        n[k] = ia_make(-1, 1);
                    const_form(&Nn[k], ia_make(fmax(n[k].lo, -1), fmin(n[k].hi, 1)));
                }
                return;
            }
        }
        return;
    default:
        normalize_aa(ctx, g->Ng, Nn);
        return;
    }
}

/* ---- interval ---- */

bool geom_unit_slopes_ia(const ia_interval N[3], const ia_interval dNu[3],
                         const ia_interval dNv[3], ia_interval dNdu[3], ia_interval dNdv[3])
{
    ia_interval n2 = ia_add(ia_add(ia_sqr(N[0]), ia_sqr(N[1])), ia_sqr(N[2]));
    if (!(n2.lo > 0) || !isfinite(n2.hi)) return false;
    ia_interval inv = ia_invsqrt(n2), Nn[3];
    for (int i = 0; i < 3; i++) Nn[i] = ia_mul(N[i], inv);
    for (int d = 0; d < 2; d++) {
        const ia_interval *a = d == 0 ? dNu : dNv;
        ia_interval dot = ia_add(ia_add(ia_mul(Nn[0], a[0]), ia_mul(Nn[1], a[1])),
                                 ia_mul(Nn[2], a[2]));
        ia_interval *out = d == 0 ? dNdu : dNdv;
        for (int i = 0; i < 3; i++) {
            out[i] = ia_mul(ia_sub(a[i], ia_mul(Nn[i], dot)), inv);
            if (!isfinite(out[i].lo) || !isfinite(out[i].hi)) return false;
        }
    }
    return true;
}

/* The slopes of Nn = Nv / |Nv| with Nv = C + A u + B v (interpolated
 * vertex normals; a bilinear patch's Pu x Pv) */
static bool linear_normal_slopes(ia_interval u, ia_interval v, const ia_interval C[3],
                                 const ia_interval A[3], const ia_interval B[3],
                                 ia_interval dNdu[3], ia_interval dNdv[3])
{
    ia_interval Nv[3];
    for (int i = 0; i < 3; i++)
        Nv[i] = ia_add(ia_add(ia_mul(u, A[i]), ia_mul(v, B[i])), C[i]);
    return geom_unit_slopes_ia(Nv, A, B, dNdu, dNdv);
}

bool geom_unit_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                const geom_ia *g, ia_interval dNdu[3], ia_interval dNdv[3])
{
    ia_interval theta = ia_mul_s(u, s->thetamax), zero = ia_point(0);
    switch (s->kind) {
    case GEOM_SPHERE: {              /* Nn = k P */
        ia_interval k = ia_mul_s(ia_recip(ia_point(s->radius)), sgn(s->thetamax) * dphi_sign(s));
        for (int i = 0; i < 3; i++) {
            dNdu[i] = ia_mul(g->dPdu[i], k);
            dNdv[i] = ia_mul(g->dPdv[i], k);
        }
        return true;
    }
    case GEOM_CYLINDER: {            /* Nn = k (Px, Py, 0) */
        ia_interval k = ia_mul_s(ia_recip(ia_point(s->radius)), sgn(s->thetamax) * sgn(s->zmax - s->zmin));
        for (int i = 0; i < 2; i++) {
            dNdu[i] = ia_mul(g->dPdu[i], k);
            dNdv[i] = ia_mul(g->dPdv[i], k);
        }
        dNdu[2] = dNdv[2] = zero;
        return true;
    }
    case GEOM_CONE: {                /* Nn = k (h cos theta, h sin theta, r) */
        ia_interval kh = ia_mul_s(ia_mul_s(inv_hypot(s->height, s->radius), sgn(s->thetamax)),
                                  s->height);
        ia_interval kt = ia_mul_s(kh, s->thetamax);
        dNdu[0] = ia_neg(ia_mul(ia_sin(theta), kt));
        dNdu[1] = ia_mul(ia_cos(theta), kt);
        dNdu[2] = zero;
        dNdv[0] = dNdv[1] = dNdv[2] = zero;
        return true;
    }
    case GEOM_TORUS: {               /* Nn = k (cos phi cos theta, cos phi sin theta, sin phi) */
        double pa, pb;
        geom_phi_range(s, &pa, &pb);
        ia_interval phi = ia_add_s(ia_mul(v, s->consts[K_DPHI]), pa);
        ia_interval cp = ia_cos(phi), sp = ia_sin(phi), ct = ia_cos(theta), st = ia_sin(theta);
        double k = sgn(s->thetamax) * dphi_sign(s);
        ia_interval ku = ia_point(k * s->thetamax), kv = ia_mul_s(s->consts[K_DPHI], k);
        dNdu[0] = ia_neg(ia_mul(ia_mul(cp, st), ku));
        dNdu[1] = ia_mul(ia_mul(cp, ct), ku);
        dNdu[2] = zero;
        dNdv[0] = ia_neg(ia_mul(ia_mul(sp, ct), kv));
        dNdv[1] = ia_neg(ia_mul(ia_mul(sp, st), kv));
        dNdv[2] = ia_mul(cp, kv);
        return true;
    }
    case GEOM_DISK:
        for (int i = 0; i < 3; i++) dNdu[i] = dNdv[i] = zero;
        return true;
    case GEOM_POLYGON:
        if (!geom_has_vertex_normals(s)) {
            for (int i = 0; i < 3; i++) dNdu[i] = dNdv[i] = zero;
            return true;
        }
        return linear_normal_slopes(u, v, &s->consts[K_VNC], &s->consts[K_VNU],
                                    &s->consts[K_VNV], dNdu, dNdv);
    case GEOM_PATCH:                 /* Ng = Pu x Pv is linear in (u, v) */
        return linear_normal_slopes(u, v, &s->consts[K_N0], &s->consts[K_N1], &s->consts[K_N2],
                                    dNdu, dNdv);
    case GEOM_BICUBIC:
        return geom_bicubic_normal_slopes_ia(s, u, v, dNdu, dNdv);
    case GEOM_SUBDIV:
        return geom_subdiv_normal_slopes_ia(s, u, v, dNdu, dNdv);
    default:
        return false;
    }
}

static void normalize_ia(const ia_interval Ng[3], ia_interval Nn[3])
{
    ia_interval n2 = ia_add(ia_add(ia_sqr(Ng[0]), ia_sqr(Ng[1])), ia_sqr(Ng[2]));
    if (n2.hi == 0) {                     /* Ng = 0 over the box: a limit */
        for (int i = 0; i < 3; i++) Nn[i] = ia_make(-1, 1);
        return;
    }
    ia_interval inv = ia_invsqrt(n2);
    for (int i = 0; i < 3; i++) Nn[i] = ia_mul(Ng[i], inv);
}

void geom_unit_normal_ia(const geom_surface *s, ia_interval u, ia_interval v,
                         const geom_ia *g, ia_interval Nn[3])
{
    if (closed_normal_ia(NULL, NULL, s, &u, &v, g->P, Nn)) return;
    switch (s->kind) {
    case GEOM_POLYGON:
        if (geom_has_vertex_normals(s)) {
            ia_interval Nv[3];
            for (int i = 0; i < 3; i++)
                Nv[i] = ia_add(ia_add(ia_mul(u, s->consts[K_VNU + i]),
                                      ia_mul(v, s->consts[K_VNV + i])), s->consts[K_VNC + i]);
            normalize_ia(Nv, Nn);
            return;
        }
        normalize_ia(g->Ng, Nn);
        return;
    case GEOM_SUBDIV:
    case GEOM_NURBS:
        normalize_ia(g->Ng, Nn);
        for (int i = 0; i < 3; i++)
            if (!isfinite(Nn[i].lo) || !isfinite(Nn[i].hi) || (Nn[i].flags & AA_UNBOUNDED)) {
                if (geom_subdiv_unit_normal_box(s, u, v, Nn)) return;
                for (int k = 0; k < 3; k++) Nn[k] = ia_make(-1, 1);
                return;
            }
        return;
    default:
        normalize_ia(g->Ng, Nn);
        return;
    }
}

/* ---- float and dual ---- */

void geom_normal_dual(const geom_surface *s, double u, double v, const geom_sample *g,
                      vec3 *N, vec3 *dNdu, vec3 *dNdv)
{
    *N = g->Ng;
    *dNdu = g->dNgdu;
    *dNdv = g->dNgdv;
    double len = v3_length(g->Ng);
    if (len > 0 && isfinite(len)) return;
    /* a singular point: the limit normal */
    dual U = {u, 1, 0}, V = {v, 0, 1}, P[3], Nn[3];
    P[0] = (dual){g->P.x, g->dPdu.x, g->dPdv.x};
    P[1] = (dual){g->P.y, g->dPdu.y, g->dPdv.y};
    P[2] = (dual){g->P.z, g->dPdu.z, g->dPdv.z};
    if (closed_normal_dual(NULL, NULL, s, &U, &V, P, Nn)) {
        *N = v3(Nn[0].v, Nn[1].v, Nn[2].v);
        *dNdu = v3(Nn[0].du, Nn[1].du, Nn[2].du);
        *dNdv = v3(Nn[0].dv, Nn[1].dv, Nn[2].dv);
        return;
    }
    /* Ng ~ (v - v*) dNg/dv near an edge v = v* where Ng vanishes: its
     * direction moving into the square (then likewise along u); the
     * derivatives of this limit are not known here (the boxes' are
     * unknown too): 0 */
    geom_sample d;
    geom_eval_dual(s, u, v, &d);
    vec3 dv = v3_scale(d.dNgdv, v < 1 ? 1.0 : -1.0), du = v3_scale(d.dNgdu, u < 1 ? 1.0 : -1.0);
    double lv = v3_length(dv), lu = v3_length(du);
    if (lv > 0 && isfinite(lv)) *N = v3_scale(dv, 1 / lv);
    else if (lu > 0 && isfinite(lu)) *N = v3_scale(du, 1 / lu);
    *dNdu = *dNdv = v3(0, 0, 0);
}
