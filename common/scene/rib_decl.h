/*
 * rib_decl.h: parameter declarations of RIB (RI Specification 3.2, §3.1
 * "Parameter lists" and RiDeclare): what type a parameter name has.
 *
 * A parameter's type comes from, first match wins:
 *   1. an inline declaration in the name itself: "uniform float Km",
 *      "color specularcolor", "float[2] st";
 *   2. the Declare table (rib_decls), the latest Declare of the name;
 *   3. the standard predeclared names (Ka Kd Ks roughness Km intensity
 *      lightcolor from to coneangle ..., P N Cs Os s t st ...).
 *
 * A declaration reads "[class] type [ '[' n ']' ]": class is constant,
 * uniform, varying, vertex or facevarying (recorded for primitive
 * variables; a shader call is uniform); type is float, integer (read as float), point, vector,
 * normal, color, string or matrix.
 */
#ifndef SCENE_RIB_DECL_H
#define SCENE_RIB_DECL_H

#include <stdbool.h>
#include <stddef.h>

#include "scene/scene.h"
#include "sl/shader.h"

typedef struct rib_decl {
    sl_type type;
    int arraylen;        /* 1 unless "[n]" */
    scene_class cls;     /* the class word, SCENE_CLASS_NONE when not written */
} rib_decl;

/* Numbers one value of the type takes (float 1, color 3, matrix 16;
 * string 1, counted in strings). */
int rib_type_components(sl_type type);
const char *rib_type_name(sl_type type);

/* Parses a declaration "[class] type [n]" (`with_name` false) or an
 * inline declaration "[class] type [n] name" (`with_name` true; *name
 * receives a pointer into `text` and *name_len its length). On failure
 * returns false with a reason ("unknown type 'flaot'"). */
bool rib_decl_parse(const char *text, bool with_name, rib_decl *out,
                    const char **name, int *name_len, char *err, size_t errsz);

/* True when the text has more than one word or a '[', i.e. it is an
 * inline declaration rather than a plain name. */
bool rib_decl_is_inline(const char *text);

/* The standard predeclared type of `name`, or false. */
bool rib_decl_standard(const char *name, rib_decl *out);

/* The table of Declare'd names. */
typedef struct rib_decls rib_decls;
rib_decls *rib_decls_new(void);
void rib_decls_destroy(rib_decls **self_p);
void rib_decls_add(rib_decls *self, const char *name, rib_decl decl);
/* Declare'd first, then standard. */
bool rib_decls_find(const rib_decls *self, const char *name, rib_decl *out);

#endif
