/*
 * read_tiff.c: TIFF textures through libtiff: stripped or tiled images,
 * interleaved (contiguous) or planar, of 8, 16 or 32 bit unsigned
 * integers or 32 bit IEEE floats, any number of samples per pixel.
 * Integer texels are the stored value over 2^bits - 1; floats as they are.
 * libtiff's warnings are silenced and its errors become the message.
 */
#include "tex/tex_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <tiffio.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static _Thread_local char tiff_message[256];

static void on_error(const char *module, const char *fmt, va_list ap)
{
    (void)module;
    vsnprintf(tiff_message, sizeof tiff_message, fmt, ap);
}

static void on_warning(const char *module, const char *fmt, va_list ap)
{
    (void)module;
    (void)fmt;
    (void)ap;
}

static float sample_at(const unsigned char *buf, size_t k, int bits, int format)
{
    if (format == SAMPLEFORMAT_IEEEFP) {
        float v;
        memcpy(&v, buf + 4 * k, 4);
        return v;
    }
    if (bits == 8)
        return (float)(buf[k] / 255.0);
    if (bits == 16) {
        uint16_t v;
        memcpy(&v, buf + 2 * k, 2);
        return (float)(v / 65535.0);
    }
    uint32_t v;
    memcpy(&v, buf + 4 * k, 4);
    return (float)(v / 4294967295.0);
}

bool tex_read_tiff(const char *path, tex_pixels *out, char *err, size_t errsz)
{
    TIFFSetErrorHandler(on_error);
    TIFFSetWarningHandler(on_warning);
    tiff_message[0] = '\0';
    TIFF *tif = TIFFOpen(path, "r");
    if (!tif) {
        return err_set(err, errsz, "%s: not a readable TIFF image: %s", path, tiff_message);
    }
    uint32_t w = 0, h = 0;
    uint16_t spp = 1, bits = 8, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
    TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &h);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &spp);
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
    bool ok = false;
    float *data = NULL;
    unsigned char *buf = NULL;
    bool supported = (format == SAMPLEFORMAT_UINT && (bits == 8 || bits == 16 || bits == 32)) ||
                     (format == SAMPLEFORMAT_IEEEFP && bits == 32);
    if (!supported) {
        err_set(err, errsz, "%s: TIFF samples of %u bits, format %u are not supported; "
                "textures take 8, 16 or 32 bit unsigned integers or 32 bit floats", path,
                bits, format);
        goto done;
    }
    if (w < 1 || h < 1 || w > TEX_MAX_SIDE || h > TEX_MAX_SIDE || spp < 1 ||
        spp > TEX_MAX_CHANNELS) {
        err_set(err, errsz, "%s: the image is %u x %u with %u samples per pixel", path, w, h,
                spp);
        goto done;
    }
    int nch = spp, bps = bits / 8;
    data = try_calloc((size_t)w * h * (size_t)nch, sizeof *data);
    if (!data) {
        err_set(err, errsz, "%s: out of memory for %u x %u x %d texels", path, w, h, nch);
        goto done;
    }
    int planes = planar == PLANARCONFIG_SEPARATE ? nch : 1;
    int per = planar == PLANARCONFIG_SEPARATE ? 1 : nch;     /* samples per buffer pixel */
    if (TIFFIsTiled(tif)) {
        uint32_t tw = 0, th = 0;
        TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tw);
        TIFFGetField(tif, TIFFTAG_TILELENGTH, &th);
        buf = try_malloc((size_t)TIFFTileSize(tif));
        if (!buf || tw == 0 || th == 0) {
            err_set(err, errsz, "%s: bad tile size %u x %u", path, tw, th);
            goto done;
        }
        for (int p = 0; p < planes; p++)
            for (uint32_t y0 = 0; y0 < h; y0 += th)
                for (uint32_t x0 = 0; x0 < w; x0 += tw) {
                    if (TIFFReadTile(tif, buf, x0, y0, 0, (uint16_t)p) < 0) {
                        err_set(err, errsz, "%s: cannot read the tile at (%u, %u): %s", path,
                                x0, y0, tiff_message);
                        goto done;
                    }
                    for (uint32_t y = y0; y < y0 + th && y < h; y++)
                        for (uint32_t x = x0; x < x0 + tw && x < w; x++)
                            for (int s = 0; s < per; s++) {
                                size_t k = ((size_t)(y - y0) * tw + (x - x0)) * (size_t)per + s;
                                data[((size_t)y * w + x) * (size_t)nch + (size_t)(p + s)] =
                                    sample_at(buf, k, bits, format);
                            }
                }
    } else {
        buf = try_malloc((size_t)TIFFScanlineSize(tif));
        if (!buf) {
            err_set(err, errsz, "%s: out of memory", path);
            goto done;
        }
        for (int p = 0; p < planes; p++)
            for (uint32_t y = 0; y < h; y++) {
                if (TIFFReadScanline(tif, buf, y, (uint16_t)p) < 0) {
                    err_set(err, errsz, "%s: cannot read row %u: %s", path, y, tiff_message);
                    goto done;
                }
                for (uint32_t x = 0; x < w; x++)
                    for (int s = 0; s < per; s++)
                        data[((size_t)y * w + x) * (size_t)nch + (size_t)(p + s)] =
                            sample_at(buf, (size_t)x * (size_t)per + (size_t)s, bits, format);
            }
    }
    (void)bps;
    out->data = data;
    out->w = (int)w;
    out->h = (int)h;
    out->nch = nch;
    out->type = format == SAMPLEFORMAT_IEEEFP ? "float" : bits == 8 ? "uint8"
              : bits == 16 ? "uint16" : "uint32";
    data = NULL;
    ok = true;
done:
    free(data);
    free(buf);
    TIFFClose(tif);
    return ok;
}
