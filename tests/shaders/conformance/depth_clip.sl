/* depth: camera-space z between the clipping planes (the suite sets
 * Clipping 0.5 10.5) */
displacement depth_clip()
{
    point q = point (s, t, 4 * s + 1);
    P = point(depth(q), depth(point "camera" (0, 0, 10 * t)), depth(P + N));
}
