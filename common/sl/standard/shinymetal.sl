/*
 * shinymetal.sl: the RI Specification's standard shinymetal surface, built
 * into aafarm: metal plus Kr times an environment map looked up in the
 * mirror direction (in world space). With no map named, it is metal.
 */
surface shinymetal(float Ka = 1; float Ks = 1; float Kr = 1; float roughness = 0.1;
                   string texturename = "")
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    color mirror = 0;
    if (texturename != "") {
        vector R = vtransform("world", reflect(I, Nf));
        mirror = color environment(texturename, R);
    }
    Oi = Os;
    Ci = Os * Cs * (Ka * ambient() + Ks * specular(Nf, V, roughness) + Kr * mirror);
}
