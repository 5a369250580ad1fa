/* noises.h: turbulence with a nested per-octave helper, as a displacement */
#include "noises.h"

displacement noises_turbulence()
{
    float amp = turbulence(point(s, t, 0.5) * 2, 3);
    P += amp * normalize(N);
}
