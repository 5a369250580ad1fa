/* matrices: filled element by element with setcomp in nested loops (the
 * indices vary), then applied to a point */
displacement matrix_setcomp_loop()
{
    matrix m = 0;
    float i, j;
    for (i = 0; i < 4; i += 1)
        for (j = 0; j < 4; j += 1)
            setcomp(m, i, j, i == j ? 1 : 0);
    setcomp(m, 3, 0, s);
    setcomp(m, 3, 2, t);
    setcomp(m, 1, 1, 2);
    P = transform(m, point (1, 1, 1)) + vector (0, comp(m, 1, 1), 0);
}
