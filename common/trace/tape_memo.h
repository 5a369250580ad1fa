/*
 * tape_memo.h: the plans of tape pruning (common/sl/tape_plan.c) that a
 * rendering thread's box runs take, made once per program and tape and
 * kept in a per-thread memo (issue 24). A box's tape (box.h) holds the
 * decisions its affine run proved; its children's runs take the plan of
 * that tape (displace.c). See tape_memo.c.
 */
#ifndef TRACE_TAPE_MEMO_H
#define TRACE_TAPE_MEMO_H

#include <stdint.h>

#include "sl/shader.h"
#include "trace/thread.h"

/* The plan of program p for tape (sl_program_tape_plan), from th's memo
 * or made there; NULL where the tape decides nothing. Valid until the
 * next call on th. */
const uint8_t *trace_tape_plan(trace_thread *th, const sl_program *p, uint32_t tape);

/* th's memo, freed (trace_thread_destroy) */
void trace_tape_memo_free(trace_thread *th);

#endif
