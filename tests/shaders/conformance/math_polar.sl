/* polar coordinates about a centre, as the star shader computes them:
 * atan(y, x), sqrt, sin/cos of the angle */
displacement math_polar()
{
    float x = s - 0.5, y = t - 0.6;
    float r = sqrt(x * x + y * y);
    float angle = atan(y, x);
    P = point(r, sin(3 * angle), cos(angle) * r + atan(s + 0.5));
}
