/*
 * world.c: the per-object quantities derived from the scene before any
 * ray is traced (trace_world_prepare, world.h): the transform checks, the
 * object's largest stretch (leaf sizes), the bounds of its camera-space
 * normal lengths (the one globals binding, globals.inc) and its du, dv
 * (docs/renderer.md "Shader globals"). All pure functions of the scene,
 * so every worker derives the same values.
 */
#include "trace/world.h"
#include "trace/edge_sort.h"
#include "trace/group.h"
#include "trace/mesh.h"
#include "trace/region.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Spectral norm of the 3x3 part (largest stretch), by power iteration on
 * M^T M, rounded up a little: the leaf test multiplies object-space sizes
 * by it, so a slight overestimate only makes leaves smaller. */
static double stretch_of(const mat4 *m)
{
    vec3 x = v3(1, 1, 1);
    double s = 0;
    for (int it = 0; it < 64; it++) {
        vec3 y = mat4_xform_vector(m, x);
        vec3 z = v3(m->m[0][0] * y.x + m->m[1][0] * y.y + m->m[2][0] * y.z,
                    m->m[0][1] * y.x + m->m[1][1] * y.y + m->m[2][1] * y.z,
                    m->m[0][2] * y.x + m->m[1][2] * y.y + m->m[2][2] * y.z);
        double l = v3_length(z);
        if (!(l > 0)) break;
        s = sqrt(l / v3_length(x));
        vec3 next = v3_scale(z, 1.0 / l);
        /* a fixed point to the bit: every further step would repeat this
         * one, so s is what the 64 steps give (a rotation times a uniform
         * scale gets there in two or three) */
        bool same = memcmp(&next, &x, sizeof x) == 0;
        x = next;
        if (same) break;
    }
    return s * (1.0 + 1e-6);
}

/* For a similarity (rotation x uniform scale), the constant 1/|from_camera^T n|
 * of unit object normals n; 0 otherwise (then normals are normalised in
 * the bounding arithmetic, displace.c). */
static double normal_scale_of(const trace_object *obj)
{
    mat4 t = mat4_transpose(obj->from_camera);
    double len[3];
    for (int i = 0; i < 3; i++) {
        vec3 e = v3(i == 0, i == 1, i == 2);
        len[i] = v3_length(mat4_xform_vector(&t, e));
    }
    for (int i = 0; i < 3; i++) {
        vec3 a = mat4_xform_vector(&t, v3(i == 0, i == 1, i == 2));
        vec3 b = mat4_xform_vector(&t, v3(i == 2, i == 0, i == 1));
        if (fabs(len[i] - len[0]) > 1e-13 * len[0] ||
            fabs(v3_dot(a, b)) > 1e-13 * len[0] * len[0])
            return 0.0;
    }
    return len[0] > 0 && isfinite(len[0]) ? 1.0 / len[0] : 0.0;
}

/* The shader globals du and dv of an object (issue 9): RenderMan's grid
 * spacing, a micropolygon of ShadingRate pixels, taken once per object so
 * that every box and every point of the surface sees the same value:
 * du = sqrt(ShadingRate) / (the surface's longest u-line projected on the
 * raster, in pixels), dv likewise, from a 9x9 grid of base-surface points;
 * between 2^-16 and 1. A pure function of the scene (no tile, thread or
 * worker enters it). Points behind the eye are measured at distance 1. */
/* The longest u- and v-lines of obj's base surface on the raster, in
 * pixels, over the rows and points of the 9 x 9 grid every `step`-th (1:
 * all; 4: 3 x 3, a subset of the same points, so by the triangle
 * inequality and the max over fewer rows never longer; a surface of
 * finite points, a polynomial of (u,v) with finite coefficients, has
 * finite points at all 81) */
static void raster_lines(const trace_world *world, const trace_object *obj, int step, double *lu,
                         double *lv)
{
    const trace_camera *cam = &world->camera;
    double px = fabs(cam->screen[1] - cam->screen[0]) / cam->xres;
    if (!cam->orthographic) px *= cam->tan_half_fov;
    enum { G = 9 };
    double raster[G][G][2];
    for (int j = 0; j < G; j += step)
        for (int i = 0; i < G; i += step) {
            vec3 P = geom_eval_point(&obj->surf, i / (double)(G - 1), j / (double)(G - 1));
            vec3 p = mat4_xform_point(&obj->to_camera, P);
            double z = cam->orthographic || !(p.z > 1.0) ? 1.0 : p.z;
            raster[j][i][0] = p.x / z / px;
            raster[j][i][1] = p.y / z / px;
        }
    *lu = *lv = 0;
    for (int k = 0; k < G; k += step) {
        double su = 0, sv = 0;
        for (int m = step; m < G; m += step) {
            su += hypot(raster[k][m][0] - raster[k][m - step][0],
                        raster[k][m][1] - raster[k][m - step][1]);
            sv += hypot(raster[m][k][0] - raster[m - step][k][0],
                        raster[m][k][1] - raster[m - step][k][1]);
        }
        *lu = fmax(*lu, su);
        *lv = fmax(*lv, sv);
    }
}

/* du or dv from a line's length */
static double spacing(const trace_world *world, double l)
{
    double k = sqrt(world->shading_rate > 0 ? world->shading_rate : 1.0);
    return fmin(1.0, fmax(0x1p-16, l > 0 && isfinite(l) ? k / l : 1.0));
}

void trace_object_grid_spacing(const trace_world *world, trace_object *obj)
{
    double lu, lv;
    raster_lines(world, obj, 1, &lu, &lv);
    obj->du = spacing(world, lu);
    obj->dv = spacing(world, lv);
}

void trace_object_grid_spacing_max(const trace_world *world, const trace_object *obj,
                                   double *du, double *dv)
{
    double lu, lv;
    raster_lines(world, obj, 4, &lu, &lv);
    /* a hair over for the rounding of the 9 x 9 grid's longer sums */
    *du = fmin(1.0, spacing(world, lu) * (1.0 + 0x1p-30));
    *dv = fmin(1.0, spacing(world, lv) * (1.0 + 0x1p-30));
}

static bool matrix_finite(const mat4 *m)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(m->m[r][c])) return false;
    return true;
}

/* A polygon edge by a 64-bit hash of its exact key: the bits of its
 * object's transform and of its RIB vertices (the lower first); and where it
 * is: its object id (a mesh piece's id for pieces) times 64 plus its
 * index. 16 bytes an edge. Equal keys have equal hashes; two different
 * keys whose hashes agree (about one chance in 10^6 for a scene of 10^6
 * edges) would only turn the hit proofs off near one more edge: the
 * proofs decide nothing the leaves do not. */
typedef trace_edge world_edge;

/* the RIB vertex of the polygon nearest to p (p is one of them, up to the
 * rounding of its (u,v) round trip) */
static vec3 rib_vertex(const geom_surface *s, vec3 p)
{
    int best = 0;
    double d = INFINITY;
    for (int j = 0; j < s->nverts; j++) {
        double dj = v3_length(v3_sub(s->verts[j], p));
        if (dj < d) { d = dj; best = j; }
    }
    return s->verts[best];
}

static uint64_t mix(uint64_t h, uint64_t b, uint64_t m)
{
    h = (h ^ b) * m;
    return h ^ (h >> 31);
}

static uint64_t mix_doubles(uint64_t h, const double *x, int n)
{
    for (int i = 0; i < n; i++) {
        uint64_t bits;
        memcpy(&bits, &x[i], sizeof bits);
        h = mix(h, bits, 0x9e3779b97f4a7c15ull);
    }
    return h;
}

/* The hash of an object's transform: where its edges' hashes start
 * (edge_hash), made once per object instead of once per edge. The key is
 * the transform's bits, then the edge's: equal keys, equal hashes. */
static uint64_t transform_hash(const mat4 *to_camera)
{
    return mix_doubles(0x243f6a8885a308d3ull, &to_camera->m[0][0], 16);
}

/* memcmp(x, y, 24) < 0 for three doubles each, without the call: bytes
 * compare in memory order, so each double's bits read big-endian are
 * compared as unsigned numbers, the first that differ deciding */
static bool bytes_below(const double x[3], const double y[3])
{
    for (int i = 0; i < 3; i++) {
        uint64_t a, b;
        memcpy(&a, &x[i], sizeof a);
        memcpy(&b, &y[i], sizeof b);
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        a = __builtin_bswap64(a);
        b = __builtin_bswap64(b);
#endif
        if (a != b) return a < b;
    }
    return false;
}

/* The hash of the edge from RIB vertex a to RIB vertex b (either way
 * round: the lower first, as memcmp orders their bytes) under the
 * transform of hash h0 */
static uint64_t edge_hash(uint64_t h0, vec3 a, vec3 b)
{
    double pa[3] = {a.x, a.y, a.z}, pb[3] = {b.x, b.y, b.z}, key[6];
    bool swap = bytes_below(pb, pa);
    memcpy(key, swap ? pb : pa, sizeof pa);
    memcpy(key + 3, swap ? pa : pb, sizeof pa);
    return mix_doubles(h0, key, 6);
}

/* The object of id `id`: a plain object, or the mesh of a piece (meshes:
 * the mesh objects' indices, in order). */
static trace_object *owner_of_id(trace_world *world, const int *meshes, int nmeshes, int id)
{
    if (id < world->nobjects) return &world->objects[id];
    int lo = 0, hi = nmeshes - 1;      /* the last mesh whose first_id <= id */
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (world->objects[meshes[mid]].mesh->first_id <= id) lo = mid; else hi = mid - 1;
    }
    return &world->objects[meshes[lo]];
}

static void mark_shared(trace_world *world, const int *meshes, int nmeshes, uint64_t ref)
{
    int id = (int)(ref / 64), edge = (int)(ref % 64);
    trace_object *owner = owner_of_id(world, meshes, nmeshes, id);
    if (owner->mesh)
        trace_mesh_mark_edge(owner->mesh, id - owner->mesh->first_id, edge);
    else
        owner->shared_edges |= (uint64_t)1 << edge;
}

/* Adds the edges of polygon s (object id `id`, the hash of its object's
 * transform h0) to *e: edge j from corner j to corner j + 1, each corner
 * taken to its RIB vertex once (as geom_polygon_edge gives them). */
static void add_edges(world_edge **e, size_t *n, size_t *cap, const geom_surface *s,
                      uint64_t h0, int id)
{
    if (s->kind != GEOM_POLYGON || s->nuv < 1) return;
    vec3 v[GEOM_MAX_POLY_VERTS];
    for (int j = 0; j < s->nuv; j++) v[j] = rib_vertex(s, geom_polygon_corner(s, j));
    for (int j = 0; j < s->nuv && j < 64; j++) {
        if (*n == *cap) *e = xreallocarray(*e, *cap *= 2, sizeof **e);
        (*e)[*n].h = edge_hash(h0, v[j], v[(j + 1) % s->nuv]);
        (*e)[(*n)++].ref = (uint64_t)id * 64 + (uint64_t)j;
    }
}

/* One thread's share of a mesh's pieces [k0, k1): their edges (in piece
 * order) and their bounds (displaced: undisplaced, over their squares). */
typedef struct edge_share {
    const trace_object *obj;
    int k0, k1;
    world_edge *e;
    size_t n, cap;
} edge_share;

static void *mesh_edges(void *arg)
{
    edge_share *sh = arg;
    trace_mesh *m = sh->obj->mesh;
    geom_surface *tmp = xcalloc(1, sizeof *tmp);
    aa_context ctx;
    aa_context_init(&ctx, 2);
    uint64_t h0 = transform_hash(&sh->obj->to_camera);
    /* an undisplaced piece's bounds and edges need its outline alone */
    bool outline = m->outline && !sh->obj->displacement;
    for (int k = sh->k0; k < sh->k1; k++) {
        int npv;
        if (outline ? !m->outline(m->user, k, tmp)
                    : !m->piece(m->user, sh->obj, k, tmp, NULL, &npv))
            continue;
        if (!sh->obj->displacement) trace_mesh_piece_bounds(tmp, m->bounds[k]);
        else trace_region_base(&ctx, tmp, m->bounds[k]);   /* before its regions' shift */
        add_edges(&sh->e, &sh->n, &sh->cap, tmp, h0, m->first_id + k);
    }
    free(tmp);
    return NULL;
}

/* The edges' lists, in ref order one after another (the world's parts
 * of the list it sorts: edge_sort.h), each owned */
typedef struct edge_parts {
    world_edge **part;
    size_t *len;
    int n, cap;
} edge_parts;

static void push_part(edge_parts *p, world_edge *e, size_t n)
{
    if (p->n == p->cap) {
        p->cap = p->cap ? 2 * p->cap : 8;
        p->part = xreallocarray(p->part, (size_t)p->cap, sizeof *p->part);
        p->len = xreallocarray(p->len, (size_t)p->cap, sizeof *p->len);
    }
    p->part[p->n] = e;
    p->len[p->n++] = n;
}

/* The pass over mesh object obj's pieces, over the world's build threads:
 * each share's edges a part of *parts, in piece order, so the list (and
 * everything after it) is the one a single thread makes. */
static void mesh_edges_in_parallel(const trace_world *world, const trace_object *obj,
                                   edge_parts *parts)
{
    int npieces = obj->mesh->npieces;
    int threads = world->options.build_threads;
    /* a thread is worth its start for a few thousand pieces */
    if (threads > npieces / 4096) threads = npieces / 4096;
    if (threads < 1) threads = 1;
    edge_share *share = xcalloc((size_t)threads, sizeof *share);
    for (int i = 0; i < threads; i++) {
        share[i].obj = obj;
        share[i].k0 = (int)((long)npieces * i / threads);
        share[i].k1 = (int)((long)npieces * (i + 1) / threads);
        share[i].cap = 3 * (size_t)(share[i].k1 - share[i].k0) + 1;
        share[i].e = xmalloc(sizeof *share[i].e * share[i].cap);
    }
    trace_run_shares(share, sizeof *share, threads, mesh_edges);
    for (int i = 0; i < threads; i++) push_part(parts, share[i].e, share[i].n);
    free(share);
}

/* The shared edges' marks from a slice of the sorted list: neighbours
 * of equal hashes in two objects or pieces */
enum { EDGE_SLICES = 4 };

typedef struct marking {
    trace_world *world;
    const int *meshes;
    int nmeshes;
} marking;

static void mark_slice(void *ctx, const world_edge *e, size_t n)
{
    marking *mk = ctx;
    for (size_t i = 0; i + 1 < n; i++) {
        size_t j = i + 1;
        if (e[i].h != e[j].h || e[i].ref / 64 == e[j].ref / 64) continue;
        mark_shared(mk->world, mk->meshes, mk->nmeshes, e[i].ref);
        mark_shared(mk->world, mk->meshes, mk->nmeshes, e[j].ref);
    }
}

/* The edges polygons share (the meshes of Polygon and PointsPolygons
 * calls, whose shared vertices are the same numbers under the same
 * transform): the hit proofs (intersect.c) stay off near them, where the
 * neighbour's leaves decide. Sorted by their hashes, so equal edges are
 * neighbours: O(n log n) for meshes of any size. A mesh that several
 * objects place is seen once, under its first object's transform. The
 * same pass over a mesh's pieces keeps the object-space bounds of the
 * undisplaced ones (trace_mesh_build needs no second one). meshes[0..nmeshes):
 * the objects that place a mesh first, in order. */
static void find_shared_edges(trace_world *world, const int *meshes, int nmeshes)
{
    size_t n = 0;
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        obj->shared_edges = 0;
        if (!obj->mesh && !obj->group && obj->surf.kind == GEOM_POLYGON)
            n += (size_t)obj->surf.nuv;
    }
    for (int j = 0; j < nmeshes; j++) {
        trace_mesh *m = world->objects[meshes[j]].mesh;
        m->shared_edges = xcalloc((size_t)(m->npieces > 0 ? m->npieces : 1),
                                  sizeof *m->shared_edges);
    }
    /* the plain objects' edges, then each mesh's */
    size_t cap = n > 0 ? n : 1;
    world_edge *e = xmalloc(cap * sizeof *e);
    n = 0;
    for (int i = 0; i < world->nobjects; i++)
        if (!world->objects[i].mesh && !world->objects[i].group)
            add_edges(&e, &n, &cap, &world->objects[i].surf,
                      transform_hash(&world->objects[i].to_camera), i);
    edge_parts parts = {0};
    push_part(&parts, e, n);
    for (int j = 0; j < nmeshes; j++) {
        trace_object *obj = &world->objects[meshes[j]];
        trace_mesh *m = obj->mesh;
        m->bounds = xmalloc(sizeof *m->bounds * (size_t)(m->npieces > 0 ? m->npieces : 1));
        mesh_edges_in_parallel(world, obj, &parts);
    }
    /* sorted a slice at a time (equal hashes never split between two):
     * the list and a quarter of it held, not the list twice */
    n = 0;
    for (int p = 0; p < parts.n; p++) n += parts.len[p];
    marking mk = {world, meshes, nmeshes};
    trace_edges_sort_each(parts.part, parts.len, parts.n, world->options.build_threads,
                          n / EDGE_SLICES + 1, mark_slice, &mk);
    for (int p = 0; p < parts.n; p++) free(parts.part[p]);
    free(parts.part);
    free(parts.len);
    for (int j = 0; j < nmeshes; j++) trace_mesh_edges_done(world->objects[meshes[j]].mesh);
}

bool trace_object_derive(const trace_world *world, trace_object *obj, bool grid, char *err,
                         size_t errsz)
{
    double s = stretch_of(&obj->to_camera), si = stretch_of(&obj->from_camera);
    if (!matrix_finite(&obj->to_camera) || !matrix_finite(&obj->from_camera) ||
        !(s > 0) || !isfinite(s * si) || s * si > 1e12)
        return err_set(err, errsz, "%s: its transformation to camera space is not "
                       "finite or nearly singular (stretch %.3g, inverse stretch %.3g); check "
                       "the Translate/Scale/ConcatTransform values before it", obj->name, s, si);
    obj->scale = s;
    obj->normal_scale = normal_scale_of(obj);
    /* |from_camera^T n| lies between the smallest and the largest
     * stretch of from_camera: 1/stretch(to_camera) and stretch(from),
     * both rounded outward (stretch_of rounds up) */
    double lo = 1.0 / s;
    obj->normal_len2[0] = lo * lo * (1.0 - 1e-9);
    obj->normal_len2[1] = si * si * (1.0 + 1e-9);
    if (grid) trace_object_grid_spacing(world, obj);
    return true;
}

/* Each placement of group object g passes the object checks (its view's
 * transforms are the scene's). */
static bool check_placements(const trace_world *world, const trace_object *g, char *err,
                             size_t errsz)
{
    const trace_group *gr = g->group;
    trace_object probe = world->objects[gr->proto];
    for (int k = 0; k < gr->n; k++) {
        gr->transform(gr->user, k, &probe.to_camera, &probe.from_camera);
        if (!trace_object_derive(world, &probe, false, err, errsz)) return false;
    }
    return true;
}

bool trace_world_check(trace_world *world, char *err, size_t errsz)
{
    int places = 0;
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        obj->id = i;
        obj->top = i;
        if (obj->group) {
            /* after its prototype (the adapter appends the groups) */
            assert(obj->group->proto >= 0 && obj->group->proto < i &&
                   !world->objects[obj->group->proto].group &&
                   !world->objects[obj->group->proto].box_proto);
            obj->group->first = places;
            obj->group->first_id = -1;         /* trace_world_prepare's */
            places += obj->group->n;
            continue;
        }
        /* pieces: their views */
        if (!trace_object_derive(world, obj, !obj->mesh, err, errsz)) return false;
        const sl_program *dp = obj->displacement ? sl_instance_program(obj->displacement) : NULL;
        obj->box_skip_tangents = dp && !sl_program_takes_derivatives(dp) &&
                                 !sl_program_reads_global(dp, SL_G_dPdu) &&
                                 !sl_program_reads_global(dp, SL_G_dPdv);
        obj->box_runs_skip_tangents = dp && !sl_program_box_reads(dp, SL_G_dPdu, false) &&
                                      !sl_program_box_reads(dp, SL_G_dPdv, false) &&
                                      !sl_program_box_reads(dp, SL_G_P, true) &&
                                      !sl_program_box_reads(dp, SL_G_I, true);
        obj->bend_unknown = dp && sl_program_reads_textures(dp);
    }
    for (int i = 0; i < world->nobjects; i++)
        if (world->objects[i].group && !check_placements(world, &world->objects[i], err, errsz))
            return false;
    return true;
}

bool trace_world_prepare(trace_world *world, char *err, size_t errsz)
{
    if (!trace_world_check(world, err, errsz)) return false;
    /* ids: the objects, then each mesh's pieces (once per mesh: the
     * objects sharing it share them); its derived arrays made anew */
    for (int i = 0; i < world->nobjects; i++) {
        if (world->objects[i].group)
            trace_group_clear(world->objects[i].group);
        if (world->objects[i].mesh) {
            trace_mesh_clear(world->objects[i].mesh);
            world->objects[i].mesh->first_id = -1;
        }
    }
    int *meshes = xmalloc(sizeof *meshes * (size_t)(world->nobjects > 0 ? world->nobjects : 1));
    int nmeshes = 0;
    long next = world->nobjects;
    for (int i = 0; i < world->nobjects; i++) {
        trace_mesh *m = world->objects[i].mesh;
        if (!m || m->first_id >= 0) continue;
        if (next + m->npieces > INT32_MAX / 64) {
            free(meshes);
            return err_set(err, errsz, "%s: too many mesh pieces in the scene (%ld before "
                           "this mesh's %d)", world->objects[i].name, next - world->nobjects,
                           m->npieces);
        }
        m->first_id = (int)next;
        next += m->npieces;
        meshes[nmeshes++] = i;                 /* the mesh's first placing object */
    }
    /* then each displaced group's placements (trace_group.first_id) */
    for (int i = 0; i < world->nobjects; i++) {
        trace_group *gr = world->objects[i].group;
        if (!gr) continue;
        gr->first_id = -1;
        /* (a displaced mesh's placements: trace_group_classify_meshes) */
        if (!world->objects[gr->proto].displacement || world->objects[gr->proto].mesh) continue;
        if (next + gr->n > INT32_MAX / 64) {
            free(meshes);
            return err_set(err, errsz, "%s: too many objects and pieces in the scene (%ld "
                           "before these %d instances)", world->objects[i].name,
                           next - world->nobjects, gr->n);
        }
        gr->first_id = (int)next;
        next += gr->n;
    }
    world->nids = (int)next;
    find_shared_edges(world, meshes, nmeshes);
    free(meshes);
    return true;
}

void trace_world_count(const trace_world *world, trace_world_counts *out)
{
    memset(out, 0, sizeof *out);
    for (int i = 0; i < world->nobjects; i++) {
        const trace_object *obj = &world->objects[i];
        const trace_group *gr = obj->group;
        if (gr) {
            out->groups++;
            out->placements += gr->n;
            if (gr->own) {
                out->own += gr->nown;
                out->moved += gr->n - gr->nown;
            }
            continue;
        }
        out->objects++;
        out->meshes += obj->mesh != NULL;
    }
    /* the ids (trace_world_prepare): the objects, each mesh's pieces once,
     * each displaced group's placements */
    long ids = world->nids;
    for (int i = 0; i < world->nobjects; i++) {
        const trace_group *gr = world->objects[i].group;
        if (gr && gr->first_id >= 0) ids -= gr->n;
    }
    out->pieces = ids > world->nobjects ? ids - world->nobjects : 0;
}
