/* nested functions: patterns.h's filteredabs defines its integral inside */
#include "patterns.h"

displacement nested_filteredabs(float width = 0.2)
{
    P = point(filteredabs(s - 0.5, width), filteredabs(t - 0.3, width / 2), 0);
}
