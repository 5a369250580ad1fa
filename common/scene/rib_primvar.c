/*
 * rib_primvar.c: primitive variables of meshes and patches (see
 * rib_primvar.h; RI Specification 3.2 §5.1).
 *
 * Classes: constant (one value), uniform (one per face or patch), varying
 * (one per point of a mesh, per corner of a patch; interpolated
 * bilinearly), vertex (one per point or control point; on a mesh the same
 * as varying), facevarying (one per face corner of a mesh). Over a mesh
 * triangle the value is the linear interpolation of its corners' values,
 * over a patch the bilinear one of its four corners': both are
 * polynomials of the object's (u,v) (scene_primvar), which the
 * shading language's VM evaluates in every arithmetic (sl_vm_set_varying_*),
 * so a box over a (u,v) range bounds them exactly up to rounding (the
 * linear ones are affine forms of u and v).
 */
#include "scene/rib_primvar.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const class_names[] = {
    "", "constant", "uniform", "varying", "vertex", "facevarying",
};

static bool skipped(const char *name, const char *const *skip)
{
    static const char *const always[] = {"P", "Pw", "Pz", "N", NULL};
    for (int i = 0; always[i]; i++)
        if (strcmp(name, always[i]) == 0) return true;
    for (int i = 0; skip && skip[i]; i++)
        if (strcmp(name, skip[i]) == 0) return true;
    return false;
}

static void add_src(rib_primvars *out, const char *name, const scene_param *pa,
                    scene_class cls, int size, int stride, int offset)
{
    out->v = xrealloc(out->v, (size_t)(out->n + 1) * sizeof *out->v);
    rib_primvar_src *s = &out->v[out->n++];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name);
    s->type = size == 1 ? SL_TYPE_FLOAT : pa->type;
    s->cls = cls;
    s->values = pa->values;
    s->size = size;
    s->stride = stride;
    s->offset = offset;
}

bool rib_primvars_collect(rib_parser *p, const rib_request *req, const rib_params *params,
                          const int counts[SCENE_CLASS_FACEVARYING + 1],
                          const char *const *skip, rib_primvars *out)
{
    memset(out, 0, sizeof *out);
    char ignored[256] = "";
    for (int i = 0; i < params->count; i++) {
        const scene_param *pa = &params->items[i];
        if (skipped(pa->name, skip) || strlen(pa->name) >= 64)
            continue;
        if (out->n + 2 > RIB_MAX_PRIMVARS) {
            rib_error(p, req, pa->pos, "\"%s\": more than %d primitive variables on one "
                      "primitive", pa->name, RIB_MAX_PRIMVARS);
            rib_primvars_clear(out);
            return false;
        }
        bool st = strcmp(pa->name, "st") == 0 && pa->type == SL_TYPE_FLOAT &&
                  pa->arraylen == 2;
        bool ok = pa->values && (pa->type == SL_TYPE_FLOAT || pa->type == SL_TYPE_COLOR ||
                                 pa->type == SL_TYPE_POINT || pa->type == SL_TYPE_VECTOR ||
                                 pa->type == SL_TYPE_NORMAL) && (pa->arraylen == 1 || st);
        if (!ok) {
            size_t used = strlen(ignored);
            snprintf(ignored + used, sizeof ignored - used, "%s\"%s\"", used ? ", " : "",
                     pa->name);
            continue;
        }
        int stride = rib_type_components(pa->type) * pa->arraylen;
        int n = pa->count / stride;
        scene_class cls = pa->cls;
        if (cls != SCENE_CLASS_NONE && counts[cls] != n) {
            if (counts[cls] == 0)
                rib_error(p, req, pa->pos, "\"%s\": class %s is not available on %s", pa->name,
                          class_names[cls], req->name);
            else
                rib_error(p, req, pa->pos, "\"%s\" is %s: it needs %d value%s, got %d",
                          pa->name, class_names[cls], counts[cls], counts[cls] == 1 ? "" : "s",
                          n);
            rib_primvars_clear(out);
            return false;
        }
        static const scene_class order[] = {SCENE_CLASS_VERTEX, SCENE_CLASS_VARYING,
                                            SCENE_CLASS_FACEVARYING, SCENE_CLASS_UNIFORM,
                                            SCENE_CLASS_CONSTANT};
        for (int k = 0; k < 5 && cls == SCENE_CLASS_NONE; k++)
            if (counts[order[k]] == n)
                cls = order[k];
        if (cls == SCENE_CLASS_NONE) {
            rib_error(p, req, pa->pos, "\"%s\" has %d values; give one per vertex (%d), per "
                      "varying point (%d), per face corner (%d), per face (%d) or one", pa->name,
                      n, counts[SCENE_CLASS_VERTEX], counts[SCENE_CLASS_VARYING],
                      counts[SCENE_CLASS_FACEVARYING], counts[SCENE_CLASS_UNIFORM]);
            rib_primvars_clear(out);
            return false;
        }
        if (st) {
            add_src(out, "s", pa, cls, 1, 2, 0);
            add_src(out, "t", pa, cls, 1, 2, 1);
        } else {
            add_src(out, pa->name, pa, cls, rib_type_components(pa->type), stride, 0);
        }
    }
    if (ignored[0])
        rib_warning(p, req, req->pos, "primitive variables %s ignored (strings, matrices "
                    "and arrays other than \"st\" are not handed to shaders)", ignored);
    return true;
}

void rib_primvars_clear(rib_primvars *pv)
{
    free(pv->v);
    pv->v = NULL;
    pv->n = 0;
}

/* The components of variable s at corner c. */
static const double *value_at(const rib_primvar_src *s, const rib_corner *c)
{
    int i = 0;
    switch (s->cls) {
    case SCENE_CLASS_UNIFORM:     i = c->uniform; break;
    case SCENE_CLASS_VARYING:     i = c->varying; break;
    case SCENE_CLASS_VERTEX:      i = c->vertex; break;
    case SCENE_CLASS_FACEVARYING: i = c->facevarying; break;
    default:                      i = 0; break;
    }
    return s->values + (size_t)i * (size_t)s->stride + s->offset;
}

static void start(const rib_primvar_src *s, scene_primvar *o)
{
    memset(o, 0, sizeof *o);
    snprintf(o->name, sizeof o->name, "%s", s->name);
    o->type = s->type;
    o->size = s->size;
}

bool rib_primvars_same_at(const rib_primvars *pv, const rib_corner *c, int n)
{
    for (int k = 0; k < pv->n; k++) {
        const double *a = value_at(&pv->v[k], &c[0]);
        for (int i = 1; i < n; i++) {
            const double *b = value_at(&pv->v[k], &c[i]);
            for (int j = 0; j < pv->v[k].size; j++)
                if (a[j] != b[j]) return false;
        }
    }
    return true;
}

int rib_primvars_st_edge(const rib_primvars *pv, const rib_corner *c, int n)
{
    const rib_primvar_src *vs = NULL, *vt = NULL;
    for (int k = 0; k < pv->n; k++) {
        if (pv->v[k].size != 1) continue;
        if (strcmp(pv->v[k].name, "s") == 0) vs = &pv->v[k];
        else if (strcmp(pv->v[k].name, "t") == 0) vt = &pv->v[k];
    }
    if (!vs || !vt) return 0;
    int best = 0;
    double best_r = -1;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double ds = fabs(*value_at(vs, &c[j]) - *value_at(vs, &c[i]));
        double dt = fabs(*value_at(vt, &c[j]) - *value_at(vt, &c[i]));
        double r = ds + dt > 0 ? fmax(ds, dt) / (ds + dt) : -1;
        if (r > best_r) {               /* the first of equals: a quad keeps 0 */
            best_r = r;
            best = i;
        }
    }
    return best;
}

void rib_primvars_constant(const rib_primvars *pv, const rib_corner *c, scene_primvar *out)
{
    for (int k = 0; k < pv->n; k++) {
        start(&pv->v[k], &out[k]);
        const double *a = value_at(&pv->v[k], c);
        for (int j = 0; j < pv->v[k].size; j++)
            out[k].c[0][j] = a[j];
    }
}

bool rib_primvars_triangle(const rib_primvars *pv, const rib_corner c[3],
                           const double uv[3][2], scene_primvar *out)
{
    /* as the vertex normals (geom/surface_vertex_normal.c): the plane
     * through the three corners' values over their (u,v) */
    double d1u = uv[1][0] - uv[0][0], d1v = uv[1][1] - uv[0][1];
    double d2u = uv[2][0] - uv[0][0], d2v = uv[2][1] - uv[0][1];
    double det = d1u * d2v - d1v * d2u;
    if (!(fabs(det) > 0))
        return false;
    for (int k = 0; k < pv->n; k++) {
        start(&pv->v[k], &out[k]);
        const double *v0 = value_at(&pv->v[k], &c[0]), *v1 = value_at(&pv->v[k], &c[1]),
                     *v2 = value_at(&pv->v[k], &c[2]);
        for (int j = 0; j < pv->v[k].size; j++) {
            double e1 = v1[j] - v0[j], e2 = v2[j] - v0[j];
            double a = (e1 * d2v - e2 * d1v) / det, b = (e2 * d1u - e1 * d2u) / det;
            out[k].c[1][j] = a;             /* u */
            out[k].c[4][j] = b;             /* v */
            out[k].c[0][j] = v0[j] - uv[0][0] * a - uv[0][1] * b;
        }
    }
    return true;
}

bool rib_primvars_polygon(const rib_primvars *pv, const rib_corner *c, const double (*uv)[2],
                          int n, scene_primvar *out)
{
    if (rib_primvars_same_at(pv, c, n)) {
        rib_primvars_constant(pv, &c[0], out);
        return true;
    }
    if (!uv) return false;
    /* the plane of the fan triangle (0, i, i + 1) widest in (u,v) */
    int best = -1;
    double area = 0;
    for (int i = 1; i + 1 < n; i++) {
        double d1u = uv[i][0] - uv[0][0], d1v = uv[i][1] - uv[0][1];
        double d2u = uv[i + 1][0] - uv[0][0], d2v = uv[i + 1][1] - uv[0][1];
        double a = fabs(d1u * d2v - d1v * d2u);
        if (a > area) {
            area = a;
            best = i;
        }
    }
    if (best < 0) return false;
    const rib_corner tc[3] = {c[0], c[best], c[best + 1]};
    const double tuv[3][2] = {{uv[0][0], uv[0][1]},
                              {uv[best][0], uv[best][1]},
                              {uv[best + 1][0], uv[best + 1][1]}};
    if (!rib_primvars_triangle(pv, tc, tuv, out)) return false;
    /* and every corner on that plane */
    for (int k = 0; k < pv->n; k++)
        for (int i = 0; i < n; i++) {
            const double *v = value_at(&pv->v[k], &c[i]);
            for (int j = 0; j < pv->v[k].size; j++) {
                double fit = out[k].c[0][j] + out[k].c[1][j] * uv[i][0] + out[k].c[4][j] * uv[i][1];
                double size = fabs(out[k].c[0][j]) + fabs(out[k].c[1][j]) + fabs(out[k].c[4][j]) +
                              fabs(v[j]);
                if (!(fabs(fit - v[j]) <= 1e-12 * size)) return false;
            }
        }
    return true;
}

void rib_primvars_bilinear(const rib_primvars *pv, const rib_corner c[4], scene_primvar *out)
{
    for (int k = 0; k < pv->n; k++) {
        start(&pv->v[k], &out[k]);
        const double *v00 = value_at(&pv->v[k], &c[0]), *v10 = value_at(&pv->v[k], &c[1]),
                     *v01 = value_at(&pv->v[k], &c[2]), *v11 = value_at(&pv->v[k], &c[3]);
        for (int j = 0; j < pv->v[k].size; j++) {
            out[k].c[0][j] = v00[j];
            out[k].c[1][j] = v10[j] - v00[j];                   /* u */
            out[k].c[4][j] = v01[j] - v00[j];                   /* v */
            out[k].c[5][j] = v11[j] - v10[j] - v01[j] + v00[j]; /* u v */
        }
    }
}

void rib_primvars_mean(const rib_primvars *pv, const rib_corner *c, int n,
                       double out[RIB_MAX_PRIMVARS][3])
{
    for (int k = 0; k < pv->n; k++)
        for (int j = 0; j < 3; j++) {
            double sum = 0;
            for (int i = 0; i < n && j < pv->v[k].size; i++)
                sum += value_at(&pv->v[k], &c[i])[j];
            out[k][j] = j < pv->v[k].size ? sum / n : 0;
        }
}

void rib_primvars_bilinear_values(const rib_primvars *pv,
                                  double vals[4][RIB_MAX_PRIMVARS][3], scene_primvar *out)
{
    for (int k = 0; k < pv->n; k++) {
        start(&pv->v[k], &out[k]);
        for (int j = 0; j < pv->v[k].size; j++) {
            double v00 = vals[0][k][j], v10 = vals[1][k][j], v01 = vals[2][k][j],
                   v11 = vals[3][k][j];
            out[k].c[0][j] = v00;
            out[k].c[1][j] = v10 - v00;
            out[k].c[4][j] = v01 - v00;
            out[k].c[5][j] = v11 - v10 - v01 + v00;
        }
    }
}

void rib_primvars_bicubic(const rib_primvars *pv, const int idx[16], const double mu[16],
                          const double mv[16], scene_primvar *out)
{
    for (int n = 0; n < pv->n; n++) {
        const rib_primvar_src *s = &pv->v[n];
        if (s->cls != SCENE_CLASS_VERTEX) continue;
        start(s, &out[n]);
        for (int j = 0; j < s->size; j++) {
            /* T = Mu G Mv^T; the term of u^a v^b is T[3 - a][3 - b] */
            for (int r = 0; r < 4; r++)
                for (int q = 0; q < 4; q++) {
                    double t = 0;
                    for (int k = 0; k < 4; k++)
                        for (int l = 0; l < 4; l++)
                            t += mu[4 * r + k] * mv[4 * q + l] *
                                 s->values[(size_t)idx[4 * l + k] * (size_t)s->stride +
                                           (size_t)s->offset + (size_t)j];
                    out[n].c[(3 - r) + 4 * (3 - q)][j] = t;
                }
        }
    }
}
