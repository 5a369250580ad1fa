/* untyped triples as the elements of an array of points: a bilinear patch */
displacement list_array_init()
{
    point corners[4] = {(0, 0, 0), (1, 0, 0), (1, 1, 1), (0, 1, 0)};
    point a = mix(corners[0], corners[1], s), b = mix(corners[3], corners[2], s);
    P = mix(a, b, t);
}
