/*
 * rib_decl.c: parameter declarations (see rib_decl.h).
 *
 * The predeclared names are those of RI Specification 3.2 Table 5.1
 * (standard geometric primitive variables) and of the standard shaders of
 * Appendix A (surface, displacement and light parameters), plus the names
 * the supported Attribute / Option / Projection / LightSource requests
 * take.
 */
#include "scene/rib_decl.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* types                                                                   */
/* ---------------------------------------------------------------------- */

int rib_type_components(sl_type type)
{
    switch (type) {
    case SL_TYPE_POINT: case SL_TYPE_VECTOR: case SL_TYPE_NORMAL: case SL_TYPE_COLOR:
        return 3;
    case SL_TYPE_MATRIX:
        return 16;
    default:
        return 1;
    }
}

const char *rib_type_name(sl_type type)
{
    switch (type) {
    case SL_TYPE_FLOAT:  return "float";
    case SL_TYPE_POINT:  return "point";
    case SL_TYPE_VECTOR: return "vector";
    case SL_TYPE_NORMAL: return "normal";
    case SL_TYPE_COLOR:  return "color";
    case SL_TYPE_STRING: return "string";
    case SL_TYPE_MATRIX: return "matrix";
    default:             return "void";
    }
}

static const struct { const char *name; sl_type type; } type_words[] = {
    { "float", SL_TYPE_FLOAT },   { "integer", SL_TYPE_FLOAT }, { "int", SL_TYPE_FLOAT },
    { "point", SL_TYPE_POINT },   { "vector", SL_TYPE_VECTOR }, { "normal", SL_TYPE_NORMAL },
    { "color", SL_TYPE_COLOR },   { "string", SL_TYPE_STRING }, { "matrix", SL_TYPE_MATRIX },
};

static const char *const class_words[] = {
    "constant", "uniform", "varying", "vertex", "facevarying",
};

/* ---------------------------------------------------------------------- */
/* parsing "[class] type [n] [name]"                                       */
/* ---------------------------------------------------------------------- */

typedef struct word { const char *s; int len; } word;

static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/* Splits into words; '[' ... ']' is one word of its own. */
static int split_words(const char *text, word *out, int max)
{
    int n = 0;
    const char *p = text;
    while (*p) {
        while (is_blank(*p))
            p++;
        if (!*p)
            break;
        const char *start = p;
        if (*p == '[') {
            while (*p && *p != ']')
                p++;
            if (*p)
                p++;
        } else {
            while (*p && !is_blank(*p) && *p != '[')
                p++;
        }
        if (n == max)
            return max + 1;
        out[n].s = start;
        out[n].len = (int)(p - start);
        n++;
    }
    return n;
}

static bool word_is(word w, const char *s)
{
    return (size_t)w.len == strlen(s) && memcmp(w.s, s, (size_t)w.len) == 0;
}

static bool parse_arraylen(word w, int *arraylen, char *err, size_t errsz)
{
    char buf[32];
    int n = w.len - 2;
    if (w.len < 3 || w.s[w.len - 1] != ']' || n >= (int)sizeof buf) {
        err_set(err, errsz, "bad array size '%.*s'", w.len > 40 ? 40 : w.len, w.s);
        return false;
    }
    memcpy(buf, w.s + 1, (size_t)n);
    buf[n] = '\0';
    char *end;
    long v = strtol(buf, &end, 10);
    while (is_blank(*end))
        end++;
    if (*end || v < 1 || v > 4096) {
        err_set(err, errsz, "bad array size '%.*s' (expected [1] to [4096])",
                 w.len > 40 ? 40 : w.len, w.s);
        return false;
    }
    *arraylen = (int)v;
    return true;
}

static bool parse_type_word(word w, sl_type *type, char *err, size_t errsz)
{
    for (size_t i = 0; i < sizeof type_words / sizeof type_words[0]; i++)
        if (word_is(w, type_words[i].name)) {
            *type = type_words[i].type;
            return true;
        }
    if (word_is(w, "hpoint"))
        err_set(err, errsz, "type 'hpoint' is not supported");
    else
        err_set(err, errsz, "unknown type '%.*s'", w.len > 40 ? 40 : w.len, w.s);
    return false;
}

/* SCENE_CLASS_CONSTANT... for a class word, else SCENE_CLASS_NONE */
static scene_class class_word(word w)
{
    for (size_t i = 0; i < sizeof class_words / sizeof class_words[0]; i++)
        if (word_is(w, class_words[i]))
            return (scene_class)(SCENE_CLASS_CONSTANT + (int)i);
    return SCENE_CLASS_NONE;
}

bool rib_decl_parse(const char *text, bool with_name, rib_decl *out,
                    const char **name, int *name_len, char *err, size_t errsz)
{
    word w[5];
    int n = split_words(text, w, 4), i = 0;
    out->type = SL_TYPE_FLOAT;
    out->arraylen = 1;
    out->cls = SCENE_CLASS_NONE;
    if (n == 0) {
        err_set(err, errsz, "empty declaration");
        return false;
    }
    if (n > 4) {
        err_set(err, errsz, "too many words (expected [class] type [n]%s)",
                 with_name ? " name" : "");
        return false;
    }
    if ((out->cls = class_word(w[i])) != SCENE_CLASS_NONE)
        i++;
    if (i == n) {
        err_set(err, errsz, "missing type after '%.*s'", w[0].len, w[0].s);
        return false;
    }
    if (!parse_type_word(w[i++], &out->type, err, errsz))
        return false;
    if (i < n && w[i].s[0] == '[' && !parse_arraylen(w[i++], &out->arraylen, err, errsz))
        return false;
    if (with_name) {
        if (i != n - 1) {
            err_set(err, errsz, i == n ? "missing parameter name" :
                     "too many words (expected [class] type [n] name)");
            return false;
        }
        *name = w[i].s;
        *name_len = w[i].len;
        return true;
    }
    if (i != n) {
        err_set(err, errsz, "unexpected '%.*s' after the type",
                 w[i].len > 40 ? 40 : w[i].len, w[i].s);
        return false;
    }
    return true;
}

bool rib_decl_is_inline(const char *text)
{
    word w[3];
    return split_words(text, w, 2) > 1;
}

/* ---------------------------------------------------------------------- */
/* predeclared names                                                       */
/* ---------------------------------------------------------------------- */

static const struct { const char *name; sl_type type; int arraylen; } standard[] = {
    /* geometric primitive variables (Table 5.1) */
    { "P", SL_TYPE_POINT, 1 },      { "Pz", SL_TYPE_FLOAT, 1 },
    { "Pw", SL_TYPE_FLOAT, 4 },     /* an hpoint, read as 4 floats (NuPatch) */
    { "N", SL_TYPE_NORMAL, 1 },     { "Np", SL_TYPE_NORMAL, 1 },
    { "Cs", SL_TYPE_COLOR, 1 },     { "Os", SL_TYPE_COLOR, 1 },
    { "s", SL_TYPE_FLOAT, 1 },      { "t", SL_TYPE_FLOAT, 1 },
    { "st", SL_TYPE_FLOAT, 2 },
    /* standard surface / displacement shaders (Appendix A) */
    { "Ka", SL_TYPE_FLOAT, 1 },     { "Kd", SL_TYPE_FLOAT, 1 },
    { "Ks", SL_TYPE_FLOAT, 1 },     { "Kr", SL_TYPE_FLOAT, 1 },
    { "Km", SL_TYPE_FLOAT, 1 },     { "roughness", SL_TYPE_FLOAT, 1 },
    { "specularcolor", SL_TYPE_COLOR, 1 },
    { "amplitude", SL_TYPE_FLOAT, 1 },
    { "texturename", SL_TYPE_STRING, 1 },
    { "mindistance", SL_TYPE_FLOAT, 1 }, { "maxdistance", SL_TYPE_FLOAT, 1 },
    { "distancecolor", SL_TYPE_COLOR, 1 }, { "background", SL_TYPE_COLOR, 1 },
    /* standard light sources */
    { "intensity", SL_TYPE_FLOAT, 1 }, { "lightcolor", SL_TYPE_COLOR, 1 },
    { "from", SL_TYPE_POINT, 1 },   { "to", SL_TYPE_POINT, 1 },
    { "coneangle", SL_TYPE_FLOAT, 1 }, { "conedeltaangle", SL_TYPE_FLOAT, 1 },
    { "beamdistribution", SL_TYPE_FLOAT, 1 },
    { "shadows", SL_TYPE_STRING, 1 }, { "__shadows", SL_TYPE_STRING, 1 },
    /* requests' own parameters */
    { "fov", SL_TYPE_FLOAT, 1 },    { "sphere", SL_TYPE_FLOAT, 1 },
    { "coordinatesystem", SL_TYPE_STRING, 1 },
    { "name", SL_TYPE_STRING, 1 },  { "shader", SL_TYPE_STRING, 1 },
    { "maxdepth", SL_TYPE_FLOAT, 1 },       /* Option "trace" */
};

bool rib_decl_standard(const char *name, rib_decl *out)
{
    for (size_t i = 0; i < sizeof standard / sizeof standard[0]; i++)
        if (strcmp(name, standard[i].name) == 0) {
            out->type = standard[i].type;
            out->arraylen = standard[i].arraylen;
            out->cls = SCENE_CLASS_NONE;
            return true;
        }
    return false;
}

/* ---------------------------------------------------------------------- */
/* the Declare table                                                       */
/* ---------------------------------------------------------------------- */

typedef struct entry { char *name; rib_decl decl; } entry;

struct rib_decls {
    entry *items;
    int count, cap;
};

rib_decls *rib_decls_new(void)
{
    rib_decls *self = xrealloc(NULL, sizeof *self);
    memset(self, 0, sizeof *self);
    return self;
}

void rib_decls_destroy(rib_decls **self_p)
{
    if (!self_p || !*self_p)
        return;
    for (int i = 0; i < (*self_p)->count; i++)
        free((*self_p)->items[i].name);
    free((*self_p)->items);
    free(*self_p);
    *self_p = NULL;
}

void rib_decls_add(rib_decls *self, const char *name, rib_decl decl)
{
    for (int i = 0; i < self->count; i++)
        if (strcmp(self->items[i].name, name) == 0) {
            self->items[i].decl = decl;
            return;
        }
    if (self->count == self->cap) {
        self->cap = self->cap ? 2 * self->cap : 16;
        self->items = xrealloc(self->items, (size_t)self->cap * sizeof *self->items);
    }
    self->items[self->count].name = xstrndup(name, strlen(name));
    self->items[self->count].decl = decl;
    self->count++;
}

bool rib_decls_find(const rib_decls *self, const char *name, rib_decl *out)
{
    for (int i = 0; i < self->count; i++)
        if (strcmp(self->items[i].name, name) == 0) {
            *out = self->items[i].decl;
            return true;
        }
    return rib_decl_standard(name, out);
}
