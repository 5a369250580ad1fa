/*
 * atan_ratio.sl: the one-argument form atan(y / x) of object-space
 * coordinates (old shaders do this instead of atan(y, x)), making rays of
 * bumps around the axis.
 * Idiom: atan of a ratio whose denominator spans 0 (issue 9, finding 5).
 */
displacement atan_ratio(float Km = 0.02, rays = 6)
{
    point Pobj = transform("object", P);
    float a = atan(ycomp(Pobj) / xcomp(Pobj));
    float h = 0.5 + 0.5 * cos(2 * rays * a);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
