/*
 * subdiv_internal.h: what the Catmull-Clark files share (subdiv_mesh.c
 * builds, subdiv_refine.c refines, subdiv_eval.c evaluates): the mesh in
 * face-corner form and one Catmull-Clark step with DeRose's sharpness
 * rules.
 */
#ifndef GEOM_SUBDIV_INTERNAL_H
#define GEOM_SUBDIV_INTERNAL_H

#include <stdatomic.h>

#include "geom/subdiv.h"

/* A polygon mesh with sharpness: face f has corners fo[f] .. fo[f+1]-1,
 * corner c holds the point fv[c] and the sharpness es[c] of the edge from
 * fv[c] to the next corner's point. vs[i]: corner sharpness of point i.
 * INFINITY is infinitely sharp. The arrays belong to whoever made the
 * mesh (heap for the shared mesh, fixed buffers for local refinement). */
typedef struct sd_mesh {
    int nv, nf;
    vec3 *P;
    double *vs;
    int *fo;                       /* nf + 1 */
    int *fv;
    double *es;
} sd_mesh;

/* One step: out's arrays must hold its sizes: points nv + nf + nedges
 * (nedges <= corners), faces = corners of m, corners = 4 * corners of m. New points: the
 * vertex points of m's points (same indices), then face points (nv + f),
 * then edge points. Child faces are quads, one per corner, in corner
 * order; a quad parent's child k covers the parent's quadrant k (0:
 * [0,.5]^2, 1: u >= .5, 2: both >= .5, 3: v >= .5) with the parent's
 * u, v directions (face corners 0..3 = (0,0) (1,0) (1,1) (0,1)).
 * Points whose 1-ring is not complete in m get some value (unused). */
void sd_refine(const sd_mesh *m, sd_mesh *out);

typedef struct sd_node sd_node;    /* subdiv_cache.c */

/* The mesh a worker keeps (issue 23: a few bytes a control face): the
 * control mesh and its point -> faces table, and per face of the refined
 * mesh (level 1, all quads: face f is the child of control corner f) one
 * byte of flags. The refined mesh itself is not kept: the 1-ring of a
 * refined face is made when it is asked for (sd_local_from_shared,
 * subdiv_mesh.c) by refining the control faces around its control face,
 * the same steps in the same order as refining the whole mesh, so it is
 * the same to the bit; a regular face's Bezier net is made with its
 * surface (geom_subdiv_surface) and travels in it. */
enum { SD_DRAWN = 1, SD_REGULAR = 2 };

struct geom_subdiv {
    unsigned long serial;          /* a number of its own (subdiv_mesh.c's ring cache) */
    sd_mesh m0;                    /* the control mesh (vs, es NULL when all 0) */
    bool faces_shared;             /* m0.fo, m0.fv are the caller's
                                    * (geom_subdiv_share_faces): not freed */
    int nf1;                       /* refined faces (control corners) */
    int *vf_off, *vf;              /* control point -> faces holding it (CSR, ascending) */
    int maxval;                    /* the largest valence of the refined mesh (>= 4):
                                    * local meshes' sizes */
    double pmax;                   /* the largest |coordinate| of a control point:
                                    * the refinement's rounding (subdiv_ev.c's rings) */
    unsigned char *flags;          /* per refined face: SD_DRAWN, SD_REGULAR */
    int *irr_base;                 /* per 64 refined faces: drawn irregular faces before */
    int nirr;
    _Atomic(sd_node *) *roots;     /* per drawn irregular face (by rank): its local
                                    * refinements (subdiv_cache.c) */
};

/* The rank of drawn irregular face f among them (its slot in roots). */
int sd_irregular_rank(const geom_subdiv *sd, int f);

/* The per-face trees of subdiv_cache.c: made empty, freed with the mesh. */
void sd_cache_init(geom_subdiv *sd);
void sd_cache_clear(geom_subdiv *sd);

#endif
