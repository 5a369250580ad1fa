/* tan, atan of one and two arguments, asin, acos, degrees, radians */
displacement math_trig_inverse()
{
    P = point(tan(s) + atan(t), asin(s - 0.5) + acos(t - 0.5),
              degrees(atan(t, s)) + radians(90 * s));
}
