/* fresnel: the glass idiom of the books, reflection and transmission
 * weights with the reflected and refracted directions */
displacement geom_fresnel(float ior = 1.5)
{
    normal Nf = normal (0, 0, 1);
    vector V = normalize(vector (s - 0.5, 0.3 * t, -1));
    float Kr, Kt;
    vector R, T;
    fresnel(V, Nf, 1 / ior, Kr, Kt, R, T);
    float Kr2, Kt2;
    fresnel(normalize(vector (2 * t - 1, 0.2, -0.5)), Nf, ior, Kr2, Kt2);
    P = point(Kr + xcomp(T), Kt + zcomp(R) + ycomp(T), Kr2 + Kt2 * 0.5);
}
