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

/* The primary ray through raster position (x, y) from lens position
 * (lu, lv) in [0,1)^2 (trace_sample_lens; 0.5 0.5 is the lens centre):
 * with a thin lens (DepthOfField) it starts on the lens disk, at depth 0,
 * and passes through the point the pinhole ray meets at the focal
 * distance, so whatever lies at that depth is sharp and a point at depth
 * z spreads over a circle of confusion of diameter
 *     2 lens_radius |z - focal_distance| / (z focal_distance)
 * at z = 1 (camera.c). The direction keeps z = 1 (t is the depth). A
 * pinhole camera ignores (lu, lv). */
void trace_camera_lens_ray(const trace_camera *cam, double x, double y, double lu, double lv,
                           trace_ray *ray);

/* Leaf tolerance for primary rays: box size allowed at parameter t. */
trace_tolerance trace_camera_tolerance(const trace_camera *cam, double shading_rate,
                                       double leaf_fraction);

#endif
