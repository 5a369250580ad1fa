/*
 * tests/tex/test_tex_cache.c: the per-process texture cache and the
 * search-path resolver (common/tex/cache.c).
 *
 *  - 8 threads asking at once for two maps (and a missing one) get one
 *    copy of each: the same pointer everywhere, the cache's bytes those of
 *    the two textures once; the missing name fails in every thread with
 *    the resolver's reason;
 *  - the byte budget: a texture that would pass it is refused with a
 *    message naming the budget, and nothing is kept;
 *  - the resolver: folders of the path in order (relative ones from the
 *    base folder, absolute ones as they are), "&" and "@" the base folder,
 *    the base folder last, absolute names as they are; a name found
 *    nowhere gives a reason that names the path and the Option to add.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tex/tex.h"

static char dir[200];
static tex_searchpath sp;

static void write_map(const char *rel, int w, int h)
{
    float *px = malloc((size_t)w * h * sizeof *px);
    for (int k = 0; k < w * h; k++)
        px[k] = (float)k;
    tex_texture *t = tex_from_pixels(px, w, h, 1, rel);
    char path[400], err[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    assert_true(tex_write_exr(path, t, false, err, sizeof err));
    tex_destroy(&t);
    free(px);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/test_tex_cache.XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    char path[300];
    snprintf(path, sizeof path, "%s/a", dir);
    mkdir(path, 0700);
    snprintf(path, sizeof path, "%s/b", dir);
    mkdir(path, 0700);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

typedef struct job {
    tex_cache *cache;
    const tex_texture *got[3];
    int failures;
    char why[512];
} job;

static void *worker(void *arg)
{
    job *j = arg;
    static const char *const names[3] = { "one.exr", "two.exr", "none.exr" };
    for (int k = 0; k < 300; k++) {
        char err[512];
        int n = (k * 7) % 3;
        const tex_texture *t = tex_cache_get(j->cache, names[n], err, sizeof err);
        if (n == 2) {
            j->failures += t == NULL;
            snprintf(j->why, sizeof j->why, "%s", err);
        } else if (!j->got[n]) {
            j->got[n] = t;
        } else if (j->got[n] != t) {
            j->got[n] = NULL;            /* two copies: caught below */
            j->failures += 1000;
        }
    }
    return NULL;
}

static void test_one_copy_per_process(void **state)
{
    (void)state;
    write_map("a/one.exr", 40, 30);
    write_map("b/two.exr", 17, 9);
    snprintf(sp.path, sizeof sp.path, "a:b");
    snprintf(sp.base, sizeof sp.base, "%s", dir);
    tex_cache *cache = tex_cache_new(0);
    tex_cache_set_resolver(cache, tex_searchpath_resolve, &sp);
    job jobs[8];
    pthread_t th[8];
    for (int i = 0; i < 8; i++) {
        memset(&jobs[i], 0, sizeof jobs[i]);
        jobs[i].cache = cache;
        assert_int_equal(pthread_create(&th[i], NULL, worker, &jobs[i]), 0);
    }
    for (int i = 0; i < 8; i++)
        assert_int_equal(pthread_join(th[i], NULL), 0);
    for (int i = 0; i < 8; i++) {
        assert_int_equal(jobs[i].failures, 100);          /* every missing lookup */
        assert_non_null(jobs[i].got[0]);
        assert_non_null(jobs[i].got[1]);
        assert_ptr_equal(jobs[i].got[0], jobs[0].got[0]);
        assert_ptr_equal(jobs[i].got[1], jobs[0].got[1]);
        assert_non_null(strstr(jobs[i].why, "texture 'none.exr': not found"));
    }
    assert_int_equal(tex_width(jobs[0].got[0]), 40);
    assert_int_equal(tex_width(jobs[0].got[1]), 17);
    assert_int_equal(tex_cache_bytes(cache),
                     tex_bytes(jobs[0].got[0]) + tex_bytes(jobs[0].got[1]));
    tex_cache_destroy(&cache);
}

static void test_budget(void **state)
{
    (void)state;
    write_map("a/one.exr", 40, 30);
    write_map("b/two.exr", 17, 9);
    snprintf(sp.path, sizeof sp.path, "a:b");
    snprintf(sp.base, sizeof sp.base, "%s", dir);
    char err[512], path[400];
    snprintf(path, sizeof path, "%s/a/one.exr", dir);
    tex_texture *one = tex_open(path, err, sizeof err);
    assert_non_null(one);
    tex_cache *cache = tex_cache_new(tex_bytes(one) + 100);    /* one.exr fits, not both */
    tex_destroy(&one);
    tex_cache_set_resolver(cache, tex_searchpath_resolve, &sp);
    assert_non_null(tex_cache_get(cache, "one.exr", err, sizeof err));
    size_t before = tex_cache_bytes(cache);
    assert_null(tex_cache_get(cache, "two.exr", err, sizeof err));
    if (!strstr(err, "over the budget of"))
        fail_msg("message: %s", err);
    assert_int_equal(tex_cache_bytes(cache), before);
    tex_cache_destroy(&cache);
}

static void test_resolver(void **state)
{
    (void)state;
    write_map("a/x.exr", 2, 2);
    write_map("b/x.exr", 3, 3);
    write_map("y.exr", 4, 4);
    char path[4096], why[512], want[400];
    snprintf(sp.base, sizeof sp.base, "%s", dir);
    snprintf(sp.path, sizeof sp.path, "b:a");                 /* in order */
    assert_true(tex_searchpath_resolve(&sp, "x.exr", path, sizeof path, why, sizeof why));
    snprintf(want, sizeof want, "%s/b/x.exr", dir);
    assert_string_equal(path, want);
    snprintf(sp.path, sizeof sp.path, "%s/a:b", dir);         /* absolute folder */
    assert_true(tex_searchpath_resolve(&sp, "x.exr", path, sizeof path, why, sizeof why));
    snprintf(want, sizeof want, "%s/a/x.exr", dir);
    assert_string_equal(path, want);
    snprintf(sp.path, sizeof sp.path, "nowhere:&");           /* & and @: the base */
    assert_true(tex_searchpath_resolve(&sp, "y.exr", path, sizeof path, why, sizeof why));
    snprintf(want, sizeof want, "%s/y.exr", dir);
    assert_string_equal(path, want);
    snprintf(sp.path, sizeof sp.path, "@");
    assert_true(tex_searchpath_resolve(&sp, "a/x.exr", path, sizeof path, why, sizeof why));
    snprintf(sp.path, sizeof sp.path, "%s", "");              /* the base folder last */
    assert_true(tex_searchpath_resolve(&sp, "y.exr", path, sizeof path, why, sizeof why));
    snprintf(want, sizeof want, "%s/b/x.exr", dir);           /* absolute names */
    assert_true(tex_searchpath_resolve(&sp, want, path, sizeof path, why, sizeof why));
    assert_string_equal(path, want);
    snprintf(sp.path, sizeof sp.path, "a:b");
    assert_false(tex_searchpath_resolve(&sp, "z.exr", path, sizeof path, why, sizeof why));
    if (!strstr(why, "\"a:b\"") || !strstr(why, "Option \"searchpath\" \"texture\""))
        fail_msg("reason: %s", why);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_copy_per_process),
        cmocka_unit_test(test_budget),
        cmocka_unit_test(test_resolver),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
