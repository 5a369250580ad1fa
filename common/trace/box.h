/*
 * box.h: axis-aligned boxes in camera space and the ray/box slab test.
 *
 * A trace_box is what the bounding arithmetic (affine or interval) gives for
 * the displaced surface over one (u,v) range (Heidrich & Seidel §3): the
 * ranges of x, y, z. It also carries the flags of those ranges
 * (AA_DISCONTINUOUS, AA_UNBOUNDED, aa/interval.h), which the subdivision
 * uses for the §5 termination rule.
 *
 * The slab test is conservative under rounding: the far distance is widened
 * by 2*gamma(3) as in pbrt (Pharr, Jakob, Humphreys, "Physically Based
 * Rendering" 3rd ed., §3.9.2), so a ray that truly meets the box is never
 * reported as a miss. Boxes themselves are conservative (common/aa), so
 * together no hit is lost to floating point.
 *
 * A box of a displaced surface may also carry one more slab (issue 10):
 * the surface over the cell lies between the planes n . P = slo and
 * n . P = shi, n the unit normal of the plane spanned by the affine forms'
 * u and v terms (the cell's mean tangent plane), [slo, shi] the range of
 * the affine form n . P (rounded outward: displace.c; in the box cache as
 * floats rounded outward again, trace_fbox below). A box is as thick as
 * the cell is tilted against the axes; the slab only as thick as the
 * surface is bumpy, so a grazing ray leaves it far sooner (the paper's
 * wave: 2.4x fewer boxes computed, the nodes a ray visits -12 %). It is
 * tested after the box (trace_box_slab_hit), and only kept where it is
 * under half the box's own extent along n.
 */
#ifndef TRACE_BOX_H
#define TRACE_BOX_H

#include <float.h>
#include <assert.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <math.h>
#include <stdbool.h>

#include "trace/float_round.h"
#include "trace/lin_bound.h"
#include "util/vecmath.h"

/* A box estimated from samples where range arithmetic stagnated
 * (intersect.c, "stagnant-box fallback"); above the flags of common/aa. */
#define TRACE_BOX_SAMPLED (1u << 8)
/* A stagnant box that the cases of its seams did not narrow, or the
 * stagnant child of one (intersect.c, children_of): its stagnant children
 * do not try them again (issue 24) */
#define TRACE_BOX_UNSPLIT (1u << 9)
/* A box narrowed by the cases of its seams (trace_surface_box_cases,
 * trace_surface_box_split): its children run their cases first */
#define TRACE_BOX_SPLIT (1u << 10)
/* The box has a linear bound (lin_bound.h: the plain affine run's forms,
 * reduced to u, v and a radius; displace.c), which travels beside it (a
 * trace_lin) and is kept in the box cache as codes (trace_fbox's qlin) */
#define TRACE_BOX_LIN (1u << 11)
/* Not evaluated yet: only the restricted bound of the parent's linear
 * bound (trace_box_restrict), which holds the box the child will have
 * (intersect.c, "Lazy children") */
#define TRACE_BOX_LAZY (1u << 12)
/* The displacement left P as the base surface gave it over the cell (its
 * affine form unchanged: displace.c, box_affine), so the surface there is
 * the base surface: where that has closed-form intersections the walk
 * intersects it exactly (intersect.c, "Undisplaced cells") */
#define TRACE_BOX_UNDISPLACED (1u << 13)
/* The displacement moved the base surface by a constant over the cell
 * (displace.c, offset_affine): the surface there is the base surface
 * moved, intersected exactly where the base can be (intersect.c) */
#define TRACE_BOX_OFFSET (1u << 14)
/* A stagnant box across a proven step: the cases of its seams
 * (trace_surface_box_cases) gave pairwise disjoint boxes, so wherever two
 * of them meet inside the cell the surface jumps; not narrowed by them
 * (TRACE_BOX_UNSPLIT too). Its stagnant children keep the flag and none of
 * them is re-estimated from samples (intersect.c, "Stagnant boxes") */
#define TRACE_BOX_STEP (1u << 15)
/* Every case of the box's seams is the flat base moved by a constant
 * (trace_surface_box_cases): over the cell the surface is pieces of
 * parallel planes and the walls between them, which all lie between the
 * outermost two (intersect.c, "planes_cell") */
#define TRACE_BOX_PLANES (1u << 16)
/* The displaced surface over the cell is one plane piece: the run's
 * forms are affine in the cell's u and v alone, up to rounding
 * (displace.c, planar_forms: a slate's face, a ramp), intersected
 * exactly (intersect.c, "planar_cell") */
#define TRACE_BOX_PLANAR (1u << 17)
/* The flags above use the low TRACE_BOX_FLAG_BITS bits; the box cache
 * keeps a box's tape (below) in the rest of trace_fbox's flags */
#define TRACE_BOX_FLAG_BITS 18
#define TRACE_BOX_TAPE_BITS 14

typedef struct trace_box {
    vec3 lo, hi;
    unsigned flags;          /* AA_DISCONTINUOUS | AA_UNBOUNDED | TRACE_BOX_SAMPLED |
                                TRACE_BOX_UNSPLIT | TRACE_BOX_SPLIT | TRACE_BOX_LIN |
                                TRACE_BOX_LAZY | TRACE_BOX_UNDISPLACED | TRACE_BOX_OFFSET |
                                TRACE_BOX_STEP | TRACE_BOX_PLANES | TRACE_BOX_PLANAR */
    float bend;              /* how far from linear in (u,v) the surface is over
                                the box: the affine forms' other terms over
                                their u and v terms (displace.c); 0: unknown */
    float sn[3];             /* the slab's unit normal; all 0: no slab */
    uint32_t tape;           /* the decisions the box's affine run proved,
                                for its children's runs (tape pruning:
                                common/sl/tape_plan.c, displace.c); 0: none */
    double slo, shi;         /* n . P over the cell, rounded outward */
} trace_box;

/* A box as the box cache stores it (issue 24, session 17): lo and hi as
 * float OFFSETS from a base box (the parent node's box: a child's offsets
 * are about its parent's size, so a float keeps 2^-24 of that, not of the
 * coordinates; a flat child of a flat parent stays exact), slo and shi as
 * floats; all ROUNDED OUTWARD: lo and slo such that base + offset,
 * converted and added in double, is at most the double value, hi and shi at
 * least it. So the float box contains the double box it came from, which
 * contains the surface. 52 bytes against 88. A base coordinate that is not
 * finite counts as 0 (no base: all 0). An axis (or slab) with lo > hi, or
 * NaN, is rounded INWARD (lo up, hi down), so an empty box stays empty;
 * +-inf stay +-inf, a value out of the floats' range goes outward to
 * +-inf, a nonzero offset below the smallest subnormal float outward to
 * +-2^-149. */
typedef struct trace_fbox {
    float lo[3], hi[3];
    unsigned flags;
    float bend;
    float sn[3];
    float slo, shi;
    trace_qlin qlin;         /* TRACE_BOX_LIN: the linear bound's codes against
                                the box as unpacked (else all 0) */
} trace_fbox;

/* x - base as a float d such that base + d (double, rounded to nearest) is
 * <= x (up false) or >= x (up true): d is on that side of x - base exactly
 * (the subtraction's error by two-sum), and rounding is monotonic */
static inline float trace_float_offset(double x, double base, bool up)
{
    double diff = x - base;
    if (!isfinite(diff) && isfinite(x) && isfinite(base))   /* overflow */
        return up ? INFINITY : -INFINITY;
    float d = up ? trace_float_up(diff) : trace_float_down(diff);
    if (isfinite(diff) && (double)d == diff) {
        double bb = diff - x;
        double err = (x - (diff - bb)) + (-base - bb);     /* x - base = diff + err */
        if (up ? err > 0.0 : err < 0.0) d = trace_float_step(d, up);
    }
    return d;
}

/* [lo, hi] as float offsets from [blo, bhi]: outward when lo <= hi, else
 * inward (empty stays empty) */
static inline void trace_float_range(double lo, double hi, double blo, double bhi, float *flo,
                                     float *fhi)
{
    bool outward = lo <= hi;
    *flo = trace_float_offset(lo, blo, !outward);
    *fhi = trace_float_offset(hi, bhi, outward);
}

/* the base box's coordinates, 0 where not finite (or no base) */
static inline void trace_fbox_base(const trace_box *base, double blo[3], double bhi[3])
{
    for (int i = 0; i < 3; i++) {
        double l = base ? (&base->lo.x)[i] : 0.0, h = base ? (&base->hi.x)[i] : 0.0;
        blo[i] = isfinite(l) ? l : 0.0;
        bhi[i] = isfinite(h) ? h : 0.0;
    }
}

/* base + d in double (a base of 0 keeps the sign of a zero d) */
static inline double trace_fbox_coord(double base, float d)
{
    return base == 0.0 ? (double)d : base + (double)d;
}

/* b as floats against base, with its linear bound lin where b has
 * TRACE_BOX_LIN and lin is given (else none: the flag goes) */
static inline void trace_fbox_pack_lin(const trace_box *b, const trace_lin *lin,
                                       const trace_box *base, trace_fbox *f)
{
    double blo[3], bhi[3];
    trace_fbox_base(base, blo, bhi);
    const double *lo = &b->lo.x, *hi = &b->hi.x;
    for (int i = 0; i < 3; i++) {
        trace_float_range(lo[i], hi[i], blo[i], bhi[i], &f->lo[i], &f->hi[i]);
        f->sn[i] = b->sn[i];
    }
    assert(b->flags < 1u << TRACE_BOX_FLAG_BITS && b->tape < 1u << TRACE_BOX_TAPE_BITS);
    f->flags = b->flags | b->tape << TRACE_BOX_FLAG_BITS;
    f->bend = b->bend;
    trace_float_range(b->slo, b->shi, 0.0, 0.0, &f->slo, &f->shi);
    /* the linear bound as codes against the box as unpacked */
    if (lin && (b->flags & TRACE_BOX_LIN)) {
        double flo[3], fhi[3];
        for (int i = 0; i < 3; i++) {
            flo[i] = trace_fbox_coord(blo[i], f->lo[i]);
            fhi[i] = trace_fbox_coord(bhi[i], f->hi[i]);
        }
        if (!trace_qlin_encode(lin, flo, fhi, &f->qlin)) f->flags &= ~(unsigned)TRACE_BOX_LIN;
    } else {
        f->flags &= ~(unsigned)TRACE_BOX_LIN;
    }
    if (!(f->flags & TRACE_BOX_LIN)) memset(&f->qlin, 0, sizeof f->qlin);
}

/* b as floats against base, without a linear bound */
static inline void trace_fbox_pack(const trace_box *b, const trace_box *base, trace_fbox *f)
{
    trace_fbox_pack_lin(b, NULL, base, f);
}

/* trace_fbox_unpack with the base's coordinates given (trace_fbox_base) */
static inline void trace_fbox_unpack_on(const trace_fbox *f, const double blo[3],
                                        const double bhi[3], trace_box *b)
{
    b->lo = v3(trace_fbox_coord(blo[0], f->lo[0]), trace_fbox_coord(blo[1], f->lo[1]),
               trace_fbox_coord(blo[2], f->lo[2]));
    b->hi = v3(trace_fbox_coord(bhi[0], f->hi[0]), trace_fbox_coord(bhi[1], f->hi[1]),
               trace_fbox_coord(bhi[2], f->hi[2]));
    b->flags = f->flags & ((1u << TRACE_BOX_FLAG_BITS) - 1);
    b->tape = f->flags >> TRACE_BOX_FLAG_BITS;
    b->bend = f->bend;
    for (int i = 0; i < 3; i++) b->sn[i] = f->sn[i];
    b->slo = f->slo;
    b->shi = f->shi;
}

static inline void trace_fbox_unpack(const trace_fbox *f, const trace_box *base, trace_box *b)
{
    double blo[3], bhi[3];
    trace_fbox_base(base, blo, bhi);
    trace_fbox_unpack_on(f, blo, bhi, b);
}

/* The box as the cache would give it back (stored against base, without
 * a linear bound: TRACE_BOX_LIN goes). The traversal packs its boxes once
 * and goes on with what the packing gives (trace_boxcache_insert_kept),
 * cached or not, so a box stays a pure function of (object, u-range,
 * v-range) whatever the cache holds */
static inline void trace_box_round_float(trace_box *b, const trace_box *base)
{
    trace_fbox f;
    trace_fbox_pack(b, base, &f);
    trace_fbox_unpack(&f, base, b);
}

/* The restricted bound of the child cell c of the cell r (lin_bound.h)
 * by the node's decoded linear bound d, within the node's box: no slab,
 * no flags but TRACE_BOX_LAZY */
static inline void trace_box_restrict(const trace_dlin *d, const trace_box *node, const double r[4],
                                      const double c[4], trace_box *out)
{
    double lo[3], hi[3];
    trace_lin_restrict(d, r, c, lo, hi);
    memset(out, 0, sizeof *out);
    out->lo = v3(fmax(lo[0], node->lo.x), fmax(lo[1], node->lo.y), fmax(lo[2], node->lo.z));
    out->hi = v3(fmin(hi[0], node->hi.x), fmin(hi[1], node->hi.y), fmin(hi[2], node->hi.z));
    out->flags = TRACE_BOX_LAZY;
}

/* The node's linear bound decoded (against its box) */
static inline void trace_box_lin(const trace_qlin *q, const trace_box *node, trace_dlin *d)
{
    const double lo[3] = {node->lo.x, node->lo.y, node->lo.z};
    const double hi[3] = {node->hi.x, node->hi.y, node->hi.z};
    trace_qlin_decode(q, lo, hi, d);
}

/* b met with another enclosure rb of the same surface (a restricted bound,
 * trace_box_restrict; the hull of a cell's cases): both hold the surface
 * over the cell, so their intersection does; where the meet is finite it
 * is bounded (AA_UNBOUNDED goes); an empty b stays empty. Boxes only: b's
 * slab and flags otherwise stay */
static inline void trace_box_meet(trace_box *b, const trace_box *rb)
{
    b->lo = v3(fmax(b->lo.x, rb->lo.x), fmax(b->lo.y, rb->lo.y), fmax(b->lo.z, rb->lo.z));
    b->hi = v3(fmin(b->hi.x, rb->hi.x), fmin(b->hi.y, rb->hi.y), fmin(b->hi.z, rb->hi.z));
    if (isfinite(b->lo.x) && isfinite(b->lo.y) && isfinite(b->lo.z) && isfinite(b->hi.x) &&
        isfinite(b->hi.y) && isfinite(b->hi.z))
        b->flags &= ~(unsigned)AA_UNBOUNDED;
}

static inline void trace_box_no_slab(trace_box *b)
{
    b->sn[0] = b->sn[1] = b->sn[2] = 0.0f;
    b->slo = b->shi = 0.0;
}

static inline bool trace_box_has_slab(const trace_box *b)
{
    return b->sn[0] != 0.0f || b->sn[1] != 0.0f || b->sn[2] != 0.0f;
}

typedef struct trace_ray {
    vec3 o, d;               /* origin, direction (not necessarily unit) */
    vec3 invd;               /* 1 / d per component */
    double tmin, tmax;
} trace_ray;

static inline void trace_ray_init(trace_ray *r, vec3 o, vec3 d, double tmin, double tmax)
{
    r->o = o;
    r->d = d;
    r->invd = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    r->tmin = tmin;
    r->tmax = tmax;
}

static inline vec3 trace_ray_at(const trace_ray *r, double t)
{
    return v3(r->o.x + r->d.x * t, r->o.y + r->d.y * t, r->o.z + r->d.z * t);
}

/* Largest side of the box (the size the termination rules compare). */
static inline double trace_box_extent(const trace_box *b)
{
    double e = b->hi.x - b->lo.x;
    if (b->hi.y - b->lo.y > e) e = b->hi.y - b->lo.y;
    if (b->hi.z - b->lo.z > e) e = b->hi.z - b->lo.z;
    return e;
}

static inline bool trace_box_is_empty(const trace_box *b)
{
    return !(b->lo.x <= b->hi.x && b->lo.y <= b->hi.y && b->lo.z <= b->hi.z);
}

static inline void trace_box_union(trace_box *a, const trace_box *b)
{
    a->lo = v3(fmin(a->lo.x, b->lo.x), fmin(a->lo.y, b->lo.y), fmin(a->lo.z, b->lo.z));
    a->hi = v3(fmax(a->hi.x, b->hi.x), fmax(a->hi.y, b->hi.y), fmax(a->hi.z, b->hi.z));
    a->flags |= b->flags;
}

/* Slab test: the parameter interval [*t0, *t1] where the ray is inside the
 * box, clipped to [tmin, tmax]; false when empty. Axis of entry in *axis
 * (0..2, or -1 when the ray starts inside). Unbounded boxes always hit. */
static inline bool trace_box_hit(const trace_box *b, const trace_ray *r,
                                 double tmin, double tmax,
                                 double *t0, double *t1, int *axis)
{
    const double widen = 1.0 + 6.0 * (DBL_EPSILON * 0.5) / (1.0 - 3.0 * DBL_EPSILON * 0.5);
    double lo = tmin, hi = tmax;
    int ax = -1;
    const double *blo = &b->lo.x, *bhi = &b->hi.x, *o = &r->o.x, *inv = &r->invd.x;
    for (int i = 0; i < 3; i++) {
        double tn = (blo[i] - o[i]) * inv[i];
        double tf = (bhi[i] - o[i]) * inv[i];
        if (tn > tf) { double s = tn; tn = tf; tf = s; }
        tf *= widen;
        if (tn > lo) { lo = tn; ax = i; }   /* NaN (0 * inf) compares false */
        if (tf < hi) hi = tf;
        if (lo > hi) return false;
    }
    *t0 = lo;
    *t1 = hi;
    if (axis) *axis = ax;
    return true;
}

/* The box's slab (if any) against the ray: narrows [*t0, *t1] to where
 * o + t d lies between its planes; false when that leaves nothing.
 * Conservative under rounding: n . o and n . d are sums of three products,
 * within gamma(3) < 2^-50 of the sums of their magnitudes (om, dm); the
 * planes are moved out by 2^-48 of om + |slo| + |shi|, which also covers
 * the subtractions, and n . d is kept as the interval den -+ 2^-48 dm. A
 * ray that may run along the planes (that interval holds 0) is not
 * narrowed. The quotients are moved out by 2^-50 of themselves. slo and
 * shi may be the box cache's floats (trace_fbox): exact as doubles, so the
 * argument holds as it is. */
static inline bool trace_box_slab_hit(const trace_box *b, const trace_ray *r, double *t0,
                                      double *t1)
{
    if (!trace_box_has_slab(b)) return true;
    const double n[3] = {b->sn[0], b->sn[1], b->sn[2]};
    const double *o = &r->o.x, *d = &r->d.x;
    double num = 0.0, den = 0.0, om = 0.0, dm = 0.0;
    for (int i = 0; i < 3; i++) {
        num += n[i] * o[i];
        den += n[i] * d[i];
        om += fabs(n[i] * o[i]);
        dm += fabs(n[i] * d[i]);
    }
    double e = 0x1p-48 * (om + fabs(b->slo) + fabs(b->shi)) + 0x1p-1000;
    double a = (b->slo - num) - e, c = (b->shi - num) + e;   /* t den in [a, c] */
    double ed = 0x1p-48 * dm + 0x1p-1000, dlo = den - ed, dhi = den + ed;
    if (!(dlo > 0.0 || dhi < 0.0)) return true;
    if (dhi < 0.0) {                     /* t in [c, a] / den */
        double s = a;
        a = c;
        c = s;
    }
    double lo = fmin(a / dlo, a / dhi), hi = fmax(c / dlo, c / dhi);
    lo -= 0x1p-50 * fabs(lo) + 0x1p-1000;
    hi += 0x1p-50 * fabs(hi) + 0x1p-1000;
    if (!(lo == lo) || !(hi == hi)) return true;    /* NaN: no narrowing */
    if (lo > *t0) *t0 = lo;
    if (hi < *t1) *t1 = hi;
    return *t0 <= *t1;
}

#endif
