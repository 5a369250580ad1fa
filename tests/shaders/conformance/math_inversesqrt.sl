/* inversesqrt, and 1 / sqrt written out */
displacement math_inversesqrt()
{
    P = point(inversesqrt(s + 0.5), inversesqrt(t * t + 1) * t,
              1 / sqrt(s + t + 1) - inversesqrt(s + t + 1));
}
