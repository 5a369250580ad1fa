/*
 * tests/tex/test_tex_asserts.c: common/tex's invariants are live (the death
 * test CONTRIBUTING.md asks of every module with invariants): a tile pool
 * destroyed while a texture opened with it still holds loaded tiles trips
 * tex_tiles_destroy's assert (tiles.c: "every texture opened with it is
 * gone"), so a build that compiled its asserts away fails here.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "death.h"
#include "tex/tex.h"

static char path[300];

/* An aafarm-maketx file of 300 x 300 texels: its level 0 is read in tiles. */
static int setup(void **state)
{
    (void)state;
    snprintf(path, sizeof path, "/tmp/test_tex_asserts.%ld.exr", (long)getpid());
    enum { W = 300, H = 300 };
    float *px = malloc(sizeof(float) * W * H);
    for (int k = 0; k < W * H; k++)
        px[k] = (float)(k % 97) / 97.0f;
    tex_texture *t = tex_from_pixels(px, W, H, 1, "ramp");
    free(px);
    char err[1024];
    bool ok = t && tex_write_exr(path, t, true, err, sizeof err);
    tex_destroy(&t);
    return ok ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    unlink(path);
    return 0;
}

/* Loads a tile into a pool, then destroys the pool before the texture. */
static void destroy_pool_with_tiles(void *arg)
{
    (void)arg;
    char err[1024];
    tex_tiles *pool = tex_tiles_new(0);
    tex_texture *t = tex_open_in(path, pool, err, sizeof err);
    if (!t || tex_tiled_levels(t) == 0) {
        fprintf(stderr, "no tiled texture: %s\n", t ? "all in memory" : err);
        exit(1);
    }
    (void)tex_texel(t, 0, 0, 10, 10);      /* level 0's tile (0, 0) is loaded */
    tex_tiles_destroy(&pool);
}

static void test_pool_outliving_its_tiles(void **state)
{
    (void)state;
    assert_death(destroy_pool_with_tiles, NULL, "pool->n == 0");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pool_outliving_its_tiles),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
