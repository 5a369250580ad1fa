/* noise family: point results of cellnoise() in every argument form,
 * typed by the declarations (piecewise constant: the range modes merge
 * the cells a box covers) */
displacement cellnoise_forms_point()
{
    point a = cellnoise(s * 4);
    point b = cellnoise(s * 4, t * 4);
    point c = cellnoise(point(s, t, 0) * 4);
    point d = cellnoise(point(s, t, 0) * 4, t * 3);
    P = point(xcomp(a) + ycomp(b), zcomp(c) + xcomp(d), ycomp(a) + zcomp(d));
}
