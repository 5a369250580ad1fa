/*
 * shader.h: the public face of the shading language, what the renderer
 * (common/trace) and the tools (aafarm-slc, the worker) use:
 *
 *   sl_program   a compiled shader: one bytecode for all four modes
 *   sl_instance  a program plus the parameter values of one RIB
 *                Surface/Displacement call (uniform values)
 *   sl_vm        per-thread execution state: globals, spaces, lights,
 *                limits; runs an instance in one of four arithmetics
 *
 * Modes (Heidrich & Seidel 1998 §4, §4.1):
 *   SL_MODE_FLOAT     plain doubles (surface shading)
 *   SL_MODE_DUAL      value + d/du + d/dv per scalar (automatic
 *                     differentiation): Du, Dv, Deriv, calculatenormal
 *   SL_MODE_INTERVAL  ia_interval per scalar (conservative, --arith interval)
 *   SL_MODE_AFFINE    aa_form per scalar over the caller's aa_context
 *                     (conservative, correlations kept)
 *
 * In FLOAT mode derivatives are 0 and calculatenormal(P) returns the
 * current N. In INTERVAL/AFFINE modes a program whose derivatives
 * (Du/Dv/Deriv/calculatenormal/area) can flow into P runs with interval
 * bounds of every value's d/du and d/dv (vm_deriv.inc), seeded from the
 * globals' bounds (sl_vm_set_derivs): its P encloses the DUAL mode's at
 * every point of the range. Derivatives that cannot reach P (`N =
 * calculatenormal(P)` after the last write of P) are not tracked, and what
 * they compute is unbounded in these modes: range runs are for P.
 * In INTERVAL/AFFINE modes a comparison whose operands overlap runs both
 * branches and merges the results (flag AA_DISCONTINUOUS); see
 * docs/shading-language.md "Evaluation".
 *
 * "current" space is camera space (RenderMan's convention): the renderer
 * sets P, N, I, E, ... in camera space and supplies the matrices of the
 * named spaces (sl_spaces).
 */
#ifndef SL_SHADER_H
#define SL_SHADER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "sl/diag.h"
#include "sl/source.h"
#include "util/vecmath.h"

typedef enum sl_shader_kind {
    SL_SHADER_SURFACE,
    SL_SHADER_DISPLACEMENT,
    SL_SHADER_LIGHT,        /* evaluated with sl_light_eval */
} sl_shader_kind;

typedef enum sl_type {
    SL_TYPE_VOID, SL_TYPE_FLOAT, SL_TYPE_POINT, SL_TYPE_VECTOR, SL_TYPE_NORMAL,
    SL_TYPE_COLOR, SL_TYPE_STRING, SL_TYPE_MATRIX,
} sl_type;

typedef enum sl_mode {
    SL_MODE_FLOAT, SL_MODE_DUAL, SL_MODE_INTERVAL, SL_MODE_AFFINE,
} sl_mode;

/* The renderer-supplied global variables (RenderMan names). Scalars take
 * one value, point/vector/normal/color globals three. */
typedef enum sl_global {
    SL_G_P, SL_G_N, SL_G_Ng, SL_G_I, SL_G_E,
    SL_G_s, SL_G_t, SL_G_u, SL_G_v, SL_G_du, SL_G_dv,
    SL_G_dPdu, SL_G_dPdv, SL_G_Cs, SL_G_Os, SL_G_Ci, SL_G_Oi,
    SL_G_L, SL_G_Cl, SL_G_time,
    SL_G__COUNT
} sl_global;

/* ---- compiling ---------------------------------------------------------- */

typedef struct sl_program sl_program;

/* Compiles main_file (a name in `set`, or one its loader finds) with
 * #include search path `search_path` (NULL-terminated, may be NULL).
 * Returns NULL when there were errors; every error is in `diag` with its
 * file:line:col. Warnings may be reported on success too. cancel: the
 * program's stop flag (a signal) or NULL; the parser and the checker look
 * at it as they go (every SL_PARSE_CANCEL_EVERY tokens, every definition),
 * and a compile that finds it set ends with the error "interrupted". */
sl_program *sl_compile(sl_source_set *set, const char *main_file,
                       const char *const *search_path, const atomic_int *cancel,
                       sl_diag *diag);
void sl_program_destroy(sl_program **self_p);

const char *sl_program_name(const sl_program *self);      /* "wave" */
sl_shader_kind sl_program_kind(const sl_program *self);
/* Bytecode listing for aafarm-slc --dump. */
void sl_program_dump(const sl_program *self, FILE *out);

typedef struct sl_param_info {
    const char *name;
    sl_type type;
    bool output;
} sl_param_info;
/* Whether the program may touch global g (conservative: an operand that
 * could be a matrix or triple starting below g counts too). */
bool sl_program_reads_global(const sl_program *self, sl_global g);
/* Whether the program may use named space `space` (SL_SPACE_*: transform()
 * and the casts; conservative: a space named by a string variable counts
 * as every space, and depth() as a use of "camera"). */
bool sl_program_uses_space(const sl_program *self, int space);
/* Whether the program looks up a texture map (texture(), environment()
 * and the like). */
bool sl_program_reads_textures(const sl_program *self);
/* Whether range runs carry derivative bounds (sl_program_derivatives_reach_P). */
bool sl_program_takes_derivatives(const sl_program *self);
/* Tape pruning (issue 24, tape_plan.c): a tape holds SL_TAPE_BITS bits
 * for each of the program's tape sites (sl_program_tape_site_count, at
 * most SL_TAPE_SITES; 0: its box runs take no tape), the decision a box
 * run proved there or 0; sl_program_tape_plan gives the plan of a box
 * run below a node whose runs proved `tape` (sl_vm_set_tape; the caller
 * frees it), NULL where the tape decides nothing. */
enum { SL_TAPE_SITES = 7, SL_TAPE_BITS = 2 };
int sl_program_tape_site_count(const sl_program *self);
uint8_t *sl_program_tape_plan(const sl_program *self, uint32_t tape);
/* Whether a box run of this displacement (sl_vm_set_box_runs) may read
 * global g's value (derivs false) or its derivative bounds (derivs true):
 * what box_plan.c finds can reach P; true for a program without a plan.
 * A renderer need not compute what no box run reads. */
bool sl_program_box_reads(const sl_program *self, sl_global g, bool derivs);
int sl_program_param_count(const sl_program *self);
/* Whether any parameter is an output (message passing) */
bool sl_program_has_outputs(const sl_program *self);
void sl_program_param(const sl_program *self, int index, sl_param_info *info);
int sl_program_find_param(const sl_program *self, const char *name); /* -1 */

/* ---- instances: parameter values --------------------------------------- */

typedef struct sl_instance sl_instance;

sl_instance *sl_instance_new(const sl_program *program);  /* defaults */
void sl_instance_destroy(sl_instance **self_p);
const sl_program *sl_instance_program(const sl_instance *self);

/* Sets parameter `name` from RIB values: `type` is what the RIB declared
 * (float: 1 value, point/vector/normal/color: 3, matrix: 16, string: use
 * sl_instance_set_string). On a mismatch (unknown name, wrong type or
 * count) returns false with a one-line reason in err. */
bool sl_instance_set(sl_instance *self, const char *name, sl_type type,
                     const double *values, int count, char *err, size_t errsz);
bool sl_instance_set_string(sl_instance *self, const char *name,
                            const char *value, char *err, size_t errsz);

/* ---- the virtual machine ------------------------------------------------ */

typedef struct sl_limits {
    long max_instructions;     /* per run (default 1,000,000) */
    int max_loop_iterations;   /* per loop in interval/affine mode (default 64) */
} sl_limits;

enum { SL_SPACE_CURRENT, SL_SPACE_WORLD, SL_SPACE_OBJECT, SL_SPACE_SHADER,
       SL_SPACE_CAMERA, SL_SPACE__COUNT,
       /* the projective spaces, made by the VM from "camera" and the
        * camera's projection (sl_vm_set_projection), not in sl_spaces */
       SL_SPACE_SCREEN = SL_SPACE__COUNT, SL_SPACE_NDC, SL_SPACE_RASTER, SL_SPACE__NAMED };

/* For each named space, the matrix from that space to "current" and back
 * (util/vecmath.h conventions). transform("object", P) applies
 * from_current[SL_SPACE_OBJECT]. */
typedef struct sl_spaces {
    mat4 to_current[SL_SPACE__COUNT];
    mat4 from_current[SL_SPACE__COUNT];
} sl_spaces;

/* Lights, for ambient/diffuse/specular/phong in surface shaders (float
 * mode). The callback fills up to `max` samples for surface point P
 * (current space) and returns how many: L points from P towards the light
 * (unnormalised), Cl is the light's colour arriving at P with shadows
 * already applied; ambient lights set `ambient` (L ignored). */
typedef struct sl_light_sample {
    double L[3];
    double Cl[3];
    bool ambient;
    bool directional;   /* L is a direction (distant, solar): the light is at
                           infinity, for shadow() in an illuminance loop */
} sl_light_sample;
typedef int (*sl_light_fn)(void *user, const double P[3], sl_light_sample *out, int max);

typedef struct sl_dual { double v, du, dv; } sl_dual;

typedef enum sl_status {
    SL_OK = 0,
    SL_ERR_BUDGET,       /* instruction budget exhausted */
    SL_ERR_LOOP_CAP,     /* interval/affine loop hit its iteration cap */
    SL_ERR_RUNTIME,      /* anything else the VM refuses */
    SL_ERR_CANCELLED,    /* the cancel flag was set (sl_vm_set_cancel) */
} sl_status;

typedef struct sl_vm sl_vm;

sl_vm *sl_vm_new(const sl_limits *limits);    /* NULL: defaults */
/* A flag the program sets to stop (SIGINT/SIGTERM): a run that finds it
 * non-zero (looked at every SL_VM_CANCEL_EVERY instructions) fails with
 * SL_ERR_CANCELLED and "interrupted", so one long evaluation (a large
 * --budget) does not hold a signal up. NULL: never. */
enum { SL_VM_CANCEL_EVERY = 4096 };
void sl_vm_set_cancel(sl_vm *self, const atomic_int *flag);
/* Box runs: the caller reads P alone from this VM's affine runs (the
 * renderer's boxes of a displaced surface). A program that takes
 * derivatives then leaves out what cannot reach P (box_plan.c: operations
 * whose results only reach N = calculatenormal(P), derivative bounds that
 * only reach such results); P is as without. The other globals an affine
 * run writes are then not meaningful. Default off. */
void sl_vm_set_box_runs(sl_vm *self, bool on);
/* Tape pruning (issue 24, tape_plan.c): the next affine box runs (box
 * runs on, not slope runs) take `plan`, sl_program_tape_plan of the
 * decisions `tape` that their node's runs proved (NULL: the program's own
 * plan), and with record note the decisions of the program's tape sites
 * (at most SL_TAPE_SITES min, max, clamp, step, smoothstep, mix and
 * branches).
 * A plan belongs to the program of the runs. Set it per run: it stays
 * until changed (sl_vm_set_tape(vm, NULL, 0, false): none). */
void sl_vm_set_tape(sl_vm *self, const uint8_t *plan, uint32_t tape, bool record);
/* After a recorded run: `tape` with the decisions that run proved added
 * (a site decided where each of its executions made the same choice) */
uint32_t sl_vm_tape(const sl_vm *self);
/* The uniform memo (vm_uniform.inc): affine runs copy the result of an
 * operation on symbol-free operands they met before instead of computing
 * it again (the same bits either way). Default on; off for tests that
 * compare the two. */
void sl_vm_set_uniform_memo(sl_vm *self, bool on);
/* Operations the memo answered, over this VM's life */
long sl_vm_uniform_hits(const sl_vm *self);
void sl_vm_destroy(sl_vm **self_p);

/* The named spaces the next runs read: kept by pointer (the binding of
 * every evaluation sets them), so *spaces must stay alive and unchanged
 * until the VM's last run with them or the next call; NULL: identity. */
void sl_vm_set_spaces(sl_vm *self, const sl_spaces *spaces);
/* The camera's projection, for the "screen", "NDC" and "raster" spaces (RI
 * Spec 3.2 §4.1, RenderMan's conventions): "screen" is "camera" after
 * screen_from_camera (projective: a perspective one divides by camera z,
 * which interval and affine runs do with their conservative division),
 * "NDC" maps the screen window (left, right, bottom, top) to [0, 1] x
 * [0, 1] with y down, "raster" is NDC times the resolution; z is screen
 * z throughout. Copied. Default: screen = camera, window [-1, 1]^2, 1 x 1
 * pixels. sl_projection_perspective/_orthographic make the matrix of the
 * RIB's Projection. */
void sl_vm_set_projection(sl_vm *self, const mat4 *screen_from_camera,
                          const double window[4], int xres, int yres);
/* x and y divided by z tan(fov / 2), z from near..far to 0..1 (of 1/z):
 * the standard homogeneous perspective (w = camera z). */
mat4 sl_projection_perspective(double fov_degrees, double near, double far);
/* x and y kept, z from near..far to 0..1. */
mat4 sl_projection_orthographic(double near, double far);
void sl_vm_set_lights(sl_vm *self, sl_light_fn fn, void *user);
/* The textures that texture(), environment(), bump() and textureinfo()
 * read (tex/tex.h; shared by the VMs of a process; NULL: none, a lookup is
 * a runtime error). */
struct tex_cache;
void sl_vm_set_textures(sl_vm *self, struct tex_cache *textures);
/* Where the shader's printf lines go: fn(ctx, text) once per line (float
 * mode only, at most 100 lines per VM, then one note that the rest are not
 * shown). With none installed (the default) they are dropped: the library
 * never prints; a program that wants them in its log installs one. */
typedef void (*sl_print_fn)(void *ctx, const char *text);
void sl_vm_set_print(sl_vm *self, sl_print_fn fn, void *ctx);
/* The texture names a program's lookups use that are known when it is
 * bound: string constants and the instance's string parameter values
 * (default or set) that reach a texture operation directly. Up to max
 * names into names (duplicates removed); returns their number. */
int sl_instance_texture_names(const sl_instance *inst, const char **names, int max);

/* Globals, before a run, in the arithmetic of the coming run. Globals not
 * set since the last sl_vm_clear_globals are 0 (point values). */
void sl_vm_clear_globals(sl_vm *self);
void sl_vm_set_float(sl_vm *self, sl_global g, const double *values);
void sl_vm_set_dual(sl_vm *self, sl_global g, const sl_dual *values);
void sl_vm_set_interval(sl_vm *self, sl_global g, const ia_interval *values);
void sl_vm_set_affine(sl_vm *self, sl_global g, const aa_form *values);
/* Bounds of the d/du and d/dv of global g over the range of the coming
 * interval/affine run (one interval per component). Globals without them
 * have unknown derivatives (the whole line) until sl_vm_clear_globals. */
void sl_vm_set_derivs(sl_vm *self, sl_global g, const ia_interval *du,
                      const ia_interval *dv);

/* Varying values (primitive variables, RI Spec 3.2 §5.1): from the next
 * run until sl_vm_clear_globals, global g, or parameter `param` (an index
 * of the program that runs), takes per component k the polynomial
 *   sum over i, j < 4 of coef[i + 4 j][k] u^i v^j,
 * u and v being the globals u, v, computed at the start of the run in its
 * arithmetic (Horner's rule over the non-zero terms; so a range run bounds
 * it over the range, with derivatives).
 * size: 1 or 3 components (the parameter's must match). False when more
 * than SL_VM_MAX_VARYING are set. */
enum { SL_VM_MAX_VARYING = 32 };   /* 16 primitive variables, each a global and a parameter */
bool sl_vm_set_varying_global(sl_vm *self, sl_global g, const double coef[16][3]);
bool sl_vm_set_varying_param(sl_vm *self, int param, int size, const double coef[16][3]);

/* Runs the instance. `ctx` is used (and required) in affine mode only. */
sl_status sl_vm_run(sl_vm *self, const sl_instance *inst, sl_mode mode,
                    aa_context *ctx);
/* Case splits of affine runs (issue 24, "walls and patterns"). Between
 * sl_vm_split_begin and sl_vm_split_end, an affine run splits the first
 * max_ops of its floor, ceil, round, mod and step operations whose result
 * takes exactly two values over the range (a cell across one seam of a
 * brick or a tile): the operation gives one of them exactly, a constant
 * (mod: x - k y for one k), flagged AA_DISCONTINUOUS, instead of their
 * hull; an if (or ?:) whose condition the range leaves undecided counts
 * as such an operation too, and runs one of its sides a case (the nearest
 * cell of a Voronoi loop) instead of both merged. The caller runs the
 * shader once per case: after each run,
 * sl_vm_split_next says whether another case remains and selects it (the
 * runs replay the choices before the last one that can change, so they
 * meet the same operations). Every point of the range belongs to one
 * case, in which the run computes what the point computes with bounds
 * over the whole range for the rest: the hull of the cases' results
 * encloses the values, as one run does, and it is tighter where the
 * hull of the two values lost what the rest of the program made of them
 * (mortar on both sides of a brick's seam: 0, not [0, 1]). max_ops is at
 * most SL_VM_MAX_SPLITS (2^max_ops runs); 0 splits nothing.
 * sl_vm_split_full: whether the last run met more such operations than
 * max_ops (those beyond took both values, as without splits). */
enum { SL_VM_MAX_SPLITS = 8 };
void sl_vm_split_begin(sl_vm *self, int max_ops);
bool sl_vm_split_next(sl_vm *self);
bool sl_vm_split_full(const sl_vm *self);
void sl_vm_split_end(sl_vm *self);

/* After a failed run: "shader 'wave': instruction budget of 1000000
 * exceeded" and the like. */
const char *sl_vm_error(const sl_vm *self);

/* A run in interval arithmetic whose derivative bounds are SLOPE bounds:
 * for every global, in every component, the d/du and d/dv bounds of
 * sl_vm_get_slopes enclose the true partial derivatives of the value as a
 * function of (u, v) at every point of the range where it is
 * differentiable, given that the globals' bounds (sl_vm_set_derivs) do.
 * Where the program's own definitions are first-order or jump (Du, Dv,
 * Deriv, calculatenormal, area, a texture's gradient, an undecided
 * comparison used as a value), the bound is the whole line; functions that
 * jump inside the range flag their values AA_DISCONTINUOUS, and a caller
 * that needs a continuous function refuses those. Used by the hit proof
 * (trace/prove.c); sl_vm_get_interval reads the values as after
 * sl_vm_run. */
sl_status sl_vm_run_slopes(sl_vm *self, const sl_instance *inst);
void sl_vm_get_slopes(const sl_vm *self, sl_global g, ia_interval *du, ia_interval *dv);

/* Globals after a run (P and N of a displacement shader, Ci and Oi of a
 * surface shader), in the arithmetic of the run. */
void sl_vm_get_float(const sl_vm *self, sl_global g, double *values);
void sl_vm_get_dual(const sl_vm *self, sl_global g, sl_dual *values);
void sl_vm_get_interval(const sl_vm *self, sl_global g, ia_interval *values);
void sl_vm_get_affine(const sl_vm *self, sl_global g, aa_form *values);

/* Instructions executed by the last run (statistics). */
long sl_vm_instructions(const sl_vm *self);

/* ---- additions (not part of the original contract) -------------------- */

/* Lights whose L and Cl do not depend on the surface point (distant and
 * ambient lights): used by ambient/diffuse/specular/phong in ALL modes,
 * after the callback's samples, so that interval/affine runs of surface
 * shaders get sound bounds. At most 64; replaces the previous set. In
 * interval/affine mode a light callback (sl_vm_set_lights) makes these
 * functions unbounded, since its samples are only known at points. */
void sl_vm_set_fixed_lights(sl_vm *self, const sl_light_sample *samples, int count);

/* Seed of random(): every run restarts the sequence from it (default 0),
 * so results are a pure function of the inputs. */
void sl_vm_set_seed(sl_vm *self, uint64_t seed);

/* Message passing (RI Spec 3.2 §15.7): what `displacement("name", x)`,
 * `surface(...)`, `lightsource(...)`, `attribute(...)`, `option(...)` and
 * `rendererinfo(...)` read. A call finds the message of its scope and name
 * whose type matches the variable's (float, triple, matrix, string), sets
 * the variable and returns 1; otherwise it returns 0 and leaves the
 * variable alone. */
typedef enum sl_message_scope {
    SL_MSG_DISPLACEMENT, SL_MSG_SURFACE, SL_MSG_LIGHTSOURCE, SL_MSG_ATTRIBUTE,
    SL_MSG_OPTION, SL_MSG_RENDERERINFO, SL_MSG__COUNT
} sl_message_scope;

/* Sets (or replaces) a uniform message: values has sl_type's count of
 * numbers (1, 3 or 16), or string is the value of a string message (copied;
 * at most 127 bytes). Uniform messages are the same over any range, so
 * interval and affine runs read them exactly. Names: at most 63 bytes. At
 * most 64 messages; returns false when full or too long. A new VM has
 * rendererinfo "renderer" = "aafarm". */
bool sl_vm_set_message(sl_vm *self, sl_message_scope scope, const char *name, sl_type type,
                       const double *values, const char *string);
/* After a float or dual run: the output parameters of the program just run
 * become messages of `scope` (the displacement shader's outputs, for the
 * surface shader run next on this VM). They are values at one point: an
 * interval or affine run reads them as unbounded. Returns how many. */
int sl_vm_capture_outputs(sl_vm *self, sl_message_scope scope);
void sl_vm_clear_messages(sl_vm *self, sl_message_scope scope);

/* Light shaders (RI Spec 3.2 §9.3, §15.4 illuminate, solar): runs the light
 * instance `inst` in float mode for the surface point Ps (current space)
 * and fills the sample the surface shader's light functions take: L from
 * Ps towards the light, Cl, and ambient for a light shader without
 * illuminate or solar. Cl is 0 where the light's illuminate/solar cone
 * leaves Ps out. Use a VM of its own (a light callback runs while the
 * surface shader's VM is busy), with the scene's spaces set on it. */
sl_status sl_light_eval(sl_vm *self, const sl_instance *inst, const double Ps[3],
                        sl_light_sample *out);

/* Rays from shaders (RI Spec 3.2 §15.6 trace, §15.7 shadow): the
 * renderer's ray tracer, called in float and dual mode at the point of the
 * run (dual: derivatives 0). `trace` fills the colour seen from P along R.
 * `shadow` returns the fraction of light blocked on the segment from P
 * towards the light, P + t D for t in (0, tmax): tmax 1 when the light is
 * at P + D, INFINITY when D is a direction; `map` is the name the shader
 * gave. Either may be NULL. Without a tracer trace() is black and shadow()
 * 0 in every mode; with one, an interval or affine run reads trace() as
 * unbounded and shadow() as [0, 1] (rays are traced at points only). */
typedef struct sl_tracer {
    void (*trace)(void *user, const double P[3], const double R[3], double Ci[3]);
    double (*shadow)(void *user, const char *map, const double P[3], const double D[3],
                     double tmax);
    void *user;
} sl_tracer;
/* NULL: none. */
void sl_vm_set_tracer(sl_vm *self, const sl_tracer *tracer);

/* The camera's clipping planes (RIB Clipping), for depth(P) =
 * (z_camera - near) / (far - near). Default near 0, far 1: depth(P) is
 * then the camera-space z. far <= near is ignored. */
void sl_vm_set_clipping(sl_vm *self, double near, double far);

#endif
