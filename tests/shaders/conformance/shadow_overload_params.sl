/* scopes and overloading: overloads whose parameters are named s, t, P */
float tex(float s, t) { return s * 10 + t; }
float tex(point P) { return xcomp(P) * 10 + ycomp(P); }

displacement shadow_overload_params()
{
    P = point(tex(t, s), tex(point(s, t, 0)), tex(P));
}
