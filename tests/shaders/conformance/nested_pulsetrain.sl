/* nested functions: patterns.h's filteredpulsetrain, whose nested integral
 * reads a local of the enclosing function through extern */
#include "patterns.h"

displacement nested_pulsetrain(float freq = 4, width = 0.03)
{
    P = point(filteredpulsetrain(0.5, 1, s * freq, width),
              filteredpulsetrain(0.25, 0.5, t * 2, width * 4), 0);
}
