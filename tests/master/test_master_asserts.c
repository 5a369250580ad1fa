/*
 * tests/master/test_master_asserts.c: the master's asserts are live
 * (CONTRIBUTING.md, "Invariants"). The scheduler's entry points that
 * resolve a lease take a worker slot that scheduler_worker_add returned;
 * one that was never added is a bug of the master, and the assert stops
 * it before it counts a result against another worker's slot. The
 * journal takes only tiles of its own grid (a record its resume would call
 * corrupt would drop every tile after it); the registry holds one live
 * worker per routing id (the old one is retired first). A build that
 * compiled its asserts away fails here.
 *
 * No thread is started in this process (death_run forks).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "death.h"
#include "journal.h"
#include "registry.h"
#include "scheduler.h"

static void complete_for_unknown_slot(void *arg)
{
    (void)arg;
    scheduler *s = scheduler_new(2, 2, NULL);
    scheduler_complete(s, 3, 1, 0);   /* no worker was ever added */
    scheduler_destroy(&s);
}

static void test_scheduler_slot_assert(void **state)
{
    (void)state;
    assert_death(complete_for_unknown_slot, NULL, "worker < self->nworkers");
}

/* arg: the journal's path */
static void append_outside_the_grid(void *arg)
{
    journal_id id = {.width = 64, .height = 64, .tile_size = 32, .layers = 1, .tiles = 4};
    memset(id.job_hash, 'a', 64);
    char err[1024];
    bool replaced;
    journal *j = journal_create(arg, &id, &replaced, err, sizeof err);
    if (!j) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    journal_append(j, 4, "chunk", 5, 0, err, sizeof err);   /* tiles 0..3 only */
    journal_close(&j);
}

static void test_journal_grid_assert(void **state)
{
    (void)state;
    char dir[] = "/tmp/aafarm-master-asserts-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[sizeof dir + 16];
    snprintf(path, sizeof path, "%s/x.journal", dir);
    assert_death(append_outside_the_grid, path, "(uint32_t)tile < self->tiles");
    unlink(path);
    rmdir(dir);
}

static void add_the_same_worker_twice(void *arg)
{
    (void)arg;
    registry *r = registry_new();
    const uint8_t id[] = {0, 0x80, 0, 0, 1};
    registry_add(r, id, sizeof id, 0);
    registry_add(r, id, sizeof id, 1);   /* the first was never retired */
    registry_destroy(&r);
}

static void test_registry_live_id_assert(void **state)
{
    (void)state;
    assert_death(add_the_same_worker_twice, NULL, "registry_find(self, id, id_len) == NULL");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scheduler_slot_assert),
        cmocka_unit_test(test_journal_grid_assert),
        cmocka_unit_test(test_registry_live_id_assert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
