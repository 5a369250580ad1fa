/*
 * tests/image/test_image_asserts.c: common/image's invariants are live
 * (the death test CONTRIBUTING.md asks of every module with invariants): a
 * tile whose N layer lost its buffer trips image_tile_clear_nonfinite's
 * assert that a tile has the buffers of its layers (tile.c), so a build
 * that compiled its asserts away fails here.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdlib.h>

#include "death.h"
#include "image/tile.h"

static void tile_without_its_normals(void *arg)
{
    (void)arg;
    image_tile *t = image_tile_new(0, 0, 4, 4, IMAGE_LAYER_N);
    free(t->n);
    t->n = NULL;                            /* layers say N, the buffer is gone */
    int x, y;
    image_tile_clear_nonfinite(t, &x, &y);
}

static void test_tile_buffers_follow_layers(void **state)
{
    (void)state;
    assert_death(tile_without_its_normals, NULL, "IMAGE_LAYER_N");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tile_buffers_follow_layers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
