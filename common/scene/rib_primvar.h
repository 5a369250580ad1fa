/*
 * rib_primvar.h: primitive variables of meshes and patches (RI
 * Specification 3.2 §5.1, "Primitive variables"): the parameters of a
 * primitive other than its points, their storage class (declared, or told
 * by the count), and their value over each object the primitive becomes
 * (scene_primvar: linear over a triangle, bilinear over a patch).
 */
#ifndef SCENE_RIB_PRIMVAR_H
#define SCENE_RIB_PRIMVAR_H

#include "scene/rib_parser.h"

/* One primitive variable as given: its values, which class indexes them
 * and where one value's components sit (st gives two: s, offset 0, and t,
 * offset 1, stride 2). */
typedef struct rib_primvar_src {
    char name[64];
    sl_type type;
    scene_class cls;               /* resolved: never SCENE_CLASS_NONE */
    const double *values;
    int size, stride, offset;
} rib_primvar_src;

/* The most variables one primitive hands to shaders (st counts two). */
enum { RIB_MAX_PRIMVARS = SCENE_MAX_PRIMVARS };

typedef struct rib_primvars {
    rib_primvar_src *v;
    int n;
} rib_primvars;

/* Where a corner of an object sits in each class's values: the face
 * (uniform), the point (varying and vertex on meshes; a patch's corner
 * for varying), the control point (vertex) and the face corner
 * (facevarying). */
typedef struct rib_corner {
    int uniform, varying, vertex, facevarying;
} rib_corner;

/* The primitive variables of params other than "P", "Pw", "Pz", "N" and
 * those listed in `skip` (NULL-terminated, may be NULL). counts[class] is
 * how many values each class takes for this primitive (0: the class is
 * not available, e.g. facevarying on a patch). A declared class must have
 * its count; an undeclared one is told by the count (vertex, varying,
 * facevarying, uniform, constant: first match). A count that fits nothing
 * is an error naming the variable (false); strings, matrices and arrays
 * other than "st" get one warning per request and are left out. */
bool rib_primvars_collect(rib_parser *p, const rib_request *req, const rib_params *params,
                          const int counts[SCENE_CLASS_FACEVARYING + 1],
                          const char *const *skip, rib_primvars *out);
void rib_primvars_clear(rib_primvars *pv);

/* Whether every variable has one value at all n corners (the face may
 * stay one polygon, its variables constant). */
bool rib_primvars_same_at(const rib_primvars *pv, const rib_corner *c, int n);

/* The variables over a triangle whose corners c[i] sit at (u,v) = uv[i]
 * of its parametrisation: linear in (u,v). out gets pv->n entries.
 * False when the triangle has no area in (u,v). */
bool rib_primvars_triangle(const rib_primvars *pv, const rib_corner c[3],
                           const double uv[3][2], scene_primvar *out);

/* The variables over a flat polygon of n corners c[i] at (u,v) = uv[i]:
 * constant where every one has one value at all corners
 * (rib_primvars_constant), else linear in (u,v), as over a triangle,
 * where every one is affine there (the plane of three corners holds the
 * others to 1e-12 of the values' size). False (out undefined) where one
 * is not, or uv is NULL (corners without their own (u,v)) and one varies:
 * the face is cut into triangles. */
bool rib_primvars_polygon(const rib_primvars *pv, const rib_corner *c, const double (*uv)[2],
                          int n, scene_primvar *out);

/* The corner of a flat polygon's n corners c[i] whose edge to the next
 * runs most nearly along s or t ("st", or "s" and "t": the largest of
 * |ds|, |dt| over |ds| + |dt|; the first of equals), where both are
 * given; else 0. A polygon's (u,v) run along its first edge: started
 * there, its quadtree's cells run along the patterns of s and t (a
 * triangle of a wall whose first edge is the quad's diagonal has cells at
 * 45 degrees to its bricks). */
int rib_primvars_st_edge(const rib_primvars *pv, const rib_corner *c, int n);

/* The variables over a patch, corners c[0..4) at (u,v) = (0,0), (1,0),
 * (0,1), (1,1): bilinear. */
void rib_primvars_bilinear(const rib_primvars *pv, const rib_corner c[4], scene_primvar *out);

/* The mean of every variable over corners c[0..n): out[variable][component]. */
void rib_primvars_mean(const rib_primvars *pv, const rib_corner *c, int n,
                       double out[RIB_MAX_PRIMVARS][3]);

/* The variables over a patch from their values at its corners (0,0),
 * (1,0), (0,1), (1,1) (vals[corner] as rib_primvars_mean gives them). */
void rib_primvars_bilinear_values(const rib_primvars *pv,
                                  double vals[4][RIB_MAX_PRIMVARS][3], scene_primvar *out);

/* The vertex-class variables over a bicubic patch whose control point
 * (u index k, v index l) is value idx[4 l + k], with the basis matrices mu,
 * mv (rows as in the RI Spec: P = U Mu G Mv^T V^T, U = [u^3 u^2 u 1]):
 * their bicubic polynomials replace out[i] for those variables only. */
void rib_primvars_bicubic(const rib_primvars *pv, const int idx[16], const double mu[16],
                          const double mv[16], scene_primvar *out);

/* The variables constant over an object: their values at corner c. */
void rib_primvars_constant(const rib_primvars *pv, const rib_corner *c, scene_primvar *out);

#endif
