/*
 * tests/fuzz/fuzz_sl.c: fuzz target for the shading-language compiler
 * (common/sl: preprocessor, parser, checker, code generator) plus a short
 * run of the virtual machine. The input is the text of main.sl; #include
 * finds nothing else. When it compiles, the shader runs once in float mode
 * and once in interval mode (Heidrich & Seidel 1998 §4) on a plane, with an
 * instruction budget of 20,000, so an endless loop ends as SL_ERR_BUDGET.
 * Checked: a program comes back exactly when no error was reported, every
 * diagnostic has a message, a failed run says why, and the instructions
 * counted stay within the budget.
 */
#include <string.h>

#include "aa/interval.h"
#include "fuzz_target.h"
#include "fuzz_nest.h"
#include "sl/diag.h"
#include "sl/shader.h"
#include "sl/source.h"

enum { FUZZ_BUDGET = 20000 };

static void globals_float(sl_vm *vm)
{
    const double P[3] = { 0.3, 0.5, 1 }, N[3] = { 0, 0, -1 }, du[3] = { 1, 0, 0 },
                 dv[3] = { 0, 1, 0 }, one[3] = { 1, 1, 1 }, I[3] = { 0, 0, 1 };
    const double u = 0.3, v = 0.5;
    sl_vm_clear_globals(vm);
    sl_vm_set_float(vm, SL_G_P, P);
    sl_vm_set_float(vm, SL_G_N, N);
    sl_vm_set_float(vm, SL_G_Ng, N);
    sl_vm_set_float(vm, SL_G_dPdu, du);
    sl_vm_set_float(vm, SL_G_dPdv, dv);
    sl_vm_set_float(vm, SL_G_I, I);
    sl_vm_set_float(vm, SL_G_Cs, one);
    sl_vm_set_float(vm, SL_G_Os, one);
    sl_vm_set_float(vm, SL_G_u, &u);
    sl_vm_set_float(vm, SL_G_v, &v);
    sl_vm_set_float(vm, SL_G_s, &u);
    sl_vm_set_float(vm, SL_G_t, &v);
}

static void globals_interval(sl_vm *vm)
{
    const ia_interval u = ia_make(0.25, 0.375), v = ia_make(0.5, 0.625);
    const ia_interval P[3] = { u, v, ia_make(1, 1) };
    const ia_interval N[3] = { ia_make(0, 0), ia_make(0, 0), ia_make(-1, -1) };
    const ia_interval du[3] = { ia_make(1, 1), ia_make(0, 0), ia_make(0, 0) };
    const ia_interval dv[3] = { ia_make(0, 0), ia_make(1, 1), ia_make(0, 0) };
    sl_vm_clear_globals(vm);
    sl_vm_set_interval(vm, SL_G_P, P);
    sl_vm_set_interval(vm, SL_G_N, N);
    sl_vm_set_interval(vm, SL_G_Ng, N);
    sl_vm_set_interval(vm, SL_G_dPdu, du);
    sl_vm_set_interval(vm, SL_G_dPdv, dv);
    sl_vm_set_interval(vm, SL_G_u, &u);
    sl_vm_set_interval(vm, SL_G_v, &v);
    sl_vm_set_interval(vm, SL_G_s, &u);
    sl_vm_set_interval(vm, SL_G_t, &v);
}

static void run(sl_vm *vm, const sl_instance *inst, sl_mode mode)
{
    sl_status st = sl_vm_run(vm, inst, mode, NULL);
    fuzz_check(st == SL_OK || st == SL_ERR_BUDGET || st == SL_ERR_LOOP_CAP ||
               st == SL_ERR_RUNTIME);
    if (st != SL_OK) {
        const char *why = sl_vm_error(vm);
        fuzz_check(why != NULL && why[0] != '\0');
    }
    fuzz_check(sl_vm_instructions(vm) <= FUZZ_BUDGET + 1);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_source_set *set = sl_source_set_new();
    sl_diag *diag = sl_diag_new();
    sl_program *p = NULL;
    if (sl_source_set_add(set, "main.sl", (const char *)data, size) == 0)
        p = sl_compile(set, "main.sl", NULL, NULL, diag);
    else
        fuzz_check(size > sl_source_set_max_size(set));
    fuzz_check((p != NULL) == (sl_diag_error_count(diag) == 0) || size > sl_source_set_max_size(set));
    for (size_t i = 0; i < sl_diag_count(diag); i++)
        fuzz_check(sl_diag_get(diag, i)->message != NULL);
    if (p) {
        sl_instance *inst = sl_instance_new(p);
        sl_limits limits = { .max_instructions = FUZZ_BUDGET, .max_loop_iterations = 16 };
        sl_vm *vm = sl_vm_new(&limits);
        globals_float(vm);
        run(vm, inst, SL_MODE_FLOAT);
        globals_interval(vm);
        run(vm, inst, SL_MODE_INTERVAL);
        sl_vm_destroy(&vm);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return 0;
}
