/*
 * tape_memo.c: a rendering thread's memo of tape plans (tape_memo.h). A
 * plan is a pure function of its program and tape, so the memo changes
 * speed only: TAPE_MEMO_ENTRIES plans, looked up by (program, tape) in
 * turn, the least recently used one replaced on a miss; a plan the memo
 * lost is made again (a liveness over the program: common/sl/box_plan.c,
 * ~10^5 instructions, a few box runs' worth). A tape holds at most
 * SL_TAPE_SITES decisions, and the tapes a frame's boxes prove are few (a
 * plateau, a mask's two sides, their combinations), so the memo keeps
 * them all. (A direct-mapped table lost two plans that shared a slot in
 * turn, a plan per box run: measured on corpus mesa_clamp.)
 */
#include "trace/tape_memo.h"

#include <stdlib.h>

#include "util/xalloc.h"

enum { TAPE_MEMO_ENTRIES = 16 };

typedef struct tape_entry {
    const sl_program *prog;       /* NULL: empty */
    uint32_t tape;
    unsigned long used;           /* the memo's clock at the last use */
    uint8_t *plan;                /* owned; NULL: the tape decides nothing */
} tape_entry;

struct trace_tape_memo {
    tape_entry e[TAPE_MEMO_ENTRIES];
    unsigned long clock;
};

const uint8_t *trace_tape_plan(trace_thread *th, const sl_program *p, uint32_t tape)
{
    if (tape == 0)
        return NULL;
    if (!th->tapes)
        th->tapes = xcalloc(1, sizeof *th->tapes);
    struct trace_tape_memo *m = th->tapes;
    tape_entry *e = NULL, *oldest = &m->e[0];
    for (int i = 0; i < TAPE_MEMO_ENTRIES && !e; i++) {
        if (m->e[i].prog == p && m->e[i].tape == tape)
            e = &m->e[i];
        else if (m->e[i].used < oldest->used)
            oldest = &m->e[i];
    }
    if (!e) {
        e = oldest;
        free(e->plan);
        e->plan = sl_program_tape_plan(p, tape);
        e->prog = p;
        e->tape = tape;
        th->stats.tape_plans++;
    }
    e->used = ++m->clock;
    return e->plan;
}

void trace_tape_memo_free(trace_thread *th)
{
    if (!th->tapes)
        return;
    for (int i = 0; i < TAPE_MEMO_ENTRIES; i++)
        free(th->tapes->e[i].plan);
    free(th->tapes);
    th->tapes = NULL;
}
