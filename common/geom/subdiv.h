/*
 * subdiv.h: Catmull-Clark subdivision surfaces (RI Specification 3.2
 * §5.5, SubdivisionMesh "catmull-clark") as base surfaces of common/geom.
 *
 * A geom_subdiv is one mesh, shared by all its faces: the control mesh
 * refined once (so every face is a quad), with the tags applied (crease
 * and corner sharpness as in DeRose, Kass & Truong 1998: semi-sharp
 * sharpness decays by 1 per level; boundary edges are infinitely sharp
 * with "interpolateboundary"; hole faces are kept as control but not
 * drawn). Each drawable face of that mesh is one geom_surface of kind
 * GEOM_SUBDIV pointing at the mesh (subdiv, subdiv_face), so a face costs
 * no copy of control points. The refined mesh is not kept: what lasts is
 * the control mesh and a byte a refined face (subdiv_internal.h); a face's
 * 1-ring and Bezier net are made again, the same to the bit, when its
 * surface is made.
 *
 * The surface of a face is its exact Catmull-Clark limit over the unit
 * square (u along the face's first edge, v along its last): where the
 * face's 1-ring is regular it is a uniform bicubic B-spline patch (boundary
 * and infinitely sharp crease edges by mirrored "ghost" points); elsewhere
 * the 1-ring is refined locally until the point or (u,v) box falls in a
 * regular sub-patch (subdiv_eval.c). Docs: docs/geometry.md.
 */
#ifndef GEOM_SUBDIV_H
#define GEOM_SUBDIV_H

#include <stdbool.h>
#include <stddef.h>

#include "geom/surface.h"

/* A SubdivisionMesh as the RIB gives it (all indices checked by the
 * caller to be in range). Tags: creases are vertex chains with one
 * sharpness each; corners are vertices with a sharpness each; holes are
 * face indices. Sharpness >= GEOM_SUBDIV_INFINITE (10) is infinitely
 * sharp, as in RenderMan. */
typedef struct geom_subdiv_desc {
    int nfaces;
    const int *nverts;             /* per face, >= 3 */
    const int *verts;              /* sum(nverts) point indices */
    int npoints;
    const double *P;               /* 3 * npoints */
    int ncreases;
    const int *crease_len;         /* points per chain (>= 2) */
    const int *crease_verts;       /* the chains, concatenated */
    const double *crease_sharp;    /* one per chain */
    int ncorners;
    const int *corner_verts;
    const double *corner_sharp;    /* one per corner */
    int nholes;
    const int *holes;
    bool interpolateboundary;
} geom_subdiv_desc;

#define GEOM_SUBDIV_INFINITE 10.0

typedef struct geom_subdiv geom_subdiv;

/* Builds the mesh; NULL with a one-line reason in err (a non-manifold
 * edge, faces that disagree on orientation, ...; any valence and any
 * face size are taken). */
geom_subdiv *geom_subdiv_new(const geom_subdiv_desc *desc, char *err, size_t errsz);
void geom_subdiv_destroy(geom_subdiv **self_p);

/* Faces of the refined mesh, and whether face f is drawn: not a hole and
 * (without interpolateboundary) not touching the boundary. */
int geom_subdiv_nfaces(const geom_subdiv *self);
bool geom_subdiv_face_drawn(const geom_subdiv *self, int f);
/* The control face (of the RIB's faces) that refined face f comes from. */
int geom_subdiv_face_origin(const geom_subdiv *self, int f);

/* The points of refined face f in its corner order ((u,v) = (0,0),
 * (1,0), (1,1), (0,1)), as indices of the refined mesh (its first
 * npoints points are the control points' vertex points). */
void geom_subdiv_face_points(const geom_subdiv *self, int f, int out[4]);

/* A GEOM_SUBDIV surface for face f (prepared): its 1-ring is made again
 * from the control mesh, and so is its Bezier net where the face is regular
 * (a pure function of the cage: the same bits each time). */
void geom_subdiv_surface(const geom_subdiv *self, int f, geom_surface *out);

/* The control faces' corner offsets (nfaces + 1, from 0: face f's corners
 * are fo[f] .. fo[f + 1] - 1) and points (the desc's verts) read from
 * the caller's arrays from now on instead of the mesh's own copies
 * (issue 23: 20 bytes a quad face): they must hold the same values (an
 * assert) and outlive the mesh. */
void geom_subdiv_share_faces(geom_subdiv *self, const int *fo, const int *verts);

/* The bytes the mesh holds (its irregular faces' trees of local
 * refinements, grown while rendering, not counted), and of them (*points)
 * its control points. */
size_t geom_subdiv_bytes(const geom_subdiv *self, size_t *points);

/* Bounds of d/du, d/dv of the unit normal over the box where it lies in
 * one regular sub-patch (a bicubic's, surface_bicubic.c); false
 * elsewhere (near an extraordinary point, a crease's irregular corner) */
bool geom_subdiv_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                  ia_interval dNdu[3], ia_interval dNdv[3]);

/* The unit normal over the (u,v) box of a GEOM_SUBDIV surface where its
 * Ng cannot bound it (an irregular sub-face): true and Nn when the box
 * lies in one irregular sub-face whose normal is proven constant
 * (subdiv_cache.c); false otherwise ([-1,1]^3 is all that is known). */
bool geom_subdiv_unit_normal_box(const geom_surface *s, ia_interval u, ia_interval v,
                                 ia_interval Nn[3]);

/* The limit position of control point i (after the tags), for tests:
 * refines around it until no semi-sharp tag is left and applies the limit
 * mask of its rule (smooth, crease or corner). */
bool geom_subdiv_limit_point(const geom_subdiv *self, int point, vec3 *out);

#endif
