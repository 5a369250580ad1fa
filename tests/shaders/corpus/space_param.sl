/*
 * space_param.sl: the Advanced RenderMan "Displace" habit: the space of the
 * pattern and of the amplitude is a string parameter, looked up at run
 * time; uniform/varying/output declarations as production shaders write
 * them.
 * Idiom: string space parameter, length(vtransform(space, ...)), output
 * varying parameter.
 */
displacement space_param(uniform float Km = 0.03;
                         uniform float frequency = 4;
                         uniform string dispspace = "shader";
                         output varying float height = 0)
{
    normal Nn = normalize(N);
    point Pp = transform(dispspace, P) * frequency;
    height = noise(Pp) - 0.5;
    vector Nsp = vtransform(dispspace, vector Nn);
    float spacescale = 1 / length(Nsp);
    P += Km * height * spacescale * Nn;
    N = calculatenormal(P);
}
