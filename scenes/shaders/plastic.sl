/*
 * plastic.sl: diffuse colour plus a white (specularcolor) highlight, the
 * look of painted plastic (RenderMan's standard plastic).
 */
surface plastic(
    float Ka = 1, Kd = 0.5, Ks = 0.5;
    float roughness = 0.1;
    color specularcolor = 1)
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * (Cs * (Ka * ambient() + Kd * diffuse(Nf)) +
               specularcolor * Ks * specular(Nf, V, roughness));
}
