/* illuminance: a Blinn highlight written out, beside specular() */
surface surface_illuminance_specular(float roughness = 0.25)
{
    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    color C = 0;
    illuminance(P, Nf, PI / 2) {
        vector H = normalize(normalize(L) + V);
        C += Cl * pow(max(0, Nf . H), 1 / roughness);
    }
    Ci = C;
    Oi = specular(Nf, V, roughness);
}
