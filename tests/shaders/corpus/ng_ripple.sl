/*
 * ng_ripple.sl: ripples along the geometric normal Ng (not N), faceforward
 * against I so the ripples always face the viewer.
 * Idiom: Ng, faceforward with I.
 */
displacement ng_ripple(float Km = 0.02, frequency = 10)
{
    normal Nf = faceforward(normalize(Ng), I);
    float h = sin(2 * PI * frequency * (s + t));
    P += Km * h * Nf;
    N = calculatenormal(P);
}
