/*
 * rib_patch.c: bicubic patches and patch meshes (RI Specification 3.2
 * §5.3): Basis, Patch "bicubic", PatchMesh "bilinear" / "bicubic" with
 * "periodic" / "nonperiodic" wrapping in u and v.
 *
 * Every bicubic patch, whatever its basis, becomes one GEOM_BICUBIC (a
 * Bezier patch, common/geom/surface_bicubic.c): with the basis matrices Mu,
 * Mv (P(u,v) = U Mu G Mv^T V^T, U = [u^3 u^2 u 1]) and the Bezier matrix
 * Mb, the Bezier net is B = (Mb^-1 Mu) G (Mb^-1 Mv)^T, computed here in
 * double; the Bezier net is then the surface's definition (what the
 * enclosures bound). Each patch of a bilinear PatchMesh is one GEOM_PATCH.
 * Each patch has its own (u,v) in [0,1]^2.
 */
#include "scene/rib_parser.h"
#include "scene/rib_primvar.h"
#include "sl/strbuf.h"
#include "util/err.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* RI Spec 3.2 §4.2 (Basis): the standard bases and their steps. */
static const struct basis_def {
    const char *name;
    double m[16];
    int step;
} bases[] = {
    { "bezier", { -1, 3, -3, 1,  3, -6, 3, 0,  -3, 3, 0, 0,  1, 0, 0, 0 }, 3 },
    { "b-spline", { -1 / 6.0, 3 / 6.0, -3 / 6.0, 1 / 6.0,  3 / 6.0, -6 / 6.0, 3 / 6.0, 0,
                    -3 / 6.0, 0, 3 / 6.0, 0,  1 / 6.0, 4 / 6.0, 1 / 6.0, 0 }, 1 },
    { "catmull-rom", { -0.5, 1.5, -1.5, 0.5,  1, -2.5, 2, -0.5,  -0.5, 0, 0.5, 0,
                       0, 1, 0, 0 }, 1 },
    { "hermite", { 2, 1, -2, 1,  -3, -2, 3, -1,  0, 1, 0, 0,  1, 0, 0, 0 }, 2 },
    { "power", { 1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1 }, 4 },
};

void rib_basis_default(double m[16], int *step)
{
    memcpy(m, bases[0].m, sizeof bases[0].m);
    *step = bases[0].step;
}

/* One basis argument (a name or 16 numbers) at index *i, then its step. */
static bool read_basis(rib_parser *p, const rib_request *req, int *i, const char *which,
                       double m[16], int *step)
{
    if (*i >= req->nargs) {
        rib_error(p, req, req->pos, "missing the %s basis (a name or 16 numbers)", which);
        return false;
    }
    const rib_arg *arg = &req->args[*i];
    if (rib_arg_is_string(arg)) {
        const char *name = rib_arg_string(req, arg);
        int k = -1;
        for (int b = 0; b < (int)(sizeof bases / sizeof bases[0]); b++)
            if (strcmp(name, bases[b].name) == 0)
                k = b;
        if (k < 0) {
            rib_error(p, req, arg->pos, "unknown %s basis \"%s\" (expected \"bezier\", "
                      "\"b-spline\", \"catmull-rom\", \"hermite\", \"power\" or 16 numbers)",
                      which, name);
            return false;
        }
        memcpy(m, bases[k].m, sizeof bases[k].m);
    } else {
        int n;
        const double *v = rib_arg_numbers(req, arg, &n);
        if (n != 16) {
            rib_error(p, req, arg->pos, "the %s basis matrix needs 16 numbers, got %d",
                      which, n);
            return false;
        }
        for (int k = 0; k < 16; k++)
            if (!isfinite(v[k])) {
                rib_error(p, req, arg->pos, "the %s basis matrix is not finite", which);
                return false;
            }
        memcpy(m, v, 16 * sizeof *v);
    }
    (*i)++;
    double s;
    if (*i >= req->nargs || !rib_arg_is_numeric(&req->args[*i])) {
        rib_error(p, req, req->pos, "missing the %s step after the %s basis", which, which);
        return false;
    }
    int n;
    const double *steps = rib_arg_numbers(req, &req->args[*i], &n);
    s = n == 1 ? steps[0] : 0;              /* "[]" has no numbers at all */
    if (n != 1 || !(s == floor(s) && s >= 1 && s <= 4)) {
        rib_error(p, req, req->args[*i].pos, "the %s step must be a whole number from 1 to 4",
                  which);
        return false;
    }
    *step = (int)s;
    (*i)++;
    return true;
}

void rib_basis(rib_parser *p, const rib_request *req)
{
    double um[16], vm[16];
    int us, vs, i = 0;
    if (!read_basis(p, req, &i, "u", um, &us) || !read_basis(p, req, &i, "v", vm, &vs) ||
        !rib_no_more_args(p, req, i))
        return;
    memcpy(p->attr.ubasis, um, sizeof um);
    memcpy(p->attr.vbasis, vm, sizeof vm);
    p->attr.ustep = us;
    p->attr.vstep = vs;
}

/* T = Mb^-1 M: maps a basis' geometry to Bezier control points. */
static void to_bezier(const double m[16], double t[16])
{
    static const double mb_inv[16] = { 0, 0, 0, 1,  0, 0, 1 / 3.0, 1,  0, 1 / 3.0, 2 / 3.0, 1,
                                       1, 1, 1, 1 };
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += mb_inv[4 * r + k] * m[4 * k + c];
            t[4 * r + c] = s;
        }
}

bool rib_patch_primvars(rib_parser *p, const rib_request *req, const rib_params *params,
                        const int counts[6], bool cubic, rib_primvars *out)
{
    (void)cubic;           /* bicubic vertex-class values: add_bicubic */
    return rib_primvars_collect(p, req, params, counts, NULL, out);
}

void rib_patch_vars(rib_parser *p, const rib_primvars *pv, int uniform, int pu, int pv_,
                    int nuvar, int nvvar, const int *vtx, scene_primvar *out)
{
    rib_corner c[4];
    for (int i = 0; i < 4; i++) {
        int du = i & 1, dv = i >> 1;
        c[i].uniform = uniform;
        c[i].varying = ((pv_ + dv) % nvvar) * nuvar + (pu + du) % nuvar;
        c[i].vertex = vtx ? vtx[i] : 0;
        c[i].facevarying = 0;
    }
    rib_primvars_bilinear(pv, c, out);
    p->surface_vars = out;
    p->nsurface_vars = pv->n;
}

/* Adds the bicubic patch whose geometry G[k][l] (u index k, v index l) is
 * point idx[4 l + k] of P (with the variables set by rib_patch_vars, its
 * vertex-class ones, of pv, into vars, interpolated with the basis as P
 * is). */
static void add_bicubic(rib_parser *p, const rib_request *req, const double *P,
                        const int idx[16], sl_pos at, const rib_primvars *pv,
                        scene_primvar *vars)
{
    if (pv && pv->n > 0)
        rib_primvars_bicubic(pv, idx, p->attr.ubasis, p->attr.vbasis, vars);
    double tu[16], tv[16];
    to_bezier(p->attr.ubasis, tu);
    to_bezier(p->attr.vbasis, tv);
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_BICUBIC;
    s.nverts = 16;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            double b[3] = { 0, 0, 0 };
            for (int l = 0; l < 4; l++)
                for (int k = 0; k < 4; k++) {
                    double w = tu[4 * i + k] * tv[4 * j + l];
                    if (w == 0)
                        continue;
                    const double *q = P + 3 * idx[4 * l + k];
                    for (int c = 0; c < 3; c++)
                        b[c] += w * q[c];
                }
            s.verts[4 * j + i] = v3(b[0], b[1], b[2]);
        }
#ifdef SCENE_HAVE_GEOM
    char err[ERR_LEN];
    if (!geom_surface_prepare(&s, err, sizeof err)) {
        rib_error(p, req, at, "%s", err);
        return;
    }
#else
    (void)at;
#endif
    rib_add_surface(p, req, &s);
}

/* Patch "bicubic" "P" [16 points] (rib_patch hands it over). */
void rib_patch_bicubic(rib_parser *p, const rib_request *req, const scene_param *P,
                       rib_primvars *pv)
{
    if (P->count != 48) {
        rib_error(p, req, P->pos, "a bicubic patch needs 16 points in \"P\" (48 numbers), got "
                  "%d numbers", P->count);
        return;
    }
    int idx[16];
    for (int k = 0; k < 16; k++)
        idx[k] = k;
    scene_primvar vars[RIB_MAX_PRIMVARS];
    if (pv)
        rib_patch_vars(p, pv, 0, 0, 0, 2, 2, NULL, vars);
    add_bicubic(p, req, P->values, idx, req->pos, pv, vars);
    p->surface_vars = NULL;
    p->nsurface_vars = 0;
}

static bool read_wrap(rib_parser *p, const rib_request *req, int i, const char *which,
                      bool *periodic)
{
    const char *w = rib_read_string(p, req, i, which);
    if (!w)
        return false;
    if (strcmp(w, "periodic") == 0 || strcmp(w, "nonperiodic") == 0) {
        *periodic = w[0] == 'p';
        return true;
    }
    rib_error(p, req, req->args[i].pos, "%s must be \"periodic\" or \"nonperiodic\", got \"%s\"",
              which, w);
    return false;
}

/* The patches along one direction: n points, step, cubic or linear. */
static int count_patches(rib_parser *p, const rib_request *req, sl_pos at, const char *which,
                         int n, bool periodic, bool cubic, int step)
{
    int order = cubic ? 4 : 2;
    if (!cubic)
        step = 1;
    if (periodic) {
        if (n < order || n % step != 0) {
            rib_error(p, req, at, "a periodic %s direction needs at least %d points and a "
                      "multiple of the step %d, got %d", which, order, step, n);
            return -1;
        }
        return n / step;
    }
    if (n < order || (n - order) % step != 0) {
        rib_error(p, req, at, "a nonperiodic %s direction needs %d + k*%d points (the step), "
                  "got %d", which, order, step, n);
        return -1;
    }
    return (n - order) / step + 1;
}

bool rib_read_patch_type(rib_parser *p, const rib_request *req, bool *cubic)
{
    const char *type = rib_read_string(p, req, 0, "the patch type");
    if (!type)
        return false;
    *cubic = strcmp(type, "bicubic") == 0;
    if (!*cubic && strcmp(type, "bilinear") != 0) {
        rib_error(p, req, req->args[0].pos, "unknown patch type \"%s\" (expected \"bilinear\" "
                  "or \"bicubic\")", type);
        return false;
    }
    return true;
}

/* PatchMesh type nu uwrap nv vwrap "P" [...] */
void rib_patch_mesh(rib_parser *p, const rib_request *req)
{
    bool cubic;
    if (!rib_read_patch_type(p, req, &cubic))
        return;
    double nu, nv;
    bool uper, vper;
    if (rib_read_numbers(p, req, 1, 1, &nu, "the number of points in u") < 0 ||
        !read_wrap(p, req, 2, "uwrap", &uper) ||
        rib_read_numbers(p, req, 3, 1, &nv, "the number of points in v") < 0 ||
        !read_wrap(p, req, 4, "vwrap", &vper))
        return;
    if (!(nu == floor(nu) && nu >= 1 && nv == floor(nv) && nv >= 1 && nu * nv <= 1e7)) {
        rib_error(p, req, req->args[1].pos, "the point counts must be whole numbers with at "
                  "most 10000000 points in all, got %g x %g", nu, nv);
        return;
    }
    int nupatch = count_patches(p, req, req->args[1].pos, "u", (int)nu, uper, cubic,
                                p->attr.ustep);
    int nvpatch = nupatch < 0 ? -1 : count_patches(p, req, req->args[3].pos, "v", (int)nv,
                                                    vper, cubic, p->attr.vstep);
    if (nvpatch < 0)
        return;
    rib_params params;
    if (!rib_params_read(p, req, 5, RIB_PARAMS_VARYING, &params))
        return;
    const scene_param *P = rib_params_points(p, req, &params);
    if (!P)
        ;                              /* reported */
    else if (P->count / 3 != (int)nu * (int)nv)
        rib_error(p, req, P->pos, "\"P\" needs %d x %d = %d points, got %d", (int)nu, (int)nv,
                  (int)nu * (int)nv, P->count / 3);
    else {
        int NU = (int)nu, NV = (int)nv;
        int su = cubic ? p->attr.ustep : 1, sv = cubic ? p->attr.vstep : 1;
        int nuvar = uper ? nupatch : nupatch + 1, nvvar = vper ? nvpatch : nvpatch + 1;
        int counts[] = { 0, 1, nupatch * nvpatch, nuvar * nvvar, NU * NV, 0 };
        rib_primvars vars;
        scene_primvar pvars[RIB_MAX_PRIMVARS];
        if (!rib_patch_primvars(p, req, &params, counts, cubic, &vars)) {
            rib_params_clear(&params);
            return;
        }
        for (int pv = 0; pv < nvpatch; pv++)
            for (int pu = 0; pu < nupatch; pu++) {
                if (cubic) {
                    int idx[16];
                    for (int l = 0; l < 4; l++)
                        for (int k = 0; k < 4; k++)
                            idx[4 * l + k] = ((pv * sv + l) % NV) * NU + (pu * su + k) % NU;
                    rib_patch_vars(p, &vars, pv * nupatch + pu, pu, pv, nuvar, nvvar, NULL, pvars);
                    add_bicubic(p, req, P->values, idx, req->pos, &vars, pvars);
                    continue;
                }
                int u0 = pu, u1 = (pu + 1) % NU, v0 = pv, v1 = (pv + 1) % NV;
                int corner[4] = { v0 * NU + u0, v0 * NU + u1, v1 * NU + u0, v1 * NU + u1 };
                geom_surface s;
                memset(&s, 0, sizeof s);
                s.kind = GEOM_PATCH;
                s.nverts = 4;
                for (int c = 0; c < 4; c++)
                    s.verts[c] = v3(P->values[3 * corner[c]], P->values[3 * corner[c] + 1],
                                    P->values[3 * corner[c] + 2]);
#ifdef SCENE_HAVE_GEOM
                char err[ERR_LEN];
                if (!geom_surface_prepare(&s, err, sizeof err)) {
                    rib_error(p, req, req->pos, "patch (%d, %d): %s", pu, pv, err);
                    continue;
                }
#endif
                rib_patch_vars(p, &vars, pv * nupatch + pu, pu, pv, nuvar, nvvar, corner, pvars);
                rib_add_surface(p, req, &s);
            }
        p->surface_vars = NULL;
        p->nsurface_vars = 0;
        rib_primvars_clear(&vars);
    }
    rib_params_clear(&params);
}
