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

enum { MIN_DEPTH_TRANSVERSAL = 3, MIN_DEPTH = 5, MAX_DEPTH = 16,
       STACK = 3 * MAX_DEPTH + 8 };

typedef struct node { double u0, v0; int depth; } node;

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
    double eps = 1e-12 * scale * pc->wmax;
    size_t sz = 4 * (size_t)count;
    /* the nets of the stack, a work area and four quarter slots */
    double *mem = xmalloc(sizeof(double) * sz * (STACK + 2 + 4));
    node stack[STACK];
    double *root = mem;
    for (int k = 0; k < count; k++) {
        const double *h = pc->H + 4 * k;
        vec3 q = v3_sub(v3(h[0], h[1], h[2]), v3_scale(o, h[3]));
        root[4 * k + 0] = v3_dot(n1, q);
        root[4 * k + 1] = v3_dot(n2, q);
        root[4 * k + 2] = v3_dot(d, q) / dd;
        root[4 * k + 3] = h[3];
    }
    stack[0] = (node){ 0, 0, 0 };
    int n = 1;
    double *half = mem + sz * STACK, *quarter = half + 2 * sz;
    double best = tmax;
    bool found = false;
    while (n > 0) {
        node cur = stack[--n];
        double *net = mem + sz * (size_t)n;
        double side = ldexp(1, -cur.depth), u0 = cur.u0, v0 = cur.v0;
        if (one_sign(net, count, 0, eps) || one_sign(net, count, 1, eps))
            continue;
        double t0 = INFINITY, t1 = -INFINITY;
        for (int k = 0; k < count; k++) {
            double t = net[4 * k + 2] / net[4 * k + 3];
            t0 = fmin(t0, t), t1 = fmax(t1, t);
        }
        double tpad = 1e-12 * (fabs(t0) + fabs(t1)) + eps / pc->wmin;
        t0 = fmax(t0 - tpad, tmin), t1 = fmin(t1 + tpad, best);
        if (!(t0 <= t1))
            continue;
        bool across = transversal(net, ku, kv);
        if (cur.depth >= (across ? MIN_DEPTH_TRANSVERSAL : MIN_DEPTH)) {
            double u = u0 + side / 2, v = v0 + side / 2;
            geom_sample c;
            geom_nurbs_eval_dual(s, u, v, &c);
            double t = v3_dot(v3_sub(c.P, o), d) / dd;
            double slack = 1e-9;
            bool inside = geom_patch_newton(s, geom_nurbs_eval_dual, o, d, &t, &u, &v, scale) &&
                          u >= u0 - slack && u <= u0 + side + slack && v >= v0 - slack &&
                          v <= v0 + side + slack && t >= t0 && t <= t1;
            if (inside && t > tmin + 1e-9 * fabs(tmin) && t < best) {
                best = t;
                hit->t = t;
                hit->u = fmin(fmax(u, 0), 1);
                hit->v = fmin(fmax(v, 0), 1);
                found = true;
            }
            if ((inside && across) || cur.depth >= MAX_DEPTH)
                continue;
        }
        if (n + 4 > STACK)
            continue;
        double *q[4] = { quarter, quarter + sz, quarter + 2 * sz, quarter + 3 * sz };
        split_net(net, ku, kv, half, q);
        double h = side / 2;
        for (int k = 3; k >= 0; k--) {     /* quarter 0 on top */
            memcpy(mem + sz * (size_t)n, q[k], sizeof(double) * sz);
            stack[n++] = (node){ u0 + (k & 1) * h, v0 + (k >> 1) * h, cur.depth + 1 };
        }
    }
    free(mem);
    return found;
}
