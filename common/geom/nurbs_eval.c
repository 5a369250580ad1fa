/*
 * nurbs_eval.c: one rational Bezier piece of a NuPatch (GEOM_NURBS,
 * geom/nurbs.h) in the four arithmetics, and its bounds.
 *
 * With H(u,v) = sum_ij B_i(u) B_j(v) Hw_ij (homogeneous, W = H.w) and
 * H.xyz = W P, differentiating gives
 *
 *     P   = H.xyz / W
 *     Pu  = (Hu - Wu P) / W                      Pv likewise
 *     Puu = (Huu - 2 Wu Pu - Wuu P) / W          Pvv likewise
 *     Puv = (Huv - Wu Pv - Wv Pu - Wuv P) / W
 *
 * Float and dual evaluate these at a point (Bernstein polynomials of any
 * degree by the triangle recurrence, their derivatives from the degree
 * n-1 and n-2 ones). Interval and affine evaluate the tensor forms H, Hu,
 * Hv over the box (the basis from powers of u and s = 1 - u, the
 * derivative basis n (b_{i-1,n-1} - b_{i,n-1}); control values are exact
 * doubles), then divide: W's enclosure is first met with [min w, max w]
 * of the net (exact: the basis is non-negative and sums to 1), which is
 * > 0, so 1/W stays bounded over any box (Heidrich & Seidel §4: a range
 * holding 0 would make the box unbounded); P is met with the projected
 * points' hull. Where all weights are equal W is that constant exactly.
 * The affine forms share u's and v's noise symbols throughout. The
 * interval enclosure is met with the affine one's ranges (plain interval
 * arithmetic loses the correlation of H and W).
 *
 * The ray intersection is nurbs_intersect.c.
 */
#include "geom/nurbs_internal.h"
#include "geom/surface_internal.h"
#include "util/err.h"

#include <math.h>
#include <stdlib.h>

enum { MAXO = GEOM_NURBS_MAX_ORDER };

static const geom_nurbs_piece *piece_of(const geom_surface *s)
{
    return &s->nurbs->pieces[s->nurbs_piece];
}

static double binomial(int n, int k)
{
    double r = 1;
    for (int i = 1; i <= k; i++)
        r = r * (n - k + i) / i;       /* exact: every partial product is an integer */
    return r;
}

/* ---- float and dual ------------------------------------------------- */

/* Bernstein polynomials of degree n at t and their first and second
 * derivatives. */
static void bern(int n, double t, double B[MAXO], double D1[MAXO], double D2[MAXO])
{
    double cur[MAXO + 1] = { 1 }, m1[MAXO + 1] = { 0 }, m2[MAXO + 1] = { 0 };
    if (n == 1)
        m1[0] = 1;
    if (n == 2)
        m2[0] = 1;
    for (int k = 1; k <= n; k++) {
        cur[k] = 0;
        for (int i = k; i >= 0; i--)
            cur[i] = (1 - t) * cur[i] + (i > 0 ? t * cur[i - 1] : 0);
        if (k == n - 1)
            for (int i = 0; i <= k; i++) m1[i] = cur[i];
        if (k == n - 2)
            for (int i = 0; i <= k; i++) m2[i] = cur[i];
    }
    for (int i = 0; i <= n; i++) {
        B[i] = cur[i];
        D1[i] = n * ((i > 0 ? m1[i - 1] : 0) - (i < n ? m1[i] : 0));
        double a = i >= 2 ? m2[i - 2] : 0, b = i >= 1 && i - 1 <= n - 2 ? m2[i - 1] : 0;
        double c = i <= n - 2 ? m2[i] : 0;
        D2[i] = n >= 2 ? n * (n - 1) * (a - 2 * b + c) : 0;
    }
}

void geom_nurbs_eval_dual(const geom_surface *s, double u, double v, geom_sample *out)
{
    const geom_nurbs_piece *pc = piece_of(s);
    double bu[MAXO], du[MAXO], ddu[MAXO], bv[MAXO], dv[MAXO], ddv[MAXO];
    bern(pc->ku - 1, u, bu, du, ddu);
    bern(pc->kv - 1, v, bv, dv, ddv);
    /* H, Hu, Hv, Huu, Huv, Hvv */
    double h[6][4] = { { 0 } };
    for (int j = 0; j < pc->kv; j++)
        for (int i = 0; i < pc->ku; i++) {
            const double *w = pc->H + 4 * (j * pc->ku + i);
            double k[6] = { bu[i] * bv[j], du[i] * bv[j], bu[i] * dv[j], ddu[i] * bv[j],
                            du[i] * dv[j], bu[i] * ddv[j] };
            for (int q = 0; q < 6; q++)
                for (int c = 0; c < 4; c++)
                    h[q][c] += k[q] * w[c];
        }
    double W = h[0][3], Wu = h[1][3], Wv = h[2][3], Wuu = h[3][3], Wuv = h[4][3],
           Wvv = h[5][3];
    vec3 H[6];
    for (int q = 0; q < 6; q++)
        H[q] = v3(h[q][0], h[q][1], h[q][2]);
    double r = 1 / W;
    vec3 P = v3_scale(H[0], r);
    vec3 Pu = v3_scale(v3_sub(H[1], v3_scale(P, Wu)), r);
    vec3 Pv = v3_scale(v3_sub(H[2], v3_scale(P, Wv)), r);
    vec3 Puu = v3_scale(v3_sub(v3_sub(H[3], v3_scale(Pu, 2 * Wu)), v3_scale(P, Wuu)), r);
    vec3 Puv = v3_scale(v3_sub(v3_sub(v3_sub(H[4], v3_scale(Pv, Wu)), v3_scale(Pu, Wv)),
                               v3_scale(P, Wuv)), r);
    vec3 Pvv = v3_scale(v3_sub(v3_sub(H[5], v3_scale(Pv, 2 * Wv)), v3_scale(P, Wvv)), r);
    out->P = P;
    out->dPdu = Pu;
    out->dPdv = Pv;
    out->Ng = v3_cross(Pu, Pv);
    out->dNgdu = v3_add(v3_cross(Puu, Pv), v3_cross(Pu, Puv));
    out->dNgdv = v3_add(v3_cross(Puv, Pv), v3_cross(Pu, Pvv));
}

/* ---- interval ------------------------------------------------------- */

static void basis_ia(int n, ia_interval u, ia_interval B[MAXO], ia_interval D[MAXO])
{
    ia_interval s = ia_sub(ia_point(1), u), up[MAXO + 1], sp[MAXO + 1], m1[MAXO + 1];
    up[0] = sp[0] = ia_point(1);
    for (int k = 1; k <= n; k++) {
        up[k] = k == 1 ? u : ia_mul(up[k - 1], u);
        sp[k] = k == 1 ? s : ia_mul(sp[k - 1], s);
    }
    for (int i = 0; i <= n; i++)
        B[i] = ia_mul_s(ia_mul(up[i], sp[n - i]), binomial(n, i));
    for (int i = 0; i < n; i++)
        m1[i] = ia_mul_s(ia_mul(up[i], sp[n - 1 - i]), binomial(n - 1, i));
    for (int i = 0; i <= n; i++) {
        ia_interval a = i > 0 ? m1[i - 1] : ia_point(0), b = i < n ? m1[i] : ia_point(0);
        D[i] = ia_mul_s(ia_sub(a, b), n);
    }
}

static ia_interval meet_ia(ia_interval x, ia_interval k)
{
    if (x.lo < k.lo) x.lo = k.lo;
    if (x.hi > k.hi) x.hi = k.hi;
    return x;
}

static void eval_ia_plain(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *o)
{
    const geom_nurbs_piece *pc = piece_of(s);
    ia_interval bu[MAXO], du[MAXO], bv[MAXO], dv[MAXO];
    basis_ia(pc->ku - 1, u, bu, du);
    basis_ia(pc->kv - 1, v, bv, dv);
    bool poly = pc->wmin == pc->wmax;
    ia_interval H[3][4];               /* H, Hu, Hv */
    for (int c = 0; c < (poly ? 3 : 4); c++) {
        ia_interval h = ia_point(0), hu = ia_point(0), hv = ia_point(0);
        for (int j = 0; j < pc->kv; j++) {
            ia_interval C = ia_point(0), D = ia_point(0);
            for (int i = 0; i < pc->ku; i++) {
                double x = pc->H[4 * (j * pc->ku + i) + c];
                C = ia_add(C, ia_mul_s(bu[i], x));
                D = ia_add(D, ia_mul_s(du[i], x));
            }
            h = ia_add(h, ia_mul(bv[j], C));
            hu = ia_add(hu, ia_mul(bv[j], D));
            hv = ia_add(hv, ia_mul(dv[j], C));
        }
        H[0][c] = h, H[1][c] = hu, H[2][c] = hv;
    }
    ia_interval W, Wu, Wv;
    if (poly) {
        W = ia_point(pc->wmin), Wu = Wv = ia_point(0);
    } else {
        W = meet_ia(H[0][3], ia_make(pc->wmin, pc->wmax));
        Wu = H[1][3], Wv = H[2][3];
    }
    ia_interval r = ia_recip(W);
    for (int c = 0; c < 3; c++) {
        o->P[c] = meet_ia(ia_mul(H[0][c], r), pc->hull[c]);
        o->dPdu[c] = ia_mul(ia_sub(H[1][c], ia_mul(Wu, o->P[c])), r);
        o->dPdv[c] = ia_mul(ia_sub(H[2][c], ia_mul(Wv, o->P[c])), r);
    }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        o->Ng[c] = ia_sub(ia_mul(o->dPdu[a], o->dPdv[b]), ia_mul(o->dPdu[b], o->dPdv[a]));
    }
}

/* ---- affine --------------------------------------------------------- */

static void basis_aa(aa_context *ctx, int n, const aa_form *u, aa_form B[MAXO],
                     aa_form D[MAXO])
{
    aa_form s, up[MAXO + 1], sp[MAXO + 1], m1[MAXO + 1];
    aa_lincomb(ctx, &s, -1, u, 0, u, 1);
    aa_const(&up[0], 1);
    aa_const(&sp[0], 1);
    up[1] = *u;
    sp[1] = s;
    for (int k = 2; k <= n; k++) {
        aa_mul(ctx, &up[k], &up[k - 1], u);
        aa_mul(ctx, &sp[k], &sp[k - 1], &s);
    }
    for (int i = 0; i <= n; i++) {
        if (i == 0 || i == n) {
            B[i] = i == 0 ? sp[n] : up[n];
        } else {
            aa_mul(ctx, &B[i], &up[i], &sp[n - i]);
            aa_mul_s(ctx, &B[i], &B[i], binomial(n, i));
        }
    }
    for (int i = 0; i < n; i++) {
        if (i == 0 || i == n - 1) {
            m1[i] = i == 0 ? sp[n - 1] : up[n - 1];
        } else {
            aa_mul(ctx, &m1[i], &up[i], &sp[n - 1 - i]);
            aa_mul_s(ctx, &m1[i], &m1[i], binomial(n - 1, i));
        }
    }
    for (int i = 0; i <= n; i++) {
        if (i == 0)
            aa_mul_s(ctx, &D[i], &m1[0], -n);
        else if (i == n)
            aa_mul_s(ctx, &D[i], &m1[n - 1], n);
        else
            aa_lincomb(ctx, &D[i], n, &m1[i - 1], -n, &m1[i], 0);
    }
}

static void meet_aa(aa_form *x, ia_interval k)
{
    if (x->lo < k.lo) x->lo = k.lo;
    if (x->hi > k.hi) x->hi = k.hi;
}

/* z = sum_i w[i] x[i] (w exact doubles) */
static void dot_aa(aa_context *ctx, aa_form *z, const aa_form *w, const double *x, int stride,
                   int n)
{
    aa_mul_s(ctx, z, &w[0], x[0]);
    for (int i = 1; i < n; i++)
        aa_lincomb(ctx, z, 1, z, x[i * stride], &w[i], 0);
}

/* The homogeneous numerator and weight (H[0]), and their derivatives in
 * u (H[1]) and v (H[2]), over the box of u and v from the piece's Bezier
 * net there (bezier_net.c): false on boxes thinner than 2^-12 or beyond
 * the unit square (the tensor form there) */
static bool net_forms(aa_context *ctx, const geom_nurbs_piece *pc, const aa_form *u,
                      const aa_form *v, int ncoord, aa_form H[3][4])
{
    ia_interval ur = aa_range(u), vr = aa_range(v);
    double s0 = ur.lo, s1 = ur.hi, t0 = vr.lo, t1 = vr.hi;
    if (!(s1 - s0 > 0x1p-12) || !(t1 - t0 > 0x1p-12) || (u->flags | v->flags)) return false;
    int ku = pc->ku, kv = pc->kv;
    double big = 0;
    for (int i = 0; i < 4 * ku * kv; i++) big = fmax(big, fabs(pc->H[i]));
    double pad = GEOM_NET_PAD * big;
    ia_interval is = ia_recip(ia_sub(ia_point(s1), ia_point(s0)));
    ia_interval it = ia_recip(ia_sub(ia_point(t1), ia_point(t0)));
    for (int c = 0; c < ncoord; c++) {
        ia_interval q[MAXO][MAXO], d[MAXO][MAXO];
        if (!geom_net_piece(pc->H + c, 4, ku, kv, s0, s1, t0, t1, pad, &q[0][0], MAXO))
            return false;
        geom_net_form(ctx, &H[0][c], &q[0][0], MAXO, ku, kv, ia_point(1), u, v, s0, s1, t0, t1);
        /* d/ds: (ku - 1) times the differences along u, a net of ku - 1 */
        for (int j = 0; j < kv; j++)
            for (int i = 0; i + 1 < ku; i++)
                d[j][i] = ia_mul_s(ia_sub(q[j][i + 1], q[j][i]), ku - 1);
        geom_net_form(ctx, &H[1][c], &d[0][0], MAXO, ku - 1, kv, is, u, v, s0, s1, t0, t1);
        for (int j = 0; j + 1 < kv; j++)
            for (int i = 0; i < ku; i++)
                d[j][i] = ia_mul_s(ia_sub(q[j + 1][i], q[j][i]), kv - 1);
        geom_net_form(ctx, &H[2][c], &d[0][0], MAXO, ku, kv - 1, it, u, v, s0, s1, t0, t1);
    }
    return true;
}

void geom_nurbs_eval_aa(aa_context *ctx, const geom_surface *s, const aa_form *u,
                        const aa_form *v, geom_aa *o)
{
    const geom_nurbs_piece *pc = piece_of(s);
    bool poly = pc->wmin == pc->wmax;
    aa_form H[3][4], t;
    if (pc->ku >= 3 && pc->kv >= 3 && net_forms(ctx, pc, u, v, poly ? 3 : 4, H))
        goto divide;
    aa_form bu[MAXO], du[MAXO], bv[MAXO], dv[MAXO];
    basis_aa(ctx, pc->ku - 1, u, bu, du);
    basis_aa(ctx, pc->kv - 1, v, bv, dv);
    for (int c = 0; c < (poly ? 3 : 4); c++) {
        aa_const(&H[0][c], 0);
        aa_const(&H[1][c], 0);
        aa_const(&H[2][c], 0);
        for (int j = 0; j < pc->kv; j++) {
            aa_form C, D;
            const double *row = pc->H + 4 * j * pc->ku + c;
            dot_aa(ctx, &C, bu, row, 4, pc->ku);
            dot_aa(ctx, &D, du, row, 4, pc->ku);
            aa_mul(ctx, &t, &bv[j], &C);
            aa_add(ctx, &H[0][c], &H[0][c], &t);
            aa_mul(ctx, &t, &bv[j], &D);
            aa_add(ctx, &H[1][c], &H[1][c], &t);
            aa_mul(ctx, &t, &dv[j], &C);
            aa_add(ctx, &H[2][c], &H[2][c], &t);
        }
    }
divide:;
    aa_form W, Wu, Wv, r;
    if (poly) {
        aa_context none;
        aa_context_init(&none, 0);
        aa_from_interval(&none, &r, ia_recip(ia_point(pc->wmin)));
        aa_const(&Wu, 0);
        aa_const(&Wv, 0);
    } else {
        W = H[0][3];
        meet_aa(&W, ia_make(pc->wmin, pc->wmax));
        Wu = H[1][3], Wv = H[2][3];
        aa_recip(ctx, &r, &W);
    }
    for (int c = 0; c < 3; c++) {
        aa_mul(ctx, &o->P[c], &H[0][c], &r);
        meet_aa(&o->P[c], pc->hull[c]);
        if (poly) {
            aa_mul(ctx, &o->dPdu[c], &H[1][c], &r);
            aa_mul(ctx, &o->dPdv[c], &H[2][c], &r);
            continue;
        }
        aa_mul(ctx, &t, &Wu, &o->P[c]);
        aa_sub(ctx, &t, &H[1][c], &t);
        aa_mul(ctx, &o->dPdu[c], &t, &r);
        aa_mul(ctx, &t, &Wv, &o->P[c]);
        aa_sub(ctx, &t, &H[2][c], &t);
        aa_mul(ctx, &o->dPdv[c], &t, &r);
    }
    geom_ng_aa(ctx, o);
}

/* The interval enclosure: the plain interval evaluation met with the
 * ranges of the affine one (both enclose the same values). Plain interval
 * arithmetic loses the correlation of H and W: over boxes of side 1/100
 * its normals still hold 0, where the affine ones are tight. */
void geom_nurbs_eval_ia(const geom_surface *s, ia_interval u, ia_interval v, geom_ia *o)
{
    eval_ia_plain(s, u, v, o);
    if (!(u.lo <= u.hi && v.lo <= v.hi && isfinite(u.lo) && isfinite(u.hi) &&
          isfinite(v.lo) && isfinite(v.hi)))
        return;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form U, V;
    aa_input(&ctx, &U, u.lo, u.hi);
    aa_input(&ctx, &V, v.lo, v.hi);
    geom_aa g;
    geom_nurbs_eval_aa(&ctx, s, &U, &V, &g);
    for (int c = 0; c < 3; c++) {
        o->P[c] = meet_ia(o->P[c], aa_range(&g.P[c]));
        o->dPdu[c] = meet_ia(o->dPdu[c], aa_range(&g.dPdu[c]));
        o->dPdv[c] = meet_ia(o->dPdv[c], aa_range(&g.dPdv[c]));
        o->Ng[c] = meet_ia(o->Ng[c], aa_range(&g.Ng[c]));
    }
}

/* ---- prepare and bounds --------------------------------------------- */

bool geom_nurbs_prepare(geom_surface *s, char *err, size_t errsz)
{
    if (!s->nurbs || s->nurbs_piece < 0 || s->nurbs_piece >= geom_nurbs_npieces(s->nurbs))
        return err_set(err, errsz, "NuPatch piece without its patch");
    return true;
}

void geom_nurbs_bounds(const geom_surface *s, vec3 *lo, vec3 *hi)
{
    const geom_nurbs_piece *pc = piece_of(s);
    *lo = v3(pc->hull[0].lo, pc->hull[1].lo, pc->hull[2].lo);
    *hi = v3(pc->hull[0].hi, pc->hull[1].hi, pc->hull[2].hi);
}
