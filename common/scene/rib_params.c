/*
 * rib_params.c: RIB parameter lists ("name" value pairs, RI Specification
 * 3.2 §3.1) read into typed scene_param lists.
 *
 * The type of each name comes from rib_decl (inline declaration, Declare,
 * predeclared). The value must fit it: numbers for numeric types, strings
 * for string; for a uniform parameter (shader calls) exactly
 * components * arraylen numbers; for a primitive variable any non-zero
 * multiple of the components. In LOOSE mode (Attribute, Option), names
 * with no declaration are kept with type SL_TYPE_VOID and their values
 * unchecked: unknown attributes and options are ignored quietly.
 */
#include "scene/rib_parser.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rib_params_clear(rib_params *params)
{
    for (int i = 0; i < params->count; i++)
        scene_param_clear(&params->items[i]);
    free(params->items);
    params->items = NULL;
    params->count = 0;
}

const scene_param *rib_params_find(const rib_params *params, const char *name)
{
    for (int i = params->count - 1; i >= 0; i--)
        if (strcmp(params->items[i].name, name) == 0)
            return &params->items[i];
    return NULL;
}

const scene_param *rib_params_points(rib_parser *p, const rib_request *req,
                                     const rib_params *params)
{
    const scene_param *P = rib_params_find(params, "P");
    if (!P) {
        rib_error(p, req, req->pos, "missing the points: add \"P\" [x y z x y z ...]");
        return NULL;
    }
    if (P->type != SL_TYPE_POINT) {
        rib_error(p, req, P->pos, "\"P\" must be declared as a point, not a %s",
                  rib_type_name(P->type));
        return NULL;
    }
    return P;
}

/* The name and declared type of a parameter name as written. Returns
 * false after an error; *decl type VOID when undeclared in LOOSE mode. */
static bool resolve_name(rib_parser *p, const rib_request *req, const rib_arg *arg,
                         rib_params_mode mode, char **name, rib_decl *decl)
{
    const char *text = rib_arg_string(req, arg);
    char err[ERR_LEN];
    if (rib_decl_is_inline(text)) {
        const char *n;
        int len;
        if (!rib_decl_parse(text, true, decl, &n, &len, err, sizeof err)) {
            rib_error(p, req, arg->pos, "cannot read the declaration \"%s\": %s", text, err);
            return false;
        }
        *name = xstrndup(n, (size_t)len);
        return true;
    }
    *name = xstrndup(text, strlen(text));
    if (rib_decls_find(p->decls, text, decl))
        return true;
    if (mode == RIB_PARAMS_LOOSE) {
        decl->type = SL_TYPE_VOID;
        decl->arraylen = 1;
        return true;
    }
    rib_error(p, req, arg->pos,
              "parameter \"%s\" is not declared (add Declare \"%s\" \"float\" before it, "
              "or write the type in the name: \"float %s\")", text, text, text);
    free(*name);
    return false;
}

/* Checks the value against the declaration and stores it in *out. */
static bool take_value(rib_parser *p, const rib_request *req, const rib_arg *value,
                       rib_params_mode mode, scene_param *out)
{
    const char *tname = rib_type_name(out->type);
    const char *s = rib_arg_string(req, value);
    if (out->type == SL_TYPE_VOID) {
        if (s)
            out->string = xstrndup(s, strlen(s));
        return true;
    }
    if (out->type == SL_TYPE_STRING) {
        if (!rib_arg_is_string(value) || value->count != 1) {
            rib_error(p, req, value->pos, "parameter \"%s\" is a string and needs one "
                      "string, got %s", out->name, rib_arg_describe(value));
            return false;
        }
        out->string = xstrndup(s, strlen(s));
        out->count = 1;
        return true;
    }
    int n, per = rib_type_components(out->type) * out->arraylen;
    const double *v = rib_arg_numbers(req, value, &n);
    if (!rib_arg_is_numeric(value)) {
        rib_error(p, req, value->pos, "parameter \"%s\" is a %s and needs numbers, got %s",
                  out->name, tname, rib_arg_describe(value));
        return false;
    }
    if (mode == RIB_PARAMS_VARYING ? (n == 0 || n % per != 0) : n != per) {
        rib_error(p, req, value->pos, "parameter \"%s\" is a %s and needs %s%d number%s, got %d",
                  out->name, tname, mode == RIB_PARAMS_VARYING ? "a multiple of " : "",
                  per, per == 1 ? "" : "s", n);
        return false;
    }
    out->values = xrealloc(NULL, (size_t)n * sizeof *out->values);
    memcpy(out->values, v, (size_t)n * sizeof *v);
    out->count = n;
    return true;
}

static bool read_one(rib_parser *p, const rib_request *req, int i, rib_params_mode mode,
                     scene_param *out)
{
    const rib_arg *name = &req->args[i];
    memset(out, 0, sizeof *out);
    if (!rib_arg_is_string(name) || name->kind != RIB_ARG_STRING) {
        rib_error(p, req, name->pos, "expected a parameter name (a string), got %s",
                  rib_arg_describe(name));
        return false;
    }
    if (i + 1 >= req->nargs) {
        rib_error(p, req, name->pos, "parameter \"%s\" has no value", rib_arg_string(req, name));
        return false;
    }
    rib_decl decl = { .type = SL_TYPE_VOID, .arraylen = 1, .cls = SCENE_CLASS_NONE };
    if (!resolve_name(p, req, name, mode, &out->name, &decl))
        return false;
    out->type = decl.type;
    out->arraylen = decl.arraylen;
    out->cls = decl.cls;
    out->pos = name->pos;
    if (!take_value(p, req, &req->args[i + 1], mode, out)) {
        scene_param_clear(out);
        return false;
    }
    return true;
}

bool rib_params_read(rib_parser *p, const rib_request *req, int first,
                     rib_params_mode mode, rib_params *out)
{
    out->items = NULL;
    out->count = 0;
    if (first >= req->nargs)
        return true;
    int max = (req->nargs - first + 1) / 2;
    out->items = xrealloc(NULL, (size_t)max * sizeof *out->items);
    for (int i = first; i < req->nargs; i += 2) {
        if (!read_one(p, req, i, mode, &out->items[out->count])) {
            rib_params_clear(out);
            return false;
        }
        out->count++;
    }
    return true;
}
