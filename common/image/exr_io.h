/*
 * exr_io.h: the glue between common/image and OpenEXRCore (internal to
 * common/image; not part of the library's public interface).
 *
 * What lives here:
 *   - image_exr_stream: the custom I/O stream handed to every OpenEXRCore
 *     context we open. It reads from a byte buffer (a tile received from
 *     the network) or a file descriptor, and writes to a growing byte
 *     buffer (a tile to send) or a file descriptor (the output file). The
 *     stream also collects the last error message OpenEXRCore reports, so
 *     errors become one-line messages instead of prints on stderr.
 *   - context set-up: every context of aafarm uses the same ZIP level, so
 *     the same pixels always give the same compressed chunk.
 *   - the part definition of an aafarm image (image/format.h) and the
 *     encoder and decoder of one chunk, shared by the tile encoder, the
 *     validator, the output writer and the reader.
 */
#ifndef IMAGE_EXR_IO_H
#define IMAGE_EXR_IO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <openexr.h>

#include "image/format.h"
#include "image/tile.h"
#include "util/err.h"

/* zlib level of every ZIP chunk aafarm writes. Fixed, so that a worker's
 * tile and the standalone renderer's chunk are byte-identical. */
enum { IMAGE_EXR_ZIP_LEVEL = 4 };

typedef struct image_exr_stream {
    const uint8_t *in;     /* memory read: the bytes */
    size_t in_len;
    uint8_t *out;          /* memory write: the bytes written so far */
    size_t out_len, out_cap;
    int fd;                /* file read/write; -1 for memory streams */
    bool discard;          /* drop writes (aborting an output file) */
    int sys_errno;         /* errno of the last failed system call */
    char message[ERR_LEN];  /* last error reported through this stream */
} image_exr_stream;

void image_exr_stream_memory_reader(image_exr_stream *self, const void *bytes,
                                    size_t len);
void image_exr_stream_memory_writer(image_exr_stream *self);
void image_exr_stream_fd(image_exr_stream *self, int fd);
/* Forgets the error messages of earlier operations (call before each
 * OpenEXRCore operation whose failure image_exr_error() will report). */
void image_exr_stream_reset_errors(image_exr_stream *self);
/* Frees a memory writer's buffer (unless taken by setting out to NULL)
 * and zeroes its length and capacity. */
void image_exr_stream_clear(image_exr_stream *self);

/* Open contexts over a stream (name is used in messages only). */
exr_result_t image_exr_start_read(exr_context_t *ctxt, const char *name,
                                  image_exr_stream *stream);
exr_result_t image_exr_start_write(exr_context_t *ctxt, const char *name,
                                   image_exr_stream *stream);

/* Defines the single tiled part of an aafarm image in a write context and
 * writes the header: display window = the whole image of `fmt`, data
 * window = `data_window` (the whole image for the output file, one tile's
 * rectangle for a tile file). */
exr_result_t image_exr_define_part(exr_context_t ctxt, const image_format *fmt,
                                   image_rect data_window);

/* Compresses `tile` (whose size must be the size of tile (tx, ty) of the
 * context's part) and writes it as the chunk of tile (tx, ty). */
exr_result_t image_exr_write_tile(exr_context_t ctxt, const image_format *fmt,
                                  int tx, int ty, const image_tile *tile);

/* Decodes chunk `cinfo` of part 0, converting every channel to float.
 * Channel c (file order) of chunk pixel (x, y) goes to
 * dst[c][y * line_stride + x]; a NULL dst[c] skips the channel. */
exr_result_t image_exr_decode_chunk(exr_const_context_t ctxt,
                                    const exr_chunk_info_t *cinfo,
                                    float *const *dst, size_t line_stride);

/* Writes "what: reason" into err, the reason being the stream's own
 * message (an I/O error with errno) when there is one, else the text
 * OpenEXRCore reported on this thread, else its default text for rv. */
void image_exr_error(char *err, size_t errsz, const char *what,
                     exr_result_t rv, const image_exr_stream *stream);

#endif
