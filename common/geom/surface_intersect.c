/*
 * surface_intersect.c: exact ray intersection of the undisplaced surfaces
 * (geom_intersect), nearest t in (tmin, tmax), with the (u,v) of the hit.
 *
 * Surfaces without displacement need no box refinement (Heidrich & Seidel
 * §3 is for displaced ones): the quadrics are solved in closed form, as
 * ray tracers have always done (a quadric's implicit equation along the
 * ray is a quadratic in t), the torus as a quartic, polygons as a plane,
 * bilinear patches as two planes through the ray (a quadratic in v or u).
 * Each candidate t, nearest first, is mapped back to (u,v) by inverting the
 * RenderMan parameterisation (theta from atan2, v from z, phi or the
 * radius) and kept if (u,v) lies in the sweep: partial sweeps (thetamax,
 * zmin/zmax, phimin/phimax) are honoured there.
 *
 * Conditioning: the ray is first rewritten as oc + s*dn with |dn| = 1 and
 * oc the ray's point closest to the object's origin, which keeps the
 * coefficients free of the cancellation a distant origin would cause.
 * Tangent rays give double roots; the solvers (roots.h) accept near-touches
 * within a tolerance of 1e-12 of the coefficients' term magnitudes.
 */
#include "geom/roots.h"
#include "geom/surface.h"
#include "geom/surface_internal.h"

#include <math.h>

#define V_TOL 1e-9          /* (u,v) slack at the ends of a sweep */
#define ANGLE_TOL 1e-9      /* radians, the same for theta and phi */
#define TOUCH 1e-12         /* relative tolerance for tangent rays */

typedef struct ray {
    vec3 o, d;              /* as given: o + t d */
    vec3 oc, dn;            /* oc + s dn, |dn| = 1, oc closest to the origin */
    double len, tc;         /* t = (tc + s) / len */
    double tmin, tmax;
} ray;

static bool ray_make(vec3 o, vec3 d, double tmin, double tmax, ray *r)
{
    r->o = o;
    r->d = d;
    r->len = v3_length(d);
    if (!(r->len > 0) || !isfinite(r->len) || !isfinite(o.x + o.y + o.z))
        return false;
    r->dn = v3_scale(d, 1.0 / r->len);
    r->tc = -v3_dot(o, r->dn);
    r->oc = v3_add(o, v3_scale(r->dn, r->tc));
    r->tmin = tmin;
    r->tmax = tmax;
    return true;
}

static double ray_t(const ray *r, double s)
{
    return (r->tc + s) / r->len;
}

static vec3 ray_at(const ray *r, double t)
{
    return v3_add(r->o, v3_scale(r->d, t));
}

bool geom_sweep_param(double angle, double sweep, double tol, double *t)
{
    if (sweep < 0)
        return geom_sweep_param(-angle, -sweep, tol, t);
    double a = fmod(angle, GEOM_TWO_PI);
    if (a < 0)
        a += GEOM_TWO_PI;
    if (a <= sweep) {
        *t = fmin(a / sweep, 1.0);
        return true;
    }
    if (a - sweep <= tol) {
        *t = 1;
        return true;
    }
    if (GEOM_TWO_PI - a <= tol) {
        *t = 0;
        return true;
    }
    return false;
}

/* v in [0,1] up to V_TOL, clamped */
static bool v_in_range(double *v)
{
    if (!(*v >= -V_TOL && *v <= 1 + V_TOL))
        return false;
    *v = fmin(fmax(*v, 0.0), 1.0);
    return true;
}

/* u of the point p on a surface of revolution whose profile point at this
 * v sits at angle offset (0 but for the hyperboloid) */
static bool u_of(const geom_surface *s, vec3 p, double offset, double *u)
{
    double theta = (p.x == 0 && p.y == 0) ? offset : atan2(p.y, p.x);
    return geom_sweep_param(theta - offset, s->thetamax, ANGLE_TOL, u);
}

/* ---------------------------------------------------------------------- */
/* inverse parameterisations                                               */
/* ---------------------------------------------------------------------- */

static bool hyperboloid_uv(const geom_surface *s, vec3 p, double v, double *u)
{
    vec3 q = v3_add(s->point1, v3_scale(v3_sub(s->point2, s->point1), v));
    double offset = (q.x == 0 && q.y == 0) ? 0 : atan2(q.y, q.x);
    return u_of(s, p, offset, u);
}

static bool inverse(const geom_surface *s, vec3 p, double *u, double *v)
{
    double rho = hypot(p.x, p.y), pa, pb;
    switch (s->kind) {
    case GEOM_SPHERE:
        *v = (atan2(p.z, rho) - s->phi0) / (s->phi1 - s->phi0);
        break;
    case GEOM_TORUS:
        geom_phi_range(s, &pa, &pb);
        if (!geom_sweep_param(atan2(p.z, rho - s->majorrad) - pa, pb - pa, ANGLE_TOL, v))
            return false;
        break;
    case GEOM_CYLINDER:
    case GEOM_PARABOLOID:
        *v = (p.z - s->zmin) / (s->zmax - s->zmin);
        break;
    case GEOM_CONE:
        *v = p.z / s->height;
        break;
    case GEOM_DISK:
        *v = 1 - rho / s->radius;
        break;
    default:                                   /* GEOM_HYPERBOLOID */
        *v = (p.z - s->point1.z) / (s->point2.z - s->point1.z);
        if (!v_in_range(v))
            return false;
        return hyperboloid_uv(s, p, *v, u);
    }
    return v_in_range(v) && u_of(s, p, 0, u);
}

/* The candidates s (ascending) in order: the first inside (tmin, tmax)
 * whose point maps back into the sweep is the hit. */
static bool first_hit(const geom_surface *s, const ray *r, const double *roots,
                      int n, geom_hit *hit)
{
    for (int i = 0; i < n; i++) {
        double t = ray_t(r, roots[i]), u, v;
        if (!(t > r->tmin && t < r->tmax))
            continue;
        if (inverse(s, ray_at(r, t), &u, &v)) {
            hit->t = t;
            hit->u = u;
            hit->v = v;
            return true;
        }
    }
    return false;
}

/* A s^2 + B s + C with term magnitudes Am, Bm, Cm (for the tolerance) */
static bool quadric_hit(const geom_surface *s, const ray *r, double A, double B,
                        double C, double Am, double Bm, double Cm, geom_hit *hit)
{
    double roots[2];
    double tol = TOUCH * (Bm * Bm + 4 * Am * Cm);
    int n = geom_quadratic(A, B, C, tol, tol, roots);
    return first_hit(s, r, roots, n, hit);
}

/* ---------------------------------------------------------------------- */
/* the quadrics (implicit forms of RI spec §5.2's surfaces)                */
/* ---------------------------------------------------------------------- */

/* x^2 + y^2 + z^2 = r^2 */
static bool hit_sphere(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 o = r->oc, d = r->dn;
    double rr = s->radius * s->radius, od = v3_dot(o, d), oo = v3_dot(o, o);
    return quadric_hit(s, r, v3_dot(d, d), 2 * od, oo - rr, 1, 2 * fabs(od), oo + rr, hit);
}

/* x^2 + y^2 = r^2 */
static bool hit_cylinder(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 o = r->oc, d = r->dn;
    double A = d.x * d.x + d.y * d.y, rr = s->radius * s->radius;
    double B = 2 * (o.x * d.x + o.y * d.y), Bm = 2 * (fabs(o.x * d.x) + fabs(o.y * d.y));
    double oo = o.x * o.x + o.y * o.y;
    return quadric_hit(s, r, A, B, oo - rr, A, Bm, oo + rr, hit);
}

/* x^2 + y^2 = (r/h)^2 (h - z)^2 */
static bool hit_cone(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 o = r->oc, d = r->dn;
    double k = s->radius / s->height, k2 = k * k, w = s->height - o.z;
    double A = d.x * d.x + d.y * d.y - k2 * d.z * d.z;
    double Am = d.x * d.x + d.y * d.y + k2 * d.z * d.z;
    double B = 2 * (o.x * d.x + o.y * d.y + k2 * w * d.z);
    double Bm = 2 * (fabs(o.x * d.x) + fabs(o.y * d.y) + k2 * fabs(w * d.z));
    double C = o.x * o.x + o.y * o.y - k2 * w * w, Cm = o.x * o.x + o.y * o.y + k2 * w * w;
    return quadric_hit(s, r, A, B, C, Am, Bm, Cm, hit);
}

/* x^2 + y^2 = (rmax^2/zmax) z */
static bool hit_paraboloid(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 o = r->oc, d = r->dn;
    double k = s->rmax * s->rmax / s->zmax;
    double A = d.x * d.x + d.y * d.y;
    double B = 2 * (o.x * d.x + o.y * d.y) - k * d.z;
    double Bm = 2 * (fabs(o.x * d.x) + fabs(o.y * d.y)) + fabs(k * d.z);
    double C = o.x * o.x + o.y * o.y - k * o.z, Cm = o.x * o.x + o.y * o.y + fabs(k * o.z);
    return quadric_hit(s, r, A, B, C, A, Bm, Cm, hit);
}

/* flat hyperboloid (point1.z == point2.z): an annulus in the plane z */
static bool hit_hyperboloid_flat(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 p1 = s->point1, dd = v3_sub(s->point2, s->point1);
    if (r->d.z == 0)
        return false;
    double t = (p1.z - r->o.z) / r->d.z;
    if (!(t > r->tmin && t < r->tmax))
        return false;
    vec3 p = ray_at(r, t);
    double A = dd.x * dd.x + dd.y * dd.y, B = 2 * (p1.x * dd.x + p1.y * dd.y);
    double pp = p.x * p.x + p.y * p.y, qq = p1.x * p1.x + p1.y * p1.y;
    double C = qq - pp, Bm = 2 * (fabs(p1.x * dd.x) + fabs(p1.y * dd.y));
    double vs[2], u;
    double tol = TOUCH * (Bm * Bm + 4 * A * (qq + pp));
    int n = geom_quadratic(A, B, C, tol, tol, vs);
    for (int i = 0; i < n; i++) {
        double v = vs[i];
        if (v_in_range(&v) && hyperboloid_uv(s, p, v, &u)) {
            hit->t = t;
            hit->u = u;
            hit->v = v;
            return true;
        }
    }
    return false;
}

/* x^2 + y^2 = qx(v)^2 + qy(v)^2 with v = (z - z1)/(z2 - z1), q the line
 * from point1 to point2 */
static bool hit_hyperboloid(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 p1 = s->point1, dd = v3_sub(s->point2, s->point1);
    if (dd.z == 0)
        return hit_hyperboloid_flat(s, r, hit);
    vec3 o = r->oc, d = r->dn;
    double v0 = (o.z - p1.z) / dd.z, v1 = d.z / dd.z;
    double a0 = p1.x + dd.x * v0, a1 = dd.x * v1, b0 = p1.y + dd.y * v0, b1 = dd.y * v1;
    double A = d.x * d.x + d.y * d.y - a1 * a1 - b1 * b1;
    double Am = d.x * d.x + d.y * d.y + a1 * a1 + b1 * b1;
    double B = 2 * (o.x * d.x + o.y * d.y - a0 * a1 - b0 * b1);
    double Bm = 2 * (fabs(o.x * d.x) + fabs(o.y * d.y) + fabs(a0 * a1) + fabs(b0 * b1));
    double C = o.x * o.x + o.y * o.y - a0 * a0 - b0 * b0;
    double Cm = o.x * o.x + o.y * o.y + a0 * a0 + b0 * b0;
    return quadric_hit(s, r, A, B, C, Am, Bm, Cm, hit);
}

/* the plane z = height */
static bool hit_disk(const geom_surface *s, const ray *r, geom_hit *hit)
{
    if (r->d.z == 0)
        return false;
    double t = (s->height - r->o.z) / r->d.z, u, v;
    if (!(t > r->tmin && t < r->tmax))
        return false;
    if (!inverse(s, ray_at(r, t), &u, &v))
        return false;
    hit->t = t;
    hit->u = u;
    hit->v = v;
    return true;
}

/* (|p|^2 + R^2 - r^2)^2 = 4 R^2 (x^2 + y^2), a quartic in s, with
 * |p|^2 = s^2 + 2 od s + |oc|^2 (od = oc.dn, 0 up to rounding). Roots are sought only where the ray is inside the
 * bounding sphere of radius R + r (slightly enlarged, so that rays tangent
 * at the outer equator, which graze the sphere too, are kept). */
static bool hit_torus(const geom_surface *s, const ray *r, geom_hit *hit)
{
    vec3 o = r->oc, d = r->dn;
    double R = s->majorrad, rm = s->minorrad, RR = 4 * R * R;
    double oo = v3_dot(o, o), big = (R + rm) * (1 + 1e-9);
    if (oo > big * big)
        return false;
    double h = sqrt(big * big - oo);
    double lo = fmax(-h, r->tmin * r->len - r->tc), hi = fmin(h, r->tmax * r->len - r->tc);
    if (!(lo <= hi))
        return false;
    double K = oo + R * R - rm * rm, Km = oo + R * R + rm * rm, od = v3_dot(o, d);
    double dxy = d.x * d.x + d.y * d.y, oxy = o.x * o.x + o.y * o.y;
    double odxy = o.x * d.x + o.y * d.y, odm = fabs(o.x * d.x) + fabs(o.y * d.y);
    double c[5] = { K * K - RR * oxy, 4 * od * K - 2 * RR * odxy,
                    4 * od * od + 2 * K - RR * dxy, 4 * od, 1 };
    double m[5] = { Km * Km + RR * oxy, 4 * fabs(od) * Km + 2 * RR * odm,
                    4 * od * od + 2 * Km + RR * dxy, 4 * fabs(od), 1 };
    double tol[5];
    for (int i = 0; i < 5; i++)
        tol[i] = TOUCH * m[i];
    double roots[GEOM_POLY_MAX_ROOTS];
    int n = geom_poly_roots(c, tol, 4, lo, hi, roots);
    return first_hit(s, r, roots, n, hit);
}

/* ---------------------------------------------------------------------- */
/* polygon and bilinear patch                                              */
/* ---------------------------------------------------------------------- */

static bool hit_polygon(const geom_surface *s, const ray *r, geom_hit *hit)
{
    double den = v3_dot(s->normal, r->d);
    if (den == 0)
        return false;
    double t = v3_dot(s->normal, v3_sub(s->origin, r->o)) / den;
    if (!(t > r->tmin && t < r->tmax))
        return false;
    vec3 rel = v3_sub(ray_at(r, t), s->origin);
    double u = v3_dot(rel, s->axis_u) / v3_dot(s->axis_u, s->axis_u);
    double v = v3_dot(rel, s->axis_v) / v3_dot(s->axis_v, s->axis_v);
    if (!geom_uv_inside(s, u, v))
        return false;
    hit->t = t;
    hit->u = fmin(fmax(u, 0.0), 1.0);          /* the edge slack may step out */
    hit->v = fmin(fmax(v, 0.0), 1.0);
    return true;
}

typedef struct patch { vec3 p00, b, c, a; } patch;   /* P = p00 + u b + v c + uv a */

static vec3 patch_at(const patch *pt, double u, double v)
{
    return v3_add(pt->p00, v3_add(v3_scale(pt->b, u),
                                  v3_add(v3_scale(pt->c, v), v3_scale(pt->a, u * v))));
}

static double patch_residual(const patch *pt, const ray *r, double u, double v, double t)
{
    return v3_length(v3_sub(patch_at(pt, u, v), ray_at(r, t)));
}

/* Newton on P(u,v) - o - t d = 0 (Cramer's rule on [Pu Pv -d]); a couple
 * of steps polish the closed-form candidate to full precision. A step is
 * kept only if it lowers the residual: for tangent rays the system is
 * singular (det = -Ng.d = 0) and the candidate is already the best. */
static void patch_polish(const patch *pt, const ray *r, double *u, double *v, double *t)
{
    double res = patch_residual(pt, r, *u, *v, *t);
    for (int it = 0; it < 3 && res > 0; it++) {
        vec3 f = v3_sub(patch_at(pt, *u, *v), ray_at(r, *t));
        vec3 pu = v3_add(pt->b, v3_scale(pt->a, *v)), pv = v3_add(pt->c, v3_scale(pt->a, *u));
        vec3 nd = v3_neg(r->d);
        double det = v3_dot(pu, v3_cross(pv, nd));
        if (det == 0 || !isfinite(det))
            return;
        double nu = *u - v3_dot(f, v3_cross(pv, nd)) / det;
        double nv = *v - v3_dot(pu, v3_cross(f, nd)) / det;
        double nt = *t - v3_dot(pu, v3_cross(pv, f)) / det;
        double nres = patch_residual(pt, r, nu, nv, nt);
        if (!(nres < res))
            return;
        *u = nu;
        *v = nv;
        *t = nt;
        res = nres;
    }
}

/* Candidate (u,v): keep it if it polishes onto the ray inside the patch
 * and nearer than the best so far. */
static void patch_candidate(const patch *pt, const ray *r, double u, double v,
                            double size, geom_hit *best)
{
    if (!(u >= -0.1 && u <= 1.1 && v >= -0.1 && v <= 1.1))
        return;
    double t = v3_dot(v3_sub(patch_at(pt, u, v), r->o), r->d) / (r->len * r->len);
    patch_polish(pt, r, &u, &v, &t);
    if (!v_in_range(&u) || !v_in_range(&v) || !(t > r->tmin && t < r->tmax) || t >= best->t)
        return;
    vec3 miss = v3_sub(patch_at(pt, u, v), ray_at(r, t));
    if (!(v3_length(miss) <= 1e-7 * size))
        return;
    best->t = t;
    best->u = u;
    best->v = v;
}

/* One of the two unknowns from the other: A w x + B x + C w + D = 0 for the
 * two planes k = 1, 2 (the better conditioned one). */
static bool solve_other(const double *A, const double *B, const double *C,
                        const double *D, double w, double *x)
{
    double d1 = A[0] * w + B[0], d2 = A[1] * w + B[1];
    int k = fabs(d1) >= fabs(d2) ? 0 : 1;
    double den = k == 0 ? d1 : d2;
    if (den == 0)
        return false;
    *x = -(C[k] * w + D[k]) / den;
    return isfinite(*x);
}

/* Eliminating x from A_k w x + B_k x + C_k w + D_k = 0, k = 1, 2:
 * (A1 C2 - A2 C1) w^2 + (A1 D2 + B1 C2 - A2 D1 - B2 C1) w + B1 D2 - B2 D1.
 * m[] bound the magnitudes of A..D (|a|, |b|, |c|, |P00 - o|) for the
 * tangent tolerance. Close roots are not merged: the candidates are
 * polished and checked afterwards, and merging would lose one of the two
 * roots of a grazing ray. */
static int patch_quadratic(const double *A, const double *B, const double *C,
                           const double *D, const double *m, double w[2])
{
    double qa = A[0] * C[1] - A[1] * C[0], qam = 2 * m[0] * m[2];
    double qb = A[0] * D[1] + B[0] * C[1] - A[1] * D[0] - B[1] * C[0];
    double qbm = 2 * (m[0] * m[3] + m[1] * m[2]);
    double qc = B[0] * D[1] - B[1] * D[0], qcm = 2 * m[1] * m[3];
    return geom_quadratic(qa, qb, qc, TOUCH * (qbm * qbm + 4 * qam * qcm), 0, w);
}

/* The slab of a bilinear patch: its points are convex combinations of its
 * corners, so the patch lies between the two planes normal to any vector
 * n that pass through its lowest and its highest corner along n (here n
 * is the cross product of the diagonals, a flat patch's normal, whose slab
 * is then as thin as rounding leaves it). A ray that starts beyond the
 * slab and heads away from it meets no point of the patch at any t >= 0.
 * Both are decided with margins that cover the rounding of the dot
 * products (each within 2^-50 of the magnitudes it sums; the margins are
 * 2^-45 of upper bounds of them, norms taken as sums of |components|):
 * the start beyond the slab by more than that, the direction's component
 * along n positive (negative) by more than that, so a ray that only
 * rounding would call parallel goes to the general solve. Shadow rays
 * leaving a floor start so (a few 1e-9 above it), and so do those leaving
 * the objects that stand on it: in the gallery they made 8 % of the
 * frame's instructions, each solving two quadratics and polishing two
 * candidates. The general solve (patch_solve) accepts a candidate within
 * 1e-7 of the patch's size of the ray, so it could in principle call a
 * near miss at t > 0 a hit; on the 144,000 rays of test_geom_same_bits
 * (rays leaving patches from 0 to 1e-3 of their size off them at down to
 * 1e-9 radians among them) it never does: the two give the same bits. */
static double l1(vec3 a)                /* >= |a|: margins without a sqrt */
{
    return fabs(a.x) + fabs(a.y) + fabs(a.z);
}

static bool patch_slab_misses(const vec3 p[4], const ray *r)
{
    if (!(r->tmin >= 0))
        return false;
    vec3 n = v3_cross(v3_sub(p[3], p[0]), v3_sub(p[2], p[1]));
    double nn = l1(n), mag = l1(p[0]) + l1(r->o);
    if (!(nn > 0) || !isfinite(nn))
        return false;
    double lo = 0, hi = 0;               /* corner 0 is the slab's origin */
    for (int i = 1; i < 4; i++) {
        vec3 q = v3_sub(p[i], p[0]);
        double h = v3_dot(n, q);
        lo = h < lo ? h : lo;            /* finite: n is */
        hi = h > hi ? h : hi;
        mag += l1(q);
    }
    vec3 q = v3_sub(r->o, p[0]);
    double e = 0x1p-45 * nn * (mag + l1(q)), ed = 0x1p-45 * nn * l1(r->d);
    double s0 = v3_dot(n, q), sd = v3_dot(n, r->d);
    if (!isfinite(s0) || !isfinite(sd) || !isfinite(e))
        return false;
    return (s0 > hi + e && sd > ed) || (s0 < lo - e && sd < -ed);
}

static double patch_size(const vec3 p[4], const ray *r)
{
    double size = 0;
    for (int i = 1; i < 4; i++)
        size = fmax(size, v3_length(v3_sub(p[i], p[0])));
    return size + v3_length(v3_sub(p[0], r->o));
}

/* Two planes through the ray, n1 and n2 (orthonormal, both normal to d):
 * n_k . (P(u,v) - o) = A_k uv + B_k u + C_k v + D_k = 0. Eliminating u
 * gives a quadratic in v, eliminating v one in u; the candidates of both
 * cover the cases where one elimination degenerates. */
static bool patch_solve(const geom_surface *s, const ray *r, double size, geom_hit *hit)
{
    const vec3 *p = s->verts;
    patch pt = { p[0], v3_sub(p[1], p[0]), v3_sub(p[2], p[0]),
                 v3_add(v3_sub(p[3], p[1]), v3_sub(p[0], p[2])) };
    vec3 d = r->dn;
    vec3 any = fabs(d.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    vec3 n1 = v3_normalize(v3_cross(d, any)), n2 = v3_cross(d, n1);
    double A[2], B[2], C[2], D[2];
    for (int k = 0; k < 2; k++) {
        vec3 n = k == 0 ? n1 : n2;
        A[k] = v3_dot(n, pt.a);
        B[k] = v3_dot(n, pt.b);
        C[k] = v3_dot(n, pt.c);
        D[k] = v3_dot(n, v3_sub(pt.p00, r->o));
    }
    geom_hit best = { INFINITY, 0, 0 };
    double w[2], x;
    double mv[4] = { v3_length(pt.a), v3_length(pt.b), v3_length(pt.c),
                     v3_length(v3_sub(pt.p00, r->o)) };
    double mu[4] = { mv[0], mv[2], mv[1], mv[3] };
    int n = patch_quadratic(A, B, C, D, mv, w);
    for (int i = 0; i < n; i++)                  /* v known, u from it */
        if (solve_other(A, B, C, D, w[i], &x))
            patch_candidate(&pt, r, x, w[i], size, &best);
    n = patch_quadratic(A, C, B, D, mu, w);
    for (int i = 0; i < n; i++)                  /* u known, v from it */
        if (solve_other(A, C, B, D, w[i], &x))
            patch_candidate(&pt, r, w[i], x, size, &best);
    if (!(best.t < INFINITY))
        return false;
    *hit = best;
    return true;
}

static bool hit_patch(const geom_surface *s, const ray *r, geom_hit *hit)
{
    return !patch_slab_misses(s->verts, r) && patch_solve(s, r, patch_size(s->verts, r), hit);
}

bool geom_patch_solve(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                      geom_hit *hit)
{
    ray r;
    return s->kind == GEOM_PATCH && ray_make(o, d, tmin, tmax, &r) &&
           patch_solve(s, &r, patch_size(s->verts, &r), hit);
}

bool geom_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin,
                    double tmax, geom_hit *hit)
{
    ray r;
    if (!ray_make(o, d, tmin, tmax, &r))
        return false;
    switch (s->kind) {
    case GEOM_SPHERE:      return hit_sphere(s, &r, hit);
    case GEOM_DISK:        return hit_disk(s, &r, hit);
    case GEOM_CYLINDER:    return hit_cylinder(s, &r, hit);
    case GEOM_CONE:        return hit_cone(s, &r, hit);
    case GEOM_PARABOLOID:  return hit_paraboloid(s, &r, hit);
    case GEOM_HYPERBOLOID: return hit_hyperboloid(s, &r, hit);
    case GEOM_TORUS:       return hit_torus(s, &r, hit);
    case GEOM_POLYGON:     return hit_polygon(s, &r, hit);
    case GEOM_PATCH:       return hit_patch(s, &r, hit);
    case GEOM_BICUBIC:     return geom_bicubic_intersect(s, o, d, tmin, tmax, hit);
    case GEOM_SUBDIV:      return geom_subdiv_intersect(s, o, d, tmin, tmax, hit);
    case GEOM_NURBS:       return geom_nurbs_intersect(s, o, d, tmin, tmax, hit);
    default:               return false;
    }
}

/* Newton's method on o + t d - P(u,v) = 0 from (t, u, v), for the patches
 * whose hits are refined from a subdivided net (bicubic, NuPatch pieces),
 * run until the steps stop shrinking (near a tangent ray the root is double
 * and the convergence only linear: stopping at a small residual would leave
 * t off by its square root). True when it lands on the surface within
 * 1e-9 of `scale`. */
bool geom_patch_newton(const geom_surface *s, geom_dual_eval_fn eval, vec3 o, vec3 d,
                       double *t, double *u, double *v, double scale)
{
    double last = INFINITY;
    geom_sample g;
    for (int it = 0; it < 60; it++) {
        eval(s, *u, *v, &g);
        vec3 f = v3_sub(v3_add(o, v3_scale(d, *t)), g.P);
        /* [d, -Pu, -Pv] (dt, du, dv) = -f by Cramer's rule */
        vec3 a = d, b = v3_neg(g.dPdu), c = v3_neg(g.dPdv);
        double det = v3_dot(a, v3_cross(b, c));
        if (!(fabs(det) > 0))
            break;
        vec3 r = v3_neg(f);
        double dt = v3_dot(r, v3_cross(b, c)) / det;
        double du = v3_dot(a, v3_cross(r, c)) / det, dv = v3_dot(a, v3_cross(b, r)) / det;
        double step = fabs(du) + fabs(dv) + fabs(dt) * v3_length(d) / scale;
        if (!isfinite(step) || (it > 2 && step > 0.9 * last) || (it > 40 && step > 1e-6))
            break;
        *t += dt, *u += du, *v += dv;
        last = step;
        if (step < 1e-16)
            break;
        if (fabs(*u - 0.5) > 2 || fabs(*v - 0.5) > 2)
            return false;
    }
    eval(s, *u, *v, &g);
    return v3_length(v3_sub(v3_add(o, v3_scale(d, *t)), g.P)) <= 1e-9 * scale;
}

/* The subdivision walk shared by bicubic patches and NuPatch pieces (see
 * geom_patch_walk in surface_internal.h): pop a sub-patch, clip the ray's t
 * range against it, from side 1/8 (1/32 where it may hold two hits) run
 * Newton from its centre, and split into quarters until a transversal
 * sub-patch has given its hit or side 2^-16. */
bool geom_patch_intersect(const geom_patch_walk *w, vec3 o, vec3 d, double tmin, double tmax,
                          geom_hit *hit)
{
    enum { MIN_DEPTH_TRANSVERSAL = 3, MIN_DEPTH = 5, MAX_DEPTH = 16 };
    struct { double u0, v0; int depth; } stack[GEOM_PATCH_STACK];
    stack[0].u0 = stack[0].v0 = 0;
    stack[0].depth = 0;
    int n = 1;
    double best = tmax;
    bool found = false;
    while (n > 0) {
        n--;
        double u0 = stack[n].u0, v0 = stack[n].v0;
        int depth = stack[n].depth;
        double side = ldexp(1, -depth);
        double t0, t1;
        if (!w->clip(w->user, n, tmin, best, &t0, &t1))
            continue;
        /* where the ray crosses the sub-patch transversally (Ng.d keeps one
         * sign) it crosses at most once: a hit found there is its only one */
        bool across = w->transversal(w->user, n);
        if (depth >= (across ? MIN_DEPTH_TRANSVERSAL : MIN_DEPTH)) {
            double u = u0 + side / 2, v = v0 + side / 2;
            geom_sample c;
            w->eval(w->s, u, v, &c);
            double t = v3_dot(v3_sub(c.P, o), d) / v3_dot(d, d);
            double slack = 1e-9;
            bool inside = geom_patch_newton(w->s, w->eval, o, d, &t, &u, &v, w->scale) &&
                          u >= u0 - slack && u <= u0 + side + slack && v >= v0 - slack &&
                          v <= v0 + side + slack && t >= t0 && t <= t1;
            if (inside && t > tmin + 1e-9 * fabs(tmin) && t < best) {
                best = t;
                hit->t = t;
                hit->u = fmin(fmax(u, 0), 1);
                hit->v = fmin(fmax(v, 0), 1);
                found = true;
            }
            if ((inside && across) || depth >= MAX_DEPTH)
                continue;      /* else the sub-patch may hold a nearer hit: split on */
        }
        if (n + 4 > GEOM_PATCH_STACK)
            continue;
        w->split(w->user, n);
        double h = side / 2;
        for (int j = 0; j < 4; j++) {
            int k = w->quarter0_on_top ? 3 - j : j;
            stack[n + j].u0 = u0 + (k & 1) * h;
            stack[n + j].v0 = v0 + (k >> 1) * h;
            stack[n + j].depth = depth + 1;
        }
        n += 4;
    }
    return found;
}
