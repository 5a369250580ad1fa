/* arrays: points, arraylength in a loop bound, a varying index */
displacement array_points()
{
    point pts[3] = {(0, 0, 0), (1, 0, 0), (0, 1, 0)};
    float i, best = 1e6;
    point q = point(s, t, 0);
    for (i = 0; i < arraylength(pts); i += 1)
        best = min(best, distance(q, pts[i]));
    P = point(best, xcomp(pts[s * 3]), 0);
}
