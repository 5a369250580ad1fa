/* illuminance inside a helper function, the wrap-lighting helper of the
 * books' local illumination headers: lights up to 'wrap' past the
 * terminator, a narrow cone for a rim term */
color wrapdiffuse(normal Nn; float wrap)
{
    color C = 0;
    extern point P;
    illuminance(P, Nn, PI) {
        float d = normalize(L) . Nn;
        C += Cl * max(0, (d + wrap) / (1 + wrap));
    }
    return C;
}

surface surface_illuminance_helper(float wrap = 0.3)
{
    normal Nf = faceforward(normalize(N), I);
    color rim = 0;
    illuminance(P, -Nf, radians(60))
        rim += Cl;
    Ci = wrapdiffuse(Nf, wrap);
    Oi = rim;
}
