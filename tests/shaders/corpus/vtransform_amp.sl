/*
 * vtransform_amp.sl: amplitude in shader-space units through vtransform of
 * the unit normal: P += amp * Nn * length(vtransform("shader", Nn)).
 * Idiom: length(vtransform(space, Nn)) as a space scale.
 */
displacement vtransform_amp(float Km = 0.02, frequency = 8)
{
    normal Nn = normalize(N);
    float spacescale = length(vtransform("shader", Nn));
    float h = sin(2 * PI * frequency * s) * 0.5 + 0.5;
    P += Km * h * spacescale * Nn;
    N = calculatenormal(P);
}
