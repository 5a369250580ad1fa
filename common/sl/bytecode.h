/*
 * bytecode.h: the compiled form of a shader (struct sl_program): a scalar
 * register machine's instructions, its constant pool, operand tables and
 * the layout of its slot file, plus the listing of aafarm-slc --dump.
 *
 * Register model (docs/shading-language.md, "Evaluation"): every scalar is
 * one slot of the slot file; point/vector/normal/color take 3 consecutive
 * slots, matrix 16. A slot holds a double, an sl_dual, an ia_interval or
 * an aa_form depending on the mode of the run; the same bytecode serves
 * all four. Strings live in a separate, mode-independent string file (one
 * `const char *` per string slot). The code generator lowers all vector
 * work to scalar operations, so a backend implements scalar operations
 * only, plus a few special ones (noise, derivatives, lights, transforms).
 *
 * Slot file layout:
 *   [0, SL_GLOBAL_SLOTS)           the renderer's globals (P, N, ...), at
 *                                  fixed offsets (sl_global_slot)
 *   [const_base, +nconsts)         the constant pool, loaded per run
 *   [...,  nslots)                 parameters, variables, temporaries
 *
 * Booleans (comparisons, && || !) are slots too: 0 and 1 in float/dual
 * mode; in interval/affine mode an enclosure of {0}, {1} or {0, 1} (the
 * "maybe" of paper §4.1). A branch tests lo > 0.5 (true), hi < 0.5 (false).
 *
 * Instruction: an opcode and up to four 16-bit operands (slots, string
 * slots, jump targets, table indexes or small immediates, per opcode).
 * Programs are limited to SL_MAX_CODE instructions and SL_MAX_SLOTS slots.
 */
#ifndef SL_BYTECODE_H
#define SL_BYTECODE_H

#include <stdint.h>
#include <stdio.h>

#include "sl/shader.h"

enum {
    SL_MAX_SLOTS = 4096,          /* scalar slots per program */
    SL_MAX_STRING_SLOTS = 1024,   /* string slots per program */
    SL_MAX_CODE = 65535,          /* instructions per program */
    SL_GLOBAL_SLOTS = 46,         /* slots of the globals, below */
};

/* Operand kinds for the listing: z/x = slot (written/read), s = string
 * slot, j = jump target, t = table, k = immediate, p = parameter, n =
 * noise variant, - = unused. */
#define SL_OPCODES(X)                                            \
    X(END, "end", "----")                                        \
    X(MOV, "mov", "zx--") X(MOVN, "movn", "zxk-")                \
    X(ADD, "add", "zxx-") X(SUB, "sub", "zxx-")                  \
    X(MUL, "mul", "zxx-") X(DIV, "div", "zxx-")                  \
    X(NEG, "neg", "zx--")                                        \
    X(SQRT, "sqrt", "zx--") X(INVSQRT, "invsqrt", "zx--")        \
    X(EXP, "exp", "zx--") X(LOG, "log", "zx--")                  \
    X(SIN, "sin", "zx--") X(COS, "cos", "zx--")                  \
    X(TAN, "tan", "zx--") X(ASIN, "asin", "zx--")                \
    X(ACOS, "acos", "zx--") X(ATAN, "atan", "zx--")              \
    X(ABS, "abs", "zx--") X(SIGN, "sign", "zx--")                \
    X(FLOOR, "floor", "zx--") X(CEIL, "ceil", "zx--")            \
    X(ROUND, "round", "zx--")                                    \
    X(POW, "pow", "zxx-") X(ATAN2, "atan2", "zxx-")              \
    X(MOD, "mod", "zxx-") X(MIN, "min", "zxx-")                  \
    X(MAX, "max", "zxx-") X(STEP, "step", "zxx-")                \
    X(CLAMP, "clamp", "zxxx") X(SMOOTHSTEP, "smoothstep", "zxxx")\
    X(MIX, "mix", "zxxx")                                        \
    X(LT, "lt", "zxx-") X(LE, "le", "zxx-") X(GT, "gt", "zxx-")  \
    X(GE, "ge", "zxx-") X(EQ, "eq", "zxx-") X(NE, "ne", "zxx-")  \
    X(AND, "and", "zxx-") X(OR, "or", "zxx-") X(NOT, "not", "zx--") \
    X(SEQ, "seq", "zss-") X(SNE, "sne", "zss-")                  \
    X(SMOV, "smov", "ss--")                                      \
    X(NOISE, "noise", "zxnx") X(RANDOM, "random", "zk--")        \
    X(DU, "du", "zx--") X(DV, "dv", "zx--")                      \
    X(DERIV, "deriv", "zxx-")                                    \
    X(CALCNORMAL, "calcnormal", "zx--") X(AREA, "area", "zx--")  \
    X(AMBIENT, "ambient", "z---") X(DIFFUSE, "diffuse", "zx--")  \
    X(SPECULAR, "specular", "zxxx") X(PHONG, "phong", "zxxx")    \
    X(SPACE, "space", "zsk-") X(SPACEK, "spacek", "zkk-")        \
    X(XPOINT, "xpoint", "zxx-") X(XVECTOR, "xvector", "zxx-")    \
    X(XNORMAL, "xnormal", "zxx-") X(MINVERT, "minvert", "zx--")  \
    X(COMP, "comp", "zxx-") X(SETCOMP, "setcomp", "zxx-")        \
    X(JMP, "jmp", "j---")                                        \
    X(BR_BEGIN, "br.begin", "xjt-") X(BR_ELSE, "br.else", "jk--") \
    X(BR_END, "br.end", "kt--")                                  \
    X(LOOP_TEST, "loop.test", "xjt-") X(LOOP_END, "loop.end", "kt--") \
    X(PARAM, "param", "zpjx") X(SPARAM, "sparam", "spjs")        \
    X(ESCAPE, "escape", "zktk") X(ACCUM_END, "accum.end", "kt-k") \
    X(ALOAD, "aload", "zxxk") X(ASTORE, "astore", "zxxk")        \
    X(LSTART, "lstart", "----") X(LNEXT, "lnext", "z---")          \
    X(MESSAGE, "message", "zskk")                                \
    X(SCAT, "scat", "sss-") X(SFMT, "sfmt", "sxsk")              \
    X(SPRINT, "sprint", "s---") X(SMATCH, "smatch", "zss-")      \
    X(RAY, "ray", "zxxk")                                        \
    X(TEXTURE, "texture", "zsxk") X(TEXINFO, "texinfo", "zsxk")

typedef enum sl_opcode {
#define SL_OPCODE_ENUM(name, text, operands) SL_OP_##name,
    SL_OPCODES(SL_OPCODE_ENUM)
#undef SL_OPCODE_ENUM
    SL_OP__COUNT
} sl_opcode;

const char *sl_opcode_name(sl_opcode op);
/* The operand kinds of op, four letters as in SL_OPCODES ("zxx-"). */
const char *sl_opcode_operands(sl_opcode op);
/* How many slots past its first a slot operand of op may reach (0 for the
 * scalar operations; conservative for the rest: sl_program_reads_global). */
int sl_operand_reach(sl_opcode op);

/* ALOAD z, base, index, d / ASTORE base, index, value, d: one lane of an
 * array element, z = base[index * stride] / base[index * stride] = value,
 * the index rounded down; d = length | stride code << 12 (code 0, 1, 2:
 * stride 1, 3, 16). In interval/affine mode every element the index can
 * reach is read (merged) or written (merged with its old value). */
enum { SL_ARRAY_LEN_MASK = 0xfff, SL_ARRAY_STRIDE_SHIFT = 12 };
static inline int sl_array_stride(int d)
{
    int code = d >> SL_ARRAY_STRIDE_SHIFT;
    return code == 0 ? 1 : code == 1 ? 3 : 16;
}

/* RAY z, P, D, d: trace(P, D) (3 slots) or shadow(map, P) (1 slot), by
 * the renderer's tracer (shader.h, sl_tracer); d = kind | the string slot
 * of the map's name << 2. For shadow(), D is the L global: in a light
 * shader it points from the light to Ps (illuminate: the light is at
 * Ps - L; solar: L is its direction), in a surface shader's illuminance
 * loop from P towards the current light. */
enum {
    SL_RAY_TRACE = 0,
    SL_RAY_SHADOW_ILLUMINATE = 1,   /* light shader: towards Ps - L */
    SL_RAY_SHADOW_SOLAR = 2,        /* light shader: along -L to infinity */
    SL_RAY_SHADOW_SURFACE = 3,      /* surface shader: along L, the current light */
    SL_RAY_KIND_BITS = 2,
};

typedef struct sl_insn {
    uint8_t op;
    uint16_t a, b, c, d;
} sl_insn;

/* Where an instruction came from (for runtime errors and the listing). */
typedef struct sl_insn_pos {
    uint16_t file;     /* index into sl_program.files */
    uint16_t col;
    int line;
} sl_insn_pos;

/* Merge tables: tables[i] = number of positions, then one position per
 * slot written in the region; a string slot is tagged SL_TABLE_STRING; a
 * function's return slot is tagged SL_TABLE_GUARDED and followed by the
 * slot of its "returned" flag: where that flag is definitely 0 on one side
 * the return slot is dead there and the other side's value is taken. */
enum {
    SL_TABLE_STRING = 0x8000, SL_TABLE_GUARDED = 0x4000, SL_TABLE_DEATH = 0x2000,
    SL_TABLE_SLOT = 0x0fff,
};

/* break and return (paper §4.1 "dead paths"): ESCAPE flag, id, table, kind
 * sets the escape flag (a break or "returned" flag) and, in interval and
 * affine mode, first saves the merge table of the construct it leaves
 * (kind SL_ESCAPE_LOOP, id = the pc of its LOOP_TEST; kind SL_ESCAPE_FUNC,
 * id = the inlined call, 0 for the shader body) into that construct's
 * accumulator. From then on the path is dead: in the merge tables the flag
 * is tagged SL_TABLE_DEATH, and a side whose flag is definitely 1 is
 * dropped at BR_END. LOOP_END (loops) and ACCUM_END (functions) merge the
 * accumulator back. */
enum { SL_ESCAPE_LOOP = 0, SL_ESCAPE_FUNC = 1 };

/* MESSAGE flag, name, var, d (message passing, shader.h): d = scope | size
 * << 4 (size 0: var is a string slot, else var's numeric slots). */

/* Strings (RI Spec 3.2 §15.6): SCAT z, a, b concatenates; SFMT z, x, spec,
 * size formats size numbers from slot x with the C conversion spec (checked
 * when compiling: flags, width, precision, one of f e g or lld), a range
 * as "[lo hi]"; SPRINT s hands a line to the VM's print callback (float
 * mode only, at most SL_VM_MAX_PRINTS lines per VM); SMATCH z, pattern,
 * subject is match().
 * Results live in the VM's string space, reset at each run. */

/* illuminance loops (RI Spec 3.2 §15.4): LSTART takes the non-ambient
 * light samples of this mode at P; each LNEXT z loads the next one into the
 * globals L and Cl and sets z to 1, or sets z to 0 after the last. */

/* NOISE variant (operand c): dimension in bits 0-2, kind in bits 3-4,
 * three outputs (point/vector/color noise) in bit 5. */
enum {
    SL_NOISE_PLAIN = 0, SL_NOISE_PERIODIC = 1, SL_NOISE_CELL = 2,
    SL_NOISE_VECTOR = 1 << 5,
};
#define SL_NOISE_VARIANT(dim, kind, vec) ((dim) | ((kind) << 3) | ((vec) ? SL_NOISE_VECTOR : 0))
#define SL_NOISE_DIM(v) ((v) & 7)
#define SL_NOISE_KIND(v) (((v) >> 3) & 3)

/* Textures (docs/textures.md): TEXTURE z, name, args, d looks texture
 * vm->str[name] up with the arguments in 6 consecutive slots from args: s,
 * t, the footprint widths ws and wt, the channel, the fill value; d packs
 * what it writes (SL_TEXOP_FLOAT: 1 slot, the filter of the channel;
 * SL_TEXOP_COLOR: 3, channels c..c+2; SL_TEXOP_GRAD: 2, d/ds and d/dt of
 * the channel), the wrap modes of s and t (tex_wrap) and SL_TEXOP_FILL.
 * TEXINFO z, name, var, query: z = 1 and var set when the texture opens
 * (query SL_TEXINFO_*, builtins.h: resolution writes 2 slots, channels and
 * levels 1, type none), else z = 0. */
enum { SL_TEXINFO_RESOLUTION, SL_TEXINFO_CHANNELS, SL_TEXINFO_LEVELS, SL_TEXINFO_TYPE };
enum { SL_TEXOP_FLOAT = 0, SL_TEXOP_COLOR = 1, SL_TEXOP_GRAD = 2 };
#define SL_TEXOP(kind, swrap, twrap) ((kind) | ((swrap) << 2) | ((twrap) << 4))
#define SL_TEXOP_KIND(d) ((d) & 3)
#define SL_TEXOP_SWRAP(d) (((d) >> 2) & 3)
#define SL_TEXOP_TWRAP(d) (((d) >> 4) & 3)
/* The shader gave "fill": a channel the texture lacks reads the fill slot;
 * without it, sl_tex_default_fill (vm_internal.h). */
#define SL_TEXOP_FILL (1 << 6)
static inline int sl_texop_outs(int d)
{
    return SL_TEXOP_KIND(d) == SL_TEXOP_COLOR ? 3 : SL_TEXOP_KIND(d) == SL_TEXOP_GRAD ? 2 : 1;
}

/* SPACE/SPACEK direction (operand c): the matrix that takes points from the
 * named space to "current", or the one from "current" to it. */
enum { SL_SPACE_TO_CURRENT = 0, SL_SPACE_FROM_CURRENT = 1 };

/* SPACEK's pseudo-space of depth(P): the matrix from "current" to camera
 * space with z mapped to (z - near) / (far - near) (sl_vm_set_clipping). */
enum { SL_SPACE_DEPTH = 15 };

typedef struct sl_param {
    char *name;
    sl_type type;
    bool output;
    int slot;          /* scalar slot, or string slot for strings */
    int size;          /* slots */
} sl_param;

struct sl_program {
    char *name;
    sl_shader_kind kind;
    unsigned long serial;           /* unique per compiled program */

    sl_insn *code;
    sl_insn_pos *pos;
    int ncode;

    double *consts;                 /* loaded into [const_base, +nconsts) */
    int nconsts, const_base;

    uint16_t *tables;               /* merge lists: count, then slots */
    int ntables;

    char **strings;                 /* string constants ... */
    int *string_slots;              /* ... and the string slots they load into */
    int nstrings;

    sl_param *params;
    int nparams;

    char **files;                   /* file names for positions */
    int nfiles;

    int nslots;                     /* scalar slots used */
    int nstring_slots;
    bool emits_light;               /* a light shader with illuminate or solar */
    bool has_outputs;               /* an output parameter (message passing:
                                       the renderer captures them at a hit) */
    bool takes_derivatives;         /* a DU, DV, DERIV, CALCNORMAL or AREA may
                                       flow into P: interval/affine runs carry
                                       derivative bounds (vm_deriv.inc) */
    uint8_t *box_plan;              /* per instruction, what a box run may
                                       leave out (SL_BOX_*, box_plan.c); NULL:
                                       nothing */
    uint8_t *slope_plan;            /* the same for a slope run, which also
                                       reads P's derivative bounds */
    int32_t *split_same;            /* per instruction, the earlier case
                                       split of the same value it must agree
                                       with, or -1 (split_plan.c); NULL:
                                       none */
    uint64_t global_slots;          /* bit s: a run may read or write global
                                       slot s (sl_program_global_slots); 0:
                                       not known, every slot */
    int32_t tape_site[SL_TAPE_SITES]; /* the pcs of the tape sites
                                       (tape_plan.c) */
    int ntape_sites;
    int8_t *tape_site_of;           /* per instruction, its site or -1; NULL:
                                       no site */
    uint64_t box_values, box_derivs; /* bit s: a box run may read global slot
                                       s's value, its derivative bounds
                                       (box_plan.c); every bit where the
                                       program has no plan */
};

/* Scalar slot of a global: P at 0, N at 3, ... (3 slots for points and
 * colors, 1 for s t u v du dv time). Inline: the renderer binds a dozen
 * globals before every shader evaluation (issue 24: the calls and the
 * copies of unknown size were 8 % of the wave's frame). */
extern const unsigned char sl_global_slot_table[SL_G__COUNT + 1];
static inline int sl_global_slot(sl_global g) { return sl_global_slot_table[g]; }
static inline int sl_global_size(sl_global g)
{
    return sl_global_slot_table[g + 1] - sl_global_slot_table[g];
}
const char *sl_global_name(sl_global g);

/* Can a derivative (Du, Dv, Deriv, calculatenormal, area) flow into P? A
 * conservative test on the bytecode: some derivative precedes a possible
 * write of P, or a jump leads back over the first derivative. When it
 * cannot (`N = calculatenormal(P)` after the last write of P, the common
 * case), range runs need no derivative bounds to bound P. */
bool sl_program_derivatives_reach_P(const sl_program *p);

/* The global slots a run of p may read or write, as bit s for slot s:
 * those of every global sl_program_reads_global names, u and v (a varying
 * parameter is evaluated from them), and all of them for a program with an
 * operation that reaches globals without naming them (lights, illuminance,
 * trace, message passing). The derivative-carrying runs copy only these
 * in and out of their own slot file (vm.c). */
uint64_t sl_program_global_slots(const sl_program *p);

/* What a box run (an affine or interval run read for P alone:
 * sl_vm_set_box_runs) may leave out of instruction pc (box_plan.c); with
 * slopes, a slope run's (P and its derivative bounds): */
enum {
    SL_BOX_RUN = 0,       /* run it as it is */
    SL_BOX_VALUE = 1,     /* its value only: no derivative bounds reach P
                             from what it writes (they are set to the
                             whole line) */
    SL_BOX_DEAD = 2,      /* nothing it writes reaches P: unbounded */
    /* tape pruning (tape_plan.c): what a node's run proved the
     * instruction does over the node, for its children's runs */
    SL_BOX_TAKE_B = 3,    /* z = operand b (min, max, clamp, mix: x) */
    SL_BOX_TAKE_C = 4,    /* z = operand c (min, max, mix: y; clamp: lo) */
    SL_BOX_TAKE_D = 5,    /* z = operand d (clamp: hi) */
    SL_BOX_ZERO = 6,      /* z = 0 (step, smoothstep) */
    SL_BOX_ONE = 7,       /* z = 1 (step, smoothstep) */
    SL_BOX_THEN = 8,      /* a branch (BR_BEGIN) into its then-part */
    SL_BOX_ELSE = 9,      /* a branch to its else-part */
};
/* How many slots from operand a an instruction that a box run may leave
 * out writes: a copy's n, a lookup's outputs, a normal's 3, a vector
 * noise's 3; 1 for the others */
static inline int sl_box_writes(const sl_insn *in)
{
    switch ((sl_opcode)in->op) {
    case SL_OP_MOVN: return in->c;
    case SL_OP_TEXTURE: return sl_texop_outs(in->d);
    case SL_OP_CALCNORMAL: return 3;
    case SL_OP_NOISE: return (in->c & SL_NOISE_VECTOR) ? 3 : 1;
    default: return 1;
    }
}
/* The plan of p (ncode bytes, freed with the program), or NULL where the
 * analysis does not apply (lights, trace, message passing, a program too
 * large to analyse): then every instruction runs. *values and *derivs
 * (each may be NULL) get the global slots whose values and derivative
 * bounds a box run may read (every bit without a plan). */
uint8_t *sl_program_box_plan(const sl_program *p, bool slopes, uint64_t *values,
                             uint64_t *derivs);
/* The same with decisions (box runs only; NULL: none): per instruction 0
 * or the SL_BOX_TAKE_B..SL_BOX_ELSE code it was proved to take; with
 * decisions a plan is made for programs that take no derivatives too.
 * The caller frees it. */
uint8_t *sl_program_plan(const sl_program *p, bool slopes, const uint8_t *decided,
                         uint64_t *values, uint64_t *derivs);

/* Tape pruning (tape_plan.c, issue 24; the tape: shader.h): the program's
 * tape sites, at most
 * SL_TAPE_SITES of its min, max, clamp, step, smoothstep, mix and branches,
 * chosen where deciding them leaves the most of the program dead; a
 * TAPE (uint32_t) holds SL_TAPE_BITS per site, site i at bits 2i:
 * 0 undecided, else the decision (sl_tape_code: 1 the first choice,
 * 2 the second, 3 a clamp's hi). Sets p->tape_site, p->ntape_sites and
 * p->tape_site_of. */
void sl_program_choose_tape_sites(sl_program *p);
/* The plan code of decision dec (1..3) of site instruction in, or 0 */
uint8_t sl_tape_code(const sl_insn *in, int dec);

/* Case splits that must agree (split_plan.c, issue 24): per instruction,
 * -1 or the pc of an earlier floor, ceil, round, mod or step of the same
 * opcode on the same operand slots, not written since, that every run
 * reaching this one executed just before on the same values (no jump
 * target and only plain operations between): a split run gives it that
 * operation's case (sl_vm_split_begin). ncode entries freed with the
 * program, or NULL where no operation has such a twin, or the program has
 * lights, illuminance, trace or message passing. */
int32_t *sl_program_split_same(const sl_program *p);

/* Asserts the invariants of a generated program (every slot, string slot,
 * jump and table operand inside the program's bounds, END last), once when
 * the code generator hands it out, so the VM's loop need not check them. */
void sl_program_assert_valid(const sl_program *p);

/* Source position of instruction pc as "file:line:col". */
void sl_program_pos_string(const sl_program *self, int pc, char *buf, size_t size);

#endif
