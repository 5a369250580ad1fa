/* untyped triples returned through ?: by a nested function */
displacement list_nested_return()
{
    color pick(float x) { return x < 0.5 ? (1, 0, 0) : (0, 0, 1); }
    color c = pick(s) + pick(t);
    P = (comp(c, 0), comp(c, 1), comp(c, 2));
}
