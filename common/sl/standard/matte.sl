/*
 * matte.sl: the RI Specification's standard matte surface, built into
 * aafarm: a Lambertian reflector, the surface colour times Ka times the
 * ambient light plus Kd times the diffuse light, on the side facing the eye.
 */
surface matte(float Ka = 1; float Kd = 1)
{
    normal Nf = faceforward(normalize(N), I);
    Oi = Os;
    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf));
}
