/*
 * vm_internal.h: what the virtual machine's files share: the sl_vm and
 * sl_instance structures, the merge frames of interval/affine control flow,
 * and the entry points of the four backends (vm_float.c, vm_dual.c,
 * vm_interval.c, vm_affine.c), each an instance of the dispatch loop in
 * vm_exec.inc over its own slot type.
 *
 * Memory: every slot file (one per mode), the string file and the merge
 * pool are allocated at their hard limits when the VM is created, so that
 * a run never allocates and a shader cannot make it grow.
 */
#ifndef SL_VM_INTERNAL_H
#define SL_VM_INTERNAL_H

#include <assert.h>
#include <math.h>
#include <stdint.h>

#include "sl/bytecode.h"
#include "sl/shader.h"
#include "sl/strmatch.h"
#include "tex/tex.h"
#include "util/err.h"

#include <stdio.h>
#include <string.h>

enum {
    SL_VM_POOL_VALUES = 8192,     /* snapshot values of open merge frames */
    SL_VM_MAX_FRAMES = 512,       /* open merge frames (nested maybe-branches) */
    SL_VM_MAX_LIGHTS = 64,        /* light samples per shading call */
    SL_VM_MAX_MESSAGES = 64,      /* message-passing values (sl_vm_set_message) */
    SL_VM_STRING_SPACE = 16384,   /* bytes of strings made by one run (concat, format) */
    SL_VM_MAX_PRINTS = 100,       /* printf lines per VM, then one note */
    SL_VM_TEX_MEMO = 16,          /* textures a VM remembers by name */
};

/* The instantiations of the dispatch loop (vm_exec.inc). The two _DERIV
 * ones run programs that take derivatives (Du, Dv, Deriv, calculatenormal,
 * area) in interval/affine mode: each slot carries its value in the mode's
 * arithmetic and interval bounds of its d/du and d/dv (vm_deriv.inc). */
enum {
    VM_VAR_FLOAT, VM_VAR_DUAL, VM_VAR_INTERVAL, VM_VAR_AFFINE,
    VM_VAR_INTERVAL_DERIV, VM_VAR_AFFINE_DERIV, VM_VAR__COUNT
};

/* Slots of the derivative-carrying modes: the value, and enclosures of
 * its derivatives over the range (every d/du of the dual mode at a point
 * inside lies in du). */
typedef struct sl_ideriv { ia_interval v, du, dv; } sl_ideriv;
typedef struct sl_aderiv { ia_interval du, dv; aa_form v; } sl_aderiv;

/* The parameter values of one instance. */
typedef struct sl_inst_value {
    bool set;
    double v[16];
    char *s;
} sl_inst_value;

struct sl_instance {
    const sl_program *program;
    sl_inst_value *values;
};

/* An open merge frame: an undecided `if` (then or else part running) or
 * one undecided iteration of a loop; `pool` is where the snapshot of the
 * frame's merge table starts. */
typedef enum { VM_FRAME_IF, VM_FRAME_LOOP } vm_frame_kind;
typedef struct vm_frame {
    vm_frame_kind kind;
    int phase;          /* IF: 0 then, 1 else */
    int owner;          /* pc of its BR_BEGIN / LOOP_TEST */
    int count;          /* LOOP: undecided iterations so far */
    int table;
    int pool, spool;
} vm_frame;

/* The saved states of the dead paths of one loop or inlined call (its
 * break or early return), merged back where it ends. Stored at the top end
 * of the merge pool, growing down. */
enum { SL_VM_MAX_ACCUMULATORS = 64 };
/* One message (shader.h, sl_vm_set_message): size 1, 3 or 16 numbers, or
 * 0 for a string; varying: a captured output, known at one point only. */
typedef struct vm_message {
    int scope, size;
    bool varying;
    char name[64];
    double v[16];
    char s[128];
} vm_message;

/* A varying global or parameter (sl_vm_set_varying_*): sum c[i + 4 j] u^i v^j. */
typedef struct vm_varying {
    bool global;
    int target;                    /* the global's first slot, or the parameter */
    int size;
    double c[16][3];
} vm_varying;

typedef struct vm_accumulator {
    int kind, id;
    int pool, spool;
    bool live;
} vm_accumulator;

/* The uniform memo of the affine VMs (vm_uniform.inc): per program, the
 * last symbol-free operands and result of each eligible instruction. */
enum {
    VM_UNIFORM_BLOCKS = 8,        /* programs remembered per VM */
    VM_UNIFORM_GIVE_UP = 8,       /* misses in a row: the instruction is varying */
};
typedef struct vm_uniform_val {   /* a symbol-free slot; no padding (memcmp) */
    double x0, err, lo, hi;
    double dlo[2], dhi[2];        /* derivative bounds (zero without them) */
    uint32_t dflags[2];
    uint32_t flags, spare;
} vm_uniform_val;
typedef struct vm_uniform_entry {
    vm_uniform_val ops[3], out;
    int plan;                     /* the box plan it ran with */
} vm_uniform_entry;
typedef struct vm_uniform_block {
    unsigned long serial;         /* the program's (0: unused block) */
    int variant, flavour;
    unsigned long last_use;
    int ncode;
    uint8_t *misses;              /* per pc; VM_UNIFORM_GIVE_UP: not looked at */
    uint8_t *arity;               /* per pc: vm_uniform_arity of its opcode */
    int32_t *index;               /* per pc: its entry, or -1 */
    vm_uniform_entry *entries;
    int nentries, cap;
} vm_uniform_block;

/* How many slot operands (b, c, d) an eligible opcode reads; 0: not
 * eligible (several outputs, cases, random numbers, textures, state);
 * VM_UNIFORM_DERIVS_OF_B: Du and Dv, which read b's derivative bounds
 * alone (a symbol in b's value does not make them varying) */
enum { VM_UNIFORM_DERIVS_OF_B = 4 };
int vm_uniform_arity(int op);
/* b now holds no entry, for program p in this arithmetic and flavour */
void vm_uniform_block_reset(vm_uniform_block *b, const sl_program *p, int variant, int flavour);
/* pc's entry, made when it has none */
vm_uniform_entry *vm_uniform_entry_at(vm_uniform_block *b, int pc);
void vm_uniform_free(sl_vm *vm);

struct sl_vm {
    sl_limits limits;
    /* the caller's spaces, read in place (sl_vm_set_spaces: a pointer, not
     * a copy, since every evaluation binds them); identity until set */
    const sl_spaces *spaces;
    sl_spaces identity;
    double near, far;             /* clipping planes, for depth() */
    mat4 depth;                   /* current -> camera, z to depth */
    bool depth_stale;             /* depth not yet made from spaces, near, far */
    /* sl_vm_set_projection: camera -> screen -> NDC -> raster, and the
     * three spaces from and to "current" made from them and "camera" when
     * a shader first asks after the spaces change (proj_stale) */
    mat4 screen_from_camera, ndc_from_screen, raster_from_ndc;
    mat4 proj_from[3], proj_to[3];
    bool proj_stale;
    sl_light_fn light_fn;
    void *light_user;
    sl_tracer tracer;             /* trace() and shadow(); zeroed: none */
    sl_light_sample fixed_lights[SL_VM_MAX_LIGHTS];
    sl_light_sample illum[SL_VM_MAX_LIGHTS];   /* the illuminance loop's lights */
    int nillum, illum_next;
    vm_message messages[SL_VM_MAX_MESSAGES];
    int nmessages;
    vm_varying varying[SL_VM_MAX_VARYING];   /* cleared with the globals */
    int nvarying;
    char strings[SL_VM_STRING_SPACE];  /* strings made by this run */
    int strings_used;
    int prints;
    int nfixed_lights;
    uint64_t seed;
    tex_cache *textures;          /* sl_vm_set_textures */
    sl_print_fn print;            /* sl_vm_set_print (NULL: printf dropped) */
    const atomic_int *cancel;     /* sl_vm_set_cancel (NULL: never) */
    void *print_ctx;
    struct { char name[256]; const tex_texture *tex; } tex_memo[SL_VM_TEX_MEMO];
    int ntex_memo;

    double *f;                    /* slot files, SL_MAX_SLOTS each */
    sl_dual *d;
    ia_interval *i;
    aa_form *a;
    sl_ideriv *id;                /* allocated on the first derivative run */
    sl_aderiv *ad;
    ia_interval gderiv[SL_GLOBAL_SLOTS][2];   /* d/du, d/dv of the globals for
                                                 interval/affine runs; a slot
                                                 not in gderiv_set is unknown */
    uint64_t gderiv_set;          /* bit s: gderiv[s] was given since the last
                                     sl_vm_clear_globals (the clear runs per box
                                     and per point: 46 slots cleared lazily) */
    const char **str;             /* string file */
    unsigned long loaded[VM_VAR__COUNT];   /* program whose constants each file holds */
    unsigned clear_pending;       /* modes whose globals still have to be zeroed */

    void *pool;                   /* SL_VM_POOL_VALUES values of the run's mode */
    const char **spool;
    int pool_top, spool_top;
    vm_frame frames[SL_VM_MAX_FRAMES];
    int nframes;
    vm_accumulator accs[SL_VM_MAX_ACCUMULATORS];
    int naccs, acc_bottom, sacc_bottom;

    /* case splits of affine runs (sl_vm_split_begin): the first max
     * two-valued discontinuous operations of a run take pick[i] (0: the
     * lower value); n of them so far this run; picks from `fixed` on are
     * 0 (the choices before replay the previous run's); at[i]: the pc of
     * split i, whose case a later operation of the same value takes
     * (prog->split_same, split_plan.c); pc: the operation running now */
    struct {
        bool on;
        bool full;                /* this run met more than max of them */
        int max, n, fixed, pc;
        unsigned char pick[SL_VM_MAX_SPLITS];
        int at[SL_VM_MAX_SPLITS];
    } split;

    /* the current run */
    const sl_program *prog;
    const sl_instance *inst;
    aa_context *ctx;
    sl_mode mode;
    bool slopes;                  /* sl_vm_run_slopes: derivative bounds must be
                                     true slope bounds (vm_deriv.inc) */
    bool box_runs;                /* sl_vm_set_box_runs: affine runs are read
                                     for P alone (box_plan.c) */
    long executed;
    uint64_t rng;
    /* tape pruning (sl_vm_set_tape, tape_plan.c): the plan of the next
     * affine box runs (NULL: the program's), the tape it came from, and
     * with tape_record the decisions of the program's tape sites, noted
     * per site at every execution (0: not met, 1..3: the same decision at
     * every one, VM_TAPE_MIXED: not) */
    const uint8_t *tape_plan;
    uint32_t tape_in;
    bool tape_record;
    uint8_t tape_seen[SL_TAPE_SITES];
    /* the uniform memo (vm_uniform.inc) */
    bool uniform_off;             /* sl_vm_set_uniform_memo(false) */
    vm_uniform_block uniform[VM_UNIFORM_BLOCKS];
    unsigned long uniform_clock;
    long uniform_hits;
    char error[ERR_LEN];
};

enum { VM_TAPE_MIXED = 0xff };       /* tape_seen: executions disagreed */

sl_status sl_vm_exec_float(sl_vm *vm);
sl_status sl_vm_exec_dual(sl_vm *vm);
sl_status sl_vm_exec_interval(sl_vm *vm);
sl_status sl_vm_exec_affine(sl_vm *vm);
sl_status sl_vm_exec_interval_deriv(sl_vm *vm);
sl_status sl_vm_exec_affine_deriv(sl_vm *vm);
/* the same with tape pruning (vm_affine_tape.c, vm_affine_deriv_tape.c) */
sl_status sl_vm_exec_affine_tape(sl_vm *vm);
sl_status sl_vm_exec_affine_deriv_tape(sl_vm *vm);

/* "shader 'name': " + message into vm->error; returns st. */
sl_status sl_vm_fail(sl_vm *vm, sl_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The matrix of space `name` (SL_SPACE_TO_CURRENT or _FROM_CURRENT), or
 * NULL for an unknown name. */
const mat4 *sl_vm_space(sl_vm *vm, const char *name, int dir);
const mat4 *sl_vm_space_id(sl_vm *vm, int space, int dir);

/* Light samples at surface point P for float/dual runs: the callback's,
 * then the fixed lights. */
int sl_vm_light_samples(sl_vm *vm, const double P[3], sl_light_sample *out);

/* trace() / shadow() at one point (the RAY instruction in float and dual
 * mode): kind SL_RAY_*, map the shadow map's name, P the ray's origin,
 * D trace()'s direction or the L global for shadow(); out gets the colour
 * (trace) or the blocked fraction (out[0], shadow). */
void sl_vm_ray(sl_vm *vm, int kind, const char *map, const double P[3], const double D[3],
               double out[3]);
/* Does this VM's tracer answer rays of this kind? */
bool sl_vm_traces(const sl_vm *vm, int kind);
/* The texture called name for instruction pc: from the VM's memo, else
 * from its cache (opened there on first use; sl_vm_set_textures). NULL
 * with *st set and the error in vm->error when it cannot be had. */
const tex_texture *sl_vm_texture(sl_vm *vm, const char *name, int pc, sl_status *st);
/* The same without the error: err NULL remembers a texture that cannot be
 * opened, and answers NULL for it from then on (textureinfo). */
const tex_texture *sl_vm_texture_find(sl_vm *vm, const char *name, char *err, size_t errsz);

/* A texture channel from a slot's value (rounded down; -1: none, so the
 * lookup gives its fill value). */
static inline int sl_tex_channel(double v) { return v >= 0 && v < 4096 ? (int)v : -1; }

/* What a channel ch the texture lacks reads when the shader gave no
 * "fill" (RI Spec 3.2, texture access parameters: a texture without an
 * alpha channel answers requests for its alpha, channel 3 of RGBA, with
 * 1: opaque); 0 for any other missing channel. */
static inline double sl_tex_default_fill(int ch) { return ch == 3 ? 1.0 : 0.0; }
/* The fill of channel ch for the TEXTURE operand d, `given` the fill slot's value */
static inline double sl_tex_fill(int d, int ch, double given)
{
    return (d & SL_TEXOP_FILL) ? given : sl_tex_default_fill(ch);
}

/* The error of a channel that varies over the range of a run. */
sl_status sl_vm_texture_channel_error(sl_vm *vm, int pc);

/* The next random number in [0, 1) of this run (splitmix64). */
double sl_vm_random(sl_vm *vm);

const char *sl_mode_name(sl_mode mode);
/* The message of this scope, name and size (0: a string), or NULL. */
const vm_message *sl_vm_message(const sl_vm *vm, int scope, const char *name, int size);

/* Whether clamp(x, lo, hi) is to [-1, 1], the clamp normalize() puts on
 * each component of a unit vector (codegen_builtin.c, gen_normalize):
 * there it only cuts the arithmetic's overshoot (a component of a flat
 * base's N that is -1 up to rounding), so the range modes give it no
 * AA_KINK (a shader's own clamp to [-1, 1] loses the flag too; only the
 * renderer's leaf starts read it: intersect.c, leaf_start) */
static inline bool sl_unit_clamp(double lo, double hi)
{
    return lo == -1.0 && hi == 1.0;
}

/* a op b (op: SL_OP_ADD/SUB/MUL/DIV/MOD) when the double result is EXACT, so
 * that interval and affine runs keep integer counters and octave
 * frequencies as points instead of widening them by a rounding error
 * (which would leave `i < 5` undecided, or mod(2, 1) straddle its jump).
 * TwoSum for sums, fma for products and quotients; results near underflow
 * are refused. */
static inline bool sl_exact_op(int op, double a, double b, double *r)
{
    double s;
    if (op == SL_OP_ADD || op == SL_OP_SUB) {
        if (op == SL_OP_SUB)
            b = -b;
        s = a + b;
        double bb = s - a;
        if (!isfinite(s) || (a - (s - bb)) + (b - bb) != 0.0)
            return false;
    } else if (op == SL_OP_MUL) {
        s = a * b;
        if (!isfinite(s) || (fabs(s) < 0x1p-900 && a != 0.0 && b != 0.0) ||
            fma(a, b, -s) != 0.0)
            return false;
    } else if (op == SL_OP_MOD) {
        /* RenderMan mod(a, b) = a - b floor(a/b), as vm_float.c computes it:
         * fmod is exact; the sign correction r + b must be exact too */
        if (b == 0.0 || !isfinite(a) || !isfinite(b))
            return false;
        s = fmod(a, b);
        if (s != 0 && ((s < 0) != (b < 0)))
            return sl_exact_op(SL_OP_ADD, s, b, r);
    } else {
        if (b == 0.0)
            return false;
        s = a / b;
        if (!isfinite(s) || (fabs(s) < 0x1p-900 && a != 0.0) || fma(s, b, -a) != 0.0)
            return false;
    }
    *r = s;
    return true;
}

#endif
