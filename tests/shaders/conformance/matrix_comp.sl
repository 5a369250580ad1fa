/* matrices: comp and setcomp by row and column as written (translation in
 * row 3), a varying index, and a constructor from the "object" space */
displacement matrix_comp()
{
    matrix m = matrix (1, 2, 3, 4,  5, 6, 7, 8,  9, 10, 11, 12,  13, 14, 15, 16);
    setcomp(m, 3, 1, t);
    float row = floor(s * 4);
    matrix o = matrix "object" 1;
    P = point(comp(m, 3, 0) + comp(m, 0, 2), comp(m, 3, 1) + comp(m, row, 1),
              comp(o, 0, 0) + comp(o, 3, 2));
}
