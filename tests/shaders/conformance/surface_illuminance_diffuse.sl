/* illuminance: the diffuse loop of the books' matte shader, within a cone
 * of PI/2 about the facing normal; Oi gets diffuse() for comparison */
surface surface_illuminance_diffuse(float Kd = 0.8)
{
    normal Nf = faceforward(normalize(N), I);
    color C = 0;
    illuminance(P, Nf, PI / 2) {
        C += Cl * normalize(L) . Nf;
    }
    Ci = Kd * C;
    Oi = Kd * diffuse(Nf);
}
