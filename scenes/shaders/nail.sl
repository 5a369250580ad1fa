/*
 * nail.sl: a nail standing on a disk (Heidrich & Seidel 1998, Figure 5):
 * the discontinuous, extreme displacement of the paper's §5. Inside a
 * small radius around the object-space z axis the surface rises by Km
 * (times a shallow conical tip); outside it stays put. The step makes the
 * shaft's sides vertical walls, which the ray tracer finds as
 * discontinuities (AA_DISCONTINUOUS) rather than as thin boxes that never
 * shrink.
 *
 * Meant for a disk of radius 1 (or the square [-1,1]^2) at the base of the
 * nail, with Km around 0.5: a nail ten times taller than it is wide.
 */
displacement nail(
    float Km = 0.5;          /* height of the nail */
    float radius = 0.05;     /* radius of the shaft, object space */
    float tip = 0.2)         /* how pointed the top is (0: flat) */
{
    point Po = transform("object", P);
    float x = xcomp(Po), y = ycomp(Po);
    float r = sqrt(x * x + y * y);
    float shaft = 1 - step(radius, r);
    P += Km * shaft * (1 - tip * r / radius) * normalize(N);
    N = calculatenormal(P);
}
