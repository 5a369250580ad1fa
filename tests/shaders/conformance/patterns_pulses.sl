/* patterns.h: pulse (overloaded for a colour), filteredpulse, smoothpulse */
#include "patterns.h"

displacement patterns_pulses(float width = 0.05)
{
    color c = pulse(color(1, 2, 3), 0.3, 0.7, s);
    P = point(filteredpulse(0.3, 0.7, s, width), smoothpulse(0.1, 0.3, 0.6, 0.9, t),
              comp(c, 1));
}
