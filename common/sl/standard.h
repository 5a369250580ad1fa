/*
 * standard.h: the RI Specification 3.2's standard shaders, built into
 * every program (constant, matte, metal, shinymetal, plastic,
 * paintedplastic, bumpy). Their SL texts live in common/sl/standard/NAME.sl;
 * the build embeds them as C arrays (standard/embed.cmake), so they need no
 * folder at run time.
 *
 * A scene finds a shader on its search path first; a name found nowhere
 * there that is a standard shader's gets the built-in text (job_load), which
 * then travels in the job like any other source, under the name
 * "<standard>/NAME.sl" (SL_STANDARD_DIR): diagnostics point there, and a
 * worker needs nothing of its own. A user's plastic.sl on the path wins.
 */
#ifndef SL_STANDARD_H
#define SL_STANDARD_H

#include <stddef.h>

#define SL_STANDARD_DIR "<standard>"

typedef struct sl_standard_shader {
    const char *name;   /* "plastic": the name a RIB calls it by */
    const char *text;   /* its SL source, NUL-terminated */
    size_t len;         /* bytes of text, without the NUL */
} sl_standard_shader;

/* The table, in file name order (generated at build time). */
extern const sl_standard_shader sl_standard_shaders[];
extern const int sl_standard_nshaders;

/* The standard shader called `name`, or NULL. */
const sl_standard_shader *sl_standard_find(const char *name);

#endif
