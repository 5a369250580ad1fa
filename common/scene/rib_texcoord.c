/*
 * rib_texcoord.c: TextureCoordinates s1 t1 s2 t2 s3 t3 s4 t4 (RI
 * Specification 3.2 §4.2, an attribute): the texture coordinates (s,t) at
 * the corners (u,v) = (0,0), (1,0), (0,1), (1,1) of the parametric
 * surfaces (the quadrics and the patches), bilinear between. The default,
 * 0 0 1 0 0 1 1 1, is s = u, t = v: what shaders see when a surface gives
 * no s and t of its own.
 *
 * aafarm hands the map to the shaders as a pair of primitive variables "s"
 * and "t" bilinear in (u,v) (scene_primvar), added to each quadric, Patch
 * and patch of a PatchMesh (each patch has its own (u,v) in [0,1]^2, see
 * rib_patch.c) placed while the attribute differs from the default, unless
 * the surface gives "s", "t" or "st" itself (those win, as the spec
 * says). Meshes, subdivision meshes, polygons and NuPatch keep their own.
 */
#include "scene/rib_parser.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const double default_st[8] = { 0, 0, 1, 0, 0, 1, 1, 1 };

void rib_texture_coordinates(rib_parser *p, const rib_request *req)
{
    double v[8];
    int next = rib_read_numbers(p, req, 0, 8, v, "s1 t1 s2 t2 s3 t3 s4 t4");
    if (next < 0 || !rib_no_more_args(p, req, next))
        return;
    for (int i = 0; i < 8; i++)
        if (!isfinite(v[i])) {
            rib_error(p, req, req->args[0].pos, "texture coordinate %d is %g: give finite "
                      "numbers", i + 1, v[i]);
            return;
        }
    p->attr.texcoords = memcmp(v, default_st, sizeof v) != 0;
    memcpy(p->attr.st, v, sizeof v);
}

static bool parametric(geom_kind k)
{
    switch (k) {
    case GEOM_SPHERE: case GEOM_DISK: case GEOM_CYLINDER: case GEOM_CONE:
    case GEOM_PARABOLOID: case GEOM_HYPERBOLOID: case GEOM_TORUS:
    case GEOM_PATCH: case GEOM_BICUBIC:
        return true;
    default:
        return false;
    }
}

/* c[i + 4 j] is the term of u^i v^j: a (1-u)(1-v) + b u(1-v) + c (1-u)v + d uv */
static void bilinear(scene_primvar *out, const char *name, double a, double b, double c,
                     double d)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", name);
    out->type = SL_TYPE_FLOAT;
    out->size = 1;
    out->c[0][0] = a;
    out->c[1][0] = b - a;
    out->c[4][0] = c - a;
    out->c[5][0] = a - b - c + d;
}

int rib_texcoord_vars(const rib_parser *p, const geom_surface *surf, const scene_primvar *vars,
                      int nvars, scene_primvar out[SCENE_MAX_PRIMVARS])
{
    const rib_attributes *a = &p->attr;
    if (!a->texcoords || !parametric(surf->kind) || nvars + 2 > SCENE_MAX_PRIMVARS)
        return -1;
    for (int i = 0; i < nvars; i++)
        if (strcmp(vars[i].name, "s") == 0 || strcmp(vars[i].name, "t") == 0)
            return -1;                 /* the surface's own win */
    if (nvars > 0)
        memcpy(out, vars, (size_t)nvars * sizeof *out);
    const double *st = a->st;
    bilinear(&out[nvars], "s", st[0], st[2], st[4], st[6]);
    bilinear(&out[nvars + 1], "t", st[1], st[3], st[5], st[7]);
    return nvars + 2;
}
