/* noise family: the argument types a point form takes (a point, a vector,
 * a normal, the global P) and a constant argument; float results by cast */
displacement noise_argument_types()
{
    float a = float noise(P * 2) + noise(1.5);
    float b = float noise(vector(s, t, 1));
    float c = noise(normal(t, s, 0) * 3, s);
    P = point(a, b, c);
}
