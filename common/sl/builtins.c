/*
 * builtins.c: the table of built-in functions (RI Spec 3.2 §15, "Built-in
 * Functions": math, geometry, noise, shading) with their signatures and
 * lowerings, overload resolution against it, and the table of global
 * variables (§14, "Predefined Shader Variables").
 *
 * Overload resolution scores each candidate of the right arity: an exact
 * argument costs 0, a point/vector/normal passed as another of the three
 * costs 1, a float promoted to a triple costs 2; the cheapest candidate
 * wins, the first of equally cheap ones (the table lists float versions
 * first).
 */
#include "sl/builtins.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define OP(n, s, o) { n, s, SL_LOWER_OP, SL_OP_##o, 0 }
#define LW(n, s, l, o, k) { n, s, SL_LOWER_##l, SL_OP_##o, k }

static const sl_builtin table[] = {
    /* math (§15.1) */
    OP("sin", "f:f", SIN), OP("cos", "f:f", COS), OP("tan", "f:f", TAN),
    OP("asin", "f:f", ASIN), OP("acos", "f:f", ACOS),
    OP("atan", "f:f", ATAN), OP("atan", "f:ff", ATAN2),
    OP("exp", "f:f", EXP), OP("sqrt", "f:f", SQRT),
    OP("inversesqrt", "f:f", INVSQRT),
    OP("log", "f:f", LOG), LW("log", "f:ff", LOGBASE, END, 0),
    OP("pow", "f:ff", POW),
    LW("radians", "f:f", SCALE, MUL, M_PI / 180.0),
    LW("degrees", "f:f", SCALE, MUL, 180.0 / M_PI),
    OP("abs", "G:G", ABS), OP("sign", "G:G", SIGN),
    OP("floor", "G:G", FLOOR), OP("ceil", "G:G", CEIL),
    OP("round", "G:G", ROUND),
    OP("mod", "f:ff", MOD),
    OP("min", "G:GG", MIN), OP("max", "G:GG", MAX),
    OP("clamp", "G:GGG", CLAMP),
    OP("step", "f:ff", STEP), OP("smoothstep", "f:fff", SMOOTHSTEP),
    LW("filterstep", "f:ff", FILTERSTEP, END, 0),
    LW("filterstep", "f:fff", FILTERSTEP, END, 0),
    LW("filterstep", "f:ffsf", FILTERSTEP, END, 0),
    LW("filterstep", "f:ffss", FILTERSTEP, END, 0),
    LW("filterstep", "f:fffsf", FILTERSTEP, END, 0),
    LW("filterstep", "f:fffss", FILTERSTEP, END, 0),
    LW("filterstep", "f:ffsfss", FILTERSTEP, END, 0),
    LW("filterstep", "f:ffsssf", FILTERSTEP, END, 0),
    LW("filterstep", "f:fffsfss", FILTERSTEP, END, 0),
    LW("filterstep", "f:fffsssf", FILTERSTEP, END, 0),
    OP("mix", "G:GGf", MIX), OP("mix", "T:TTT", MIX),
    /* geometry (§15.2) */
    LW("length", "f:S", LENGTH, END, 0),
    LW("normalize", "v:v", NORMALIZE, END, 0),
    LW("normalize", "n:n", NORMALIZE, END, 0),
    LW("normalize", "v:p", NORMALIZE, END, 0),
    LW("distance", "f:pp", DISTANCE, END, 0),
    LW("dot", "f:SS", DOT, END, 0), LW("dot", "f:cc", DOT, END, 0),
    LW("cross", "v:SS", CROSS, END, 0),
    LW("faceforward", "A:SS", FACEFORWARD, END, 0),
    LW("faceforward", "A:SSS", FACEFORWARD, END, 0),
    LW("reflect", "v:SS", REFLECT, END, 0),
    LW("refract", "v:SSf", REFRACT, END, 0),
    LW("fresnel", "0:SSfww", FRESNEL, END, 0),
    LW("fresnel", "0:SSfwwoo", FRESNEL, END, 0),
    LW("depth", "f:p", DEPTH, END, 0),
    LW("ptlined", "f:ppp", EXTRA, END, 0),
    LW("transform", "p:sp", TRANSFORM, XPOINT, 0),
    LW("transform", "p:ssp", TRANSFORM, XPOINT, 0),
    LW("transform", "p:mp", TRANSFORM, XPOINT, 0),
    LW("vtransform", "v:sv", TRANSFORM, XVECTOR, 0),
    LW("vtransform", "v:ssv", TRANSFORM, XVECTOR, 0),
    LW("vtransform", "v:mv", TRANSFORM, XVECTOR, 0),
    LW("ntransform", "n:sn", TRANSFORM, XNORMAL, 0),
    LW("ntransform", "n:ssn", TRANSFORM, XNORMAL, 0),
    LW("ntransform", "n:mn", TRANSFORM, XNORMAL, 0),
    LW("calculatenormal", "n:p", CALCNORMAL, CALCNORMAL, 0),
    LW("area", "f:p", AREA, AREA, 0),
    LW("Du", "f:f", DERIV, DU, 0), LW("Du", "v:p", DERIV, DU, 0),
    LW("Du", "T:T", DERIV, DU, 0),
    LW("Dv", "f:f", DERIV, DV, 0), LW("Dv", "v:p", DERIV, DV, 0),
    LW("Dv", "T:T", DERIV, DV, 0),
    LW("Deriv", "f:ff", DERIV, DERIV, 0), LW("Deriv", "v:pf", DERIV, DERIV, 0),
    LW("Deriv", "T:Tf", DERIV, DERIV, 0),
    LW("xcomp", "f:S", COMP, END, 0), LW("ycomp", "f:S", COMP, END, 1),
    LW("zcomp", "f:S", COMP, END, 2),
    LW("setxcomp", "0:of", SETCOMP_K, END, 0),
    LW("setycomp", "0:of", SETCOMP_K, END, 1),
    LW("setzcomp", "0:of", SETCOMP_K, END, 2),
    LW("comp", "f:Tf", COMP_RT, COMP, 0),
    LW("comp", "f:mff", MCOMP, END, 0),
    LW("setcomp", "0:Off", SETCOMP_RT, SETCOMP, 0),
    LW("setcomp", "0:Mfff", MSETCOMP, END, 0),
    LW("ptransform", "p:sp", TRANSFORM, XPOINT, 0),
    LW("ptransform", "p:ssp", TRANSFORM, XPOINT, 0),
    LW("ptransform", "p:mp", TRANSFORM, XPOINT, 0),
    LW("ctransform", "c:sc", CTRANSFORM, END, 0),
    LW("ctransform", "c:ssc", CTRANSFORM, END, 0),
    /* matrices (§15.3) */
    LW("determinant", "f:m", DETERMINANT, END, 0),
    LW("translate", "m:mv", MATRIX_XFORM, END, 0),
    LW("rotate", "m:mfv", MATRIX_XFORM, END, 1),
    LW("rotate", "p:pfpp", EXTRA, END, 1),      /* §15.2: Q about the line P0 P1 */
    LW("scale", "m:mp", MATRIX_XFORM, END, 2),
    /* noise (§15.1) */
    LW("noise", "F:f", NOISE, NOISE, SL_NOISE_PLAIN),
    LW("noise", "F:ff", NOISE, NOISE, SL_NOISE_PLAIN),
    LW("noise", "F:p", NOISE, NOISE, SL_NOISE_PLAIN),
    LW("noise", "F:pf", NOISE, NOISE, SL_NOISE_PLAIN),
    LW("pnoise", "F:ff", NOISE, NOISE, SL_NOISE_PERIODIC),
    LW("pnoise", "F:ffff", NOISE, NOISE, SL_NOISE_PERIODIC),
    LW("pnoise", "F:pp", NOISE, NOISE, SL_NOISE_PERIODIC),
    LW("pnoise", "F:pfpf", NOISE, NOISE, SL_NOISE_PERIODIC),
    LW("cellnoise", "F:f", NOISE, NOISE, SL_NOISE_CELL),
    LW("cellnoise", "F:ff", NOISE, NOISE, SL_NOISE_CELL),
    LW("cellnoise", "F:p", NOISE, NOISE, SL_NOISE_CELL),
    LW("cellnoise", "F:pf", NOISE, NOISE, SL_NOISE_CELL),
    LW("random", "F:", RANDOM, RANDOM, 0),
    /* textures (§15.7): variadic, checked apart (check_texture) */
    LW("texture", "F:s", TEXTURE, TEXTURE, 0), LW("texture", "F:sff", TEXTURE, TEXTURE, 0),
    LW("environment", "F:sv", TEXTURE, TEXTURE, 0),
    LW("bump", "v:snvv", TEXTURE, TEXTURE, 0), LW("bump", "v:snvvff", TEXTURE, TEXTURE, 0),
    LW("textureinfo", "f:ssV", TEXTURE, TEXINFO, 0),
    /* shading (§15.4) */
    LW("ambient", "c:", LIGHT, AMBIENT, 0),
    LW("diffuse", "c:n", LIGHT, DIFFUSE, 0),
    LW("specular", "c:nvf", LIGHT, SPECULAR, 0),
    LW("phong", "c:nvf", LIGHT, PHONG, 0),
    LW("specularbrdf", "c:SSSf", EXTRA, END, 2),
    LW("shadername", "s:", EXTRA, END, 3),
    /* the parts of an illuminance loop (parser.c builds the calls; their
     * names cannot be written in a source) */
    LW("illuminance start", "0:p", ILLUMINANCE, LSTART, 0),
    LW("illuminance next", "f:", ILLUMINANCE, LNEXT, 0),
    LW("illuminance cone", "f:vf", ILLUMINANCE, END, 0),
    LW("illuminate begin", "0:p", EMITTER, END, 0),
    LW("solar begin", "0:v", EMITTER, END, 1),
    LW("solar begin", "0:", EMITTER, END, 1),
    /* strings (§15.6): concat, format and printf are variadic */
    LW("concat", "s:", STRINGS, SCAT, 0),
    LW("format", "s:", STRINGS, SFMT, 0),
    LW("printf", "0:", STRINGS, SPRINT, 0),
    LW("match", "f:ss", MATCH, SMATCH, 0),
    /* message passing (§15.7) */
    LW("displacement", "f:sV", MESSAGE, MESSAGE, SL_MSG_DISPLACEMENT),
    LW("surface", "f:sV", MESSAGE, MESSAGE, SL_MSG_SURFACE),
    LW("lightsource", "f:sV", MESSAGE, MESSAGE, SL_MSG_LIGHTSOURCE),
    LW("attribute", "f:sV", MESSAGE, MESSAGE, SL_MSG_ATTRIBUTE),
    LW("option", "f:sV", MESSAGE, MESSAGE, SL_MSG_OPTION),
    LW("rendererinfo", "f:sV", MESSAGE, MESSAGE, SL_MSG_RENDERERINFO),
    /* rays (§15.6 trace, §15.7 shadow): the renderer's tracer (shader.h, sl_tracer);
     * shadow()'s optional parameters are checked, warned about and dropped by
     * check_call.c before this entry is looked up */
    LW("trace", "c:pv", RAY, RAY, SL_RAY_TRACE),
    LW("shadow", "f:sp", RAY, RAY, 1),
    /* spline (§15.1): variadic, checked by check_spline */
    LW("spline", "A:", SPLINE, END, 0),
};

enum { TABLE_SIZE = sizeof table / sizeof table[0] };

const sl_builtin *sl_builtin_find(const char *name, int *count)
{
    for (int i = 0; i < TABLE_SIZE; i++) {
        if (strcmp(table[i].name, name) != 0)
            continue;
        int n = 1;
        while (i + n < TABLE_SIZE && strcmp(table[i + n].name, name) == 0)
            n++;
        *count = n;
        return &table[i];
    }
    *count = 0;
    return NULL;
}

/* ---------------------------------------------------------------------- */
/* resolution                                                              */
/* ---------------------------------------------------------------------- */

static sl_ty letter_type(char c)
{
    switch (c) {
    case 'f': return SL_TYPE_FLOAT;
    case 'p': return SL_TYPE_POINT;
    case 'v': return SL_TYPE_VECTOR;
    case 'n': return SL_TYPE_NORMAL;
    case 'c': return SL_TYPE_COLOR;
    case 's': return SL_TYPE_STRING;
    case 'm': return SL_TYPE_MATRIX;
    default: return SL_TYPE_VOID;
    }
}

/* Cost of passing `have` where `want` (a concrete type) is expected; -1: no. */
static int conversion_cost(sl_ty have, sl_ty want)
{
    if (have == want)
        return 0;
    if ((have == SL_TY_LIST3 && sl_ty_is_triple(want)) ||
        (have == SL_TY_LIST16 && want == SL_TYPE_MATRIX))
        return 0;
    if (sl_ty_is_spatial(have) && sl_ty_is_spatial(want))
        return 1;
    if (have == SL_TYPE_FLOAT && (sl_ty_is_triple(want) || want == SL_TYPE_MATRIX))
        return 2;
    return -1;
}

/* The type the generic letter g (G or T) stands for in this call: the
 * first triple among its arguments; else, when an untyped list (x, y, z)
 * is among them, the triple the context asks for (hint) or a point; else
 * float (G) / nothing (T). */
static sl_ty bind_generic(const char *args, char g, const sl_ty *have, int n, sl_ty hint)
{
    bool list = false;
    for (int i = 0; i < n; i++) {
        if (args[i] == g && sl_ty_is_triple(have[i]))
            return have[i];
        list |= args[i] == g && have[i] == SL_TY_LIST3;
    }
    if (list)
        return sl_ty_is_triple(hint) ? hint : SL_TYPE_POINT;
    return g == 'G' ? SL_TYPE_FLOAT : SL_TYPE_VOID;
}

/* Cost of one candidate, filling the wanted argument types; -1: no. */
static int candidate_cost(const sl_builtin *b, const sl_ty *have, int n, sl_ty hint,
                          sl_ty *want)
{
    const char *args = strchr(b->sig, ':') + 1;
    if ((int)strlen(args) != n)
        return -1;
    sl_ty g = bind_generic(args, 'G', have, n, hint);
    sl_ty t = bind_generic(args, 'T', have, n, hint);
    int cost = 0;
    for (int i = 0; i < n; i++) {
        char c = args[i];
        if (c == 'S' && have[i] == SL_TY_LIST3) {     /* (x, y, z) as a point */
            want[i] = SL_TYPE_POINT;
            continue;
        }
        if (c == 'S' || c == 'o') {
            if (!sl_ty_is_spatial(have[i]))
                return -1;
            want[i] = have[i];
            continue;
        }
        if (c == 'V') {
            if (sl_ty_is_array(have[i]) || sl_ty_is_list(have[i]) || have[i] == SL_TY_BOOL ||
                have[i] == SL_TY_ERROR)
                return -1;
            want[i] = have[i];
            continue;
        }
        if (c == 'w') {
            if (have[i] != SL_TYPE_FLOAT)
                return -1;
            want[i] = have[i];
            continue;
        }
        if (c == 'M') {
            if (have[i] != SL_TYPE_MATRIX)
                return -1;
            want[i] = have[i];
            continue;
        }
        if (c == 'O') {
            if (!sl_ty_is_triple(have[i]))
                return -1;
            want[i] = have[i];
            continue;
        }
        want[i] = c == 'G' ? g : c == 'T' ? t : letter_type(c);
        if (want[i] == SL_TYPE_VOID)
            return -1;
        int k = conversion_cost(have[i], want[i]);
        if (k < 0)
            return -1;
        cost += k;
    }
    return cost;
}

const sl_builtin *sl_builtin_resolve(const char *name, const sl_ty *args, int nargs,
                                     sl_ty hint, sl_ty *arg_types, sl_ty *result)
{
    int count;
    const sl_builtin *first = sl_builtin_find(name, &count);
    const sl_builtin *best = NULL;
    int best_cost = 0;
    sl_ty want[SL_MAX_BUILTIN_ARGS];
    if (nargs > SL_MAX_BUILTIN_ARGS)
        return NULL;
    for (int i = 0; i < count; i++) {
        int cost = candidate_cost(&first[i], args, nargs, hint, want);
        if (cost < 0 || (best && cost >= best_cost))
            continue;
        best = &first[i];
        best_cost = cost;
        memcpy(arg_types, want, (size_t)nargs * sizeof *want);
    }
    if (!best)
        return NULL;
    char r = best->sig[0];
    const char *sig_args = best->sig + 2;
    if (r == 'A')
        *result = arg_types[0];
    else if (r == 'G')
        *result = bind_generic(sig_args, 'G', args, nargs, hint);
    else if (r == 'T')
        *result = bind_generic(sig_args, 'T', args, nargs, hint);
    else if (r == 'F')
        *result = sl_ty_is_triple(hint) ? hint : SL_TYPE_FLOAT;
    else
        *result = letter_type(r);
    return best;
}

static const char *letter_name(char c)
{
    switch (c) {
    case 'S': case 'o': return "point|vector|normal";
    case 'O': case 'T': return "triple";
    case 'M': return "matrix";
    case 'w': return "float";
    case 'V': return "variable";
    case 'G': return "float|triple";
    default: return sl_ty_name(letter_type(c));
    }
}

void sl_builtin_candidates(const char *name, char *buf, size_t size)
{
    int count;
    const sl_builtin *b = sl_builtin_find(name, &count);
    size_t o = 0;
    buf[0] = '\0';
    for (int i = 0; i < count && o < size; i++) {
        o += (size_t)snprintf(buf + o, size - o, "%s%s(", i ? ", " : "", name);
        for (const char *a = b[i].sig + 2; *a && o < size; a++)
            o += (size_t)snprintf(buf + o, size - o, "%s%s", a == b[i].sig + 2 ? "" : ", ",
                                  letter_name(*a));
        if (o < size)
            o += (size_t)snprintf(buf + o, size - o, ")");
    }
}

/* ---------------------------------------------------------------------- */
/* spline bases                                                            */
/* ---------------------------------------------------------------------- */

/* The basis matrices of RiBasis (RI Spec 3.2 §4.1.2) in the power form
 * x^3, x^2, x, 1 (rows) over the segment's 4 knots (columns). */
static const sl_spline_basis bases[] = {
    [SL_SPLINE_CATMULL_ROM] = { "catmull-rom", 1, { { -0.5, 1.5, -1.5, 0.5 },
                                                    { 1, -2.5, 2, -0.5 },
                                                    { -0.5, 0, 0.5, 0 },
                                                    { 0, 1, 0, 0 } } },
    [1] = { "bezier", 3, { { -1, 3, -3, 1 }, { 3, -6, 3, 0 }, { -3, 3, 0, 0 },
                           { 1, 0, 0, 0 } } },
    [2] = { "b-spline", 1, { { -1 / 6.0, 0.5, -0.5, 1 / 6.0 }, { 0.5, -1, 0.5, 0 },
                             { -0.5, 0, 0.5, 0 }, { 1 / 6.0, 4 / 6.0, 1 / 6.0, 0 } } },
    /* knots: value0, tangent0, value1, tangent1 */
    [3] = { "hermite", 2, { { 2, 1, -2, 1 }, { -3, -2, 3, -1 }, { 0, 1, 0, 0 },
                            { 1, 0, 0, 0 } } },
    [4] = { "linear", 1, { { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, -1, 1, 0 },
                           { 0, 1, 0, 0 } } },
    [SL_SPLINE_CONSTANT] = { "constant", 1, { { 0, 0, 0, 0 }, { 0, 0, 0, 0 },
                                              { 0, 0, 0, 0 }, { 0, 1, 0, 0 } } },
};

int sl_spline_basis_find(const char *name)
{
    for (int i = 0; i < (int)(sizeof bases / sizeof bases[0]); i++)
        if (strcmp(bases[i].name, name) == 0)
            return i;
    if (strcmp(name, "catmullrom") == 0)
        return SL_SPLINE_CATMULL_ROM;
    if (strcmp(name, "bspline") == 0)
        return 2;
    return -1;
}

const sl_spline_basis *sl_spline_basis_get(int index) { return &bases[index]; }

/* ---------------------------------------------------------------------- */
/* color spaces                                                            */
/* ---------------------------------------------------------------------- */

int sl_color_space_find(const char *name)
{
    static const struct {
        const char *name;
        sl_color_space space;
    } names[] = {
        { "rgb", SL_CSPACE_RGB }, { "hsv", SL_CSPACE_HSV }, { "hsl", SL_CSPACE_HSL },
        { "xyz", SL_CSPACE_XYZ }, { "XYZ", SL_CSPACE_XYZ }, { "xyY", SL_CSPACE_XYY },
        { "YIQ", SL_CSPACE_YIQ },
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(names[i].name, name) == 0)
            return (int)names[i].space;
    return -1;
}

/* ---------------------------------------------------------------------- */
/* globals                                                                 */
/* ---------------------------------------------------------------------- */

static const struct {
    const char *name;
    sl_ty ty;
    bool writable;
} globals[SL_G__COUNT] = {
    [SL_G_P] = { "P", SL_TYPE_POINT, true },
    [SL_G_N] = { "N", SL_TYPE_NORMAL, true },
    [SL_G_Ng] = { "Ng", SL_TYPE_NORMAL, false },
    [SL_G_I] = { "I", SL_TYPE_VECTOR, false },
    [SL_G_E] = { "E", SL_TYPE_POINT, false },
    [SL_G_s] = { "s", SL_TYPE_FLOAT, false },
    [SL_G_t] = { "t", SL_TYPE_FLOAT, false },
    [SL_G_u] = { "u", SL_TYPE_FLOAT, false },
    [SL_G_v] = { "v", SL_TYPE_FLOAT, false },
    [SL_G_du] = { "du", SL_TYPE_FLOAT, false },
    [SL_G_dv] = { "dv", SL_TYPE_FLOAT, false },
    [SL_G_dPdu] = { "dPdu", SL_TYPE_VECTOR, false },
    [SL_G_dPdv] = { "dPdv", SL_TYPE_VECTOR, false },
    [SL_G_Cs] = { "Cs", SL_TYPE_COLOR, false },
    [SL_G_Os] = { "Os", SL_TYPE_COLOR, false },
    [SL_G_Ci] = { "Ci", SL_TYPE_COLOR, true },
    [SL_G_Oi] = { "Oi", SL_TYPE_COLOR, true },
    [SL_G_L] = { "L", SL_TYPE_VECTOR, false },
    [SL_G_Cl] = { "Cl", SL_TYPE_COLOR, false },
    [SL_G_time] = { "time", SL_TYPE_FLOAT, false },
};

int sl_global_find(const char *name)
{
    if (strcmp(name, "Ps") == 0)     /* light shaders: the point being lit */
        return SL_G_P;
    for (int g = 0; g < SL_G__COUNT; g++)
        if (strcmp(globals[g].name, name) == 0)
            return g;
    return -1;
}

sl_ty sl_global_type(sl_global g) { return globals[g].ty; }
bool sl_global_writable(sl_global g) { return globals[g].writable; }
const char *sl_global_name(sl_global g) { return globals[g].name; }
/* Slot offsets of the globals in the order of sl_global: 3 slots for
 * points, vectors, normals and colors, 1 for floats. */
const unsigned char sl_global_slot_table[SL_G__COUNT + 1] = {
    [SL_G_P] = 0, [SL_G_N] = 3, [SL_G_Ng] = 6, [SL_G_I] = 9, [SL_G_E] = 12,
    [SL_G_s] = 15, [SL_G_t] = 16, [SL_G_u] = 17, [SL_G_v] = 18, [SL_G_du] = 19,
    [SL_G_dv] = 20, [SL_G_dPdu] = 21, [SL_G_dPdv] = 24, [SL_G_Cs] = 27, [SL_G_Os] = 30,
    [SL_G_Ci] = 33, [SL_G_Oi] = 36, [SL_G_L] = 39, [SL_G_Cl] = 42, [SL_G_time] = 45,
    [SL_G__COUNT] = 46,
};

int sl_texinfo_find(const char *name)
{
    static const char *const names[] = { "resolution", "channels", "levels", "type" };
    for (int k = 0; k < 4; k++)
        if (strcmp(name, names[k]) == 0)
            return k;
    return -1;
}
