/*
 * codec_err.h: the error handlers aafarm installs in libpng and
 * OpenEXRCore, written once for common/tex (the texture readers and the
 * texture writer) and common/image (tiles, the output file, the PNG
 * preview), so that a codec's complaint becomes part of a one-line message
 * (util/err.h) and nothing is printed.
 *
 * Why here: tex is the lower of the two layers that use the codecs (util
 * <- aa <- tex <- sl <- geom <- trace <- scene <- image) and already links
 * both, so image reaches these by linking tex; util stays free of codec
 * headers.
 */
#ifndef TEX_CODEC_ERR_H
#define TEX_CODEC_ERR_H

#include <openexr.h>
#include <png.h>

/* libpng: create the struct with a tex_png_error as its error pointer and
 * these two handlers; an error keeps libpng's text in message and
 * longjmps to the caller's setjmp; warnings are dropped. */
typedef struct tex_png_error {
    char message[200];
} tex_png_error;

void tex_png_on_error(png_structp png, png_const_charp msg);
void tex_png_on_warning(png_structp png, png_const_charp msg);

/* OpenEXRCore: the context's error_handler_fn. It keeps the first message
 * of this thread's current operation (later ones are usually the same
 * failure reported again further up OpenEXRCore's call chain) in a
 * per-thread buffer: it never calls back into the context, which
 * OpenEXRCore holds locked while it reports (image/exr_io.c). */
void tex_exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg);
/* Forgets the kept message (before an operation whose failure is reported). */
void tex_exr_clear(void);
/* Keeps msg unless a message is kept already (a failure found by aafarm
 * itself, reported like OpenEXRCore's). */
void tex_exr_note(const char *msg);
/* The kept message; "" when none. */
const char *tex_exr_message(void);
/* The kept message, else OpenEXRCore's text for rv. */
const char *tex_exr_reason(exr_result_t rv);

#endif
