/* matrices: determinant of a varying matrix and of a product (det(ab) =
 * det(a) det(b)), the inverse's scale */
displacement matrix_determinant()
{
    matrix a = matrix (2, s, 0, 0,  t, 1, 0.5, 0,  0, 0.25, 3, 0,  s, t, 1, 1);
    matrix b = matrix (1, 0, 0, 0,  0, 1 + s, 0, 0,  0, t, 2, 0,  0, 0, 0, 1);
    P = point(determinant(a), determinant(a * b), determinant(matrix 2));
}
