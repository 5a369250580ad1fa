/*
 * peers_png.h: the image files of the peer benchmark (bench/peers/):
 * 16-bit RGBA PNG holding LINEAR values (no gamma), which is what POV-Ray
 * writes with +FN16 +UA File_Gamma=1.0, so aafarm's, POV-Ray's and
 * Embree's images are compared in one format. Alpha is the hit mask
 * (one ray per pixel: 0 or 1).
 */
#ifndef PEERS_PNG_H
#define PEERS_PNG_H

#include <stdbool.h>

/* rgba: w*h*4 floats in [0,1] (clamped), rows top to bottom. false with a
 * message naming the file in err. */
bool peers_png_write(const char *path, int w, int h, const float *rgba,
                     char *err, int errsz);

/* Reads any 8/16-bit PNG as linear RGBA floats (malloc'd into *rgba).
 * false with a message naming the file in err. */
bool peers_png_read(const char *path, int *w, int *h, float **rgba,
                    char *err, int errsz);

#endif
