/*
 * rib_options.c: the camera and image options of RI Specification 3.2
 * §4.1 (Format, Projection, ScreenWindow, Clipping, DepthOfField,
 * PixelSamples, PixelFilter, Exposure, Display), Option "searchpath",
 * version; and the
 * camera checks at WorldBegin.
 *
 * aafarm needs a camera to render: Format and Projection are required
 * (RenderMan would default to 640x480 orthographic, which is never what a
 * scene meant). The screen window defaults as in §4.1.1: the shorter image
 * side spans [-1, 1], the longer one [-a, a] with a the frame aspect ratio.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rib_version(rib_parser *p, const rib_request *req)
{
    double v;
    rib_read_numbers(p, req, 0, 1, &v, "the RIB version");
}

void rib_display(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the image name");
    const char *type = name ? rib_read_string(p, req, 1, "the display type") : NULL;
    const char *mode = type ? rib_read_string(p, req, 2, "the display mode") : NULL;
    if (!mode)
        return;
    if (name[0] == '+') {
        rib_warning(p, req, req->pos, "only one image is written; the extra display \"%s\" "
                    "is ignored", name);
        return;
    }
    scene *s = p->scene;
    free(s->display_name);
    free(s->display_type);
    free(s->display_mode);
    s->display_name = xstrndup(name, strlen(name));
    s->display_type = xstrndup(type, strlen(type));
    s->display_mode = xstrndup(mode, strlen(mode));
}

static bool is_whole(double v) { return v == floor(v); }

void rib_format(rib_parser *p, const rib_request *req)
{
    double v[3];
    int next = rib_read_numbers(p, req, 0, 3, v, "xresolution yresolution pixelaspectratio");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!is_whole(v[0]) || !is_whole(v[1]) || v[0] < 1 || v[1] < 1 || v[0] > 65536 ||
        v[1] > 65536) {
        rib_error(p, req, req->pos, "the image size must be whole numbers from 1 to 65536, "
                  "got %g x %g", v[0], v[1]);
        return;
    }
    if (!(v[2] > 0)) {
        rib_error(p, req, req->pos, "the pixel aspect ratio must be > 0, got %g", v[2]);
        return;
    }
    p->scene->camera.xres = (int)v[0];
    p->scene->camera.yres = (int)v[1];
    p->scene->camera.pixel_aspect = v[2];
    p->have_format = true;
}

static bool is_identity(const mat4 *m)
{
    mat4 id = mat4_identity();
    return memcmp(m, &id, sizeof id) == 0;
}

/* Projection resets the current transform (RI Spec §4.1.1: the camera
 * transform starts after Projection). */
static void reset_transform(rib_parser *p, const rib_request *req)
{
    if (!is_identity(&p->attr.ctm))
        rib_warning(p, req, req->pos, "the transforms before Projection are dropped (the "
                    "camera transform starts at Projection); move them after it");
    p->attr.ctm = mat4_identity();
}

void rib_projection(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the projection name");
    if (!name)
        return;
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_UNIFORM, &params))
        return;
    scene_camera *cam = &p->scene->camera;
    if (strcmp(name, "perspective") == 0) {
        const scene_param *fov = rib_params_find(&params, "fov");
        double f = fov && fov->type == SL_TYPE_FLOAT ? fov->values[0] : 90;
        if (!(f > 0 && f < 180)) {
            rib_error(p, req, fov->pos, "\"fov\" must be between 0 and 180 degrees, got %g", f);
        } else {
            cam->projection = SCENE_PERSPECTIVE;
            cam->fov = f;
            p->have_projection = true;
            reset_transform(p, req);
        }
    } else if (strcmp(name, "orthographic") == 0) {
        cam->projection = SCENE_ORTHOGRAPHIC;
        p->have_projection = true;
        reset_transform(p, req);
    } else {
        rib_error(p, req, req->args[0].pos, "unsupported projection \"%s\" (supported: "
                  "\"perspective\", \"orthographic\")", name);
    }
    rib_params_clear(&params);
}

void rib_screen_window(rib_parser *p, const rib_request *req)
{
    double v[4];
    int next = rib_read_numbers(p, req, 0, 4, v, "left right bottom top");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!(v[0] < v[1]) || !(v[2] < v[3])) {
        rib_error(p, req, req->pos, "needs left < right and bottom < top, got %g %g %g %g",
                  v[0], v[1], v[2], v[3]);
        return;
    }
    memcpy(p->scene->camera.screen, v, sizeof v);
    p->have_screen = true;
}

void rib_clipping(rib_parser *p, const rib_request *req)
{
    double v[2];
    int next = rib_read_numbers(p, req, 0, 2, v, "near far");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!(v[0] > 0 && v[0] < v[1])) {
        rib_error(p, req, req->pos, "needs 0 < near < far, got %g %g", v[0], v[1]);
        return;
    }
    p->scene->camera.near_clip = v[0];
    p->scene->camera.far_clip = v[1];
}

/* DepthOfField fstop focallength focaldistance (RI Spec 3.2 §4.1.2): a
 * thin lens of diameter focallength / fstop focused at focaldistance;
 * without arguments, a pinhole again. */
void rib_depth_of_field(rib_parser *p, const rib_request *req)
{
    scene_camera *c = &p->scene->camera;
    if (req->nargs == 0) {
        c->fstop = c->focal_length = c->focal_distance = 0;
        return;
    }
    double v[3];
    int next = rib_read_numbers(p, req, 0, 3, v, "fstop focallength focaldistance");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!(v[0] > 0 && v[1] > 0 && v[2] > 0 && isfinite(v[1]) && isfinite(v[2]))) {
        rib_error(p, req, req->pos, "needs fstop, focallength and focaldistance > 0, got %g %g "
                  "%g (DepthOfField with no arguments turns depth of field off)", v[0], v[1],
                  v[2]);
        return;
    }
    c->fstop = isfinite(v[0]) ? v[0] : 0;   /* an infinite f-stop is a pinhole */
    c->focal_length = v[1];
    c->focal_distance = v[2];
}

void rib_pixel_samples(rib_parser *p, const rib_request *req)
{
    double v[2];
    int next = rib_read_numbers(p, req, 0, 2, v, "xsamples ysamples");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!is_whole(v[0]) || !is_whole(v[1]) || v[0] < 1 || v[1] < 1 || v[0] > 64 || v[1] > 64) {
        rib_error(p, req, req->pos, "the samples must be whole numbers from 1 to 64, got %g %g",
                  v[0], v[1]);
        return;
    }
    p->scene->pixel_samples[0] = (int)v[0];
    p->scene->pixel_samples[1] = (int)v[1];
}

static const char *const filter_names[] = { "box", "gaussian", "triangle", "catmull-rom", "sinc" };

void rib_pixel_filter(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the filter name");
    double w[2];
    int next = name ? rib_read_numbers(p, req, 1, 2, w, "xwidth ywidth") : -1;
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    int kind = -1;
    for (int i = 0; i < (int)(sizeof filter_names / sizeof filter_names[0]); i++)
        if (strcmp(name, filter_names[i]) == 0)
            kind = i;
    if (kind < 0) {
        rib_error(p, req, req->args[0].pos, "unknown filter \"%s\" (supported: box, gaussian, "
                  "triangle, catmull-rom, sinc)", name);
        return;
    }
    if (!(w[0] > 0 && w[1] > 0 && w[0] <= 16 && w[1] <= 16)) {
        rib_error(p, req, req->pos, "the filter widths must be > 0 and <= 16 pixels, got %g %g",
                  w[0], w[1]);
        return;
    }
    p->scene->filter.kind = (scene_filter_kind)kind;
    p->scene->filter.xwidth = w[0];
    p->scene->filter.ywidth = w[1];
}

const char *scene_filter_name(scene_filter_kind kind)
{
    return (unsigned)kind < sizeof filter_names / sizeof filter_names[0] ? filter_names[kind] : "?";
}

void rib_exposure(rib_parser *p, const rib_request *req)
{
    double v[2];
    int next = rib_read_numbers(p, req, 0, 2, v, "gain gamma");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    if (!(v[0] > 0 && v[1] > 0)) {
        rib_error(p, req, req->pos, "gain and gamma must be > 0, got %g %g", v[0], v[1]);
        return;
    }
    p->scene->exposure_gain = v[0];
    p->scene->exposure_gamma = v[1];
}

/* ---------------------------------------------------------------------- */
/* Option "searchpath" "shader" / "archive" / "texture" ["dir:dir:&"]      */
/* ---------------------------------------------------------------------- */

static void path_push(char ***list, int *n, const char *s, size_t len)
{
    *list = xrealloc(*list, (size_t)(*n + 1) * sizeof **list);
    (*list)[(*n)++] = xstrndup(s, len);
}

/* At most this many folders in one search path: "&:&" repeated doubles a
 * path, and twenty such Options would otherwise ask for millions. */
#define RIB_MAX_PATH_FOLDERS 2048

/* Splits at ':'; "&" is the previous path, "@" the standard one (empty).
 * A path of more than RIB_MAX_PATH_FOLDERS folders is an error at the
 * request (the path is left as it was). */
static void set_path(rib_parser *p, const rib_request *req, const char *kind, char ***path,
                     int *npath, const char *value)
{
    char **list = NULL;
    int n = 0;
    long want = 0;
    for (const char *s = value;;) {           /* count first: no huge list */
        const char *colon = strchr(s, ':');
        size_t len = colon ? (size_t)(colon - s) : strlen(s);
        want += (len == 1 && s[0] == '&') ? *npath : (len > 0 && !(len == 1 && s[0] == '@'));
        if (!colon)
            break;
        s = colon + 1;
    }
    if (want > RIB_MAX_PATH_FOLDERS) {
        rib_error(p, req, req->pos, "the %s search path would have %ld folders; keep it under "
                  "%d (each \"&\" repeats the previous path)", kind, want, RIB_MAX_PATH_FOLDERS);
        return;
    }
    const char *s = value;
    for (;;) {
        const char *colon = strchr(s, ':');
        size_t len = colon ? (size_t)(colon - s) : strlen(s);
        if (len == 1 && s[0] == '&') {
            for (int i = 0; i < *npath; i++)
                path_push(&list, &n, (*path)[i], strlen((*path)[i]));
        } else if (len > 0 && !(len == 1 && s[0] == '@')) {
            path_push(&list, &n, s, len);
        }
        if (!colon)
            break;
        s = colon + 1;
    }
    for (int i = 0; i < *npath; i++)
        free((*path)[i]);
    free(*path);
    *path = list;
    *npath = n;
}

/* Option "trace" "maxdepth" [n]: how deep trace() rays from shaders nest
 * (docs/renderer.md, "Shading"). */
static void trace_option(rib_parser *p, const rib_request *req)
{
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params))
        return;
    const scene_param *depth = rib_params_find(&params, "maxdepth");
    if (depth && depth->values && depth->count >= 1) {
        double d = depth->values[0];
        if (!(d >= 0 && d <= SCENE_MAX_TRACE_DEPTH && d == floor(d)))
            rib_error(p, req, depth->pos, "\"maxdepth\" must be a whole number from 0 to %d, "
                      "got %g", SCENE_MAX_TRACE_DEPTH, d);
        else
            p->scene->trace_maxdepth = (int)d;
    }
    rib_params_clear(&params);
}

void rib_option(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the option name");
    if (name && strcmp(name, "trace") == 0) {
        trace_option(p, req);
        return;
    }
    if (!name || strcmp(name, "searchpath") != 0)
        return;   /* other options are ignored quietly */
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params))
        return;
    const scene_param *shader = rib_params_find(&params, "shader");
    if (shader && shader->string)
        set_path(p, req, "shader", &p->shader_path, &p->nshader_path, shader->string);
    const scene_param *archive = rib_params_find(&params, "archive");
    if (archive && archive->string)
        set_path(p, req, "archive", &p->archive_path, &p->narchive_path, archive->string);
    const scene_param *texture = rib_params_find(&params, "texture");
    if (texture && texture->string)
        set_path(p, req, "texture", &p->texture_path, &p->ntexture_path, texture->string);
    rib_params_clear(&params);
}

/* ---------------------------------------------------------------------- */
/* at WorldBegin                                                           */
/* ---------------------------------------------------------------------- */

void rib_options_finish(rib_parser *p, const rib_request *req)
{
    scene_camera *cam = &p->scene->camera;
    if (!p->have_projection)
        rib_error(p, req, req->pos, "the scene has no camera: add Projection \"perspective\" "
                  "\"fov\" [45] (or Projection \"orthographic\") before WorldBegin");
    if (!p->have_format) {
        rib_error(p, req, req->pos, "the image has no size: add Format <xresolution> "
                  "<yresolution> 1 before WorldBegin, e.g. Format 640 480 1");
        return;
    }
    if (p->have_screen)
        return;
    double a = cam->xres * cam->pixel_aspect / cam->yres;
    if (a >= 1) {
        cam->screen[0] = -a, cam->screen[1] = a, cam->screen[2] = -1, cam->screen[3] = 1;
    } else {
        cam->screen[0] = -1, cam->screen[1] = 1, cam->screen[2] = -1 / a, cam->screen[3] = 1 / a;
    }
}

const char *scene_projection_name(scene_projection proj)
{
    return proj == SCENE_ORTHOGRAPHIC ? "orthographic" : "perspective";
}
