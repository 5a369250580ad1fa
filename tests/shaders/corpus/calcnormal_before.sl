/*
 * calcnormal_before.sl: the direction of displacement from
 * normalize(calculatenormal(P)) taken BEFORE moving P (a common way to get
 * the true geometric normal).
 * Idiom: calculatenormal before moving P (issue 9, finding 2).
 */
displacement calcnormal_before(float Km = 0.02, frequency = 6)
{
    normal Nn = normalize(calculatenormal(P));
    float h = sin(2 * PI * frequency * s) * sin(2 * PI * frequency * t);
    P += Km * h * Nn;
    N = calculatenormal(P);
}
