/*
 * prove.c: the Krawczyk test of a quadtree cell against a ray, and the
 * Newton iteration that places a proven hit (see prove.h).
 *
 * With x = (u, v, t), X the cell's box in those three, x~ a point of X,
 * J(X) an interval matrix enclosing the Jacobian of F over X and Y any
 * real matrix (here the inverse of J's midpoint), the Krawczyk operator
 *
 *     K(X) = x~ - Y F(x~) + (I - Y J(X)) (X - x~)
 *
 * contains every zero of F in X. Hence K(X) disjoint from X proves that X
 * holds no zero, and K(X) inside the interior of X proves that it holds
 * exactly one (Krawczyk 1969; Neumaier 1990, Theorem 5.1.8; the operator
 * needs only slope bounds, so a function that is merely Lipschitz, as
 * min, max and clamp make it, is covered). Here J(X) = [P_u | P_v | -d],
 * the first two columns from trace_surface_slopes over the cell, the last
 * exact; F(x~) encloses P at the cell's centre minus o + t~ d. Every
 * operation is an outward-rounded interval operation (common/aa).
 */
#include "trace/prove.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "aa/interval.h"

/* Newton steps after a proof: quadratic convergence from inside the
 * proof's box, which is already a fraction of a pixel wide */
#define PROVE_NEWTON_STEPS 4

/* What a proof needs of a cell, computed once per cell and kept in a
 * direct-mapped per-thread cache (a pure function of object and cell, so
 * what it holds never changes an answer; fixed size, so memory stays flat):
 * the slope bounds over the cell and the enclosure of P at its centre. */
enum { SLOPE_CACHE_ENTRIES = 2048 };
typedef struct slope_entry {
    double r[4];                    /* the cell; r[0] > r[1]: empty */
    int obj;
    bool ok;                        /* the slopes are known */
    ia_interval Pu[3], Pv[3], Pc[3];
} slope_entry;
struct trace_slope_cache { slope_entry e[SLOPE_CACHE_ENTRIES]; };

static uint64_t bits_of(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static const slope_entry *cell_slopes(trace_thread *th, const trace_object *obj,
                                      const double r[4])
{
    if (!th->slopes) {
        th->slopes = malloc(sizeof *th->slopes);
        if (!th->slopes) abort();
        for (int i = 0; i < SLOPE_CACHE_ENTRIES; i++) {
            th->slopes->e[i].r[0] = 1.0;
            th->slopes->e[i].r[1] = 0.0;
        }
    }
    uint64_t h = bits_of(r[0]) * 0x9e3779b97f4a7c15ull ^ bits_of(r[2]) * 0xbf58476d1ce4e5b9ull ^
                 bits_of(r[1] - r[0]) * 0x94d049bb133111ebull ^ (uint64_t)obj->id;
    h ^= h >> 29;
    slope_entry *e = &th->slopes->e[(h * 0x9e3779b97f4a7c15ull) >> 53 & (SLOPE_CACHE_ENTRIES - 1)];
    if (e->obj == obj->id && e->r[0] == r[0] && e->r[1] == r[1] && e->r[2] == r[2] &&
        e->r[3] == r[3])
        return e->ok ? e : NULL;
    ia_interval P[3], cu[3], cv[3];
    double uc = 0.5 * (r[0] + r[1]), vc = 0.5 * (r[2] + r[3]);
    e->ok = trace_surface_slopes(th, obj, r[0], r[1], r[2], r[3], P, e->Pu, e->Pv) &&
            trace_surface_slopes(th, obj, uc, uc, vc, vc, e->Pc, cu, cv);
    if (th->failed) {                   /* a failed run: nothing to keep */
        e->r[0] = 1.0;
        e->r[1] = 0.0;
        return NULL;
    }
    memcpy(e->r, r, sizeof e->r);
    e->obj = obj->id;
    return e->ok ? e : NULL;
}

bool trace_prove_eligible(const trace_object *obj)
{
    return obj->displacement && !obj->box_proto && trace_surface_flat(obj);
}

static double mid(ia_interval x) { return 0.5 * x.lo + 0.5 * x.hi; }

/* Solves [Pu | Pv | -d] s = -f for the Newton step s (Cramer's rule on
 * the float matrix); false when singular. */
static bool newton_step(vec3 Pu, vec3 Pv, vec3 d, vec3 f, double s[3])
{
    vec3 nd = v3_neg(d);
    double det = v3_dot(Pu, v3_cross(Pv, nd));
    if (!(fabs(det) > 0) || !isfinite(det)) return false;
    vec3 rhs = v3_neg(f);
    s[0] = v3_dot(rhs, v3_cross(Pv, nd)) / det;
    s[1] = v3_dot(Pu, v3_cross(rhs, nd)) / det;
    s[2] = v3_dot(Pu, v3_cross(Pv, rhs)) / det;
    return isfinite(s[0]) && isfinite(s[1]) && isfinite(s[2]);
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
 * or, with o = NULL, of a derivative */
static ia_interval plane_g(const ray_planes *rp, int a, const ia_interval P[3], bool point)
{
    ia_interval xa = P[a], xk = P[rp->k];
    if (point) {
        xa = ia_sub(xa, ia_point(rp->o[a]));
        xk = ia_sub(xk, ia_point(rp->o[rp->k]));
    }
    return ia_sub(ia_mul_s(xa, rp->d[rp->k]), ia_mul_s(xk, rp->d[a]));
}

trace_proof trace_prove_hit(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                            const double r[4], double tmin, double tmax,
                            double *t_out, trace_surface_point *sp, double *spread)
{
    th->stats.proofs++;
    *spread = INFINITY;
    ray_planes rp;
    if (!planes_of(ray, &rp)) return TRACE_PROOF_UNKNOWN;
    const slope_entry *e = cell_slopes(th, obj, r);
    if (!e) return TRACE_PROOF_UNKNOWN;
    double uc = 0.5 * (r[0] + r[1]), vc = 0.5 * (r[2] + r[3]);

    /* G at the centre, G's Jacobian over the cell, Y = inverse of its
     * midpoint (any real matrix serves), then K = c - Y G(c) + (I - Y J) (X - c) */
    int ax[2] = {rp.i, rp.j};
    ia_interval G[2], J[2][2];
    for (int a = 0; a < 2; a++) {
        G[a] = plane_g(&rp, ax[a], e->Pc, true);
        J[a][0] = plane_g(&rp, ax[a], e->Pu, false);
        J[a][1] = plane_g(&rp, ax[a], e->Pv, false);
    }
    double m00 = mid(J[0][0]), m01 = mid(J[0][1]), m10 = mid(J[1][0]), m11 = mid(J[1][1]);
    double det = m00 * m11 - m01 * m10;
    if (!(fabs(det) > 0) || !isfinite(det)) return TRACE_PROOF_UNKNOWN;
    double y[2][2] = {{m11 / det, -m01 / det}, {-m10 / det, m00 / det}};
    if (!isfinite(y[0][0]) || !isfinite(y[0][1]) || !isfinite(y[1][0]) || !isfinite(y[1][1]))
        return TRACE_PROOF_UNKNOWN;
    ia_interval X[2] = {ia_make(r[0], r[1]), ia_make(r[2], r[3])};
    double c[2] = {uc, vc};
    ia_interval dX[2] = {ia_sub(X[0], ia_point(uc)), ia_sub(X[1], ia_point(vc))};
    ia_interval K[2];
    bool inside = true;
    for (int a = 0; a < 2; a++) {
        ia_interval k = ia_sub(ia_point(c[a]),
                               ia_add(ia_mul_s(G[0], y[a][0]), ia_mul_s(G[1], y[a][1])));
        for (int b = 0; b < 2; b++) {
            ia_interval yj = ia_add(ia_mul_s(J[0][b], y[a][0]), ia_mul_s(J[1][b], y[a][1]));
            k = ia_add(k, ia_mul(ia_sub(ia_point(a == b ? 1.0 : 0.0), yj), dX[b]));
        }
        if (!(k.lo <= k.hi)) return TRACE_PROOF_UNKNOWN;      /* NaN: no verdict */
        if (k.hi < X[a].lo || k.lo > X[a].hi) {
            th->stats.proven_misses++;
            return TRACE_PROOF_MISS;
        }
        inside = inside && k.lo > X[a].lo && k.hi < X[a].hi;
        K[a] = k;
    }
    *spread = fmax((K[0].hi - K[0].lo) / (r[1] - r[0]), (K[1].hi - K[1].lo) / (r[3] - r[2]));
    if (!inside) return TRACE_PROOF_UNKNOWN;

    /* The ray's line meets the surface over the cell exactly once, at a
     * (u, v) in K; there P lies in Pc + Pu (K_u - uc) + Pv (K_v - vc)
     * (mean value theorem, slopes over the cell), so t = (P - o) . d / d.d
     * in T. A hit only inside (tmin, tmax) and on the base surface's domain. */
    ia_interval ku = ia_sub(K[0], ia_point(uc)), kv = ia_sub(K[1], ia_point(vc));
    ia_interval num = ia_point(0.0), dd = ia_point(0.0);
    for (int a = 0; a < 3; a++) {
        ia_interval p = ia_add(e->Pc[a], ia_add(ia_mul(e->Pu[a], ku), ia_mul(e->Pv[a], kv)));
        num = ia_add(num, ia_mul_s(ia_sub(p, ia_point(rp.o[a])), rp.d[a]));
        dd = ia_add(dd, ia_mul(ia_point(rp.d[a]), ia_point(rp.d[a])));
    }
    ia_interval T = ia_div(num, dd);
    if (T.hi <= tmin || T.lo >= tmax) {
        th->stats.proven_misses++;
        return TRACE_PROOF_MISS;
    }
    if (!(T.lo > tmin && T.hi < tmax)) return TRACE_PROOF_UNKNOWN;
    geom_cover cover = geom_uv_box_cover(&obj->surf, K[0].lo, K[0].hi, K[1].lo, K[1].hi);
    if (cover == GEOM_OUTSIDE) {
        th->stats.proven_misses++;
        return TRACE_PROOF_MISS;
    }
    if (cover != GEOM_INSIDE) return TRACE_PROOF_UNKNOWN;

    /* Newton's iteration on F(u, v, t) = P - (o + t d), inside K x T, from
     * K's centre: the hit point to rounding, and its shading point */
    ia_interval B[3] = {K[0], K[1], T};
    double x[3] = {mid(K[0]), mid(K[1]), mid(T)};
    trace_surface_point_eval(th, obj, x[0], x[1], sp);
    x[2] = clampd(v3_dot(v3_sub(sp->P, ray->o), ray->d) / v3_dot(ray->d, ray->d), T);
    for (int it = 0; it < PROVE_NEWTON_STEPS; it++) {
        vec3 f = v3_sub(sp->P, trace_ray_at(ray, x[2]));
        double s[3];
        if (!v3_is_finite(sp->P) || !newton_step(sp->Pu, sp->Pv, ray->d, f, s)) break;
        double nx[3];
        for (int i = 0; i < 3; i++) nx[i] = clampd(x[i] + s[i], B[i]);
        /* converged: the step moves the point by less than 2^-20 of the
         * cell, far below anything a pixel shows */
        bool done = fabs(nx[0] - x[0]) <= 0x1p-20 * (r[1] - r[0]) &&
                    fabs(nx[1] - x[1]) <= 0x1p-20 * (r[3] - r[2]);
        x[2] = nx[2];
        if (done) break;
        x[0] = nx[0];
        x[1] = nx[1];
        trace_surface_point_eval(th, obj, x[0], x[1], sp);
    }
    th->stats.proven_hits++;
    *t_out = x[2];
    return TRACE_PROOF_HIT;
}
