/*
 * subdiv_local.h: a face of a Catmull-Clark mesh with its 1-ring, copied
 * into fixed buffers (no allocation while rendering), refined locally
 * (subdiv_eval.c), tested for regularity and turned into a bicubic Bezier
 * net where regular (subdiv_regular.c). Face 0 of a local mesh is the face
 * of interest; the other faces are those that touch its corners.
 */
#ifndef GEOM_SUBDIV_LOCAL_H
#define GEOM_SUBDIV_LOCAL_H

#include "geom/subdiv_internal.h"

enum { SD_MAX_LEVEL = 48 };       /* local refinement stops here */
/* The normal of an irregular sub-face is checked on its rings down to
 * this level (below it the nets near a crease vertex of valence 3 are
 * slivers narrower than the hodographs' padding for rounding); a deeper
 * sub-face takes its ancestor's at level SD_SIGN_LEVEL - 1
 * (subdiv_cache.c). */
enum { SD_SIGN_LEVEL = 16 };

/* A local mesh's sizes follow the largest valence of the level-1 mesh it
 * comes from (geom_subdiv.maxval: a point's faces, or a control face's
 * points, at least 4); refinement keeps every valence, so the sizes hold
 * at every level. */
static inline int sd_lf(int maxval) { return 4 * maxval; }     /* faces touching a quad's corners */
static inline int sd_lc(int maxval) { return 16 * maxval; }    /* their corners (quads) */
static inline int sd_lv(int maxval) { return sd_lc(maxval); }  /* their points */

typedef struct sd_local {
    sd_mesh m;
    int maxval;
    vec3 *P;                       /* sd_lv */
    double *vs;                    /* sd_lv */
    int *fo;                       /* sd_lf + 1 */
    int *fv;                       /* sd_lc */
    double *es;                    /* sd_lc */
    int *list, *src;               /* scratch: sd_lf faces, sd_lv points */
} sd_local;

/* After one refinement step (sd_local_child's scratch). */
typedef struct sd_big {
    sd_mesh m;
    vec3 *P;                       /* points + face points + edge points */
    double *vs;
    int *fo;
    int *fv;
    double *es;
} sd_big;

void sd_local_init(sd_local *L, int maxval);
void sd_local_clear(sd_local *L);
void sd_big_init(sd_big *big, int maxval);
void sd_big_clear(sd_big *big);

/* Copies faces list[0..n) of M into L (list[0] becomes face 0). */
void sd_local_take(sd_local *L, const sd_mesh *M, const int *list, int n);

/* Face f of the refined mesh with its 1-ring (L made with sd->maxval),
 * made again from the control mesh (subdiv_mesh.c). */
void sd_local_from_shared(const geom_subdiv *sd, int f, sd_local *L);

/* The control faces around control face F (those sharing a point with
 * it) and their refinement, from which the 1-rings of F's children are
 * copied (sd_ring_child: child k, of F's corner k): subdiv_mesh.c. */
typedef struct sd_ring {
    sd_mesh ctl, ref;              /* the control faces, and refined */
    int base;                      /* F's first corner in ctl (its children in ref) */
    int *list;                     /* scratch: a child's faces */
    int *local;                    /* scratch: ref's points' numbers in a child's
                                    * 1-ring (-1 between children) */
    void *block;                   /* all of the above's arrays */
} sd_ring;

void sd_ring_make(const geom_subdiv *sd, int F, sd_ring *R);
void sd_ring_child(const sd_ring *R, int k, sd_local *L);
void sd_ring_clear(sd_ring *R);

/* The hull of a local mesh's points, padded for the rounding of the
 * refinement (subdiv_eval.c). */
void sd_local_hull(const sd_mesh *m, vec3 *lo, vec3 *hi);

/* Refines L and makes L the child k (quadrant, subdiv_internal.h) of its
 * face 0 with that child's 1-ring. big is scratch. */
void sd_local_child(sd_local *L, int k, sd_big *big);

/* Whether face 0's limit is a uniform bicubic B-spline patch (its 1-ring a
 * 4x4 grid, boundary and infinitely sharp edges by mirrored points); if so
 * its Bezier net (verts[4 j + i] order, u along face 0's first edge). */
bool sd_regular_net(const sd_mesh *L, vec3 net[16]);
/* The same net for a face known to be regular (geom_subdiv's SD_REGULAR
 * flag, found by sd_regular_net): the tests of its corners skipped. */
void sd_known_regular_net(const sd_mesh *L, vec3 net[16]);

/* The limit position of face 0's corner k when no semi-sharp tag touches
 * it (false otherwise): smooth, crease or corner mask. */
bool sd_corner_limit(const sd_mesh *L, int k, vec3 *out);

/* The tree of local refinements of a face (subdiv_cache.c): a node is a
 * sub-face at some level, immutable once built, shared by threads. The
 * root is the face (level 0); child q is quadrant q (subdiv_internal.h),
 * built on first use. */
const sd_node *sd_node_root(const geom_subdiv *sd, int f);
const sd_node *sd_node_child(const sd_node *n, int q);
/* Whether the sub-face is regular, and its Bezier net. */
bool sd_node_regular(const sd_node *n, const vec3 **net);
/* The largest valence of the mesh the node comes from (sd_local_init). */
int sd_node_maxval(const sd_node *n);
/* An irregular sub-face: its 1-ring into L, and the hull of the points its
 * limit depends on (its sectors: no infinitely sharp edge crossed). */
void sd_node_local(const sd_node *n, sd_local *L);
void sd_node_hull(const sd_node *n, vec3 *lo, vec3 *hi);
/* The unit normal of an irregular sub-face's limit where it is proven
 * constant (a planar sector, subdiv_cache.c); false otherwise. */
bool sd_node_unit_normal(const sd_node *n, vec3 *N);
/* The unit normal box of an irregular sub-face at an interior smooth
 * extraordinary point (subdiv_ev.h's proven cone, the ring's rounding from
 * pmax, the mesh's largest |coordinate|), made once per node; false where
 * the sub-face is not such a one or the cone is not below 90 degrees. */
bool sd_node_ev_box(const sd_node *n, double pmax, ia_interval N[3]);

/* Component `axis` of Ng = dP/du x dP/dv over a whole regular sub-patch
 * from its hodographs (subdiv_eval.c). */
ia_interval sd_net_normal_component(const vec3 net[16], int axis);

#endif
