/*
 * rib_nupatch.c: NuPatch (RI Specification 3.2 §5.4, non-uniform rational
 * B-spline patches) of any order up to 16, and TrimCurve (read and
 * ignored with a warning: the whole patch is rendered).
 *
 *   NuPatch nu uorder uknot umin umax nv vorder vknot vmin vmax "P" | "Pw"
 *
 * Each knot interval pair inside [umin, umax] x [vmin, vmax] is one
 * piece. A polynomial patch ("P", or "Pw" with every weight the same) of
 * orders up to 4 becomes bicubic Bezier patches (GEOM_BICUBIC): the piece
 * is evaluated by de Boor's algorithm (in the interval's own span, also
 * at its ends) on the 4 x 4 grid t = 0, 1/3, 2/3, 1 of the interval, and
 * the Bezier net interpolating those values is B = C^-1 F C^-T with C the
 * Bernstein collocation matrix at those t; lower orders are thereby
 * raised to cubic. A rational patch (weights that differ) or a higher
 * order becomes one geom_nurbs (common/geom/nurbs.h: rational Bezier
 * pieces by knot insertion), owned by the scene (scene.nurbs), and one
 * GEOM_NURBS object per piece. "Pw" is RenderMan's homogeneous point
 * (w x, w y, w z, w); every weight must be > 0.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"

#ifdef SCENE_HAVE_GEOM
#include "geom/nurbs.h"
#include "util/err.h"
#include "util/xalloc.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NUPATCH_MAX_ORDER = 16 };     /* GEOM_NURBS_MAX_ORDER */

typedef struct nurbs_dir {
    int n, order;
    double *knots;                 /* n + order */
    double lo, hi;                 /* umin umax */
} nurbs_dir;

/* Argument i as one number (bare or [x]); false with an error naming what. */
static bool one_number(rib_parser *p, const rib_request *req, int i, const char *what,
                       double *out)
{
    int n = 0;
    const double *v = i < req->nargs && rib_arg_is_numeric(&req->args[i])
                          ? rib_arg_numbers(req, &req->args[i], &n) : NULL;
    if (!v || n != 1) {
        rib_error(p, req, i < req->nargs ? req->args[i].pos : req->pos, "expected %s (one "
                  "number) as argument %d", what, i + 1);
        return false;
    }
    *out = v[0];
    return true;
}

/* Reads n order knot[] min max from argument *i on. */
static bool read_dir(rib_parser *p, const rib_request *req, int *i, const char *w,
                     nurbs_dir *d)
{
    double no[2], mm[2];
    char what[4][32];
    snprintf(what[0], sizeof what[0], "n%s", w);
    snprintf(what[1], sizeof what[1], "%sorder", w);
    snprintf(what[2], sizeof what[2], "%smin", w);
    snprintf(what[3], sizeof what[3], "%smax", w);
    if (!one_number(p, req, *i, what[0], &no[0]) || !one_number(p, req, *i + 1, what[1], &no[1]))
        return false;
    if (!(no[0] == floor(no[0]) && no[1] == floor(no[1]) && no[1] >= 2 &&
          no[1] <= NUPATCH_MAX_ORDER && no[0] >= no[1] && no[0] <= 1e6)) {
        rib_error(p, req, req->args[*i].pos, "%sorder must be 2 to %d (orders above %d are "
                  "not supported) and n%s at least the order, got n%s %g, %sorder %g",
                  w, NUPATCH_MAX_ORDER, NUPATCH_MAX_ORDER, w, w, no[0], w, no[1]);
        return false;
    }
    d->n = (int)no[0], d->order = (int)no[1];
    int next = *i + 2;
    if (next >= req->nargs || !rib_arg_is_numeric(&req->args[next])) {
        rib_error(p, req, next < req->nargs ? req->args[next].pos : req->pos,
                  "missing %sknot (an array of %d numbers)", w, d->n + d->order);
        return false;
    }
    int nk;
    const double *k = rib_arg_numbers(req, &req->args[next], &nk);
    if (nk != d->n + d->order) {
        rib_error(p, req, req->args[next].pos, "%sknot needs n%s + %sorder = %d numbers, got %d",
                  w, w, w, d->n + d->order, nk);
        return false;
    }
    for (int j = 0; j < nk; j++)
        if (!isfinite(k[j]) || (j > 0 && k[j] < k[j - 1])) {
            rib_error(p, req, req->args[next].pos, "%sknot must be finite and nondecreasing "
                      "(entry %d is %g)", w, j, k[j]);
            return false;
        }
    if (!one_number(p, req, next + 1, what[2], &mm[0]) ||
        !one_number(p, req, next + 2, what[3], &mm[1]))
        return false;
    double dlo = k[d->order - 1], dhi = k[d->n];
    if (!(mm[0] < mm[1] && mm[0] >= dlo && mm[1] <= dhi)) {
        rib_error(p, req, req->args[next + 1].pos, "%smin %smax must satisfy %g <= %smin < "
                  "%smax <= %g (the knots' domain), got %g %g", w, w, dlo, w, w, dhi, mm[0],
                  mm[1]);
        return false;
    }
    d->knots = xrealloc(NULL, (size_t)nk * sizeof *d->knots);
    memcpy(d->knots, k, (size_t)nk * sizeof *k);
    d->lo = mm[0], d->hi = mm[1];
    *i = next + 3;
    return true;
}

/* The B-spline basis functions of span k (knots[k] <= t <= knots[k+1])
 * at t: N[0..order) for control points k-order+1 .. k (Cox-de Boor,
 * evaluated as the span's polynomial, also at its ends). */
static void basis_funs(const nurbs_dir *d, int k, double t, double N[4])
{
    int p = d->order - 1;
    const double *U = d->knots;
    double left[4], right[4];
    N[0] = 1;
    for (int j = 1; j <= p; j++) {
        left[j] = t - U[k + 1 - j];
        right[j] = U[k + j] - t;
        double saved = 0;
        for (int r = 0; r < j; r++) {
            double tmp = N[r] / (right[r + 1] + left[j - r]);
            N[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        N[j] = saved;
    }
}

/* The breakpoints of d inside [lo, hi] and the span of each interval. */
static int intervals(const nurbs_dir *d, double *a, double *b, int *span, int max)
{
    int count = 0, p = d->order - 1;
    for (int k = p; k < d->n && count < max; k++) {
        double x0 = fmax(d->knots[k], d->lo), x1 = fmin(d->knots[k + 1], d->hi);
        if (!(x0 < x1))
            continue;
        a[count] = x0, b[count] = x1, span[count] = k;
        count++;
    }
    return count;
}

/* Bezier control values from the values at t = 0, 1/3, 2/3, 1. */
static void interpolate4(const double f[4], double b[4])
{
    b[0] = f[0];
    b[1] = (-5 * f[0] + 18 * f[1] - 9 * f[2] + 2 * f[3]) / 6;
    b[2] = (2 * f[0] - 9 * f[1] + 18 * f[2] - 5 * f[3]) / 6;
    b[3] = f[3];
}

/* A rational or high-order patch: one geom_nurbs, one object per piece. */
static void add_nurbs(rib_parser *p, const rib_request *req, const nurbs_dir *du,
                      const nurbs_dir *dv, const double *pts, int stride)
{
#ifdef SCENE_HAVE_GEOM
    size_t npts = (size_t)du->n * (size_t)dv->n;
    double *Pw = xrealloc(NULL, 4 * npts * sizeof *Pw);
    for (size_t k = 0; k < npts; k++) {
        for (int c = 0; c < 3; c++)
            Pw[4 * k + c] = pts[stride * k + c];
        Pw[4 * k + 3] = stride == 4 ? pts[4 * k + 3] : 1;
    }
    geom_nurbs_desc d = { du->n, du->order, du->knots, du->lo, du->hi,
                          dv->n, dv->order, dv->knots, dv->lo, dv->hi, Pw };
    char err[ERR_LEN] = "";
    geom_nurbs *nb = geom_nurbs_new(&d, err, sizeof err);
    free(Pw);
    if (!nb) {
        rib_error(p, req, req->pos, "%s", err);
        return;
    }
    scene *sc = p->scene;
    sc->nurbs = xrealloc(sc->nurbs, (size_t)(sc->nnurbs + 1) * sizeof *sc->nurbs);
    sc->nurbs[sc->nnurbs++] = nb;
    for (int k = 0; k < geom_nurbs_npieces(nb) && !sl_diag_full(p->diag); k++) {
        geom_surface s;
        geom_nurbs_surface(nb, k, &s);
        rib_add_surface(p, req, &s);
    }
#else
    (void)du, (void)dv, (void)pts, (void)stride;
    rib_error(p, req, req->pos, "rational NuPatch needs common/geom");
#endif
}

void rib_nu_patch(rib_parser *p, const rib_request *req)
{
    nurbs_dir du = { 0 }, dv = { 0 };
    int i = 0;
    rib_params params = { 0 };
    if (!read_dir(p, req, &i, "u", &du) || !read_dir(p, req, &i, "v", &dv))
        goto out;
    if ((double)du.n * dv.n > 1e7) {
        rib_error(p, req, req->pos, "at most 10000000 control points are supported, got "
                  "%d x %d", du.n, dv.n);
        goto out;
    }
    if (!rib_params_read(p, req, i, RIB_PARAMS_VARYING, &params))
        goto out;
    const scene_param *P = rib_params_find(&params, "P");
    const scene_param *Pw = rib_params_find(&params, "Pw");
    int npts = du.n * dv.n, stride = 3;
    bool rational = false;
    const double *pts = NULL;
    double w = 1;
    if (P && P->type == SL_TYPE_POINT) {
        pts = P->values;
        if (P->count / 3 != npts) {
            rib_error(p, req, P->pos, "\"P\" needs nu x nv = %d points, got %d", npts,
                      P->count / 3);
            goto out;
        }
    } else if (Pw && Pw->type == SL_TYPE_FLOAT) {
        if (Pw->count != 4 * npts) {
            rib_error(p, req, Pw->pos, "\"Pw\" needs nu x nv = %d points of 4 numbers, got "
                      "%d numbers", npts, Pw->count);
            goto out;
        }
        pts = Pw->values, stride = 4, w = Pw->values[3];
        for (int k = 0; k < npts; k++) {
            double wk = Pw->values[4 * k + 3];
            if (!(wk > 0) || !isfinite(wk)) {
                rib_error(p, req, Pw->pos, "\"Pw\" point %d has weight %g: every weight must be "
                          "a finite number > 0 (\"Pw\" is x*w y*w z*w w)", k, wk);
                goto out;
            }
            if (wk != w)
                rational = true;
        }
    } else {
        rib_error(p, req, req->pos, "missing the control points: add \"P\" [x y z ...] (or "
                  "\"Pw\" declared as \"vertex float[4] Pw\")");
        goto out;
    }
    if (rational || du.order > 4 || dv.order > 4) {
        add_nurbs(p, req, &du, &dv, pts, stride);
        goto out;
    }
    size_t nu = (size_t)du.n, nv = (size_t)dv.n;
    double *ua = xrealloc(NULL, 2 * (nu + nv) * sizeof *ua);
    double *ub = ua + nu, *va = ua + 2 * nu, *vb = va + nv;
    int *us = xrealloc(NULL, (nu + nv) * sizeof *us), *vs = us + nu;
    int nui = intervals(&du, ua, ub, us, du.n), nvi = intervals(&dv, va, vb, vs, dv.n);
    for (int a = 0; a < nvi; a++)
        for (int b = 0; b < nui; b++) {
            /* F[l][k][c]: the surface at (u_k, v_l), then the net */
            double F[4][4][3], Bn[4][4][3];
            double Nu[4][4], Nv[4][4];
            for (int k = 0; k < 4; k++) {
                basis_funs(&du, us[b], ua[b] + (ub[b] - ua[b]) * k / 3.0, Nu[k]);
                basis_funs(&dv, vs[a], va[a] + (vb[a] - va[a]) * k / 3.0, Nv[k]);
            }
            for (int l = 0; l < 4; l++)
                for (int k = 0; k < 4; k++)
                    for (int c = 0; c < 3; c++) {
                        double s = 0;
                        for (int y = 0; y < dv.order; y++)
                            for (int x = 0; x < du.order; x++) {
                                int iu = us[b] - du.order + 1 + x, iv = vs[a] - dv.order + 1 + y;
                                s += Nu[k][x] * Nv[l][y] * pts[stride * (iv * du.n + iu) + c];
                            }
                        F[l][k][c] = s / w;
                    }
            for (int c = 0; c < 3; c++) {
                double tmp[4][4];
                for (int l = 0; l < 4; l++) {     /* along u */
                    double f[4] = { F[l][0][c], F[l][1][c], F[l][2][c], F[l][3][c] }, r[4];
                    interpolate4(f, r);
                    for (int k = 0; k < 4; k++)
                        tmp[l][k] = r[k];
                }
                for (int k = 0; k < 4; k++) {     /* along v */
                    double f[4] = { tmp[0][k], tmp[1][k], tmp[2][k], tmp[3][k] }, r[4];
                    interpolate4(f, r);
                    for (int l = 0; l < 4; l++)
                        Bn[l][k][c] = r[l];
                }
            }
            geom_surface s;
            memset(&s, 0, sizeof s);
            s.kind = GEOM_BICUBIC;
            s.nverts = 16;
            for (int l = 0; l < 4; l++)
                for (int k = 0; k < 4; k++)
                    s.verts[4 * l + k] = v3(Bn[l][k][0], Bn[l][k][1], Bn[l][k][2]);
#ifdef SCENE_HAVE_GEOM
            char err[ERR_LEN];
            if (!geom_surface_prepare(&s, err, sizeof err)) {
                rib_error(p, req, req->pos, "piece (%d, %d): %s", b, a, err);
                continue;
            }
#endif
            rib_add_surface(p, req, &s);
        }
    free(ua);
    free(us);
out:
    rib_params_clear(&params);
    free(du.knots);
    free(dv.knots);
}

void rib_trim_curve(rib_parser *p, const rib_request *req)
{
    if (!p->warned_trim)
        rib_warning(p, req, req->pos, "trim curves are not supported: the NuPatches that "
                    "follow are rendered whole");
    p->warned_trim = true;
}
