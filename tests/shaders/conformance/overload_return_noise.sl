/* overloading by return type, the noise idiom: float or colour by context */
float noisy(point p) { return noise(p); }
color noisy(point p) { return color noise(p); }

displacement overload_return_noise()
{
    color c = noisy(P * 2);
    float f = noisy(P * 2);
    P = point(f, comp(c, 0), comp(c, 2));
}
