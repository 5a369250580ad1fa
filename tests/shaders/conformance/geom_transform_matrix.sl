/* transform, vtransform and ntransform by a matrix built with scale and
 * translate (translate applies first) */
displacement geom_transform_matrix()
{
    matrix m = translate(scale(matrix 1, point(2, 3, 1)), vector(1, 0, 0));
    point p = transform(m, point(s, t, 0));
    vector v = vtransform(m, vector(s, t, 1));
    normal n = ntransform(m, normal(0, t, 1));
    P = point(xcomp(p) + ycomp(v), ycomp(p) + ycomp(n), zcomp(n) + xcomp(v));
}
