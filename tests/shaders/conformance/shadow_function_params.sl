/* scopes: function parameters named s and t (patterns.h's tilecoord) */
#include "patterns.h"

displacement shadow_function_params(float freq = 3)
{
    P = point(tilecoord(t, s, freq), tilecoord(s + 0.1, t, 2), 0);
}
