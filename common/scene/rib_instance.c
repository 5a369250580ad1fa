/*
 * rib_instance.c: retained geometry (RI Specification 3.2 §5.6, "Objects"):
 * ObjectBegin handle ... ObjectEnd records the surfaces between them, each
 * with the transform current inside the block (relative to the block's
 * start); ObjectInstance handle places them all with the attributes and
 * the transform current at the ObjectInstance (shaders, color, sides,
 * lights), as RenderMan does: attributes inside the block other than the
 * transform do not travel with the object.
 *
 * The handle is a number (RIB's sequence number) or a string. Defining a
 * handle again replaces the earlier object for the instances that follow.
 * A definition may not nest another, and may only hold surfaces (they are
 * recorded instead of placed: see rib_record_surface).
 *
 * Every object an instance places remembers the first object placed from
 * the same recorded surface (scene_object.instance_of): the renderer then
 * keeps one set of boxes per recorded surface, shared by its instances
 * (trace/instance.c).
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The handle as text ("7", "lamp"); NULL with an error when malformed. */
static char *handle_of(rib_parser *p, const rib_request *req)
{
    if (req->nargs != 1 || (req->args[0].kind != RIB_ARG_NUMBER &&
                            req->args[0].kind != RIB_ARG_STRING)) {
        if (req->nargs == 0)
            rib_error(p, req, req->pos, "missing the object handle (a number or a string)");
        else
            rib_error(p, req, req->nargs == 1 ? req->args[0].pos : req->args[1].pos,
                      "takes one argument, the object handle (a number or a string)");
        return NULL;
    }
    const rib_arg *arg = &req->args[0];
    if (arg->kind == RIB_ARG_STRING) {
        const char *s = rib_arg_string(req, arg);
        return xstrndup(s, strlen(s));
    }
    int n;
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", rib_arg_numbers(req, arg, &n)[0]);
    return xstrndup(buf, strlen(buf));
}

static rib_object_def *find_def(rib_parser *p, const char *handle)
{
    for (int i = p->ndefs - 1; i >= 0; i--)
        if (p->defs[i].handle && strcmp(p->defs[i].handle, handle) == 0)
            return &p->defs[i];
    return NULL;
}

void rib_object_begin(rib_parser *p, const rib_request *req)
{
    const rib_object_def *open = rib_defining(p);
    if (open) {
        rib_error(p, req, req->pos, "object definitions cannot nest: the ObjectBegin at "
                  "%s:%d:%d is still open (missing ObjectEnd)", open->pos.file, open->pos.line,
                  open->pos.col);
        return;
    }
    char *handle = req->broken ? NULL : handle_of(p, req);
    p->defs = xrealloc(p->defs, (size_t)(p->ndefs + 1) * sizeof *p->defs);
    rib_object_def *d = &p->defs[p->ndefs++];
    memset(d, 0, sizeof *d);
    d->handle = handle;              /* NULL: malformed, never found */
    d->pos = req->pos;
    if (!rib_push_block(p, req, RIB_BLOCK_OBJECT))
        return;
    p->blocks[p->nblocks - 1].object_def = p->ndefs - 1;
    p->attr.ctm = mat4_identity();
}

void rib_object_end(rib_parser *p, const rib_request *req)
{
    rib_close_block(p, req, RIB_BLOCK_OBJECT);
}

rib_object_def *rib_defining(rib_parser *p)
{
    int i = p->nblocks > 0 ? p->blocks[p->nblocks - 1].object_block : -1;   /* O(1) */
    return i >= 0 ? &p->defs[p->blocks[i].object_def] : NULL;
}

void rib_record_surface(rib_parser *p, const rib_request *req, const geom_surface *surf,
                        const scene_mesh *mesh)
{
    rib_object_def *d = rib_defining(p);
    d->parts = xrealloc(d->parts, (size_t)(d->nparts + 1) * sizeof *d->parts);
    rib_object_part *part = &d->parts[d->nparts++];
    part->surface = NULL;
    if (surf) {
        /* kept by the scene: every instance's object points at it */
        geom_surface *kept = scene_keep(p->scene, xmalloc(sizeof *kept));
        *kept = *surf;
        part->surface = kept;
    }
    part->mesh = mesh;
    part->ctm = p->attr.ctm;
    part->pos = req->pos;
    part->first_object = -1;
    part->nprimvars = p->nsurface_vars;
    part->primvars = NULL;
    if (p->nsurface_vars > 0) {
        size_t size = (size_t)p->nsurface_vars * sizeof *part->primvars;
        part->primvars = memcpy(scene_keep(p->scene, xmalloc(size)), p->surface_vars, size);
    }
}

void rib_object_instance(rib_parser *p, const rib_request *req)
{
    char *handle = handle_of(p, req);
    if (!handle)
        return;
    if (rib_defining(p)) {
        rib_error(p, req, req->pos, "cannot be used inside an object definition (instances "
                  "of instances are not supported)");
        free(handle);
        return;
    }
    rib_object_def *d = find_def(p, handle);
    if (!d) {
        rib_error(p, req, req->args[0].pos, "no object has the handle %s (define it first "
                  "with ObjectBegin %s ... ObjectEnd)", handle, handle);
        free(handle);
        return;
    }
    free(handle);
    if (d->nparts == 0)
        rib_warning(p, req, req->pos, "the object defined at %s:%d:%d holds no surfaces",
                    d->pos.file, d->pos.line, d->pos.col);
    mat4 ctm = p->attr.ctm;
    for (int i = 0; i < d->nparts; i++) {
        rib_object_part *part = &d->parts[i];
        int before = p->scene->nobjects;
        rib_place_surface(p, req, part->surface, part->mesh, mat4_mul(ctm, part->ctm), part->pos,
                          part->primvars, part->nprimvars, true, part->first_object);
        if (p->scene->nobjects == before)
            continue;                  /* not placed (an error said why) */
        if (part->first_object < 0)
            part->first_object = before;
        scene_object *o = &p->scene->objects[before];
        o->instance_of = part->first_object;
        if (p->check && part->first_object < before &&
            scene_object_placeable(o, &p->scene->objects[part->first_object])) {
            /* a check's parse: a reference is checked and not kept */
            char err[ERR_LEN] = "";
            if (!p->check->placement(p->check->user, p->scene,
                                     &p->scene->objects[part->first_object], o, err, sizeof err))
                rib_error(p, req, req->pos, "%s", err[0] ? err : "cannot be placed");
            p->scene->nobjects--;
            p->scene->nchecked_placements++;
        }
    }
}

void rib_object_defs_clear(rib_parser *p)
{
    for (int i = 0; i < p->ndefs; i++) {
        free(p->defs[i].handle);
        free(p->defs[i].parts);        /* their surfaces and variables: the scene's */
    }
    free(p->defs);
    p->defs = NULL;
    p->ndefs = 0;
}
