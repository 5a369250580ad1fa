/* noise family, triple results from the context: color, vector and point
 * noise of every argument form, as colour variation and bump shaders use */
displacement noise_triple_forms()
{
    point q = point (s, t, 0.5) * 2;
    color c = color noise(q) + color noise(s * 4, t * 4);
    vector v = vector noise(q, t) + vector noise(s * 7);
    point p = pnoise(q, point (4, 4, 4));
    color w = color cellnoise(q * 2) + color pnoise(s * 3, t * 3, 3, 3);
    P = point(comp(c, 0) + xcomp(v), ycomp(v) + ycomp(p), comp(w, 2) + zcomp(p));
}
