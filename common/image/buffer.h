/*
 * buffer.h: a whole image in memory as float planes, one per channel
 * (image_buffer), read from any ordinary OpenEXR file, and the pixel-by-
 * pixel comparison of two of them.
 *
 * This is what tests everywhere use to check the determinism contract
 * (a farm render equals the standalone render pixel for pixel) and what
 * the preview writer reads. It is not on the render path: the master
 * never holds a whole image.
 *
 * Reading accepts scanline and tiled single-part files (the first part of
 * a multi-part file; level 0 of mip/rip-mapped files) with any
 * compression OpenEXRCore supports and HALF, FLOAT or UINT channels, all
 * converted to float. Deep files and subsampled channels are rejected
 * with a message. Planes cover the data window: plane[c][y*width + x] is
 * pixel (x0 + x, y0 + y). Channels keep the file's (sorted) order.
 *
 * Memory: this is the one part of common/image that survives out of
 * memory (util/xalloc.h try_*): the size of a buffer comes from a file's
 * header, so an image too large for this process is refused with a message
 * ("image too large to read into memory") instead of aborting the reader;
 * tests/image/test_image_buffer.c drives it. The rest of common/image
 * (tiles, the writer, the output file, the preview) holds a few MB whose
 * size the image format bounds, and aborts naming the size (x*).
 */
#ifndef IMAGE_BUFFER_H
#define IMAGE_BUFFER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

typedef struct image_buffer {
    int x0, y0;            /* data window origin */
    int width, height;     /* data window size */
    int channel_count;
    char **names;          /* channel_count names */
    float **planes;        /* channel_count planes of width*height floats */
} image_buffer;

/* A zero-filled buffer with the given channels; NULL on bad sizes
 * (more than 2^31 samples) or when memory runs out. */
image_buffer *image_buffer_new(int width, int height, int channel_count,
                               const char *const *names);
void image_buffer_destroy(image_buffer **self_p);

/* Reads `path`; NULL with a one-line reason in err. */
image_buffer *image_buffer_read_exr(const char *path, char *err, size_t errsz);

/* As image_buffer_read_exr, looking at cancel (the program's stop flag, or
 * NULL) before each chunk: NULL with "interrupted" when it is set. */
image_buffer *image_buffer_read_exr_cancel(const char *path, const atomic_int *cancel,
                                           char *err, size_t errsz);

/* The plane of channel `name`, or NULL. */
float *image_buffer_channel(const image_buffer *self, const char *name);

/* Result of a comparison. Two samples are equal when both are NaN or when
 * |a - b| <= tolerance (infinities of the same sign are equal). */
typedef struct image_diff {
    size_t count;          /* samples that differ */
    double max_abs;        /* largest |a - b| (inf when a NaN meets a number) */
    char channel[64];      /* where the largest difference is */
    int x, y;              /* ... in full-image coordinates */
} image_diff;

/* Compares a and b sample by sample. False (and err) when they cannot be
 * compared: different data windows or channel lists. True otherwise, with
 * *diff filled (diff->count == 0 means equal within tolerance). */
bool image_buffer_compare(const image_buffer *a, const image_buffer *b,
                          double tolerance, image_diff *diff,
                          char *err, size_t errsz);

#endif
