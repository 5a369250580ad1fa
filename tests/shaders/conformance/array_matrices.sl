/* arrays of matrices (16 values per element) indexed by a varying float */
displacement array_matrices()
{
    matrix ms[2] = {matrix(1), (2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  0, 0, 0, 1)};
    matrix m = ms[s * 2];
    P = transform(m, point(1, t, 1));
}
