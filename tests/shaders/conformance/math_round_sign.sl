/* round, sign and inversesqrt, and abs/floor/ceil on triples */
displacement math_round_sign()
{
    float x = 6 * s - 3;
    point q = point (x, 4 * t - 2, x * t);
    point r = round(q) + sign(q) * 10;
    P = point(xcomp(r) + inversesqrt(1 + s * s), ycomp(r) + zcomp(abs(q)),
              zcomp(r) + xcomp(floor(q) + ceil(q)));
}
