/* overloading: point, vector and normal overloads, each an exact match */
float h(point p) { return 1; }
float h(vector v) { return 2; }
float h(normal n) { return 3; }

displacement overload_triples()
{
    P = point(h(P) + 10 * h(P - P) + 100 * h(N), s, t);
}
