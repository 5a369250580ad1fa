/*
 * dpdu_rivets.sl: rivets spaced evenly in surface length along u: the
 * frequency is scaled by length(dPdu), and the rivets lean along
 * normalize(dPdu).
 * Idiom: dPdu / normalize(dPdu) (vanishes at a sphere's poles).
 */
displacement dpdu_rivets(float Km = 0.02, spacing = 0.4, radius = 0.15)
{
    vector T = normalize(dPdu);
    float len = length(dPdu);
    float ss = mod(s * len / spacing, 1), tt = mod(t * 8, 1);
    float r = distance(point(ss, tt, 0), point(0.5, 0.5, 0));
    float h = 1 - smoothstep(radius * 0.6, radius, r);
    P += Km * h * (normalize(N) + 0.2 * T);
    N = calculatenormal(P);
}
