/*
 * ufo.sl: a flying saucer from a sphere (Heidrich & Seidel 1998, Figure 7):
 * the profile is a function of the latitude t only. A sharp rim bulges out
 * around the equator, the caps are pulled in so the sphere flattens into a
 * saucer, and a cockpit dome rises on the northern cap only (an if on t,
 * so ranges across the equator run both branches and merge).
 *
 * Meant for a unit sphere (t = 0 at the south pole, 1 at the north), Km
 * around 0.3.
 */
displacement ufo(
    float Km = 0.3;
    float rimwidth = 0.15;     /* latitude band of the rim, 0..1 from the equator */
    float flatten = 0.7;       /* how far the caps are pulled in */
    float domesize = 0.35;     /* cockpit: cap of this size around the north pole */
    float domeheight = 0.5)
{
    float lat = abs(2 * t - 1);                  /* 0 at the equator, 1 at the poles */
    float rim = 1 - smoothstep(0, rimwidth, lat);
    float h = rim - flatten * lat * lat;
    if (t > 0.5)
        h += domeheight * smoothstep(1 - domesize, 1, lat);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}
