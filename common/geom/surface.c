/*
 * surface.c: checking a surface's parameters (geom_surface_prepare), its
 * derived constants, its name, and its object-space bounding box.
 *
 * The parameterisations are RenderMan's (RI Specification 3.2, §5.2
 * Quadrics); docs/geometry.md lists them. Validation follows the spec where
 * it is explicit and otherwise rejects what would make the surface empty or
 * degenerate, each time with a one-line reason naming the parameter and its
 * value, so that the scene parser can prefix file:line.
 *
 * The evaluations live in surface_float.c, surface_interval.c and
 * surface_affine.c, the ray intersection in surface_intersect.c, polygons
 * (plane basis, convexity, (u,v) coverage) in surface_polygon.c.
 */
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "geom/subdiv.h"
#include "util/err.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static const char *const kind_names[GEOM__COUNT] = {
    "sphere", "disk", "cylinder", "cone", "paraboloid",
    "hyperboloid", "torus", "polygon", "patch", "bicubic patch",
    "subdivision face", "NuPatch piece",
};

const char *geom_kind_name(geom_kind kind)
{
    if ((int)kind < 0 || kind >= GEOM__COUNT)
        return "unknown";
    return kind_names[kind];
}

/* ---------------------------------------------------------------------- */
/* parameter checks shared by the kinds                                    */
/* ---------------------------------------------------------------------- */

static bool need_finite(const geom_surface *s, const char *name, double x,
                        char *err, size_t errsz)
{
    if (isfinite(x))
        return true;
    return err_set(err, errsz, "%s %s must be a finite number, got %g",
                     geom_kind_name(s->kind), name, x);
}

static bool need_positive(const geom_surface *s, const char *name, double x,
                          char *err, size_t errsz)
{
    if (!need_finite(s, name, x, err, errsz))
        return false;
    if (x > 0)
        return true;
    return err_set(err, errsz, "%s %s must be > 0, got %g",
                     geom_kind_name(s->kind), name, x);
}

/* RI spec §5.2 gives the range's ends in either order: z = zmin + v (zmax
 * - zmin) runs down when zmin > zmax, which (like a negative thetamax)
 * turns the surface inside out ("the sense of a quadric can be reversed by
 * giving negative parameters"). Only equal ends leave nothing. */
static bool need_apart(const geom_surface *s, const char *a_name, double a,
                       const char *b_name, double b, char *err, size_t errsz)
{
    if (!need_finite(s, a_name, a, err, errsz) || !need_finite(s, b_name, b, err, errsz))
        return false;
    if (a != b)
        return true;
    return err_set(err, errsz, "%s %s and %s must differ, both are %g (nothing left)",
                   geom_kind_name(s->kind), a_name, b_name, a);
}

/* |thetamax| in (0, 2 pi]: RI spec §5.2 sweeps at most one revolution. */
static bool need_sweep(const geom_surface *s, char *err, size_t errsz)
{
    double t = s->thetamax;
    if (!need_finite(s, "thetamax", t, err, errsz))
        return false;
    if (t == 0)
        return err_set(err, errsz, "%s thetamax must not be 0", geom_kind_name(s->kind));
    if (fabs(t) > GEOM_TWO_PI * (1 + GEOM_SWEEP_SLACK))
        return err_set(err, errsz,
                         "%s thetamax must be at most 2*pi (360 degrees) in magnitude, got %g",
                         geom_kind_name(s->kind), t);
    return true;
}

static bool need_vec(const geom_surface *s, const char *name, vec3 p, char *err, size_t errsz)
{
    if (isfinite(p.x) && isfinite(p.y) && isfinite(p.z))
        return true;
    return err_set(err, errsz, "%s %s must be finite numbers, got (%g %g %g)",
                     geom_kind_name(s->kind), name, p.x, p.y, p.z);
}

static ia_interval diff(double hi, double lo)
{
    return ia_sub(ia_point(hi), ia_point(lo));
}

/* ---------------------------------------------------------------------- */
/* the kinds                                                               */
/* ---------------------------------------------------------------------- */

/* RI spec §5.2: phimin = asin(zmin/radius) (-90 degrees when zmin <=
 * -radius, 90 when >= radius), phimax likewise. These two doubles then
 * define the sphere; phimin > phimax (zmin > zmax) sweeps down. */
static double sphere_phi(double z, double r)
{
    return z <= -r ? -M_PI_2 : z >= r ? M_PI_2 : asin(z / r);
}

static bool prepare_sphere(geom_surface *s, char *err, size_t errsz)
{
    double r = s->radius;
    if (!need_positive(s, "radius", r, err, errsz) ||
        !need_apart(s, "zmin", s->zmin, "zmax", s->zmax, err, errsz) || !need_sweep(s, err, errsz))
        return false;
    double lo = fmin(s->zmin, s->zmax), hi = fmax(s->zmin, s->zmax);
    if (lo >= r)
        return err_set(err, errsz, "sphere zmin and zmax must not both be >= radius %g, got "
                       "%g and %g (nothing left)", r, s->zmin, s->zmax);
    if (hi <= -r)
        return err_set(err, errsz, "sphere zmin and zmax must not both be <= -radius %g, got "
                       "%g and %g (nothing left)", -r, s->zmin, s->zmax);
    s->phi0 = sphere_phi(s->zmin, r);
    s->phi1 = sphere_phi(s->zmax, r);
    if (s->phi0 == s->phi1)
        return err_set(err, errsz, "sphere zmin %g and zmax %g are too close", s->zmin, s->zmax);
    s->consts[K_DPHI] = diff(s->phi1, s->phi0);
    return true;
}

static bool prepare_disk(geom_surface *s, char *err, size_t errsz)
{
    return need_positive(s, "radius", s->radius, err, errsz) &&
           need_finite(s, "height", s->height, err, errsz) && need_sweep(s, err, errsz);
}

static bool prepare_cylinder(geom_surface *s, char *err, size_t errsz)
{
    if (!need_positive(s, "radius", s->radius, err, errsz) ||
        !need_apart(s, "zmin", s->zmin, "zmax", s->zmax, err, errsz) || !need_sweep(s, err, errsz))
        return false;
    s->consts[K_DZ] = diff(s->zmax, s->zmin);
    return true;
}

static bool prepare_cone(geom_surface *s, char *err, size_t errsz)
{
    if (!need_finite(s, "height", s->height, err, errsz))
        return false;
    if (s->height == 0)
        return err_set(err, errsz, "cone height must not be 0");
    return need_positive(s, "radius", s->radius, err, errsz) && need_sweep(s, err, errsz);
}

/* RI spec §5.2: r = rmax*sqrt(z/zmax), z = zmin + v*(zmax - zmin) (zmin >
 * zmax runs down: inside out); z >= 0 throughout. */
static bool prepare_paraboloid(geom_surface *s, char *err, size_t errsz)
{
    if (!need_positive(s, "rmax", s->rmax, err, errsz) ||
        !need_positive(s, "zmax", s->zmax, err, errsz) ||
        !need_finite(s, "zmin", s->zmin, err, errsz))
        return false;
    if (s->zmin < 0)
        return err_set(err, errsz, "paraboloid zmin must be >= 0, got %g", s->zmin);
    if (!need_apart(s, "zmin", s->zmin, "zmax", s->zmax, err, errsz) || !need_sweep(s, err, errsz))
        return false;
    s->consts[K_DZ] = diff(s->zmax, s->zmin);
    s->consts[K_PK] = ia_div(ia_sqr(ia_point(s->rmax)), ia_point(s->zmax));
    s->consts[K_PC] = ia_mul_s(ia_mul(s->consts[K_DZ], s->consts[K_PK]), 0.5);
    return true;
}

static bool prepare_hyperboloid(geom_surface *s, char *err, size_t errsz)
{
    vec3 a = s->point1, b = s->point2;
    if (!need_vec(s, "point1", a, err, errsz) || !need_vec(s, "point2", b, err, errsz) ||
        !need_sweep(s, err, errsz))
        return false;
    if (a.x == b.x && a.y == b.y && a.z == b.z)
        return err_set(err, errsz, "hyperboloid point1 and point2 must differ, both are (%g %g %g)",
                         a.x, a.y, a.z);
    if (a.x == 0 && a.y == 0 && b.x == 0 && b.y == 0)
        return err_set(err, errsz, "hyperboloid point1 and point2 both lie on the z axis: "
                         "the surface is a line");
    s->consts[K_D + 0] = diff(b.x, a.x);
    s->consts[K_D + 1] = diff(b.y, a.y);
    s->consts[K_D + 2] = diff(b.z, a.z);
    return true;
}

static bool prepare_torus(geom_surface *s, char *err, size_t errsz)
{
    if (!need_positive(s, "majorradius", s->majorrad, err, errsz) ||
        !need_positive(s, "minorradius", s->minorrad, err, errsz) ||
        !need_apart(s, "phimin", s->phimin, "phimax", s->phimax, err, errsz) ||
        !need_sweep(s, err, errsz))
        return false;
    if (fabs(s->phimax - s->phimin) > GEOM_TWO_PI * (1 + GEOM_SWEEP_SLACK))
        return err_set(err, errsz, "torus phimax - phimin must be at most 2*pi (360 degrees) in "
                       "magnitude, got %g", s->phimax - s->phimin);
    s->consts[K_DPHI] = diff(s->phimax, s->phimin);
    return true;
}

static ia_interval ia_cross_comp(ia_interval ay, ia_interval az, ia_interval by,
                                 ia_interval bz)
{
    return ia_sub(ia_mul(ay, bz), ia_mul(az, by));
}

/* c = a x b over intervals, componentwise slots c[0..2] */
static void ia_cross(const ia_interval *a, const ia_interval *b, ia_interval *c)
{
    c[0] = ia_cross_comp(a[1], a[2], b[1], b[2]);
    c[1] = ia_cross_comp(a[2], a[0], b[2], b[0]);
    c[2] = ia_cross_comp(a[0], a[1], b[0], b[1]);
}

/* Bilinear patch (RI spec §5.3 Patch "bilinear"): P = P00 + u b + v c +
 * uv a. Its Ng = (b + v a) x (c + u a) = b x c + u b x a + v a x c (a x a
 * = 0) is affine in (u,v): kept as three interval vectors. */
static bool prepare_patch(geom_surface *s, char *err, size_t errsz)
{
    if (s->nverts != 4)
        return err_set(err, errsz, "patch needs 4 corners (P00 P10 P01 P11), got %d", s->nverts);
    for (int i = 0; i < 4; i++) {
        char name[16];
        snprintf(name, sizeof name, "corner %d", i);
        if (!need_vec(s, name, s->verts[i], err, errsz))
            return false;
    }
    const vec3 *p = s->verts;
    for (int c = 0; c < 3; c++) {
        ia_interval p00 = ia_point(v3_comp(p[0], c)), p10 = ia_point(v3_comp(p[1], c));
        ia_interval p01 = ia_point(v3_comp(p[2], c)), p11 = ia_point(v3_comp(p[3], c));
        s->consts[K_B + c] = ia_sub(p10, p00);
        s->consts[K_C + c] = ia_sub(p01, p00);
        s->consts[K_A + c] = ia_add(ia_sub(p11, p10), ia_sub(p00, p01));
    }
    ia_cross(&s->consts[K_B], &s->consts[K_C], &s->consts[K_N0]);
    ia_cross(&s->consts[K_B], &s->consts[K_A], &s->consts[K_N1]);
    ia_cross(&s->consts[K_A], &s->consts[K_C], &s->consts[K_N2]);
    double size = 0, area = 0;
    for (int i = 1; i < 4; i++)
        size = fmax(size, v3_length(v3_sub(p[i], p[0])));
    for (int i = K_N0; i < K_N0 + 9; i++)
        area = fmax(area, fmax(fabs(s->consts[i].lo), fabs(s->consts[i].hi)));
    if (!isfinite(size) || !isfinite(area))
        return err_set(err, errsz, "patch corners are too large");
    if (!(area > 1e-12 * size * size))
        return err_set(err, errsz, "patch is degenerate: its corners lie on one line");
    return true;
}

bool geom_surface_prepare(geom_surface *s, char *err, size_t errsz)
{
    if (err && errsz > 0)
        err[0] = '\0';
    switch (s->kind) {
    case GEOM_SPHERE:      return prepare_sphere(s, err, errsz);
    case GEOM_DISK:        return prepare_disk(s, err, errsz);
    case GEOM_CYLINDER:    return prepare_cylinder(s, err, errsz);
    case GEOM_CONE:        return prepare_cone(s, err, errsz);
    case GEOM_PARABOLOID:  return prepare_paraboloid(s, err, errsz);
    case GEOM_HYPERBOLOID: return prepare_hyperboloid(s, err, errsz);
    case GEOM_TORUS:       return prepare_torus(s, err, errsz);
    case GEOM_POLYGON:     return geom_polygon_prepare(s, err, errsz);
    case GEOM_PATCH:       return prepare_patch(s, err, errsz);
    case GEOM_BICUBIC:     return geom_bicubic_prepare(s, err, errsz);
    case GEOM_SUBDIV:
        if (!s->subdiv || s->subdiv_face < 0 || s->subdiv_face >= geom_subdiv_nfaces(s->subdiv))
            return err_set(err, errsz, "subdivision face without its mesh");
        return true;
    case GEOM_NURBS:       return geom_nurbs_prepare(s, err, errsz);
    default:
        return err_set(err, errsz, "unknown surface kind %d", (int)s->kind);
    }
}

/* ---------------------------------------------------------------------- */
/* bounds                                                                  */
/* ---------------------------------------------------------------------- */

static void grow(vec3 *lo, vec3 *hi, const ia_interval *p)
{
    lo->x = geom_min(lo->x, p[0].lo); hi->x = geom_max(hi->x, p[0].hi);
    lo->y = geom_min(lo->y, p[1].lo); hi->y = geom_max(hi->y, p[1].hi);
    lo->z = geom_min(lo->z, p[2].lo); hi->z = geom_max(hi->z, p[2].hi);
}

/* ia_mul_s(ia_point(x), s), the same bits */
static ia_interval point_times(double x, double s)
{
    ia_interval r;
    return geom_point_product(x, s, &r) ? r : ia_mul_s(ia_point(x), s);
}

/* Polygons: the hull of the vertices (the polygon is their convex hull
 * and P is affine), widened by what geom_uv_inside's tolerance admits.
 * P at each vertex's (u,v) as geom_eval_ia makes it (surface_interval.c's
 * eval_polygon: the same operations on the same numbers), without its
 * dPdu, dPdv and Ng (tests/geom/test_geom_same_bits.c). */
static void polygon_bounds(const geom_surface *s, vec3 *lo, vec3 *hi)
{
    ia_interval P[3];
    for (int i = 0; i < s->nuv; i++) {
        double u = s->uv[i][0], v = s->uv[i][1];
        for (int k = 0; k < 3; k++)
            P[k] = ia_add_s(ia_add(point_times(u, v3_comp(s->axis_u, k)),
                                   point_times(v, v3_comp(s->axis_v, k))),
                            v3_comp(s->origin, k));
        grow(lo, hi, P);
    }
    double pad = 1e-9 * (v3_length(s->axis_u) + v3_length(s->axis_v));
    *lo = v3_sub(*lo, v3(pad, pad, pad));
    *hi = v3_add(*hi, v3(pad, pad, pad));
}

/* The hull of interval enclosures over an 8x8 grid of (u,v) boxes: every
 * point of the surface lies in one box, and each box's enclosure is
 * conservative, so the hull is; the grid keeps the trig ranges tight. */
void geom_bounds(const geom_surface *s, vec3 *lo, vec3 *hi)
{
    *lo = v3(INFINITY, INFINITY, INFINITY);
    *hi = v3(-INFINITY, -INFINITY, -INFINITY);
    if (s->kind == GEOM_POLYGON) {
        polygon_bounds(s, lo, hi);
        return;
    }
    if (s->kind == GEOM_SUBDIV) {       /* the 1-ring's convex hull */
        geom_subdiv_bounds(s, lo, hi);
        return;
    }
    if (s->kind == GEOM_NURBS) {        /* the projected points' convex hull */
        geom_nurbs_bounds(s, lo, hi);
        return;
    }
    if (s->kind == GEOM_BICUBIC) {      /* the control points' convex hull */
        geom_bicubic_bounds(s, lo, hi);
        return;
    }
    enum { N = 8 };
    geom_ia box;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            ia_interval u = ia_make((double)i / N, (double)(i + 1) / N);
            ia_interval v = ia_make((double)j / N, (double)(j + 1) / N);
            geom_eval_ia(s, u, v, &box);
            grow(lo, hi, box.P);
        }
}
