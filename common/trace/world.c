/*
 * world.c: the per-object quantities derived from the scene before any
 * ray is traced (trace_world_prepare, world.h): the transform checks, the
 * object's largest stretch (leaf sizes), the bounds of its camera-space
 * normal lengths (the one globals binding, globals.inc) and its du, dv
 * (docs/renderer.md "Shader globals"). All pure functions of the scene,
 * so every worker derives the same values.
 */
#include "trace/world.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
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
        x = v3_scale(z, 1.0 / l);
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
static void grid_spacing(const trace_world *world, trace_object *obj)
{
    const trace_camera *cam = &world->camera;
    double px = fabs(cam->screen[1] - cam->screen[0]) / cam->xres;
    if (!cam->orthographic) px *= cam->tan_half_fov;
    enum { G = 9 };
    double raster[G][G][2];
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            geom_sample g;
            geom_eval(&obj->surf, i / (double)(G - 1), j / (double)(G - 1), &g);
            vec3 p = mat4_xform_point(&obj->to_camera, g.P);
            double z = cam->orthographic || !(p.z > 1.0) ? 1.0 : p.z;
            raster[j][i][0] = p.x / z / px;
            raster[j][i][1] = p.y / z / px;
        }
    double lu = 0, lv = 0;
    for (int k = 0; k < G; k++) {
        double su = 0, sv = 0;
        for (int m = 1; m < G; m++) {
            su += hypot(raster[k][m][0] - raster[k][m - 1][0], raster[k][m][1] - raster[k][m - 1][1]);
            sv += hypot(raster[m][k][0] - raster[m - 1][k][0], raster[m][k][1] - raster[m - 1][k][1]);
        }
        lu = fmax(lu, su);
        lv = fmax(lv, sv);
    }
    double k = sqrt(world->shading_rate > 0 ? world->shading_rate : 1.0);
    obj->du = fmin(1.0, fmax(0x1p-16, lu > 0 && isfinite(lu) ? k / lu : 1.0));
    obj->dv = fmin(1.0, fmax(0x1p-16, lv > 0 && isfinite(lv) ? k / lv : 1.0));
}

static bool matrix_finite(const mat4 *m)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            if (!isfinite(m->m[r][c])) return false;
    return true;
}

/* A polygon edge by the exact bits of its RIB vertices (the lower first)
 * and of its object's transform, for finding shared ones. */
typedef struct world_edge { double key[6 + 16]; int obj, edge; } world_edge;

static int edge_cmp(const void *x, const void *y)
{
    const world_edge *a = x, *b = y;
    int c = memcmp(a->key, b->key, sizeof a->key);
    return c ? c : (a->obj > b->obj) - (a->obj < b->obj);
}

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

/* The edges polygons share (the meshes of Polygon and PointsPolygons
 * calls, whose shared vertices are the same numbers under the same
 * transform): the hit proofs (intersect.c) stay off near them, where the
 * neighbour's leaves decide. Sorted by their exact bits, so equal edges
 * are neighbours: O(n log n) for meshes of any size. */
static void find_shared_edges(trace_world *world)
{
    size_t n = 0;
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        obj->shared_edges = 0;
        if (obj->surf.kind == GEOM_POLYGON) n += (size_t)obj->surf.nuv;
    }
    if (n < 2) return;
    world_edge *e = xcalloc(n, sizeof *e);
    n = 0;
    for (int i = 0; i < world->nobjects; i++) {
        const trace_object *obj = &world->objects[i];
        if (obj->surf.kind != GEOM_POLYGON) continue;
        for (int k = 0; k < obj->surf.nuv && k < 64; k++) {
            vec3 a, b;
            geom_polygon_edge(&obj->surf, k, &a, &b);
            a = rib_vertex(&obj->surf, a);
            b = rib_vertex(&obj->surf, b);
            double pa[3] = {a.x, a.y, a.z}, pb[3] = {b.x, b.y, b.z};
            bool swap = memcmp(pb, pa, sizeof pa) < 0;
            world_edge *w = &e[n++];
            memcpy(w->key, swap ? pb : pa, sizeof pa);
            memcpy(w->key + 3, swap ? pa : pb, sizeof pa);
            memcpy(w->key + 6, obj->to_camera.m, sizeof obj->to_camera.m);
            w->obj = i;
            w->edge = k;
        }
    }
    qsort(e, n, sizeof *e, edge_cmp);
    for (size_t i = 0; i + 1 < n; i++) {
        size_t j = i + 1;
        if (memcmp(e[i].key, e[j].key, sizeof e[i].key) != 0 || e[i].obj == e[j].obj) continue;
        world->objects[e[i].obj].shared_edges |= (uint64_t)1 << e[i].edge;
        world->objects[e[j].obj].shared_edges |= (uint64_t)1 << e[j].edge;
    }
    free(e);
}

bool trace_world_prepare(trace_world *world, char *err, size_t errsz)
{
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        double s = stretch_of(&obj->to_camera), si = stretch_of(&obj->from_camera);
        if (!matrix_finite(&obj->to_camera) || !matrix_finite(&obj->from_camera) ||
            !(s > 0) || !isfinite(s * si) || s * si > 1e12) {
            err_set(err, errsz, "%s: its transformation to camera space is not "
                     "finite or nearly singular (stretch %.3g, inverse stretch %.3g); check "
                     "the Translate/Scale/ConcatTransform values before it", obj->name, s, si);
            return false;
        }
        obj->id = i;
        obj->scale = s;
        obj->normal_scale = normal_scale_of(obj);
        /* |from_camera^T n| lies between the smallest and the largest
         * stretch of from_camera: 1/stretch(to_camera) and stretch(from),
         * both rounded outward (stretch_of rounds up) */
        double lo = 1.0 / s;
        obj->normal_len2[0] = lo * lo * (1.0 - 1e-9);
        obj->normal_len2[1] = si * si * (1.0 + 1e-9);
        grid_spacing(world, obj);
        const sl_program *dp = obj->displacement ? sl_instance_program(obj->displacement) : NULL;
        obj->box_skip_tangents = dp && !sl_program_takes_derivatives(dp) &&
                                 !sl_program_reads_global(dp, SL_G_dPdu) &&
                                 !sl_program_reads_global(dp, SL_G_dPdv);
    }
    find_shared_edges(world);
    return true;
}
