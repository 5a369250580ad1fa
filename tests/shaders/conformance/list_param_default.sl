/* untyped triples as shader parameter defaults */
displacement list_param_default(point center = (0.5, 0.5, 0); color tint = (1, 0.5, 0.25))
{
    P = (xcomp(P) - xcomp(center), comp(tint, 1), comp(tint, 2) * t);
}
