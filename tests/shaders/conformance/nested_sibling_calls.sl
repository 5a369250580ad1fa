/* nested functions: a later helper calls an earlier one of the same block */
displacement nested_sibling_calls()
{
    float sq(float x) { return x * x; }
    float quad(float x) { return sq(sq(x)); }
    P = point(quad(s), sq(t) + quad(0.5), 0);
}
