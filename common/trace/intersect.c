/*
 * intersect.c: the subdivision intersector of Heidrich & Seidel §3, §5, §6
 * (see intersect.h) and the exact path for undisplaced objects.
 */
#include "trace/intersect.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "aa/interval.h"
#include "trace/cellkey.h"
#include "trace/converge.h"
#include "trace/prove.h"
#include "util/err.h"
#include "util/xalloc.h"

/* §5: a discontinuous box "stopped shrinking" when a child keeps more than
 * this fraction of its parent's size (smooth boxes halve, roughly). */
#define TRACE_NO_SHRINK 0.75

/* The first depth at which stagnant flagged boxes may be sampled. */
#define TRACE_SAMPLE_DEPTH 6

/* Hit proofs (prove.h) are tried on cells whose box is at most this many
 * leaf tolerances (pixel footprints, for primary rays) wide, and where the
 * surface is nearly linear over the cell: its affine box's other terms at
 * most this fraction of its u and v terms (trace_box.bend). Cells that
 * bend more rarely pass the test (dented without this rule: 258 hits in
 * 25,230 tests) and cost a slope run each (docs/benchmarks.md, step 4).
 * Not on an object whose displacement reads a texture (bend_unknown):
 * there a lookup over several texels is a bound, a fresh noise symbol
 * however smooth the map, so the bend says nothing of the surface's, and
 * the test settles most cells (the peer terrain: 396,013 of 692,090,
 * where the rule left 35 proven hits; 8.2 -> 7.9 s, 610 -> 447 pixels
 * from the 1/16-pixel reference; dented with every cell tried: 2.60 ->
 * 3.20 s). On a whole cell of a leaf's size (at most one tolerance) the
 * test would only place the leaf's point: there, where the ray does not
 * graze the surface, the leaf's Newton steps go first and the test runs
 * only where they do not settle (session 22: dented's tests 27,767 ->
 * 5,349, CPU 0.86x, 143 -> 145 pixels from the 1/16-pixel reference; the
 * wave, nail, meshes, terrain and a wall of bricks the same counts).
 * Skipping those tests altogether made the wall of bricks_filtered 1.36x
 * slower: the failed ones narrow prove_below, which keeps larger cells of
 * that walk from failing at folds into subtrees of 1/8-tolerance leaves. */
#define TRACE_PROVE_CELLS 16.0
#define TRACE_PROVE_BEND 0.05
/* Below a cell whose test failed at a fold (G's Jacobian may be singular
 * there: a silhouette, where the ray grazes a crest) or across the base
 * surface's edge, and at a leaf where the ray grazes the surface (|cos|
 * of its angle to the normal below TRACE_PROVE_GRAZE) and the cell has
 * slope bounds, leaves are taken at TRACE_PROVE_LEAF of the tolerance:
 * the hits and misses around are exact, so the leaves' near misses there
 * are the image's only error
 * (peers_compare against the 1/16-pixel reference, one ray per pixel: the
 * wave 4 pixels instead of 24, the UFO 10 instead of 42; 6 % more CPU on
 * the dented plane, whose far bumps graze). Not where a test fails for
 * other reasons (a crease, a texture, a jump): bounds need not shrink
 * there below the tolerance (converge.h), and there is no fold to resolve. */
#define TRACE_PROVE_LEAF 0.125
#define TRACE_PROVE_GRAZE 0.1
/* Wall leaves are taken at TRACE_PROVE_LEAF of the tolerance where the ray
 * meets the wall at |cos| below this (a wall's normal is an estimate from
 * samples, and a cylinder's leaves a pixel from its silhouette lean by up
 * to ~25 degrees: with 0.1 instead, the nail is 47 pixels from its
 * 1/16-pixel reference instead of 22) */
#define TRACE_WALL_GRAZE 0.5

typedef struct walk {
    trace_thread *th;
    const trace_object *obj;
    const trace_ray *cam_ray;      /* camera space */
    trace_ray ray;                 /* object space */
    trace_tolerance tol;
    bool any;
    bool found;
    bool stopped;                  /* the work limit or a cancel ended the walk */
    bool prove;                    /* hit proofs may succeed on this object */
    bool exact_cells;              /* undisplaced cells are intersected
                                      exactly (exact_cell) */
    double prove_below;            /* ... on cells of at most this size (a
                                      failed test's estimate, visit) */
    long nodes;                    /* quadtree nodes visited so far */
    trace_hit *best;
    trace_zero zero;               /* the last zero a test proved (prove.h) */
} walk;

/* A child in the walk's order: its entry and exit along the ray (of its
 * restricted bound while it is pending: a lazy child not yet evaluated) */
typedef struct child_order {
    double t0, t1;
    int i, axis;
    geom_cover cover;
    bool pending;
} child_order;

/* The walk's order: by entry, ties by the child's number (the order in
 * which the children were put in) */
static inline bool order_before(const child_order *a, const child_order *b)
{
    return a->t0 < b->t0 || (a->t0 == b->t0 && a->i < b->i);
}

static inline __attribute__((always_inline)) void order_insert(child_order *order, int *n,
                                                             child_order o)
{
    int k = (*n)++;
    while (k > 0 && order_before(&o, &order[k - 1])) {
        order[k] = order[k - 1];
        k--;
    }
    order[k] = o;
}

static void child_range(int i, double u0, double u1, double v0, double v1,
                        double r[4])
{
    double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    r[0] = (i & 1) ? um : u0;
    r[1] = (i & 1) ? u1 : um;
    r[2] = (i & 2) ? vm : v0;
    r[3] = (i & 2) ? v1 : vm;
}

static double box_min_extent(const trace_box *b)
{
    double e = b->hi.x - b->lo.x;
    if (b->hi.y - b->lo.y < e) e = b->hi.y - b->lo.y;
    if (b->hi.z - b->lo.z < e) e = b->hi.z - b->lo.z;
    return e;
}

/* The displaced surface on a 3x3 grid of a (u,v) cell, in dual mode (as
 * hit points are), camera space, with its derivatives; the samples off a
 * polygon or not finite are marked missing. `residual` is how far grid
 * neighbours miss the trapezoid rule P_k - P_i = (J_i + J_k) d / 2: a few
 * third-order terms on a continuous surface, the size of the jump where it
 * jumps. Used by the wall test and the stagnant-box fallback. With a
 * finite `stop`, the sampling ends (n = -1) as soon as the residual
 * exceeds it and two samples differ: the residual can only grow, so a
 * caller that asks for residual <= stop with a spread above 0 has its
 * answer. The residual is the largest over the same pairs, each computed
 * the same way, whichever order they are met in. */
enum { CELL_G = 3, CELL_N = CELL_G * CELL_G };
typedef struct cell_samples {
    vec3 P[CELL_N], Pu[CELL_N], Pv[CELL_N], base[CELL_N];
    bool ok[CELL_N];
    int n;                         /* samples present */
    double residual;
} cell_samples;

static void sample_cell(trace_thread *th, const trace_object *obj, const double r[4],
                        double stop, cell_samples *cs)
{
    double du = (r[1] - r[0]) / (CELL_G - 1), dv = (r[3] - r[2]) / (CELL_G - 1);
    cs->n = 0;
    cs->residual = 0;
    bool spread = false;                /* a sample apart from the first */
    for (int k = 0; k < CELL_N; k++) {
        double u = r[0] + du * (k % CELL_G), v = r[2] + dv * (k / CELL_G);
        cs->ok[k] = false;
        if (geom_uv_inside(&obj->surf, u, v)) {
            trace_surface_point sp;
            trace_surface_point_eval(th, obj, u, v, &sp);
            if (!(v3_is_finite(sp.P) && v3_is_finite(sp.Pu) && v3_is_finite(sp.Pv))) {
                /* a sample on a singular line of the shader's formula
                 * (atan(y / x) at x = 0: inf / inf in the derivative): once
                 * more a hair inside the cell (2^-20 of its side), where
                 * the formula is finite if the surface is */
                double un = u + (k % CELL_G < CELL_G - 1 ? 1 : -1) * 0x1p-20 * (r[1] - r[0]);
                double vn = v + (k / CELL_G < CELL_G - 1 ? 1 : -1) * 0x1p-20 * (r[3] - r[2]);
                if (geom_uv_inside(&obj->surf, un, vn))
                    trace_surface_point_eval(th, obj, un, vn, &sp);
            }
            if (v3_is_finite(sp.P) && v3_is_finite(sp.Pu) && v3_is_finite(sp.Pv)) {
                geom_sample g;
                geom_eval(&obj->surf, u, v, &g);
                cs->P[k] = sp.P;
                cs->Pu[k] = sp.Pu;
                cs->Pv[k] = sp.Pv;
                cs->base[k] = mat4_xform_point(&obj->to_camera, g.P);
                cs->ok[k] = true;
                cs->n++;
            }
        }
        if (!cs->ok[k]) continue;
        /* the pairs that end at k: from its left and upper neighbours */
        int left = k % CELL_G > 0 ? k - 1 : -1, up = k - CELL_G;
        if (left >= 0 && cs->ok[left]) {
            vec3 pred = v3_add(cs->P[left], v3_scale(v3_add(cs->Pu[left], cs->Pu[k]), 0.5 * du));
            cs->residual = fmax(cs->residual, v3_length(v3_sub(cs->P[k], pred)));
        }
        if (up >= 0 && cs->ok[up]) {
            vec3 pred = v3_add(cs->P[up], v3_scale(v3_add(cs->Pv[up], cs->Pv[k]), 0.5 * dv));
            cs->residual = fmax(cs->residual, v3_length(v3_sub(cs->P[k], pred)));
        }
        spread = spread || (cs->ok[0] && (cs->P[k].x != cs->P[0].x || cs->P[k].y != cs->P[0].y ||
                                          cs->P[k].z != cs->P[0].z));
        if (cs->residual > stop && spread) {
            cs->n = -1;                 /* stopped: the caller's test fails */
            return;
        }
    }
}

/* §5 walls, issue 9: a discontinuous box that stopped shrinking is a wall
 * only where the surface really jumps: its samples (sample_cell) miss the
 * trapezoid rule by more than twice the tolerance. A function that is
 * continuous at this scale (sin of a mod, a branch whose sides agree, a
 * steep slope) passes, and its cell is subdivided further like any other.
 * At a wall the samples fall into the two sides of the jump (nearer to one
 * or the other of the two farthest samples); the wall's normal is the step
 * between the sides' base-surface centroids, made perpendicular to the
 * jump of their displacements: for a nail, the radius. Where the edge
 * runs at an angle to the cell's (u,v) grid (a mesh's triangle, whose "st"
 * runs across its (u,v)), that step leans with the grid, so once a cell is
 * found to be a wall (real_wall) the step is also made perpendicular to
 * the edge itself (refine_wall_normal).
 *
 * What the samples tell of a cell is a pure function of object and cell,
 * kept in a direct-mapped per-thread cache (wall_cell; fixed size, so
 * memory stays flat, and what it holds never changes an answer): every
 * ray near a wall tests the same cells, and sampling one costs 9 dual
 * evaluations (a nail without its cache: 3 times the evaluations). */
enum { WALL_CACHE_LOG2 = 10, WALL_CACHE_ENTRIES = 1 << WALL_CACHE_LOG2 };
typedef struct wall_entry {
    double r[4];                  /* the cell; r[0] >= r[1]: empty */
    int obj;
    double residual;              /* cs.residual */
    bool sided;                   /* the normal and the sides below are known */
    vec3 normal;                  /* not yet facing the ray; 0: degenerate */
    bool jumps;                   /* j, high and low are known */
    vec3 j;                       /* the jump's direction, unit */
    double high, low;             /* the high side's lowest sample along j,
                                     the low side's highest */
    vec3 step;                    /* the sides' base centroids' step */
    vec3 pa, pb;                  /* the two farthest samples: side 0's, 1's */
    unsigned short ok_bits, side_bits;  /* per sample: present, on side 1 */
    bool refined;                 /* normal made perpendicular to the edge */
} wall_entry;
struct trace_wall_cache { wall_entry e[WALL_CACHE_ENTRIES]; };

/* The side of the jump a surface point p lies on: 1 where it is nearer
 * the farthest pair's second sample pb than its first pa */
static int wall_side(vec3 p, vec3 pa, vec3 pb)
{
    return v3_length(v3_sub(p, pb)) < v3_length(v3_sub(p, pa));
}

/* the wall's unit normal from the step between its sides: made
 * perpendicular to the jump (0 where degenerate) */
static void wall_normal_from(wall_entry *e, vec3 step)
{
    vec3 nrm = e->jumps ? v3_sub(step, v3_scale(e->j, v3_dot(step, e->j))) : step;
    double len = v3_length(nrm);
    e->normal = len > 0 && isfinite(len) ? v3_scale(nrm, 1.0 / len) : v3(0, 0, 0);
}

/* the samples' verdict on the cell: residual, normal, sides */
static void analyse_wall(trace_thread *th, const trace_object *obj, const double r[4],
                         wall_entry *e)
{
    cell_samples cs;
    sample_cell(th, obj, r, INFINITY, &cs);
    e->residual = cs.residual;
    e->sided = e->jumps = e->refined = false;
    int a = -1, b = -1;
    double far = -1;
    for (int i = 0; i < CELL_N; i++)
        for (int k = i + 1; k < CELL_N; k++) {
            if (!cs.ok[i] || !cs.ok[k]) continue;
            double d = v3_length(v3_sub(cs.P[i], cs.P[k]));
            if (d > far) { far = d; a = i; b = k; }
        }
    if (a < 0) return;
    vec3 sum_base[2] = {v3(0, 0, 0), v3(0, 0, 0)}, sum_disp[2] = {v3(0, 0, 0), v3(0, 0, 0)};
    int count[2] = {0, 0};
    int side_of[CELL_N];
    for (int i = 0; i < CELL_N; i++) {
        side_of[i] = 0;
        if (!cs.ok[i]) continue;
        int side = wall_side(cs.P[i], cs.P[a], cs.P[b]);
        side_of[i] = side;
        sum_base[side] = v3_add(sum_base[side], cs.base[i]);
        sum_disp[side] = v3_add(sum_disp[side], v3_sub(cs.P[i], cs.base[i]));
        count[side]++;
    }
    e->sided = true;
    e->pa = cs.P[a];
    e->pb = cs.P[b];
    e->ok_bits = e->side_bits = 0;
    for (int i = 0; i < CELL_N; i++) {
        if (cs.ok[i]) e->ok_bits |= (unsigned short)(1u << i);
        if (side_of[i]) e->side_bits |= (unsigned short)(1u << i);
    }
    vec3 step = v3_sub(v3_scale(sum_base[1], 1.0 / count[1]), v3_scale(sum_base[0], 1.0 / count[0]));
    e->step = step;
    vec3 jump = v3_sub(v3_scale(sum_disp[1], 1.0 / count[1]), v3_scale(sum_disp[0], 1.0 / count[0]));
    double jj = v3_dot(jump, jump);
    if (jj > 0 && isfinite(jj)) {
        /* along the jump: the high side's lowest sample, the low side's
         * highest; between them only the wall */
        e->j = v3_scale(jump, 1.0 / sqrt(jj));
        e->high = INFINITY;
        e->low = -INFINITY;
        for (int i = 0; i < CELL_N; i++) {
            if (!cs.ok[i]) continue;
            double h = v3_dot(cs.P[i], e->j);
            if (side_of[i]) e->high = fmin(e->high, h);
            else e->low = fmax(e->low, h);
        }
        e->jumps = true;
    }
    wall_normal_from(e, step);
}

/* A wall's normal made perpendicular to its edge too: where two grid
 * neighbours of the samples lie on two sides, the edge crosses between
 * them. Of those crossings, the two whose midpoints lie farthest apart are
 * bisected (WALL_BISECT steps each, every point's side judged as the
 * samples' were); their base points lie on the edge and span it, and the
 * step between the sides' centroids loses its part along that span. A
 * pure function of object and cell, as the analysis is. */
#define WALL_BISECT 4
static void refine_wall_normal(trace_thread *th, const trace_object *obj, const double r[4],
                               wall_entry *e)
{
    e->refined = true;
    enum { MAXC = 2 * CELL_G * (CELL_G - 1) };
    double seg[MAXC][4];                  /* a crossing's (u,v) ends */
    int side0[MAXC];                      /* the side of its first end */
    int n = 0;
    double du = (r[1] - r[0]) / (CELL_G - 1), dv = (r[3] - r[2]) / (CELL_G - 1);
    for (int i = 0; i < CELL_N; i++)
        for (int dir = 0; dir < 2; dir++) {
            int k = dir == 0 ? (i % CELL_G < CELL_G - 1 ? i + 1 : -1)
                             : (i + CELL_G < CELL_N ? i + CELL_G : -1);
            if (k < 0 || !((e->ok_bits >> i) & 1) || !((e->ok_bits >> k) & 1)) continue;
            if (((e->side_bits >> i) & 1) == ((e->side_bits >> k) & 1)) continue;
            side0[n] = (e->side_bits >> i) & 1;
            seg[n][0] = r[0] + du * (i % CELL_G);
            seg[n][1] = r[2] + dv * (i / CELL_G);
            seg[n][2] = r[0] + du * (k % CELL_G);
            seg[n][3] = r[2] + dv * (k / CELL_G);
            n++;
        }
    /* the two crossings farthest apart, by their midpoints' base points */
    vec3 mid[MAXC];
    for (int c = 0; c < n; c++) {
        geom_sample g;
        geom_eval(&obj->surf, 0.5 * (seg[c][0] + seg[c][2]), 0.5 * (seg[c][1] + seg[c][3]), &g);
        mid[c] = g.P;
    }
    int pick[2] = {-1, -1};
    double best = -1;
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++) {
            vec3 d = v3_sub(mid[b], mid[a]);
            if (v3_dot(d, d) > best) { best = v3_dot(d, d); pick[0] = a; pick[1] = b; }
        }
    if (pick[0] < 0) return;
    vec3 at[2];
    for (int m = 0; m < 2; m++) {
        const double *sg = seg[pick[m]];
        double u0 = sg[0], v0 = sg[1], u1 = sg[2], v1 = sg[3];
        for (int it = 0; it < WALL_BISECT; it++) {
            double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
            trace_surface_point sp;
            trace_surface_point_eval(th, obj, um, vm, &sp);
            if (!v3_is_finite(sp.P)) break;
            if (wall_side(sp.P, e->pa, e->pb) == side0[pick[m]]) {
                u0 = um;
                v0 = vm;
            } else {
                u1 = um;
                v1 = vm;
            }
        }
        geom_sample g;
        geom_eval(&obj->surf, 0.5 * (u0 + u1), 0.5 * (v0 + v1), &g);
        at[m] = mat4_xform_point(&obj->to_camera, g.P);
    }
    vec3 edge = v3_sub(at[1], at[0]);
    double ee = v3_dot(edge, edge);
    if (!(ee > 0) || !isfinite(ee)) return;
    wall_normal_from(e, v3_sub(e->step, v3_scale(edge, v3_dot(e->step, edge) / ee)));
}

static wall_entry *wall_cell(trace_thread *th, const trace_object *obj, const double r[4])
{
    if (!th->walls) {                   /* zeroed: empty (cellkey.h) */
        th->walls = xcalloc(1, sizeof *th->walls);
    }
    wall_entry *e = &th->walls->e[trace_cell_slot(r, obj->id, WALL_CACHE_LOG2)];
    if (trace_cell_is(e->r, e->obj, r, obj->id)) return e;
    analyse_wall(th, obj, r, e);
    if (th->failed)                     /* a failed run: nothing to keep */
        trace_cell_forget(e->r);
    else
        trace_cell_keep(e->r, &e->obj, r, obj->id);
    return e;
}

/* Whether the cell is a wall for this ray (residual over twice its
 * tolerance), its normal facing the ray, and *capped: whether the ray,
 * between t0 and t1, comes within tol of the high side's lowest sample or
 * the low side's highest along the jump, where the wall meets the surface
 * on its sides (the nail's rim and foot), whose hits a wall leaf would
 * take. */
static bool real_wall(walk *w, const double r[4], double tol, double t0, double t1,
                      vec3 *normal, bool *capped)
{
    *capped = false;
    wall_entry *e = wall_cell(w->th, w->obj, r);
    if (!(e->residual > 2.0 * tol) || !e->sided) return false;
    if (!e->refined) refine_wall_normal(w->th, w->obj, r, e);
    if (e->jumps) {
        double h0 = v3_dot(trace_ray_at(w->cam_ray, t0), e->j);
        double h1 = v3_dot(trace_ray_at(w->cam_ray, t1), e->j);
        *capped = fmax(h0, h1) >= e->high - tol || fmin(h0, h1) <= e->low + tol;
    }
    *normal = e->normal;                /* 0: the box face's, in leaf_hit */
    if (v3_dot(*normal, w->cam_ray->d) > 0) *normal = v3_neg(*normal);
    return true;
}

/* Where, in the leaf's cell, the ray meets the surface's tangent plane at
 * sp (one Newton step: P + Pu a + Pv b = o + t d, by Cramer's rule),
 * clamped to the cell. False when the ray runs along the plane. */
static bool newton_uv(const trace_ray *ray, const trace_surface_point *sp,
                      const double r[4], double *u, double *v)
{
    double s[3];
    if (!trace_newton_step(sp->Pu, sp->Pv, ray->d, v3_sub(sp->P, ray->o), s)) return false;
    *u = fmin(fmax(sp->u + s[0], r[0]), r[1]);
    *v = fmin(fmax(sp->v + s[1], r[2]), r[3]);
    return true;
}

/*
 * The point of a leaf's cell where the ray meets the surface: Newton's
 * iteration from the cell's centre, or from a point of the cell already
 * evaluated (`start`: leaf_start; *uc, *vc follow its (u,v) and the
 * steps) (newton_uv, each step clamped to the
 * cell grown by half its width on each side, within the unit square: the
 * ray's hit may lie just beside the cell whose box it entered). Fills sp
 * at the (u,v) used.
 *
 * A cell the polygon covers only in part (partial; issue 9, watertight
 * meshes) takes one step, and is the polygon's only where that point is
 * on the polygon: false otherwise. Deciding by the cell's centre instead
 * let both polygons of a shared edge drop a ray near it: the cracks of
 * issue 9's finding 4.
 *
 * A cell the surface covers whole is a hit either way (issue 10, exact hit
 * points): the steps only move the point the hit is placed and shaded at,
 * up to LEAF_NEWTON_STEPS of them, to where the ray meets the surface.
 * *settled says whether they converged (a step of at most 1/64 of the
 * cell, strictly inside the grown cell, taken to first order): where they
 * did not (or stopped shrinking by half each step), the
 * ray may pass the surface within the leaf's tolerance without meeting it
 * (a near miss, drawn a pixel too fat at a crest's silhouette), which
 * visit settles with a hit test. A step that leaves the (u,v) domain can
 * mean that the ray passes beyond the surface's edge, but also only that a
 * steep displacement is poorly linearised over the cell; dropping such
 * leaves lost real hits of steep shaders on meshes (tests/corpus), so the
 * last point inside stays.
 */
#define LEAF_NEWTON_STEPS 4
#define LEAF_SETTLED 0x1p-7             /* of the widened cell: 1/64 of the cell */
static bool leaf_point(walk *w, const double *r, bool partial, double *uc, double *vc,
                       const trace_surface_point *start, trace_surface_point *sp,
                       bool *settled)
{
    const trace_object *obj = w->obj;
    *settled = false;
    /* a whole cell's steps may reach its neighbours (half its width on
     * each side); a partial cell's stay in it */
    double hu = partial ? 0.0 : 0.5 * (r[1] - r[0]), hv = partial ? 0.0 : 0.5 * (r[3] - r[2]);
    double rw[4] = {fmax(0.0, r[0] - hu), fmin(1.0, r[1] + hu), fmax(0.0, r[2] - hv),
                    fmin(1.0, r[3] + hv)};
    r = rw;
    if (start) {
        *sp = *start;
        *uc = sp->u;
        *vc = sp->v;
    } else {
        trace_surface_point_eval(w->th, obj, *uc, *vc, sp);
    }
    double u, v, s[3];
    /* a mesh piece's partial cell: the clamp below keeps a ray beside a
     * shared edge for one of its two polygons, but one beyond an edge of
     * the piece's own (the mesh's outline) is no hit of the mesh: taken,
     * a leaf drew the outline up to its width past the polygon the mesh
     * tiles where a shared edge met it (issue 27) */
    if (partial && obj->shared_edges && v3_is_finite(sp->P) &&
        trace_newton_step(sp->Pu, sp->Pv, w->cam_ray->d, v3_sub(sp->P, w->cam_ray->o), s) &&
        geom_uv_beyond(&obj->surf, sp->u + s[0], sp->v + s[1], ~obj->shared_edges))
        return false;
    if (!v3_is_finite(sp->P) || !newton_uv(w->cam_ray, sp, r, &u, &v))
        return partial ? geom_uv_inside(&obj->surf, *uc, *vc) : true;
    if (!geom_uv_inside(&obj->surf, u, v))
        return !partial;
    double last = INFINITY;
    for (int it = 0;; it++) {
        double su = u - *uc, sv = v - *vc;
        double step = fmax(fabs(su) / (r[1] - r[0]), fabs(sv) / (r[3] - r[2]));
        if (step <= LEAF_SETTLED) {
            *settled = u > r[0] && u < r[1] && v > r[2] && v < r[3];
            if (su == 0 && sv == 0) return true;
            if (*settled && !partial) {
                /* the last step to first order: the point where the ray
                 * meets the tangent plane, a square of the step off the
                 * surface (no evaluation) */
                sp->P = v3_add(sp->P, v3_add(v3_scale(sp->Pu, su), v3_scale(sp->Pv, sv)));
                sp->u = *uc = u;
                sp->v = *vc = v;
                return true;
            }
        }
        if (!(step < 0.5 * last)) return true;      /* not converging */
        last = step;
        trace_surface_point moved;
        trace_surface_point_eval(w->th, obj, u, v, &moved);
        if (!partial && !v3_is_finite(moved.P)) return true;
        *uc = u;
        *vc = v;
        *sp = moved;
        if (partial || *settled || it + 1 == LEAF_NEWTON_STEPS) return true;
        if (!newton_uv(w->cam_ray, sp, r, &u, &v) || !geom_uv_inside(&obj->surf, u, v))
            return true;
    }
}

/* The hit a leaf stands for, recorded in w->best when nearer; Newton's
 * steps start at `start` where given (a point of the cell: leaf_start),
 * else at the cell's centre. With may_test, a leaf whose point did not
 * settle (leaf_point) records nothing and returns true: the caller tests
 * the cell first. */
static bool leaf_hit(walk *w, const trace_box *box, const double r[4],
                     const child_order *o, trace_leaf_kind kind, vec3 surface_normal,
                     const trace_surface_point *start, bool may_test)
{
    double t0 = o->t0, t1 = o->t1;
    int axis = o->axis;
    geom_cover cover = o->cover;
    const trace_object *obj = w->obj;
    double uc = 0.5 * (r[0] + r[1]), vc = 0.5 * (r[2] + r[3]);
    trace_surface_point sp;
    bool has_point = false;
    bool settled;
    if (cover == GEOM_PARTIAL && kind != TRACE_LEAF_WALL) {
        if (!leaf_point(w, r, true, &uc, &vc, start, &sp, &settled)) return false;
        has_point = true;
    } else if (!geom_uv_inside(&obj->surf, uc, vc)) {
        return false;
    } else if (kind == TRACE_LEAF_SMALL) {
        leaf_point(w, r, false, &uc, &vc, start, &sp, &settled);
        if (may_test && !settled) return true;
        has_point = true;
    }
    trace_thread *th = w->th;
    th->stats.leaves++;
    double t;
    vec3 wall_n = v3(0, 0, 0);
    if (kind == TRACE_LEAF_WALL) {
        /* the ray meets the wall where it enters its box */
        th->stats.wall_leaves++;
        t = t0;
        if (v3_dot(surface_normal, surface_normal) > 0) {
            wall_n = surface_normal;
        } else if (axis >= 0) {
            double n[3] = {0, 0, 0};
            n[axis] = (&w->ray.d.x)[axis] > 0 ? -1.0 : 1.0;
            wall_n = v3_normalize(mat4_xform_normal(&obj->from_camera, v3(n[0], n[1], n[2])));
        } else {
            wall_n = v3_normalize(v3_neg(w->cam_ray->d));
        }
    } else {
        if (kind == TRACE_LEAF_DEPTH) th->stats.depth_cap_leaves++;
        if (!has_point) trace_surface_point_eval(th, obj, uc, vc, &sp);
        has_point = true;
        const trace_ray *cr = w->cam_ray;
        double dd = v3_dot(cr->d, cr->d);
        if (!v3_is_finite(sp.P) || !(dd > 0)) {
            th->stats.rejected_leaves++;   /* no surface point to place a hit */
            return false;
        }
        t = v3_dot(v3_sub(sp.P, cr->o), cr->d) / dd;
        if (kind == TRACE_LEAF_DEPTH) {
            /* The box never got small: the surface jumps or is unbounded in
             * this tiny (u,v) cell. A hit only where the surface point
             * itself lies on the ray within the tolerance (issue 9). */
            vec3 off = v3_sub(sp.P, trace_ray_at(cr, t));
            double tol = w->tol.a + w->tol.b * (t > 0 ? t : 0);
            if (!(v3_length(off) <= tol)) {
                th->stats.rejected_leaves++;
                return false;
            }
        }
        if (!(t >= t0)) t = t0;
        if (t > t1) t = t1;
    }
    if (!(t > w->ray.tmin) || !(t < w->best->t)) return false;
    trace_hit *b = w->best;
    b->t = t;
    b->obj = obj;
    b->u = uc;
    b->v = vc;
    b->leaf_size = trace_box_extent(box) * obj->scale;
    b->kind = kind;
    b->wall_normal = wall_n;
    b->has_point = has_point;
    if (has_point) b->point = sp;
    w->found = true;
    return false;
}

/* A hit proven unique in the cell (prove.h): the surface's own point */
static void proven_hit(walk *w, double t, double tol, const trace_surface_point *sp)
{
    if (!(t > w->ray.tmin) || !(t < w->best->t)) return;
    w->th->stats.leaves++;
    trace_hit *b = w->best;
    b->t = t;
    b->obj = w->obj;
    b->u = sp->u;
    b->v = sp->v;
    b->leaf_size = tol;             /* offsets secondary rays as a pixel leaf's */
    b->kind = TRACE_LEAF_PROVEN;
    b->wall_normal = v3(0, 0, 0);
    b->has_point = true;
    b->point = *sp;
    w->found = true;
}

/* The base surfaces whose intersections with a ray geom_intersect gives
 * in closed form, nearest first, at most EXACT_ROOTS of them: planes (a
 * polygon, with vertex normals or not, which only shading reads; a disk),
 * the quadrics, the bilinear patch (a quadratic after eliminating one
 * parameter: two roots) and the torus (a quartic) */
#define EXACT_ROOTS 4
static bool exact_kind(geom_kind k)
{
    switch (k) {
    case GEOM_POLYGON: case GEOM_DISK: case GEOM_SPHERE: case GEOM_CYLINDER: case GEOM_CONE:
    case GEOM_PARABOLOID: case GEOM_HYPERBOLOID: case GEOM_TORUS: case GEOM_PATCH:
        return true;
    default:
        return false;
    }
}

/* The move of a cell the displacement moved by a constant
 * (TRACE_BOX_OFFSET), in object space: the displaced point less the
 * base's at any point of the cell, here its centre. A pure function of
 * object and cell, kept in a direct-mapped per-thread cache as the walls'
 * samples are (every ray that meets the cell asks; one evaluation each
 * cost a brick wall 18 % more dual evaluations) */
enum { MOVE_CACHE_LOG2 = 10, MOVE_CACHE_ENTRIES = 1 << MOVE_CACHE_LOG2 };
typedef struct move_entry {
    double r[4];                  /* the cell; r[0] >= r[1]: empty */
    int obj;
    vec3 back;                    /* object space; not finite: none */
} move_entry;
struct trace_move_cache { move_entry e[MOVE_CACHE_ENTRIES]; };

static vec3 cell_move(trace_thread *th, const trace_object *obj, const double c[4])
{
    if (!th->moves) th->moves = xcalloc(1, sizeof *th->moves);   /* zeroed: empty */
    move_entry *e = &th->moves->e[trace_cell_slot(c, obj->id, MOVE_CACHE_LOG2)];
    if (trace_cell_is(e->r, e->obj, c, obj->id)) return e->back;
    double uc = 0.5 * (c[0] + c[1]), vc = 0.5 * (c[2] + c[3]);
    trace_surface_point sp;
    trace_surface_point_eval(th, obj, uc, vc, &sp);
    geom_sample g;
    geom_eval(&obj->surf, uc, vc, &g);
    vec3 move = v3_sub(sp.P, mat4_xform_point(&obj->to_camera, g.P));
    e->back = mat4_xform_vector(&obj->from_camera, move);
    if (th->failed) {                   /* a failed run: nothing to keep */
        trace_cell_forget(e->r);
        return v3(NAN, NAN, NAN);
    }
    trace_cell_keep(e->r, &e->obj, c, obj->id);
    return e->back;
}

/* A cell where the displacement left the base surface as it is
 * (TRACE_BOX_UNDISPLACED): the ray against the base surface exactly, as
 * objects without displacement are (geom_intersect), its intersections
 * nearest first (each query from the last one's t: geom_intersect takes
 * only t beyond tmin) until one falls in the cell: that is the cell's
 * hit; none, and the cell has none. True where the cell is settled so;
 * false (the walk goes on as before) only if a closed form gave more
 * intersections than it can have (issue 24: the nail's disk, a
 * displacement masked to 0 or one that only bends N). moved: the cell is
 * the base moved by a constant (TRACE_BOX_OFFSET: a brick's top, a
 * tile's), intersected as the base with the ray moved back. */
static bool exact_cell(walk *w, const double c[4], double tol, bool moved)
{
    geom_hit h;
    double t = w->ray.tmin;
    vec3 o = w->ray.o;
    if (moved) {
        /* the ray moved back by the cell's move meets the base where it
         * meets the moved surface, at the same t */
        vec3 back = cell_move(w->th, w->obj, c);
        if (!v3_is_finite(back)) return false;
        o = v3_sub(o, back);
        w->th->stats.offset_cells++;
    }
    w->th->stats.exact_cells++;
    for (int i = 0; i < EXACT_ROOTS; i++) {
        if (!geom_intersect(&w->obj->surf, o, w->ray.d, t, w->best->t, &h)) return true;
        if (h.u >= c[0] && h.u <= c[1] && h.v >= c[2] && h.v <= c[3]) {
            trace_surface_point sp;
            trace_surface_point_eval(w->th, w->obj, h.u, h.v, &sp);
            proven_hit(w, h.t, tol, &sp);
            return true;
        }
        if (!(h.t > t)) return false;
        t = h.t;
    }
    return false;
}

/* A cell whose displaced surface is one plane piece (TRACE_BOX_PLANAR: a
 * slate's face, a ramp; trace_surface_plane): the ray against that
 * parallelogram, solved in closed form (Cramer's rule on o + t d = Q + e Eu
 * + f Ev), is the cell's hit where (u,v) falls in the cell and t before
 * the best hit; else the cell has none. A hit within 2^-30 of the cell's
 * side outside it is taken, at the cell's edge (where two cells of one
 * plane meet, the rounding of either solve must not let a ray through
 * both). tape: what the cell's box's run took (node_tape). True where the
 * cell is settled so; false (the walk goes on as before) where the plane
 * is degenerate or the ray runs along it
 * (|n . d| below 2^-20 of |n| |d|: t is ill-conditioned there). */
#define PLANAR_GRAZE 0x1p-20
#define PLANAR_MARGIN 0x1p-30
static bool planar_cell(walk *w, const double c[4], double tol, uint32_t tape)
{
    trace_plane pl;
    if (!trace_surface_plane(w->th, w->obj, c[0], c[1], c[2], c[3], tape, &pl)) return false;
    vec3 n = v3_cross(pl.Eu, pl.Ev), d = w->ray.d;
    double nd = v3_dot(n, d), nn = v3_dot(n, n);
    if (!(fabs(nd) > PLANAR_GRAZE * sqrt(nn * v3_dot(d, d)))) return false;
    w->th->stats.planar_cells++;
    w->th->stats.exact_cells++;
    double t = v3_dot(n, v3_sub(pl.Q, w->ray.o)) / nd;
    if (!(t > w->ray.tmin) || !(t < w->best->t)) return true;
    vec3 x = v3_sub(trace_ray_at(&w->ray, t), pl.Q);
    double e = v3_dot(v3_cross(x, pl.Ev), n) / nn, f = v3_dot(v3_cross(pl.Eu, x), n) / nn;
    double u = pl.um + e * pl.ur, v = pl.vm + f * pl.vr;
    double mu = PLANAR_MARGIN * (c[1] - c[0]), mv = PLANAR_MARGIN * (c[3] - c[2]);
    if (!(u >= c[0] - mu && u <= c[1] + mu && v >= c[2] - mv && v <= c[3] + mv)) return true;
    trace_surface_point sp;
    trace_surface_point_eval(w->th, w->obj, fmin(fmax(u, c[0]), c[1]), fmin(fmax(v, c[2]), c[3]),
                             &sp);
    proven_hit(w, t, tol, &sp);
    return true;
}

/* The moves of a TRACE_BOX_PLANES cell's cases (object space;
 * trace_surface_case_moves), kept per cell in a direct-mapped per-thread
 * cache as the single moves are: child_box stores what the cell's cases
 * gave when it made the box, and a cell the cache lost runs its cases
 * again. A pure function of the owner of the boxes and the cell. */
enum { CASE_CACHE_LOG2 = 10, CASE_CACHE_ENTRIES = 1 << CASE_CACHE_LOG2 };
typedef struct case_entry {
    double r[4];                  /* the cell; r[0] >= r[1]: empty */
    int obj;
    trace_case_moves m;
} case_entry;
struct trace_case_cache { case_entry e[CASE_CACHE_ENTRIES]; };

static case_entry *case_slot(trace_thread *th, const trace_object *owner, const double c[4])
{
    if (!th->cases) th->cases = xcalloc(1, sizeof *th->cases);   /* zeroed: empty */
    return &th->cases->e[trace_cell_slot(c, owner->id, CASE_CACHE_LOG2)];
}

static void case_store(trace_thread *th, const trace_object *obj, const double c[4],
                       const trace_case_moves *m)
{
    const trace_object *owner = trace_box_owner(obj);
    case_entry *e = case_slot(th, owner, c);
    trace_cell_keep(e->r, &e->obj, c, owner->id);
    e->m = *m;
}

static const trace_case_moves *case_moves(trace_thread *th, const trace_object *obj,
                                          const double c[4])
{
    const trace_object *owner = trace_box_owner(obj);
    case_entry *e = case_slot(th, owner, c);
    if (!trace_cell_is(e->r, e->obj, c, owner->id)) {
        trace_surface_case_moves(th, owner, c[0], c[1], c[2], c[3], &e->m);
        if (th->failed) {                 /* a failed run: nothing to keep */
            trace_cell_forget(e->r);
            e->m.n = 0;
            return &e->m;
        }
        trace_cell_keep(e->r, &e->obj, c, owner->id);
    }
    return &e->m;
}

/* (u,v) of the point x of a polygon's plane (object space): its (u,v) are
 * affine there, x = P0 + (u - uc) dPdu + (v - vc) dPdv (least squares:
 * the part of x - P0 along the normal is left out) */
static void plane_uv(const geom_sample *g, double uc, double vc, vec3 x, double *u, double *v)
{
    vec3 d = v3_sub(x, g->P);
    double a = v3_dot(g->dPdu, g->dPdu), b = v3_dot(g->dPdu, g->dPdv),
           e = v3_dot(g->dPdv, g->dPdv), p = v3_dot(g->dPdu, d), q = v3_dot(g->dPdv, d);
    double det = a * e - b * b;
    *u = uc + (e * p - b * q) / det;
    *v = vc + (a * q - b * p) / det;
}

/* Whether the segment from (u0,v0) to (u1,v1) misses the rectangle r
 * grown by mu, mv (clipped as Liang and Barsky do) */
static bool segment_misses(double u0, double v0, double u1, double v1, const double r[4],
                           double mu, double mv)
{
    double t0 = 0.0, t1 = 1.0, du = u1 - u0, dv = v1 - v0;
    const double p[4] = {-du, du, -dv, dv},
                 q[4] = {u0 - (r[0] - mu), (r[1] + mu) - u0, v0 - (r[2] - mv), (r[3] + mv) - v0};
    for (int i = 0; i < 4; i++) {
        if (p[i] == 0.0) {
            if (q[i] < 0.0) return true;
            continue;
        }
        double t = q[i] / p[i];
        if (p[i] < 0.0) {
            if (t > t1) return true;
            if (t > t0) t0 = t;
        } else {
            if (t < t0) return true;
            if (t < t1) t1 = t;
        }
    }
    return false;
}

/*
 * A cell whose every case is the flat base moved by a constant
 * (TRACE_BOX_PLANES: a brick's edge, the top and the mortar): its surface
 * is pieces of those parallel planes, and every wall between two pieces
 * lies between the outermost planes (issue 24, "one box per branch").
 * Along the ray, before it first crosses one of the planes it is outside
 * that band and meets nothing of the cell. So:
 *   - the band begins beyond the best hit: nothing of the cell is nearer;
 *   - on a polygon whose cases move it along its normal alone, the ray's
 *     stretch in the band lies over a segment of (u,v): one that misses
 *     the cell misses everything of it;
 *   - where the first crossing falls in the cell on the surface (the point
 *     evaluated: its displacement there is that plane's move), it is the
 *     cell's hit.
 * True where one of these settles the cell, without subdividing it down
 * to the wall. Otherwise false and the walk goes on: the ray crosses into
 * the band over another piece (a wall or a lower piece may be its hit),
 * starts inside the band, or runs along the planes.
 */
static bool planes_cell(walk *w, const double c[4], double tol)
{
    const trace_case_moves *m = case_moves(w->th, w->obj, c);
    int n = m->n;
    if (n < 2) return false;
    const trace_ray *ray = &w->ray;
    double uc = 0.5 * (c[0] + c[1]), vc = 0.5 * (c[2] + c[3]);
    geom_sample g;
    geom_eval(&w->obj->surf, uc, vc, &g);
    vec3 nrm = g.Ng;
    double dn = v3_dot(nrm, ray->d), nl = v3_length(nrm);
    if (!(fabs(dn) > 1e-6 * nl * v3_length(ray->d))) return false;   /* along the planes */
    int first = -1;
    double t1 = INFINITY, t2 = -INFINITY, mmax = 0.0;
    bool normal_moves = true;             /* every move less the first's along nrm */
    for (int k = 0; k < n; k++) {
        double tk = v3_dot(nrm, v3_sub(v3_add(g.P, m->move[k]), ray->o)) / dn;
        if (!(tk > ray->tmin)) return false;        /* starts in or beyond the band */
        if (tk < t1) {
            t1 = tk;
            first = k;
        }
        t2 = fmax(t2, tk);
        vec3 dm = v3_sub(m->move[k], m->move[0]);
        normal_moves = normal_moves &&
                       v3_length(v3_cross(dm, nrm)) <= 1e-9 * v3_length(dm) * nl;
        mmax = fmax(mmax, v3_length(m->move[k]));
    }
    w->th->stats.plane_cells++;
    /* a thousandth of t's for the rounding of the t computed here against
     * the walk's own */
    if (t1 * (1.0 - 1e-3) >= w->best->t) return true;
    double scale = v3_length(g.P) + v3_length(ray->o) + mmax;
    if (w->obj->surf.kind == GEOM_POLYGON && normal_moves) {
        /* the band's stretch of the ray, to the best hit, over (u,v): the
         * points less the first move, which the others only lengthen
         * along the normal; margins far above the rounding */
        double te = fmin(t2, w->best->t), ua, va, ub, vb;
        plane_uv(&g, uc, vc, v3_sub(trace_ray_at(ray, t1), m->move[0]), &ua, &va);
        plane_uv(&g, uc, vc, v3_sub(trace_ray_at(ray, te), m->move[0]), &ub, &vb);
        double mu = 1e-6 * (c[1] - c[0]) + 1e-9 * scale / v3_length(g.dPdu),
               mv = 1e-6 * (c[3] - c[2]) + 1e-9 * scale / v3_length(g.dPdv);
        if (isfinite(ua) && isfinite(va) && isfinite(ub) && isfinite(vb) &&
            segment_misses(ua, va, ub, vb, c, mu, mv)) {
            w->th->stats.plane_misses++;
            return true;
        }
    }
    geom_hit h;
    vec3 o = v3_sub(ray->o, m->move[first]);
    if (!geom_intersect(&w->obj->surf, o, ray->d, ray->tmin, INFINITY, &h) ||
        !(h.u >= c[0] && h.u <= c[1] && h.v >= c[2] && h.v <= c[3]))
        return false;
    trace_surface_point sp;
    trace_surface_point_eval(w->th, w->obj, h.u, h.v, &sp);
    geom_sample b;
    geom_eval(&w->obj->surf, h.u, h.v, &b);
    vec3 p = mat4_xform_point(&w->obj->from_camera, sp.P);
    if (!(v3_length(v3_sub(v3_sub(p, b.P), m->move[first])) <= 1e-9 * scale)) return false;
    /* and no other plane within that of it along the normal (a piece of
     * another case so near could be the one the point is on) */
    for (int k = 0; k < n; k++) {
        vec3 dm = v3_sub(m->move[k], m->move[first]);
        bool same = dm.x == 0.0 && dm.y == 0.0 && dm.z == 0.0;
        if (!same && fabs(v3_dot(nrm, dm)) / nl <= 1e-6 * scale) return false;
    }
    w->th->stats.plane_hits++;
    proven_hit(w, h.t, tol, &sp);
    return true;
}

/* The stagnant-box fallback (issue 9; docs/renderer.md "Stagnant boxes").
 * Range arithmetic loses the correlation of some continuous idioms, and
 * their boxes then stop shrinking along a curve of (u,v): a box-filtered
 * pulse train (floor(x) and x - floor(x) jump together where x crosses an
 * integer, their sum does not), normalize(calculatenormal(P)) at a pole.
 * Every cell along such a seam keeps a fat box that every nearby ray
 * meets, so the walk fans out exponentially into the work limit and the
 * surface there is lost. When a child's bounded box is flagged
 * discontinuous (only a flagged operation can lose such a correlation
 * without an unbounded result) and keeps more than TRACE_NO_SHRINK of its
 * parent's size, at depth TRACE_SAMPLE_DEPTH or deeper (cells of at most
 * 1/64 of the (u,v) square per side), the
 * surface is sampled on a 3x3 grid of the cell (dual mode); if the
 * samples follow the trapezoid rule (a continuous surface at this scale:
 * residual at most a quarter of their spread), the child's box becomes
 * their hull widened by twice the residual. This is an estimate, not a
 * proof: a step-built feature narrower than the sample spacing (1/128 of
 * the square at the first level sampled) inside such a cell can be
 * missed; surfaces whose operations are all continuous never take this
 * path and keep the guarantee. It is used only where the proof had
 * already failed, and each use is counted (stats: sampled_boxes). A pure
 * function of the cell, so it is cached like any box. Returns true when it
 * replaced the box. */
static bool sample_stagnant(trace_thread *th, const trace_object *obj, const double r[4],
                            trace_box *box)
{
    cell_samples cs;
    th->stats.samplings++;
    /* the samples lie in the box (object space), so their spread in camera
     * space is at most its diagonal times the object's stretch (scale):
     * a residual above a quarter of that fails the test below, whatever
     * the rest of the samples (a jump at a wall: half the samples on
     * average, issue 24) */
    vec3 diag = v3_sub(box->hi, box->lo);
    double bound = 0.25 * v3_length(diag) * obj->scale * (1.0 + 1e-6);
    sample_cell(th, obj, r, isfinite(bound) ? bound : INFINITY, &cs);
    if (cs.n < CELL_N) return false;
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    double spread = 0;
    for (int k = 0; k < CELL_N; k++) {
        vec3 p = mat4_xform_point(&obj->from_camera, cs.P[k]);
        lo = v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
        spread = fmax(spread, v3_length(v3_sub(cs.P[k], cs.P[0])));
    }
    if (!(cs.residual <= 0.25 * spread) && !(spread == 0)) return false;
    /* twice the camera-space residual in object units (world.c's bound of
     * the stretch of from_camera), and a rounding hair */
    double m = 2.0 * cs.residual * sqrt(obj->normal_len2[1]) +
               1e-12 * (1.0 + fmax(v3_length(lo), v3_length(hi)));
    box->lo = v3_sub(lo, v3(m, m, m));
    box->hi = v3_add(hi, v3(m, m, m));
    box->flags &= ~(unsigned)AA_DISCONTINUOUS;
    box->flags |= TRACE_BOX_SAMPLED;
    trace_box_no_slab(box);
    box->bend = 1e30f;                /* no slopes there: no hit proofs */
    th->stats.sampled_boxes++;
    return true;
}

/* A discontinuous box that kept more than TRACE_NO_SHRINK of its
 * parent's size (§5: smooth boxes halve, roughly) */
static bool stagnant(const trace_box *b, double parent_extent)
{
    return (b->flags & AA_DISCONTINUOUS) && !(b->flags & AA_UNBOUNDED) &&
           !trace_box_is_empty(b) && trace_box_extent(b) >= TRACE_NO_SHRINK * parent_extent;
}

/* The decisions a node's children's runs take (tape pruning: the node's
 * box's tape, displace.c): none below an object's root (instances that
 * share their prototype's broods have roots of their own, which a child's
 * box must not depend on) */
static uint32_t node_tape(trace_brood_id parent, const trace_box *node)
{
    return parent == TRACE_BROOD_NONE ? 0 : node->tape;
}

/* Child i's box, evaluated: the shader's run over its cell (with the
 * cases of its seams, then samples, where it stagnates; taking the
 * decisions `tape` of its node's run, node_tape), met with the
 * restricted bound of the node's linear bound where the node has one
 * (box.h). The caller stores it, which rounds it outward as the cache
 * keeps it (trace_boxcache_insert_kept: a hit and a miss give the same
 * box) */
static void child_box(walk *w, const trace_box *node, const trace_dlin *lin, const double r[4],
                      int depth, int i, uint32_t tape, trace_box *kid, trace_lin *kid_lin)
{
    trace_thread *th = w->th;
    const trace_object *owner = trace_box_owner(w->obj);
    double node_extent = trace_box_extent(node);
    double c[4];
    child_range(i, r[0], r[1], r[2], r[3], c);
    /* below a box its cases narrowed, the children run their cases first
     * (the plain run of one across the same seam is stagnant again) */
    bool cases_first = (node->flags & TRACE_BOX_SPLIT) != 0, split = false;
    trace_case_moves moves;
    moves.n = 0;                          /* set by the cases below, where they run */
    if (cases_first)
        split = trace_surface_box_split(th, owner, c[0], c[1], c[2], c[3], kid, kid_lin, &moves);
    else
        trace_surface_box_tape(th, owner, c[0], c[1], c[2], c[3], tape, kid, kid_lin);
    if (stagnant(kid, node_extent)) {
        /* issue 24: the cases of a seam, then (still stagnant) samples;
         * below a box they did not narrow, not again (a pattern whose
         * seams overflow the cases); with its cases run first, not again */
        if (cases_first ? !split
                        : (node->flags & TRACE_BOX_UNSPLIT) ||
                              !trace_surface_box_cases(th, owner, c[0], c[1], c[2], c[3], kid,
                                                       kid_lin, &moves))
            kid->flags |= TRACE_BOX_UNSPLIT;
        /* across a proven step (the cases' boxes apart, box.h), its
         * stagnant children too: the samples could only find the jump
         * (or, in a cell beside it that the range has not yet decided,
         * estimate a box the subdivision will prove) */
        if (!cases_first && (node->flags & (TRACE_BOX_UNSPLIT | TRACE_BOX_STEP)) ==
                                (TRACE_BOX_UNSPLIT | TRACE_BOX_STEP))
            kid->flags |= TRACE_BOX_STEP;
        if (depth >= TRACE_SAMPLE_DEPTH && stagnant(kid, node_extent) &&
            !(kid->flags & TRACE_BOX_STEP))
            sample_stagnant(th, owner, c, kid);
    }
    /* the planes of its cases, for the walk (planes_cell) */
    if (kid->flags & TRACE_BOX_PLANES) case_store(th, w->obj, c, &moves);
    /* an estimate: its children are made from their runs alone */
    if (kid->flags & TRACE_BOX_SAMPLED) kid->flags &= ~(unsigned)TRACE_BOX_LIN;
    if (lin) {
        trace_box rb;
        trace_box_restrict(lin, node, r, c, &rb);
        trace_box_meet(kid, &rb);
    }
}

/* The node's linear bound decoded, or NULL where it has none: from its
 * brood's codes (the lookups copy none), or where its brood could not be
 * stored, from the codes the walk kept (node_q). None at an object's
 * root: instances that share their prototype's broods have roots of
 * their own. */
static const trace_dlin *node_lin(const walk *w, trace_brood_id parent, int slot,
                                  const trace_box *node, const trace_qlin *node_q, trace_dlin *d)
{
    if (!(node->flags & TRACE_BOX_LIN) || parent == TRACE_BROOD_NONE) return NULL;
    const trace_qlin *q = parent >= 0 ? trace_boxcache_qlin(w->th->cache, parent, slot) : node_q;
    assert(q != NULL);
    trace_box_lin(q, node, d);
    return d;
}

/*
 * The node's children (the brood of its four cells), from the box cache
 * or made here; their linear bounds' codes in kq where the brood could not
 * be stored. Lazy children (issue 24): below a node with a linear bound
 * a new brood holds only the children's restricted bounds
 * (TRACE_BOX_LAZY); visit evaluates a child when a ray meets its
 * restricted bound (lazy_child). A child's box is the same either way,
 * child_box's, which its restricted bound holds, so no ray that misses
 * the bound could meet the box: the cache's state never changes a walk.
 */
static trace_brood_id children_of(walk *w, trace_brood_id parent, int slot,
                                  const double r[4], const trace_box *node,
                                  const trace_qlin *node_q, int depth, trace_box kids[4],
                                  trace_qlin kq[4])
{
    trace_thread *th = w->th;
    /* instances sharing a prototype's boxes share its cache entries */
    const trace_object *owner = trace_box_owner(w->obj);
    /* the boxes as float offsets from the node's box (box.h, trace_fbox);
     * an object's root box may differ between instances sharing the
     * prototype's broods: the root's children are stored without a base */
    const trace_box *base = parent == TRACE_BROOD_NONE ? NULL : node;
    trace_brood_id id = trace_boxcache_lookup_at(th->cache, owner->id, parent, slot, base, kids);
    if (id != TRACE_BROOD_NONE) return id;
    trace_dlin d;
    const trace_dlin *lin = node_lin(w, parent, slot, node, node_q, &d);
    trace_lin lins[4];
    bool lazy = lin && th->world->options.lazy_children;
    for (int i = 0; i < 4; i++) {
        if (lazy) {
            double c[4];
            child_range(i, r[0], r[1], r[2], r[3], c);
            trace_box_restrict(lin, node, r, c, &kids[i]);
            th->stats.lazy_bounds++;
        } else {
            child_box(w, node, lin, r, depth, i, node_tape(parent, node), &kids[i], &lins[i]);
        }
    }
    return trace_boxcache_insert_kept(th->cache, owner->id, parent, slot, base, kids,
                                      lazy ? NULL : lins, kq);
}

/* A lazy child that a ray meets: evaluated (child_box) and kept in its
 * brood (its codes in *kq as well) */
static void lazy_child(walk *w, trace_brood_id brood, trace_brood_id parent, int slot,
                       const trace_box *node, const trace_qlin *node_q, const double r[4],
                       int depth, int i, trace_box *kid, trace_qlin *kq)
{
    const trace_box *base = parent == TRACE_BROOD_NONE ? NULL : node;
    trace_dlin d;
    const trace_dlin *lin = node_lin(w, parent, slot, node, node_q, &d);
    assert(lin != NULL);                 /* a lazy child's node has one */
    trace_lin kid_lin;
    w->th->stats.lazy_evals++;
    child_box(w, node, lin, r, depth, i, node_tape(parent, node), kid, &kid_lin);
    trace_boxcache_update_kept(w->th->cache, brood, i, base, kid, &kid_lin, kq);
}

/* Bounded work (issue 9): a walk ends after max_nodes_per_ray nodes, or
 * at once when the render is cancelled. The hits found so far stay; the
 * ray and the (u,v) range where it stopped are counted per object. */
static bool over_limit(walk *w, const double r[4])
{
    if (w->stopped) return true;
    trace_thread *th = w->th;
    if (++w->nodes <= th->world->options.max_nodes_per_ray && !th->failed &&
        !trace_thread_cancelled(th))
        return false;
    w->stopped = true;
    if (th->failed) return true;           /* failed or cancelled: the tile ends */
    th->stats.limited_rays++;
    trace_object_work *ow = &th->work[w->obj->top];
    if (!ow->probed || ow->diverges) {     /* converge.h: fail fast where hopeless */
        ow->probed = true;
        char err[ERR_LEN];
        ow->diverges = !trace_surface_converges(th, w->obj, err, sizeof err);
        if (ow->diverges)
            trace_thread_fail(th, err);    /* again on every tile this thread retries */
    }
    if (ow->limited_rays++ == 0) {
        ow->u0 = r[0]; ow->u1 = r[1]; ow->v0 = r[2]; ow->v1 = r[3];
    } else {
        ow->u0 = fmin(ow->u0, r[0]); ow->u1 = fmax(ow->u1, r[1]);
        ow->v0 = fmin(ow->v0, r[2]); ow->v1 = fmax(ow->v1, r[3]);
    }
    return true;
}

/* Proofs only on cells a cell's width or more away from the edges a
 * polygon shares with another (see visit) */
static bool clear_of_shared_edges(const walk *w, const double c[4])
{
    return !w->obj->shared_edges ||
           geom_uv_box_clear_of(&w->obj->surf, 2 * c[0] - c[1], 2 * c[1] - c[0], 2 * c[2] - c[3],
                                2 * c[3] - c[2], w->obj->shared_edges);
}

/* Whether the ray meets a surface of camera-space normal n at |cos| of
 * their angle below cos_max (a zero n: true) */
static bool ray_grazes(const walk *w, vec3 n, double cos_max)
{
    vec3 d = w->cam_ray->d;
    double nn = v3_dot(n, n), dd = v3_dot(d, d), nd = v3_dot(n, d);
    return !(nd * nd > cos_max * cos_max * nn * dd);
}

/*
 * Where a leaf's first point goes (issue 24, session 29). Its box's
 * linear bound (lin_bound.h) says that over the cell the surface lies
 * within r of the plane x + U eu + V ev, eu and ev in [-1, 1] the cell's
 * u and v as aa_input maps them: the affine run fitted that plane over
 * the whole cell. Where the ray meets it (clamped to the cell) is about
 * where a Newton step from the centre would go, so the steps started
 * there (leaf_point) settle one evaluation sooner: the corpus's fbm_du on
 * the wall 2.0 -> 1.06 dual evaluations a leaf. Only where the steps
 * start changes; the leaf, its box and the tests are the same, and the
 * point is a pure function of the box and its codes (cached or not).
 *
 * The centre instead where the box has no bound (or no bend: planar, or
 * unknown), the cell is the polygon's only in part (a partial cell's one
 * step comes from its centre: leaf_point), the ray runs within
 * LEAF_START_GRAZE of along the plane, the world's option leaf_start is
 * off, or the run saw a crease or a jump in the cell (AA_KINK: an abs
 * across 0, a min or max undecided; AA_DISCONTINUOUS): at a crease
 * (dented's abs()) a start on the plane often settles at once where the
 * steps from the centre would not, and the cell then goes without the
 * test visit gives a leaf that does not settle. Against the peer
 * dented's 1/16-pixel reference: 145 pixels off with the centre, 201
 * with starts in every cell; a limit on the bend instead of the creases
 * (0.1) kept it at 144 but left out most cells of fbm with fixed octaves.
 * And on an object whose displacement reads a texture (bend_unknown): a
 * lookup over several texels is a bound, whose linear part says nothing
 * of where the ray meets the map (the peer terrain: 379 pixels off its
 * 1/16-pixel reference with starts on the plane, 353 without).
 */
#define LEAF_START_GRAZE 0x1p-10        /* |cos| of the ray's angle to the plane's normal */

/* The point of [lo, hi] where a symbol e in [-1, 1] puts it, as aa_input
 * maps the cell (its midpoint, the larger half), kept in [lo, hi] */
static double cell_at(double lo, double hi, double e)
{
    double m = aa_input_mid(lo, hi), half = m - lo > hi - m ? m - lo : hi - m;
    return fmin(fmax(m + e * half, lo), hi);
}

static void leaf_start_uv(const walk *w, const trace_box *kid, const trace_qlin *q,
                          const double c[4], geom_cover cover, double *u, double *v)
{
    *u = 0.5 * (c[0] + c[1]);
    *v = 0.5 * (c[2] + c[3]);
    if (!(kid->flags & TRACE_BOX_LIN) || !q || cover != GEOM_INSIDE || !(kid->bend > 0.0f) ||
        (kid->flags & (AA_KINK | AA_DISCONTINUOUS)) || w->obj->bend_unknown ||
        !w->th->world->options.leaf_start)
        return;
    trace_dlin d;
    trace_box_lin(q, kid, &d);
    vec3 x = v3(d.x[0], d.x[1], d.x[2]), U = v3(d.u[0], d.u[1], d.u[2]),
         V = v3(d.v[0], d.v[1], d.v[2]), n = v3_cross(U, V);
    const trace_ray *ray = &w->ray;
    double nd = v3_dot(n, ray->d), nn = v3_dot(n, n);
    if (!(nd * nd > LEAF_START_GRAZE * LEAF_START_GRAZE * nn * v3_dot(ray->d, ray->d)))
        return;                          /* along the plane, or no plane (NaN) */
    /* x + U eu + V ev = o + t d: t from the normal, then eu, ev */
    double t = v3_dot(n, v3_sub(x, ray->o)) / nd;
    vec3 p = v3_sub(trace_ray_at(ray, t), x);
    double eu = v3_dot(v3_cross(p, V), n) / nn, ev = v3_dot(v3_cross(U, p), n) / nn;
    if (!(eu == eu) || !(ev == ev)) return;
    *u = cell_at(c[0], c[1], fmin(fmax(eu, -1.0), 1.0));
    *v = cell_at(c[2], c[3], fmin(fmax(ev, -1.0), 1.0));
    w->th->stats.leaf_starts++;
}

/* The leaf's first point (leaf_start_uv) evaluated, in *sp; `i` the
 * child's number in its brood, whose codes kq holds where the brood is
 * not stored */
static void leaf_start(walk *w, const trace_box *kid, trace_brood_id brood, const trace_qlin kq[4],
                       int i, const double c[4], geom_cover cover, trace_surface_point *sp)
{
    const trace_qlin *q = brood >= 0 ? trace_boxcache_qlin(w->th->cache, brood, i) : &kq[i];
    double u, v;
    leaf_start_uv(w, kid, q, c, cover, &u, &v);
    trace_surface_point_eval(w->th, w->obj, u, v, sp);
}

/* Whether the ray grazes the surface at the point sp: the displaced
 * surface's normal Pu x Pv at TRACE_PROVE_GRAZE. A leaf there may be a
 * near miss at a fold (a silhouette), which finer leaves resolve. */
static bool grazes(const walk *w, const trace_surface_point *sp)
{
    return ray_grazes(w, v3_cross(sp->Pu, sp->Pv), TRACE_PROVE_GRAZE);
}

/* The hit test on the cell c (prove.h), a proven hit recorded */
static trace_proof test_cell(walk *w, const double c[4], double tol, trace_proof_detail *why)
{
    double t;
    trace_surface_point sp;
    trace_proof pr = trace_prove_hit(w->th, w->obj, w->cam_ray, c, w->ray.tmin, w->best->t,
                                     &w->zero, &t, &sp, why);
    if (pr == TRACE_PROOF_HIT) proven_hit(w, t, tol, &sp);
    return pr;
}

/* Whether the ray's stretch [t0, t1] in a child's box (or bound) misses
 * its stretch [nt0, nt1] in the node's box and slab, which hold the
 * child's surface too: then it cannot meet the surface over the child,
 * and the child is skipped (issue 24: dented's boxes 292 k -> 278 k;
 * the stretch itself is not narrowed). Not on cells near an
 * edge the polygon shares with another: there a leaf's hit may come from
 * its Newton steps into the next cell, across the edge, as both polygons'
 * leaves must apply alike (without this, test_corpus_render's fw_grooves
 * on the mesh missed a sure pixel; clear_of_shared_edges). */
static bool beside_node(const walk *w, const double c[4], double t0, double t1, double nt0,
                        double nt1)
{
    return (t1 < nt0 || t0 > nt1) && clear_of_shared_edges(w, c);
}

/* Whether the ray meets an evaluated child's box and slab before tmax and
 * not beside its node's stretch [nt0, nt1]: its stretch in *t0, *t1 and
 * its axis of entry in *axis */
static bool meets_child(const walk *w, const trace_box *kid, const double c[4], double tmax,
                        double nt0, double nt1, double *t0, double *t1, int *axis)
{
    return trace_box_hit(kid, &w->ray, w->ray.tmin, tmax, t0, t1, axis) &&
           trace_box_slab_hit(kid, &w->ray, t0, t1) && !beside_node(w, c, *t0, *t1, nt0, nt1);
}

/* node_q: the node's linear bound's codes where its brood (parent) could
 * not be stored; nt0, nt1: the ray's stretch in the node's box and slab */
static void visit(walk *w, const trace_box *node, const trace_qlin *node_q, const double r[4],
                  trace_brood_id parent, int slot, int depth, bool fine, geom_cover node_cover,
                  double nt0, double nt1)
{
    if (over_limit(w, r)) return;
    trace_box kids[4];
    trace_qlin kq[4];
    trace_brood_id brood = children_of(w, parent, slot, r, node, node_q, depth, kids, kq);
    trace_boxcache_pin(w->th->cache, brood);

    child_order order[4];
    int n = 0;
    double node_extent = trace_box_extent(node);
    /* every box test of this node's children clips the ray at the hit it
     * had on entry, wherever in the walk the test is made */
    const double tmax = w->best->t;
    for (int i = 0; i < 4; i++) {
        double c[4];
        child_range(i, r[0], r[1], r[2], r[3], c);
        if (trace_box_is_empty(&kids[i]) && !(kids[i].flags & AA_UNBOUNDED)) continue;
        /* inside the base surface's domain: so are the node's parts */
        geom_cover cover = node_cover == GEOM_INSIDE
                               ? GEOM_INSIDE
                               : geom_uv_box_cover(&w->obj->surf, c[0], c[1], c[2], c[3]);
        if (cover == GEOM_OUTSIDE) continue;
        double t0, t1;
        int axis;
        if (kids[i].flags & TRACE_BOX_LAZY) {
            /* pending where the ray meets its restricted bound: evaluated
             * when the walk reaches it (below) */
            if (!trace_box_hit(&kids[i], &w->ray, w->ray.tmin, tmax, &t0, &t1, NULL) ||
                beside_node(w, c, t0, t1, nt0, nt1))
                continue;
            w->th->stats.lazy_met++;
            order_insert(order, &n, (child_order){t0, t1, i, -1, cover, true});
            continue;
        }
        if (!meets_child(w, &kids[i], c, tmax, nt0, nt1, &t0, &t1, &axis)) continue;
        order_insert(order, &n, (child_order){t0, t1, i, axis, cover, false});
    }

    for (int k = 0; k < n && !(w->any && w->found) && !w->stopped; k++) {
        if (!(order[k].t0 < w->best->t)) break;
        if (order[k].pending) {
            /* a lazy child the walk reaches (issue 24): evaluated now, and
             * back in the order at its box's entry. Its bound holds its
             * box, so the bound's entry is at most the box's: the children
             * are walked in the order of their boxes' entries, ties by
             * number, as if all had been evaluated first, and none whose
             * bound starts beyond the hit is evaluated at all */
            child_order o = order[k];
            for (int j = k + 1; j < n; j++) order[j - 1] = order[j];
            n--;
            int i = o.i;
            double t0, t1, c[4];
            int axis;
            child_range(i, r[0], r[1], r[2], r[3], c);
            lazy_child(w, brood, parent, slot, node, node_q, r, depth, i, &kids[i], &kq[i]);
            if (!(trace_box_is_empty(&kids[i]) && !(kids[i].flags & AA_UNBOUNDED)) &&
                meets_child(w, &kids[i], c, tmax, nt0, nt1, &t0, &t1, &axis)) {
                o.t0 = t0;
                o.t1 = t1;
                o.axis = axis;
                o.pending = false;
                /* among the rest, from k on (all enter at or after o's
                 * bound) */
                int m = n - k;
                order_insert(order + k, &m, o);
                n = k + m;
            }
            k--;                         /* position k again */
            continue;
        }
        const trace_box *kid = &kids[order[k].i];
        double c[4];
        child_range(order[k].i, r[0], r[1], r[2], r[3], c);
        double size = trace_box_extent(kid) * w->obj->scale;
        double t_at = order[k].t0 > 0 ? order[k].t0 : 0;
        double tol = w->tol.a + w->tol.b * t_at;
        int d = depth + 1;
        if ((kid->flags & (TRACE_BOX_UNDISPLACED | TRACE_BOX_OFFSET)) && w->exact_cells &&
            clear_of_shared_edges(w, c) &&
            exact_cell(w, c, tol, (kid->flags & TRACE_BOX_OFFSET) != 0))
            continue;
        if ((kid->flags & TRACE_BOX_PLANES) && w->exact_cells && clear_of_shared_edges(w, c) &&
            planes_cell(w, c, tol))
            continue;
        if ((kid->flags & TRACE_BOX_PLANAR) && w->exact_cells && order[k].cover == GEOM_INSIDE &&
            clear_of_shared_edges(w, c) && planar_cell(w, c, tol, node_tape(parent, node)))
            continue;
        bool unbounded = (kid->flags & AA_UNBOUNDED) != 0;
        vec3 wall_n = v3(0, 0, 0);
        bool kid_fine = false, capped = false;
        /* proofs only on cells a cell's width or more away from the
         * edges a polygon shares with another: there the leaves stay,
         * which the two polygons apply alike (an exact miss on one side
         * next to an estimate on the other opened cracks: tests/corpus,
         * mesh); at an edge of its own a proof draws it exactly */
        bool provable = w->prove && !unbounded && !(kid->flags & AA_DISCONTINUOUS) &&
                        size <= TRACE_PROVE_CELLS * tol;
        bool try_proof = provable && (kid->bend <= TRACE_PROVE_BEND || w->obj->bend_unknown) &&
                         size <= w->prove_below;
        bool at_leaf = provable && size <= tol && d < TRACE_MAX_DEPTH;
        if ((try_proof || at_leaf) && !clear_of_shared_edges(w, c)) try_proof = at_leaf = false;
        /* the leaf's first point (leaf_start), where the graze test looks
         * and Newton's steps start */
        trace_surface_point start;
        bool started = false, grazing = false;
        /* a whole cell of a leaf's size where the ray does not graze the
         * surface: its test would only place the leaf's point, which the
         * leaf's own Newton steps place where they settle; tested (below)
         * only where they do not */
        if (try_proof && at_leaf && !fine && !w->obj->bend_unknown &&
            order[k].cover == GEOM_INSIDE) {
            started = true;
            leaf_start(w, kid, brood, kq, order[k].i, c, order[k].cover, &start);
            grazing = grazes(w, &start);
            if (!grazing && !leaf_hit(w, kid, c, &order[k], TRACE_LEAF_SMALL, wall_n, &start, true))
                continue;
        }
        if (try_proof) {
            trace_proof_detail why;
            if (test_cell(w, c, tol, &why) != TRACE_PROOF_UNKNOWN) continue;
            /* an undecided test: this walk tries again only on cells small
             * enough for K to fit (prove.h, spread); none after a cell
             * without slopes (a jump, a singularity) */
            if (why.spread > 1.0) w->prove_below = fmin(w->prove_below, size / why.spread);
            kid_fine = why.fold;
        }
        kid_fine = kid_fine || fine;
        /* a leaf where the ray grazes the surface: finer leaves */
        if (!kid_fine && at_leaf) {
            if (!started) {
                leaf_start(w, kid, brood, kq, order[k].i, c, order[k].cover, &start);
                grazing = grazes(w, &start);
            }
            started = true;
            kid_fine = grazing && trace_prove_cell_has_slopes(w->th, w->obj, c);
        }
        if (d >= TRACE_MAX_DEPTH) {
            leaf_hit(w, kid, c, &order[k], TRACE_LEAF_DEPTH, wall_n, NULL, false);
            continue;
        }
        if (!unbounded && size <= (kid_fine ? tol * TRACE_PROVE_LEAF : tol)) {
            /* a leaf whose point did not settle in the cell, tested here if
             * it was not above: a proven miss drops it, a proven hit is
             * exact, a fold takes finer leaves */
            bool may_test = at_leaf && !try_proof && !kid_fine;
            if (!started)
                leaf_start(w, kid, brood, kq, order[k].i, c, order[k].cover, &start);
            started = true;
            if (!leaf_hit(w, kid, c, &order[k], TRACE_LEAF_SMALL, wall_n, &start, may_test))
                continue;
            trace_proof_detail why;
            w->th->stats.leaf_tests++;
            if (test_cell(w, c, tol, &why) != TRACE_PROOF_UNKNOWN) continue;
            if (!why.fold) {
                /* the leaf as its steps left it (from the same start:
                 * the same point, no evaluation of the start again) */
                leaf_hit(w, kid, c, &order[k], TRACE_LEAF_SMALL, wall_n, &start, false);
                continue;
            }
            kid_fine = true;
        } else if (!unbounded && (kid->flags & AA_DISCONTINUOUS) &&
                   trace_box_extent(kid) >= TRACE_NO_SHRINK * node_extent &&
                   box_min_extent(kid) * w->obj->scale <= (kid_fine ? tol * TRACE_PROVE_LEAF : tol) &&
                   real_wall(w, c, tol, order[k].t0, order[k].t1, &wall_n, &capped)) {
            /* a wall the ray grazes (the shaft's silhouette), or meets
             * near where it joins the surface (capped: the nail's rim and
             * foot): finer leaves, as at a fold, so that the wall is drawn
             * neither a leaf too wide nor over the surface beside it */
            bool grazed = v3_dot(wall_n, wall_n) > 0 && ray_grazes(w, wall_n, TRACE_WALL_GRAZE);
            if (kid_fine || !(capped || grazed)) {
                leaf_hit(w, kid, c, &order[k], TRACE_LEAF_WALL, wall_n, NULL, false);
                continue;
            }
            kid_fine = true;
        }
        visit(w, kid, brood >= 0 ? NULL : &kq[order[k].i], c, brood, order[k].i, d, kid_fine,
              order[k].cover, order[k].t0, order[k].t1);
    }
    trace_boxcache_unpin(w->th->cache, brood);
}

static void object_ray(const trace_object *obj, const trace_ray *cam, double tmax,
                       trace_ray *out)
{
    vec3 o = mat4_xform_point(&obj->from_camera, cam->o);
    vec3 d = mat4_xform_vector(&obj->from_camera, cam->d);
    trace_ray_init(out, o, d, cam->tmin, tmax);
}

static bool intersect_displaced(trace_thread *th, const trace_object *obj,
                                const trace_ray *ray, const trace_tolerance *tol,
                                bool any, trace_hit *best)
{
    walk w = {.th = th, .obj = obj, .cam_ray = ray, .tol = *tol, .any = any,
              .found = false, .prove = th->world->options.prove_hits && trace_prove_eligible(obj),
              .prove_below = INFINITY,
              .exact_cells = exact_kind(obj->surf.kind),
              .best = best};
    object_ray(obj, ray, best->t, &w.ray);
    double t0, t1;
    if (!trace_box_hit(&obj->root, &w.ray, ray->tmin, best->t, &t0, &t1, NULL))
        return false;
    double r[4] = {0, 1, 0, 1};
    /* the whole domain's cover: a polygon that fills its (u,v) square (a
     * quad: the wave's, the nail's) is inside at the root, and no node of
     * the walk tests its children against the edges again (issue 24: four
     * tests a ray at the root, 2 % of the wave's frame) */
    geom_cover root_cover = geom_uv_box_cover(&obj->surf, r[0], r[1], r[2], r[3]);
    if (root_cover == GEOM_OUTSIDE)
        return false;
    visit(&w, &obj->root, NULL, r, TRACE_BROOD_NONE, 0, 0, false, root_cover, t0, t1);
    th->stats.nodes += w.nodes;
    if (w.nodes > th->stats.max_nodes_per_ray) th->stats.max_nodes_per_ray = w.nodes;
    return w.found;
}

static bool intersect_exact(const trace_object *obj, const trace_ray *ray,
                            trace_hit *best)
{
    trace_ray oray;
    object_ray(obj, ray, best->t, &oray);
    geom_hit h;
    if (!geom_intersect(&obj->surf, oray.o, oray.d, ray->tmin, best->t, &h)) return false;
    if (!(h.t < best->t)) return false;
    best->t = h.t;
    best->obj = obj;
    best->u = h.u;
    best->v = h.v;
    best->leaf_size = 0;
    best->kind = TRACE_LEAF_EXACT;
    best->wall_normal = v3(0, 0, 0);
    best->has_point = false;
    return true;
}

bool trace_intersect_object(trace_thread *th, const trace_object *obj,
                            const trace_ray *ray, const trace_tolerance *tol,
                            bool any, trace_hit *best)
{
    if (obj->displacement) return intersect_displaced(th, obj, ray, tol, any, best);
    return intersect_exact(obj, ray, best);
}
