/* RSL 2: the diffuse loop of surface_illuminance_diffuse as a shader class
 * with a public surface method, a member for the facing normal (set by
 * begin()) and a lighting method */
class surface_class_matte(float Kd = 0.8)
{
    varying normal Nf = 0;

    color lambert() {
        color C = 0;
        illuminance(P, Nf, PI / 2)
            C += Cl * normalize(L) . Nf;
        return C;
    }

    public void begin() { Nf = faceforward(normalize(N), I); }

    public void surface(output color Ci, Oi)
    {
        Ci = Kd * lambert();
        Oi = Kd * diffuse(Nf);
    }
}
