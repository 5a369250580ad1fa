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
