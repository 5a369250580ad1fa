/*
 * scene_mesh.c: a polygon mesh as one scene object (see scene_mesh.h):
 * its shared arrays, its 16-byte pieces, and the piece's base surface made
 * again on demand by the steps rib_mesh.c used to take once per piece.
 */
#include "scene/scene_mesh.h"
#include "scene/rib_parser.h"
#ifdef SCENE_HAVE_GEOM
#include "geom/subdiv.h"
#endif
#include "scene/rib_primvar.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

struct scene_mesh {
    double *P;                     /* npoints * 3, object space */
    int npoints;
    int *idx;                      /* the face-vertices' points, nidx of them */
    int nidx;
    scene_mesh_nclass ncls;
    double *N;                     /* corner normals as ncls says, nN * 3 */
    int nN;
    rib_primvars pv;               /* their values point into `values` */
    double **values;               /* the variables' arrays (owned), nvalues */
    int nvalues;
    size_t values_bytes;
    scene_mesh_piece *pieces;      /* polygon meshes' pieces (cap of them) */
    int32_t *sub_face;             /* a subdivision mesh's: piece k is refined
                                    * face sub_face[k]; NULL once trimmed when
                                    * that is k (every face drawn) */
    int npieces, cap;
    int index;                     /* in scene.meshes (rib_add_mesh) */
    /* a subdivision mesh: the refined mesh, the control faces' corner
     * counts and first face-vertices (nfaces + 1) */
    const struct geom_subdiv *sd;
    int *nverts, *fo;
    int nfaces;
    bool counted;                  /* a check's mesh: pieces counted, no arrays */
};

static void *copy_of(const void *src, size_t bytes)
{
    void *dst = xmalloc(bytes > 0 ? bytes : 1);
    if (bytes > 0) memcpy(dst, src, bytes);
    return dst;
}

/* The mesh of the arrays P, idx and N (taken: the mesh frees them); the
 * variables' arrays are found among params' and copied, or, with `take`
 * (params then writable), moved out of params (their values set NULL). */
static scene_mesh *assemble(double *P, int npoints, int *idx, int nidx, scene_mesh_nclass ncls,
                            double *N, int nN, const rib_primvars *pv, const rib_params *params,
                            rib_params *take)
{
    assert(!take || take == params);
    scene_mesh *self = xcalloc(1, sizeof *self);
    self->P = P;
    self->npoints = npoints;
    self->idx = idx;
    self->nidx = nidx;
    self->ncls = ncls;
    self->N = N;
    self->nN = N ? nN : 0;
    /* the variables: each source points into a parameter's values, which
     * go with the parameters; copy (or take) every parameter array a
     * source uses (st's s and t share one) and point the sources at the
     * mesh's */
    self->pv.n = pv->n;
    self->pv.v = pv->n > 0 ? copy_of(pv->v, (size_t)pv->n * sizeof *pv->v) : NULL;
    self->values = xcalloc((size_t)(params->count > 0 ? params->count : 1), sizeof *self->values);
    for (int k = 0; k < pv->n; k++) {
        rib_primvar_src *v = &self->pv.v[k];
        bool found = v->values == NULL;
        for (int i = 0; i < params->count && !found; i++) {
            const scene_param *pa = &params->items[i];
            if (pa->values != v->values) continue;
            if (!self->values[i]) {
                size_t bytes = (size_t)pa->count * sizeof *pa->values;
                self->values[i] = take ? pa->values : copy_of(pa->values, bytes);
                self->values_bytes += bytes;
            }
            v->values = self->values[i];
            found = true;
        }
        assert(found && "a variable's values are a parameter's");
    }
    for (int i = 0; take && i < params->count; i++)
        if (self->values[i]) take->items[i].values = NULL;
    self->nvalues = params->count;
    return self;
}

scene_mesh *scene_mesh_new(const double *P, int npoints, const int *idx, int nidx,
                           scene_mesh_nclass ncls, const double *N, int nN,
                           const rib_primvars *pv, const rib_params *params)
{
    return assemble(copy_of(P, (size_t)npoints * 3 * sizeof *P), npoints,
                    copy_of(idx, (size_t)nidx * sizeof *idx), nidx, ncls,
                    N ? copy_of(N, (size_t)nN * 3 * sizeof *N) : NULL, nN, pv, params, NULL);
}

scene_mesh *scene_mesh_new_taking(double *P, int npoints, int *idx, int nidx,
                                  scene_mesh_nclass ncls, double *N, int nN,
                                  const rib_primvars *pv, rib_params *params)
{
    return assemble(P, npoints, idx, nidx, ncls, N, nN, pv, params, params);
}

scene_mesh *scene_mesh_new_counted(int nprimvars)
{
    scene_mesh *self = xcalloc(1, sizeof *self);
    self->counted = true;
    self->pv.n = nprimvars;
    return self;
}

void scene_mesh_set_subdiv(scene_mesh *self, const struct geom_subdiv *sd, const int *nverts,
                           int nfaces)
{
    if (self->counted) return;
    self->sd = sd;
    self->nfaces = nfaces;
    self->nverts = copy_of(nverts, (size_t)nfaces * sizeof *nverts);
    self->fo = xmalloc(sizeof *self->fo * (size_t)(nfaces + 1));
    self->fo[0] = 0;
    for (int f = 0; f < nfaces; f++) self->fo[f + 1] = self->fo[f] + nverts[f];
}

const int *scene_mesh_face_offsets(const scene_mesh *self)
{
    assert(self->sd && !self->counted);
    return self->fo;
}

const int *scene_mesh_indices(const scene_mesh *self)
{
    assert(!self->counted);
    return self->idx;
}

void scene_mesh_add_piece(scene_mesh *self, scene_piece_kind kind, int face, int fv0,
                          const int k[3], int ncorners)
{
    if (self->counted) {
        self->npieces++;
        return;
    }
    if (kind == SCENE_PIECE_SUBDIV) {
        /* 4 bytes a piece: its refined face */
        /* (none after scene_mesh_trim, which may drop an identity list) */
        assert(self->sd && !self->pieces && face >= 0 && (self->npieces == 0 || self->sub_face));
        if (self->npieces == self->cap) {
            self->cap = self->cap ? 2 * self->cap : 64;
            self->sub_face = xreallocarray(self->sub_face, (size_t)self->cap, sizeof *self->sub_face);
        }
        self->sub_face[self->npieces++] = face;
        return;
    }
    assert(!self->sub_face);
    if (self->npieces == self->cap) {
        self->cap = self->cap ? 2 * self->cap : 64;
        self->pieces = xreallocarray(self->pieces, (size_t)self->cap, sizeof *self->pieces);
    }
    scene_mesh_piece *pc = &self->pieces[self->npieces++];
    memset(pc, 0, sizeof *pc);
    pc->face = face;
    pc->fv0 = fv0;
    pc->kind = (uint8_t)kind;
    if (kind == SCENE_PIECE_POLYGON) {
        assert(ncorners >= 3 && ncorners <= GEOM_MAX_POLY_VERTS);
        assert(!k || (k[0] >= 0 && k[0] < ncorners));
        pc->k[0] = (uint16_t)ncorners;
        pc->k[1] = (uint16_t)(k ? k[0] : 0);     /* its first corner */
    } else {
        for (int i = 0; i < 3; i++) {
            assert(k[i] >= 0 && k[i] <= UINT16_MAX);
            pc->k[i] = (uint16_t)k[i];
        }
    }
}

void scene_mesh_trim(scene_mesh *self)
{
    if (self->sub_face) {
        bool identity = true;
        for (int k = 0; k < self->npieces && identity; k++) identity = self->sub_face[k] == k;
        if (identity) {
            free(self->sub_face);
            self->sub_face = NULL;
            self->cap = 0;
        } else if (self->npieces < self->cap) {
            self->sub_face = xreallocarray(self->sub_face, (size_t)self->npieces, sizeof *self->sub_face);
            self->cap = self->npieces;
        }
        return;
    }
    if (self->npieces > 0 && self->npieces < self->cap) {
        self->pieces = xreallocarray(self->pieces, (size_t)self->npieces, sizeof *self->pieces);
        self->cap = self->npieces;
    }
}

int scene_mesh_npieces(const scene_mesh *self) { return self->npieces; }
int scene_mesh_index(const scene_mesh *self) { return self->index; }

void scene_mesh_set_index(scene_mesh *self, int index) { self->index = index; }
int scene_mesh_nprimvars(const scene_mesh *self) { return self->pv.n; }

size_t scene_mesh_piece_bytes(const scene_mesh *self)
{
    return (size_t)self->cap * (self->sub_face ? sizeof *self->sub_face : sizeof *self->pieces);
}

size_t scene_mesh_bytes(const scene_mesh *self)
{
    return sizeof *self + (size_t)self->npoints * 3 * sizeof(double) +
           (size_t)self->nidx * sizeof(int) + (size_t)self->nN * 3 * sizeof(double) +
           (size_t)self->pv.n * sizeof(rib_primvar_src) + self->values_bytes +
           scene_mesh_piece_bytes(self) +
           (size_t)(2 * self->nfaces + (self->sd ? 1 : 0)) * sizeof(int);
}

size_t scene_mesh_subdiv_bytes(const scene_mesh *self, size_t *points)
{
    *points = 0;
#ifdef SCENE_HAVE_GEOM
    if (self->sd) return geom_subdiv_bytes(self->sd, points);
#endif
    return 0;
}

void scene_mesh_destroy(scene_mesh **self_p)
{
    scene_mesh *self = *self_p;
    if (!self) return;
    free(self->P);
    free(self->idx);
    free(self->N);
    for (int i = 0; i < self->nvalues; i++) free(self->values[i]);
    free(self->values);
    free(self->pv.v);
    free(self->pieces);
    free(self->sub_face);
    free(self->nverts);
    free(self->fo);
    free(self);
    *self_p = NULL;
}

/* ---- a piece's surface: rib_mesh.c's steps, in the same order ---------- */

static vec3 point_at(const scene_mesh *m, int i)
{
    return v3(m->P[3 * i], m->P[3 * i + 1], m->P[3 * i + 2]);
}

vec3 scene_mesh_corner_normal(scene_mesh_nclass ncls, const double *N, int face,
                              const int *idx, int fv0, int i)
{
    int k = 0;
    switch (ncls) {
    case SCENE_MESH_N_VERTEX:      k = idx[fv0 + i]; break;
    case SCENE_MESH_N_FACEVARYING: k = fv0 + i; break;
    case SCENE_MESH_N_UNIFORM:     k = face; break;
    default:                       k = 0; break;
    }
    return v3(N[3 * k], N[3 * k + 1], N[3 * k + 2]);
}

static rib_corner corner_at(const scene_mesh *m, const scene_mesh_piece *pc, int i)
{
    int v = m->idx[pc->fv0 + i];
    return (rib_corner){pc->face, v, v, pc->fv0 + i};
}

#ifdef SCENE_HAVE_GEOM
/* The variables of refined face f (RenderMan's varying class over the
 * control face): its corners are the control corner, the edge point towards
 * the next corner, the face point and the edge point from the previous
 * corner, turned so that a quad face's children keep its (u,v) directions
 * (geom/subdiv_refine.c). Their values are those of the control corner and
 * the means of the edge's two and of the face's corners: the bilinear
 * interpolation over the control face (facevarying per face corner the
 * same; vertex-class values are interpolated so too, not by the
 * subdivision rules). */
static void refined_face_vars(const scene_mesh *m, int f, scene_primvar *out)
{
    const rib_primvars *vars = &m->pv;
    const int *fo = m->fo, *idx = m->idx;
    int F = geom_subdiv_face_origin(m->sd, f), n = m->nverts[F], k = f - fo[F];
    rib_corner *all = xmalloc(sizeof *all * (size_t)n), c;
    for (int i = 0; i < n; i++) {
        int ci = fo[F] + i;
        all[i] = (rib_corner){F, idx[ci], idx[ci], ci};
    }
    double g[4][RIB_MAX_PRIMVARS][3];
    int here = fo[F] + k, next = fo[F] + (k + 1) % n, prev = fo[F] + (k + n - 1) % n;
    c = (rib_corner){F, idx[here], idx[here], here};
    rib_primvars_mean(vars, &c, 1, g[0]);
    rib_corner e1[2] = {c, {F, idx[next], idx[next], next}};
    rib_primvars_mean(vars, e1, 2, g[1]);
    rib_primvars_mean(vars, all, n, g[2]);
    rib_corner e3[2] = {{F, idx[prev], idx[prev], prev}, c};
    rib_primvars_mean(vars, e3, 2, g[3]);
    int start = n == 4 ? (4 - k) % 4 : 0;
    /* corner j of the refined face sits at (0,0), (1,0), (1,1), (0,1) */
    static const int slot[4] = {0, 1, 3, 2};
    double vals[4][RIB_MAX_PRIMVARS][3];
    for (int j = 0; j < 4; j++)
        memcpy(vals[slot[j]], g[(j + start) % 4], sizeof vals[0]);
    rib_primvars_bilinear_values(vars, vals, out);
    free(all);
}

/* A refined face's surface, and its variables where its control face
 * holds it (as rib_subdiv.c placed one object per face). */
static bool subdiv_piece(const scene_mesh *m, int k, geom_surface *s,
                         struct scene_primvar *vars, int *nvars)
{
    int f = m->sub_face ? m->sub_face[k] : k;
    geom_subdiv_surface(m->sd, f, s);
    int F = geom_subdiv_face_origin(m->sd, f);
    *nvars = 0;
    if (m->pv.n > 0 && F >= 0 && F < m->nfaces && f >= m->fo[F] && f < m->fo[F + 1]) {
        refined_face_vars(m, f, vars);
        *nvars = m->pv.n;
    }
    return true;
}

/* A polygon piece's i-th corner among its face's: it starts at k[1] */
static int polygon_corner(const scene_mesh_piece *pc, int i)
{
    return (pc->k[1] + i) % pc->k[0];
}
#endif

bool scene_mesh_piece_surface(const scene_mesh *self, int k, geom_surface *s,
                              struct scene_primvar *vars, int *nvars)
{
    assert(k >= 0 && k < self->npieces);
    assert(!self->counted && "a checked scene's mesh has no pieces to make");
#ifndef SCENE_HAVE_GEOM
    (void)s, (void)vars, (void)nvars;
    return false;
#else
    if (self->sd) return subdiv_piece(self, k, s, vars, nvars);
    const scene_mesh_piece *pc = &self->pieces[k];
    *nvars = self->pv.n;
    memset(s, 0, sizeof *s);
    s->kind = GEOM_POLYGON;
    char err[ERR_LEN];
    if (pc->kind == SCENE_PIECE_POLYGON) {
        int n = pc->k[0];
        s->nverts = n;
        for (int i = 0; i < n; i++)
            s->verts[i] = point_at(self, self->idx[pc->fv0 + polygon_corner(pc, i)]);
        if (!geom_surface_prepare(s, err, sizeof err)) return false;
        if (self->pv.n > 0) {
            /* constant, or affine in its (u,v) (rib_mesh.c kept it whole) */
            rib_corner c[GEOM_MAX_POLY_VERTS];
            for (int i = 0; i < n; i++) c[i] = corner_at(self, pc, polygon_corner(pc, i));
            const double (*uv)[2] = s->nuv == n ? (const double (*)[2])s->uv : NULL;
            if (!rib_primvars_polygon(&self->pv, c, uv, n, vars)) return false;
        }
        return true;
    }
    s->nverts = 3;
    for (int i = 0; i < 3; i++) s->verts[i] = point_at(self, self->idx[pc->fv0 + pc->k[i]]);
    if (pc->kind == SCENE_PIECE_TRIANGLE_N) {
        s->nvn = 3;
        for (int i = 0; i < 3; i++)
            s->vn[i] = scene_mesh_corner_normal(self->ncls, self->N, pc->face, self->idx,
                                                pc->fv0, pc->k[i]);
    }
    if (!geom_surface_prepare(s, err, sizeof err)) {
        if (pc->kind != SCENE_PIECE_TRIANGLE_N) return false;
        s->nvn = 0;                  /* normals it cannot interpolate: flat */
        if (!geom_surface_prepare(s, err, sizeof err)) return false;
    }
    if (self->pv.n > 0) {
        rib_corner c[3];
        for (int i = 0; i < 3; i++) c[i] = corner_at(self, pc, pc->k[i]);
        if (s->nuv != 3 || !rib_primvars_triangle(&self->pv, c, (const double (*)[2])s->uv, vars))
            return false;
    }
    return true;
#endif
}

bool scene_mesh_piece_outline(const scene_mesh *self, int k, geom_surface *s)
{
    assert(k >= 0 && k < self->npieces);
    assert(!self->counted && "a checked scene's mesh has no pieces to make");
#ifndef SCENE_HAVE_GEOM
    (void)s;
    return false;
#else
    if (self->sd) {
        geom_subdiv_surface(self->sd, self->sub_face ? self->sub_face[k] : k, s);
        return true;
    }
    const scene_mesh_piece *pc = &self->pieces[k];
    s->kind = GEOM_POLYGON;
    s->nvn = 0;
    if (pc->kind == SCENE_PIECE_POLYGON) {
        s->nverts = pc->k[0];
        for (int i = 0; i < s->nverts; i++)
            s->verts[i] = point_at(self, self->idx[pc->fv0 + polygon_corner(pc, i)]);
    } else {
        s->nverts = 3;
        for (int i = 0; i < 3; i++) s->verts[i] = point_at(self, self->idx[pc->fv0 + pc->k[i]]);
    }
    return geom_polygon_basis(s, NULL, 0);
#endif
}
