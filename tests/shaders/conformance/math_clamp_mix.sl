/* clamp, mix, min, max on floats and triples */
displacement math_clamp_mix()
{
    point a = point(s, t, s * t), b = point(1 - t, s * s, 0.5);
    point lo = min(a, b), hi = max(a, b);
    P = point(mix(s, t, 0.3) + clamp(2 * s - 0.5, 0, 1),
              xcomp(hi) - xcomp(lo) + ycomp(mix(a, b, 0.25)),
              zcomp(clamp(a, point(0.1), point(0.4))) + max(max(s, t), 0.6) - min(s, t));
}
