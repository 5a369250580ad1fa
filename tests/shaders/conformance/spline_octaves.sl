/* spline: inside a loop of octaves, the knots from an array filled by the
 * loop, as layered-colour shaders do */
displacement spline_octaves(float octaves = 3)
{
    float knots[5], i, sum = 0;
    for (i = 0; i < 5; i += 1)
        knots[i] = i * i / 16;
    for (i = 0; i < octaves; i += 1)
        sum += spline("catmull-rom", mod(s * pow(2, i), 1), knots) / pow(2, i);
    P = point(sum, spline("linear", t, knots), spline("constant", s, knots));
}
