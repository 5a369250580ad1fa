/*
 * tex_heightmap.sl: a height map along N, the displacement a sculpting
 * tool exports: h = texture(map, s, t) scaled and offset, its lookup
 * blurred by the filter width of s and t, a second "detail" lookup of the
 * same map tiled four times (issue 16).
 * Idiom: texture() with "blur" from filterwidth; layered maps.
 */
#include "include/filterwidth.h"

displacement tex_heightmap(float Km = 0.04, repeats = 2, detail = 0.25;
                           string mapname = "corpus_height.exr")
{
    float ss = s * repeats, tt = t * repeats;
    float fw = max(filterwidth(ss), filterwidth(tt));
    float h = texture(mapname, ss, tt, "blur", fw);
    h += detail * texture(mapname[0], ss * 4, tt * 4, "blur", 4 * fw);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
