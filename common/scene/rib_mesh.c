/*
 * rib_mesh.c: polygon meshes (RI Specification 3.2 §5.1): PointsPolygons
 * (convex faces sharing points), PointsGeneralPolygons (faces that may
 * be concave and hold holes: loops of points, the outer one first) and
 * GeneralPolygon (one such face with its own points).
 *
 * PointsPolygons and PointsGeneralPolygons are each ONE scene object
 * (issue 23): their arrays are kept once in a scene_mesh and each piece
 * below is a 16-byte record there, its surface made again on demand
 * (scene_mesh.c follows the same steps as add_triangle and add_face here).
 * GeneralPolygon and a Polygon with variables add one object per piece.
 *
 * Each face becomes base surfaces of common/geom: a convex planar face is
 * one GEOM_POLYGON (its parametrisation is the polygon's own, docs/
 * geometry.md); a concave, holed or non-planar face, or one with more than
 * GEOM_MAX_POLY_VERTS points, is cut into triangles (geom/triangulate.h),
 * each a GEOM_POLYGON. Faces without area are skipped, with one warning
 * per request.
 *
 * Normals (crack-free displacement, issue 14): PointsPolygons and
 * PointsGeneralPolygons give every face corner a normal: the "N" primitive
 * variable where present (vertex/varying, facevarying, uniform or constant,
 * told apart by its count: one per point, per face corner, per face, or
 * one), else the area-weighted average of the (Newell) normals of the faces
 * around the point. A face whose corner normals all equal its own normal
 * stays one flat polygon; any other is cut into triangles that carry their
 * corner normals (geom_vertex_normal), so N is continuous across shared
 * edges and a shader displacing along N opens no crack. GeneralPolygon uses
 * a given "N" only.
 *
 * Other primitive variables ("st", "Cs", user-declared; every class) go
 * with each surface (rib_primvar.c): a face whose variables differ at its
 * corners is cut into triangles too, over each of which they are linear
 * (flat ones, without corner normals, where the face is flat), unless the
 * face is flat and they are affine in its (u,v) ("st" across a wall of
 * quads): then it stays one polygon with them linear over it.
 * A Polygon with variables is read as a one-face mesh (rib_polygon_vars).
 *
 * Threads (issue 23): a large PointsPolygons or PointsGeneralPolygons mesh
 * has its faces prepared over the parser's threads (p->threads, a worker's:
 * scene_parse_frame_threads), in chunks of contiguous faces that the
 * threads take as they come free. Each chunk logs what its faces did (a
 * piece, a face without area, an error's message) and the logs are played
 * back in face order, stopping where one thread would have stopped (the
 * diagnostics full): the same pieces, the same messages in the same order,
 * for any number of threads.
 */
#include "scene/rib_parser.h"
#include "scene/rib_primvar.h"
#include "sl/strbuf.h"

#ifdef SCENE_HAVE_GEOM
#include "geom/triangulate.h"
#include "util/err.h"
#include "util/shares.h"
#include "util/xalloc.h"
#endif

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { RIB_MAX_FACE_POINTS = 10000 };

static long sum(const int *v, int n)
{
    long s = 0;
    for (int i = 0; i < n; i++)
        s += v[i];
    return s;
}

/* How a mesh's "N" is given (or computed: MESH_N_VERTEX). */
typedef scene_mesh_nclass mesh_nclass;
#define MESH_N_NONE SCENE_MESH_N_NONE
#define MESH_N_VERTEX SCENE_MESH_N_VERTEX
#define MESH_N_FACEVARYING SCENE_MESH_N_FACEVARYING
#define MESH_N_UNIFORM SCENE_MESH_N_UNIFORM
#define MESH_N_CONSTANT SCENE_MESH_N_CONSTANT

/* What a face did, logged by a chunk of the faces (threads) to be played
 * back in face order: 20 bytes (a piece's corners fit 16 bits, as in
 * scene_mesh_piece). */
typedef enum { FACE_PIECE, FACE_SKIPPED, FACE_ERROR } face_event_kind;

typedef struct face_event {
    int face, fv0;
    uint16_t k[3];                 /* FACE_PIECE: scene_mesh_add_piece's */
    uint8_t n;
    uint8_t what;                  /* face_event_kind */
    uint8_t kind;                  /* FACE_PIECE: its scene_piece_kind */
    bool has_k;
} face_event;

typedef struct face_log {
    face_event *ev;
    size_t n, cap;
    char **msgs;                   /* the FACE_ERROR events' messages, in order */
    size_t nmsgs;
} face_log;

/* A mesh being cut into surfaces. */
typedef struct mesh {
    const rib_request *req;
    const double *P;               /* npoints * 3 */
    int npoints;
    int skipped;                   /* faces without area */
    sl_pos vertices_pos;
    mesh_nclass ncls;              /* corner normals: none, or N as the class says */
    const double *N;
    int fv0;                       /* the current face's first face-vertex */
    rib_primvars pv;               /* the other primitive variables */
    scene_mesh *out;               /* PointsPolygons, PointsGeneralPolygons: the
                                    * pieces go here (one object, issue 23);
                                    * NULL: one object each */
    geom_surface *scratch;         /* with out: the one surface every face and
                                    * piece is prepared in (polygon_surface) */
    face_log *log;                 /* a share's (threads): what the faces did
                                    * goes here; NULL: to out, skipped, p */
} mesh;

static face_event *log_event(const mesh *m, int face, face_event_kind what)
{
    face_log *l = m->log;
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 1024;
        l->ev = xreallocarray(l->ev, l->cap, sizeof *l->ev);
    }
    face_event *e = &l->ev[l->n++];
    memset(e, 0, sizeof *e);
    e->face = face;
    e->fv0 = m->fv0;
    e->what = (uint8_t)what;
    return e;
}

/* scene_mesh_add_piece(m->out, ...) for the current face, or its log entry */
static void add_piece(const mesh *m, scene_piece_kind kind, int face, const int k[3], int n)
{
    if (!m->log) {
        scene_mesh_add_piece(m->out, kind, face, m->fv0, k, n);
        return;
    }
    face_event *e = log_event(m, face, FACE_PIECE);
    e->kind = (uint8_t)kind;
    e->n = (uint8_t)n;             /* 3, or a whole face's <= GEOM_MAX_POLY_VERTS */
    e->has_k = k != NULL;
    if (k)                         /* corners of a face of <= RIB_MAX_FACE_POINTS */
        for (int i = 0; i < 3; i++) e->k[i] = (uint16_t)k[i];
}

/* a face without area */
static void skip_face(mesh *m, int face)
{
    if (m->log)
        log_event(m, face, FACE_SKIPPED);
    else
        m->skipped++;
}

/* rib_error at the mesh's vertices, or its log entry */
static void face_error(rib_parser *p, const mesh *m, int face, const char *fmt, ...)
{
    char msg[2048];                /* rib_error's own bound */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (m->log) {
        face_log *l = m->log;
        log_event(m, face, FACE_ERROR);
        l->msgs = xreallocarray(l->msgs, l->nmsgs + 1, sizeof *l->msgs);
        l->msgs[l->nmsgs++] = xstrdup(msg);
    } else
        rib_error(p, m->req, m->vertices_pos, "%s", msg);
}

/* Corner i of face `face` (point idx[i]) in the variables' classes. */
static rib_corner corner_of(const mesh *m, int face, const int *idx, int i)
{
    return (rib_corner){face, idx[i], idx[i], m->fv0 + i};
}

/* rib_add_surface with the variables pv_out[0..m->pv.n) */
static void add_with_vars(rib_parser *p, const mesh *m, const geom_surface *s,
                          const scene_primvar *vars)
{
    p->surface_vars = vars;
    p->nsurface_vars = m->pv.n;
    rib_add_surface(p, m->req, s);
    p->surface_vars = NULL;
    p->nsurface_vars = 0;
}

static vec3 point(const mesh *m, int i)
{
    return v3(m->P[3 * i], m->P[3 * i + 1], m->P[3 * i + 2]);
}

/* The surface to prepare a polygon of n corners in, its corners still to
 * be set. A surface that becomes an object is *local, zeroed. A mesh's
 * (m->out) is kept nowhere: only whether it prepares, its normal and its
 * (u,v) are read, so every face and piece of the mesh is prepared in the
 * one scratch surface, zeroed once (a geom_surface is ~4.9 KB; zeroing
 * one per face and per piece was ~8 % of the parse of a million quads).
 * That is the same surface to the prepare: it reads only what is set here
 * and the corners (and corner normals when nvn > 0), and derives the rest
 * anew (geom_surface_prepare). */
static geom_surface *polygon_surface(const mesh *m, geom_surface *local, int n)
{
    geom_surface *s = m->scratch;
    if (!s) {
        memset(local, 0, sizeof *local);
        s = local;
    }
    s->kind = GEOM_POLYGON;
    s->nverts = n;
    s->nvn = 0;
    return s;
}

#ifdef SCENE_HAVE_GEOM
/* geom_surface_prepare of a face or piece s; a mesh's (m->out) keeps no
 * surface and reads only whether it is accepted, its normal and (u,v):
 * geom_polygon_check, without the enclosures of Ng the prepare adds */
static bool prepare(const mesh *m, geom_surface *s, char *err, size_t errsz)
{
    return m->out && s->nvn == 0 ? geom_polygon_check(s, err, errsz)
                                 : geom_surface_prepare(s, err, errsz);
}
#endif

/* The normal of corner i of the current face (point idx[i]). */
static vec3 corner_normal(const mesh *m, int face, const int *idx, int i)
{
    int k = 0;
    switch (m->ncls) {
    case MESH_N_VERTEX:      k = idx[i]; break;
    case MESH_N_FACEVARYING: k = m->fv0 + i; break;
    case MESH_N_UNIFORM:     k = face; break;
    default:                 k = 0; break;
    }
    return v3(m->N[3 * k], m->N[3 * k + 1], m->N[3 * k + 2]);
}

/* Adds the triangle of corners k[0..3) of face `face` (points idx[k[i]])
 * with corner normals n (NULL: none) and the face's variables; false when
 * it has no area. */
static bool add_triangle(rib_parser *p, const mesh *m, int face, const int *idx,
                         const int k[3], const vec3 *n)
{
    geom_surface local, *s = polygon_surface(m, &local, 3);
    for (int i = 0; i < 3; i++)
        s->verts[i] = point(m, idx[k[i]]);
    /* A piece of a mesh (m->out) keeps no surface: whether it is kept
     * and its (u,v) are all that is asked here, and the corner normals
     * change neither (they are read only by the last step of the
     * prepare, geom_vertex_normal_prepare, which may fail where the flat
     * triangle does not: the piece is then flat, scene_mesh.c). So a
     * mesh's triangle is prepared once, flat. */
    if (n && !m->out) {
        s->nvn = 3;
        s->vn[0] = n[0], s->vn[1] = n[1], s->vn[2] = n[2];
    }
#ifdef SCENE_HAVE_GEOM
    char err[ERR_LEN];
    if (!prepare(m, s, err, sizeof err)) {
        if (s->nvn == 0)
            return false;
        s->nvn = 0;                 /* normals it cannot interpolate: flat */
        if (!prepare(m, s, err, sizeof err))
            return false;
    }
#endif
    scene_primvar vars[RIB_MAX_PRIMVARS];
    if (m->pv.n > 0) {
        rib_corner c[3];
        for (int i = 0; i < 3; i++)
            c[i] = corner_of(m, face, idx, k[i]);
        if (s->nuv != 3 || !rib_primvars_triangle(&m->pv, c, (const double (*)[2])s->uv, vars))
            return false;
    }
    if (m->out)      /* scene_mesh_piece_surface makes s and vars again */
        add_piece(m, n ? SCENE_PIECE_TRIANGLE_N : SCENE_PIECE_TRIANGLE, face, k, 3);
    else
        add_with_vars(p, m, s, vars);
    return true;
}

#ifdef SCENE_HAVE_GEOM
/* Whether every corner normal of the prepared face s is its own normal
 * (then the flat polygon is crack-free too: its neighbours interpolate
 * that same normal along the shared edges). */
static bool corners_flat(const mesh *m, const geom_surface *s, int face, const int *idx,
                         int total)
{
    for (int i = 0; i < total; i++) {
        vec3 n = corner_normal(m, face, idx, i);
        double len = v3_length(n);
        if (!(len > 0) || v3_length(v3_sub(v3_scale(n, 1 / len), s->normal)) > 1e-12)
            return false;
    }
    return true;
}
#endif

/* One face: loops[0..nloops) of point indices idx (outer loop first). */
static bool add_face(rib_parser *p, mesh *m, int face, const int *loop_sizes, int nloops,
                     const int *idx)
{
    int total = (int)sum(loop_sizes, nloops);
    if (nloops == 1 && total <= GEOM_MAX_POLY_VERTS) {
        geom_surface local, *s = polygon_surface(m, &local, total);
        for (int i = 0; i < total; i++)
            s->verts[i] = point(m, idx[i]);
#ifdef SCENE_HAVE_GEOM
        char err[ERR_LEN];
        if (prepare(m, s, err, sizeof err)) {
            rib_corner corners[GEOM_MAX_POLY_VERTS];
            for (int i = 0; i < total; i++)
                corners[i] = corner_of(m, face, idx, i);
            bool flat = m->ncls == MESH_N_NONE || corners_flat(m, s, face, idx, total);
            scene_primvar vars[RIB_MAX_PRIMVARS];
            /* one polygon where its variables are constant, or affine in
             * its (u,v) ("st" across a wall of quads), started at the
             * corner whose edge runs along s or t (its (u,v) follow its
             * first edge: its cells then run along the pattern) */
            const double (*uv)[2] = s->nuv == total ? (const double (*)[2])s->uv : NULL;
            int rot = flat ? rib_primvars_st_edge(&m->pv, corners, total) : 0;
            if (rot) {
                rib_corner rc[GEOM_MAX_POLY_VERTS];
                for (int i = 0; i < total; i++) {
                    rc[i] = corners[(i + rot) % total];
                    s->verts[i] = point(m, idx[(i + rot) % total]);
                }
                memcpy(corners, rc, sizeof(rib_corner) * (size_t)total);
                /* the same polygon, so it prepares as before */
                bool again = prepare(m, s, err, sizeof err);
                assert(again);
                (void)again;
                uv = s->nuv == total ? (const double (*)[2])s->uv : NULL;
            }
            if (flat && rib_primvars_polygon(&m->pv, corners, uv, total, vars)) {
                if (m->out) {
                    const int k[3] = {rot, 0, 0};
                    add_piece(m, SCENE_PIECE_POLYGON, face, rot ? k : NULL, total);
                    return true;
                }
                add_with_vars(p, m, s, vars);
                return true;
            }
            /* convex and planar: a fan of triangles with corner normals
             * (and variables); flat ones where the face is (cut only for
             * its variables: its corner normals are its own, so its
             * triangles stay crack-free, and flat, their displaced cells
             * are intersected exactly, docs/renderer.md) */
            int added = 0;
            for (int i = 1; i + 1 < total; i++) {
                int c[3] = {0, i, i + 1};
                vec3 cn[3];
                for (int k = 0; k < 3 && !flat; k++)
                    cn[k] = corner_normal(m, face, idx, c[k]);
                added += add_triangle(p, m, face, idx, c, flat ? NULL : cn);
            }
            if (added == 0)
                skip_face(m, face);
            return true;
        }
#else
        (void)face;
        rib_add_surface(p, m->req, s);
        return true;
#endif
    }
#ifdef SCENE_HAVE_GEOM
    if (total > RIB_MAX_FACE_POINTS) {      /* cutting is quadratic in them */
        face_error(p, m, face, "face %d has %d points; faces to be cut into triangles may "
                   "have at most %d", face, total, RIB_MAX_FACE_POINTS);
        return false;
    }
    vec3 *pts = xrealloc(NULL, (size_t)total * sizeof *pts);
    for (int i = 0; i < total; i++)
        pts[i] = point(m, idx[i]);
    int max = total + 2 * nloops;
    int (*tris)[3] = xrealloc(NULL, (size_t)max * sizeof *tris);
    char err[ERR_LEN];
    int n = geom_triangulate(pts, loop_sizes, nloops, tris, max, err, sizeof err);
    bool ok = true;
    if (n < 0 && strcmp(err, "the polygon has no area") == 0) {
        skip_face(m, face);
    } else if (n < 0) {
        face_error(p, m, face, "face %d: %s", face, err);
        ok = false;
    } else {
        int added = 0;
        for (int t = 0; t < n; t++) {
            vec3 cn[3];
            for (int k = 0; k < 3; k++)
                cn[k] = m->ncls != MESH_N_NONE ? corner_normal(m, face, idx, tris[t][k])
                                               : v3(0, 0, 0);
            added += add_triangle(p, m, face, idx, tris[t], m->ncls != MESH_N_NONE ? cn : NULL);
        }
        if (added == 0)
            skip_face(m, face);
    }
    free(pts);
    free(tris);
    return ok;
#else
    (void)face;
    skip_face(m, face);
    return true;
#endif
}

/* Area-weighted vertex normals: every face adds its Newell normal (twice
 * its vector area, outer loop) to each of its points. npoints * 3 doubles,
 * the caller frees. */
static double *smooth_normals(int npoints, const double *P, const int *nloops, int nfaces,
                              const int *nverts, const int *idx)
{
    double *N = xrealloc(NULL, (size_t)npoints * 3 * sizeof *N);
    memset(N, 0, (size_t)npoints * 3 * sizeof *N);
    const int *loop = nverts, *vi = idx;
    for (int f = 0; f < nfaces; f++) {
        int nl = nloops ? nloops[f] : 1;
        int npts = (int)sum(loop, nl);
        double nn[3] = {0, 0, 0};
        for (int i = 0; i < loop[0]; i++) {
            const double *a = P + 3 * vi[i], *b = P + 3 * vi[i + 1 < loop[0] ? i + 1 : 0];
            nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
            nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
            nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        for (int i = 0; i < npts; i++)
            for (int k = 0; k < 3; k++)
                N[3 * vi[i] + k] += nn[k];
        loop += nl;
        vi += npts;
    }
    return N;
}

/* The class of a given "N" from its count; MESH_N_NONE with an error when
 * the count fits none. */
static mesh_nclass normal_class(rib_parser *p, const rib_request *req, const scene_param *N,
                                int npoints, int nfv, int nfaces)
{
    if (N->type != SL_TYPE_NORMAL && N->type != SL_TYPE_VECTOR) {
        rib_error(p, req, N->pos, "\"N\" must be declared as a normal, not a %s",
                  rib_type_name(N->type));
        return MESH_N_NONE;
    }
    int n = N->count / 3;
    if (n == npoints) return MESH_N_VERTEX;
    if (n == nfv) return MESH_N_FACEVARYING;
    if (n == nfaces) return MESH_N_UNIFORM;
    if (n == 1) return MESH_N_CONSTANT;
    rib_error(p, req, N->pos, "\"N\" has %d normals; give one per point (%d), per face "
              "corner (%d), per face (%d) or one", n, npoints, nfv, nfaces);
    return MESH_N_NONE;
}

#ifdef SCENE_HAVE_GEOM
/* Faces a chunk holds; chunks a wave holds (at least WAVE_CHUNKS, at
 * least CHUNKS_PER_THREAD a thread: a wave's logs are ~10 MB on 2
 * threads); the fewest faces worth threads */
enum { FACES_PER_CHUNK = 8192, WAVE_CHUNKS = 32, CHUNKS_PER_THREAD = 4,
       FACES_FOR_THREADS = 8192 };

/* The faces in chunks over threads, a wave of chunks at a time (so that
 * the logs are a wave's: ~0.7 MB a chunk, reused): chunk c is faces
 * [c * FACES_PER_CHUNK, ...), its loops from loop[c] and its points from
 * vi[c]; a thread takes the wave's next chunk not taken (next) until none
 * is left before `end`, into log[c - first]. */
typedef struct face_chunks {
    rib_parser *p;
    const int *nloops, *idx;
    int nfaces, nchunks;
    const int **loop, **vi;
    face_log *log;
    int first, end;
    atomic_int next;
} face_chunks;

/* A thread's share: the chunks and its own copy of the mesh (a scratch
 * surface of its own; its log set per chunk) */
typedef struct face_share {
    face_chunks *all;
    mesh m;
} face_share;

static void *faces_of_share(void *arg)
{
    face_share *sh = arg;
    face_chunks *all = sh->all;
    int c;
    while ((c = atomic_fetch_add(&all->next, 1)) < all->end) {
        const int *loop = all->loop[c], *vi = all->vi[c];
        int f1 = (c + 1) * FACES_PER_CHUNK < all->nfaces ? (c + 1) * FACES_PER_CHUNK : all->nfaces;
        sh->m.log = &all->log[c - all->first];
        for (int f = c * FACES_PER_CHUNK; f < f1; f++) {
            int nl = all->nloops ? all->nloops[f] : 1;
            int npts = (int)sum(loop, nl);
            sh->m.fv0 = (int)(vi - all->idx);
            add_face(all->p, &sh->m, f, loop, nl, vi);
            loop += nl;
            vi += npts;
        }
    }
    return NULL;
}

/* Plays back a chunk's log in face order into m (its pieces, faces
 * without area and errors) while `go`; false where one thread would have
 * stopped: the diagnostics full before a face that did something. Empties
 * the log (its events' array kept for the next wave). */
static bool play_back(rib_parser *p, mesh *m, face_log *log, bool go)
{
    int last = -1;
    size_t msg = 0;
    for (size_t i = 0; i < log->n && go; i++) {
        const face_event *e = &log->ev[i];
        if (e->face != last) {
            go = !sl_diag_full(p->diag);
            last = e->face;
            if (!go) break;
        }
        if (e->what == FACE_PIECE) {
            int k[3] = {e->k[0], e->k[1], e->k[2]};
            scene_mesh_add_piece(m->out, (scene_piece_kind)e->kind, e->face, e->fv0,
                                 e->has_k ? k : NULL, e->n);
        } else if (e->what == FACE_SKIPPED) {
            m->skipped++;
        } else {
            rib_error(p, m->req, m->vertices_pos, "%s", log->msgs[msg++]);
        }
    }
    for (size_t i = 0; i < log->nmsgs; i++) free(log->msgs[i]);
    free(log->msgs);
    log->msgs = NULL;
    log->nmsgs = 0;
    log->n = 0;
    return go;
}

/* The faces of mesh m over p->threads threads in chunks of
 * FACES_PER_CHUNK (taken as threads come free: a thread held up by the
 * machine's load holds up no other for more than a chunk), a wave of
 * chunks at a time, each wave's logs played back in order. */
static void faces_in_threads(rib_parser *p, mesh *m, const int *nloops, int nfaces,
                             const int *nverts, const int *idx)
{
    face_chunks all = { p, nloops, idx, nfaces, (nfaces + FACES_PER_CHUNK - 1) / FACES_PER_CHUNK,
                        NULL, NULL, NULL, 0, 0, 0 };
    int threads = p->threads < all.nchunks ? p->threads : all.nchunks;
    int wave = CHUNKS_PER_THREAD * threads > WAVE_CHUNKS ? CHUNKS_PER_THREAD * threads : WAVE_CHUNKS;
    all.loop = xcalloc((size_t)all.nchunks, sizeof *all.loop);
    all.vi = xcalloc((size_t)all.nchunks, sizeof *all.vi);
    all.log = xcalloc((size_t)wave, sizeof *all.log);
    const int *loop = nverts, *vi = idx;
    for (int f = 0; f < nfaces; f++) {
        if (f % FACES_PER_CHUNK == 0) {
            all.loop[f / FACES_PER_CHUNK] = loop;
            all.vi[f / FACES_PER_CHUNK] = vi;
        }
        int nl = nloops ? nloops[f] : 1;
        vi += sum(loop, nl);
        loop += nl;
    }
    face_share *sh = xcalloc((size_t)threads, sizeof *sh);
    for (int i = 0; i < threads; i++) {
        sh[i].all = &all;
        sh[i].m = *m;
        sh[i].m.scratch = xcalloc(1, sizeof *sh[i].m.scratch);
    }
    bool go = true;
    for (all.first = 0; all.first < all.nchunks && go; all.first = all.end) {
        all.end = all.nchunks - all.first > wave ? all.first + wave : all.nchunks;
        atomic_store(&all.next, all.first);
        util_run_shares(sh, sizeof *sh, threads, faces_of_share);
        for (int c = all.first; c < all.end; c++)
            go = play_back(p, m, &all.log[c - all.first], go);
    }
    for (int i = 0; i < threads; i++) free(sh[i].m.scratch);
    free(sh);
    for (int i = 0; i < wave; i++) free(all.log[i].ev);
    free(all.log);
    free(all.vi);
    free(all.loop);
}
#endif

/* The shared part of both requests: nloops per face (NULL: one loop per
 * face), nverts per loop, the vertex indices, then the parameters. */
static void read_mesh(rib_parser *p, const rib_request *req, const int *nloops, int nfaces,
                      const int *nverts, int nnverts, int first_vertices)
{
    int nidx;
    int *idx = rib_read_ints(p, req, first_vertices, 0, false, &nidx, "the vertex indices");
    if (!idx)
        return;
    rib_params params = { 0 };
    if (sum(nverts, nnverts) != nidx) {
        rib_error(p, req, req->args[first_vertices].pos, "the loops have %ld points in all, "
                  "but %d vertex indices are given", sum(nverts, nnverts), nidx);
        goto out;
    }
    if (!rib_params_read(p, req, first_vertices + 1, RIB_PARAMS_VARYING, &params))
        goto out;
    const scene_param *P = rib_params_points(p, req, &params);
    if (!P)
        goto out;
    int maxidx = 0;
    for (int i = 0; i < nidx; i++)
        maxidx = idx[i] > maxidx ? idx[i] : maxidx;
    if (P->count / 3 <= maxidx) {
        rib_error(p, req, P->pos, "\"P\" has %d points, but the vertex indices go up to %d",
                  P->count / 3, maxidx);
        goto out;
    }
    mesh m = { req, P->values, P->count / 3, 0, req->args[first_vertices].pos,
               MESH_N_VERTEX, NULL, 0, { NULL, 0 }, NULL, NULL, NULL };
    int counts[] = { 0, 1, nfaces, m.npoints, m.npoints, nidx };
    if (!rib_primvars_collect(p, req, &params, counts, NULL, &m.pv))
        goto out;
    double *smooth = NULL;
    const scene_param *N = rib_params_find(&params, "N");
    if (N) {
        m.ncls = normal_class(p, req, N, m.npoints, nidx, nfaces);
        if (m.ncls == MESH_N_NONE) {
            rib_primvars_clear(&m.pv);
            goto out;
        }
        m.N = N->values;
    } else {
        m.N = smooth = smooth_normals(m.npoints, P->values, nloops, nfaces, nverts, idx);
    }
    bool taken = false;                /* idx and smooth are the mesh's */
#ifdef SCENE_HAVE_GEOM
    if (p->check) {
        m.out = scene_mesh_new_counted(m.pv.n);        /* a check keeps no arrays */
    } else {
        /* the mesh takes the arrays as they are (P's and N's values out
         * of params, the smooth normals, the indices): no copies; m's
         * pointers stay valid while it lives */
        scene_param *Pp = &params.items[P - params.items];
        double *Nv = smooth;
        int nN = m.npoints;
        if (N) {
            scene_param *Np = &params.items[N - params.items];
            Nv = Np->values;
            Np->values = NULL;
            nN = N->count / 3;
        }
        m.out = scene_mesh_new_taking(Pp->values, m.npoints, idx, nidx, m.ncls, Nv, nN, &m.pv,
                                      &params);
        Pp->values = NULL;
        taken = true;
    }
    m.scratch = xcalloc(1, sizeof *m.scratch);
#endif
    const int *loop = nverts, *vi = idx;
#ifdef SCENE_HAVE_GEOM
    if (p->threads > 1 && nfaces >= FACES_FOR_THREADS)
        faces_in_threads(p, &m, nloops, nfaces, nverts, idx);
    else
#endif
    for (int f = 0; f < nfaces && !sl_diag_full(p->diag); f++) {
        int nl = nloops ? nloops[f] : 1;
        int npts = (int)sum(loop, nl);
        m.fv0 = (int)(vi - idx);
        add_face(p, &m, f, loop, nl, vi);
        loop += nl;
        vi += npts;
    }
    if (taken) {
        idx = NULL;
        smooth = NULL;
    }
    free(smooth);
    free(m.scratch);
    if (m.out) {
        scene_mesh_trim(m.out);
        if (scene_mesh_npieces(m.out) > 0 && !sl_diag_full(p->diag))
            rib_add_mesh(p, req, m.out);        /* the scene's from here */
        else
            scene_mesh_destroy(&m.out);
    }
    rib_primvars_clear(&m.pv);
    if (m.skipped > 0)
        rib_warning(p, req, req->pos, "%d face%s without area skipped", m.skipped,
                    m.skipped == 1 ? "" : "s");
out:
    rib_params_clear(&params);
    free(idx);
}

void rib_points_polygons(rib_parser *p, const rib_request *req)
{
    int nfaces;
    int *nverts = rib_read_ints(p, req, 0, 3, false, &nfaces, "the vertex counts (nvertices)");
    if (!nverts)
        return;
    read_mesh(p, req, NULL, nfaces, nverts, nfaces, 1);
    free(nverts);
}

/* GeneralPolygon nvertices "P" [...]: one face, its loops' points in
 * order. */
void rib_general_polygon(rib_parser *p, const rib_request *req)
{
    int nloops;
    int *nverts = rib_read_ints(p, req, 0, 3, false, &nloops, "the vertex counts (nvertices)");
    if (!nverts)
        return;
    rib_params params;
    if (rib_params_read(p, req, 1, RIB_PARAMS_VARYING, &params)) {
        const scene_param *P = rib_params_points(p, req, &params);
        long n = sum(nverts, nloops);
        if (!P)
            ;                          /* reported */
        else if (P->count / 3 != n)
            rib_error(p, req, P->pos, "the loops have %ld points in all, but \"P\" has %d",
                      n, P->count / 3);
        else {
            int *idx = xrealloc(NULL, (size_t)n * sizeof *idx);
            for (int i = 0; i < n; i++)
                idx[i] = i;
            mesh m = { req, P->values, (int)n, 0, req->args[0].pos, MESH_N_NONE, NULL, 0,
                       { NULL, 0 }, NULL, NULL, NULL };
            int counts[] = { 0, 1, 1, (int)n, (int)n, (int)n };
            const scene_param *N = rib_params_find(&params, "N");
            if (N) {
                m.ncls = normal_class(p, req, N, (int)n, (int)n, 1);
                m.N = N->values;
            }
            if ((!N || m.ncls != MESH_N_NONE) &&
                rib_primvars_collect(p, req, &params, counts, NULL, &m.pv)) {
                add_face(p, &m, 0, nverts, nloops, idx);
                if (m.skipped)
                    rib_warning(p, req, req->pos, "the polygon has no area: skipped");
            }
            rib_primvars_clear(&m.pv);
            free(idx);
        }
        rib_params_clear(&params);
    }
    free(nverts);
}

void rib_points_general_polygons(rib_parser *p, const rib_request *req)
{
    int nfaces, nnverts;
    int *nloops = rib_read_ints(p, req, 0, 1, false, &nfaces, "the loop counts (nloops)");
    if (!nloops)
        return;
    int *nverts = rib_read_ints(p, req, 1, 3, false, &nnverts, "the vertex counts (nvertices)");
    if (nverts && sum(nloops, nfaces) != nnverts)
        rib_error(p, req, req->args[1].pos, "the faces have %ld loops in all, but %d vertex "
                  "counts are given", sum(nloops, nfaces), nnverts);
    else if (nverts)
        read_mesh(p, req, nloops, nfaces, nverts, nnverts, 2);
    free(nloops);
    free(nverts);
}

bool rib_polygon_vars(rib_parser *p, const rib_request *req, const rib_params *params,
                      const scene_param *P)
{
    static const char *const geometric[] = {"P", "Pw", "Pz", "N"};
    bool any = false;
    for (int i = 0; i < params->count; i++) {
        bool g = false;
        for (size_t k = 0; k < sizeof geometric / sizeof geometric[0]; k++)
            g |= strcmp(params->items[i].name, geometric[k]) == 0;
        any |= !g;
    }
    if (!any)
        return false;
    int n = P->count / 3;
    int *idx = xrealloc(NULL, (size_t)n * sizeof *idx);
    for (int i = 0; i < n; i++)
        idx[i] = i;
    mesh m = { req, P->values, n, 0, req->pos, MESH_N_NONE, NULL, 0, { NULL, 0 }, NULL, NULL,
               NULL };
    int counts[] = { 0, 1, 1, n, n, n };
    if (rib_primvars_collect(p, req, params, counts, NULL, &m.pv)) {
        int loop[1] = { n };
        add_face(p, &m, 0, loop, 1, idx);
    }
    rib_primvars_clear(&m.pv);
    free(idx);
    return true;
}
