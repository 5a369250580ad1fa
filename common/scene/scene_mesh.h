/*
 * scene_mesh.h: a polygon mesh, or a subdivision mesh, kept as ONE scene
 * object (issue 23):
 * PointsPolygons and PointsGeneralPolygons keep their shared arrays once
 * (the points, the vertex indices, the corner normals, every primitive
 * variable's values) and each piece of a face (a convex planar face, or
 * one triangle of a face that had to be cut) as a 16-byte record that
 * names the face and its corners. The base surface of a piece, with its
 * primitive variables, is made again on demand (scene_mesh_piece) by the
 * same steps the parser once used to make one object per piece, so it is
 * the same surface to the bit: a renderer materialises the pieces a ray
 * reaches and keeps none of the others.
 *
 * A SubdivisionMesh (rib_subdiv.c) is such an object too: its pieces are
 * the faces of its refined mesh (geom/subdiv.h, shared by the pieces, owned
 * by the scene's subdivs), its variables the control faces' corners'.
 *
 * The pieces are decided when the mesh is read (rib_mesh.c: faces without
 * area are skipped, faces whose corner normals or variables differ are cut
 * into triangles); a mesh is immutable once read and owned by its scene
 * (scene.meshes), shared by every object that places it (instances).
 */
#ifndef SCENE_SCENE_MESH_H
#define SCENE_SCENE_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "geom/surface.h"

struct scene_primvar;
typedef struct scene_mesh scene_mesh;

/* Where a mesh's corner normals come from: none (flat pieces), one per
 * point (given or the area-weighted average, rib_mesh.c), one per face
 * corner, one per face, or one for the whole mesh. */
typedef enum scene_mesh_nclass {
    SCENE_MESH_N_NONE, SCENE_MESH_N_VERTEX, SCENE_MESH_N_FACEVARYING, SCENE_MESH_N_UNIFORM,
    SCENE_MESH_N_CONSTANT
} scene_mesh_nclass;

/* How a piece is made from its face. */
typedef enum scene_piece_kind {
    SCENE_PIECE_POLYGON,           /* the whole face, one convex planar polygon */
    SCENE_PIECE_TRIANGLE,          /* corners k[0..3) of the face, flat */
    SCENE_PIECE_TRIANGLE_N,        /* the same with its corner normals */
    SCENE_PIECE_SUBDIV,            /* face `face` of the refined subdivision mesh
                                    * (kept as its face alone) */
} scene_piece_kind;

/* One piece of a polygon mesh: 16 bytes (a subdivision mesh's piece is
 * its refined face: 4 bytes, or none, scene_mesh.c). */
typedef struct scene_mesh_piece {
    int32_t face;                  /* the face (uniform class index) */
    int32_t fv0;                   /* its first face-vertex (index into the vertex indices) */
    uint16_t k[3];                 /* triangles: the face's corners; polygons: k[0] the
                                    * corner count, k[1] the corner it starts at (its
                                    * (u,v) follow "st": rib_primvars_st_edge) */
    uint8_t kind;                  /* scene_piece_kind */
    uint8_t unused;
} scene_mesh_piece;

/* Its index in scene.meshes. */
int scene_mesh_index(const scene_mesh *self);

/* The number of pieces, and of primitive variables each piece carries. */
int scene_mesh_npieces(const scene_mesh *self);
int scene_mesh_nprimvars(const scene_mesh *self);

/* Piece k's base surface (object space, prepared) and its primitive
 * variables (*nvars of them, at most scene_mesh_nprimvars, into vars), as
 * the parser made them when the mesh was read; false only if that is no
 * longer possible (never for a piece the parser kept). */
bool scene_mesh_piece_surface(const scene_mesh *self, int k, geom_surface *s,
                              struct scene_primvar *vars, int *nvars);

/* Piece k's outline: for a polygon mesh, its flat polygon's corners and
 * plane basis alone (geom_polygon_basis: origin, axes, normal, nuv and
 * uv the same bits as scene_mesh_piece_surface gives them; the rest of s
 * is not set, kind, nverts, verts and nvn = 0 aside), what its bounds and
 * shared edges need at a fraction of the cost; for a subdivision mesh, its
 * surface. False as scene_mesh_piece_surface. */
bool scene_mesh_piece_outline(const scene_mesh *self, int k, geom_surface *s);

/* The bytes the mesh holds (arrays and pieces), and of them its pieces'
 * records (16 bytes a piece of a polygon mesh, 4 a piece of a subdivision
 * mesh, none when every refined face is drawn), for benchmarks and the
 * per-face budgets' tests. */
size_t scene_mesh_bytes(const scene_mesh *self);
size_t scene_mesh_piece_bytes(const scene_mesh *self);

/* A subdivision mesh's own bytes (geom/subdiv.h: its control mesh and
 * its flags per refined face; 0 for a polygon mesh), and of them its
 * control points' (*points), which count with the shared arrays. */
size_t scene_mesh_subdiv_bytes(const scene_mesh *self, size_t *points);

void scene_mesh_destroy(scene_mesh **self_p);

#endif
