/* 16 values typed as a matrix by a declaration */
displacement list_matrix()
{
    matrix m = (2, 0, 0, 0,  0, 3, 0, 0,  0, 0, 1, 0,  s, t, 0, 1);
    P = transform(m, point(1, 1, 1));
}
