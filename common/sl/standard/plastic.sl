/*
 * plastic.sl: the RI Specification's standard plastic surface, built into
 * aafarm: the surface colour lit by the ambient and diffuse light, plus a
 * highlight of specularcolor (white by default) that the surface colour
 * does not tint.
 */
surface plastic(float Ks = 0.5; float Kd = 0.5; float Ka = 1; float roughness = 0.1;
                color specularcolor = 1)
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * (Cs * (Ka * ambient() + Kd * diffuse(Nf)) +
               specularcolor * Ks * specular(Nf, V, roughness));
}
