/*
 * pinholes.h: the pinhole count of issue 14: pixels that are not opaque
 * (alpha < 1) although all eight of their neighbours are. On an image of
 * one closed object every such pixel is a ray that slipped through the
 * surface (a crack between faces, a box that lost the surface), so renders
 * of closed displaced objects must count 0.
 */
#ifndef TESTS_TRACE_PINHOLES_H
#define TESTS_TRACE_PINHOLES_H

/* rgba: w x h pixels, 4 floats each (alpha last). Border pixels, which lack
 * neighbours, are not counted. */
int count_pinholes(const float *rgba, int w, int h);

/* Pixels with alpha exactly 1 (to check that the object fills the image
 * enough for the count to mean something). */
int count_opaque(const float *rgba, int w, int h);

#endif
