/* specular() written out with specularbrdf in an illuminance loop over
 * every light (as RI Spec 3.2 defines it): the same colour */
surface surface_specularbrdf(float roughness = 0.25)
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    color C = 0;
    illuminance(P)
        C += Cl * specularbrdf(normalize(L), Nf, V, roughness);
    Ci = C;
    Oi = specular(Nf, V, roughness);
}
