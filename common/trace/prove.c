/*
 * prove.c: the Krawczyk test of a quadtree cell against a ray, and the
 * Newton iteration that places a proven hit (see prove.h).
 *
 * The ray as two planes through it (ray_planes): G(u, v) = 0 exactly where
 * the displaced P(u, v) lies on the ray's line. With X the cell widened by
 * a quarter of its width on each side (the slopes' box), c the cell's
 * centre, J(X) an interval matrix enclosing G's Jacobian over X (from the
 * slope bounds of trace_surface_slopes) and Y any real matrix (here the
 * inverse of J's midpoint), the Krawczyk operator
 *
 *     K(X) = c - Y G(c) + (I - Y J(X)) (X - c)
 *
 * contains every zero of G in X (Krawczyk 1969; Neumaier 1990, Theorem
 * 5.1.8; the operator needs only slope bounds, so a function that is
 * merely Lipschitz, as min, max and clamp make it, is covered). Hence
 * K(X) disjoint from the cell proves that the cell holds no zero, and K(X)
 * inside the interior of X proves that X holds exactly one. That zero is
 * the cell's only candidate: the answer is it, whether it lies in the cell
 * or beside it (a real intersection found early only prunes the walk).
 *
 * Where K(X) is too wide for either (the zero near the cell's border, the
 * common case on 16-pixel cells), the zero is placed per ray instead:
 * Newton's iteration from K's centre settles at a point y, and the small
 * box B about y (four times the last step) passes K(B, y) inside B's
 * interior, with G(y) enclosed by an interval evaluation at y and J still
 * over X. That proves a zero in B, and the only one in X: K(B, y) inside
 * B with J over X makes |I - Y J| contract (Rump 1983: every matrix in J
 * is regular, so G is one-to-one on X). G(c) comes from an enclosure of P
 * at the centre, cached with the slopes per cell. Every operation is
 * rounding-safe: midpoint-radius arithmetic whose radii cover the
 * round-to-nearest errors (mr_*, below), ends rounded outward exactly
 * (common/aa/rounding.h).
 */
#include "trace/prove.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "aa/interval.h"
#include "aa/rounding.h"
#include "trace/cellkey.h"
#include "util/xalloc.h"

/* Newton steps after a proof: quadratic convergence from inside the
 * proof's box, which is already a fraction of a pixel wide */
#define PROVE_NEWTON_STEPS 4
/* Newton's iteration has settled when its step is at most this fraction
 * of the cell: the step is then taken to first order (settle), which
 * leaves the point off the ray by the step's square, quadratic
 * convergence's next step (2^-16 of a cell, a cell being at most 16
 * pixels: below 1/4000 of a pixel) */
#define PROVE_SETTLED 0x1p-8

/* The slopes are taken over the cell widened by this fraction of its
 * width on each side (within the unit square) */
#define PROVE_MARGIN 0.25

/* Midpoint-radius arithmetic in round-to-nearest (Rump 1999, "Fast and
 * parallel interval arithmetic"): x is [m - r, m + r]. An operation takes
 * its midpoint in RN and a radius that covers the operands' radii, the
 * midpoint's own rounding (at most u |m|, u = 2^-53, for a normal result;
 * an underflow loses at most 2^-1075, covered by MR_TINY), and, by the
 * factor MR_UP, the rounding of the few RN operations (at most six, each a
 * factor 1 + u) that compute the radius itself. No rounding mode changes:
 * the proof's arithmetic costs a few flops per operation, a third of the
 * directed-rounding intervals' (ia_*) it replaced. */
typedef struct mr { double m, r; } mr;
#define MR_U 0x1p-53
#define MR_UP (1.0 + 0x1p-50)
#define MR_TINY 0x1p-1000

static inline double mr_up(double r) { return r * MR_UP + MR_TINY; }
static inline mr mr_of(ia_interval x)
{
    double m = 0.5 * x.lo + 0.5 * x.hi;
    return (mr){m, mr_up(fmax(m - x.lo, x.hi - m))};
}
static inline mr mr_pt(double x) { return (mr){x, 0.0}; }
static inline mr mr_add(mr x, mr y)
{
    double m = x.m + y.m;
    return (mr){m, mr_up(x.r + y.r + MR_U * fabs(m))};
}
static inline mr mr_sub(mr x, mr y)
{
    double m = x.m - y.m;
    return (mr){m, mr_up(x.r + y.r + MR_U * fabs(m))};
}
static inline mr mr_scale(mr x, double s)
{
    double m = s * x.m;
    return (mr){m, mr_up(fabs(s) * x.r + MR_U * fabs(m))};
}
static inline mr mr_mul(mr x, mr y)
{
    double m = x.m * y.m;
    return (mr){m, mr_up(fabs(x.m) * y.r + x.r * (fabs(y.m) + y.r) + MR_U * fabs(m))};
}
/* the ends, rounded outward exactly (rounding.h) */
static inline double mr_lo(mr x) { return fp_add_dn(x.m, -x.r); }
static inline double mr_hi(mr x) { return fp_add_up(x.m, x.r); }

/* What a proof needs of a cell, computed once per cell and kept in a
 * direct-mapped per-thread cache (a pure function of object and cell, so
 * what it holds never changes an answer; fixed size, so memory stays flat):
 * the slope bounds over the cell and the enclosure of P at its centre. */
enum { SLOPE_CACHE_LOG2 = 11, SLOPE_CACHE_ENTRIES = 1 << SLOPE_CACHE_LOG2 };
typedef struct slope_entry {
    double r[4];                    /* the cell; r[0] >= r[1]: empty */
    double X[4];                    /* the box the slopes hold over */
    int obj;
    bool ok;                        /* the slopes are known */
    mr Pu[3], Pv[3], Pc[3];
} slope_entry;
struct trace_slope_cache { slope_entry e[SLOPE_CACHE_ENTRIES]; };

static const slope_entry *cell_slopes(trace_thread *th, const trace_object *obj,
                                      const double r[4])
{
    if (!th->slopes) {                   /* zeroed: empty (cellkey.h) */
        th->slopes = xcalloc(1, sizeof *th->slopes);
    }
    slope_entry *e = &th->slopes->e[trace_cell_slot(r, obj->id, SLOPE_CACHE_LOG2)];
    if (trace_cell_is(e->r, e->obj, r, obj->id)) return e->ok ? e : NULL;
    ia_interval P[3], Pu[3], Pv[3], Pc[3];
    double uc = 0.5 * (r[0] + r[1]), vc = 0.5 * (r[2] + r[3]);
    double du = PROVE_MARGIN * (r[1] - r[0]), dv = PROVE_MARGIN * (r[3] - r[2]);
    double *X = e->X;
    X[0] = fmax(0.0, r[0] - du);
    X[1] = fmin(1.0, r[1] + du);
    X[2] = fmax(0.0, r[2] - dv);
    X[3] = fmin(1.0, r[3] + dv);
    e->ok = trace_surface_slopes(th, obj, X[0], X[1], X[2], X[3], P, Pu, Pv);
    if (!e->ok && !th->failed && PROVE_MARGIN > 0) { /* a jump beside the cell */
        memcpy(X, r, sizeof e->X);
        e->ok = trace_surface_slopes(th, obj, r[0], r[1], r[2], r[3], P, Pu, Pv);
    }
    e->ok = e->ok && trace_surface_slopes(th, obj, uc, uc, vc, vc, Pc, NULL, NULL);
    for (int i = 0; e->ok && i < 3; i++) {
        e->Pu[i] = mr_of(Pu[i]);
        e->Pv[i] = mr_of(Pv[i]);
        e->Pc[i] = mr_of(Pc[i]);
    }
    if (th->failed) {                   /* a failed run: nothing to keep */
        trace_cell_forget(e->r);
        return NULL;
    }
    trace_cell_keep(e->r, &e->obj, r, obj->id);
    return e->ok ? e : NULL;
}

bool trace_prove_cell_has_slopes(trace_thread *th, const trace_object *obj, const double r[4])
{
    if (obj->box_proto) obj = obj->box_proto;
    return cell_slopes(th, obj, r) != NULL;
}

bool trace_prove_eligible(const trace_object *obj)
{
    return obj->displacement && trace_surface_has_slopes(trace_box_owner(obj));
}

static double mid(ia_interval x) { return 0.5 * x.lo + 0.5 * x.hi; }

bool trace_newton_step(vec3 Pu, vec3 Pv, vec3 d, vec3 f, double s[3])
{
    vec3 nd = v3_neg(d);
    double det = v3_dot(Pu, v3_cross(Pv, nd));
    if (!(fabs(det) > 0) || !isfinite(det)) return false;
    vec3 rhs = v3_neg(f);
    s[0] = v3_dot(rhs, v3_cross(Pv, nd)) / det;
    s[1] = v3_dot(Pu, v3_cross(rhs, nd)) / det;
    s[2] = v3_dot(Pu, v3_cross(Pv, rhs)) / det;
    return isfinite(s[0]) && isfinite(s[1]);
}

static double clampd(double x, ia_interval r) { return x < r.lo ? r.lo : x > r.hi ? r.hi : x; }

/* The ray as two planes through it: with k the axis of d's largest
 * component and i, j the others, G(u, v) = (g_i, g_j),
 *     g_i = d_k (P_i - o_i) - d_i (P_k - o_k),
 * vanishes exactly where P(u, v) lies on the ray's line (the two normals
 * (d_k e_i - d_i e_k) and (d_k e_j - d_j e_k) are orthogonal to d in real
 * arithmetic, being made of d's own components, and independent since
 * d_k != 0). t is then (P - o) . d / (d . d). */
typedef struct ray_planes { int i, j, k; double o[3], d[3]; } ray_planes;

static bool planes_of(const trace_ray *ray, ray_planes *rp)
{
    double d[3] = {ray->d.x, ray->d.y, ray->d.z}, o[3] = {ray->o.x, ray->o.y, ray->o.z};
    int k = fabs(d[0]) > fabs(d[1]) ? 0 : 1;
    if (fabs(d[2]) > fabs(d[k])) k = 2;
    if (!(fabs(d[k]) > 0) || !isfinite(d[k])) return false;
    rp->k = k;
    rp->i = (k + 1) % 3;
    rp->j = (k + 2) % 3;
    for (int a = 0; a < 3; a++) {
        rp->o[a] = o[a];
        rp->d[a] = d[a];
    }
    return true;
}

/* g = d_k x_a - d_a x_k for the axis a (i or j): of a point (x = P - o)
 * or, with point false, of a derivative */
static mr plane_g(const ray_planes *rp, int a, const mr P[3], bool point)
{
    mr xa = P[a], xk = P[rp->k];
    if (point) {
        xa = mr_sub(xa, mr_pt(rp->o[a]));
        xk = mr_sub(xk, mr_pt(rp->o[rp->k]));
    }
    return mr_sub(mr_scale(xa, rp->d[rp->k]), mr_scale(xk, rp->d[a]));
}

/* P at a point of X from an enclosure at y and the slopes over X (the
 * mean value theorem): t = (P - o) . d / d.d over the box B */
static bool t_range(const ray_planes *rp, const mr Py[3], const mr Pu[3], const mr Pv[3],
                    const double y[2], const double B[2][2], ia_interval *T)
{
    mr ku = mr_sub(mr_of(ia_make(B[0][0], B[0][1])), mr_pt(y[0]));
    mr kv = mr_sub(mr_of(ia_make(B[1][0], B[1][1])), mr_pt(y[1]));
    mr num = mr_pt(0.0), dd = mr_pt(0.0);
    for (int a = 0; a < 3; a++) {
        mr p = mr_add(Py[a], mr_add(mr_mul(Pu[a], ku), mr_mul(Pv[a], kv)));
        num = mr_add(num, mr_scale(mr_sub(p, mr_pt(rp->o[a])), rp->d[a]));
        dd = mr_add(dd, mr_mul(mr_pt(rp->d[a]), mr_pt(rp->d[a])));
    }
    /* t = num / dd: |num/dd - num.m/dd.m| <= (num.r + |t| dd.r) / (dd.m - dd.r) */
    double dlo = dd.m - dd.r * MR_UP;
    if (!(dlo > 0)) return false;
    double tm = num.m / dd.m;
    mr tq = {tm, mr_up((num.r + fabs(tm) * dd.r) / dlo * MR_UP + MR_U * fabs(tm))};
    *T = ia_make(mr_lo(tq), mr_hi(tq));
    return isfinite(T->lo) && isfinite(T->hi);
}

/* The Krawczyk operator about the point y with G(y) enclosed by Gy, over
 * the box B (containing y, inside the slopes' box): K's ends per axis */
static bool krawczyk(const mr Gy[2], mr J[2][2], double Y[2][2], const double y[2],
                     double B[2][2], double K[2][2])
{
    mr dB[2] = {mr_sub(mr_of(ia_make(B[0][0], B[0][1])), mr_pt(y[0])),
                mr_sub(mr_of(ia_make(B[1][0], B[1][1])), mr_pt(y[1]))};
    for (int a = 0; a < 2; a++) {
        mr k = mr_sub(mr_pt(y[a]), mr_add(mr_scale(Gy[0], Y[a][0]), mr_scale(Gy[1], Y[a][1])));
        for (int b = 0; b < 2; b++) {
            mr yj = mr_add(mr_scale(J[0][b], Y[a][0]), mr_scale(J[1][b], Y[a][1]));
            k = mr_add(k, mr_mul(mr_sub(mr_pt(a == b ? 1.0 : 0.0), yj), dB[b]));
        }
        K[a][0] = mr_lo(k);
        K[a][1] = mr_hi(k);
        if (!isfinite(K[a][0]) || !isfinite(K[a][1])) return false;
    }
    return true;
}

/* Whether ||I - Y J||_inf < 1, rounding included: then every matrix in J
 * is regular, so G is one-to-one on the slopes' box (G(a) - G(b) = M (a - b)
 * with M, the mean of G' along the segment, inside J). The early test
 * before Newton's iteration: K(B, y) inside B with J over the slopes' box
 * proves as much (|I - Y J| rho < rho for B's radii rho > 0: |I - Y J|'s
 * spectral radius is below 1), so the proof rests on both. */
static bool contracts(mr J[2][2], double Y[2][2])
{
    for (int a = 0; a < 2; a++) {
        double row = 0.0;
        for (int b = 0; b < 2; b++) {
            mr yj = mr_add(mr_scale(J[0][b], Y[a][0]), mr_scale(J[1][b], Y[a][1]));
            mr e = mr_sub(mr_pt(a == b ? 1.0 : 0.0), yj);
            row = fp_add_up(row, fp_add_up(fabs(e.m), e.r));
        }
        if (!(row < 1.0)) return false;
    }
    return true;
}

static bool box_inside(double K[2][2], double X[2][2])
{
    return K[0][0] > X[0][0] && K[0][1] < X[0][1] && K[1][0] > X[1][0] && K[1][1] < X[1][1];
}

/* Newton's iteration on F(u, v, t) = P - (o + t d) inside B (u, v) x T
 * from x: on true, sp is the surface at x[0..1], whose step s to the
 * root moves the point by at most PROVE_SETTLED of the cell (w), and
 * x[2] the ray parameter after that step */
static bool newton(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                   const double B[2][2], ia_interval T, const double w[2], double x[3],
                   double s[3], trace_surface_point *sp)
{
    ia_interval R[3] = {ia_make(B[0][0], B[0][1]), ia_make(B[1][0], B[1][1]), T};
    trace_surface_point_eval(th, obj, x[0], x[1], sp);
    x[2] = clampd(v3_dot(v3_sub(sp->P, ray->o), ray->d) / v3_dot(ray->d, ray->d), T);
    for (int it = 0; it < PROVE_NEWTON_STEPS; it++) {
        vec3 f = v3_sub(sp->P, trace_ray_at(ray, x[2]));
        if (!v3_is_finite(sp->P) || !trace_newton_step(sp->Pu, sp->Pv, ray->d, f, s) ||
            !isfinite(s[2]))
            return false;
        double nx[3];
        for (int i = 0; i < 3; i++) nx[i] = clampd(x[i] + s[i], R[i]);
        bool done = fabs(nx[0] - x[0]) <= PROVE_SETTLED * w[0] &&
                    fabs(nx[1] - x[1]) <= PROVE_SETTLED * w[1];
        if (done) {
            for (int i = 0; i < 3; i++) s[i] = nx[i] - x[i];
            x[2] = nx[2];
            return true;
        }
        x[2] = nx[2];
        x[0] = nx[0];
        x[1] = nx[1];
        trace_surface_point_eval(th, obj, x[0], x[1], sp);
    }
    return false;
}

/* The settled step s taken to first order: the point and its (u, v) */
static void settle(trace_surface_point *sp, const double s[3])
{
    sp->P = v3_add(sp->P, v3_add(v3_scale(sp->Pu, s[0]), v3_scale(sp->Pv, s[1])));
    sp->u += s[0];
    sp->v += s[1];
}

trace_proof trace_prove_hit(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                            const double r[4], double tmin, double tmax, trace_zero *zero,
                            double *t_out, trace_surface_point *sp, trace_proof_detail *why)
{
    th->stats.proofs++;
    why->spread = INFINITY;
    why->fold = false;
    /* an instance sharing its prototype's boxes (trace/instance.c): the
     * test runs on the prototype, the ray moved rigidly into its camera
     * space (t is kept), and the hit's point is the instance's */
    const trace_object *inst = obj;
    trace_ray moved;
    if (obj->box_proto) {
        moved = *ray;
        moved.o = mat4_xform_point(&obj->to_proto, ray->o);
        moved.d = mat4_xform_vector(&obj->to_proto, ray->d);
        ray = &moved;
        obj = obj->box_proto;
    }
    ray_planes rp;
    if (!planes_of(ray, &rp)) return TRACE_PROOF_UNKNOWN;
    const slope_entry *e = cell_slopes(th, obj, r);
    if (!e) return TRACE_PROOF_UNKNOWN;

    /* G at the cell's centre c, G's Jacobian over the slopes' box X, Y =
     * inverse of its midpoint (any real matrix serves), then
     * K = c - Y G(c) + (I - Y J) (X - c) */
    int ax[2] = {rp.i, rp.j};
    mr G[2], J[2][2];
    for (int a = 0; a < 2; a++) {
        G[a] = plane_g(&rp, ax[a], e->Pc, true);
        J[a][0] = plane_g(&rp, ax[a], e->Pu, false);
        J[a][1] = plane_g(&rp, ax[a], e->Pv, false);
    }
    mr detJ = mr_sub(mr_mul(J[0][0], J[1][1]), mr_mul(J[0][1], J[1][0]));
    why->fold = !(fabs(detJ.m) > detJ.r);
    double det = J[0][0].m * J[1][1].m - J[0][1].m * J[1][0].m;
    if (!(fabs(det) > 0) || !isfinite(det)) return TRACE_PROOF_UNKNOWN;
    double Y[2][2] = {{J[1][1].m / det, -J[0][1].m / det}, {-J[1][0].m / det, J[0][0].m / det}};
    if (!isfinite(Y[0][0]) || !isfinite(Y[0][1]) || !isfinite(Y[1][0]) || !isfinite(Y[1][1]))
        return TRACE_PROOF_UNKNOWN;
    double c[2] = {0.5 * (r[0] + r[1]), 0.5 * (r[2] + r[3])};
    double X[2][2] = {{e->X[0], e->X[1]}, {e->X[2], e->X[3]}};
    double cell[2][2] = {{r[0], r[1]}, {r[2], r[3]}};
    double w[2] = {r[1] - r[0], r[3] - r[2]};
    double K[2][2];
    if (!krawczyk(G, J, Y, c, X, K)) return TRACE_PROOF_UNKNOWN;
    /* every zero in X lies in K: none in the cell */
    for (int a = 0; a < 2; a++)
        if (K[a][1] < cell[a][0] || K[a][0] > cell[a][1]) {
            th->stats.proven_misses++;
            return TRACE_PROOF_MISS;
        }
    why->spread = fmax((K[0][1] - K[0][0]) / (X[0][1] - X[0][0]),
                   (K[1][1] - K[1][0]) / (X[1][1] - X[1][0]));

    /* One zero in X, in B; the cell's zeros are X's, so the answer is
     * X's zero whether or not it lies in the cell itself. Either K inside
     * X's interior (Krawczyk), or, where I - Y J contracts (G one-to-one
     * on X), a box B about the point y where Newton's iteration from K's
     * centre settled, with K(B, y) inside B's interior: B holds a zero */
    ia_interval T = ia_make(tmin, tmax);
    double x[3], s[3], B[2][2];
    bool unique = box_inside(K, X), placed = false;
    /* a zero this walk has proven lies in X, and X holds one zero at most:
     * the cell has nothing nearer than the best hit */
    if (zero->set && zero->uv[0][0] >= X[0][0] && zero->uv[0][1] <= X[0][1] &&
        zero->uv[1][0] >= X[1][0] && zero->uv[1][1] <= X[1][1] && (unique || contracts(J, Y))) {
        th->stats.proven_misses++;
        return TRACE_PROOF_MISS;
    }
    if (unique) {
        memcpy(B, K, sizeof B);
        if (!t_range(&rp, e->Pc, e->Pu, e->Pv, c, B, &T)) return TRACE_PROOF_UNKNOWN;
        if (T.hi <= tmin || T.lo >= tmax) {
            th->stats.proven_misses++;
            return TRACE_PROOF_MISS;
        }
    }
    geom_cover cover = GEOM_PARTIAL;
    if (unique && T.lo > tmin && T.hi < tmax)
        cover = geom_uv_box_cover(&obj->surf, B[0][0], B[0][1], B[1][0], B[1][1]);
    if (cover == GEOM_PARTIAL) {
        /* undecided: place the zero by Newton's iteration from K's centre
         * and prove a small box B about it (y, its last point) to hold a
         * zero, K(B, y) inside B; it is X's only zero where K was inside
         * X or where I - Y J contracts */
        if (!unique && !contracts(J, Y)) return TRACE_PROOF_UNKNOWN;
        x[0] = clampd(0.5 * (K[0][0] + K[0][1]), ia_make(X[0][0], X[0][1]));
        x[1] = clampd(0.5 * (K[1][0] + K[1][1]), ia_make(X[1][0], X[1][1]));
        if (!isfinite(T.hi)) T.hi = DBL_MAX;
        if (!newton(th, obj, ray, X, T, w, x, s, sp)) return TRACE_PROOF_UNKNOWN;
        placed = true;
        double y[2] = {x[0], x[1]}, Bt[2][2];
        for (int a = 0; a < 2; a++) {
            double rho = 4.0 * fabs(s[a]) + 0x1p-30 * w[a];
            Bt[a][0] = y[a] - rho;
            Bt[a][1] = y[a] + rho;
            if (!(Bt[a][0] > X[a][0] && Bt[a][1] < X[a][1])) {
                /* at the unit square's edge: the base surface's edge */
                why->fold = X[a][0] == 0.0 || X[a][1] == 1.0;
                return TRACE_PROOF_UNKNOWN;
            }
        }
        ia_interval Pi[3];
        if (!trace_surface_slopes(th, obj, y[0], y[0], y[1], y[1], Pi, NULL, NULL))
            return TRACE_PROOF_UNKNOWN;
        mr Py[3] = {mr_of(Pi[0]), mr_of(Pi[1]), mr_of(Pi[2])}, Gy[2];
        for (int a = 0; a < 2; a++) Gy[a] = plane_g(&rp, ax[a], Py, true);
        if (!krawczyk(Gy, J, Y, y, Bt, B) || !box_inside(B, Bt)) return TRACE_PROOF_UNKNOWN;
        if (!t_range(&rp, Py, e->Pu, e->Pv, y, B, &T)) return TRACE_PROOF_UNKNOWN;
        /* outside (tmin, tmax), or a tie with the hit found so far: T is
         * a few roundings wide, so nothing nearer is lost */
        if (T.hi <= tmin || T.hi >= tmax) {
            th->stats.proven_misses++;
            return TRACE_PROOF_MISS;
        }
        if (!(T.lo > tmin)) return TRACE_PROOF_UNKNOWN;
        cover = geom_uv_box_cover(&obj->surf, B[0][0], B[0][1], B[1][0], B[1][1]);
    }
    /* a hit only on the base surface's domain */
    if (cover == GEOM_OUTSIDE) {
        th->stats.proven_misses++;
        return TRACE_PROOF_MISS;
    }
    if (cover != GEOM_INSIDE) {
        why->fold = true;            /* the zero on the base surface's edge */
        return TRACE_PROOF_UNKNOWN;
    }

    /* Newton's iteration inside B x T, from B's centre: the hit point to
     * rounding, and its shading point */
    if (placed) {
        settle(sp, s);
        x[2] = clampd(x[2], T);
    } else {
        x[0] = mid(ia_make(B[0][0], B[0][1]));
        x[1] = mid(ia_make(B[1][0], B[1][1]));
        x[2] = mid(T);
        if (newton(th, obj, ray, B, T, w, x, s, sp)) settle(sp, s);
    }
    if (inst != obj) trace_surface_point_move(inst, sp);
    zero->set = true;
    memcpy(zero->uv, B, sizeof zero->uv);
    th->stats.proven_hits++;
    *t_out = x[2];
    return TRACE_PROOF_HIT;
}
