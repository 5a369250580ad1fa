/* illuminance: a category, no cone (lights behind the surface too),
 * continue for the ones behind, and a count of the lights */
surface surface_illuminance_category()
{
    normal Nf = faceforward(normalize(N), I);
    float n = 0;
    color C = 0;
    illuminance("diffuse", P) {
        n += 1;
        if (L . Nf < 0)
            continue;
        C += Cl * 0.5;
    }
    Ci = C;
    Oi = color (n, 0, 0);
}
