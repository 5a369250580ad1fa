/* specularbrdf: the lobe specular() sums over the lights, for one
 * direction (a grey colour) */
displacement shading_specularbrdf(float roughness = 0.2)
{
    color c = specularbrdf(normalize(vector(s - 0.5, t - 0.5, 1)), normal(0, 0.2, 1),
                           vector(0, 0, 1), roughness);
    color d = specularbrdf(vector(1, 0, -1), normal(0, 0, 1), vector(0, 0, 1), 0.5);
    P = point(comp(c, 0), comp(c, 2) - comp(c, 1), comp(d, 1));
}
