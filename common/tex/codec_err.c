/*
 * codec_err.c: the libpng and OpenEXRCore error handlers (codec_err.h).
 */
#include "tex/codec_err.h"

#include <stdio.h>

void tex_png_on_error(png_structp png, png_const_charp msg)
{
    tex_png_error *e = png_get_error_ptr(png);
    snprintf(e->message, sizeof e->message, "%s", msg);
    png_longjmp(png, 1);
}

void tex_png_on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static _Thread_local char exr_message[512];

void tex_exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;              /* locked by the caller: never call back into it here */
    (void)code;
    if (msg)
        tex_exr_note(msg);
}

void tex_exr_clear(void)
{
    exr_message[0] = '\0';
}

void tex_exr_note(const char *msg)
{
    if (exr_message[0] == '\0')
        snprintf(exr_message, sizeof exr_message, "%s", msg);
}

const char *tex_exr_message(void)
{
    return exr_message;
}

const char *tex_exr_reason(exr_result_t rv)
{
    return exr_message[0] ? exr_message : exr_get_default_error_message(rv);
}
