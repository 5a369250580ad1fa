/*
 * tests/fuzz/fuzz_rib.c: fuzz target for the RIB parser (common/scene).
 * The input is a RIB text, parsed from memory with no archives (ReadArchive
 * finds nothing, so no file is touched) and a small object limit. Checked:
 * a scene comes back exactly when no error was reported, every diagnostic
 * has a message, and a scene's object count is within the limit.
 */
#include "fuzz_target.h"
#include "fuzz_nest.h"
#include "scene/scene.h"

enum { FUZZ_MAX_OBJECTS = 4096 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sl_diag *diag = sl_diag_new();
    scene *s = scene_parse_limited("fuzz.rib", (const char *)data, size, NULL,
                                   FUZZ_MAX_OBJECTS, diag);
    int errors = sl_diag_error_count(diag);
    fuzz_check((s != NULL) == (errors == 0));
    for (size_t i = 0; i < sl_diag_count(diag); i++)
        fuzz_check(sl_diag_get(diag, i)->message != NULL);
    if (s) {
        fuzz_check(s->nobjects >= 0 && s->nobjects <= FUZZ_MAX_OBJECTS);
        scene_destroy(&s);
    }
    sl_diag_destroy(&diag);
    return 0;
}
