/*
 * vector_wrinkles.sl: wrinkles that move P off the normal: a vector noise
 * added to P directly (not along N).
 * Idiom: P += vector noise (displacement in an arbitrary direction).
 */
displacement vector_wrinkles(float Km = 0.02, frequency = 5)
{
    point Psh = transform("shader", P) * frequency;
    vector d = vector noise(Psh) - 0.5;
    P += Km * d;
    N = calculatenormal(P);
}
