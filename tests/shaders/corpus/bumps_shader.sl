/*
 * bumps_shader.sl: bumps in shader space, with the displacement measured in
 * shader-space units: the length of the unit normal transformed to
 * "shader" scales it back to current space.
 * Idiom: bumps in shader space, amplitude via length(ntransform(...)).
 */
displacement bumps_shader(float Km = 0.03, frequency = 5)
{
    normal Nn = normalize(N);
    point Psh = transform("shader", P);
    float h = noise(Psh * frequency) - 0.5;
    normal Nsh = ntransform("shader", Nn);
    float scale = 1 / length(Nsh);
    P += Km * h * scale * Nn;
    N = calculatenormal(P);
}
