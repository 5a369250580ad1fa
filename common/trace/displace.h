/*
 * displace.h: an object's displaced surface, evaluated through its base
 * surface (common/geom) and its displacement shader (common/sl) in the
 * arithmetic a caller needs (Heidrich & Seidel §3):
 *
 *   trace_surface_box    conservative OBJECT-space box of the displaced
 *                        surface over a (u,v) range: affine (default) or
 *                        interval arithmetic, per trace_options.arith.
 *                        The shader runs in camera ("current") space; its
 *                        P is mapped back to object space as affine forms
 *                        (exact), so boxes of e.g. the nail's vertical walls
 *                        stay axis-aligned and tight whatever the camera.
 *   trace_surface_point  the displaced point and its shading normal at one
 *                        (u,v): dual mode (value + d/du + d/dv), so that
 *                        calculatenormal(P) in the shader is exact
 *
 * Both are pure functions of (object, u, v): the box cache and every
 * determinism test rely on that. An instance that shares its prototype's
 * boxes (trace/instance.c) gets the prototype's box, and the prototype's
 * point moved rigidly into its camera space.
 */
#ifndef TRACE_DISPLACE_H
#define TRACE_DISPLACE_H

#include "trace/thread.h"
#include "trace/world.h"

void trace_surface_box(trace_thread *th, const trace_object *obj,
                       double u0, double u1, double v0, double v1,
                       trace_box *out);
/* The same, and the box's linear bound in *lin where the run gives one
 * (TRACE_BOX_LIN on the box; lin_bound.h, issue 24's lazy children) */
void trace_surface_box_lin(trace_thread *th, const trace_object *obj, double u0, double u1,
                           double v0, double v1, trace_box *out, trace_lin *lin);
/* The same below a node whose box has tape `tape` (box.h: the decisions
 * its run proved; 0 at a root, or to take the whole program): the run
 * takes its plan and out->tape gets the decisions of this run too (tape
 * pruning, common/sl/tape_plan.c; world option tape_pruning). The box
 * still encloses the surface over the range; it is a pure function of the
 * range and tape. */
void trace_surface_box_tape(trace_thread *th, const trace_object *obj, double u0, double u1,
                            double v0, double v1, uint32_t tape, trace_box *out, trace_lin *lin);

/* The pieces of a box's affine binding (also trace/region.c's): out = m *
 * in (with m's translation when `point`; out must not alias in), and the
 * camera-space unit normal N of obj from its object-space unit normal Nn
 * (the inverse transpose, normalised; exact scaling for a similarity). */
void trace_xform_aa(aa_context *ctx, const mat4 *m, const aa_form in[3], aa_form out[3],
                    bool point);
void trace_camera_normal_aa(aa_context *ctx, const trace_object *obj, const aa_form Nn[3],
                            aa_form N[3]);

/* At most this many operations split per box (trace_surface_box_cases):
 * TRACE_MAX_CASES runs */
#define TRACE_SPLIT_OPS 3
#define TRACE_MAX_CASES (1 << TRACE_SPLIT_OPS)

/* The moves (object space) of a cell's cases where every case is the flat
 * base moved by a constant (TRACE_BOX_PLANES); n = 0 where not */
typedef struct trace_case_moves {
    int n;
    vec3 move[TRACE_MAX_CASES];
} trace_case_moves;

/* Issue 24, walls and patterns: *box, the range's trace_surface_box in
 * affine arithmetic, narrowed by case splits (sl_vm_split_begin): floor,
 * ceil, round, mod and step taking two values over the range (a cell
 * across a seam of bricks or tiles) run once per value, at most 3 of them
 * (8 runs), and *box becomes its meet with the hull of the cases' boxes.
 * Every point of the range is in one case, whose box holds it, so the
 * meet is as conservative as *box; it is thin where the values the
 * pattern takes on both sides of its seam agree (mortar on both sides of a
 * brick's joint: no displacement, where one run bounds [0, 1] of it).
 * Flagged AA_DISCONTINUOUS, without slab or proofs (bend). False (and *box
 * untouched) when nothing was split: interval arithmetic, no displacement,
 * no such operation; false too where the cases did not narrow it, and
 * then *box gains TRACE_BOX_STEP where the cases' boxes are pairwise
 * apart (a true step: the surface jumps where two cases meet, box.h),
 * and TRACE_BOX_PLANES where every case is the flat base moved by a
 * constant (their moves in *moves where given; else moves->n = 0).
 * Where lin is given (the box's linear bound, TRACE_BOX_LIN on *box if
 * it has one) and the box is narrowed, *lin becomes the cases' own
 * bound (one that holds every case's) where that is tighter.
 * Costs 1 to 8 shader runs, counted as one box; the
 * intersector calls it on discontinuous boxes that stopped shrinking
 * (intersect.c). A pure function of (object, range, *box). */
bool trace_surface_box_cases(trace_thread *th, const trace_object *obj,
                             double u0, double u1, double v0, double v1, trace_box *box,
                             trace_lin *lin, trace_case_moves *moves);

/* The box of the range, its cases first: where the children of a box the
 * cases narrowed (TRACE_BOX_SPLIT) still lie across its seam, the plain
 * run would only find them stagnant again. One run with case splits: when
 * it split nothing it is trace_surface_box_lin's own run, and *box and
 * *lin are what that gives, but for its tape (none: box.h) (false); else the other cases run and *box is
 * the hull of their boxes, flagged AA_DISCONTINUOUS and TRACE_BOX_SPLIT
 * (and TRACE_BOX_STEP where their boxes are pairwise apart), without
 * slab or proofs, with a linear bound in *lin that holds every case's
 * (TRACE_BOX_LIN, where all have one; lin may be NULL), and
 * TRACE_BOX_PLANES with the moves as trace_surface_box_cases gives them
 * (true). Where the seams overflow the
 * cases, or a case has a NaN side, *box and *lin are
 * trace_surface_box_lin's (false; the lost runs counted as a box). The
 * hull encloses the surface as trace_surface_box_cases's does (every
 * point is in one case). A pure function of (object, range). */
bool trace_surface_box_split(trace_thread *th, const trace_object *obj,
                             double u0, double u1, double v0, double v1, trace_box *box,
                             trace_lin *lin, trace_case_moves *moves);

/* The moves of the cases of the range's seams, as trace_surface_box_cases
 * runs them, where every case is the flat base moved by a constant
 * (TRACE_BOX_PLANES; 2 to TRACE_MAX_CASES of them); else moves->n = 0. A
 * pure function of (object, range). */
void trace_surface_case_moves(trace_thread *th, const trace_object *obj, double u0, double u1,
                              double v0, double v1, trace_case_moves *moves);

/* A cell whose displaced surface is one plane piece (TRACE_BOX_PLANAR:
 * its run's forms are affine in u and v alone): object space,
 * P(u, v) = Q + e Eu + f Ev where u = um + e ur and v = vm + f vr (e, f in
 * [-1, 1] over the cell) */
typedef struct trace_plane {
    vec3 Q, Eu, Ev;
    double um, ur, vm, vr;
} trace_plane;

/* The plane of a TRACE_BOX_PLANAR cell, as the run that made its box gave
 * it (kept per cell in a per-thread cache; a cell the cache lost runs
 * again with the tape its box's run took, counted as a box): true with
 * *out, or false where the cell is not planar. A pure function of
 * (object, range, tape). */
bool trace_surface_plane(trace_thread *th, const trace_object *obj, double u0, double u1,
                         double v0, double v1, uint32_t tape, trace_plane *out);

/* N is constant over the object (its d/du, d/dv are 0): disks, and
 * polygons unless they carry interpolated vertex normals
 * (geom_vertex_normal). */
bool trace_surface_flat(const trace_object *obj);

/* Whether hit proofs should try the object, trace_surface_slopes
 * bounding N's slopes on it: flat ones, and spheres, cylinders, cones,
 * tori, bilinear and bicubic patches, subdivision faces (their regular
 * sub-patches) and polygons with vertex normals under a similarity
 * (geom_unit_normal_slopes_ia). */
bool trace_surface_has_slopes(const trace_object *obj);

/* Interval bounds, over a (u,v) range, of the displaced P in CAMERA space
 * and of its true partial derivatives d/du, d/dv (sl_vm_run_slopes): the
 * Jacobian the hit proof (trace/prove.c) needs. False where they are not
 * known to be finite slope bounds of a continuous function: an instance,
 * no displacement, a failed run, an unbounded or discontinuous value. A
 * range of one point gives an enclosure of P there; with Pu and Pv NULL,
 * only P's (a plain interval run, cheaper). */
bool trace_surface_slopes(trace_thread *th, const trace_object *obj,
                          double u0, double u1, double v0, double v1,
                          ia_interval P[3], ia_interval Pu[3], ia_interval Pv[3]);

typedef struct trace_surface_point {
    vec3 P;              /* displaced, camera space */
    vec3 N;              /* shading normal (unit), after the displacement shader */
    vec3 Ng;             /* geometric normal of the base surface (unit) */
    vec3 dPdu, dPdv;     /* of the base surface, camera space */
    vec3 Pu, Pv;         /* d/du, d/dv of the displaced P (dual mode) */
    double u, v;
} trace_surface_point;

void trace_surface_point_eval(trace_thread *th, const trace_object *obj,
                              double u, double v, trace_surface_point *out);

/* An instance sharing its prototype's boxes (box_proto): the prototype's
 * point at the same (u,v), moved rigidly into the instance's camera
 * space (what trace_surface_point_eval gives for the instance). */
void trace_surface_point_move(const trace_object *obj, trace_surface_point *out);

/* The same on another VM of the thread (shade.c runs it on the shading VM
 * to capture the displacement shader's outputs for message passing). */
void trace_surface_point_eval_on(trace_thread *th, sl_vm *vm, const trace_object *obj,
                                 double u, double v, trace_surface_point *out);

#endif
