/*
 * read.c: opening an image file as a texture: the format from the file's
 * first bytes (OpenEXR, PNG, TIFF), the reader of that format, then the
 * pyramids (pyramid.c); an aafarm-maketx file opens with its stored
 * pyramids instead (read_tiled.c). Errors name the file and say what to
 * do.
 */
#include "tex/tex_internal.h"
#include "util/err.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

tex_texture *tex_open(const char *path, char *err, size_t errsz)
{
    return tex_open_in(path, NULL, err, errsz);
}

tex_texture *tex_open_in(const char *path, tex_tiles *pool, char *err, size_t errsz)
{
    unsigned char magic[8] = { 0 };
    FILE *f = fopen(path, "rb");
    if (!f) {
        err_set(err, errsz, "%s: cannot open the texture: %s", path, strerror(errno));
        return NULL;
    }
    size_t n = fread(magic, 1, sizeof magic, f);
    fclose(f);
    tex_pixels px = { 0 };
    bool ok;
    if (n >= 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01) {
        tex_texture *tiled = NULL;
        if (!tex_open_tiled(path, pool, &tiled, err, errsz))
            return NULL;
        if (tiled)
            return tiled;        /* aafarm-maketx's, with its pyramids */
        ok = tex_read_exr(path, &px, err, errsz);
    } else if (n >= 8 && memcmp(magic, "\x89PNG\r\n\x1a\n", 8) == 0) {
        ok = tex_read_png(path, &px, err, errsz);
    } else if (n >= 4 && (memcmp(magic, "II*\0", 4) == 0 || memcmp(magic, "MM\0*", 4) == 0 ||
                          memcmp(magic, "II+\0", 4) == 0 || memcmp(magic, "MM\0+", 4) == 0)) {
        ok = tex_read_tiff(path, &px, err, errsz);
    } else {
        err_set(err, errsz, "%s: not an OpenEXR, PNG or TIFF file (its first bytes say "
                "neither); textures must be one of those", path);
        return NULL;
    }
    if (!ok)
        return NULL;
    if (px.w < 1 || px.h < 1 || px.nch < 1 || px.w > TEX_MAX_SIDE || px.h > TEX_MAX_SIDE) {
        err_set(err, errsz, "%s: the image is %d x %d with %d channels; a texture needs at "
                "least 1 x 1 and one channel", path, px.w, px.h, px.nch);
        free(px.data);
        return NULL;
    }
    return tex_build(&px, path);
}

int tex_wrap_find(const char *name)
{
    if (strcmp(name, "periodic") == 0 || strcmp(name, "repeat") == 0)
        return TEX_WRAP_PERIODIC;
    if (strcmp(name, "clamp") == 0)
        return TEX_WRAP_CLAMP;
    if (strcmp(name, "black") == 0)
        return TEX_WRAP_BLACK;
    return -1;
}
