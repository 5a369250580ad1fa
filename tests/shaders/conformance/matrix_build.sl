/* matrices: translate, rotate and scale concatenated onto a matrix as
 * RiTranslate, RiRotate and RiScale do (the last call applies first) */
displacement matrix_build()
{
    matrix m = translate(matrix 1, vector (0.5, 0, 0));
    m = rotate(m, radians(90 * s), vector (0, 0, 1));
    m = scale(m, point (1, 2, 1));
    matrix r = rotate(matrix 1, t, vector (1, 1, 1));
    point p = transform(m, point (1, 1, t));
    point q = transform(r, point (1, 0, 0));
    P = point(xcomp(p) + zcomp(q), ycomp(p), zcomp(p) + xcomp(q));
}
