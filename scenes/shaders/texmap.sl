/*
 * texmap.sl: a plastic surface whose colour is a texture map's, tinted by
 * the surface colour, with an optional bump map along the normal (the
 * normal tilted by bump()); falls back to the surface colour where no map
 * is named (issue 16).
 */
surface texmap(float Ka = 1, Kd = 0.7, Ks = 0.3, roughness = 0.15, bumpscale = 0;
               string colormap = "", bumpmap = "")
{
    normal Nf = normalize(N);
    if (bumpmap != "")
        Nf = normalize(Nf + bumpscale * bump(bumpmap, Nf, dPdu, dPdv));
    Nf = faceforward(Nf, I);
    color Ct = Cs;
    if (colormap != "")
        Ct *= color texture(colormap, s, t);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * (Ct * (Ka * ambient() + Kd * diffuse(Nf)) + Ks * specular(Nf, V, roughness));
}
