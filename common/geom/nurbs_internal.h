/*
 * nurbs_internal.h: what nurbs.c (building the pieces of a NuPatch) and
 * nurbs_eval.c (evaluating one piece) share: the layout of a geom_nurbs.
 */
#ifndef GEOM_NURBS_INTERNAL_H
#define GEOM_NURBS_INTERNAL_H

#include "geom/nurbs.h"

/* One rational Bezier piece: orders ku x kv, homogeneous points
 * Hw_ij = H[4 (j ku + i) + 0..3] (u fastest), all exact doubles (the
 * surface is the one these define). */
typedef struct geom_nurbs_piece {
    int ku, kv;
    const double *H;
    double wmin, wmax;             /* the weights' range (H.w lies in it) */
    ia_interval hull[3];           /* the projected points' box, rounded out */
    double u0, u1, v0, v1;         /* the knot range */
} geom_nurbs_piece;

struct geom_nurbs {
    int npieces;
    geom_nurbs_piece *pieces;
    double *H;                     /* the nets of all pieces */
};

#endif
