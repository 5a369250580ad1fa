/* untyped triples under -, *, + and /, typed by the assignment */
displacement list_operators()
{
    point q = -(s, t, 1) * 2 + (1, 1, 1);
    P = q + (0, 0, t);
    if (u > 0.5)
        P = (P + (1, 0, 0)) / 2;
}
