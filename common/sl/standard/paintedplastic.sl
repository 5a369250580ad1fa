/*
 * paintedplastic.sl: the RI Specification's standard paintedplastic
 * surface, built into aafarm: plastic whose diffuse colour is the surface
 * colour times a colour map read at (s, t). With no map named, it is
 * plastic.
 */
surface paintedplastic(float Ks = 0.5; float Kd = 0.5; float Ka = 1; float roughness = 0.1;
                       color specularcolor = 1; string texturename = "")
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    color paint = Cs;
    if (texturename != "")
        paint *= color texture(texturename, s, t);
    Oi = Os;
    Ci = Os * (paint * (Ka * ambient() + Kd * diffuse(Nf)) +
               specularcolor * Ks * specular(Nf, V, roughness));
}
