/*
 * tex_environment.sl: displacement read from a lat-long map by the
 * direction of the normal (a spherical height map on any surface), plus
 * a bump() term: the normal's change for the same height map, scaled
 * down and added to P as a small tangential offset.
 * Idiom: environment(name, direction), bump(name, N, dPdu, dPdv).
 */
displacement tex_environment(float Km = 0.04; string mapname = "corpus_height.exr")
{
    vector D = normalize(vtransform("object", N));
    float h = environment(mapname, D, "blur", 0.02);
    vector b = bump(mapname, normalize(N), dPdu, dPdv, s, t);
    P += Km * h * normalize(N) + 1e-5 * Km * b;
}
