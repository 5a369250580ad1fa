/*
 * surface.h: the base surfaces of aafarm (RenderMan's quadrics, convex
 * planar polygons and bilinear patches) as parametric surfaces P(u,v) over
 * the unit square (also bicubic patches, subdivision faces and NuPatch
 * pieces), evaluated in four arithmetics:
 *
 *   float     P, dPdu, dPdv, Ng at one (u,v)                (shading)
 *   dual      the same plus the (u,v)-derivatives of Ng     (calculatenormal
 *             of a displaced point needs d/du and d/dv of N)
 *   interval  conservative enclosures over a (u,v) box      (--arith interval)
 *   affine    affine forms over a (u,v) box, u and v being  (Heidrich-Seidel
 *             the two input noise symbols                   §3, §4)
 *
 * plus exact ray intersection for surfaces that carry no displacement, and
 * an object-space bounding box of the undisplaced surface.
 *
 * Parameterisations are RenderMan's (RI Specification 3.2, §5.2 Quadrics):
 * theta = u * thetamax, and v sweeps phi / z / the radius as the spec says.
 * All angles here are in RADIANS (the scene parser converts RIB degrees).
 * Ng = dPdu x dPdv (not normalised), which points outward for the quadrics
 * with their default parameters; for polygons it follows the vertex order
 * (Newell's normal). Everything is in object space.
 *
 * Conservative means: for every (u,v) in the box, the exact real value of
 * P(u,v) (and dPdu, dPdv, Ng) lies inside the interval / affine result,
 * floating-point rounding included (common/aa guarantees its operations).
 */
#ifndef GEOM_SURFACE_H
#define GEOM_SURFACE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "util/vecmath.h"

typedef enum geom_kind {
    GEOM_SPHERE,        /* radius zmin zmax thetamax */
    GEOM_DISK,          /* height radius thetamax */
    GEOM_CYLINDER,      /* radius zmin zmax thetamax */
    GEOM_CONE,          /* height radius thetamax */
    GEOM_PARABOLOID,    /* rmax zmin zmax thetamax */
    GEOM_HYPERBOLOID,   /* point1 point2 thetamax */
    GEOM_TORUS,         /* majorradius minorradius phimin phimax thetamax */
    GEOM_POLYGON,       /* convex planar polygon, nverts >= 3 */
    GEOM_PATCH,         /* bilinear patch, 4 corners in RIB order */
    GEOM_BICUBIC,       /* bicubic Bezier patch, 16 control points, u fastest */
    GEOM_SUBDIV,        /* a face of a Catmull-Clark mesh (geom/subdiv.h) */
    GEOM_NURBS,         /* a rational Bezier piece of a NuPatch (geom/nurbs.h) */
    GEOM__COUNT
} geom_kind;

enum { GEOM_MAX_POLY_VERTS = 64 };
enum { GEOM_NCONST = 18 };             /* size of geom_surface.consts (added) */

typedef struct geom_surface {
    geom_kind kind;
    double radius, zmin, zmax, thetamax;   /* sphere, cylinder, disk, cone, paraboloid */
    double height;                         /* disk, cone */
    double rmax;                           /* paraboloid */
    double majorrad, minorrad, phimin, phimax;   /* torus (radians) */
    vec3 point1, point2;                   /* hyperboloid */
    /* polygon: vertices; patch: corners P00 P10 P01 P11 (RIB order);
     * bicubic: Bezier control points P_ij at verts[4 j + i] */
    int nverts;
    vec3 verts[GEOM_MAX_POLY_VERTS];
    /* triangle polygons only: corner normals vn[i] at verts[i] (nvn = 3), or
     * none (nvn = 0, the shading normal is Ng); see geom_vertex_normal */
    int nvn;
    vec3 vn[3];
    /* derived by geom_surface_prepare (do not set by hand) */
    double phi0, phi1;                     /* sphere: phi range of zmin/zmax */
    vec3 origin, axis_u, axis_v, normal;   /* polygon: P = origin + u*axis_u + v*axis_v */
    /* added by the geom implementation (also derived by prepare): */
    int nuv;                               /* polygon: distinct vertices, ... */
    double uv[GEOM_MAX_POLY_VERTS][2];     /* ... their (u,v), counter-clockwise */
    double edge[GEOM_MAX_POLY_VERTS][3];   /* edge i: a*u + b*v + c >= 0 inside (unit (a,b)) */
    ia_interval consts[GEOM_NCONST];       /* enclosures of exact derived constants
                                            * (zmax - zmin, ...) for the interval and
                                            * affine evaluations; see surface_internal.h */
    /* GEOM_SUBDIV: the mesh (shared by its faces, owned by whoever built it,
     * geom/subdiv.h) and the face of its refined mesh; made with the surface
     * (geom_subdiv_surface): a regular face's Bezier net in verts (nverts =
     * 16, else 0) and the hull of its 1-ring */
    const struct geom_subdiv *subdiv;
    int subdiv_face;
    vec3 subdiv_lo, subdiv_hi;
    /* GEOM_NURBS: the NuPatch (shared by its pieces, owned by whoever built
     * it, geom/nurbs.h) and the piece */
    const struct geom_nurbs *nurbs;
    int nurbs_piece;
} geom_surface;

/* Float evaluation at one (u,v). */
typedef struct geom_sample {
    vec3 P, dPdu, dPdv, Ng;
    vec3 dNgdu, dNgdv;     /* filled by geom_eval_dual only */
} geom_sample;

/* Checks the parameters (finite numbers, radius > 0, zmin != zmax (either
 * order: RI spec §5.2, zmin > zmax turns the surface inside out),
 * thetamax != 0, polygon convex and planar with >= 3 distinct vertices,
 * ...), fills the derived fields. On failure returns false and writes a
 * one-line reason ("sphere radius must be > 0, got -1") into err. */
bool geom_surface_prepare(geom_surface *s, char *err, size_t errsz);

/* A polygon's plane basis alone (a mesh's pass over its pieces' bounds
 * and edges, trace/world.c): origin, axis_u, axis_v, normal, nuv and uv,
 * the same bits geom_surface_prepare gives them; nothing else is derived
 * (no edge lines, no enclosures, no corner normals) and the polygon is
 * not checked for planarity or convexity: for a polygon that
 * geom_surface_prepare has accepted. False (err) when it has fewer than 3
 * distinct finite vertices or no area. */
bool geom_polygon_basis(geom_surface *s, char *err, size_t errsz);

/* Whether geom_surface_prepare accepts polygon s, which has no corner
 * normals (nvn = 0), and the same message when not; with its basis,
 * (u,v) and edge lines as the prepare makes them, but not the enclosures
 * of Ng (s->consts), which a mesh's parse never reads (rib_mesh.c): s is
 * not prepared for evaluation. */
bool geom_polygon_check(geom_surface *s, char *err, size_t errsz);

const char *geom_kind_name(geom_kind kind);    /* "sphere", "disk", ... */

void geom_eval(const geom_surface *s, double u, double v, geom_sample *out);
void geom_eval_dual(const geom_surface *s, double u, double v, geom_sample *out);
/* geom_eval's P alone, the same bits, without the derivatives where a
 * kind allows it (bicubic patches and subdivision faces: 1 tensor sum of
 * the 6; a view's grid spacing evaluates 81 points) */
vec3 geom_eval_point(const geom_surface *s, double u, double v);

/* Enclosures over the box [u0,u1] x [v0,v1]. */
typedef struct geom_ia { ia_interval P[3], dPdu[3], dPdv[3], Ng[3]; } geom_ia;
void geom_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);
/* The same, tighter and dearer where a kind allows it (a bicubic patch:
 * met with the bounds of its piece over the box as a Bezier net of its
 * own), for the few evaluations that need it (hit proofs' slopes) */
void geom_eval_ia_tight(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out);

/* u and v are affine forms the caller made with aa_input (so they own the
 * query's first two noise symbols); results share them. */

typedef struct geom_aa { aa_form P[3], dPdu[3], dPdv[3], Ng[3]; } geom_aa;
void geom_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                  const aa_form *v, geom_aa *out);

/* aa_range of geom_eval_aa's P over the box, without the forms where a
 * kind allows it (bicubic patches and regular subdivision sub-patches:
 * the hull of the piece's Bezier net, which the forms' range holds, so
 * the same bits; where only a box is wanted: a mesh piece's base box) */
void geom_eval_aa_range_P(aa_context *ctx, const geom_surface *s, const aa_form *u,
                          const aa_form *v, ia_interval P[3]);

/* The UNIT normal Ng/|Ng| over the box (surface_normal.c), in closed form
 * where one exists (sphere, torus, disk, cylinder, cone, polygon), so that
 * it stays bounded where Ng vanishes (the poles of a sphere, the centre of
 * a disk, the apex of a cone); elsewhere Ng normalised in the same
 * arithmetic. `g` is the result of geom_eval_aa / geom_eval_ia for the same
 * box. Where Ng = 0 the unit normal is the limit the closed form gives. */
void geom_unit_normal_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                         const aa_form *v, const geom_aa *g, aa_form Nn[3]);
void geom_unit_normal_ia(const geom_surface *s, ia_interval u, ia_interval v,
                         const geom_ia *g, ia_interval Nn[3]);
/* The normal the point path (float and dual) gives a shader at one (u,v),
 * and its (u,v)-derivatives, not of unit length: Ng and dNg/du, dNg/dv of
 * g (geom_eval_dual's result at the same (u,v)) where Ng != 0. */
void geom_normal_dual(const geom_surface *s, double u, double v, const geom_sample *g,
                      vec3 *N, vec3 *dNdu, vec3 *dNdv);
/* Bounds of d/du and d/dv of that unit normal over the box, from the
 * same closed forms (sphere, cylinder, cone, torus, disk, polygons with
 * or without vertex normals, bilinear patches) or the second derivatives
 * (bicubic patches); false for the other kinds and where the normal's
 * length may vanish. */
bool geom_unit_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                const geom_ia *g, ia_interval dNdu[3], ia_interval dNdv[3]);

/* Vertex normals (meshes, surface_vertex_normal.c). A triangle polygon
 * with nvn = 3 has the shading normal N(u,v) = the linear interpolation of
 * its corner normals vn[] (barycentric in the triangle, extended linearly
 * over the (u,v) rectangle): N = C + A u + B v. Along an edge it depends
 * only on that edge's two corners, so faces that share the edge and its
 * corner normals agree there (displacement along N stays continuous).
 * geom_vertex_normal gives N and its (u,v)-derivatives A, B (not
 * normalised) and returns true, or returns false for surfaces without
 * vertex normals. geom_unit_normal_aa/_ia give N/|N| for such surfaces. */
bool geom_has_vertex_normals(const geom_surface *s);
bool geom_vertex_normal(const geom_surface *s, double u, double v, vec3 *N, vec3 *dNdu,
                        vec3 *dNdv);

/* Polygons only cover part of their (u,v) rectangle. For the other kinds
 * these say "inside" everywhere. */
typedef enum geom_cover { GEOM_OUTSIDE, GEOM_PARTIAL, GEOM_INSIDE } geom_cover;
bool geom_uv_inside(const geom_surface *s, double u, double v);
geom_cover geom_uv_box_cover(const geom_surface *s, double u0, double u1,
                             double v0, double v1);
/* Polygons: whether every point of the (u,v) box lies inside each edge of
 * the set (bit i: edge i, from uv[i] to uv[i+1]), by more than the
 * rounding margin; other kinds: true. */
bool geom_uv_box_clear_of(const geom_surface *s, double u0, double u1, double v0, double v1,
                          uint64_t edges);
/* Polygons: whether (u,v) lies beyond one edge of the set (bit i: edge i),
 * by more than the rounding margin (outside the polygon across it); other
 * kinds: false. */
bool geom_uv_beyond(const geom_surface *s, double u, double v, uint64_t edges);
/* Polygons: the object-space end points of edge i (corners i and i + 1,
 * after the last the first). */
void geom_polygon_edge(const geom_surface *s, int i, vec3 *a, vec3 *b);
/* Polygons: the object-space point of corner i, at uv[i] (0 <= i < nuv). */
vec3 geom_polygon_corner(const geom_surface *s, int i);

/* Object-space bounds of the undisplaced surface (conservative). */
void geom_bounds(const geom_surface *s, vec3 *lo, vec3 *hi);

/* Exact intersection of the undisplaced surface with the ray o + t d
 * (object space), nearest t in (tmin, tmax). Fills t, u, v. Partial sweeps
 * (thetamax, zmin/zmax, phimin/phimax) are honoured. */
typedef struct geom_hit { double t, u, v; } geom_hit;
bool geom_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin,
                    double tmax, geom_hit *hit);

#endif
