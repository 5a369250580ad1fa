/*
 * dv_lines.sl: thin raised lines across t whose soft edges are dv wide,
 * faded out when dv is larger than the line spacing.
 * Idiom: the global dv as a filter width.
 */
#include "include/filterwidth.h"

displacement dv_lines(float Km = 0.02, frequency = 10, duty = 0.2)
{
    float tt = t * frequency;
    float w = max(dv * frequency, MINFILTWIDTH);
    float lines = filteredpulsetrain(duty, tt, w);
    lines = fadeout(lines, duty, 1, w);
    P += Km * lines * normalize(N);
    N = calculatenormal(P);
}
