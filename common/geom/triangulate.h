/*
 * triangulate.h: triangles covering a planar polygon given as loops of 3D
 * points (an outer boundary and any number of holes), for the faces of
 * PointsGeneralPolygons and PointsPolygons that are not convex
 * (RI Specification 3.2 §5.1: "general polygons" may be concave and hold
 * holes).
 *
 * Method: the loops are projected to the coordinate plane the polygon's
 * (Newell) normal is most aligned with; each hole is joined to the outer
 * loop by a bridge to the nearest vertex it can see (a segment crossing
 * no edge), which makes one simple, weakly-simple loop; the loop is then
 * cut by ear clipping (an ear: a convex corner whose triangle holds no
 * other vertex of the loop). Triangles keep the outer loop's winding, so
 * their geometric normals agree with the polygon's.
 */
#ifndef GEOM_TRIANGULATE_H
#define GEOM_TRIANGULATE_H

#include <stdbool.h>
#include <stddef.h>

#include "util/vecmath.h"

/* pts[0 .. sum(loop_sizes)) holds the loops one after the other, the outer
 * one first. Writes up to max_tris triangles as index triples into pts and
 * returns their count, n + 2h - 2 for n points and h holes (less where
 * corners are straight: slivers of relative area below 1e-12 are dropped,
 * never emitted); returns -1
 * (with a reason in err) when the polygon is degenerate (no area, fewer
 * than 3 points in a loop) or cannot be cut (self-intersecting loops). */
int geom_triangulate(const vec3 *pts, const int *loop_sizes, int nloops, int (*tris)[3],
                     int max_tris, char *err, size_t errsz);

#endif
