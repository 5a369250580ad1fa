/*
 * metal.sl: the RI Specification's standard metal surface, built into
 * aafarm: no diffuse term; the ambient light and a highlight of the given
 * roughness, both tinted by the surface colour.
 */
surface metal(float Ka = 1; float Ks = 1; float roughness = 0.1)
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * Cs * (Ka * ambient() + Ks * specular(Nf, V, roughness));
}
