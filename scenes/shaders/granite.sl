/*
 * granite.sl: speckled stone: a turbulence sum of |noise - 0.5| over a few
 * octaves modulates the surface colour, and cell noise scatters dark
 * crystals (cells whose value falls below `speckle`).
 */
surface granite(
    float Ka = 1, Kd = 0.8, Ks = 0.2, roughness = 0.25;
    float frequency = 6;           /* of the first octave, in shader space */
    float octaves = 4;
    float speckle = 0.1)           /* share of dark crystal cells */
{
    point PP = transform("shader", P) * frequency;
    float sum = 0, f = 1, i;
    for (i = 0; i < octaves; i += 1) {
        sum += abs(noise(PP * f) - 0.5) / f;
        f *= 2;
    }
    float crystal = 1 - 0.7 * (1 - step(speckle, cellnoise(PP * 4)));
    color Ct = Cs * (0.6 + 0.6 * clamp(sum, 0, 1)) * crystal;

    normal Nf = faceforward(normalize(N), I);
    vector V = -normalize(I);
    Oi = Os;
    Ci = Os * (Ct * (Ka * ambient() + Kd * diffuse(Nf)) + Ks * specular(Nf, V, roughness));
}
