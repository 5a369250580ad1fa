/*
 * rib_ignored.c: the requests aafarm reads past with a warning instead of
 * an error (issue 14, "lenient where other renderers are"): requests a ray
 * tracer of displacement shaders has no use for (hiders, texture making,
 * level of detail, volume shaders ...), the primitives it does not render
 * (Blobby, Curves, Points: skipped), and motion blocks, of which the first
 * time sample is used. Each name is warned about once per parse, with
 * the file:line of its first use and what aafarm does instead.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <string.h>

typedef struct ignored_def {
    const char *name;
    const char *what;              /* the warning, after "Name: " */
} ignored_def;

#define NO_USE "has no use in aafarm's ray tracer; ignored"

static const ignored_def ignored[] = {
    /* options and requests of scanline renderers and of texture making */
    { "Hider", NO_USE " (every pixel is ray-traced)" },
    { "MakeTexture", NO_USE " (no texture maps are made)" },
    { "MakeShadow", NO_USE " (shadows are ray-traced)" },
    { "MakeLatLongEnvironment", NO_USE " (no environment maps are made)" },
    { "MakeCubeFaceEnvironment", NO_USE " (no environment maps are made)" },
    { "MakeBump", NO_USE " (no bump maps are made)" },
    { "GeometricApproximation", NO_USE " (surfaces are intersected directly, not diced)" },
    { "ShadingInterpolation", NO_USE " (shaders run at every hit)" },
    { "Quantize", NO_USE " (the EXR holds half floats)" },
    { "PixelVariance", NO_USE " (PixelSamples sets the samples)" },
    { "RelativeDetail", NO_USE " (no level of detail)" },
    { "Detail", NO_USE " (no level of detail)" },
    { "DetailRange", NO_USE " (no level of detail)" },
    { "ColorSamples", NO_USE " (colors are RGB)" },
    { "ErrorHandler", NO_USE " (errors are reported with file:line:col)" },
    { "Shutter", NO_USE " (no motion blur)" },
    { "Imager", NO_USE " (no imager shaders)" },
    { "Atmosphere", NO_USE " (no volume shaders)" },
    { "Interior", NO_USE " (no volume shaders)" },
    { "Exterior", NO_USE " (no volume shaders)" },
    { "Deformation", NO_USE " (no deformation shaders)" },
    { "Matte", NO_USE " (every surface is rendered)" },
    { "Bound", NO_USE " (bounds are computed from the surfaces and their displacement)" },
    { "ArchiveRecord", NO_USE },
    { "VArchiveRecord", NO_USE },
    { "DisplayChannel", "is not supported; ignored (the EXR holds RGBA and Z)" },
    { "PixelSampleImager", NO_USE " (no imager shaders)" },
    { "Camera", "is not supported; ignored (the camera is the one current at WorldBegin)" },
    { "Resource", "is not supported; ignored" },
    { "ResourceBegin", "is not supported; ignored" },
    { "ResourceEnd", "is not supported; ignored" },
    { "System", "runs no commands; ignored (a scene cannot run programs on the farm)" },
    { "AreaLightSource", "area lights are not rendered; ignored (its surfaces render as "
                         "ordinary surfaces)" },
    { "CropWindow", "is not supported; ignored (the whole image is rendered)" },
    { "FrameAspectRatio", "is not supported; ignored (the screen window follows Format, or "
                          "give ScreenWindow)" },
    { "ClippingPlane", "is not supported; ignored (nothing is clipped by it)" },
    { "Skew", "is not supported; ignored, so the objects after it are placed without it" },
    { "Perspective", "is not supported; ignored, so the objects after it are placed without "
                     "it" },
    { "SolidBegin", "solids (CSG) are not rendered; their surfaces render as a union" },
    { "SolidEnd", "solids (CSG) are not rendered; their surfaces render as a union" },
    /* primitives aafarm does not render */
    { "Blobby", "blobby implicit surfaces are not rendered; skipped" },
    { "Curves", "curves are not rendered; skipped" },
    { "Points", "point clouds are not rendered; skipped" },
    { "Procedural", "procedural primitives are not run; skipped" },
    { "Geometry", "named geometry (\"teapot\" ...) is not rendered; skipped" },
};

enum { NIGNORED = sizeof ignored / sizeof ignored[0] };

/* One warning per name: the names warned about share p->warned with
 * unknown requests. */
static void warn_once(rib_parser *p, const rib_request *req, const char *what)
{
    for (int i = 0; i < p->nwarned; i++)
        if (strcmp(p->warned[i], req->name) == 0)
            return;
    p->warned = xrealloc(p->warned, (size_t)(p->nwarned + 1) * sizeof *p->warned);
    p->warned[p->nwarned++] = xstrndup(req->name, strlen(req->name));
    rib_warning(p, req, req->pos, "%s", what);
}

bool rib_ignored_request(rib_parser *p, const rib_request *req)
{
    for (int i = 0; i < NIGNORED; i++)
        if (strcmp(ignored[i].name, req->name) == 0) {
            warn_once(p, req, ignored[i].what);
            return true;
        }
    return false;
}

void rib_option_in_world(rib_parser *p, const rib_request *req)
{
    warn_once(p, req, "options are fixed at WorldBegin; ignored inside the world (move it "
              "before WorldBegin)");
}

/* MotionBegin [times] ... MotionEnd: the requests between are the samples
 * of one request at those times (RI Spec 3.2 §4.4); without motion blur
 * the first one is used, as at the shutter's opening. */
bool rib_motion_filter(rib_parser *p, const rib_request *req)
{
    bool begin = strcmp(req->name, "MotionBegin") == 0;
    bool end = strcmp(req->name, "MotionEnd") == 0;
    if (begin) {
        if (p->in_motion) {
            rib_error(p, req, req->pos, "the MotionBegin at %s:%d:%d is still open (missing "
                      "MotionEnd)", p->motion_pos.file, p->motion_pos.line, p->motion_pos.col);
            return true;
        }
        warn_once(p, req, "motion blur is not rendered: each motion block uses its first "
                  "time sample");
        p->in_motion = true;
        p->motion_taken = false;
        p->motion_pos = req->pos;
        return true;
    }
    if (end) {
        if (!p->in_motion)
            rib_error(p, req, req->pos, "there is no open MotionBegin to close");
        p->in_motion = false;
        return true;
    }
    if (!p->in_motion)
        return false;
    if (p->motion_taken)
        return true;   /* a later time sample: skipped */
    p->motion_taken = true;
    return false;
}
