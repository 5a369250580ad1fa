/* matrices: the determinant of a composed transform is the product of its
 * scales whatever the rotations and translations */
displacement matrix_det_compose()
{
    matrix m = translate(matrix 1, vector (s, t, 1));
    m = rotate(m, 2 * PI * s, vector (t, 1, 0.5));
    m = scale(m, point (2, 1 + t, 0.5));
    matrix r = rotate(matrix 1, t, vector (0, 1, 0));
    P = point(determinant(m), determinant(r), determinant(m * r * 2));
}
