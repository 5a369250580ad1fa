/*
 * fw_stripes.sl: raised stripes along s, antialiased the production way:
 * filterwidth(ss) (Du/Dv times du/dv) feeding filteredpulsetrain.
 * Idiom: filterwidth + filtered pulse train (issue 9, finding 2).
 */
#include "include/filterwidth.h"

displacement fw_stripes(float Km = 0.02, frequency = 8, duty = 0.4)
{
    float ss = s * frequency;
    float fw = filterwidth(ss);
    float h = filteredpulsetrain(duty, ss, fw);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
