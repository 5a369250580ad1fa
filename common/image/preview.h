/*
 * preview.h: an 8-bit sRGB PNG preview of a render (libpng).
 *
 * Conversion, per channel R G B:
 *   1. composite over black: the renderer's colour is premultiplied by
 *      alpha (the OpenEXR convention), so over black it is just R G B;
 *      the PNG has no alpha channel (colour type RGB, 8 bits);
 *   2. sRGB transfer function (IEC 61966-2-1): 12.92 c for c <= 0.0031308,
 *      else 1.055 c^(1/2.4) - 0.055;
 *   3. clamp to [0, 1] (NaN -> 0, +inf -> 1), scale by 255 and round to
 *      nearest; no dithering, so the same pixels always give the same
 *      file.
 * The PNG carries an sRGB chunk (perceptual intent) and no time stamp; it
 * is written to "OUT.png.tmp-<pid>" and renamed over OUT.png when complete
 * (outfile.h).
 */
#ifndef IMAGE_PREVIEW_H
#define IMAGE_PREVIEW_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/buffer.h"

/* Linear value -> 8-bit sRGB code value, as described above. */
uint8_t image_preview_srgb8(float linear);

/* Writes a width x height preview from interleaved RGBA floats (4 per
 * pixel, row-major, top row first; alpha unused, see above). */
bool image_preview_write_png(const char *path, const float *rgba, int width,
                             int height, char *err, size_t errsz);

/* Writes the preview of an image buffer's R, G and B channels (a channel
 * that is missing reads as 0). */
bool image_preview_write_png_buffer(const char *path, const image_buffer *buf,
                                    char *err, size_t errsz);

/* Writes the preview of a finished EXR file: its R, G and B as stored
 * (half floats), read back. The farm's master and the standalone renderer
 * both make their previews here, from the same samples, so the two PNGs
 * are the same bytes (issue 27: a preview made from the renderer's floats
 * differed by 1 LSB where rounding to half moved a value across a code). */
bool image_preview_write_png_exr(const char *png_path, const char *exr_path,
                                 char *err, size_t errsz);

/* As image_preview_write_png_exr, looking at cancel (the program's stop
 * flag, or NULL) before each chunk read and each row written: when it is
 * set, false with "interrupted" and no PNG (its temporary file removed). */
bool image_preview_write_png_exr_cancel(const char *png_path, const char *exr_path,
                                        const atomic_int *cancel, char *err, size_t errsz);
/* Encodes width x height pixels already converted to 8-bit sRGB codes
 * (image_preview_srgb8; 3 bytes a pixel, row-major, top row first) as a
 * PNG in memory, with the settings of the files above, so the same pixels
 * give the same bytes as image_preview_write_png(). *png (the caller
 * frees) and *len hold it. For the master's live image (master/monitor.h). */
bool image_preview_encode_png_rgb8(const uint8_t *rgb, int width, int height,
                                   void **png, size_t *len, char *err,
                                   size_t errsz);

#endif
