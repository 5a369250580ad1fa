/*
 * render.c: preparing a world for rendering and rendering tiles (see
 * render.h): samples, pixel filter (RI Spec 3.2 §4.1.4 filter functions),
 * exposure.
 */
#include "trace/render.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace/camera.h"
#include "trace/instance.h"
#include "trace/group.h"
#include "trace/mesh.h"
#include "trace/sampler.h"
#include "trace/shade.h"
#include "util/err.h"
#include "util/xalloc.h"

trace_renderer *trace_renderer_new(trace_world *world, char *err, size_t errsz)
{
    if (!trace_world_prepare(world, err, errsz))
        return NULL;
    trace_thread *th = trace_thread_new(world);
    trace_instances_share(th, world);
    /* a displaced mesh's placements: moved or own (own ones take ids) */
    int nids = world->nids;
    if (trace_group_classify_meshes(th, world) && world->nids != nids) {
        trace_thread_destroy(&th);     /* its box cache knew fewer ids */
        th = trace_thread_new(world);
    }
    for (int i = 0; i < world->nobjects && !th->failed; i++) {
        if (trace_thread_cancelled(th)) break;   /* a signal: stop between objects */
        trace_object *obj = &world->objects[i];
        if (obj->group) {
            /* its placements' boxes (its prototype, before it, is built) */
            trace_group_build(th, obj->group, obj);
            continue;
        }
        if (obj->mesh) {
            trace_mesh_build(th, obj);          /* its pieces' boxes and BVH */
            continue;
        }
        if (obj->box_proto) {
            obj->root = obj->box_proto->root;   /* an earlier object: computed */
        } else if (obj->displacement) {
            trace_surface_box(th, obj, 0, 1, 0, 1, &obj->root);
        } else {
            geom_bounds(&obj->surf, &obj->root.lo, &obj->root.hi);
            obj->root.flags = 0;
            trace_box_no_slab(&obj->root);
        }
        trace_object_camera_bound(obj, &obj->root, &obj->bound);
    }
    if (th->failed) {
        err_set(err, errsz, "%s", th->error);
        trace_thread_destroy(&th);
        return NULL;
    }
    trace_thread_destroy(&th);
    trace_renderer *self = xcalloc(1, sizeof *self);
    self->world = world;
    self->bvh = trace_bvh_new(world);
    self->shadow_warned = xcalloc((size_t)world->nlights + 1, sizeof *self->shadow_warned);
    self->primary_tol = trace_camera_tolerance(&world->camera, world->shading_rate,
                                               world->options.leaf_fraction);
    return self;
}

void trace_renderer_destroy(trace_renderer **self_p)
{
    trace_renderer *self = *self_p;
    if (!self) return;
    trace_bvh_destroy(&self->bvh);
    free(self->shadow_warned);
    free(self);
    *self_p = NULL;
}

void trace_renderer_set_log(trace_renderer *self, trace_log_fn fn, void *user)
{
    self->log = fn;
    self->log_user = user;
}

void trace_render_sample(const trace_renderer *self, trace_thread *th,
                         double x, double y, double rgb[3], double *alpha,
                         double *z)
{
    trace_render_sample_lens(self, th, x, y, 0.5, 0.5, rgb, alpha, z);
}

void trace_render_sample_lens(const trace_renderer *self, trace_thread *th, double x,
                              double y, double lu, double lv, double rgb[3], double *alpha,
                              double *z)
{
    trace_ray ray;
    trace_camera_lens_ray(&self->world->camera, x, y, lu, lv, &ray);
    trace_hit hit = {.t = ray.tmax, .obj = NULL};
    th->stats.primary_rays++;
    if (!trace_bvh_intersect(self->bvh, th, &ray, &self->primary_tol, false, &hit)) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        *alpha = 0;
        *z = INFINITY;
        return;
    }
    vec3 P;
    trace_shade_hit(self, th, &ray, &hit, rgb, alpha, &P);
    *z = trace_ray_at(&ray, hit.t).z;
}

/* ---- pixel filter ---- */

static double filter_weight(const trace_world *w, double dx, double dy)
{
    double wx = w->filter_width[0], wy = w->filter_width[1];
    switch (w->filter) {
    case TRACE_FILTER_GAUSSIAN: {
        double x = dx * 2.0 / wx, y = dy * 2.0 / wy;
        return exp(-2.0 * (x * x + y * y));
    }
    case TRACE_FILTER_TRIANGLE:
        return (1.0 - fabs(dx) / (0.5 * wx)) * (1.0 - fabs(dy) / (0.5 * wy));
    case TRACE_FILTER_CATMULL_ROM: {
        /* radial, support 2 (in units of half the width) */
        double x = dx * 4.0 / wx, y = dy * 4.0 / wy, r = sqrt(x * x + y * y);
        if (r >= 2) return 0;
        if (r < 1) return 3 * r * r * r - 5 * r * r + 2;
        return -r * r * r + 5 * r * r - 8 * r + 4;
    }
    case TRACE_FILTER_SINC: {
        double x = dx * M_PI, y = dy * M_PI;
        return (x != 0 ? sin(x) / x : 1.0) * (y != 0 ? sin(y) / y : 1.0);
    }
    case TRACE_FILTER_BOX:
    default:
        return 1.0;
    }
}

typedef struct sample_rec { float x, y, r, g, b, a, z; } sample_rec;

/* A tile's samples: every sample of every pixel whose filter reaches the
 * tile, traced in blocks of TRACE_TILE_BLOCK consecutive Morton indices. */
struct trace_tile_samples {
    int x0, y0, w, h;          /* the tile */
    int qx0, qy0, qw, qh;      /* the pixels whose samples it needs */
    int nx, ny, ns;            /* samples per pixel */
    int side;                  /* the power-of-two square of the Morton order */
    int nblocks;
    sample_rec *smp;           /* qw x qh pixels of ns samples, row-major */
};

trace_tile_samples *trace_tile_samples_new(const trace_renderer *self, int x0, int y0,
                                           int w, int h)
{
    const trace_world *world = self->world;
    double rx = 0.5 * world->filter_width[0], ry = 0.5 * world->filter_width[1];
    trace_tile_samples *ts = xcalloc(1, sizeof *ts);
    ts->x0 = x0;
    ts->y0 = y0;
    ts->w = w;
    ts->h = h;
    ts->nx = world->samples_x > 0 ? world->samples_x : 1;
    ts->ny = world->samples_y > 0 ? world->samples_y : 1;
    ts->ns = ts->nx * ts->ny;
    /* pixels whose samples can reach the tile's pixels through the filter:
     * pixel q's samples lie in [q, q + 1) (trace_sample_position), and one
     * at s counts for the pixel centred at c where c - r <= s < c + r
     * (trace_tile_samples_filter), so the first is floor(x0 + 0.5 - r) and
     * the last ceil(x0 + w - 0.5 + r) - 1 (a box filter of width 1: the
     * tile's own pixels, no ring of neighbours whose samples would all get
     * weight 0) */
    ts->qx0 = (int)floor(x0 + 0.5 - rx);
    ts->qy0 = (int)floor(y0 + 0.5 - ry);
    ts->qw = (int)ceil(x0 + w - 0.5 + rx) - 1 - ts->qx0 + 1;
    ts->qh = (int)ceil(y0 + h - 0.5 + ry) - 1 - ts->qy0 + 1;
    ts->smp = xmalloc(sizeof(sample_rec) * (size_t)ts->qw * (size_t)ts->qh * (size_t)ts->ns);
    ts->side = 1;
    while (ts->side < ts->qw || ts->side < ts->qh) ts->side *= 2;
    long cells = (long)ts->side * ts->side;
    ts->nblocks = (int)((cells + TRACE_TILE_BLOCK - 1) / TRACE_TILE_BLOCK);
    return ts;
}

int trace_tile_samples_blocks(const trace_tile_samples *ts)
{
    return ts->nblocks;
}

void trace_tile_samples_destroy(trace_tile_samples **ts_p)
{
    if (!*ts_p) return;
    free((*ts_p)->smp);
    free(*ts_p);
    *ts_p = NULL;
}

bool trace_tile_samples_trace(const trace_renderer *self, trace_thread *th,
                              trace_tile_samples *ts, int block)
{
    assert(block >= 0 && block < ts->nblocks);
    const trace_world *world = self->world;
    /* The pixels in Morton (Z) order over the smallest power-of-two square
     * that holds them: consecutive rays stay close in both directions, so
     * the box cache keeps what the next rays need (Heidrich & Seidel §6:
     * neighbouring rays share the quadtree's boxes). Each sample is a pure
     * function of its pixel and index, so the order, and which thread
     * traces which block, change no result. */
    long m0 = (long)block * TRACE_TILE_BLOCK;
    long m1 = m0 + TRACE_TILE_BLOCK;
    if (m1 > (long)ts->side * ts->side) m1 = (long)ts->side * ts->side;
    for (long m = m0; m < m1; m++) {
        int mx = 0, my = 0;
        for (int bit = 0; (1L << (2 * bit)) <= m; bit++) {
            mx |= (int)((m >> (2 * bit)) & 1) << bit;
            my |= (int)((m >> (2 * bit + 1)) & 1) << bit;
        }
        if (mx >= ts->qw || my >= ts->qh) continue;
        int qx = ts->qx0 + mx, qy = ts->qy0 + my;
        sample_rec *r = &ts->smp[((size_t)my * (size_t)ts->qw + (size_t)mx) * (size_t)ts->ns];
        for (int s = 0; s < ts->ns; s++) {
            if (th->failed || trace_thread_cancelled(th)) return false;
            double sx, sy, lu = 0.5, lv = 0.5, rgb[3], a, d;
            trace_sample_position(qx, qy, s, ts->nx, ts->ny, &sx, &sy);
            if (world->camera.lens_radius > 0)
                trace_sample_lens(qx, qy, s, ts->nx, ts->ny, &lu, &lv);
            trace_render_sample_lens(self, th, sx, sy, lu, lv, rgb, &a, &d);
            /* the offset inside the pixel (exact), rounded to float the
             * same way in every tile that traces this sample */
            r[s] = (sample_rec){(float)(sx - qx), (float)(sy - qy), (float)rgb[0],
                                (float)rgb[1], (float)rgb[2], (float)a, (float)d};
        }
    }
    return !th->failed;
}

void trace_tile_samples_filter(const trace_renderer *self, const trace_tile_samples *ts,
                               float *rgba, float *z)
{
    const trace_world *world = self->world;
    double rx = 0.5 * world->filter_width[0], ry = 0.5 * world->filter_width[1];
    int x0 = ts->x0, y0 = ts->y0, w = ts->w, h = ts->h, ns = ts->ns;
    int qx0 = ts->qx0, qy0 = ts->qy0, qw = ts->qw;
    int qx1 = qx0 + ts->qw - 1, qy1 = qy0 + ts->qh - 1;
    const sample_rec *smp = ts->smp;
    double inv_gamma = world->gamma > 0 ? 1.0 / world->gamma : 1.0;
    for (int py = y0; py < y0 + h; py++)
        for (int px = x0; px < x0 + w; px++) {
            double cx = px + 0.5, cy = py + 0.5, sum[4] = {0, 0, 0, 0}, wsum = 0;
            float zmin = INFINITY;
            /* the pixels whose samples can count here: a sample s of
             * pixel q lies in [q, q + 1 - 2^-24] (trace_sample_position)
             * and counts where cx - rx <= s < cx + rx, so q > cx - rx - 1,
             * i.e. q >= floor(cx - rx) (the rounding of cx - rx is far
             * below 2^-24 for raster coordinates under 2^28), and q <= s <
             * cx + rx, i.e. q <= ceil(cx + rx) - 1 (a box filter of one
             * pixel: that pixel alone, not its neighbour's samples tested
             * and refused) */
            int ax0 = (int)floor(cx - rx), ax1 = (int)ceil(cx + rx) - 1;
            int ay0 = (int)floor(cy - ry), ay1 = (int)ceil(cy + ry) - 1;
            for (int qy = ay0; qy <= ay1; qy++) {
                if (qy < qy0 || qy > qy1) continue;
                for (int qx = ax0; qx <= ax1; qx++) {
                    if (qx < qx0 || qx > qx1) continue;
                    const sample_rec *r = &smp[(((size_t)(qy - qy0) * (size_t)qw) + (size_t)(qx - qx0)) * (size_t)ns];
                    for (int s = 0; s < ns; s++) {
                        double dx = (qx + (double)r[s].x) - cx, dy = (qy + (double)r[s].y) - cy;
                        if (!(dx >= -rx && dx < rx && dy >= -ry && dy < ry)) continue;
                        double wgt = filter_weight(world, dx, dy);
                        sum[0] += wgt * r[s].r;
                        sum[1] += wgt * r[s].g;
                        sum[2] += wgt * r[s].b;
                        sum[3] += wgt * r[s].a;
                        wsum += wgt;
                        if (qx == px && qy == py && r[s].z < zmin) zmin = r[s].z;
                    }
                }
            }
            float *o = &rgba[((size_t)(py - y0) * (size_t)w + (size_t)(px - x0)) * 4];
            for (int k = 0; k < 4; k++) {
                double v = wsum > 0 ? sum[k] / wsum : 0.0;
                if (k < 3) {
                    v *= world->gain;
                    if (inv_gamma != 1.0 && v > 0) v = pow(v, inv_gamma);
                }
                o[k] = (float)v;
            }
            z[(size_t)(py - y0) * (size_t)w + (size_t)(px - x0)] = zmin;
        }
}

bool trace_render_tile(const trace_renderer *self, trace_thread *th,
                       int x0, int y0, int w, int h, float *rgba, float *z)
{
    trace_tile_samples *ts = trace_tile_samples_new(self, x0, y0, w, h);
    bool ok = true;
    for (int b = 0; ok && b < ts->nblocks; b++) ok = trace_tile_samples_trace(self, th, ts, b);
    if (ok) trace_tile_samples_filter(self, ts, rgba, z);
    trace_tile_samples_destroy(&ts);
    return ok;
}
