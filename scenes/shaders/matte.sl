/*
 * matte.sl: a Lambertian surface: the surface colour times the ambient and
 * diffuse light (RenderMan's standard matte).
 */
surface matte(float Ka = 1; float Kd = 1)
{
    normal Nf = faceforward(normalize(N), I);
    Oi = Os;
    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf));
}
