/* overloading: an exact match beats a spatial conversion, which beats a
 * float promotion */
float k(point p) { return 1; }
float k(color c) { return 2; }
float k(float x) { return 3; }
float m(vector v) { return xcomp(v); }
float m(color c) { return -comp(c, 0); }

displacement overload_conversion_cost()
{
    P = point(k(normal(0, 0, 1)) * 10 + k(s), m(point(s, 0, 0)), m(color(t)));
}
