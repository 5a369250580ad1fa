/* faceforward and reflect: the normal turned towards the viewer, the
 * mirror direction, as the books' plastic and shiny shaders build them */
displacement geom_faceforward_reflect()
{
    vector V = vector (s - 0.5, t - 0.3, 0.25 - s * t);
    normal Nf = faceforward(normalize(N), V, N);
    normal Nf2 = faceforward(normal (0, 1, 0), vector (0, t - 0.5, 1));
    vector R = reflect(normalize(V), Nf);
    P = point(xcomp(R), ycomp(R) + zcomp(Nf), zcomp(R) + ycomp(Nf2));
}
