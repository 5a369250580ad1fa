/* untyped triples typed by declarations and by the other operand */
displacement list_assign()
{
    vector up = (0, 0, 1);
    color c = (s, t, 0.5);
    P = (comp(c, 0), comp(c, 1), 0) + up * comp(c, 2);
}
