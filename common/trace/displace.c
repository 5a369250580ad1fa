/*
 * displace.c: boxes and points of displaced surfaces (see displace.h).
 *
 * Box of a (u,v) range, Heidrich & Seidel §3: u and v become the query's
 * first two noise symbols, the base surface is evaluated in affine form
 * (geom_eval_aa), moved to camera space (an affine map: exact up to the
 * rounding the aa library accounts for), handed to the displacement shader
 * as its globals, and the shader's P afterwards gives x, y, z ranges. The
 * interval mode does the same with ia_interval (the comparison of §7.1).
 * The globals are bound by one template for every arithmetic
 * (globals.inc), so boxes and points see the same surface.
 */
#include "trace/displace.h"
#include "trace/cellkey.h"
#include "trace/normal_memo.h"
#include "trace/primvar.h"
#include "trace/tape_memo.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define G_T aa_form
#define G_SUFFIX affine
#define G_SET sl_vm_set_affine
#define G_CONST aa_const
#include "trace/globals.inc"

static inline void ia_const_(ia_interval *z, double k) { *z = ia_point(k); }
#define G_T ia_interval
#define G_SUFFIX interval
#define G_SET sl_vm_set_interval
#define G_CONST ia_const_
#include "trace/globals.inc"

static inline void dual_const_(sl_dual *z, double k) { *z = (sl_dual){k, 0, 0}; }
#define G_T sl_dual
#define G_SUFFIX dual
#define G_SET sl_vm_set_dual
#define G_CONST dual_const_
#include "trace/globals.inc"

/* ---- affine ---- */

/* out = m * in (a point: with m's translation); out must not alias in */
void trace_xform_aa(aa_context *ctx, const mat4 *m, const aa_form in[3], aa_form out[3],
                    bool point)
{
    for (int i = 0; i < 3; i++)
        aa_lincomb3(ctx, &out[i], m->m[i], in, point ? m->m[i][3] : 0.0);
}

/* The camera-space unit normal from the object-space one Nn: the inverse
 * transpose of to_camera (from_camera^T), then normalised; for a similarity
 * (obj->normal_scale > 0) the length is that constant and no non-affine
 * operation is needed. */
void trace_camera_normal_aa(aa_context *ctx, const trace_object *obj, const aa_form Nn[3],
                            aa_form N[3])
{
    mat4 t = mat4_transpose(obj->from_camera);
    trace_xform_aa(ctx, &t, Nn, N, false);
    double k = obj->flip ? -1.0 : 1.0;
    if (obj->normal_scale > 0) {
        for (int i = 0; i < 3; i++) aa_mul_s(ctx, &N[i], &N[i], k * obj->normal_scale);
        return;
    }
    /* |N|^2 of the true normal lies in obj->normal_len2 (world.c): meeting
     * the computed form with it is sound and keeps wide ranges bounded
     * away from 0, as are the components of a unit vector in [-1, 1] */
    aa_form len2, sq, inv, lo, hi;
    aa_sqr(ctx, &len2, &N[0]);
    aa_sqr(ctx, &sq, &N[1]);
    aa_add(ctx, &len2, &len2, &sq);
    aa_sqr(ctx, &sq, &N[2]);
    aa_add(ctx, &len2, &len2, &sq);
    aa_const(&lo, obj->normal_len2[0]);
    aa_const(&hi, obj->normal_len2[1]);
    aa_clamp(ctx, &len2, &len2, &lo, &hi);
    aa_invsqrt(ctx, &inv, &len2);
    if (obj->flip) aa_neg(ctx, &inv, &inv);
    aa_const(&lo, -1.0);
    aa_const(&hi, 1.0);
    for (int i = 0; i < 3; i++) {
        aa_mul(ctx, &N[i], &N[i], &inv);
        aa_clamp(ctx, &N[i], &N[i], &lo, &hi);
    }
}

/* A box is unbounded when a side is infinite. The arithmetic's
 * AA_UNBOUNDED flag is sticky (it stays on a clamp or a normalize of an
 * unbounded value, whose range is finite again), so it is not used.
 * AA_KINK (a crease in the cell) goes on the box for the leaves' starts
 * alone (intersect.c, leaf_start): the slab, the planar and moved cells
 * read the other flags only. */
static unsigned box_flags(const trace_box *b, unsigned flags)
{
    unsigned f = flags & (AA_DISCONTINUOUS | AA_KINK);
    if (!isfinite(b->lo.x) || !isfinite(b->lo.y) || !isfinite(b->lo.z) ||
        !isfinite(b->hi.x) || !isfinite(b->hi.y) || !isfinite(b->hi.z))
        f |= AA_UNBOUNDED;
    return f;
}

/* x cut to a float's 24 significant bits (0 below 2^-100): exactly a
 * float. By bits, not by (double)(float)x: GCC 12's vectoriser at -O2 has
 * been seen to drop that round trip when the float and the double are
 * stored side by side, which gave a slab for one normal and the box
 * another (test_corpus_containment found it). */
static double float_grid(double x)
{
    if (!(fabs(x) >= 0x1p-100)) return 0.0;
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    b &= ~((UINT64_C(1) << 29) - 1);
    memcpy(&x, &b, sizeof x);
    return x;
}

/* The slab of a box (box.h): n the unit normal of the u and v terms
 * (symbols 0 and 1, box_affine's first two inputs), rounded to float (the
 * slab holds for the n stored), [slo, shi] the outward-rounded range of the
 * affine form n . P; kept where under half the box's extent along n */
static void box_slab(const aa_form P[3], const ia_interval r[3], trace_box *out)
{
    trace_box_no_slab(out);
    vec3 cu = v3(P[0].n > 0 ? P[0].c[0] : 0, P[1].n > 0 ? P[1].c[0] : 0, P[2].n > 0 ? P[2].c[0] : 0);
    vec3 cv = v3(P[0].n > 1 ? P[0].c[1] : 0, P[1].n > 1 ? P[1].c[1] : 0, P[2].n > 1 ? P[2].c[1] : 0);
    vec3 n = v3_cross(cu, cv);
    double len = v3_length(n);
    if (!(len > 0) || !isfinite(len)) return;
    n = v3_scale(n, 1.0 / len);
    double m[3] = {float_grid(n.x), float_grid(n.y), float_grid(n.z)};
    float f[3] = {(float)m[0], (float)m[1], (float)m[2]};     /* exact */
    aa_context ctx;                      /* an affine combination: no new symbol */
    aa_context_init(&ctx, 0);
    aa_form s;
    aa_lincomb3(&ctx, &s, m, P, 0.0);
    ia_interval sr = aa_range(&s);
    double ext = fabs(m[0]) * (r[0].hi - r[0].lo) + fabs(m[1]) * (r[1].hi - r[1].lo) +
                 fabs(m[2]) * (r[2].hi - r[2].lo);
    if (!isfinite(sr.lo) || !isfinite(sr.hi) || !(sr.hi - sr.lo < 0.5 * ext)) return;
    memcpy(out->sn, f, sizeof f);
    out->slo = sr.lo;
    out->shi = sr.hi;
}

static void box_from_affine(const aa_form P[3], trace_box *out)
{
    ia_interval r[3];
    unsigned flags = 0;
    double lin = 0, other = 0;
    for (int i = 0; i < 3; i++) {
        r[i] = aa_range(&P[i]);
        flags |= P[i].flags | r[i].flags;
        /* symbols 0 and 1 are u and v (box_affine's first two inputs) */
        for (int k = 0; k < P[i].n; k++) {
            if (k < 2) lin += fabs(P[i].c[k]);
            else other += fabs(P[i].c[k]);
        }
        other += P[i].err;
    }
    out->lo = v3(r[0].lo, r[1].lo, r[2].lo);
    out->hi = v3(r[0].hi, r[1].hi, r[2].hi);
    out->flags = box_flags(out, flags);
    out->tape = 0;
    out->bend = other == 0 ? 0.0f : lin > 0 ? (float)fmin(other / lin, 1e30) : 1e30f;
    if (out->flags & ~(unsigned)AA_KINK) trace_box_no_slab(out);
    else box_slab(P, r, out);
}

bool trace_surface_has_slopes(const trace_object *obj)
{
    switch (obj->surf.kind) {
    case GEOM_SPHERE: case GEOM_CYLINDER: case GEOM_CONE: case GEOM_TORUS: case GEOM_PATCH:
    case GEOM_BICUBIC: case GEOM_SUBDIV:
        return obj->normal_scale > 0;
    case GEOM_POLYGON:
        return !geom_has_vertex_normals(&obj->surf) || obj->normal_scale > 0;
    default:
        return trace_surface_flat(obj);
    }
}

bool trace_surface_flat(const trace_object *obj)
{
    return (obj->surf.kind == GEOM_POLYGON && !geom_has_vertex_normals(&obj->surf)) ||
           obj->surf.kind == GEOM_DISK;
}

/* Whether a box run (one that reads P alone: the affine and interval
 * boxes, a proof's enclosure at a point) needs the tangents: not where the
 * shader never names them, nor where its box runs read neither them nor
 * P's and I's derivative bounds (box_runs_skip_tangents) */
static bool box_run_tangents(const trace_object *obj)
{
    return !(obj->box_skip_tangents || obj->box_runs_skip_tangents);
}

/* P's derivative bounds to bind (Pd, from the tangents) where they were
 * computed; else none for a shader that takes no derivatives, and the
 * whole line (for P's and I's: not made from tangents that were not
 * computed) for one whose box runs read none */
static const ia_interval (*bound_derivs(const trace_object *obj, bool tangents,
                                        const ia_interval (*Pd)[3]))[3]
{
    static const ia_interval unread[2][3] = {
        {{-INFINITY, INFINITY, AA_UNBOUNDED}, {-INFINITY, INFINITY, AA_UNBOUNDED},
         {-INFINITY, INFINITY, AA_UNBOUNDED}},
        {{-INFINITY, INFINITY, AA_UNBOUNDED}, {-INFINITY, INFINITY, AA_UNBOUNDED},
         {-INFINITY, INFINITY, AA_UNBOUNDED}}};
    return tangents ? Pd : obj->box_skip_tangents ? NULL : unread;
}

/* The base surface over a (u,v) box in affine arithmetic, as the
 * displacement's affine runs bind it (camera space), and the context
 * after it: every case of the box's splits runs on the same (a run
 * restores the context, so its forms are those of a run from scratch) */
typedef struct affine_cell {
    aa_context ctx;
    aa_form u, v, P[3], N[3], dPdu[3], dPdv[3];
    ia_interval Pd[2][3];
} affine_cell;

static void affine_geometry(trace_thread *th, const trace_object *obj,
                            double u0, double u1, double v0, double v1, affine_cell *c)
{
    aa_context *ctx = &th->ctx;
    aa_context_reset(ctx);
    aa_input(ctx, &c->u, u0, u1);
    aa_input(ctx, &c->v, v0, v1);
    geom_aa g;
    geom_eval_aa(ctx, &obj->surf, &c->u, &c->v, &g);
    if (!obj->displacement) {
        for (int i = 0; i < 3; i++) c->P[i] = g.P[i];
        c->ctx = *ctx;
        return;
    }
    trace_xform_aa(ctx, &obj->to_camera, g.P, c->P, true);
    trace_camera_unit_normal_aa(th, obj, &c->u, &c->v, &g, c->N);
    if (!box_run_tangents(obj)) {         /* never read: not computed */
        for (int i = 0; i < 3; i++) {
            aa_const(&c->dPdu[i], 0.0);
            aa_const(&c->dPdv[i], 0.0);
        }
    } else {
        trace_xform_aa(ctx, &obj->to_camera, g.dPdu, c->dPdu, false);
        trace_xform_aa(ctx, &obj->to_camera, g.dPdv, c->dPdv, false);
        for (int i = 0; i < 3; i++) {
            c->Pd[0][i] = aa_range(&c->dPdu[i]);
            c->Pd[1][i] = aa_range(&c->dPdv[i]);
        }
    }
    c->ctx = *ctx;
}

/* What a box run's shader did to P over the cell (affine_shade) */
typedef enum {
    TRACE_MOVED_OTHER,             /* anything, or not known */
    TRACE_MOVED_NOT,               /* nothing: P as the base gave it */
    TRACE_MOVED_OFFSET             /* P moved by a constant */
} trace_moved;

/* Whether the shader's form a is the base's form b moved by a constant:
 * the same coefficients on the base's symbols and the same flags, the
 * centre anywhere, and what a adds to b's radius (its error term's growth
 * and its coefficients on symbols b does not use: the rounding of a
 * product of two constants-up-to-rounding lands on a fresh symbol, as in
 * a box-filtered pulse inside a brick, (hi - lo) / w) no more than the
 * rounding of that move (2^-40 of the centres: far below what the float
 * evaluation of any hit point carries). A displacement that varies over
 * the cell varies a coefficient of the cell's symbols, or adds more. */
#define TRACE_OFFSET_SLACK 0x1p-40
static bool offset_affine(const aa_form *a, const aa_form *b)
{
    /* AA_DISCONTINUOUS aside: a case run's split values carry it, and
     * box_of_run takes no flagged box for a moved one; AA_KINK aside: a
     * crease adds a symbol or an error, which the comparison below sees */
    unsigned fa = a->flags & ~(unsigned)(AA_DISCONTINUOUS | AA_KINK),
             fb = b->flags & ~(unsigned)(AA_DISCONTINUOUS | AA_KINK);
    if (fa != fb || !isfinite(a->x0) || !(a->err >= b->err))
        return false;
    /* the same coefficients; a symbol one form lacks has 0 in it (an
     * operation may leave a symbol of coefficient 0: a mesh's normal) */
    double extra = a->err - b->err;
    int n = a->n > b->n ? a->n : b->n;
    for (int i = 0; i < n; i++) {
        double ca = i < a->n ? a->c[i] : 0.0, cb = i < b->n ? b->c[i] : 0.0;
        if (ca != cb) {
            if (cb != 0.0) return false;
            extra += fabs(ca);
        }
    }
    return extra <= TRACE_OFFSET_SLACK * (fabs(a->x0) + fabs(b->x0));
}

/* What the shader did to the base's P (both as forms, camera space):
 * moved it by a constant (offset_affine, all three coordinates), and of
 * that, nothing at all where the centres and error terms are the same
 * too (the hull aside: every operation recomputes it, rounding outward) */
static trace_moved moved_by(const aa_form Pc[3], const aa_form P[3])
{
    bool same = true;
    for (int k = 0; k < 3; k++) {
        if (!offset_affine(&Pc[k], &P[k])) return TRACE_MOVED_OTHER;
        same = same && Pc[k].x0 == P[k].x0 && Pc[k].err == P[k].err;
    }
    return same ? TRACE_MOVED_NOT : TRACE_MOVED_OFFSET;
}

/* One affine run of the displacement over the cell (of the case the VM's
 * splits select): the shader's P in object space, in th->ctx (valid until
 * its next reset). With same, whether the run left P's affine form as the
 * base surface gave it: every operation that reached P was exact and
 * changed nothing (adding an exact 0, as a decided step's branch gives),
 * since one whose value may differ from P's changes its form, its error
 * term at least; so the displaced surface over the cell is the base
 * surface itself (TRACE_MOVED_NOT). Or moved by a constant
 * (TRACE_MOVED_OFFSET, offset_affine: a brick's top, Km times a decided
 * step along a flat base's N). */
static void affine_shade(trace_thread *th, const trace_object *obj, const affine_cell *c,
                         aa_form P[3], trace_moved *same, vec3 *move)
{
    if (same) *same = TRACE_MOVED_OTHER;
    aa_context *ctx = &th->ctx;
    *ctx = c->ctx;
    th->stats.evals_affine++;
    if (!obj->displacement) {
        for (int i = 0; i < 3; i++) P[i] = c->P[i];
        return;
    }
    sl_vm *vm = th->vm;
    bind_globals_affine(vm, obj, &obj->displacement_spaces, c->P, c->N, c->N, c->dPdu, c->dPdv,
                        &c->u, &c->v, bound_derivs(obj, box_run_tangents(obj), c->Pd),
                        trace_surface_flat(obj));
    trace_primvars_bind(vm, obj, false);
    if (sl_vm_run(vm, obj->displacement, SL_MODE_AFFINE, ctx) != SL_OK) {
        trace_thread_fail(th, sl_vm_error(vm));
        aa_unbounded(&P[0], AA_UNBOUNDED);
        P[1] = P[2] = P[0];
    } else {
        aa_form Pc[3];
        sl_vm_get_affine(vm, SL_G_P, Pc);
        if (same) {
            *same = moved_by(Pc, c->P);
            /* the move, object space: the centres' difference (the rest of
             * the forms is the same, up to TRACE_OFFSET_SLACK) */
            if (move && *same != TRACE_MOVED_OTHER)
                *move = mat4_xform_vector(&obj->from_camera,
                                          v3(Pc[0].x0 - c->P[0].x0, Pc[1].x0 - c->P[1].x0,
                                             Pc[2].x0 - c->P[2].x0));
        }
        trace_xform_aa(ctx, &obj->from_camera, Pc, P, true);
    }
}

/* The box's linear bound (lin_bound.h; TRACE_BOX_LIN on the box) from
 * the run's forms: per coordinate the centre, the u and v terms (symbols
 * 0 and 1, where the context gave u and v their own symbols) and the rest
 * as a radius, rounded up, as floats (trace_lin_set). None for a form
 * that is unbounded or not finite. */
static bool run_linear(const aa_context *ctx, const aa_form P[3], trace_lin *lin)
{
    memset(lin, 0, sizeof *lin);
    if (ctx->capacity < 2) return false;
    for (int k = 0; k < 3; k++) {
        const aa_form *f = &P[k];
        if (f->flags & AA_UNBOUNDED) return false;
        double rad = f->err;
        for (int i = 2; i < f->n; i++) rad = fp_add_up(rad, fabs(f->c[i]));
        double lu = f->n > 0 ? f->c[0] : 0.0, lv = f->n > 1 ? f->c[1] : 0.0;
        if (!isfinite(f->x0) || !isfinite(rad) || !trace_lin_set(lin, k, f->x0, lu, lv, rad))
            return false;
    }
    return true;
}

static void box_linear(const aa_context *ctx, const aa_form P[3], trace_box *out, trace_lin *lin)
{
    if (run_linear(ctx, P, lin)) out->flags |= TRACE_BOX_LIN;
}

/* Whether the run's object-space forms P are affine in the cell's u and
 * v symbols alone (symbols 0 and 1: the context gave them), so that the
 * displaced surface over the cell is one plane piece: every other
 * coefficient and the error term together at most TRACE_OFFSET_SLACK of
 * the form's size (the rounding of the run, as for a constant move), no
 * flag. Then the piece in *out. (A plane on a curved base, or a
 * displacement that bends, leaves a remainder far above that.) */
static bool planar_forms(const affine_cell *c, const aa_form P[3], trace_plane *out)
{
    const aa_form *u = &c->u, *v = &c->v;
    if (u->n != 1 || u->err != 0.0 || v->n != 2 || v->c[0] != 0.0 || v->err != 0.0 ||
        !(u->c[0] > 0.0) || !(v->c[1] > 0.0))
        return false;                     /* u and v are not symbols 0 and 1 */
    double q[3], eu[3], ev[3];
    for (int k = 0; k < 3; k++) {
        const aa_form *f = &P[k];
        if (f->flags & ~(unsigned)AA_KINK) return false;
        double rest = f->err;
        for (int i = 2; i < f->n; i++) rest += fabs(f->c[i]);
        q[k] = f->x0;
        eu[k] = f->n > 0 ? f->c[0] : 0.0;
        ev[k] = f->n > 1 ? f->c[1] : 0.0;
        double size = fabs(q[k]) + fabs(eu[k]) + fabs(ev[k]);
        if (!isfinite(size) || !(rest <= TRACE_OFFSET_SLACK * size)) return false;
    }
    out->Q = v3(q[0], q[1], q[2]);
    out->Eu = v3(eu[0], eu[1], eu[2]);
    out->Ev = v3(ev[0], ev[1], ev[2]);
    out->um = u->x0;
    out->ur = u->c[0];
    out->vm = v->x0;
    out->vr = v->c[1];
    return true;
}

/* The planes of TRACE_BOX_PLANAR cells, kept per cell in a direct-mapped
 * per-thread cache as its box is made (box_of_run); a cell the cache lost
 * runs again (trace_surface_plane). A pure function of object and cell. */
enum { PLANE_CACHE_LOG2 = 10, PLANE_CACHE_ENTRIES = 1 << PLANE_CACHE_LOG2 };
typedef struct plane_entry {
    double r[4];                  /* the cell; r[0] >= r[1]: empty */
    int obj;
    trace_plane p;
} plane_entry;
struct trace_plane_cache { plane_entry e[PLANE_CACHE_ENTRIES]; };

static plane_entry *plane_slot(trace_thread *th, const trace_object *obj, const double c[4])
{
    if (!th->planes) th->planes = xcalloc(1, sizeof *th->planes);   /* zeroed: empty */
    return &th->planes->e[trace_cell_slot(c, obj->id, PLANE_CACHE_LOG2)];
}

/* The box of a plain run (one case: nothing split) over the cell from its
 * forms P and what it did to the base (affine_shade); lin: where given,
 * the box's linear bound (box_linear, from th->ctx as the run left it) */
static void box_of_run(trace_thread *th, const trace_object *obj, const affine_cell *cell,
                       const aa_form P[3], trace_moved same, trace_box *out, trace_lin *lin)
{
    box_from_affine(P, out);
    if (obj->displacement && !(out->flags & ~(unsigned)AA_KINK)) {
        trace_plane pl;
        if (same == TRACE_MOVED_NOT) {
            out->flags |= TRACE_BOX_UNDISPLACED;
        } else if (same == TRACE_MOVED_OFFSET) {
            out->flags |= TRACE_BOX_OFFSET;
        } else if (planar_forms(cell, P, &pl)) {
            out->flags |= TRACE_BOX_PLANAR;
            double c[4] = {cell->u.lo, cell->u.hi, cell->v.lo, cell->v.hi};
            plane_entry *e = plane_slot(th, obj, c);
            trace_cell_keep(e->r, &e->obj, c, obj->id);
            e->p = pl;
        }
    }
    if (lin) box_linear(&th->ctx, P, out, lin);
}

/*
 * Tape pruning (issue 24, common/sl/tape_plan.c): the run over a cell
 * takes the plan of `tape`, the decisions its parent node's run proved
 * (every point of the cell is a point of the parent's, so they hold here
 * too), and notes its own; the box keeps them all (out->tape) for its
 * children. The tape of a box is thus a pure function of its cell (its
 * own run's, and its parent's tape), as the box is.
 */
_Static_assert(SL_TAPE_SITES * SL_TAPE_BITS <= TRACE_BOX_TAPE_BITS, "a box holds a tape");
_Static_assert(TRACE_BOX_PLANAR < 1u << TRACE_BOX_FLAG_BITS, "flags below the tape");

static void box_affine(trace_thread *th, const trace_object *obj,
                       double u0, double u1, double v0, double v1, uint32_t tape,
                       trace_box *out, trace_lin *lin)
{
    aa_form P[3];
    trace_moved same;
    affine_cell c;
    affine_geometry(th, obj, u0, u1, v0, v1, &c);
    const sl_program *prog = obj->displacement ? sl_instance_program(obj->displacement) : NULL;
    bool taped = prog && sl_program_tape_site_count(prog) > 0 && th->world->options.tape_pruning;
    if (taped) {
        const uint8_t *plan = trace_tape_plan(th, prog, tape);
        sl_vm_set_tape(th->vm, plan, plan ? tape : 0, true);
        if (plan) th->stats.tape_runs++;
    }
    affine_shade(th, obj, &c, P, &same, NULL);
    uint32_t proved = 0;
    if (taped) {
        proved = th->failed ? 0 : sl_vm_tape(th->vm);
        sl_vm_set_tape(th->vm, NULL, 0, false);
    }
    box_of_run(th, obj, &c, P, same, out, lin);
    out->tape = proved;
}

bool trace_surface_plane(trace_thread *th, const trace_object *obj, double u0, double u1,
                         double v0, double v1, uint32_t tape, trace_plane *out)
{
    obj = trace_box_owner(obj);
    double c[4] = {u0, u1, v0, v1};
    plane_entry *e = plane_slot(th, obj, c);
    if (trace_cell_is(e->r, e->obj, c, obj->id)) {
        *out = e->p;
        return true;
    }
    if (th->world->options.arith == TRACE_ARITH_INTERVAL || !obj->displacement) return false;
    trace_box b;
    box_affine(th, obj, u0, u1, v0, v1, tape, &b, NULL);
    th->stats.boxes++;
    if (th->failed || !(b.flags & TRACE_BOX_PLANAR)) return false;
    *out = plane_slot(th, obj, c)->p;    /* box_of_run kept it */
    return true;
}

/* The cases' box is taken where it is at most this fraction of the box's
 * extent; else the box stays (a narrower box that still does not shrink
 * makes its children stagnant against it: more splits and samples for
 * nothing; the filtered pulse trains of dv_lines and fw_stripes before
 * the cases of one value agreed, split_plan.c) */
#define TRACE_SPLIT_GAIN 0.75

/* Whether a side of b is NaN (no surface where the shader ran) */
static bool box_has_nan(const trace_box *b)
{
    return isnan(b->lo.x) || isnan(b->lo.y) || isnan(b->lo.z) || isnan(b->hi.x) ||
           isnan(b->hi.y) || isnan(b->hi.z);
}

/* Whether no point lies in both boxes: on some axis one ends before the
 * other begins (a NaN side: not apart) */
static bool boxes_apart(const trace_box *a, const trace_box *b)
{
    return a->hi.x < b->lo.x || b->hi.x < a->lo.x || a->hi.y < b->lo.y || b->hi.y < a->lo.y ||
           a->hi.z < b->lo.z || b->hi.z < a->lo.z;
}

/* The cases of a cell, one by one: their boxes and linear bounds
 * (run_linear), from which they are judged apart (a proven step) and one
 * linear bound made that holds them all (cases_linear) */
typedef struct case_set {
    int n;
    bool lins;                            /* every case has its linear bound */
    bool moved;                           /* every case moved the base by a constant */
    trace_box box[TRACE_MAX_CASES];
    trace_lin lin[TRACE_MAX_CASES];
    vec3 move[TRACE_MAX_CASES];           /* its move (object space), where moved */
} case_set;

static void case_add(case_set *cs, const aa_context *ctx, const aa_form P[3], const trace_box *b,
                     trace_moved same, vec3 move)
{
    assert(cs->n < TRACE_MAX_CASES);      /* at most 2^TRACE_SPLIT_OPS cases */
    if (cs->n == 0) cs->lins = cs->moved = true;
    cs->box[cs->n] = *b;
    cs->lins = cs->lins && run_linear(ctx, P, &cs->lin[cs->n]);
    cs->moved = cs->moved && same != TRACE_MOVED_OTHER && v3_is_finite(move);
    cs->move[cs->n] = move;
    cs->n++;
}

/* Whether the cell's surface is pieces of parallel planes (the flat base
 * moved by each case's constant) and the walls between them; their moves
 * in *out where given (n = 0 where not) */
static bool cases_planes(const trace_object *obj, const case_set *cs, trace_case_moves *out)
{
    bool planes = cs->moved && cs->n >= 2 && trace_surface_flat(obj);
    if (out) {
        out->n = planes ? cs->n : 0;
        for (int i = 0; i < out->n; i++) out->move[i] = cs->move[i];
    }
    return planes;
}

/* Whether the cases' boxes are pairwise apart */
static bool cases_apart(const case_set *cs)
{
    for (int i = 0; i < cs->n; i++)
        for (int j = i + 1; j < cs->n; j++)
            if (!boxes_apart(&cs->box[i], &cs->box[j])) return false;
    return true;
}

/* One linear bound holding every case's: per coordinate the middles of
 * the cases' centres, u and v terms, and the largest of |x_j - x| +
 * |u_j - u| + |v_j - v| + r_j (eu, ev in [-1, 1]), rounded up, so that a
 * point within case j's bound is within it. False where a case has none
 * or it does not fit the floats. */
static bool cases_linear(const case_set *cs, trace_lin *lin)
{
    if (cs->n == 0 || !cs->lins) return false;
    for (int k = 0; k < 3; k++) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int j = 0; j < cs->n; j++) {
            const double t[3] = {cs->lin[j].x[k], cs->lin[j].u[k], cs->lin[j].v[k]};
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], t[a]);
                hi[a] = fmax(hi[a], t[a]);
            }
        }
        double m[3], r = 0.0;
        for (int a = 0; a < 3; a++) m[a] = 0.5 * lo[a] + 0.5 * hi[a];
        for (int j = 0; j < cs->n; j++) {
            double e = fp_add_up(fp_add_up(trace_abs_diff_up(cs->lin[j].x[k], m[0]),
                                           trace_abs_diff_up(cs->lin[j].u[k], m[1])),
                                 fp_add_up(trace_abs_diff_up(cs->lin[j].v[k], m[2]),
                                           (double)cs->lin[j].r[k]));
            r = fmax(r, e);
        }
        if (!isfinite(r) || !trace_lin_set(lin, k, m[0], m[1], m[2], r)) return false;
    }
    return true;
}

/* The sum of a linear bound's radii (how loose it is) */
static double lin_radius(const trace_lin *l)
{
    return (double)l->r[0] + (double)l->r[1] + (double)l->r[2];
}

/* The boxes of the cell's remaining cases (sl_vm_split_next has given
 * the first of them, whose box *hull is) united into *hull, each added
 * to cs */
static void union_cases(trace_thread *th, const trace_object *obj, const affine_cell *cell,
                        trace_box *hull, case_set *cs)
{
    aa_form P[3];
    do {
        trace_box b;
        trace_moved same;
        vec3 move = v3(NAN, NAN, NAN);
        affine_shade(th, obj, cell, P, &same, &move);
        box_from_affine(P, &b);
        case_add(cs, &th->ctx, P, &b, same, move);
        trace_box_union(hull, &b);
    } while (!th->failed && sl_vm_split_next(th->vm));
}

/* What the case runs of a cell came to (run_cases) */
typedef enum {
    CASES_NONE,                   /* nothing split (or a run failed) */
    CASES_FULL,                   /* more seams than TRACE_SPLIT_OPS */
    CASES_SPLIT                   /* every case run, in *hull and cs */
} cases_result;

/* The cell's base surface and its case runs, the VM's splits begun and
 * ended here: the first run's forms in P and what it did to the base in
 * *same (the plain run's, where it split nothing), its box in *hull, and,
 * where something split and the seams fit the cases, every case's box
 * united into *hull and added to cs. The base surface stays in *cell. */
static cases_result run_cases(trace_thread *th, const trace_object *obj, double u0, double u1,
                              double v0, double v1, affine_cell *cell, aa_form P[3],
                              trace_moved *same, trace_box *hull, case_set *cs)
{
    sl_vm *vm = th->vm;
    vec3 move = v3(NAN, NAN, NAN);
    affine_geometry(th, obj, u0, u1, v0, v1, cell);
    sl_vm_split_begin(vm, TRACE_SPLIT_OPS);
    affine_shade(th, obj, cell, P, same, &move);
    box_from_affine(P, hull);
    cs->n = 0;
    case_add(cs, &th->ctx, P, hull, *same, move);
    cases_result r = CASES_FULL;
    if (!sl_vm_split_full(vm)) {
        r = !th->failed && sl_vm_split_next(vm) ? CASES_SPLIT : CASES_NONE;
        if (r == CASES_SPLIT) union_cases(th, obj, cell, hull, cs);
    }
    sl_vm_split_end(vm);
    return r;
}

bool trace_surface_box_cases(trace_thread *th, const trace_object *obj,
                             double u0, double u1, double v0, double v1, trace_box *box,
                             trace_lin *lin, trace_case_moves *moves)
{
    if (moves) moves->n = 0;
    obj = trace_box_owner(obj);
    if (th->world->options.arith == TRACE_ARITH_INTERVAL || !obj->displacement) return false;
    trace_box hull;
    affine_cell cell;
    aa_form P[3];
    trace_moved same;
    case_set cs;
    /* none where the seams overflow the cases (CASES_FULL): the rest
     * would stay as wide as one run makes them, not worth the runs */
    cases_result r = run_cases(th, obj, u0, u1, v0, v1, &cell, P, &same, &hull, &cs);
    th->stats.boxes++;
    if (th->failed || r != CASES_SPLIT) return false;
    /* a NaN side (no surface where the cases run): the box as it was */
    if (box_has_nan(&hull)) return false;
    /* both enclose the surface over the cell: so does their meet */
    trace_box m = *box;
    trace_box_meet(&m, &hull);
    m.flags = box_flags(&m, box->flags | AA_DISCONTINUOUS);
    if (m.lo.x > m.hi.x || m.lo.y > m.hi.y || m.lo.z > m.hi.z) {
        m.lo = v3(INFINITY, INFINITY, INFINITY);          /* empty: no surface */
        m.hi = v3(-INFINITY, -INFINITY, -INFINITY);
        m.flags &= ~(unsigned)AA_UNBOUNDED;
    } else if (trace_box_extent(&m) > TRACE_SPLIT_GAIN * trace_box_extent(box)) {
        /* not narrowed; where the cases' boxes are pairwise apart, the
         * surface jumps wherever two cases meet in the cell (a continuous
         * one would put their common values in both): a true step */
        if (cases_apart(&cs)) box->flags |= TRACE_BOX_STEP;
        if (cases_planes(obj, &cs, moves)) box->flags |= TRACE_BOX_PLANES;
        return false;
    }
    /* the cases' linear bound where it is tighter than the box's own */
    trace_lin cl;
    if (lin && cases_linear(&cs, &cl) &&
        (!(box->flags & TRACE_BOX_LIN) || lin_radius(&cl) < lin_radius(lin))) {
        *lin = cl;
        m.flags |= TRACE_BOX_LIN;
    }
    m.flags |= TRACE_BOX_SPLIT | (cases_planes(obj, &cs, moves) ? TRACE_BOX_PLANES : 0u);
    m.bend = 1e30f;                       /* no proofs on a split cell */
    trace_box_no_slab(&m);
    *box = m;
    return true;
}

/* trace_surface_box's end: counted, and a NaN side makes it empty */
static void box_finish(trace_thread *th, trace_box *out)
{
    th->stats.boxes++;
    /* A NaN bound: the shader's result is defined nowhere in the range
     * (common/aa gives unbounded, not NaN, where only some points are
     * undefined or huge): no surface there. Empty box, counted. */
    if (box_has_nan(out)) {
        out->lo = v3(INFINITY, INFINITY, INFINITY);
        out->hi = v3(-INFINITY, -INFINITY, -INFINITY);
        out->flags &= ~(unsigned)(AA_UNBOUNDED | TRACE_BOX_LIN);
        trace_box_no_slab(out);
        th->stats.empty_boxes++;
    }
}

bool trace_surface_box_split(trace_thread *th, const trace_object *obj,
                             double u0, double u1, double v0, double v1, trace_box *box,
                             trace_lin *lin, trace_case_moves *moves)
{
    if (moves) moves->n = 0;
    const trace_object *o = trace_box_owner(obj);
    if (th->world->options.arith == TRACE_ARITH_INTERVAL || !o->displacement) {
        trace_surface_box_lin(th, obj, u0, u1, v0, v1, box, lin);
        return false;
    }
    trace_box hull;
    affine_cell cell;
    aa_form P[3];
    trace_moved same;
    case_set cs;
    cases_result r = run_cases(th, o, u0, u1, v0, v1, &cell, P, &same, &hull, &cs);
    if (r == CASES_FULL) {
        /* more seams than cases: the case run is lost, the box as usual
         * (box_affine's run on the same cell) */
        th->stats.boxes++;
        affine_shade(th, o, &cell, P, &same, NULL);
    }
    if (r != CASES_SPLIT) {
        /* nothing split (or failed): the run was box_affine's own, and so
         * is the box (its flags and linear bound too) */
        box_of_run(th, o, &cell, P, same, box, lin);
        box_finish(th, box);
        return false;
    }
    th->stats.boxes++;
    if (th->failed || box_has_nan(&hull)) {
        /* a NaN side (no surface where a case runs): the box as usual */
        trace_surface_box_lin(th, obj, u0, u1, v0, v1, box, lin);
        return false;
    }
    hull.flags = box_flags(&hull, AA_DISCONTINUOUS) | TRACE_BOX_SPLIT |
                 (cases_apart(&cs) ? TRACE_BOX_STEP : 0u) |
                 (cases_planes(o, &cs, moves) ? TRACE_BOX_PLANES : 0u);
    /* one linear bound for all the cases: its children can be lazy */
    if (lin && cases_linear(&cs, lin)) hull.flags |= TRACE_BOX_LIN;
    hull.bend = 1e30f;                    /* no proofs on a split cell */
    trace_box_no_slab(&hull);
    *box = hull;
    return true;
}

void trace_surface_case_moves(trace_thread *th, const trace_object *obj, double u0, double u1,
                              double v0, double v1, trace_case_moves *moves)
{
    moves->n = 0;
    obj = trace_box_owner(obj);
    if (th->world->options.arith == TRACE_ARITH_INTERVAL || !obj->displacement) return;
    trace_box hull;
    affine_cell cell;
    aa_form P[3];
    trace_moved same;
    case_set cs;
    if (run_cases(th, obj, u0, u1, v0, v1, &cell, P, &same, &hull, &cs) == CASES_SPLIT &&
        !th->failed)
        cases_planes(obj, &cs, moves);
}

/* ---- interval ---- */

/*
 * M (x, 1) (a point) or M (x, 0) over the box x. Each row in midpoint-
 * radius form, all in round to nearest with the rounding bounded a priori
 * (issue 24: nine directed interval scalings and six directed sums a
 * transform were 3 % of the wave's frame). Over the box, s = sum_j m_j x_j
 * (+ t) lies in C +- R exactly, C = sum_j m_j c_j (+ t), R = sum_j |m_j|
 * r_j, for centres c_j in the box and radii r_j >= |x_j - c_j|. In round
 * to nearest (u = 2^-53): each r_j errs by at most u r_j, C's four
 * products and three sums by 7u S with S = sum_j |m_j c_j| (+ |t|), R's
 * three products and two sums by 5u R, each product that underflows by
 * 2^-1074 more; so e = 2^-49 (S + R) + 2^-1000 covers them with room for
 * its own rounding, and s lies in C +- (R + e). The ends C -+ (R + e) are
 * moved out by 2^-51 (|C| + R + e) more, which is more than their own
 * rounding (u of their magnitude). A box with an unbounded, empty or NaN
 * axis, or a result that is not finite, goes the interval way. The flags
 * are the axes' (as the interval sums give).
 */
static bool ia_xform_midrad(const mat4 *m, const ia_interval in[3], ia_interval out[3],
                            bool point)
{
    double c[3], r[3];
    unsigned flags = 0;
    for (int j = 0; j < 3; j++) {
        double lo = in[j].lo, hi = in[j].hi;
        if (!(lo <= hi) || !isfinite(lo) || !isfinite(hi))
            return false;
        c[j] = aa_input_mid(lo, hi);
        double a = hi - c[j], b = c[j] - lo;
        r[j] = a > b ? a : b;
        flags |= in[j].flags;
    }
    for (int i = 0; i < 3; i++) {
        const double *row = m->m[i];
        double t = point ? row[3] : 0.0;
        double p0 = row[0] * c[0], p1 = row[1] * c[1], p2 = row[2] * c[2];
        double C = ((p0 + p1) + p2) + t;
        double S = ((fabs(p0) + fabs(p1)) + fabs(p2)) + fabs(t);
        double R = (fabs(row[0]) * r[0] + fabs(row[1]) * r[1]) + fabs(row[2]) * r[2];
        double spread = R + ((S + R) * 0x1p-49 + 0x1p-1000);
        spread = spread + (fabs(C) + spread) * 0x1p-51;
        double lo = C - spread, hi = C + spread;
        if (!isfinite(lo) || !isfinite(hi))
            return false;
        out[i] = (ia_interval){ lo, hi, flags };
    }
    return true;
}

static void ia_xform(const mat4 *m, const ia_interval in[3], ia_interval out[3],
                     bool point)
{
    if (ia_xform_midrad(m, in, out, point))
        return;
    for (int i = 0; i < 3; i++) {
        ia_interval s = ia_add(ia_mul_s(in[0], m->m[i][0]), ia_mul_s(in[1], m->m[i][1]));
        s = ia_add(s, ia_mul_s(in[2], m->m[i][2]));
        out[i] = point ? ia_add_s(s, m->m[i][3]) : s;
    }
}

/* as trace_camera_normal_aa, in interval arithmetic */
static void ia_camera_normal(const trace_object *obj, const ia_interval Nn[3],
                             ia_interval N[3])
{
    mat4 t = mat4_transpose(obj->from_camera);
    ia_xform(&t, Nn, N, false);
    double k = obj->flip ? -1.0 : 1.0;
    if (obj->normal_scale > 0) {
        for (int i = 0; i < 3; i++) N[i] = ia_mul_s(N[i], k * obj->normal_scale);
        return;
    }
    ia_interval len2 = ia_add(ia_add(ia_sqr(N[0]), ia_sqr(N[1])), ia_sqr(N[2]));
    len2 = ia_clamp(len2, ia_point(obj->normal_len2[0]), ia_point(obj->normal_len2[1]));
    ia_interval inv = ia_invsqrt(len2);
    if (obj->flip) inv = ia_neg(inv);
    for (int i = 0; i < 3; i++)
        N[i] = ia_clamp(ia_mul(N[i], inv), ia_point(-1.0), ia_point(1.0));
}

static void box_from_interval(const ia_interval P[3], trace_box *out)
{
    out->bend = 0.0f;
    out->tape = 0;
    out->lo = v3(P[0].lo, P[1].lo, P[2].lo);
    out->hi = v3(P[0].hi, P[1].hi, P[2].hi);
    out->flags = box_flags(out, P[0].flags | P[1].flags | P[2].flags);
    trace_box_no_slab(out);
}

/* The displacement shader's globals over the (u,v) box in interval
 * arithmetic, from the base surface's g (geom_eval_ia over the box), in
 * camera space: the one binding of box and slope runs. With tangents,
 * dPdu, dPdv and P's derivative bounds (Pd) too; without, zeros, and no
 * bounds (a shader that takes no derivatives) or the whole line (one whose
 * box runs read none). */
static void bind_interval(sl_vm *vm, const trace_object *obj, ia_interval u, ia_interval v,
                          const geom_ia *g, bool tangents)
{
    ia_interval P[3], N[3], dPdu[3], dPdv[3], Nn[3];
    ia_xform(&obj->to_camera, g->P, P, true);
    geom_unit_normal_ia(&obj->surf, u, v, g, Nn);
    ia_camera_normal(obj, Nn, N);
    if (!tangents) {
        for (int i = 0; i < 3; i++)
            dPdu[i] = dPdv[i] = ia_point(0.0);
    } else {
        ia_xform(&obj->to_camera, g->dPdu, dPdu, false);
        ia_xform(&obj->to_camera, g->dPdv, dPdv, false);
    }
    ia_interval Pd[2][3] = {{dPdu[0], dPdu[1], dPdu[2]}, {dPdv[0], dPdv[1], dPdv[2]}};
    bind_globals_interval(vm, obj, &obj->displacement_spaces, P, N, N, dPdu, dPdv, &u, &v,
                          bound_derivs(obj, tangents, Pd), trace_surface_flat(obj));
    trace_primvars_bind(vm, obj, false);
}

static void box_interval(trace_thread *th, const trace_object *obj,
                         double u0, double u1, double v0, double v1, trace_box *out)
{
    ia_interval u = ia_make(u0, u1), v = ia_make(v0, v1);
    geom_ia g;
    geom_eval_ia(&obj->surf, u, v, &g);
    th->stats.evals_interval++;
    if (!obj->displacement) {
        box_from_interval(g.P, out);
        return;
    }
    sl_vm *vm = th->vm;
    bind_interval(vm, obj, u, v, &g, box_run_tangents(obj));  /* never read: not computed */
    ia_interval P[3];
    if (sl_vm_run(vm, obj->displacement, SL_MODE_INTERVAL, NULL) != SL_OK) {
        trace_thread_fail(th, sl_vm_error(vm));
        P[0] = P[1] = P[2] = ia_entire();
    } else {
        ia_interval Pc[3];
        sl_vm_get_interval(vm, SL_G_P, Pc);
        ia_xform(&obj->from_camera, Pc, P, true);
    }
    box_from_interval(P, out);
}

/* ---- slopes: interval bounds of the displaced P and of its derivatives ---- */

bool trace_surface_slopes(trace_thread *th, const trace_object *obj,
                          double u0, double u1, double v0, double v1,
                          ia_interval P[3], ia_interval Pu[3], ia_interval Pv[3])
{
    if (!obj->displacement || obj->box_proto) return false;
    ia_interval u = ia_make(u0, u1), v = ia_make(v0, v1);
    geom_ia g;
    geom_eval_ia_tight(&obj->surf, u, v, &g);
    sl_vm *vm = th->vm;
    bool slopes = Pu && Pv;
    bind_interval(vm, obj, u, v, &g, slopes || box_run_tangents(obj));
    if (slopes && obj->surf.kind != GEOM_POLYGON) {
        /* the bind's tangents are constants to the shader, true only where
         * the base surface's tangents are (a polygon's parametrisation is
         * affine; a disk's is polar): else unknown slopes */
        ia_interval any[3] = {ia_entire(), ia_entire(), ia_entire()};
        sl_vm_set_derivs(vm, SL_G_dPdu, any, any);
        sl_vm_set_derivs(vm, SL_G_dPdv, any, any);
    }
    ia_interval dNn[2][3], dN[2][3];
    if (slopes && !trace_surface_flat(obj) && obj->normal_scale > 0 &&
        geom_unit_normal_slopes_ia(&obj->surf, u, v, &g, dNn[0], dNn[1])) {
        /* N = k s M^T Nn (ia_camera_normal, a similarity): its slopes are
         * those of the object's unit normal, mapped the same way */
        mat4 t = mat4_transpose(obj->from_camera);
        double k = (obj->flip ? -1.0 : 1.0) * obj->normal_scale;
        for (int d = 0; d < 2; d++) {
            ia_xform(&t, dNn[d], dN[d], false);
            for (int i = 0; i < 3; i++) dN[d][i] = ia_mul_s(dN[d][i], k);
        }
        sl_vm_set_derivs(vm, SL_G_N, dN[0], dN[1]);
        sl_vm_set_derivs(vm, SL_G_Ng, dN[0], dN[1]);
    }
    if (slopes) th->stats.evals_slopes++;
    else th->stats.evals_interval++;
    sl_status st = slopes ? sl_vm_run_slopes(vm, obj->displacement)
                          : sl_vm_run(vm, obj->displacement, SL_MODE_INTERVAL, NULL);
    if (st != SL_OK) {
        trace_thread_fail(th, sl_vm_error(vm));
        return false;
    }
    sl_vm_get_interval(vm, SL_G_P, P);
    if (slopes) sl_vm_get_slopes(vm, SL_G_P, Pu, Pv);
    unsigned flags = 0;
    for (int i = 0; i < 3; i++) {
        flags |= P[i].flags;
        if (!isfinite(P[i].lo) || !isfinite(P[i].hi)) return false;
        if (!slopes) continue;
        flags |= Pu[i].flags | Pv[i].flags;
        if (!isfinite(Pu[i].lo) || !isfinite(Pu[i].hi) || !isfinite(Pv[i].lo) ||
            !isfinite(Pv[i].hi))
            return false;
    }
    return !(flags & (AA_DISCONTINUOUS | AA_UNBOUNDED));
}

void trace_surface_box_tape(trace_thread *th, const trace_object *obj, double u0, double u1,
                            double v0, double v1, uint32_t tape, trace_box *out, trace_lin *lin)
{
    obj = trace_box_owner(obj);           /* an instance: its prototype's box */
    if (th->world->options.arith == TRACE_ARITH_INTERVAL)
        box_interval(th, obj, u0, u1, v0, v1, out);
    else
        box_affine(th, obj, u0, u1, v0, v1, tape, out, lin);
    box_finish(th, out);
}

void trace_surface_box_lin(trace_thread *th, const trace_object *obj, double u0, double u1,
                           double v0, double v1, trace_box *out, trace_lin *lin)
{
    trace_surface_box_tape(th, obj, u0, u1, v0, v1, 0, out, lin);
}

void trace_surface_box(trace_thread *th, const trace_object *obj,
                       double u0, double u1, double v0, double v1, trace_box *out)
{
    trace_surface_box_lin(th, obj, u0, u1, v0, v1, out, NULL);
}

/* ---- points: dual mode ---- */

static void dual3(vec3 v, vec3 du, vec3 dv, sl_dual out[3])
{
    out[0] = (sl_dual){v.x, du.x, dv.x};
    out[1] = (sl_dual){v.y, du.y, dv.y};
    out[2] = (sl_dual){v.z, du.z, dv.z};
}

void trace_surface_point_eval(trace_thread *th, const trace_object *obj,
                              double u, double v, trace_surface_point *out)
{
    trace_surface_point_eval_on(th, th->vm, obj, u, v, out);
}

void trace_surface_point_move(const trace_object *obj, trace_surface_point *out)
{
    const mat4 *m = &obj->from_proto, *inv = &obj->to_proto;
    out->P = mat4_xform_point(m, out->P);
    out->dPdu = mat4_xform_vector(m, out->dPdu);
    out->dPdv = mat4_xform_vector(m, out->dPdv);
    out->Pu = mat4_xform_vector(m, out->Pu);
    out->Pv = mat4_xform_vector(m, out->Pv);
    out->N = v3_normalize(mat4_xform_normal(inv, out->N));
    out->Ng = v3_normalize(mat4_xform_normal(inv, out->Ng));
}

/* An instance sharing its prototype's boxes (trace/instance.c): its
 * surface is the prototype's, moved rigidly into its camera space. */
static void point_of_instance(trace_thread *th, sl_vm *vm, const trace_object *obj,
                              double u, double v, trace_surface_point *out)
{
    trace_surface_point_eval_on(th, vm, obj->box_proto, u, v, out);
    trace_surface_point_move(obj, out);
}

void trace_surface_point_eval_on(trace_thread *th, sl_vm *vm, const trace_object *obj,
                                 double u, double v, trace_surface_point *out)
{
    if (obj->box_proto) {
        point_of_instance(th, vm, obj, u, v, out);
        return;
    }
    geom_sample g;
    if (obj->displacement) geom_eval_dual(&obj->surf, u, v, &g);
    else geom_eval(&obj->surf, u, v, &g);
    vec3 P = mat4_xform_point(&obj->to_camera, g.P);
    vec3 dPdu = mat4_xform_vector(&obj->to_camera, g.dPdu);
    vec3 dPdv = mat4_xform_vector(&obj->to_camera, g.dPdv);
    /* the base normal: Ng, or its limit where Ng = 0 (geom_normal_dual) */
    vec3 Nb, dNbdu, dNbdv;
    geom_normal_dual(&obj->surf, u, v, &g, &Nb, &dNbdu, &dNbdv);
    vec3 Ng = mat4_xform_normal(&obj->from_camera, Nb);
    if (obj->flip) Ng = v3_neg(Ng);
    /* the shading normal: that, or a mesh face's interpolated vertex
     * normals (oriented like Ng, flipped with it) */
    vec3 Ns = Nb, dNsdu = dNbdu, dNsdv = dNbdv;
    bool smooth = geom_vertex_normal(&obj->surf, u, v, &Ns, &dNsdu, &dNsdv);
    Ns = mat4_xform_normal(&obj->from_camera, Ns);
    if (obj->flip) Ns = v3_neg(Ns);
    out->u = u;
    out->v = v;
    out->dPdu = dPdu;
    out->dPdv = dPdv;
    out->Ng = v3_normalize(Ng);
    out->P = P;
    out->Pu = dPdu;
    out->Pv = dPdv;
    out->N = smooth ? v3_normalize(Ns) : out->Ng;
    if (!obj->displacement) return;

    /* N is the unit normal in every mode (see docs/renderer.md): here
     * Nn = Ns/|Ns| with d(Nn) = (dNs - Nn (Nn . dNs)) / |Ns| */
    vec3 dNdu = mat4_xform_normal(&obj->from_camera, dNsdu);
    vec3 dNdv = mat4_xform_normal(&obj->from_camera, dNsdv);
    if (obj->flip) { dNdu = v3_neg(dNdu); dNdv = v3_neg(dNdv); }
    double glen = v3_length(Ns);
    vec3 Nn = out->N;
    if (glen > 0) {
        dNdu = v3_scale(v3_sub(dNdu, v3_scale(Nn, v3_dot(Nn, dNdu))), 1.0 / glen);
        dNdv = v3_scale(v3_sub(dNdv, v3_scale(Nn, v3_dot(Nn, dNdv))), 1.0 / glen);
    }
    sl_dual dP[3], dN[3], ddPdu[3], ddPdv[3];
    dual3(P, dPdu, dPdv, dP);
    dual3(Nn, dNdu, dNdv, dN);
    dual3(dPdu, v3(0, 0, 0), v3(0, 0, 0), ddPdu);
    dual3(dPdv, v3(0, 0, 0), v3(0, 0, 0), ddPdv);
    sl_dual du_ = {u, 1, 0}, dv_ = {v, 0, 1};
    bind_globals_dual(vm, obj, &obj->displacement_spaces, dP, dN, dN, ddPdu, ddPdv, &du_, &dv_,
                      NULL, false);
    trace_primvars_bind(vm, obj, false);
    th->stats.evals_dual++;
    if (sl_vm_run(vm, obj->displacement, SL_MODE_DUAL, NULL) != SL_OK) {
        trace_thread_fail(th, sl_vm_error(vm));
        return;
    }
    sl_dual rP[3], rN[3];
    sl_vm_get_dual(vm, SL_G_P, rP);
    sl_vm_get_dual(vm, SL_G_N, rN);
    out->P = v3(rP[0].v, rP[1].v, rP[2].v);
    out->Pu = v3(rP[0].du, rP[1].du, rP[2].du);
    out->Pv = v3(rP[0].dv, rP[1].dv, rP[2].dv);
    vec3 N = v3(rN[0].v, rN[1].v, rN[2].v);
    double len = v3_length(N);
    if (len > 0 && isfinite(len)) out->N = v3_scale(N, 1.0 / len);
}
