/*
 * render.c: preparing a world for rendering and rendering tiles (see
 * render.h): samples, pixel filter (RI Spec 3.2 §4.1.4 filter functions),
 * exposure.
 */
#include "trace/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace/camera.h"
#include "trace/sampler.h"
#include "trace/shade.h"

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

static void camera_bound(const trace_object *obj, const trace_box *b, trace_box *out)
{
    if (b->flags & AA_UNBOUNDED || !isfinite(b->lo.x + b->lo.y + b->lo.z + b->hi.x + b->hi.y + b->hi.z)) {
        out->lo = v3(-INFINITY, -INFINITY, -INFINITY);
        out->hi = v3(INFINITY, INFINITY, INFINITY);
        out->flags = AA_UNBOUNDED;
        return;
    }
    out->flags = b->flags;
    for (int i = 0; i < 8; i++) {
        vec3 c = v3((i & 1) ? b->hi.x : b->lo.x, (i & 2) ? b->hi.y : b->lo.y,
                    (i & 4) ? b->hi.z : b->lo.z);
        vec3 p = mat4_xform_point(&obj->to_camera, c);
        if (i == 0) { out->lo = out->hi = p; continue; }
        out->lo = v3(fmin(out->lo.x, p.x), fmin(out->lo.y, p.y), fmin(out->lo.z, p.z));
        out->hi = v3(fmax(out->hi.x, p.x), fmax(out->hi.y, p.y), fmax(out->hi.z, p.z));
    }
    /* the corner transform rounds: widen by a relative hair */
    vec3 e = v3_scale(v3(fabs(out->hi.x) + fabs(out->lo.x), fabs(out->hi.y) + fabs(out->lo.y),
                         fabs(out->hi.z) + fabs(out->lo.z)), 1e-12);
    out->lo = v3_sub(out->lo, e);
    out->hi = v3_add(out->hi, e);
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

trace_renderer *trace_renderer_new(trace_world *world, char *err, int errsz)
{
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        double s = stretch_of(&obj->to_camera), si = stretch_of(&obj->from_camera);
        if (!matrix_finite(&obj->to_camera) || !matrix_finite(&obj->from_camera) ||
            !(s > 0) || !isfinite(s * si) || s * si > 1e12) {
            snprintf(err, (size_t)errsz, "%s: its transformation to camera space is not "
                     "finite or nearly singular (stretch %.3g, inverse stretch %.3g); check "
                     "the Translate/Scale/ConcatTransform values before it", obj->name, s, si);
            return NULL;
        }
    }
    trace_thread *th = trace_thread_new(world);
    for (int i = 0; i < world->nobjects; i++) {
        trace_object *obj = &world->objects[i];
        obj->id = i;
        obj->scale = stretch_of(&obj->to_camera);
        obj->normal_scale = normal_scale_of(obj);
        /* |from_camera^T n| lies between the smallest and the largest
         * stretch of from_camera: 1/stretch(to_camera) and stretch(from),
         * both rounded outward (stretch_of rounds up) */
        double lo = 1.0 / obj->scale, hi = stretch_of(&obj->from_camera);
        obj->normal_len2[0] = lo * lo * (1.0 - 1e-9);
        obj->normal_len2[1] = hi * hi * (1.0 + 1e-9);
        grid_spacing(world, obj);
        if (obj->displacement) {
            trace_surface_box(th, obj, 0, 1, 0, 1, &obj->root);
        } else {
            geom_bounds(&obj->surf, &obj->root.lo, &obj->root.hi);
            obj->root.flags = 0;
        }
        camera_bound(obj, &obj->root, &obj->bound);
    }
    if (th->failed) {
        snprintf(err, (size_t)errsz, "%s", th->error);
        trace_thread_destroy(&th);
        return NULL;
    }
    trace_thread_destroy(&th);
    trace_renderer *self = calloc(1, sizeof *self);
    if (!self) abort();
    self->world = world;
    self->bvh = trace_bvh_new(world);
    self->primary_tol = trace_camera_tolerance(&world->camera, world->shading_rate,
                                               world->options.leaf_fraction);
    return self;
}

void trace_renderer_destroy(trace_renderer **self_p)
{
    trace_renderer *self = *self_p;
    if (!self) return;
    trace_bvh_destroy(&self->bvh);
    free(self);
    *self_p = NULL;
}

void trace_render_sample(const trace_renderer *self, trace_thread *th,
                         double x, double y, double rgb[3], double *alpha,
                         double *z)
{
    trace_ray ray;
    trace_camera_ray(&self->world->camera, x, y, &ray);
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

bool trace_render_tile(const trace_renderer *self, trace_thread *th,
                       int x0, int y0, int w, int h, float *rgba, float *z)
{
    const trace_world *world = self->world;
    double rx = 0.5 * world->filter_width[0], ry = 0.5 * world->filter_width[1];
    int nx = world->samples_x > 0 ? world->samples_x : 1;
    int ny = world->samples_y > 0 ? world->samples_y : 1;
    int ns = nx * ny;
    /* pixels whose samples can reach the tile's pixels through the filter */
    int qx0 = (int)floor(x0 + 0.5 - rx), qx1 = (int)floor(x0 + w - 0.5 + rx);
    int qy0 = (int)floor(y0 + 0.5 - ry), qy1 = (int)floor(y0 + h - 0.5 + ry);
    int qw = qx1 - qx0 + 1, qh = qy1 - qy0 + 1;
    sample_rec *smp = malloc(sizeof(sample_rec) * (size_t)qw * (size_t)qh * (size_t)ns);
    if (!smp) {
        trace_thread_fail(th, "out of memory for the samples of a tile");
        return false;
    }
    for (int qy = qy0; qy <= qy1; qy++)
        for (int qx = qx0; qx <= qx1; qx++)
            for (int s = 0; s < ns; s++) {
                if (th->failed || trace_thread_cancelled(th)) {
                    free(smp);
                    return false;
                }
                sample_rec *r = &smp[(((size_t)(qy - qy0) * (size_t)qw) + (size_t)(qx - qx0)) * (size_t)ns + (size_t)s];
                double sx, sy, rgb[3], a, d;
                trace_sample_position(qx, qy, s, nx, ny, &sx, &sy);
                trace_render_sample(self, th, sx, sy, rgb, &a, &d);
                /* the offset inside the pixel (exact), rounded to float the
                 * same way in every tile that traces this sample */
                *r = (sample_rec){(float)(sx - qx), (float)(sy - qy), (float)rgb[0],
                                  (float)rgb[1], (float)rgb[2], (float)a, (float)d};
            }
    double inv_gamma = world->gamma > 0 ? 1.0 / world->gamma : 1.0;
    for (int py = y0; py < y0 + h; py++)
        for (int px = x0; px < x0 + w; px++) {
            double cx = px + 0.5, cy = py + 0.5, sum[4] = {0, 0, 0, 0}, wsum = 0;
            float zmin = INFINITY;
            int ax0 = (int)floor(cx - rx) - 1, ax1 = (int)floor(cx + rx);
            int ay0 = (int)floor(cy - ry) - 1, ay1 = (int)floor(cy + ry);
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
    free(smp);
    return !th->failed;
}
