/*
 * region.c: a sound box for many pieces of a displaced mesh from ONE
 * affine run of its displacement shader (see region.h).
 *
 * Heidrich & Seidel 1998 §3.1 bound a displaced surface over a (u,v)
 * range by running the shader in affine arithmetic (§4, §4.2) on
 * enclosures of its parameters (Table 1). Here the range is a REGION, a
 * set of pieces, and every global is bound to an enclosure valid for
 * every piece at every (u,v) of it:
 *
 *   P, I      the pieces' undisplaced object-space box over their whole
 *             (u,v) squares (the union of their geom_bounds and of their
 *             base P's affine range over [0,1]^2: a polygon's square is its
 *             bounding rectangle, and its root box holds all of it; widened
 *             by a relative hair for the rounding of the point paths), an
 *             affine form of 3 fresh noise symbols, moved to camera space
 *             as box_affine does (displace.c)
 *   N, Ng     the hull of the pieces' camera-space unit normals over their
 *             whole (u,v) square, each from the geometry's own affine
 *             unit normal (geom_unit_normal_aa: a normalised interpolation
 *             of vertex normals may leave the box of its corners), 3 fresh
 *             symbols
 *   u, v      [0, 1], 2 fresh symbols (s, t follow them without "st")
 *   dPdu, dPdv  hulls of the pieces' camera-space tangents, and P's
 *             derivative bounds the same hulls (zeros and no bounds where
 *             the shader never reads them: box_skip_tangents)
 *   du, dv    the range of the pieces' per-piece constants
 *   s, t, Cs, Os  from primitive variables: hulls of the pieces'
 *             polynomials over [0,1]^2 (interval Horner), derivative
 *             bounds the hulls of their d/du, d/dv
 *   E, time, the spaces  as for any piece (the mesh object's)
 *
 * The hulls other than P, u, v, N are forms of a private error term only
 * (no symbol: the symbols left are the shader's, as a piece box's).
 * Soundness: for a piece k and (u,v), the tuple of its true globals lies
 * in the product of these enclosures, and each enclosure is an affine
 * form of its own symbols, so some assignment of the symbols gives that
 * tuple; the shader's affine run then encloses P'(k, u, v). Two boxes
 * come of the run, both sound, and the result is their meet: the range
 * of P' mapped back to object space, and the pieces' box plus the range
 * of P' - P (the shift; P's symbols cancel in it: the displacement alone).
 *
 * Refused (the unbounded box): a primitive variable bound to a parameter
 * of the displacement shader (the VM takes a parameter's varying value as
 * a polynomial of the run's u, v, which the pieces do not share), one that
 * sets another global, and pieces whose variables differ in kind.
 */
#include "trace/region.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>

#include "trace/displace.h"
#include "trace/mesh.h"
#include "util/xalloc.h"

#define G_T aa_form
#define G_SUFFIX affine
#define G_SET sl_vm_set_affine
#define G_CONST aa_const
#include "trace/globals.inc"

/* A primitive variable's enclosures over the region */
typedef struct region_pv {
    sl_global global;
    int size;
    ia_interval v[3], du[3], dv[3];
} region_pv;

/* What the pieces' visit found: a region */
struct trace_region {
    int count;                         /* pieces added (0: every hull empty) */
    bool refused;                      /* a piece the region cannot bind */
    ia_interval B[3];                  /* undisplaced, object space */
    ia_interval N[3];                  /* unit normal, camera space */
    ia_interval dPdu[3], dPdv[3];      /* camera space */
    ia_interval du, dv;
    bool flat;                         /* every piece's N constant */
    int npv;
    region_pv pv[TRACE_MAX_PRIMVARS];
    int kinds[TRACE_MAX_PRIMVARS][3];  /* the first piece's variables: global, param, size */
};
static void hull3(ia_interval h[3], const ia_interval x[3], bool first)
{
    for (int i = 0; i < 3; i++) h[i] = first ? x[i] : ia_hull(h[i], x[i]);
}

/* Component k of sum c[i + 4 j] u^i v^j over [0,1]^2 (dk = 0), or of its
 * d/du (dk = 1) or d/dv (dk = 2), by Horner's rule in interval arithmetic */
static ia_interval poly_range(const double c[16][3], int k, int dk)
{
    ia_interval unit = ia_make(0.0, 1.0), acc = ia_point(0.0);
    /* the degrees the coefficients reach (zero terms add nothing) */
    int di = 0, dj = 0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (c[i + 4 * j][k] != 0.0) {
                di = i > di ? i : di;
                dj = j > dj ? j : dj;
            }
    for (int j = dj; j >= 0; j--) {
        ia_interval q = ia_point(0.0);
        for (int i = di; i >= 0; i--) {
            int si = dk == 1 ? i + 1 : i, sj = dk == 2 ? j + 1 : j;
            double a = si < 4 && sj < 4 ? c[si + 4 * sj][k] : 0.0;
            ia_interval t = ia_point(a);
            if (dk == 1) t = ia_mul_s(t, (double)si);
            if (dk == 2) t = ia_mul_s(t, (double)sj);
            q = ia_add(ia_mul(q, unit), t);
        }
        acc = ia_add(ia_mul(acc, unit), q);
    }
    return acc;
}

/* The globals a primitive variable may set in a displacement run */
static bool region_global(sl_global g)
{
    return g == SL_G__COUNT || g == SL_G_s || g == SL_G_t || g == SL_G_Cs || g == SL_G_Os;
}

/* The piece's primitive variables into the hull; false: refused */
static bool hull_primvars(const trace_object *obj, trace_region *h, bool first)
{
    if (first) h->npv = obj->nprimvars;
    if (obj->nprimvars != h->npv) return false;
    for (int i = 0; i < obj->nprimvars; i++) {
        const trace_primvar *p = &obj->primvars[i];
        int kind[3] = {(int)p->global, p->displacement_param, p->size};
        if (first) {
            for (int k = 0; k < 3; k++) h->kinds[i][k] = kind[k];
        } else if (kind[0] != h->kinds[i][0] || kind[1] != h->kinds[i][1] ||
                   kind[2] != h->kinds[i][2]) {
            return false;
        }
        if (p->displacement_param >= 0 || !region_global(p->global)) return false;
        if (p->global == SL_G__COUNT) continue;
        region_pv *r = &h->pv[i];
        r->global = p->global;
        r->size = p->size;
        if (p->size != (p->global == SL_G_s || p->global == SL_G_t ? 1 : 3)) return false;
        for (int k = 0; k < p->size; k++) {
            ia_interval x[3] = {poly_range(p->c, k, 0), poly_range(p->c, k, 1),
                                poly_range(p->c, k, 2)};
            r->v[k] = first ? x[0] : ia_hull(r->v[k], x[0]);
            r->du[k] = first ? x[1] : ia_hull(r->du[k], x[1]);
            r->dv[k] = first ? x[2] : ia_hull(r->dv[k], x[2]);
        }
    }
    return true;
}

/* Piece obj (a view) into the hull: no shader, its geometry's affine
 * forms over its whole (u,v) square as box_affine makes them */
static bool hull_piece(trace_thread *th, const trace_object *obj, const ia_interval *dudv,
                       trace_region *h, bool first)
{
    vec3 lo, hi;
    geom_bounds(&obj->surf, &lo, &hi);
    ia_interval B[3] = {ia_make(lo.x, hi.x), ia_make(lo.y, hi.y), ia_make(lo.z, hi.z)};
    if (!obj->displacement) {
        hull3(h->B, B, first);
        return true;
    }
    aa_context *ctx = &th->ctx;
    aa_context_reset(ctx);
    aa_form u, v, Nn[3], N[3], T[3];
    aa_input(ctx, &u, 0.0, 1.0);
    aa_input(ctx, &v, 0.0, 1.0);
    geom_aa g;
    geom_eval_aa(ctx, &obj->surf, &u, &v, &g);
    /* the shader runs over the whole (u,v) square, which may be more than
     * the surface (a polygon's is its bounding rectangle: the piece's box
     * holds that): the square's base points too */
    ia_interval r[3];
    for (int i = 0; i < 3; i++) r[i] = ia_hull(B[i], aa_range(&g.P[i]));
    hull3(h->B, r, first);
    geom_unit_normal_aa(ctx, &obj->surf, &u, &v, &g, Nn);
    trace_camera_normal_aa(ctx, obj, Nn, N);
    for (int i = 0; i < 3; i++) r[i] = aa_range(&N[i]);
    hull3(h->N, r, first);
    if (!obj->box_skip_tangents) {
        trace_xform_aa(ctx, &obj->to_camera, g.dPdu, T, false);
        for (int i = 0; i < 3; i++) r[i] = aa_range(&T[i]);
        hull3(h->dPdu, r, first);
        trace_xform_aa(ctx, &obj->to_camera, g.dPdv, T, false);
        for (int i = 0; i < 3; i++) r[i] = aa_range(&T[i]);
        hull3(h->dPdv, r, first);
    }
    h->flat = (first || h->flat) && trace_surface_flat(obj);
    ia_interval du = dudv ? dudv[0] : ia_point(obj->du);
    ia_interval dv = dudv ? dudv[1] : ia_point(obj->dv);
    h->du = first ? du : ia_hull(h->du, du);
    h->dv = first ? dv : ia_hull(h->dv, dv);
    return hull_primvars(obj, h, first);
}

/* x as a form without a symbol: its centre and a private error term (an
 * input whose correlations the region does not keep) */
static void hull_form(aa_form *z, ia_interval x)
{
    aa_context none;
    aa_context_init(&none, 0);         /* no symbol to hand out: folded into err */
    aa_input(&none, z, x.lo, x.hi);
}

static void unbounded_box(trace_box *out)
{
    out->lo = v3(-INFINITY, -INFINITY, -INFINITY);
    out->hi = v3(INFINITY, INFINITY, INFINITY);
    out->flags = AA_UNBOUNDED;
    out->bend = 1e30f;
    trace_box_no_slab(out);
}

/* lo - e, hi + e with e a relative hair of their magnitude (the points of
 * the float and dual paths may round a hair beyond the bounds) */
static ia_interval widen(ia_interval x)
{
    double e = (fabs(x.lo) + fabs(x.hi)) * 0x1p-40 + 0x1p-1000;
    return ia_make(x.lo - e, x.hi + e);
}

/* The shader's one run over the region (hull h, every piece visited) */
static bool region_run(trace_thread *th, const trace_object *mobj, const trace_region *h,
                       trace_box *out, ia_interval shift[3])
{
    aa_context ctx;
    aa_context_init(&ctx, th->world->options.aa_capacity + 6);
    aa_form Po[3], P[3], u, v, N[3], dPdu[3], dPdv[3];
    ia_interval B[3];
    for (int i = 0; i < 3; i++) B[i] = widen(h->B[i]);
    for (int i = 0; i < 3; i++) aa_input(&ctx, &Po[i], B[i].lo, B[i].hi);
    aa_input(&ctx, &u, 0.0, 1.0);
    aa_input(&ctx, &v, 0.0, 1.0);
    for (int i = 0; i < 3; i++) aa_input(&ctx, &N[i], h->N[i].lo, h->N[i].hi);
    trace_xform_aa(&ctx, &mobj->to_camera, Po, P, true);
    ia_interval Pd[2][3] = {{ia_point(0.0), ia_point(0.0), ia_point(0.0)},
                            {ia_point(0.0), ia_point(0.0), ia_point(0.0)}};
    for (int i = 0; i < 3; i++) {
        if (mobj->box_skip_tangents) {     /* never read: zeros, as box_affine */
            aa_const(&dPdu[i], 0.0);
            aa_const(&dPdv[i], 0.0);
            continue;
        }
        hull_form(&dPdu[i], h->dPdu[i]);
        hull_form(&dPdv[i], h->dPdv[i]);
        Pd[0][i] = h->dPdu[i];
        Pd[1][i] = h->dPdv[i];
    }
    sl_vm *vm = th->vm;
    bind_globals_affine(vm, mobj, &mobj->displacement_spaces, P, N, N, dPdu, dPdv, &u, &v,
                        mobj->box_skip_tangents ? NULL : Pd, h->flat);
    /* the per-piece constants and the primitive variables' globals, over
     * the pieces (the last variable of a global wins, as the VM's order) */
    aa_form f[3];
    ia_interval zero[3] = {ia_point(0.0), ia_point(0.0), ia_point(0.0)};
    hull_form(&f[0], h->du);
    sl_vm_set_affine(vm, SL_G_du, f);
    hull_form(&f[0], h->dv);
    sl_vm_set_affine(vm, SL_G_dv, f);
    sl_vm_set_derivs(vm, SL_G_du, zero, zero);
    sl_vm_set_derivs(vm, SL_G_dv, zero, zero);
    for (int i = 0; i < h->npv; i++) {
        const region_pv *r = &h->pv[i];
        if (h->kinds[i][0] == (int)SL_G__COUNT) continue;
        for (int k = 0; k < r->size; k++) hull_form(&f[k], r->v[k]);
        sl_vm_set_affine(vm, r->global, f);
        sl_vm_set_derivs(vm, r->global, r->du, r->dv);
    }
    th->stats.evals_affine++;
    if (sl_vm_run(vm, mobj->displacement, SL_MODE_AFFINE, &ctx) != SL_OK) return false;
    aa_form Pc[3], Pn[3], D;
    sl_vm_get_affine(vm, SL_G_P, Pc);
    trace_xform_aa(&ctx, &mobj->from_camera, Pc, Pn, true);
    ia_interval r[3];
    unsigned flags = 0;
    for (int i = 0; i < 3; i++) {
        aa_sub(&ctx, &D, &Pn[i], &Po[i]);       /* the shift: P's symbols cancel */
        ia_interval d = aa_range(&D), a = aa_range(&Pn[i]), b = ia_add(B[i], d);
        flags |= Pn[i].flags | D.flags;
        r[i] = ia_make(fmax(a.lo, b.lo), fmin(a.hi, b.hi));
        if (!(r[i].lo <= r[i].hi) || !isfinite(r[i].lo) || !isfinite(r[i].hi)) return false;
        if (shift && !(isfinite(d.lo) && isfinite(d.hi))) return false;
        if (shift) shift[i] = d;
    }
    out->lo = v3(r[0].lo, r[1].lo, r[2].lo);
    out->hi = v3(r[0].hi, r[1].hi, r[2].hi);
    out->flags = flags & AA_DISCONTINUOUS;
    out->bend = 1e30f;
    trace_box_no_slab(out);
    return true;
}

trace_region *trace_region_new(void)
{
    return xcalloc(1, sizeof(trace_region));
}

void trace_region_destroy(trace_region **self)
{
    free(*self);
    *self = NULL;
}

bool trace_region_add(trace_thread *th, trace_region *self, const trace_object *piece,
                      const ia_interval *dudv)
{
    bool first = self->count == 0;
    self->count++;
    if (!hull_piece(th, piece, dudv, self, first)) self->refused = true;
    return !self->refused;
}

void trace_region_base(aa_context *ctx, const geom_surface *surf, float base[6])
{
    vec3 lo, hi;
    geom_bounds(surf, &lo, &hi);
    ia_interval b[3] = {ia_make(lo.x, hi.x), ia_make(lo.y, hi.y), ia_make(lo.z, hi.z)};
    /* the square's base points too, as hull_piece (a box is all it
     * needs: no forms); but a subdivision face's square is the face, and
     * its bounds, the hull of its 1-ring padded by 1e-12 of its size, hold
     * the hull of its nets (padded by 2^-40 of their size, each point a
     * convex combination of the ring's) with room to spare, so the hull
     * with them is the bounds, bit for bit (test_geom_short_paths) */
    ia_interval P[3] = {b[0], b[1], b[2]};
    if (surf->kind != GEOM_SUBDIV) {
        aa_context_reset(ctx);
        aa_form u, v;
        aa_input(ctx, &u, 0.0, 1.0);
        aa_input(ctx, &v, 0.0, 1.0);
        geom_eval_aa_range_P(ctx, surf, &u, &v, P);
    }
    for (int i = 0; i < 3; i++) {
        b[i] = widen(ia_hull(b[i], P[i]));
        base[i] = trace_float_down(b[i].lo);
        base[3 + i] = trace_float_up(b[i].hi);
    }
}

void trace_region_merge(trace_region *into, const trace_region *from)
{
    if (from->count == 0) return;
    if (into->count == 0) {
        *into = *from;
        return;
    }
    into->count += from->count;
    into->refused |= from->refused;
    if (into->refused) return;
    hull3(into->B, from->B, false);
    hull3(into->N, from->N, false);
    hull3(into->dPdu, from->dPdu, false);
    hull3(into->dPdv, from->dPdv, false);
    into->du = ia_hull(into->du, from->du);
    into->dv = ia_hull(into->dv, from->dv);
    into->flat = into->flat && from->flat;
    if (into->npv != from->npv) {
        into->refused = true;
        return;
    }
    for (int i = 0; i < into->npv; i++) {
        for (int k = 0; k < 3; k++)
            if (into->kinds[i][k] != from->kinds[i][k]) {
                into->refused = true;
                return;
            }
        region_pv *a = &into->pv[i];
        const region_pv *b = &from->pv[i];
        if (into->kinds[i][0] == (int)SL_G__COUNT) continue;
        for (int k = 0; k < a->size; k++) {
            a->v[k] = ia_hull(a->v[k], b->v[k]);
            a->du[k] = ia_hull(a->du[k], b->du[k]);
            a->dv[k] = ia_hull(a->dv[k], b->dv[k]);
        }
    }
}

bool trace_region_run(trace_thread *th, const trace_object *mesh_obj, const trace_region *self,
                      trace_box *out, ia_interval shift[3])
{
    assert(mesh_obj->mesh);
    unbounded_box(out);
    if (self->count == 0 || self->refused) return false;
    bool ok;
    if (mesh_obj->displacement) {
        ok = region_run(th, mesh_obj, self, out, shift);
    } else {
        ia_interval B[3];
        for (int i = 0; i < 3; i++) B[i] = widen(self->B[i]);
        out->lo = v3(B[0].lo, B[1].lo, B[2].lo);
        out->hi = v3(B[0].hi, B[1].hi, B[2].hi);
        out->flags = 0;
        out->bend = 0.0f;
        if (shift)
            for (int i = 0; i < 3; i++) shift[i] = ia_point(0.0);
        ok = true;
    }
    if (!ok) unbounded_box(out);
    return ok;
}

bool trace_mesh_region_box(trace_thread *th, const trace_object *mesh_obj, const int *pieces,
                           int n, trace_box *out)
{
    assert(mesh_obj->mesh && n >= 0);
    if (n == 0) {
        unbounded_box(out);
        out->lo = v3(INFINITY, INFINITY, INFINITY);
        out->hi = v3(-INFINITY, -INFINITY, -INFINITY);
        out->flags = 0;
        return true;
    }
    trace_region *h = trace_region_new();
    trace_view *view = xmalloc(sizeof *view);
    bool ok = true;
    for (int i = 0; ok && i < n; i++) {
        assert(pieces[i] >= 0 && pieces[i] < mesh_obj->mesh->npieces);
        ok = trace_mesh_view_make(th, mesh_obj, pieces[i], false, view) &&
             trace_region_add(th, h, &view->obj, NULL);
    }
    free(view);
    ok = ok && trace_region_run(th, mesh_obj, h, out, NULL);
    trace_region_destroy(&h);
    if (!ok) unbounded_box(out);
    return ok;
}
