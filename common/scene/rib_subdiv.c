/*
 * rib_subdiv.c: SubdivisionMesh (RI Specification 3.2 §5.5):
 *
 *   SubdivisionMesh "catmull-clark" [nvertices] [vertices]
 *       [tags] [nargs] [intargs] [floatargs] "P" [...]
 *
 * (the four tag arrays may be left out together), and PRMan's
 *
 *   HierarchicalSubdivisionMesh "catmull-clark" [nvertices] [vertices]
 *       [tags] [nargs] [intargs] [floatargs] [stringargs] "P" [...]
 *
 * read the same way: three counts per tag in nargs (integers, floats,
 * strings), the strings in a fifth array; the hierarchical edits
 * ("vertexedit", "edgeedit", "faceedit") are tags like any other aafarm
 * does not support (warned, ignored). Tags: "crease" (a chain
 * of points, one sharpness), "corner" (points, one sharpness or one each),
 * "hole" (faces), "interpolateboundary" (no argument, or 1 / 0); other
 * tags are warned about and ignored. Sharpness >= 10 is infinite.
 *
 * The mesh becomes one geom_subdiv (common/geom/subdiv.h), owned by the
 * scene (scene.subdivs), and ONE scene object (a scene_mesh, issue 23)
 * whose pieces are the drawn faces of its once-refined mesh, GEOM_SUBDIV
 * surfaces made when asked for. Other primitive variables (rib_primvar.c)
 * are interpolated bilinearly over each refined face from their values at
 * its corners (scene_mesh.c, refined_face_vars).
 */
#include "scene/rib_parser.h"
#include "scene/rib_primvar.h"
#include "sl/strbuf.h"

#ifdef SCENE_HAVE_GEOM
#include "geom/subdiv.h"
#include "util/err.h"
#include "util/xalloc.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool is_array(const rib_arg *a)
{
    return a->kind == RIB_ARG_NUMBERS || a->kind == RIB_ARG_STRINGS;
}

typedef struct subdiv_tags {
    int *crease_len, *crease_verts, ncreases, ncrease_verts;
    double *crease_sharp;
    int *corner_verts, ncorners;
    double *corner_sharp;
    int *holes, nholes;
    bool interpolateboundary;
} subdiv_tags;

static void tags_clear(subdiv_tags *t)
{
    free(t->crease_len);
    free(t->crease_verts);
    free(t->crease_sharp);
    free(t->corner_verts);
    free(t->corner_sharp);
    free(t->holes);
}

static void *grow(void *p, int n, size_t size)
{
    return xrealloc(p, (size_t)(n + 1) * size);
}

/* Reads the tag arrays at args first .. first+3 (first+4 with the
 * strings of a hierarchical mesh: hier) into t; false after an error.
 * npoints, nfaces check the indices. */
static bool read_tags(rib_parser *p, const rib_request *req, int first, bool hier, int npoints,
                      int nfaces, subdiv_tags *t)
{
    int per = hier ? 3 : 2;            /* counts per tag in nargs */
    const rib_arg *ta = &req->args[first];
    int ntags = ta->kind == RIB_ARG_STRINGS ? ta->count : 0;
    if (ta->kind == RIB_ARG_NUMBERS && ta->count > 0) {
        rib_error(p, req, ta->pos, "the tags must be strings ([\"crease\" \"corner\" ...])");
        return false;
    }
    if (first + per + 1 >= req->nargs || (hier && !is_array(&req->args[first + 4]))) {
        rib_error(p, req, ta->pos, hier ? "the tags need four more arrays: [nargs] [intargs] "
                  "[floatargs] [stringargs]" : "the tags need three more arrays: [nargs] "
                  "[intargs] [floatargs]");
        return false;
    }
    if (hier && req->args[first + 4].kind == RIB_ARG_NUMBERS && req->args[first + 4].count > 0) {
        rib_error(p, req, req->args[first + 4].pos, "the tag strings (stringargs) must be "
                  "strings");
        return false;
    }
    int nstr = hier ? req->args[first + 4].count : 0;
    int nn = 0, ni = 0, nfl = 0;
    int *nargs = rib_read_ints(p, req, first + 1, 0, true, &nn, "the tag argument counts (nargs)");
    int *iargs = nargs ? rib_read_ints(p, req, first + 2, 0, true, &ni, "the tag integers (intargs)")
                       : NULL;
    bool ok = nargs && iargs;
    const double *fargs = NULL;
    if (ok) {
        if (!rib_arg_is_numeric(&req->args[first + 3])) {
            rib_error(p, req, req->args[first + 3].pos, "missing the tag floats (floatargs)");
            ok = false;
        } else {
            fargs = rib_arg_numbers(req, &req->args[first + 3], &nfl);
        }
    }
    if (ok && nn != per * ntags) {
        rib_error(p, req, req->args[first + 1].pos, "nargs has %d numbers, expected %d per tag "
                  "(%d tags)", nn, per, ntags);
        ok = false;
    }
    long si = 0, sf = 0, ss = 0;
    for (int k = 0; ok && k < ntags; k++) {
        si += nargs[per * k];
        sf += nargs[per * k + 1];
        ss += hier ? nargs[per * k + 2] : 0;
    }
    if (ok && (si != ni || sf != nfl || ss != nstr)) {
        if (hier)
            rib_error(p, req, req->args[first + 1].pos, "nargs asks for %ld integers, %ld floats "
                      "and %ld strings, but intargs has %d, floatargs %d and stringargs %d", si,
                      sf, ss, ni, nfl, nstr);
        else
            rib_error(p, req, req->args[first + 1].pos, "nargs asks for %ld integers and %ld "
                      "floats, but intargs has %d and floatargs %d", si, sf, ni, nfl);
        ok = false;
    }
    const int *ip = iargs;
    const double *fp = fargs;
    for (int k = 0; ok && k < ntags; k++) {
        const char *tag = req->strs[ta->first + k];
        int in = nargs[per * k], fn = nargs[per * k + 1];
        if (strcmp(tag, "crease") == 0) {
            if (in < 2 || fn != 1) {
                rib_error(p, req, ta->pos, "tag %d \"crease\" takes 2 or more points and one "
                          "sharpness, got %d and %d", k, in, fn);
                ok = false;
                break;
            }
            t->crease_len = grow(t->crease_len, t->ncreases, sizeof(int));
            t->crease_sharp = grow(t->crease_sharp, t->ncreases, sizeof(double));
            t->crease_len[t->ncreases] = in;
            t->crease_sharp[t->ncreases++] = fp[0];
            t->crease_verts = xrealloc(t->crease_verts,
                                          (size_t)(t->ncrease_verts + in) * sizeof(int));
            for (int i = 0; i < in; i++) t->crease_verts[t->ncrease_verts++] = ip[i];
        } else if (strcmp(tag, "corner") == 0) {
            if (fn != 1 && fn != in) {
                rib_error(p, req, ta->pos, "tag %d \"corner\" takes one sharpness or one per "
                          "point (%d points), got %d", k, in, fn);
                ok = false;
                break;
            }
            for (int i = 0; i < in; i++) {
                t->corner_verts = grow(t->corner_verts, t->ncorners, sizeof(int));
                t->corner_sharp = grow(t->corner_sharp, t->ncorners, sizeof(double));
                t->corner_verts[t->ncorners] = ip[i];
                t->corner_sharp[t->ncorners++] = fp[fn == 1 ? 0 : i];
            }
        } else if (strcmp(tag, "hole") == 0) {
            for (int i = 0; i < in; i++) {
                if (ip[i] >= nfaces) {
                    rib_error(p, req, ta->pos, "tag %d \"hole\": face %d, but the mesh has %d "
                              "faces", k, ip[i], nfaces);
                    ok = false;
                    break;
                }
                t->holes = grow(t->holes, t->nholes, sizeof(int));
                t->holes[t->nholes++] = ip[i];
            }
        } else if (strcmp(tag, "interpolateboundary") == 0) {
            t->interpolateboundary = in == 0 || ip[0] != 0;
        } else {
            rib_warning(p, req, ta->pos, "tag \"%s\" is not supported: ignored", tag);
        }
        if (ok && (strcmp(tag, "crease") == 0 || strcmp(tag, "corner") == 0))
            for (int i = 0; i < in; i++)
                if (ip[i] >= npoints) {
                    rib_error(p, req, ta->pos, "tag %d \"%s\": point %d, but \"P\" has %d "
                              "points", k, tag, ip[i], npoints);
                    ok = false;
                    break;
                }
        if (ok)
            for (int i = 0; i < fn; i++)
                if (!isfinite(fp[i]) || fp[i] < 0) {
                    rib_error(p, req, ta->pos, "tag %d \"%s\": sharpness %g must be >= 0", k,
                              tag, fp[i]);
                    ok = false;
                    break;
                }
        ip += in;
        fp += fn;
    }
    free(nargs);
    free(iargs);
    return ok;
}

static void subdivision_mesh(rib_parser *p, const rib_request *req, bool hier)
{
    const char *scheme = rib_read_string(p, req, 0, "the scheme (\"catmull-clark\")");
    if (!scheme) return;
    if (strcmp(scheme, "catmull-clark") != 0) {
        rib_error(p, req, req->args[0].pos, "scheme \"%s\" is not supported (only "
                  "\"catmull-clark\")", scheme);
        return;
    }
    int nfaces = 0, nidx = 0;
    int *nverts = rib_read_ints(p, req, 1, 3, false, &nfaces, "the vertex counts (nvertices)");
    if (!nverts) return;
    int *idx = rib_read_ints(p, req, 2, 0, false, &nidx, "the vertex indices");
    subdiv_tags tags;
    memset(&tags, 0, sizeof tags);
    rib_params params = { 0 };
    rib_primvars vars = { NULL, 0 };

    if (!idx) goto out;
    long total = 0;
    for (int f = 0; f < nfaces; f++) total += nverts[f];
    if (total != nidx) {
        rib_error(p, req, req->args[2].pos, "the faces have %ld points in all, but %d vertex "
                  "indices are given", total, nidx);
        goto out;
    }
    int first = 3;
    bool have_tags = first < req->nargs && is_array(&req->args[first]);
    int after_tags = first + (hier ? 5 : 4);
    for (int k = first; have_tags && k < after_tags; k++)
        if (k >= req->nargs || !is_array(&req->args[k])) {     /* before the parameters */
            rib_error(p, req, req->args[first].pos, hier ? "the tags need four more arrays: "
                      "[nargs] [intargs] [floatargs] [stringargs]" : "the tags need three more "
                      "arrays: [nargs] [intargs] [floatargs]");
            goto out;
        }
    if (!rib_params_read(p, req, have_tags ? after_tags : first, RIB_PARAMS_VARYING, &params))
        goto out;
    const scene_param *P = rib_params_points(p, req, &params);
    if (!P)
        goto out;
    int npoints = P->count / 3;
    for (int i = 0; i < nidx; i++)
        if (idx[i] >= npoints) {
            rib_error(p, req, P->pos, "\"P\" has %d points, but the vertex indices go up to %d",
                      npoints, idx[i]);
            goto out;
        }
    if (have_tags && !read_tags(p, req, first, hier, npoints, nfaces, &tags))
        goto out;
    int counts[] = { 0, 1, nfaces, npoints, npoints, nidx };
    if (!rib_primvars_collect(p, req, &params, counts, NULL, &vars))
        goto out;
#ifdef SCENE_HAVE_GEOM
    {
        geom_subdiv_desc d = {
            nfaces, nverts, idx, npoints, P->values,
            tags.ncreases, tags.crease_len, tags.crease_verts, tags.crease_sharp,
            tags.ncorners, tags.corner_verts, tags.corner_sharp,
            tags.nholes, tags.holes, tags.interpolateboundary,
        };
        char err[ERR_LEN] = "";
        geom_subdiv *sd = geom_subdiv_new(&d, err, sizeof err);
        if (!sd) {
            rib_error(p, req, req->pos, "%s", err);
            goto out;
        }
        /* one object (issue 23): a piece per drawn face of the refined
         * mesh, its surface and variables made on demand (scene_mesh.c);
         * a check's parse counts them and keeps neither */
        scene_mesh *m = p->check ? scene_mesh_new_counted(vars.n)
                                 : scene_mesh_new(NULL, 0, idx, nidx, SCENE_MESH_N_NONE, NULL,
                                                  0, &vars, &params);
        scene_mesh_set_subdiv(m, sd, nverts, nfaces);
        for (int f = 0; f < geom_subdiv_nfaces(sd); f++)
            if (geom_subdiv_face_drawn(sd, f))
                scene_mesh_add_piece(m, SCENE_PIECE_SUBDIV, f, 0, NULL, 0);
        scene_mesh_trim(m);
        scene *sc = p->scene;
        if (p->check) {
            geom_subdiv_destroy(&sd);
        } else {
            sc->subdivs = xrealloc(sc->subdivs, (size_t)(sc->nsubdivs + 1) * sizeof *sc->subdivs);
            sc->subdivs[sc->nsubdivs++] = sd;
        }
        if (scene_mesh_npieces(m) == 0) {
            rib_warning(p, req, req->pos, "no face to draw (every face is a hole or touches "
                        "the boundary: add the tag \"interpolateboundary\")");
            scene_mesh_destroy(&m);
        } else {
            /* the refined mesh reads its control faces from the scene's
             * mesh (16 + 4 bytes a quad face less: issue 23), which the
             * scene holds as long as it */
            if (sd) geom_subdiv_share_faces(sd, scene_mesh_face_offsets(m), scene_mesh_indices(m));
            rib_add_mesh(p, req, m);
        }
    }
#else
    rib_error(p, req, req->pos, "subdivision meshes need common/geom");
#endif
out:

    rib_primvars_clear(&vars);
    tags_clear(&tags);
    rib_params_clear(&params);
    free(nverts);
    free(idx);
}

void rib_subdivision_mesh(rib_parser *p, const rib_request *req)
{
    subdivision_mesh(p, req, false);
}

void rib_hierarchical_subdivision_mesh(rib_parser *p, const rib_request *req)
{
    subdivision_mesh(p, req, true);
}
