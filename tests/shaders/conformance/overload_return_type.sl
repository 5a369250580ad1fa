/* overloading by return type: the context picks (declaration, cast) */
float shade(point p) { return xcomp(p) + ycomp(p); }
color shade(point p) { return color(xcomp(p), ycomp(p), 1); }

displacement overload_return_type()
{
    float f = shade(P);
    color c = shade(P);
    P = point(f, comp(c, 1) * 2, float shade(P * 2));
}
