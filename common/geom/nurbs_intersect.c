/*
 * nurbs_intersect.c: the exact ray intersection of one rational Bezier
 * piece of a NuPatch (GEOM_NURBS, geom/nurbs.h), for pieces without
 * displacement.
 *
 * In the ray's frame (two unit normals n1, n2 of the direction d, and d
 * itself) the homogeneous net becomes the four scalar nets
 *
 *     F1 = n1 . (Hw.xyz - o w),  F2 = n2 . (Hw.xyz - o w),
 *     T  = d . (Hw.xyz - o w) / |d|^2,  w
 *
 * (a linear map, so it commutes with de Casteljau subdivision). The ray
 * meets the surface where F1 = F2 = 0 (w > 0), at t = T / w. A sub-patch
 * is pruned when all its F1 (or F2) coefficients have one sign, or when
 * T / w of all its points (the hull of its projected points holds the
 * surface, so t lies in their range) misses [tmin, best]: Bezier clipping's
 * test (Nishita, Sederberg & Kakimoto 1990) without the clipping. Where
 * the Jacobian F1u F2v - F1v F2u keeps one sign (bounded from the
 * hodograph coefficients' ranges; at a hit it is w^2 times Ng . d up to the
 * sign) the sub-patch holds at most one hit. From side 1/8 (1/32 where it
 * may hold two) Newton's method on o + t d = P(u,v) from the centre, as for
 * bicubic patches (surface_bicubic.c), down to side 2^-16.
 */
#include "geom/nurbs_internal.h"
#include "geom/surface_internal.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { STACK = GEOM_PATCH_STACK };

/* Splits the k points p[0], p[s], .. p[(k-1)s] (4 numbers each) at 1/2
 * into a and b (same stride). */
static void split(const double *p, int k, int s, double *a, double *b)
{
    double tmp[GEOM_NURBS_MAX_ORDER][4];
    for (int i = 0; i < k; i++)
        memcpy(tmp[i], p + 4 * i * s, sizeof tmp[i]);
    for (int r = 0; r < k; r++) {
        memcpy(a + 4 * r * s, tmp[0], sizeof tmp[0]);
        memcpy(b + 4 * (k - 1 - r) * s, tmp[k - 1 - r], sizeof tmp[0]);
        for (int i = 0; i < k - 1 - r; i++)
            for (int c = 0; c < 4; c++)
                tmp[i][c] = 0.5 * (tmp[i][c] + tmp[i + 1][c]);
    }
}

/* The quarters of net n (ku x kv points, u fastest) into out[0..3]
 * ((u, v) halves: 0 = low u low v, 1 = high u, 2 = high v, 3 = both). */
static void split_net(const double *n, int ku, int kv, double *half, double **out)
{
    size_t sz = 4 * (size_t)ku * kv;
    for (int j = 0; j < kv; j++)      /* along u: half[0], half[1] */
        split(n + 4 * j * ku, ku, 1, half + 4 * j * ku, half + sz + 4 * j * ku);
    for (int h = 0; h < 2; h++)
        for (int i = 0; i < ku; i++)  /* along v */
            split(half + h * sz + 4 * i, kv, ku, out[h] + 4 * i, out[2 + h] + 4 * i);
}

/* Whether all of F (component c of the net) is above eps or below -eps. */
static bool one_sign(const double *n, int count, int c, double eps)
{
    bool pos = true, neg = true;
    for (int i = 0; i < count && (pos || neg); i++) {
        pos = pos && n[4 * i + c] > eps;
        neg = neg && n[4 * i + c] < -eps;
    }
    return pos || neg;
}

/* Ranges of the differences of component c along u and along v. */
static void diffs(const double *n, int ku, int kv, int c, double du[2], double dv[2])
{
    du[0] = dv[0] = INFINITY, du[1] = dv[1] = -INFINITY;
    for (int j = 0; j < kv; j++)
        for (int i = 0; i < ku; i++) {
            const double *p = n + 4 * (j * ku + i);
            if (i + 1 < ku) {
                double x = p[4 + c] - p[c];
                du[0] = fmin(du[0], x), du[1] = fmax(du[1], x);
            }
            if (j + 1 < kv) {
                double x = p[4 * ku + c] - p[c];
                dv[0] = fmin(dv[0], x), dv[1] = fmax(dv[1], x);
            }
        }
}

/* The Jacobian F1u F2v - F1v F2u keeps one sign over the sub-patch: each
 * derivative lies in (degree times) the range of its hodograph's
 * coefficients, and the products' ranges are interval products. */
static bool transversal(const double *n, int ku, int kv)
{
    if (ku < 2 || kv < 2)
        return false;
    double a[2], b[2], c[2], d[2];          /* F1u, F1v, F2u, F2v */
    diffs(n, ku, kv, 0, a, b);
    diffs(n, ku, kv, 1, c, d);
    double p[4] = { a[0] * d[0], a[0] * d[1], a[1] * d[0], a[1] * d[1] };
    double q[4] = { b[0] * c[0], b[0] * c[1], b[1] * c[0], b[1] * c[1] };
    double plo = fmin(fmin(p[0], p[1]), fmin(p[2], p[3]));
    double phi = fmax(fmax(p[0], p[1]), fmax(p[2], p[3]));
    double qlo = fmin(fmin(q[0], q[1]), fmin(q[2], q[3]));
    double qhi = fmax(fmax(q[0], q[1]), fmax(q[2], q[3]));
    double lo = plo - qhi, hi = phi - qlo, tiny = 1e-9 * (fabs(lo) + fabs(hi));
    return lo > tiny || hi < -tiny;
}

/* The walk's view of the nets (geom_patch_walk): STACK nets of sz
 * numbers in mem, then a work area of two and four quarter slots. */
typedef struct nurbs_walk {
    double *mem;
    size_t sz;
    int ku, kv, count;
    double eps, wmin;
} nurbs_walk;

/* Pruned where F1 or F2 keeps one sign; else the range of T / w. */
static bool nurbs_clip(void *user, int k, double tmin, double best, double *t0_out,
                       double *t1_out)
{
    nurbs_walk *nw = user;
    const double *net = nw->mem + nw->sz * (size_t)k;
    if (one_sign(net, nw->count, 0, nw->eps) || one_sign(net, nw->count, 1, nw->eps))
        return false;
    double t0 = INFINITY, t1 = -INFINITY;
    for (int i = 0; i < nw->count; i++) {
        double t = net[4 * i + 2] / net[4 * i + 3];
        t0 = fmin(t0, t), t1 = fmax(t1, t);
    }
    double tpad = 1e-12 * (fabs(t0) + fabs(t1)) + nw->eps / nw->wmin;
    t0 = fmax(t0 - tpad, tmin), t1 = fmin(t1 + tpad, best);
    *t0_out = t0, *t1_out = t1;
    return t0 <= t1;
}

static bool nurbs_transversal(void *user, int k)
{
    nurbs_walk *nw = user;
    return transversal(nw->mem + nw->sz * (size_t)k, nw->ku, nw->kv);
}

static void nurbs_split(void *user, int k)
{
    nurbs_walk *nw = user;
    size_t sz = nw->sz;
    double *half = nw->mem + sz * STACK, *quarter = half + 2 * sz;
    double *q[4] = { quarter, quarter + sz, quarter + 2 * sz, quarter + 3 * sz };
    split_net(nw->mem + sz * (size_t)k, nw->ku, nw->kv, half, q);
    for (int i = 3; i >= 0; i--)     /* quarter 0 on top */
        memcpy(nw->mem + sz * (size_t)(k + 3 - i), q[i], sizeof(double) * sz);
}

bool geom_nurbs_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                          geom_hit *hit)
{
    const geom_nurbs_piece *pc = &s->nurbs->pieces[s->nurbs_piece];
    int ku = pc->ku, kv = pc->kv, count = ku * kv;
    double dd = v3_dot(d, d);
    if (!(dd > 0) || !isfinite(dd))
        return false;
    /* the ray's frame: n1, n2 unit and normal to d */
    vec3 dn = v3_scale(d, 1 / sqrt(dd));
    vec3 axis = fabs(dn.x) < 0.6 ? v3(1, 0, 0) : (fabs(dn.y) < 0.6 ? v3(0, 1, 0) : v3(0, 0, 1));
    vec3 n1 = v3_cross(dn, axis);
    n1 = v3_scale(n1, 1 / v3_length(n1));
    vec3 n2 = v3_cross(dn, n1);
    vec3 lo, hi;
    geom_nurbs_bounds(s, &lo, &hi);
    double scale = v3_length(v3_sub(hi, lo)) + v3_length(o) + 1e-300;
    size_t sz = 4 * (size_t)count;
    /* the nets of the stack, a work area and four quarter slots */
    nurbs_walk nw = { xmalloc(sizeof(double) * sz * (STACK + 2 + 4)), sz, ku, kv, count,
                      1e-12 * scale * pc->wmax, pc->wmin };
    double *root = nw.mem;
    for (int k = 0; k < count; k++) {
        const double *h = pc->H + 4 * k;
        vec3 q = v3_sub(v3(h[0], h[1], h[2]), v3_scale(o, h[3]));
        root[4 * k + 0] = v3_dot(n1, q);
        root[4 * k + 1] = v3_dot(n2, q);
        root[4 * k + 2] = v3_dot(d, q) / dd;
        root[4 * k + 3] = h[3];
    }
    geom_patch_walk w = { s, geom_nurbs_eval_dual, scale, nurbs_clip, nurbs_transversal,
                          nurbs_split, true, &nw };
    bool found = geom_patch_intersect(&w, o, d, tmin, tmax, hit);
    free(nw.mem);
    return found;
}
