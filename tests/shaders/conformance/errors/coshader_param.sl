/* a list of co-shaders as a parameter, called by method: one error, at the
 * first co-shader construct, not one per use */
displacement coshader_param(shader layers[] = {}; float Km = 0.1)
{
    uniform float i;
    float h = 0;
    for (i = 0; i < arraylength(layers); i += 1)
        h += layers[i]->height(s, t);
    P += Km * h * normalize(N);
}
