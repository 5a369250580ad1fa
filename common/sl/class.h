/*
 * class.h: RSL 2 shader classes (PRMan 13.5 and later) as the parser reads
 * them, and their lowering to an ordinary shader (class.c).
 *
 *   class name(params) {
 *       float member = 0;                        member variables
 *       float helper(float x) { ... }            methods
 *       public void construct() { ... }          run first, then begin()
 *       public void displacement(output point P; output normal N) { ... }
 *   }
 *
 * is the shader `displacement name(params) { members; methods as nested
 * functions, each reaching the members and parameters as if declared
 * 'extern'; construct(); begin(); the displacement method's body }`. The
 * kind is the one public `surface`, `displacement` or `light` method's;
 * its parameters must be the predefined variables it writes. Methods are
 * inlined like every function (docs/shading-language.md, "RSL 2").
 */
#ifndef SL_CLASS_H
#define SL_CLASS_H

#include "sl/ast.h"
#include "sl/diag.h"

typedef struct sl_class {
    const char *name;
    sl_pos pos;
    sl_node **members;      /* SL_N_DECL of the member variables */
    int nmembers, members_cap;
    sl_func **methods;      /* parsed like nested functions */
    int nmethods, methods_cap;
} sl_class;

/* Fills file's kind, name, position and body from the class (the parser
 * has set file->params). Reports what cannot be lowered (no shader method,
 * several, a shader method's parameter that is not a predefined
 * variable); false then. */
bool sl_class_lower(sl_arena *arena, sl_diag *diag, sl_ast_file *file, const sl_class *cls);

#endif
