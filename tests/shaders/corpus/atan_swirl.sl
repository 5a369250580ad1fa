/*
 * atan_swirl.sl: a spiral around the object-space z axis: the angle from
 * atan(y, x) and the radius of the object-space point.
 * Idiom: atan(y, x) (discontinuous at the branch cut, x spanning 0).
 */
displacement atan_swirl(float Km = 0.02, arms = 3, twist = 4)
{
    point Pobj = transform("object", P);
    float x = xcomp(Pobj), y = ycomp(Pobj);
    float angle = atan(y, x);
    float r = sqrt(x * x + y * y);
    float h = 0.5 + 0.5 * sin(arms * angle + twist * 2 * PI * r);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
