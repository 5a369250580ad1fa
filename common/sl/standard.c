/*
 * standard.c: looking up the built-in standard shaders (see standard.h;
 * the table itself is generated from common/sl/standard/NAME.sl).
 */
#include "sl/standard.h"

#include <string.h>

const sl_standard_shader *sl_standard_find(const char *name)
{
    for (int i = 0; i < sl_standard_nshaders; i++)
        if (strcmp(sl_standard_shaders[i].name, name) == 0) return &sl_standard_shaders[i];
    return NULL;
}
