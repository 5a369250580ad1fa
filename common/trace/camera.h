/*
 * camera.h: primary rays of RenderMan's camera model (RI Spec 3.2 §4.1.1):
 * camera space is left-handed, the camera looks down +z, x right, y up;
 * raster (x right, y down, pixel (i,j) covers [i,i+1) x [j,j+1)) maps
 * linearly onto the ScreenWindow; perspective projection scales the
 * screen window by tan(fov/2) at z = 1.
 *
 * Also the pixel footprint used as the subdivision tolerance (Heidrich &
 * Seidel §3: stop when a box covers less than a pixel; ShadingRate scales
 * the size).
 */
#ifndef TRACE_CAMERA_H
#define TRACE_CAMERA_H

#include "trace/box.h"
#include "trace/intersect.h"
#include "trace/world.h"

/* The primary ray through raster position (x, y). For perspective the
 * direction has z = 1, so the ray parameter is the camera-space depth. */
void trace_camera_ray(const trace_camera *cam, double x, double y, trace_ray *ray);

/* Leaf tolerance for primary rays: box size allowed at parameter t. */
trace_tolerance trace_camera_tolerance(const trace_camera *cam, double shading_rate,
                                       double leaf_fraction);

#endif
