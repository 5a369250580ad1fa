/*
 * nurbs.c: a NuPatch split into rational Bezier pieces (geom/nurbs.h):
 * the checks of its description, knot insertion by blossoming, and the
 * pieces' weight ranges and hull boxes.
 *
 * Knot insertion: on the knot interval [U_k, U_k+1] of degree p the
 * curve is the polynomial of control points d_{k-p} .. d_k; its Bezier
 * points over a sub-interval [a, b] are the blossom values
 * f(a^(p-i), b^i), i = 0..p, and the blossom is de Boor's algorithm with
 * the parameter of level r replaced by the r-th argument (Ramshaw 1987;
 * inserting a and b p times each, as Boehm's algorithm does, gives the
 * same points). A tensor piece applies it along u to each row of points,
 * then along v to each column of the result, on homogeneous points
 * (w x, w y, w z, w), so the rational patch is converted exactly (up to
 * the rounding of the new points, which then define the surface).
 */
#include "geom/nurbs_internal.h"
#include "geom/surface_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The blossom f(args[0..p)) of the degree-p polynomial of span k of
 * knots U, control points d[0..p] (4 numbers each, d[0] = point k-p). */
static void blossom(const double *U, int k, int p, const double *d, const double *args,
                    double out[4])
{
    double w[GEOM_NURBS_MAX_ORDER][4];
    memcpy(w, d, (size_t)(p + 1) * sizeof w[0]);
    for (int r = 1; r <= p; r++)
        for (int i = p; i >= r; i--) {        /* w[i] holds d_{k-p+i} */
            int gi = k - p + i;
            double a = (args[r - 1] - U[gi]) / (U[gi + p + 1 - r] - U[gi]);
            for (int c = 0; c < 4; c++)
                w[i][c] = (1 - a) * w[i - 1][c] + a * w[i][c];
        }
    memcpy(out, w[p], sizeof w[p]);
}

/* The Bezier points of span k over [a, b]: out[i], i = 0..p. */
static void bezier_points(const double *U, int k, int p, const double *d, double a, double b,
                          double out[][4])
{
    double args[GEOM_NURBS_MAX_ORDER];
    for (int i = 0; i <= p; i++) {
        for (int r = 0; r < p; r++)
            args[r] = r < p - i ? a : b;
        blossom(U, k, p, d, args, out[i]);
    }
}

typedef struct dir {
    int n, order;
    const double *U;
    double lo, hi;
} dir;

static bool check_dir(const dir *d, const char *w, char *err, size_t errsz)
{
    if (d->order < 2 || d->order > GEOM_NURBS_MAX_ORDER)
        return err_set(err, errsz, "%sorder must be 2 to %d, got %d", w,
                         GEOM_NURBS_MAX_ORDER, d->order);
    if (d->n < d->order)
        return err_set(err, errsz, "n%s must be at least %sorder (%d), got %d", w, w,
                         d->order, d->n);
    for (int j = 0; j < d->n + d->order; j++)
        if (!isfinite(d->U[j]) || (j > 0 && d->U[j] < d->U[j - 1]))
            return err_set(err, errsz, "%sknot must be finite and nondecreasing (entry "
                             "%d is %g)", w, j, d->U[j]);
    if (!(d->lo < d->hi && d->lo >= d->U[d->order - 1] && d->hi <= d->U[d->n]))
        return err_set(err, errsz, "%smin %smax must satisfy %g <= %smin < %smax <= %g, "
                         "got %g %g", w, w, d->U[d->order - 1], w, w, d->U[d->n], d->lo, d->hi);
    return true;
}

/* The intervals of d inside [lo, hi]: ends a[], b[] and spans. */
static int intervals(const dir *d, double *a, double *b, int *span)
{
    int count = 0;
    for (int k = d->order - 1; k < d->n; k++) {
        double x0 = fmax(d->U[k], d->lo), x1 = fmin(d->U[k + 1], d->hi);
        if (!(x0 < x1))
            continue;
        a[count] = x0, b[count] = x1, span[count] = k;
        count++;
    }
    return count;
}

/* Weights, hull box; false when the projected points lie on one line. */
static bool finish_piece(geom_nurbs_piece *pc)
{
    int n = pc->ku * pc->kv;
    pc->wmin = INFINITY, pc->wmax = -INFINITY;
    vec3 p0 = v3(0, 0, 0);
    double size = 0, area = 0;
    vec3 *q = xmalloc((size_t)n * sizeof *q);
    for (int i = 0; i < n; i++) {
        const double *h = pc->H + 4 * i;
        pc->wmin = fmin(pc->wmin, h[3]), pc->wmax = fmax(pc->wmax, h[3]);
        for (int c = 0; c < 3; c++) {
            ia_interval x = ia_div(ia_point(h[c]), ia_point(h[3]));
            pc->hull[c] = i == 0 ? x : ia_hull(pc->hull[c], x);
        }
        q[i] = v3(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
        if (i == 0) p0 = q[0];
        size = fmax(size, v3_length(v3_sub(q[i], p0)));
    }
    for (int i = 1; i < n; i++)
        for (int j = i + 1; j < n; j++)
            area = fmax(area, v3_length(v3_cross(v3_sub(q[i], p0), v3_sub(q[j], p0))));
    free(q);
    return pc->wmin > 0 && isfinite(pc->wmax) && isfinite(size) && area > 1e-12 * size * size;
}

geom_nurbs *geom_nurbs_new(const geom_nurbs_desc *desc, char *err, size_t errsz)
{
    dir du = { desc->nu, desc->uorder, desc->uknot, desc->umin, desc->umax };
    dir dv = { desc->nv, desc->vorder, desc->vknot, desc->vmin, desc->vmax };
    if (!check_dir(&du, "u", err, errsz) || !check_dir(&dv, "v", err, errsz))
        return NULL;
    if ((double)du.n * dv.n > 1e7) {
        err_set(err, errsz, "at most 10000000 control points, got %d x %d", du.n, dv.n);
        return NULL;
    }
    for (int i = 0; i < du.n * dv.n; i++) {
        const double *h = desc->Pw + 4 * i;
        if (!isfinite(h[0]) || !isfinite(h[1]) || !isfinite(h[2]) || !isfinite(h[3])) {
            err_set(err, errsz, "control point %d is not finite", i);
            return NULL;
        }
        if (!(h[3] > 0)) {
            err_set(err, errsz, "control point %d has weight %g: every weight must be "
                      "> 0", i, h[3]);
            return NULL;
        }
        if (!(fabs(h[0] / h[3]) < 1e150 && fabs(h[1] / h[3]) < 1e150 &&
              fabs(h[2] / h[3]) < 1e150)) {
            err_set(err, errsz, "control point %d is too large", i);
            return NULL;
        }
    }
    int p = du.order - 1, q = dv.order - 1;
    double *ua = xmalloc(2 * (size_t)(du.n + dv.n) * sizeof *ua);
    double *ub = ua + du.n, *va = ub + du.n, *vb = va + dv.n;
    int *us = xmalloc((size_t)(du.n + dv.n) * sizeof *us), *vs = us + du.n;
    int nui = intervals(&du, ua, ub, us), nvi = intervals(&dv, va, vb, vs);
    if ((double)nui * nvi * 4 * du.order * dv.order > GEOM_NURBS_MAX_NET) {
        err_set(err, errsz, "%d x %d pieces of orders %d x %d are too many: their nets "
                  "would hold more than %d numbers (split the patch)", nui, nvi, du.order,
                  dv.order, GEOM_NURBS_MAX_NET);
        free(ua), free(us);
        return NULL;
    }
    geom_nurbs *self = xmalloc(sizeof *self);
    self->npieces = nui * nvi;
    self->pieces = xmalloc((size_t)self->npieces * sizeof *self->pieces);
    size_t per = 4 * (size_t)du.order * (size_t)dv.order;
    self->H = xmalloc((size_t)self->npieces * per * sizeof *self->H);
    double (*rows)[4] = xmalloc((size_t)dv.order * du.order * sizeof *rows);
    double d[GEOM_NURBS_MAX_ORDER][4], out[GEOM_NURBS_MAX_ORDER][4];
    for (int b = 0; b < nvi; b++)
        for (int a = 0; a < nui; a++) {
            int k = b * nui + a;
            geom_nurbs_piece *pc = &self->pieces[k];
            double *H = self->H + (size_t)k * per;
            /* along u: rows[j][i], j over the v span's points */
            for (int j = 0; j <= q; j++) {
                int row = vs[b] - q + j;
                for (int i = 0; i <= p; i++)
                    memcpy(d[i], desc->Pw + 4 * ((size_t)row * du.n + us[a] - p + i), sizeof d[i]);
                bezier_points(du.U, us[a], p, &d[0][0], ua[a], ub[a], out);
                memcpy(rows[j * du.order], out, (size_t)du.order * sizeof out[0]);
            }
            /* along v, column by column */
            for (int i = 0; i <= p; i++) {
                for (int j = 0; j <= q; j++)
                    memcpy(d[j], rows[j * du.order + i], sizeof d[j]);
                bezier_points(dv.U, vs[b], q, &d[0][0], va[b], vb[b], out);
                for (int j = 0; j <= q; j++)
                    memcpy(H + 4 * (j * du.order + i), out[j], sizeof out[j]);
            }
            pc->ku = du.order, pc->kv = dv.order, pc->H = H;
            pc->u0 = ua[a], pc->u1 = ub[a], pc->v0 = va[b], pc->v1 = vb[b];
            if (!finish_piece(pc)) {
                err_set(err, errsz, "piece (%d, %d) over u [%g, %g], v [%g, %g] is "
                          "degenerate: its points lie on one line", a, b, ua[a], ub[a], va[b],
                          vb[b]);
                free(rows), free(ua), free(us);
                geom_nurbs_destroy(&self);
                return NULL;
            }
        }
    free(rows);
    free(ua);
    free(us);
    return self;
}

void geom_nurbs_destroy(geom_nurbs **self_p)
{
    geom_nurbs *self = *self_p;
    if (!self)
        return;
    free(self->pieces);
    free(self->H);
    free(self);
    *self_p = NULL;
}

int geom_nurbs_npieces(const geom_nurbs *self)
{
    return self->npieces;
}

void geom_nurbs_surface(const geom_nurbs *self, int k, geom_surface *out)
{
    memset(out, 0, sizeof *out);
    out->kind = GEOM_NURBS;
    out->nurbs = self;
    out->nurbs_piece = k;
}

void geom_nurbs_piece_range(const geom_nurbs *self, int k, double *u0, double *u1,
                            double *v0, double *v1)
{
    const geom_nurbs_piece *pc = &self->pieces[k];
    *u0 = pc->u0, *u1 = pc->u1, *v0 = pc->v0, *v1 = pc->v1;
}
