/*
 * subdiv_eval.c: the GEOM_SUBDIV surface of one face, in the four
 * arithmetics, its bounds and its ray intersection.
 *
 * A point (u,v) of face f: the face's 1-ring is copied into a local mesh;
 * while the face is not regular (subdiv_regular.c) it is refined locally
 * and the quadrant holding (u,v) becomes the face (u' = 2u or 2u - 1), so
 * the point ends in a regular sub-patch at some level d, evaluated as its
 * bicubic Bezier patch (surface_bicubic.c) with dP/du scaled by 2^d. A point
 * exactly on a sub-face corner that stays irregular for 3 more levels (an
 * extraordinary or tagged point) gets the limit mask of that corner
 * (sd_corner_limit) and the derivatives of a point 2^-30 inside the face.
 * After 48 levels (a point within 2^-48 of an irregular corner) the
 * sub-face's corner point stands for the limit.
 *
 * A (u,v) box: the same descent while the box lies in one quadrant; a
 * regular sub-patch gives the bicubic enclosure (interval or affine, in
 * the face's own u and v: u' = 2^d u - offset is affine, so the forms keep
 * their correlation). A box that covers an irregular sub-face whole is
 * bounded by the convex hull of that sub-face's 1-ring (Catmull-Clark
 * masks are non-negative, so the limit surface lies in the hull of the
 * points that define it), widened by 1e-12 of its size for the rounding of
 * the refinement, with unbounded derivatives (near an extraordinary point
 * dP/du may grow without bound and the normal is not bounded there:
 * geom_unit_normal_* then give the cube [-1,1]^3).
 */
#include "geom/subdiv_local.h"
#include "geom/surface_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

void sd_local_init(sd_local *L, int maxval)
{
    assert(maxval >= 4);
    size_t lf = (size_t)sd_lf(maxval), lc = (size_t)sd_lc(maxval), lv = (size_t)sd_lv(maxval);
    *L = (sd_local){ .maxval = maxval };
    /* one block (a 1-ring is made for every face's surface) */
    char *b = xmalloc(lv * sizeof(vec3) + (lv + lc) * sizeof(double) +
                      (lf + 1 + lc + lf + lv) * sizeof(int));
    L->P = (vec3 *)b;
    L->vs = (double *)(L->P + lv);
    L->es = L->vs + lv;
    L->fo = (int *)(L->es + lc);
    L->fv = L->fo + lf + 1;
    L->list = L->fv + lc;
    L->src = L->list + lf;
}

void sd_local_clear(sd_local *L)
{
    free(L->P);
    *L = (sd_local){ 0 };
}

void sd_big_init(sd_big *big, int maxval)
{
    int lf = sd_lf(maxval), lc = sd_lc(maxval), lv = sd_lv(maxval);
    int bv = lv + lf + lc, bf = lc, bc = 4 * lc;
    *big = (sd_big){ { 0 }, xmalloc((size_t)bv * sizeof(vec3)), xmalloc((size_t)bv * sizeof(double)),
                     xmalloc((size_t)(bf + 1) * sizeof(int)), xmalloc((size_t)bc * sizeof(int)),
                     xmalloc((size_t)bc * sizeof(double)) };
}

void sd_big_clear(sd_big *big)
{
    free(big->P);
    free(big->vs);
    free(big->fo);
    free(big->fv);
    free(big->es);
    *big = (sd_big){ { 0 }, NULL, NULL, NULL, NULL, NULL };
}

void sd_local_take(sd_local *L, const sd_mesh *M, const int *list, int n)
{
    L->m = (sd_mesh){ 0, 0, L->P, L->vs, L->fo, L->fv, L->es };
    int lf = sd_lf(L->maxval), lc = sd_lc(L->maxval);
    (void)lf, (void)lc;   /* without asserts */
    int *src = L->src;
    int nc = 0;
    L->fo[0] = 0;
    assert(n <= lf);
    for (int i = 0; i < n; i++) {
        int f = list[i];
        assert(nc + M->fo[f + 1] - M->fo[f] <= lc);
        for (int c = M->fo[f]; c < M->fo[f + 1]; c++) {
            int v = M->fv[c], j = 0;
            while (j < L->m.nv && src[j] != v) j++;
            if (j == L->m.nv) {
                src[j] = v;
                L->P[j] = M->P[v];
                L->vs[j] = M->vs[v];
                L->m.nv++;
            }
            L->fv[nc] = j;
            L->es[nc] = M->es[c];
            nc++;
        }
        L->fo[++L->m.nf] = nc;
    }
}

static void add_face(int *list, int *n, int cap, int f)
{
    (void)cap;   /* without asserts */
    for (int i = 0; i < *n; i++)
        if (list[i] == f) return;
    assert(*n < cap);   /* a quad's corners have at most 4 maxval faces */
    list[(*n)++] = f;
}

void sd_local_child(sd_local *L, int k, sd_big *big)
{
    big->m = (sd_mesh){ 0, 0, big->P, big->vs, big->fo, big->fv, big->es };
    sd_refine(&L->m, &big->m);
    int child = L->fo[0] + k;                  /* the child of face 0's corner k */
    int cv[4];
    for (int j = 0; j < 4; j++) cv[j] = big->fv[big->fo[child] + j];
    int *list = L->list, n = 0, cap = sd_lf(L->maxval);
    add_face(list, &n, cap, child);
    for (int f = 0; f < big->m.nf; f++)
        for (int c = big->fo[f]; c < big->fo[f + 1]; c++)
            if ((big->fv[c] == cv[0] || big->fv[c] == cv[1] ||
                           big->fv[c] == cv[2] || big->fv[c] == cv[3])) {
                add_face(list, &n, cap, f);
                break;
            }
    sd_local_take(L, &big->m, list, n);
}

static const int QUADRANT[2][2] = { { 0, 3 }, { 1, 2 } };   /* [u >= .5][v >= .5] */

/* a temporary bicubic surface for a net (only kind, nverts, verts used) */
static void net_surface(const vec3 net[16], geom_surface *b)
{
    b->kind = GEOM_BICUBIC;
    b->nverts = 16;
    memcpy(b->verts, net, 16 * sizeof *net);
}

/* ---- float and dual ---- */

/* 0: out filled; 1: (u,v) is an irregular corner: out->P is its limit.
 * point: out->P alone (the same bits; the grid spacing's points) */
static int eval_point(const geom_surface *fs, double u, double v, geom_sample *out, bool point)
{
    const geom_subdiv *sd = fs->subdiv;
    int f = fs->subdiv_face;
    geom_surface b;                    /* fields other than verts unused */
    if (fs->nverts == 16) {            /* a regular face: its net (geom_subdiv_surface) */
        net_surface(fs->verts, &b);
        if (point) out->P = geom_bicubic_eval_point(&b, u, v);
        else geom_bicubic_eval_dual(&b, u, v, out);
        return 0;
    }
    const sd_node *n = sd_node_root(sd, f);
    double s = u, t = v;
    int at_corner = 0;
    for (int d = 0; d <= SD_MAX_LEVEL; d++) {
        const vec3 *net;
        if (sd_node_regular(n, &net)) {
            net_surface(net, &b);
            if (point) {
                out->P = geom_bicubic_eval_point(&b, s, t);
                return 0;
            }
            geom_bicubic_eval_dual(&b, s, t, out);
            double k = ldexp(1, d), k2 = k * k;
            out->dPdu = v3_scale(out->dPdu, k);
            out->dPdv = v3_scale(out->dPdv, k);
            out->Ng = v3_scale(out->Ng, k2);
            out->dNgdu = v3_scale(out->dNgdu, k2 * k);
            out->dNgdv = v3_scale(out->dNgdv, k2 * k);
            return 0;
        }
        bool cu = s == 0 || s == 1, cv = t == 0 || t == 1;
        /* on a corner: descend toward it (an irregularity elsewhere in the
         * sub-face recedes in a level or two); if it stays irregular, the
         * corner itself is, and its limit mask gives the point */
        at_corner = cu && cv ? at_corner + 1 : 0;
        if (at_corner > 3 || d == SD_MAX_LEVEL) {
            sd_local L;
            sd_big big;
            sd_local_init(&L, sd_node_maxval(n));
            sd_big_init(&big, sd_node_maxval(n));
            sd_node_local(n, &L);
            int q = QUADRANT[s >= 0.5][t >= 0.5];
            bool limit = false;
            for (int i = 0; i < 12 && !limit; i++) {
                limit = sd_corner_limit(&L.m, q, &out->P);
                if (!limit) sd_local_child(&L, q, &big);
            }
            if (!limit) out->P = L.P[L.fv[L.fo[0] + q]];
            sd_big_clear(&big);
            sd_local_clear(&L);
            return 1;
        }
        int qu = s >= 0.5, qv = t >= 0.5;
        s = 2 * s - qu;
        t = 2 * t - qv;
        n = sd_node_child(n, QUADRANT[qu][qv]);
    }
    return 1;
}

void geom_subdiv_eval_dual(const geom_surface *s, double u, double v, geom_sample *out)
{
    if (eval_point(s, u, v, out, false) == 1) {
        vec3 P = out->P;
        double e = ldexp(1, -30);
        eval_point(s, u < 0.5 ? u + e : u - e, v < 0.5 ? v + e : v - e, out, false);
        out->P = P;
    }
}

vec3 geom_subdiv_eval_point(const geom_surface *s, double u, double v)
{
    geom_sample g;
    eval_point(s, u, v, &g, true);
    return g.P;
}

/* ---- interval and affine ---- */

typedef struct sd_range {
    bool regular;
    const vec3 *net;               /* regular: its Bezier net (16) */
    const sd_node *node;           /* irregular: the sub-face */
    const sd_node *normal_node;    /* its ancestor at level < SD_SIGN_LEVEL */
    int level;
    double ou, ov;                 /* the sub-face's origin in the face's (u,v) */
    vec3 lo, hi;                   /* else: the hull of its 1-ring */
    double split_u, split_v;       /* irregular, and the box crosses this line
                                    * of the sub-face's quadrants (else NAN) */
} sd_range;

void sd_local_hull(const sd_mesh *m, vec3 *lo, vec3 *hi)
{
    *lo = *hi = m->P[0];
    double big = 0;
    for (int i = 0; i < m->nv; i++) {
        vec3 p = m->P[i];
        /* (geom_min/max: fmin/fmax's bits without the calls) */
        lo->x = geom_min(lo->x, p.x), lo->y = geom_min(lo->y, p.y), lo->z = geom_min(lo->z, p.z);
        hi->x = geom_max(hi->x, p.x), hi->y = geom_max(hi->y, p.y), hi->z = geom_max(hi->z, p.z);
        big = geom_max(big, geom_max(fabs(p.x), geom_max(fabs(p.y), fabs(p.z))));
    }
    double pad = 1e-12 * (big + v3_length(v3_sub(*hi, *lo)));
    *lo = v3_sub(*lo, v3(pad, pad, pad));
    *hi = v3_add(*hi, v3(pad, pad, pad));
}

/* x - o rounded down (dir < 0) or up (dir > 0): exact when the difference
 * is a double (TwoSum gives the rounding error) */
static double sub_dir(double x, double o, int dir)
{
    double d = x - o, bb = d - x;
    double e = (x - (d - bb)) + (-o - bb);
    if (dir < 0 && e < 0) return nextafter(d, -INFINITY);
    if (dir > 0 && e > 0) return nextafter(d, INFINITY);
    return d;
}

/* The sub-face of face f that holds the box [u0,u1] x [v0,v1] whole
 * (found in the face's tree of local refinements, subdiv_cache.c). */
static void find_range(const geom_surface *s, double u0, double u1, double v0, double v1,
                       sd_range *r)
{
    const geom_subdiv *sd = s->subdiv;
    int f = s->subdiv_face;
    r->level = 0;
    r->ou = r->ov = 0;
    r->node = r->normal_node = NULL;
    if (s->nverts == 16) {             /* a regular face: its net (geom_subdiv_surface) */
        r->regular = true;
        r->net = s->verts;
        return;
    }
    const sd_node *n = sd_node_root(sd, f);
    for (int d = 0;; d++) {
        if (d < SD_SIGN_LEVEL) r->normal_node = n;
        if (sd_node_regular(n, &r->net)) {
            r->regular = true;
            return;
        }
        double k = ldexp(1, d);
        /* the box in the sub-face's coordinates, rounded outward (the
         * scaling by 2^d is exact) */
        double s0 = sub_dir(u0, r->ou, -1) * k, s1 = sub_dir(u1, r->ou, 1) * k;
        double t0 = sub_dir(v0, r->ov, -1) * k, t1 = sub_dir(v1, r->ov, 1) * k;
        bool inu = s1 <= 0.5 || s0 >= 0.5, inv = t1 <= 0.5 || t0 >= 0.5;
        if (d == SD_MAX_LEVEL || !inu || !inv) {
            r->regular = false;
            r->node = n;
            sd_node_hull(n, &r->lo, &r->hi);
            /* a box that only crosses a quadrant line (not the whole
             * sub-face) is cut there by the caller */
            bool whole = s0 <= 0 && s1 >= 1 && t0 <= 0 && t1 >= 1;
            r->split_u = r->split_v = NAN;
            if (d < SD_MAX_LEVEL && !whole) {
                if (!inu) r->split_u = r->ou + 0.5 / k;
                if (!inv) r->split_v = r->ov + 0.5 / k;
            }
            return;
        }
        int qu = s0 >= 0.5, qv = t0 >= 0.5;
        r->ou += qu * 0.5 / k;
        r->ov += qv * 0.5 / k;
        r->level = d + 1;
        n = sd_node_child(n, QUADRANT[qu][qv]);
    }
}

/* One de Casteljau level of n + 1 points at t: n points. */
static inline void casteljau(const vec3 *p, int n, double t, vec3 *out)
{
    for (int i = 0; i < n; i++) out[i] = v3_add(v3_scale(p[i], 1 - t), v3_scale(p[i + 1], t));
}

/* The Bezier points of the cubic p[0..3] over [a, b]: the blossoms
 * f(a,a,a), f(a,a,b), f(a,b,b), f(b,b,b) (level l of the de Casteljau
 * scheme at the l-th argument), the levels they share computed once: the
 * same operations on the same values as four separate blossoms, so the
 * same bits, for 16 interpolations instead of 24. */
static void bezier_piece(const vec3 p[4], double a, double b, vec3 out[4])
{
    vec3 qa[3], qb[3], raa[2], rab[2], rbb[2];
    casteljau(p, 3, a, qa);
    casteljau(p, 3, b, qb);
    casteljau(qa, 2, a, raa);
    casteljau(qa, 2, b, rab);
    casteljau(qb, 2, b, rbb);
    casteljau(raa, 1, a, &out[0]);
    casteljau(raa, 1, b, &out[1]);
    casteljau(rab, 1, b, &out[2]);
    casteljau(rbb, 1, b, &out[3]);
}

/* Tighter enclosures of a regular sub-patch over [s0,s1] x [t0,t1] (in
 * [0,1]^2) from its Bezier net there (blossoms; the patch lies in the hull
 * of that net, its u-derivative in the hull of 3 (b_i+1,j - b_ij) /
 * (s1 - s0), likewise in v, so Ng in their cross product): boxes that the
 * enclosures are met with. The tensor-form enclosure of a whole sub-patch
 * is many times wider than its net (near an extraordinary point the
 * renderer's boxes are whole sub-patches). Widened by 1e-12 of the net's
 * size for the rounding of the blossoms; k = 2^level scales to the face. */
typedef struct net_boxes { ia_interval P[3], dPdu[3], dPdv[3], Ng[3]; } net_boxes;

static ia_interval meet_ia_(ia_interval x, ia_interval y)
{
    if (!isfinite(y.lo) || !isfinite(y.hi) || (y.flags & AA_UNBOUNDED)) return x;
    if (!isfinite(x.lo) || !isfinite(x.hi) || (x.flags & AA_UNBOUNDED)) return y;
    if (y.lo > x.lo) x.lo = y.lo;
    if (y.hi < x.hi) x.hi = y.hi;
    return x;
}

static ia_interval pad_iv(double lo, double hi, double pad)
{
    return ia_make(lo - pad, hi + pad);
}

/* The rows of the net over [s0, s1] in u: H[j][i] (net_piece's first
 * half; the pieces of one column of net_bounds share it) */
static void net_rows(const vec3 net[16], double s0, double s1, vec3 H[4][4])
{
    for (int j = 0; j < 4; j++) bezier_piece(net + 4 * j, s0, s1, H[j]);
}

/* The largest coordinate of the net (geom_max: fmax's bits without the
 * calls into libm) */
static double net_big(const vec3 net[16])
{
    double big = 0;
    for (int i = 0; i < 16; i++)
        big = geom_max(big, geom_max(fabs(net[i].x), geom_max(fabs(net[i].y), fabs(net[i].z))));
    return big;
}

/* d/du = k d/ds = k / (s1 - s0) d/dw over a piece [s0, s1] */
static ia_interval slope_scale(double k, double s0, double s1)
{
    return s1 > s0 ? ia_div(ia_point(k), ia_sub(ia_point(s1), ia_point(s0))) : ia_entire();
}

/* What net_piece_of_rows fills: P, or dPdu, dPdv and Ng, or all */
enum { NB_P = 1, NB_D = 2, NB_ALL = 3 };

/* ks, kt: slope_scale of the piece's [s0, s1] and [t0, t1] (by the caller:
 * pieces of one column or row share them) */
static void net_piece_of_rows(double big, const vec3 H[4][4], double s0, double s1, double t0,
                              double t1, ia_interval ks, ia_interval kt, int what,
                              net_boxes *nb)
{
    vec3 B[4][4];                          /* [j][i] */
    for (int i = 0; i < 4; i++) {
        vec3 col[4] = { H[0][i], H[1][i], H[2][i], H[3][i] }, out[4];
        bezier_piece(col, t0, t1, out);
        for (int j = 0; j < 4; j++) B[j][i] = out[j];
    }
    double pad = 1e-12 * big;
    if (what == NB_P) {                    /* P alone (geom_subdiv_range_P_aa) */
        for (int c = 0; c < 3; c++) {
            double lo = INFINITY, hi = -INFINITY;
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) {
                    double x = v3_comp(B[j][i], c);
                    lo = x < lo ? x : lo, hi = x > hi ? x : hi;
                }
            nb->P[c] = pad_iv(lo, hi, pad);
        }
        return;
    }
    for (int c = 0; c < 3; c++) {
        double lo = INFINITY, hi = -INFINITY, ulo = INFINITY, uhi = -INFINITY;
        double vlo = INFINITY, vhi = -INFINITY;
        /* (comparisons, not fmin/fmax: those are calls into libm here,
         * and no value is NaN; a NaN would be skipped alike) */
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                double x = v3_comp(B[j][i], c);
                lo = x < lo ? x : lo, hi = x > hi ? x : hi;
                if (i < 3) {
                    double d = 3 * (v3_comp(B[j][i + 1], c) - x);
                    ulo = d < ulo ? d : ulo, uhi = d > uhi ? d : uhi;
                }
                if (j < 3) {
                    double d = 3 * (v3_comp(B[j + 1][i], c) - x);
                    vlo = d < vlo ? d : vlo, vhi = d > vhi ? d : vhi;
                }
            }
        if (what & NB_P) nb->P[c] = pad_iv(lo, hi, pad);
        nb->dPdu[c] = s1 > s0 ? ia_mul(pad_iv(ulo, uhi, 8 * pad), ks) : ia_entire();
        nb->dPdv[c] = t1 > t0 ? ia_mul(pad_iv(vlo, vhi, 8 * pad), kt) : ia_entire();
    }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        nb->Ng[c] = ia_sub(ia_mul(nb->dPdu[a], nb->dPdv[b]), ia_mul(nb->dPdu[b], nb->dPdv[a]));
    }
}

static void net_piece(const vec3 net[16], double s0, double s1, double t0, double t1,
                      double k, int what, net_boxes *nb)
{
    vec3 H[4][4];
    net_rows(net, s0, s1, H);
    ia_interval ks = ia_entire(), kt = ia_entire();
    if (what & NB_D) ks = slope_scale(k, s0, s1), kt = slope_scale(k, t0, t1);
    net_piece_of_rows(net_big(net), (const vec3(*)[4])H, s0, s1, t0, t1, ks, kt, what, nb);
}

/* The whole box of net_bounds (its clamp to the unit square) */
static void clamp_box(ia_interval su, ia_interval sv, double b[4])
{
    double s0 = geom_max(su.lo, 0), s1 = geom_min(su.hi, 1);
    double t0 = geom_max(sv.lo, 0), t1 = geom_min(sv.hi, 1);
    if (!(s0 <= s1)) s0 = s1 = geom_min(geom_max(su.lo, 0), 1);
    if (!(t0 <= t1)) t0 = t1 = geom_min(geom_max(sv.lo, 0), 1);
    b[0] = s0, b[1] = s1, b[2] = t0, b[3] = t1;
}

/* The whole box, and Ng as the hull over 3 x 3 pieces of it: the cross
 * product of derivative boxes loses the pairing of du and dv at one point,
 * which costs most where the sub-patch is distorted (near extraordinary
 * points); smaller pieces turn less. */
static void net_bounds(const vec3 net[16], ia_interval su, ia_interval sv, double k,
                       net_boxes *nb)
{
    double b[4];
    clamp_box(su, sv, b);
    double s0 = b[0], s1 = b[1], t0 = b[2], t1 = b[3];
    net_piece(net, s0, s1, t0, t1, k, NB_ALL, nb);
    if (!(s1 > s0 && t1 > t0)) return;
    /* not where the whole box's Ng already keeps well away from 0 (|Ng|^2
     * within a factor 1.25): there the pieces narrow it little (on
     * scenes/subdiv.rib 0.6 % fewer boxes, for a third of the time) */
    ia_interval n2 = ia_add(ia_add(ia_sqr(nb->Ng[0]), ia_sqr(nb->Ng[1])), ia_sqr(nb->Ng[2]));
    if (n2.lo > 0.8 * n2.hi) return;
    enum { NP = 3 };
    double big = net_big(net);
    ia_interval Ng[3];
    double a0s[NP], a1s[NP], b0s[NP], b1s[NP];
    ia_interval ks[NP], kt[NP];            /* each column's and row's, once */
    vec3 H[NP][4][4];                      /* each column's rows, once */
    for (int i = 0; i < NP; i++) {
        a0s[i] = s0 + (s1 - s0) * i / NP;
        a1s[i] = i == NP - 1 ? s1 : s0 + (s1 - s0) * (i + 1) / NP;
        b0s[i] = t0 + (t1 - t0) * i / NP;
        b1s[i] = i == NP - 1 ? t1 : t0 + (t1 - t0) * (i + 1) / NP;
        ks[i] = slope_scale(k, a0s[i], a1s[i]);
        kt[i] = slope_scale(k, b0s[i], b1s[i]);
        net_rows(net, a0s[i], a1s[i], H[i]);
    }
    for (int j = 0; j < NP; j++)
        for (int i = 0; i < NP; i++) {
            net_boxes piece;               /* (its Ng alone is wanted) */
            net_piece_of_rows(big, (const vec3(*)[4])H[i], a0s[i], a1s[i], b0s[j], b1s[j], ks[i],
                              kt[j], NB_D, &piece);
            for (int c = 0; c < 3; c++)
                Ng[c] = i == 0 && j == 0 ? piece.Ng[c] : ia_hull(Ng[c], piece.Ng[c]);
        }
    for (int c = 0; c < 3; c++) nb->Ng[c] = meet_ia_(nb->Ng[c], Ng[c]);
}

ia_interval sd_net_normal_component(const vec3 net[16], int axis)
{
    net_boxes nb;
    net_bounds(net, ia_make(0, 1), ia_make(0, 1), 1, &nb);
    return nb.Ng[axis];
}

static ia_interval meet_ia(ia_interval x, ia_interval y)
{
    if (!isfinite(y.lo) || !isfinite(y.hi) || (y.flags & AA_UNBOUNDED)) return x;
    if (y.lo > x.lo) x.lo = y.lo;
    if (y.hi < x.hi) x.hi = y.hi;
    return x;
}

static void meet_aa(aa_form *z, ia_interval y)
{
    if ((z->flags & AA_UNBOUNDED) || !isfinite(y.lo) || !isfinite(y.hi) ||
        (y.flags & AA_UNBOUNDED))
        return;
    if (y.lo > z->lo) z->lo = y.lo;
    if (y.hi < z->hi) z->hi = y.hi;
}

/* The hull of the enclosures of the pieces of a box cut at r's lines. */
static void split_ia(const geom_surface *s, ia_interval u, ia_interval v, const sd_range *r,
                     geom_ia *out)
{
    double cu[3] = { u.lo, u.hi, u.hi }, cv[3] = { v.lo, v.hi, v.hi };
    int nu = 1, nv = 1;
    if (!isnan(r->split_u) && r->split_u > u.lo && r->split_u < u.hi)
        cu[1] = r->split_u, nu = 2;
    if (!isnan(r->split_v) && r->split_v > v.lo && r->split_v < v.hi)
        cv[1] = r->split_v, nv = 2;
    bool first = true;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            geom_ia g;
            geom_subdiv_eval_ia(s, ia_make(cu[i], nu == 1 ? u.hi : cu[i + 1]),
                                ia_make(cv[j], nv == 1 ? v.hi : cv[j + 1]), &g);
            for (int c = 0; c < 3; c++) {
                out->P[c] = first ? g.P[c] : ia_hull(out->P[c], g.P[c]);
                out->dPdu[c] = first ? g.dPdu[c] : ia_hull(out->dPdu[c], g.dPdu[c]);
                out->dPdv[c] = first ? g.dPdv[c] : ia_hull(out->dPdv[c], g.dPdv[c]);
                out->Ng[c] = first ? g.Ng[c] : ia_hull(out->Ng[c], g.Ng[c]);
            }
            first = false;
        }
}

static bool can_split(const sd_range *r, ia_interval u, ia_interval v)
{
    return (!isnan(r->split_u) && r->split_u > u.lo && r->split_u < u.hi) ||
           (!isnan(r->split_v) && r->split_v > v.lo && r->split_v < v.hi);
}

void geom_subdiv_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *out)
{
    sd_range r;
    find_range(s, u.lo, u.hi, v.lo, v.hi, &r);
    if (!r.regular && can_split(&r, u, v)) {
        split_ia(s, u, v, &r, out);
        return;
    }
    if (!r.regular) {
        out->P[0] = ia_make(r.lo.x, r.hi.x);
        out->P[1] = ia_make(r.lo.y, r.hi.y);
        out->P[2] = ia_make(r.lo.z, r.hi.z);
        for (int i = 0; i < 3; i++) out->dPdu[i] = out->dPdv[i] = out->Ng[i] = ia_entire();
        return;
    }
    double k = ldexp(1, r.level);
    ia_interval su = ia_mul_s(ia_add_s(u, -r.ou), k), sv = ia_mul_s(ia_add_s(v, -r.ov), k);
    geom_surface b;
    net_surface(r.net, &b);
    geom_bicubic_eval_ia(&b, su, sv, out);
    net_boxes nb;
    net_bounds(r.net, su, sv, k, &nb);
    for (int i = 0; i < 3; i++) {
        out->P[i] = meet_ia(out->P[i], nb.P[i]);
        out->dPdu[i] = meet_ia(ia_mul_s(out->dPdu[i], k), nb.dPdu[i]);
        out->dPdv[i] = meet_ia(ia_mul_s(out->dPdv[i], k), nb.dPdv[i]);
        out->Ng[i] = meet_ia(ia_mul_s(out->Ng[i], k * k), nb.Ng[i]);
    }
}

bool geom_subdiv_normal_slopes_ia(const geom_surface *s, ia_interval u, ia_interval v,
                                  ia_interval dNdu[3], ia_interval dNdv[3])
{
    sd_range r;
    find_range(s, u.lo, u.hi, v.lo, v.hi, &r);
    if (!r.regular) return false;
    /* the regular sub-patch's Bezier net over the box, in its own
     * coordinates s = k (u - ou): d/du = k d/ds (k a power of 2: exact) */
    double k = ldexp(1, r.level);
    ia_interval su = ia_mul_s(ia_add_s(u, -r.ou), k), sv = ia_mul_s(ia_add_s(v, -r.ov), k);
    su = ia_make(fmax(su.lo, 0), fmin(su.hi, 1));
    sv = ia_make(fmax(sv.lo, 0), fmin(sv.hi, 1));
    geom_surface b;
    net_surface(r.net, &b);
    if (!(su.lo <= su.hi && sv.lo <= sv.hi) ||
        !geom_bicubic_normal_slopes_ia(&b, su, sv, dNdu, dNdv))
        return false;
    for (int i = 0; i < 3; i++) {
        dNdu[i] = ia_mul_s(dNdu[i], k);
        dNdv[i] = ia_mul_s(dNdv[i], k);
    }
    return true;
}

/* The regular sub-patch r as a bicubic patch b of its own, over the
 * inputs in its coordinates su = k (u - ou), sv = k (v - ov), k = 2^level */
static void sub_patch(aa_context *ctx, const sd_range *r, const aa_form *u, const aa_form *v,
                      double *k, aa_form *su, aa_form *sv, geom_surface *b)
{
    *k = ldexp(1, r->level);
    aa_lincomb(ctx, su, *k, u, 0, u, -r->ou * *k);
    aa_lincomb(ctx, sv, *k, v, 0, v, -r->ov * *k);
    net_surface(r->net, b);
}

void geom_subdiv_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                         const aa_form *v, geom_aa *out)
{
    ia_interval ur = aa_range(u), vr = aa_range(v);
    sd_range r;
    find_range(s, ur.lo, ur.hi, vr.lo, vr.hi, &r);
    if (!r.regular && can_split(&r, ur, vr)) {
        /* a box across quadrant lines (never one of the renderer's dyadic
         * boxes): the hull of its pieces, without correlation */
        geom_ia g;
        split_ia(s, ur, vr, &r, &g);
        aa_context none;
        aa_context_init(&none, 0);
        for (int c = 0; c < 3; c++) {
            const ia_interval *src[4] = { &g.P[c], &g.dPdu[c], &g.dPdv[c], &g.Ng[c] };
            aa_form *dst[4] = { &out->P[c], &out->dPdu[c], &out->dPdv[c], &out->Ng[c] };
            for (int q = 0; q < 4; q++) {
                if (!isfinite(src[q]->lo) || !isfinite(src[q]->hi))
                    aa_unbounded(dst[q], AA_UNBOUNDED);
                else
                    aa_from_interval(&none, dst[q], *src[q]);
            }
        }
        return;
    }
    if (!r.regular) {
        aa_context none;
        aa_context_init(&none, 0);
        aa_from_interval(&none, &out->P[0], ia_make(r.lo.x, r.hi.x));
        aa_from_interval(&none, &out->P[1], ia_make(r.lo.y, r.hi.y));
        aa_from_interval(&none, &out->P[2], ia_make(r.lo.z, r.hi.z));
        for (int i = 0; i < 3; i++) {
            aa_unbounded(&out->dPdu[i], AA_UNBOUNDED);
            aa_unbounded(&out->dPdv[i], AA_UNBOUNDED);
            aa_unbounded(&out->Ng[i], AA_UNBOUNDED);
        }
        return;
    }
    double k;
    aa_form su, sv;
    geom_surface b;
    sub_patch(ctx, &r, u, v, &k, &su, &sv, &b);
    if (!geom_bicubic_net_aa(ctx, &b, &su, &sv, out))
        geom_bicubic_eval_aa(ctx, &b, &su, &sv, out);
    net_boxes nb;
    net_bounds(r.net, aa_range(&su), aa_range(&sv), k, &nb);
    for (int i = 0; i < 3; i++) {
        aa_mul_s(ctx, &out->dPdu[i], &out->dPdu[i], k);
        aa_mul_s(ctx, &out->dPdv[i], &out->dPdv[i], k);
        aa_mul_s(ctx, &out->Ng[i], &out->Ng[i], k * k);
        meet_aa(&out->P[i], nb.P[i]);
        meet_aa(&out->dPdu[i], nb.dPdu[i]);
        meet_aa(&out->dPdv[i], nb.dPdv[i]);
        meet_aa(&out->Ng[i], nb.Ng[i]);
    }
}

void geom_subdiv_range_P_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                            const aa_form *v, ia_interval P[3])
{
    /* geom_subdiv_eval_aa's way to a regular sub-patch, and of its forms
     * the P part alone: the hull of the piece's nets (the forms' range,
     * geom_bicubic_net_range_P) met with net_bounds' P (net_piece of the
     * clamped box: its 3 x 3 pieces narrow Ng only) */
    ia_interval ur = aa_range(u), vr = aa_range(v);
    sd_range r;
    find_range(s, ur.lo, ur.hi, vr.lo, vr.hi, &r);
    if (r.regular) {
        double k;
        aa_form su, sv;
        geom_surface b;
        sub_patch(ctx, &r, u, v, &k, &su, &sv, &b);
        if (geom_bicubic_net_range_P(&b, &su, &sv, P)) {
            double box[4];
            clamp_box(aa_range(&su), aa_range(&sv), box);
            net_boxes nb;
            net_piece(r.net, box[0], box[1], box[2], box[3], k, NB_P, &nb);
            for (int i = 0; i < 3; i++)
                if (isfinite(nb.P[i].lo) && isfinite(nb.P[i].hi) &&
                    !(nb.P[i].flags & AA_UNBOUNDED)) {
                    if (nb.P[i].lo > P[i].lo) P[i].lo = nb.P[i].lo;
                    if (nb.P[i].hi < P[i].hi) P[i].hi = nb.P[i].hi;
                }
            return;
        }
    }
    /* the rest (irregular sub-faces, thin boxes) costs little or is rare:
     * the forms themselves */
    geom_aa g;
    geom_subdiv_eval_aa(ctx, s, u, v, &g);
    for (int i = 0; i < 3; i++) P[i] = aa_range(&g.P[i]);
}

bool geom_subdiv_unit_normal_box(const geom_surface *s, ia_interval u, ia_interval v,
                                 ia_interval Nn[3])
{
    if (s->kind != GEOM_SUBDIV || !s->subdiv)
        return false;              /* other kinds come through the same callers */
    sd_range r;
    find_range(s, u.lo, u.hi, v.lo, v.hi, &r);
    vec3 N;
    if (r.regular || can_split(&r, u, v)) return false;
    if (!sd_node_unit_normal(r.normal_node, &N))   /* a smooth EV's proven cone, or none */
        return sd_node_ev_box(r.node, s->subdiv->pmax, Nn);
    /* the exact normal, widened by 1e-6 for the float evaluation of points
     * near the irregular corner, whose normals tilt by the refinement's
     * rounding amplified by 2^level (1e-9 at 2^-22 from a crease point) */
    for (int i = 0; i < 3; i++) {
        double c = v3_comp(N, i);
        Nn[i] = ia_make(fmax(c - 1e-6, -1), fmin(c + 1e-6, 1));
    }
    return true;
}

/* ---- bounds and intersection ---- */

void geom_subdiv_bounds(const geom_surface *s, vec3 *lo, vec3 *hi)
{
    *lo = s->subdiv_lo;              /* the 1-ring's hull, made with the surface */
    *hi = s->subdiv_hi;
}

static bool slab(vec3 o, vec3 d, vec3 lo, vec3 hi, double *t0, double *t1)
{
    double a[3] = { o.x, o.y, o.z }, b[3] = { d.x, d.y, d.z };
    double l[3] = { lo.x, lo.y, lo.z }, h[3] = { hi.x, hi.y, hi.z };
    for (int i = 0; i < 3; i++) {
        if (b[i] == 0) {
            if (a[i] < l[i] || a[i] > h[i]) return false;
            continue;
        }
        double ta = (l[i] - a[i]) / b[i], tb = (h[i] - a[i]) / b[i];
        if (ta > tb) { double x = ta; ta = tb; tb = x; }
        if (ta > *t0) *t0 = ta;
        if (tb < *t1) *t1 = tb;
        if (*t0 > *t1) return false;
    }
    return true;
}

/* Dyadic cells of the face, nearest first is not needed: every hit found
 * shrinks tmax. A regular sub-patch is intersected as its Bezier patch;
 * an irregular cell is split down to 2^-20, where the hull's entry counts
 * as the hit (within 2^-20 of an extraordinary point). */
bool geom_subdiv_intersect(const geom_surface *s, vec3 o, vec3 d, double tmin, double tmax,
                           geom_hit *hit)
{
    enum { MAX_CELL_LEVEL = 20, STACK = 3 * MAX_CELL_LEVEL + 8 };
    struct { double u0, v0; int level; } stack[STACK];
    int n = 0;
    stack[n].u0 = stack[n].v0 = 0;
    stack[n++].level = 0;
    bool found = false;
    double best = tmax;
    while (n > 0) {
        double u0 = stack[n - 1].u0, v0 = stack[n - 1].v0;
        int level = stack[--n].level;
        double side = ldexp(1, -level);
        sd_range r;
        find_range(s, u0, u0 + side, v0, v0 + side, &r);
        if (r.regular) {
            geom_surface b;
            net_surface(r.net, &b);
            geom_hit h;
            if (geom_bicubic_intersect(&b, o, d, tmin, best, &h)) {
                double k = ldexp(1, -r.level);
                double hu = r.ou + h.u * k, hv = r.ov + h.v * k;
                if (hu >= u0 && hu <= u0 + side && hv >= v0 && hv <= v0 + side) {
                    best = h.t;
                    hit->t = h.t;
                    hit->u = hu;
                    hit->v = hv;
                    found = true;
                }
            }
            continue;
        }
        double t0 = tmin, t1 = best;
        if (!slab(o, d, r.lo, r.hi, &t0, &t1)) continue;
        if (level >= MAX_CELL_LEVEL || n + 4 > STACK) {
            if (t0 > tmin && t0 < best) {
                best = t0;
                hit->t = t0;
                hit->u = u0 + side / 2;
                hit->v = v0 + side / 2;
                found = true;
            }
            continue;
        }
        for (int q = 0; q < 4; q++) {
            stack[n].u0 = u0 + (q & 1) * side / 2;
            stack[n].v0 = v0 + (q >> 1) * side / 2;
            stack[n++].level = level + 1;
        }
    }
    return found;
}
