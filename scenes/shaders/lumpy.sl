/*
 * lumpy.sl: lumps from the sines of P's object-space components: the
 * product sin(f x) sin(f y) cos(f z) bulges out and in like an egg crate
 * (on the plane z = 0 the cosine is 1).
 *
 * Meant for unit-size objects, Km around 0.1.
 */
displacement lumpy(
    float Km = 0.1;
    float frequency = 3)     /* radians per unit of object space */
{
    point Po = transform("object", P);
    float h = sin(frequency * xcomp(Po)) * sin(frequency * ycomp(Po)) *
              cos(frequency * zcomp(Po));
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
