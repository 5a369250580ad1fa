/*
 * ntransform_amp.sl: the "displace in a named space" idiom: the amplitude
 * is given in object-space units, so the shader scales it by the length of
 * the unit normal brought to object space and back.
 * Idiom: displacement scaled by length(ntransform("object", ...)).
 */
displacement ntransform_amp(float Km = 0.03, frequency = 3)
{
    normal Nn = normalize(N);
    normal Nobj = ntransform("object", Nn);
    float objscale = length(Nobj);
    point Pobj = transform("object", P) * frequency;
    float h = noise(Pobj) - 0.5;
    P += Km * h * Nn / objscale;
    N = calculatenormal(P);
}
