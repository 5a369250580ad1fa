/*
 * camera.c: primary rays and the pixel footprint (see camera.h).
 */
#include "trace/camera.h"

#include <math.h>

static void raster_to_screen(const trace_camera *cam, double x, double y,
                             double *sx, double *sy)
{
    const double *w = cam->screen;   /* left right bottom top */
    *sx = w[0] + (x / cam->xres) * (w[1] - w[0]);
    *sy = w[3] - (y / cam->yres) * (w[3] - w[2]);
}

void trace_camera_ray(const trace_camera *cam, double x, double y, trace_ray *ray)
{
    double sx, sy;
    raster_to_screen(cam, x, y, &sx, &sy);
    if (cam->orthographic)
        trace_ray_init(ray, v3(sx, sy, 0), v3(0, 0, 1), cam->near_clip, cam->far_clip);
    else
        trace_ray_init(ray, v3(0, 0, 0),
                       v3(sx * cam->tan_half_fov, sy * cam->tan_half_fov, 1.0),
                       cam->near_clip, cam->far_clip);
}

/* Shirley & Chiu's concentric map of the unit square onto the unit disk
 * (it keeps strata compact, and (0.5, 0.5) -> the centre). */
static void concentric_disk(double u, double v, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0 && b == 0) {
        *x = *y = 0;
        return;
    }
    double r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (M_PI / 2.0) - (M_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

void trace_camera_lens_ray(const trace_camera *cam, double x, double y, double lu, double lv,
                           trace_ray *ray)
{
    trace_camera_ray(cam, x, y, ray);
    if (!(cam->lens_radius > 0))
        return;
    double dx, dy;
    concentric_disk(lu, lv, &dx, &dy);
    dx *= cam->lens_radius;
    dy *= cam->lens_radius;
    /* the pinhole ray's point at the focal distance (its direction has
     * z = 1), reached from the lens point: direction (F - o') / fd */
    double fd = cam->focal_distance;
    vec3 o = v3(ray->o.x + dx, ray->o.y + dy, ray->o.z);
    vec3 d = v3(ray->d.x - dx / fd, ray->d.y - dy / fd, ray->d.z);
    trace_ray_init(ray, o, d, cam->near_clip, cam->far_clip);
}

trace_tolerance trace_camera_tolerance(const trace_camera *cam, double shading_rate,
                                       double leaf_fraction)
{
    double px = fabs(cam->screen[1] - cam->screen[0]) / cam->xres;
    double py = fabs(cam->screen[3] - cam->screen[2]) / cam->yres;
    double pixel = px < py ? px : py;
    double k = sqrt(shading_rate > 0 ? shading_rate : 1.0) * leaf_fraction;
    trace_tolerance tol;
    if (cam->orthographic) {
        tol.a = pixel * k;
        tol.b = 0;
    } else {
        tol.a = 0;
        tol.b = pixel * cam->tan_half_fov * k;
    }
    return tol;
}
