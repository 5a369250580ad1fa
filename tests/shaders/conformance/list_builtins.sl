/* untyped triples as built-in arguments (points where spatial types are
 * wanted) */
displacement list_builtins()
{
    vector d = normalize((3, 0, 4));
    P = point(xcomp(d) + zcomp(d), distance((0, 0, 0), P), length((s, t, 0)));
}
