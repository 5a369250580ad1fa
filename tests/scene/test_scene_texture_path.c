/*
 * tests/scene/test_scene_texture_path.c: Option "searchpath" "texture"
 * (docs/scenes.md, docs/textures.md): the scene keeps the texture path as
 * its folders, "&" replaced by the previous ones and "@" (the standard
 * path) by none, the RIB's folder last; a path that "&" would blow up past
 * 2048 folders is an error at the Option's line, not an allocation of
 * gigabytes.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "scene_testing.h"

static void test_path_kept(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(CAMERA "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n", &d);
    assert_non_null(s);
    int base = s->ntexture_path;           /* without the Option: the RIB's folder */
    assert_true(base >= 1);
    char *rib_folder = strdup(s->texture_path[base - 1]);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    s = parse_rib("Option \"searchpath\" \"texture\" [\"maps\"]\n"
                  "Option \"searchpath\" \"texture\" [\"/abs/tex:&:@\"]\n" CAMERA
                  "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n", &d);
    assert_non_null(s);
    assert_int_equal(sl_diag_error_count(d), 0);
    assert_int_equal(s->ntexture_path, base + 2);
    assert_string_equal(s->texture_path[0], "/abs/tex");
    assert_true(strstr(s->texture_path[1], "maps") != NULL);   /* relative to the RIB's folder */
    assert_string_equal(s->texture_path[base + 1], rib_folder);
    free(rib_folder);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_path_too_long(void **state)
{
    (void)state;
    char rib[8192] = "Option \"searchpath\" \"texture\" [\"0123456789012345678901234567890\"]\n";
    for (int k = 0; k < 20; k++)
        strcat(rib, "Option \"searchpath\" \"texture\" [\"&:&\"]\n");
    strcat(rib, CAMERA "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n");
    sl_diag *d;
    scene *s = parse_rib(rib, &d);
    assert_null(s);
    const char *line = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
    if (!strstr(line, "the texture search path would have") || !strstr(line, "t.rib:13:1: Option:"))
        fail_msg("message: [%s]", line);
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_path_kept),
        cmocka_unit_test(test_path_too_long),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
