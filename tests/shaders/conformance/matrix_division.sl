/* matrices: a / b is a * inverse(b), f / b is f * inverse(b); and the
 * constants ncomps and dtime, min and max of more than two values */
displacement matrix_division()
{
    matrix a = translate(matrix 1, vector(s, t, 0)), b = scale(matrix 1, point(2, 4, 1));
    matrix q = (a * b) / b;
    matrix r = 2 / b;
    P = point(comp(q, 3, 0), comp(q, 3, 1) + comp(r, 1, 1),
              min(s, t, 0.5) + max(s, t, 0.25, ncomps + dtime));
}
