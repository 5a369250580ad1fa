/* untyped triples returned (through ?:) and passed as arguments */
vector axis(float which) { return which > 0.5 ? (1, 0, 0) : (0, 1, 0); }
float sum3(color c) { return comp(c, 0) + comp(c, 1) + comp(c, 2); }

displacement list_return_arg()
{
    P = point(sum3((s, t, 1)), ycomp(axis(s)), xcomp(axis(t)));
}
