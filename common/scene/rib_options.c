/*
 * rib_options.c: the camera and image options of RI Specification 3.2
 * §4.1 (Format, Projection, ScreenWindow, Clipping, PixelSamples,
 * PixelFilter, Exposure, Display), Option "searchpath", version; and the
 * camera checks at WorldBegin.
 *
 * aafarm needs a camera to render: Format and Projection are required
 * (RenderMan would default to 640x480 orthographic, which is never what a
 * scene meant). The screen window defaults as in §4.1.1: the shorter image
 * side spans [-1, 1], the longer one [-a, a] with a the frame aspect ratio.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"

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
    s->display_name = sl_xstrndup(name, strlen(name));
    s->display_type = sl_xstrndup(type, strlen(type));
    s->display_mode = sl_xstrndup(mode, strlen(mode));
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
    rib_params_free(&params);
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
    *list = sl_xrealloc(*list, (size_t)(*n + 1) * sizeof **list);
    (*list)[(*n)++] = sl_xstrndup(s, len);
}

/* Splits at ':'; "&" is the previous path, "@" the standard one (empty). */
static void set_path(char ***path, int *npath, const char *value)
{
    char **list = NULL;
    int n = 0;
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

void rib_option(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the option name");
    if (!name || strcmp(name, "searchpath") != 0)
        return;   /* other options are ignored quietly */
    rib_params params;
    if (!rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params))
        return;
    const scene_param *shader = rib_params_find(&params, "shader");
    if (shader && shader->string)
        set_path(&p->shader_path, &p->nshader_path, shader->string);
    const scene_param *texture = rib_params_find(&params, "texture");
    if (texture && texture->string) {         /* "&": the previous texture path */
        const char *prev = p->scene->texture_path ? p->scene->texture_path : "";
        size_t n = strlen(texture->string), np = strlen(prev), cap = 1;
        for (size_t k = 0; k < n; k++)
            cap += texture->string[k] == '&' ? np : 1;
        if (cap > 65536) {                     /* "&:&" repeated doubles it */
            rib_error(p, req, req->pos, "the texture search path would be %zu bytes long; "
                      "keep it under 64 KiB (each \"&\" repeats the previous path)", cap);
            rib_params_free(&params);
            return;
        }
        char *out = sl_xrealloc(NULL, cap), *o = out;
        for (size_t k = 0; k < n; k++) {
            if (texture->string[k] == '&') {
                memcpy(o, prev, np);
                o += np;
            } else {
                *o++ = texture->string[k];
            }
        }
        *o = '\0';
        free(p->scene->texture_path);
        p->scene->texture_path = out;
    }
    const scene_param *archive = rib_params_find(&params, "archive");
    if (archive && archive->string)
        set_path(&p->archive_path, &p->narchive_path, archive->string);
    rib_params_free(&params);
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
