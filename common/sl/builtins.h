/*
 * builtins.h: the built-in functions and global variables of the shading
 * language: one table of signatures that the checker resolves calls
 * against (overloads, generic triples, conversions) and that tells the
 * code generator how to lower each call to scalar bytecode.
 *
 * Signature strings: "R:AB..." with R the result and A, B... the arguments:
 *   f float  p point  v vector  n normal  c color  s string  m matrix
 *   0 void (result)   o an assignable variable of any spatial type
 *   O an assignable variable of any triple type
 *   M an assignable matrix variable   w an assignable float variable
 *   V an assignable variable of any type but arrays
 *   S any spatial type (point/vector/normal)
 *   T any triple (point/vector/normal/color; all T of a call agree)
 *   G float or any triple (all G of a call agree; floats promote)
 *   A (result) the type of the first argument
 *   F (result) float, or the triple type the context asks for
 *                (`color noise(P)`, `point p = noise(P)`): RenderMan's
 *                polymorphic noise
 */
#ifndef SL_BUILTINS_H
#define SL_BUILTINS_H

#include "sl/ast.h"
#include "sl/bytecode.h"

typedef enum sl_lowering {
    SL_LOWER_OP,          /* componentwise scalar op (op) */
    SL_LOWER_SCALE,       /* x * constant (radians, degrees) */
    SL_LOWER_LOGBASE,     /* log(x) / log(b) */
    SL_LOWER_LENGTH, SL_LOWER_NORMALIZE, SL_LOWER_DISTANCE,
    SL_LOWER_DOT, SL_LOWER_CROSS, SL_LOWER_FACEFORWARD, SL_LOWER_REFLECT,
    SL_LOWER_TRANSFORM,   /* op: XPOINT / XVECTOR / XNORMAL */
    SL_LOWER_CALCNORMAL, SL_LOWER_AREA,
    SL_LOWER_DERIV,       /* op: DU / DV / DERIV */
    SL_LOWER_COMP,        /* xcomp ycomp zcomp: constant index (k) */
    SL_LOWER_SETCOMP_K,   /* setxcomp ...: constant index (k) */
    SL_LOWER_COMP_RT,     /* comp(x, i) */
    SL_LOWER_SETCOMP_RT,  /* setcomp(x, i, v) */
    SL_LOWER_NOISE,       /* k: SL_NOISE_PLAIN / PERIODIC / CELL */
    SL_LOWER_RANDOM,
    SL_LOWER_LIGHT,       /* op: AMBIENT DIFFUSE SPECULAR PHONG */
    SL_LOWER_CTRANSFORM,  /* ctransform([from,] to, c): constant color spaces */
    SL_LOWER_DETERMINANT,
    SL_LOWER_MATRIX_XFORM, /* k: 0 translate, 1 rotate, 2 scale */
    SL_LOWER_MCOMP,       /* comp(m, row, col) */
    SL_LOWER_MSETCOMP,    /* setcomp(m, row, col, v) */
    SL_LOWER_REFRACT, SL_LOWER_FRESNEL, SL_LOWER_DEPTH,
    SL_LOWER_FILTERSTEP,  /* filterstep(edge, x [, x1] [, "width", w] [, "filter", f]) */
    SL_LOWER_ILLUMINANCE, /* the parts of an illuminance loop (parser.c):
                             op LSTART / LNEXT, or END: the cone test */
    SL_LOWER_EMITTER,     /* illuminate / solar (parser.c): k 0 / 1 */
    SL_LOWER_STRINGS,     /* concat, format, printf: variadic, checked apart
                             (check_strings); op SCAT / SFMT / SPRINT */
    SL_LOWER_MATCH,
    SL_LOWER_MESSAGE,     /* displacement("name", x) ...: k = sl_message_scope */
    SL_LOWER_EXTRA,       /* k: 0 ptlined, 1 rotate(Q, angle, P0, P1),
                             2 specularbrdf, 3 shadername() */
    SL_LOWER_RAY,         /* trace(P, R), shadow(name, P [, "param", v ...]):
                             op RAY, k = SL_RAY_TRACE or 1 (a shadow) */
    SL_LOWER_SPLINE,      /* spline([basis,] t, knots... | knots[]): checked
                             apart (variadic); node op = the basis index */
    SL_LOWER_TEXTURE,     /* texture, environment, bump, textureinfo: checked
                             apart (check_texture); node op = SL_TEX_* */
} sl_lowering;

/* The texture lookups (docs/textures.md) and textureinfo's data. */
enum { SL_TEX_TEXTURE, SL_TEX_ENVIRONMENT, SL_TEX_BUMP, SL_TEX_INFO };
/* "resolution", "channels", "levels", "type": the SL_TEXINFO_*, or -1. */
int sl_texinfo_find(const char *name);

typedef struct sl_builtin {
    const char *name;
    const char *sig;
    sl_lowering lower;
    sl_opcode op;
    double k;
} sl_builtin;

/* All entries for `name` are consecutive in the table: returns the first
 * and their number, or NULL. */
const sl_builtin *sl_builtin_find(const char *name, int *count);

/* The most arguments a built-in of the table takes (the ones with
 * "name", value lists, texture() and shadow(), are checked on their own). */
enum { SL_MAX_BUILTIN_ARGS = 8 };

/* Resolution of one call: the chosen entry, the type each argument must
 * be converted to, and the result type. hint: the type the context wants
 * (SL_TYPE_VOID: none), for 'F' results. Returns NULL when nothing
 * matches. Of equally good candidates the first in the table wins (the
 * table lists the float versions first). */
const sl_builtin *sl_builtin_resolve(const char *name, const sl_ty *args, int nargs,
                                     sl_ty hint, sl_ty *arg_types, sl_ty *result);

/* "noise(float), noise(float, float), ..." for a message, into buf. */
void sl_builtin_candidates(const char *name, char *buf, size_t size);

/* The spline bases (RI Spec 3.2 §15.1 spline, RiBasis §4.1.2): a cubic
 * segment over 4 consecutive knots, the segments `step` knots apart:
 * value(x) = sum_i x^(3-i) sum_j m[i][j] knot[seg*step + j], x in [0, 1].
 * "linear" and "constant" use catmull-rom's layout (the first and the last
 * knot are not interpolated); "constant" is knot[seg*step + 1]. */
typedef struct sl_spline_basis {
    const char *name;
    int step;
    double m[4][4];
} sl_spline_basis;

enum { SL_SPLINE_CATMULL_ROM = 0, SL_SPLINE_CONSTANT = 5 };

/* The basis index of `name` ("catmull-rom", "bezier", "b-spline",
 * "hermite", "linear", "constant"), or -1. */
int sl_spline_basis_find(const char *name);
const sl_spline_basis *sl_spline_basis_get(int index);

/* Color spaces (RI Spec 3.2 §15.1 ctransform, §13 color constructors):
 * "rgb" (the current one), "hsv", "hsl", "xyz" and "XYZ" (CIE XYZ of
 * linear Rec. 709 / sRGB primaries, D65), "xyY", "YIQ" (NTSC). */
typedef enum sl_color_space {
    SL_CSPACE_RGB, SL_CSPACE_HSV, SL_CSPACE_HSL, SL_CSPACE_XYZ, SL_CSPACE_XYY,
    SL_CSPACE_YIQ,
} sl_color_space;

/* The color space called `name`, or -1. */
int sl_color_space_find(const char *name);
#define SL_COLOR_SPACE_NAMES "\"rgb\", \"hsv\", \"hsl\", \"xyz\", \"XYZ\", \"xyY\", \"YIQ\""

/* Globals: name -> sl_global (or -1), its type, whether shaders may
 * assign it (P, N, Ci, Oi). */
int sl_global_find(const char *name);
sl_ty sl_global_type(sl_global g);
bool sl_global_writable(sl_global g);

#endif
